// tests/test_volume_files.cpp: NanoVDB media (nsp/io/nanovdb.hpp), .nvdb and .vdb files
// (nsp/io/openvdb.hpp), and the tree majorant over them. Built only when CMake finds NanoVDB
// (and the .vdb cases only with OpenVDB).
//
// - The cloud as a NanoVDB grid is the same medium as DenseGridMedium built from the same values
//   (its outer voxel layer is 0): densities equal to float rounding at random points; the same
//   image-plane mean of uni + NEE MIS (k = 5 SE, independent seeds) and lookups per sample within
//   5 SE under the same tree majorant; written as .nvdb and .vdb and read back, the same grid to
//   the bit.
// - The tree majorant on the grid's nodes and the adaptive one bound every lookup along random
//   rays through the cloud and the sparse plume (exactly), leave no density uncovered, and ratio
//   and delta tracking match the closed-form transmittance through a grid of constant tiles
//   (OpenVDB fills them as tiles): along an axis through voxel centres the density is piecewise
//   linear between index points, so the optical depth is h mu sum(values), exact.
// - Every bad file gets its message: a missing file, an unknown format, no grid of that name (the
//   grids there are listed), not float, a level set, a negative or non-finite value, a truncated
//   or corrupted file, an empty grid, a rotated transform.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nsp/io/nanovdb.hpp>
#if NSP_HAVE_OPENVDB
#include <nsp/io/openvdb.hpp>
#include <openvdb/tools/LevelSetSphere.h>
#endif

#include "common.hpp"
#include "volume_files.hpp"

namespace {

using namespace nsp_test;
using doctest::Contains;
using NM = nsp::io::NanoVdbMedium<Mono>;

constexpr double kSigmas = 5.0;

std::string temp_path(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / "nsp_test_volume_files";
    std::filesystem::create_directories(dir);
    return (dir / name).string();
}

std::vector<char> read_bytes(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), {}};
}
void write_bytes(const std::string& path, const std::vector<char>& b) {
    std::ofstream f(path, std::ios::binary);
    f.write(b.data(), std::streamsize(b.size()));
}

/// `bytes` with the value at `at` replaced by `v` (a field of the file's layout).
template <class T>
std::vector<char> with(std::vector<char> bytes, std::uint64_t at, T v) {
    std::memcpy(bytes.data() + at, &v, sizeof v);
    return bytes;
}

std::shared_ptr<const nsp::io::NanoDensityGrid> cloud_grid() {
    return std::make_shared<const nsp::io::NanoDensityGrid>(nsp::io::to_nanovdb(nsp_examples::cloud_voxels()), "cloud");
}

/// Uni + NEE MIS radiance through the camera rays of a 16 x 16 image of the box, per path: the
/// mean and its standard error, and lookups per path with theirs.
template <class M, class Maj>
std::pair<Stat, Stat> render_stats(const M& medium, const Maj& maj, std::uint64_t seed) {
    Lights<Mono> lights;
    lights.set(EnvironmentLight<Mono>{grey<Mono>(0.5f)});
    lights.set(SphereLight<Mono>{Vec3(0.5f, 2.5f, -1.f), 0.3f, grey<Mono>(40.f)});
    const auto scene = Scene(medium, maj, HenyeyGreensteinPhase(0.5f), lights);
    const PathEstimator<strategy::NullScatteringMis, mis::Balance> est;
    Stat value, lookups;
    for (int p = 0; p < 256; ++p) {
        Pcg32 rng(seed, std::uint64_t(p));
        const Ray r{Vec3(-0.9f + 1.8f * (float(p % 16) + 0.5f) / 16.f, -0.9f + 1.8f * (float(p / 16) + 0.5f) / 16.f, -3.f),
                    Vec3(0.f, 0.f, 1.f)};
        for (int k = 0; k < 100; ++k) {
            LookupCount c;
            value.add(est.radiance(scene, r, {}, rng, c).value[0]);
            lookups.add(double(c.count()));
        }
    }
    return {value, lookups};
}

TEST_CASE("the cloud as a NanoVDB grid is the medium DenseGridMedium gives from the same values") {
    const auto cloud = nsp_examples::cloud_voxels();
    using DM = DenseGridMedium<Mono>;
    const DM dense = nsp::io::to_dense_medium<Mono>(cloud, grey<Mono>(2.f), grey<Mono>(18.f));
    const NM nano(cloud_grid(), grey<Mono>(2.f), grey<Mono>(18.f));
    // The cloud's outer voxel layer is 0, so clamping (dense) and fading to 0 (NanoVDB) agree.
    Pcg32 rng(3, 1);
    double worst = 0.0;
    for (int i = 0; i < 200000; ++i) {
        const Vec3 p = random_point(rng, Box{Vec3(-1.05f), Vec3(1.05f)});
        worst = std::max(worst, double(std::abs(dense.density(p) - nano.density(p))));
    }
    CHECK(worst <= 1e-6);  // the same trilinear weights, rounded in another order
    CHECK(nano.max_extinction() == doctest::Approx(dense.max_extinction()).epsilon(1e-6));
    // The same image mean (independent seeds: 5 combined SE), and under the same tree majorant
    // (one layout over the dense grid's box, which holds the NanoVDB grid's bounds: the same
    // density bounds in every cell) the same lookups per path within 5 SE.
    const TreeLayout layout{dense.bounds(), {8, 8, 8}, {4, 4, 0}, 0.3f};
    const TreeMajorant<NM> nano_tree(nano, layout);
    const TreeMajorant<DM> dense_tree(dense, layout);
    CHECK(nano_tree.split_cells(0) == dense_tree.split_cells(0));
    CHECK(nano_tree.split_cells(1) == dense_tree.split_cells(1));
    // (No structured bindings: clang does not let doctest's CAPTURE lambdas name them.)
    const auto nano_stats = render_stats(nano, nano_tree, 1), dense_stats = render_stats(dense, dense_tree, 2);
    const Stat &vn = nano_stats.first, &ln = nano_stats.second, &vd = dense_stats.first, &ld = dense_stats.second;
    CAPTURE(vn.mean);
    CAPTURE(vd.mean);
    CHECK(std::abs(vn.mean - vd.mean) <= kSigmas * std::hypot(vn.se(), vd.se()));
    CAPTURE(ln.mean);
    CAPTURE(ld.mean);
    CHECK(std::abs(ln.mean - ld.mean) <= kSigmas * std::hypot(ln.se(), ld.se()));
    CHECK(vn.mean > 0.05);
}

template <class M, class Maj>
void check_bounds_along_rays(const M& medium, const Maj& maj, const char* name) {
    CAPTURE(name);
    const Box b = medium.bounds();
    const Box around{b.lo - 0.3f * (b.hi - b.lo), b.hi + 0.3f * (b.hi - b.lo)};
    Pcg32 rng(41, 3);
    int covered = 0;
    for (int i = 0; i < 400; ++i) {
        const Ray r{random_point(rng, around), random_direction(rng)};
        std::vector<MajorantSegment<float>> segs;
        auto it = maj.iterate(r, 0.f, kInf, {});
        while (auto s = it.next()) segs.push_back(*s);
        for (const auto& s : segs)
            for (int k = 0; k < 8; ++k) {
                const float t = k == 0 ? s.t0 : s.t0 + (s.t1 - s.t0) * rng.uniform();
                CHECK(medium.coefficients(r.at(t), {}).sigma_t()[0] <= s.sigma_maj);  // exact
            }
        const Interval in = b.clip(r, 0.f, kInf);
        for (int k = 0; k < 50 && !in.empty(); ++k) {
            const float t = in.t0 + (in.t1 - in.t0) * rng.uniform();
            if (!(medium.density(r.at(t)) > 0.f)) continue;
            ++covered;
            bool inside = false;
            for (const auto& s : segs) inside = inside || (s.t0 <= t && t < s.t1);
            CHECK(inside);
        }
    }
    CHECK(covered > 100);
}

TEST_CASE("tree majorants over NanoVDB grids bound every lookup, dense cloud and sparse plume") {
    const NM cloud(cloud_grid(), grey<Mono>(2.f), grey<Mono>(18.f));
    check_bounds_along_rays(cloud, TreeMajorant<NM>(cloud), "cloud, adaptive");
    check_bounds_along_rays(cloud, TreeMajorant<NM>(cloud, cloud.tree_layout()), "cloud, on the nodes");
    check_bounds_along_rays(cloud, TreeMajorant<NM>(cloud, cloud.tree_layout(2)), "cloud, leaves split in 2");
    const NM plume(std::make_shared<const nsp::io::NanoDensityGrid>(nsp_examples::plume_nanovdb(128), "plume"),
                   grey<Mono>(20.f), grey<Mono>(180.f));
    check_bounds_along_rays(plume, TreeMajorant<NM>(plume), "plume, adaptive");
    check_bounds_along_rays(plume, TreeMajorant<NM>(plume, plume.tree_layout()), "plume, on the nodes");
    // The plume is sparse: it fills a small part of its box, and the tree leaves coarse cells empty.
    CHECK(double(plume.grid().active_voxels()) < 0.03 * 128.0 * 128.0 * 128.0);
    CHECK(TreeMajorant<NM>(plume).empty_cells() > 0);
}

TEST_CASE("NanoVDB grids bound their density from below: a GridControl and a TreeControl over them, and decomposition tracking") {
    // The lower bound is the dense grid's (the same voxels read, the same 2^-20 margin); every lookup
    // in a GridControl cell lies at or above its control; and uni + NEE MIS under the control (decomposition
    // and residual ratio tracking) agrees with the grid majorant's within 5 combined SE, with fewer
    // lookups per path.
    const auto cloud = nsp_examples::cloud_voxels();
    using DM = DenseGridMedium<Mono>;
    const DM dense = nsp::io::to_dense_medium<Mono>(cloud, grey<Mono>(2.f), grey<Mono>(18.f));
    const NM nano(cloud_grid(), grey<Mono>(2.f), grey<Mono>(18.f));
    static_assert(LowerBoundedMedium<NM>);
    Pcg32 rng(7, 2);
    int positive = 0, dense_positive = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 c = random_point(rng, Box{Vec3(-1.f), Vec3(1.f)});
        const float h = 0.005f + 0.05f * rng.uniform();  // a few voxels (the cloud's are 1/32)
        const Box region{c - Vec3(h), c + Vec3(h)};
        const float lo = nano.density_lower_bound(region), dense_lo = dense.density_lower_bound(region);
        CHECK(lo <= dense_lo * (1.f + 1e-6f));
        positive += lo > 0.f;
        dense_positive += dense_lo > 0.f;
        for (int k = 0; k < 8; ++k) {
            const Vec3 q = region.lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (region.hi - region.lo);
            CHECK(nano.density(q) >= lo);
        }
    }
    // Inside the cloud the two bounds are the same voxels' minimum: as many regions get a floor.
    MESSAGE("regions with a positive lower bound: NanoVDB " << positive << ", dense " << dense_positive << " of 2000");
    CHECK(positive > 100);
    CHECK(positive == dense_positive);
    const GridControl<NM> control(nano, 32);
    MESSAGE("controlled fraction of the NanoVDB cloud at 32^3: " << control.controlled_fraction());
    CHECK(control.controlled_fraction() > 0.1);
    const auto with = render_stats(nano, control, 3), without = render_stats(nano, GridMajorant<NM>(nano, 32), 4);
    const Stat &vc = with.first, &lc = with.second, &vg = without.first, &lg = without.second;
    CAPTURE(vc.mean);
    CAPTURE(vg.mean);
    CHECK(std::abs(vc.mean - vg.mean) <= kSigmas * std::hypot(vc.se(), vg.se()));
    CAPTURE(lc.mean);
    CAPTURE(lg.mean);
    CHECK(lc.mean < lg.mean);
    // The same under a TreeControl on the grid's own nodes (128 -> 32 -> 8 voxels) against the tree
    // majorant of that layout: the same image within 5 combined SE, with fewer lookups.
    const auto tree_with = render_stats(nano, TreeControl<NM>(nano, nano.tree_layout()), 5);
    const auto tree_without = render_stats(nano, TreeMajorant<NM>(nano, nano.tree_layout()), 6);
    const Stat &vt = tree_with.first, &lt = tree_with.second, &vm = tree_without.first, &lm = tree_without.second;
    CAPTURE(vt.mean);
    CAPTURE(vm.mean);
    CHECK(std::abs(vt.mean - vm.mean) <= kSigmas * std::hypot(vt.se(), vm.se()));
    CHECK(std::abs(vt.mean - vg.mean) <= kSigmas * std::hypot(vt.se(), vg.se()));
    CAPTURE(lt.mean);
    CAPTURE(lm.mean);
    CHECK(lt.mean < lm.mean);
}

TEST_CASE(".nvdb files round-trip the grid to the bit, and bad ones are rejected with their problem") {
    const std::string path = temp_path("cloud.nvdb");
    nsp::io::write_nvdb(path, nsp::io::to_nanovdb(nsp_examples::cloud_voxels()));
    const auto back = nsp::io::load_nvdb(path);
    const auto direct = cloud_grid();
    Pcg32 rng(9, 9);
    for (int i = 0; i < 20000; ++i) {
        const Vec3 p = random_point(rng, Box{Vec3(-1.f), Vec3(1.f)});
        REQUIRE(back->density(p) == direct->density(p));
    }
    CHECK(nsp::io::nvdb_grid_names(path) == std::vector<std::string>{"density"});

    CHECK_THROWS_WITH_AS(nsp::io::load_nvdb(temp_path("missing.nvdb")), Contains("no such file, or it cannot be read"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(nsp::io::load_nvdb(path, "smoke"),
                         Contains("has no grid named 'smoke'; its grids are 'density'"), InvalidArgument);
    const std::string junk = temp_path("junk.nvdb");
    write_bytes(junk, std::vector<char>(300, 'x'));
    CHECK_THROWS_WITH_AS(nsp::io::load_nvdb(junk), Contains("is not a NanoVDB file"), InvalidArgument);
    // Every truncation (at 60 points) and corrupted bytes: each is rejected or reads a valid grid,
    // and a truncated file is never accepted.
    const std::vector<char> bytes = read_bytes(path);
    const std::string cut = temp_path("cut.nvdb");
    for (int k = 0; k < 60; ++k) {
        const std::size_t n = bytes.size() * std::size_t(k) / 60;
        write_bytes(cut, std::vector<char>(bytes.begin(), bytes.begin() + std::ptrdiff_t(n)));
        CAPTURE(n);
        CHECK_THROWS_AS(nsp::io::load_nvdb(cut), InvalidArgument);
    }
    int rejected = 0;
    for (std::size_t at = 200; at < bytes.size(); at += bytes.size() / 50) {
        std::vector<char> bad = bytes;
        bad[at] = char(bad[at] ^ 0x5a);
        write_bytes(cut, bad);
        try {
            (void)nsp::io::load_nvdb(cut);
        } catch (const InvalidArgument&) {
            ++rejected;
        }
    }
    CHECK(rejected > 40);  // nsp writes full checksums: they catch a flipped byte almost anywhere
}

TEST_CASE("compressed .nvdb files (ZIP, Blosc) read back as the uncompressed file's grid, to the byte") {
    // Renderers and DCC tools write compressed .nvdb files by default; nsp::nanovdb compiles both of
    // NanoVDB's codecs in when zlib and c-blosc are found (the configure step says which are on).
    const nsp::io::NanoHandle handle = nsp::io::to_nanovdb(nsp_examples::cloud_voxels());
    const std::string plain = temp_path("cloud_none.nvdb");
    nsp::io::write_nvdb(plain, handle);
    const auto reference = nsp::io::load_nvdb(plain);
    const auto plain_size = std::filesystem::file_size(plain);
    for (const auto codec : {nanovdb::io::Codec::ZIP, nanovdb::io::Codec::BLOSC}) {
        const std::string name = nanovdb::io::toStr(codec);
        CAPTURE(name);
        const std::string path = temp_path("cloud_" + name + ".nvdb");
        if (!nsp::io::detail_nvdb::codec_compiled(codec)) {
            MESSAGE("NanoVDB's " << name << " codec is off in this build: only its message is checked");
            CHECK_THROWS_WITH_AS(nsp::io::write_nvdb(path, handle, codec), Contains("codec is not compiled into this build"),
                                 InvalidArgument);
            continue;
        }
        nsp::io::write_nvdb(path, handle, codec);
        CHECK(std::filesystem::file_size(path) < plain_size);  // compressed, not stored
        const auto back = nsp::io::load_nvdb(path);
        // The same buffer, byte for byte, so the same medium: checked at random points as well.
        REQUIRE(back->grid().gridSize() == reference->grid().gridSize());
        CHECK(std::memcmp(&back->grid(), &reference->grid(), reference->grid().gridSize()) == 0);
        CHECK(back->max_density() == reference->max_density());
        const NM a(back, grey<Mono>(2.f), grey<Mono>(18.f)), b(reference, grey<Mono>(2.f), grey<Mono>(18.f));
        Pcg32 rng(11, 4);
        for (int i = 0; i < 20000; ++i) {
            const Vec3 p = random_point(rng, Box{Vec3(-1.05f), Vec3(1.05f)});
            REQUIRE(a.coefficients(p, {}).sigma_t()[0] == b.coefficients(p, {}).sigma_t()[0]);
        }
        // Both grids of a file (the plume's density and temperature) through one compressed segment.
        const std::string two = temp_path("plume_" + name + ".nvdb");
        std::vector<nsp::io::NanoHandle> grids;
        grids.push_back(nsp_examples::plume_nanovdb(64));
        grids.push_back(nsp_examples::plume_nanovdb(64, true));
        nsp::io::write_nvdb(two, grids, codec);
        CHECK(nsp::io::nvdb_grid_names(two) == std::vector<std::string>{"density", "temperature"});
        CHECK(nsp::io::load_nvdb(two, "temperature")->max_density() > 2000.f);
        CHECK(nsp::io::load_nvdb(two, "density")->active_voxels() == grids[0].grid<float>()->activeVoxelCount());
    }
}

TEST_CASE("a temperature grid from a file: blackbody emission equals the dense grid's, and renders the same") {
    // The cloud's values x 2000 K as a NanoVDB temperature grid beside the same values as an
    // EmissionGrid: the same temperatures (within 1e-6, as the densities above), so the same
    // radiance in every mode; the plume's density and temperature written to one .nvdb file.
    const auto cloud = nsp_examples::cloud_voxels();
    const nsp::io::NanoScalarField nano_t(cloud_grid());
    const EmissionGrid dense_t(cloud.bounds, cloud.resolution, cloud.values);
    const BlackbodyEmission<Hero<4>, nsp::io::NanoScalarField> nano_h(nano_t, 2000.f);
    const BlackbodyEmission<Hero<4>> dense_h(dense_t, 2000.f);
    const BlackbodyEmission<Rgb, nsp::io::NanoScalarField> nano_rgb(nano_t, 2000.f, 1.f, true);
    const BlackbodyEmission<Rgb> dense_rgb(dense_t, 2000.f, 1.f, true);
    CHECK(nano_h.max_temperature() == doctest::Approx(dense_h.max_temperature()).epsilon(1e-6));
    Pcg32 rng(17, 2);
    for (int i = 0; i < 20000; ++i) {
        const Vec3 p = random_point(rng, Box{Vec3(-1.f), Vec3(1.f)});
        const auto l = HeroWavelengths<4>::sample(rng.uniform());
        CAPTURE(p.x);
        CHECK(std::abs(nano_h.temperature(p) - dense_h.temperature(p)) <= 2e-3f);  // 2000 K x 1e-6
        // B changes by c2 / (lambda T) dT / T relative: below 1e-4 for dT = 2e-3 K above 100 K.
        const auto a = nano_h.radiance(p, l), b = dense_h.radiance(p, l);
        for (int c = 0; c < 4; ++c) REQUIRE(std::abs(a[c] - b[c]) <= 1e-4f * b[c] + 1e-30f);
        const auto x = nano_rgb.radiance(p, {}), y = dense_rgb.radiance(p, {});
        for (int c = 0; c < 3; ++c) REQUIRE(std::abs(x[c] - y[c]) <= 1e-4f * y[c] + 1e-12f);
    }
    // The emitting media, NanoVDB against dense (Rgb): the same image mean within 5 combined SE.
    using NR = nsp::io::NanoVdbMedium<Rgb>;
    using DR = DenseGridMedium<Rgb>;
    const NR nano_m(cloud_grid(), grey<Rgb>(6.f), grey<Rgb>(4.f));
    const DR dense_m = nsp::io::to_dense_medium<Rgb>(cloud, grey<Rgb>(6.f), grey<Rgb>(4.f));
    const Emissive<NR, BlackbodyEmission<Rgb, nsp::io::NanoScalarField>> nano_e(nano_m, nano_rgb);
    const Emissive<DR, BlackbodyEmission<Rgb>> dense_e(dense_m, dense_rgb);
    auto stats = [](const auto& medium, std::uint64_t seed) {
        const auto scene = Scene(medium, GridMajorant<std::decay_t<decltype(medium)>>(medium, 16), IsotropicPhase{}, Lights<Rgb>{});
        const PathEstimator<strategy::NullScatteringMis, mis::Balance> est;
        Stat v;
        for (int p = 0; p < 256; ++p) {
            Pcg32 r(seed, std::uint64_t(p));
            const Ray ray{Vec3(-0.9f + 1.8f * (float(p % 16) + 0.5f) / 16.f, -0.9f + 1.8f * (float(p / 16) + 0.5f) / 16.f, -3.f),
                          Vec3(0.f, 0.f, 1.f)};
            LookupCount c;
            for (int k = 0; k < 40; ++k) v.add(est.radiance(scene, ray, {}, r, c).value[0]);
        }
        return v;
    };
    const Stat vn = stats(nano_e, 3), vd = stats(dense_e, 4);
    CAPTURE(vn.mean);
    CAPTURE(vd.mean);
    CHECK(vn.mean > 1e-3);
    CHECK(std::abs(vn.mean - vd.mean) <= kSigmas * std::hypot(vn.se(), vd.se()));

    const std::string path = temp_path("plume.nvdb");
    std::vector<nsp::io::NanoHandle> grids;
    grids.push_back(nsp_examples::plume_nanovdb(64));
    grids.push_back(nsp_examples::plume_nanovdb(64, true));
    nsp::io::write_nvdb(path, grids);
    CHECK(nsp::io::nvdb_grid_names(path) == std::vector<std::string>{"density", "temperature"});
    const auto density = nsp::io::load_nvdb(path), temperature = nsp::io::load_nvdb(path, "temperature");
    CHECK(temperature->max_density() <= 2600.f);
    CHECK(temperature->max_density() > 1000.f);
    CHECK(temperature->active_voxels() <= density->active_voxels());  // hot only where there is smoke
}

TEST_CASE("a damaged .nvdb is rejected before NanoVDB's reader or validator follows its damaged fields") {
    // NanoVDB's reader trusts a grid name's terminating 0 and a Blosc chunk's own header, and its
    // checksum and validator walk the node arrays the grid's header points to: nsp checks the file's
    // framing (detail_nvdb::check_file) and the grid's layout (detail_nvdb::checked_grid) first.
    // File layout: a 16-byte segment header (magic 0-7, version 8-11, grid count 12-13, codec 14-15),
    // 176 bytes of metadata (grid size 16-23, file size 24-31, ..., name size at 16 + 136), the name
    // ("density" and its 0: bytes 192-199), then the grid: GridData (672 bytes), TreeData, ...
    const nsp::io::NanoHandle handle = nsp::io::to_nanovdb(nsp_examples::cloud_voxels());
    const std::string plain = temp_path("frame_none.nvdb"), bad = temp_path("frame_bad.nvdb");
    nsp::io::write_nvdb(plain, handle);
    const std::vector<char> bytes = read_bytes(plain);
    auto rejects = [&](const std::vector<char>& b, const std::string& message) {
        write_bytes(bad, b);
        CAPTURE(message);
        CHECK_THROWS_WITH_AS(nsp::io::load_nvdb(bad), Contains(message.c_str()), InvalidArgument);
    };
    rejects(with(bytes, 14, std::uint16_t(7)), "the segment header at byte 0 has codec 7");
    rejects(with(bytes, 12, std::uint16_t(0)), "the segment header at byte 0 lists no grid");
    rejects(with(bytes, 199, 'x'), "the grid name at byte 192 does not end in a 0 byte");
    rejects(with(bytes, 16 + 136, std::uint32_t(1u << 31)), "a grid's name at byte 192 takes 2147483648 bytes");
    rejects(with(bytes, 24, std::uint64_t(bytes.size())), "run past the end of the file");
    rejects(with(bytes, 24, std::uint64_t(bytes.size() - 300)), "takes " + std::to_string(bytes.size() - 300) + " bytes, but its size is");
    // The grid's layout (GridData at byte 200, TreeData at 872: node offsets 872-903, counts 904-915).
    rejects(with(bytes, 200 + 24, std::uint32_t(5)), "its header says grid 5 of 1");
    rejects(with(bytes, 200 + 636, std::uint32_t(99)), "holds unknown (corrupted?) values");
    rejects(with(bytes, 200 + 20, std::uint32_t(0)), "its nodes are not laid out breadth-first");
    rejects(with(bytes, 872 + 24, std::uint64_t(1) << 40), "its root node (");
    rejects(with(bytes, 904, std::uint32_t(1u << 30)), "its leaf array");
    rejects(with(bytes, 904 + 4, std::uint32_t(1000)), "its lower node array");
    for (const auto codec : {nanovdb::io::Codec::ZIP, nanovdb::io::Codec::BLOSC}) {
        if (!nsp::io::detail_nvdb::codec_compiled(codec)) continue;
        const std::string name = nanovdb::io::toStr(codec), path = temp_path("frame_" + name + ".nvdb");
        CAPTURE(name);
        nsp::io::write_nvdb(path, handle, codec);
        const std::vector<char> packed = read_bytes(path);
        std::uint64_t length = 0;  // the first chunk's length
        std::memcpy(&length, packed.data() + 200, sizeof length);
        const bool zip = codec == nanovdb::io::Codec::ZIP;
        rejects(with(packed, 200, length + 1), zip ? "the ZIP chunk at byte 200 says" : "the Blosc chunk at byte 200 holds");
        rejects(with(packed, 24, std::uint64_t(packed.size() - 200 - 1)),
                zip ? "the ZIP chunk at byte 200 says" : "the Blosc chunk at byte 200 runs past its grid's bytes");
        if (codec == nanovdb::io::Codec::BLOSC) {
            // The Blosc buffer's own header, after the 8-byte length: its compressed size (bytes 12-15).
            rejects(with(packed, 208 + 12, std::uint32_t(length + 64)), "the Blosc chunk at byte 200 holds");
            rejects(with(packed, 208 + 4, std::uint32_t(1000)), "the Blosc chunk at byte 200 holds 1000 bytes");
        }
        // Every truncation is rejected by the framing check or the reader, and never read as a grid.
        for (int k = 1; k < 20; ++k) {
            write_bytes(bad, std::vector<char>(packed.begin(), packed.begin() + std::ptrdiff_t(packed.size() * std::size_t(k) / 20)));
            CHECK_THROWS_AS(nsp::io::load_nvdb(bad), InvalidArgument);
        }
    }
}

TEST_CASE("a NanoVDB grid whose child offsets or node origins are damaged is rejected before any lookup") {
    // A grid without a full checksum (other tools write partial ones, or none) is not verified by
    // its checksum: lookups follow child offsets, so NanoDensityGrid checks every one of them.
    auto damaged = [](auto&& edit) {
        nsp::io::NanoHandle h = nsp::io::to_nanovdb(nsp_examples::cloud_voxels());
        edit(*h.grid<float>());
        return nsp::io::NanoDensityGrid(std::move(h), "grid 'density' of 'x.nvdb'");
    };
    CHECK_NOTHROW(damaged([](nanovdb::FloatGrid&) {}));
    CHECK_THROWS_WITH_AS(damaged([](nanovdb::FloatGrid& g) {
                             auto* lower = g.tree().getFirstNode<1>()->data();
                             for (std::uint32_t n = 0; n < 4096; ++n)
                                 if (lower->mChildMask.isOn(n)) {
                                     lower->mTable[n].child += 4;
                                     break;
                                 }
                         }),
                         Contains("the lower internal node at index (0, 0, 0) has a child offset"), InvalidArgument);
    CHECK_THROWS_WITH_AS(damaged([](nanovdb::FloatGrid& g) {
                             auto* upper = g.tree().getFirstNode<2>()->data();
                             for (std::uint32_t n = 0; n < 32768; ++n)
                                 if (upper->mChildMask.isOn(n)) {
                                     upper->mTable[n].child = std::int64_t(1) << 40;
                                     break;
                                 }
                         }),
                         Contains("the upper internal node at index (0, 0, 0) has a child offset (1099511627776)"), InvalidArgument);
    CHECK_THROWS_WITH_AS(damaged([](nanovdb::FloatGrid& g) { g.tree().root().data()->tile(0)->child = -8; }),
                         Contains("the root tile at index (0, 0, 0) has a child offset (-8)"), InvalidArgument);
    CHECK_THROWS_WITH_AS(damaged([](nanovdb::FloatGrid& g) { g.tree().getFirstNode<0>()->data()->mBBoxMin[1] = 2000000000; }),
                         Contains("2000000000, 24) lies more than 2^30 voxels from the index origin"), InvalidArgument);
}

TEST_CASE("NanoVDB grids nsp cannot render are rejected, naming the problem") {
    auto build = [](float value, nanovdb::GridClass cls, float background = 0.f) {
        nanovdb::GridBuilder<float> b(background, cls);
        auto acc = b.getAccessor();
        acc.setValue(nanovdb::Coord(1, 2, 3), 1.f);
        acc.setValue(nanovdb::Coord(4, 2, 3), value);
        return b.getHandle<nanovdb::AbsDiff>(0.1, nanovdb::Vec3d(0.0), "density");
    };
    auto make = [](nsp::io::NanoHandle h) { return nsp::io::NanoDensityGrid(std::move(h), "grid 'density' of 'x.nvdb'"); };
    CHECK_THROWS_WITH_AS(make(build(-0.5f, nanovdb::GridClass::FogVolume)),
                         Contains("the value -0.5 of the voxel at index (4, 2, 3) is not allowed"), InvalidArgument);
    CHECK_THROWS_WITH_AS(make(build(std::nanf(""), nanovdb::GridClass::FogVolume)), Contains("nan of the voxel"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(make(build(1.f, nanovdb::GridClass::LevelSet)), Contains("is a level set"), InvalidArgument);
    CHECK_THROWS_WITH_AS(make(build(1.f, nanovdb::GridClass::FogVolume, 0.25f)),
                         Contains("has background value 0.25, which is not allowed"), InvalidArgument);
    nanovdb::GridBuilder<float> none(0.f, nanovdb::GridClass::FogVolume);
    CHECK_THROWS_WITH_AS(make(none.getHandle<nanovdb::AbsDiff>(0.1, nanovdb::Vec3d(0.0), "density")),
                         Contains("is empty: it has no active voxels"), InvalidArgument);
    nanovdb::GridBuilder<nanovdb::Vec3f> vec(nanovdb::Vec3f(0.f));
    vec.getAccessor().setValue(nanovdb::Coord(0), nanovdb::Vec3f(1.f));
    CHECK_THROWS_WITH_AS(make(vec.getHandle<nanovdb::AbsDiff>(0.1, nanovdb::Vec3d(0.0), "velocity")),
                         Contains("holds Vec3f values; nsp reads float density grids"), InvalidArgument);
    nanovdb::Map rotated;
    const double m[3][3] = {{0.0, -0.1, 0.0}, {0.1, 0.0, 0.0}, {0.0, 0.0, 0.1}}, inv[3][3] = {{0.0, 10.0, 0.0}, {-10.0, 0.0, 0.0}, {0.0, 0.0, 10.0}};
    const double t[3] = {0.0, 0.0, 0.0};
    rotated.set(m, inv, t, 1.0);
    nanovdb::GridBuilder<float> rb(0.f, nanovdb::GridClass::FogVolume);
    rb.getAccessor().setValue(nanovdb::Coord(0), 1.f);
    CHECK_THROWS_WITH_AS(make(rb.getHandle<nanovdb::AbsDiff>(rotated, "density")), Contains("is rotated or sheared"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(NM(nullptr, grey<Mono>(1.f), grey<Mono>(1.f)), Contains("the density grid is null"),
                         InvalidArgument);
}

#if NSP_HAVE_OPENVDB
TEST_CASE(".vdb files load through OpenVDB as the same grid; bad ones are rejected with their problem") {
    const std::string path = temp_path("cloud.vdb");
    nsp::io::write_vdb(path, {nsp_examples::voxels_vdb(nsp_examples::cloud_voxels())});
    const auto vdb = nsp::io::load_vdb(path);
    const auto direct = cloud_grid();
    Pcg32 rng(5, 5);
    for (int i = 0; i < 20000; ++i) {
        const Vec3 p = random_point(rng, Box{Vec3(-1.f), Vec3(1.f)});
        REQUIRE(vdb->density(p) == doctest::Approx(direct->density(p)).epsilon(1e-6));
    }
    openvdb::initialize();
    // Several grids: a level set, a vector grid and a negative one beside the density.
    auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(1.f, openvdb::Vec3f(0.f), 0.1f);
    sphere->setName("surface");
    auto negative = nsp_examples::empty_vdb_grid(0.1, openvdb::Vec3d(0.0));
    negative->setName("negative");
    negative->getAccessor().setValue(openvdb::Coord(2, 3, 4), -2.f);
    auto empty = nsp_examples::empty_vdb_grid(0.1, openvdb::Vec3d(0.0));
    empty->setName("empty");
    auto rotated = nsp_examples::empty_vdb_grid(0.1, openvdb::Vec3d(0.0));
    rotated->setName("rotated");
    rotated->getAccessor().setValue(openvdb::Coord(0), 1.f);
    rotated->transform().preRotate(0.3, openvdb::math::Y_AXIS);
    auto vel = openvdb::Vec3SGrid::create();
    vel->setName("vel");
    vel->getAccessor().setValue(openvdb::Coord(0), openvdb::Vec3s(1.f));
    const std::string many = temp_path("many.vdb");
    openvdb::io::File(many).write({nsp_examples::voxels_vdb(nsp_examples::cloud_voxels()), sphere, negative, empty, rotated, vel});
    CHECK(nsp::io::vdb_grids(many).size() == 6);
    CHECK_NOTHROW(nsp::io::load_vdb(many));
    CHECK_THROWS_WITH_AS(nsp::io::load_vdb(many, "smoke"),
                         Contains("has no grid named 'smoke'; its grids are 'density' (float, fog volume), 'empty' (float, fog "
                                  "volume), 'negative' (float, fog volume), 'rotated' (float, fog volume), 'surface' "
                                  "(float, level set), 'vel' (vec3s, unknown)"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(nsp::io::load_vdb(many, "surface"), Contains("is a level set"), InvalidArgument);
    CHECK_THROWS_WITH_AS(nsp::io::load_vdb(many, "vel"), Contains("holds vec3s values"), InvalidArgument);
    CHECK_THROWS_WITH_AS(nsp::io::load_vdb(many, "negative"),
                         Contains("the value -2 of the voxel at index (2, 3, 4) is not allowed"), InvalidArgument);
    CHECK_THROWS_WITH_AS(nsp::io::load_vdb(many, "empty"), Contains("is empty: it has no active voxels"), InvalidArgument);
    CHECK_THROWS_WITH_AS(nsp::io::load_vdb(many, "rotated"), Contains("is rotated or sheared"), InvalidArgument);
    CHECK_THROWS_WITH_AS(nsp::io::load_vdb(temp_path("missing.vdb")), Contains("no such file"), InvalidArgument);
    const std::string junk = temp_path("junk.vdb");
    write_bytes(junk, std::vector<char>(300, 'x'));
    CHECK_THROWS_WITH_AS(nsp::io::load_vdb(junk), Contains("is not an OpenVDB file nsp can read"), InvalidArgument);
    const std::vector<char> bytes = read_bytes(path);
    const std::string cut = temp_path("cut.vdb");
    for (const double f : {0.05, 0.3, 0.6, 0.9, 0.99}) {
        write_bytes(cut, std::vector<char>(bytes.begin(), bytes.begin() + std::ptrdiff_t(double(bytes.size()) * f)));
        CAPTURE(f);
        CHECK_THROWS_AS(nsp::io::load_vdb(cut), InvalidArgument);
    }
}

TEST_CASE("check_vdb_file rejects a damaged .vdb header or grid descriptor before OpenVDB reads it") {
    // OpenVDB's reader trusts its input (a flipped byte in a grid's topology can crash it:
    // docs/volumes.md); nsp checks what the format lets it check cheaply first. A small grid of
    // 16^3 voxels in two leaves' worth of nodes, written as io::File writes it.
    auto grid = nsp_examples::empty_vdb_grid(0.1, openvdb::Vec3d(0.0));
    grid->tree().fill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(15)), 0.5f, true);
    grid->tree().voxelizeActiveTiles();
    const std::string path = temp_path("small.vdb");
    nsp::io::write_vdb(path, {grid});
    const nsp::io::VdbLayout layout = nsp::io::check_vdb_file(path);
    REQUIRE(layout.grids.size() == 1);
    const auto& g = layout.grids[0];
    CHECK(g.name == "density");
    CHECK(g.type == "Tree_float_5_4_3");
    CHECK(layout.version == openvdb::OPENVDB_FILE_VERSION);
    CHECK(layout.has_offsets);
    CHECK(g.grid > g.descriptor);
    CHECK(g.blocks > g.grid);
    CHECK(g.end == layout.size);
    CHECK(nsp::io::load_vdb(path)->active_voxels() == 16 * 16 * 16);

    const std::vector<char> bytes = read_bytes(path);
    const std::string bad = temp_path("small_bad.vdb");
    auto rejects = [&](const std::vector<char>& b, const std::string& message) {
        write_bytes(bad, b);
        CAPTURE(message);
        CHECK_THROWS_WITH_AS(nsp::io::check_vdb_file(bad), Contains(message.c_str()), InvalidArgument);
        CHECK_THROWS_WITH_AS(nsp::io::load_vdb(bad), Contains(message.c_str()), InvalidArgument);
    };
    // The header: magic number (bytes 0-7), file version (8-11), library version (12-19), the
    // "has grid offsets" flag (20), the UUID as 36 characters (21-56), then the file's metadata.
    rejects(with(bytes, 0, std::int64_t(0x56444221)), "does not start with OpenVDB's magic number");
    rejects(with(bytes, 8, std::uint32_t(221)), "its file format version (byte 8) is 221; nsp reads versions 222");
    rejects(with(bytes, 8, std::uint32_t(224 + 0x100)), "its file format version (byte 8) is 480");
    rejects(with(bytes, 20, std::uint8_t(7)), "its 'has grid offsets' flag (byte 20) is 7, not 0 or 1");
    rejects(with(bytes, 21 + 8, 'x'), "its UUID (bytes 21 to 56) has the byte value 120 at byte 29");
    rejects(with(bytes, 57, std::uint32_t(1u << 30)), "the file's metadata at byte 57 claims 1073741824 entries");
    // The grid count (after the file's metadata, empty here: 4 bytes) and the descriptor: name,
    // type and instance parent as strings, then three offsets.
    rejects(with(bytes, 61, std::int32_t(-1)), "its grid count (byte 61) is -1");
    rejects(with(bytes, 61, std::int32_t(1000)), "its grid count (byte 61) is 1000, more than the file's");
    rejects(with(bytes, g.descriptor, std::uint32_t(1u << 31)), "grid descriptor 0 (byte 65)'s name (2147483648 bytes) at byte 69");
    const std::uint64_t offsets = g.grid - 24;
    rejects(with(bytes, offsets, std::int64_t(g.grid + 1)), "says its data starts at byte " + std::to_string(g.grid + 1));
    rejects(with(bytes, offsets + 8, std::int64_t(g.end + 1)), "says its leaf data starts at byte " + std::to_string(g.end + 1));
    rejects(with(bytes, offsets + 8, std::int64_t(g.grid)), "says its leaf data starts at byte " + std::to_string(g.grid));
    rejects(with(bytes, offsets + 16, std::int64_t(layout.size + 1)), "says it ends at byte " + std::to_string(layout.size + 1));
    // The grid's first part: compression flags, then its metadata, then the transform's type.
    rejects(with(bytes, g.grid, std::uint32_t(0x10)), "'s compression flags (byte " + std::to_string(g.grid) + ") are 16");
    rejects(with(bytes, g.grid + 4, std::uint32_t(1u << 28)), "'s metadata at byte " + std::to_string(g.grid + 4) + " claims");
    // A metadata entry whose value would run into the leaf data: its name's length made huge.
    rejects(with(bytes, g.grid + 8, std::uint32_t(g.blocks)), "would end past the grid's leaf data");
    const std::string map = "UniformScaleTranslateMap";
    const auto map_at = std::search(bytes.begin() + std::ptrdiff_t(g.grid), bytes.end(), map.begin(), map.end()) - bytes.begin();
    REQUIRE(std::uint64_t(map_at) < g.blocks);
    rejects(with(bytes, std::uint64_t(map_at), 'V'), "'s transform type (byte " + std::to_string(map_at) + ") is 'VniformScaleTranslateMap'");
    // Every truncation fails the check (the last grid then ends past the file), before OpenVDB.
    for (int k = 0; k < 40; ++k) {
        const std::size_t n = bytes.size() * std::size_t(k) / 40;
        write_bytes(bad, std::vector<char>(bytes.begin(), bytes.begin() + std::ptrdiff_t(n)));
        CAPTURE(n);
        CHECK_THROWS_AS(nsp::io::check_vdb_file(bad), InvalidArgument);
    }
    // Every byte of the header and the descriptor, each changed: rejected by nsp (by the check,
    // or, for the name, as a missing grid), by OpenVDB with an exception (an unknown grid type),
    // or read as the same grid (the library version and the UUID's letter case are not checked).
    int rejected_by_check = 0, read_back = 0;
    for (std::uint64_t at = 0; at < g.grid; ++at) {
        std::vector<char> b = bytes;
        b[at] = char(b[at] ^ 0x21);
        write_bytes(bad, b);
        CAPTURE(at);
        try {
            nsp::io::check_vdb_file(bad);
        } catch (const InvalidArgument&) {
            ++rejected_by_check;
            continue;
        }
        std::shared_ptr<const nsp::io::NanoDensityGrid> back;
        try {
            back = nsp::io::load_vdb(bad);
        } catch (const InvalidArgument&) {
            continue;
        }
        CHECK(back->active_voxels() == 16 * 16 * 16);
        CHECK(back->max_density() == 0.5f);
        ++read_back;
    }
    // Unchecked: the library version (8 bytes), the name and type (23: OpenVDB names them or nsp
    // finds no such grid), the UUID's hex letters (their changed case is still hex), the low
    // bytes of the leaf data and end offsets (not used to read a whole grid): about 45 of 124.
    CAPTURE(read_back);
    CHECK(rejected_by_check >= 70);
}

TEST_CASE("compressed .vdb files (zlib, Blosc) read back as the uncompressed file's grid") {
    // OpenVDB compresses inside libopenvdb (Debian's is built with Blosc and zlib: OPENVDB_USE_BLOSC
    // and OPENVDB_USE_ZLIB in openvdb/version.h); io::File writes Blosc by default.
    openvdb::initialize();
    const auto cloud = nsp_examples::voxels_vdb(nsp_examples::cloud_voxels());
    auto write = [&](const std::string& name, std::uint32_t compression) {
        const std::string path = temp_path(name);
        openvdb::io::File file(path);
        file.setCompression(compression);
        file.write({cloud});
        file.close();
        return path;
    };
    const std::string plain = write("cloud_none.vdb", openvdb::io::COMPRESS_NONE);
    const auto reference = nsp::io::load_vdb(plain);
    for (const auto& [name, compression] : {std::pair{"zip", openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK},
                                            std::pair{"blosc", openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK}}) {
        const std::string label = name;
        CAPTURE(label);
        const std::string path = write(std::string("cloud_") + name + ".vdb", std::uint32_t(compression));
        CHECK(std::filesystem::file_size(path) < std::filesystem::file_size(plain));
        const auto back = nsp::io::load_vdb(path);
        CHECK(back->active_voxels() == reference->active_voxels());
        CHECK(back->max_density() == reference->max_density());
        Pcg32 rng(13, 6);
        for (int i = 0; i < 20000; ++i) {
            const Vec3 p = random_point(rng, Box{Vec3(-1.05f), Vec3(1.05f)});
            REQUIRE(back->density(p) == reference->density(p));
        }
    }
}

TEST_CASE("tracking through OpenVDB's constant tiles matches the closed-form transmittance") {
    // Tiles of an OpenVDB grid (filled boxes become 8^3 and 128^3 tiles), voxel size 0.05:
    // density 1 over index [0, 255] x [0, 127] x [0, 127] (two 128^3 tiles), 3 over [64, 71] x
    // [8, 15] x [8, 15] (an 8^3 tile inside a leafless node) and 0.5 over [200, 215] x [0, 7] x
    // [0, 7]. Along +x at index (j, k) the density is linear between index points and 0 one
    // voxel beyond the last non-zero one, so tau = h mu sum_i v(i, j, k).
    const double h = 0.05;
    auto grid = nsp_examples::empty_vdb_grid(h, openvdb::Vec3d(0.0));
    grid->tree().fill(openvdb::CoordBBox(openvdb::Coord(0, 0, 0), openvdb::Coord(255, 127, 127)), 1.f, true);
    grid->tree().fill(openvdb::CoordBBox(openvdb::Coord(64, 8, 8), openvdb::Coord(71, 15, 15)), 3.f, true);
    grid->tree().fill(openvdb::CoordBBox(openvdb::Coord(200, 0, 0), openvdb::Coord(215, 7, 7)), 0.5f, true);
    CHECK(grid->tree().leafCount() == 0);  // all tiles
    const std::string path = temp_path("tiles.vdb");
    nsp::io::write_vdb(path, {grid});
    const auto g = nsp::io::load_vdb(path);
    const float mu = 0.5f;
    const NM medium(g, grey<Mono>(0.1f * mu), grey<Mono>(0.9f * mu));
    const auto acc = grid->getConstAccessor();
    Pcg32 rng(17, 2);
    for (const auto& jk : {std::pair{10, 12}, std::pair{3, 3}, std::pair{100, 50}}) {
        const int j = jk.first, k = jk.second;
        double sum = 0.0;
        for (int i = -2; i < 260; ++i) sum += acc.getValue(openvdb::Coord(i, j, k));
        const double want = std::exp(-h * double(mu) * sum);
        const Ray r{Vec3(-1.f, float(j * h), float(k * h)), Vec3(1.f, 0.f, 0.f)};
        for (const auto& maj : {TreeMajorant<NM>(medium), TreeMajorant<NM>(medium, medium.tree_layout())}) {
            Stat ratio, delta;
            LookupCount c;
            for (int n = 0; n < 20000; ++n) {
                ratio.add(transmittance_ratio(medium, maj, r, kInf, {}, rng, c).value[0]);
                delta.add(transmittance_delta(medium, maj, r, kInf, {}, rng, c).value[0]);
            }
            CAPTURE(j);
            CAPTURE(want);
            CHECK(std::abs(ratio.mean - want) <= kSigmas * ratio.se() + kRoundingFloor);
            CHECK(std::abs(delta.mean - want) <= kSigmas * delta.se() + kRoundingFloor);
        }
        CHECK(want < 0.9);
    }
}
#endif

}  // namespace
