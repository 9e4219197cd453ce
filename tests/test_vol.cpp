// tests/test_vol.cpp: Mitsuba's .vol grids (nsp/io/vol.hpp): the byte layout read against a file
// assembled by hand, write / read round trips, the default cloud exported and read back into the
// same medium (bit-identical estimates with the same seeds), every bad-file case with its message,
// and every truncation and many corruptions of a valid file rejected with InvalidArgument, never
// a crash or another exception.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <nsp/io/vol.hpp>

#include "common.hpp"
#include "default_scene.hpp"

namespace {

using namespace nsp_test;
using nsp::io::VoxelGrid;

/// Little-endian bytes of a 32-bit value, appended.
void put(std::vector<std::byte>& b, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) b.push_back(std::byte((v >> (8 * k)) & 0xffu));
}
void put_f(std::vector<std::byte>& b, float x) {
    std::uint32_t u;
    std::memcpy(&u, &x, 4);
    put(b, u);
}

/// A .vol file assembled field by field: resolution (nx, ny, nz), `channels`, box [lo, hi], values.
std::vector<std::byte> vol_file(std::array<int, 3> res, int channels, Vec3 lo, Vec3 hi, const std::vector<float>& values,
                                int version = 3, int encoding = 1) {
    std::vector<std::byte> b{std::byte('V'), std::byte('O'), std::byte('L'), std::byte(version)};
    put(b, std::uint32_t(encoding));
    for (const int r : res) put(b, std::uint32_t(r));
    put(b, std::uint32_t(channels));
    for (int a = 0; a < 3; ++a) put_f(b, lo[a]);
    for (int a = 0; a < 3; ++a) put_f(b, hi[a]);
    for (const float v : values) put_f(b, v);
    return b;
}

std::vector<float> ramp(std::size_t n) {
    std::vector<float> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = 0.25f * float(i);
    return v;
}

/// Whether parsing `bytes` throws InvalidArgument with a message containing `part`.
bool rejects(const std::vector<std::byte>& bytes, const std::string& part) {
    try {
        (void)nsp::io::parse_vol(bytes, "test.vol");
    } catch (const InvalidArgument& e) {
        const std::string msg = e.what();
        if (msg.find(part) == std::string::npos) {
            MESSAGE("message without '" << part << "': " << msg);
            return false;
        }
        return msg.find("test.vol") != std::string::npos;
    }
    return false;
}

TEST_CASE("vol: the layout, read against a file assembled by hand") {
    // 3 x 2 x 2 voxels, 2 channels: value (x, y, z, c) = 100 c + x + 10 y + 5 z at
    // ((z ny + y) nx + x) channels + c.
    const std::array<int, 3> res{3, 2, 2};
    std::vector<float> values;
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 3; ++x)
                for (int c = 0; c < 2; ++c) values.push_back(float(100 * c + x + 10 * y + 5 * z));
    const VoxelGrid g = nsp::io::parse_vol(vol_file(res, 2, Vec3(-1.f, 0.f, 2.f), Vec3(1.f, 0.5f, 3.f), values), "hand.vol");
    CHECK(g.resolution == res);
    CHECK(g.channels == 2);
    CHECK(g.bounds.lo == Vec3(-1.f, 0.f, 2.f));
    CHECK(g.bounds.hi == Vec3(1.f, 0.5f, 3.f));
    const std::vector<float> c1 = g.channel(1);
    // DenseGridMedium's order: x + nx (y + ny z).
    CHECK(c1[std::size_t(2 + 3 * (1 + 2 * 1))] == 100.f + 2.f + 10.f + 5.f);
    CHECK(g.channel(0)[1] == 1.f);
    CHECK_THROWS_AS((void)g.channel(2), InvalidArgument);
    // The writer produces the same bytes.
    CHECK(nsp::io::vol_bytes(g) == vol_file(res, 2, Vec3(-1.f, 0.f, 2.f), Vec3(1.f, 0.5f, 3.f), values));
}

TEST_CASE("vol: the default cloud written and read back is the same medium, to the bit") {
    using nsp_examples::kGridRes;
    VoxelGrid g;
    g.bounds = Box{Vec3(-1.f), Vec3(1.f)};
    g.resolution = {kGridRes, kGridRes, kGridRes};
    g.values = nsp_examples::default_cloud_density();
    const auto path = (std::filesystem::temp_directory_path() / "nsp_test_cloud.vol").string();
    nsp::io::write_vol(path, g);
    const VoxelGrid r = nsp::io::load_vol(path);
    std::filesystem::remove(path);
    REQUIRE(r.values == g.values);
    CHECK(r.resolution == g.resolution);
    // The medium from the file against the one from the same values: the same estimates from the
    // same random numbers (exactly equal, not within k standard errors: the same medium).
    const auto file_medium = nsp::io::to_dense_medium<Mono>(r, Mono::Spectrum::Constant(2.f), Mono::Spectrum::Constant(18.f));
    const DenseGridMedium<Mono> direct(g.bounds, g.resolution, g.values, Mono::Spectrum::Constant(2.f),
                                       Mono::Spectrum::Constant(18.f));
    Lights<Mono> lights;
    lights.set(EnvironmentLight<Mono>{Mono::Spectrum::Ones()});
    const auto a = Scene(file_medium, GlobalMajorant<DenseGridMedium<Mono>>(file_medium), HenyeyGreensteinPhase(0.5f), lights);
    const auto b = Scene(direct, GlobalMajorant<DenseGridMedium<Mono>>(direct), HenyeyGreensteinPhase(0.5f), lights);
    const PathEstimator<strategy::NullScatteringMis, mis::Balance> est;
    Pcg32 ra(3, 1), rb(3, 1);
    LookupCount ca, cb;
    double sa = 0.0, sb = 0.0;
    for (int i = 0; i < 2000; ++i) {
        const Ray ray{Vec3(0.f, 0.f, -3.f), uniform_sphere(ra.uniform(), ra.uniform())};
        (void)rb.uniform(), (void)rb.uniform();
        sa += est.radiance(a, ray, {}, ra, ca).value[0];
        sb += est.radiance(b, ray, {}, rb, cb).value[0];
    }
    CHECK(sa == sb);
    CHECK(ca.n == cb.n);
    CHECK(sa > 0.0);
}

TEST_CASE("vol: every bad file is rejected with a message naming it and what is wrong") {
    const std::array<int, 3> res{2, 2, 2};
    const Vec3 lo(0.f), hi(1.f);
    const std::vector<float> good = ramp(8);
    CHECK_NOTHROW((void)nsp::io::parse_vol(vol_file(res, 1, lo, hi, good), "test.vol"));
    CHECK(rejects({}, "does not start with the bytes 'VOL'"));
    CHECK(rejects({std::byte('P'), std::byte('N'), std::byte('G'), std::byte(3)}, "not a Mitsuba .vol file"));
    CHECK(rejects(vol_file(res, 1, lo, hi, good, 2), "version 2 is not supported"));
    CHECK(rejects(vol_file(res, 1, lo, hi, good, 3, 3), "encoding 3 is not supported"));
    CHECK(rejects(vol_file(res, 1, lo, hi, good, 3, 2), "encoding 2 is not supported"));
    CHECK(rejects(vol_file({2, 0, 2}, 1, lo, hi, {}), "resolution[1] = 0"));
    CHECK(rejects(vol_file({-4, 2, 2}, 1, lo, hi, {}), "resolution[0] = -4"));
    CHECK(rejects(vol_file(res, 0, lo, hi, {}), "0 channels"));
    CHECK(rejects(vol_file(res, 1, Vec3(0.f, 1.f, 0.f), Vec3(1.f, 1.f, 1.f), good), "bounding box on axis 1"));
    CHECK(rejects(vol_file(res, 1, lo, Vec3(1.f, 1.f, std::numeric_limits<float>::infinity()), good), "axis 2"));
    CHECK(rejects(vol_file(res, 1, Vec3(std::numeric_limits<float>::quiet_NaN()), hi, good), "axis 0"));
    std::vector<std::byte> header_only = vol_file(res, 1, lo, hi, {});
    header_only.resize(20);
    CHECK(rejects(header_only, "its header needs 48 bytes, the file has 20"));
    CHECK(rejects(vol_file(res, 1, lo, hi, ramp(7)), "needs 80 bytes, the file has 76"));
    CHECK(rejects(vol_file(res, 1, lo, hi, ramp(9)), "4 bytes more"));
    CHECK(rejects(vol_file({1 << 30, 1 << 30, 1 << 30}, 1 << 30, lo, hi, {}), "more values than memory can address"));
    std::vector<float> negative = good;
    negative[std::size_t(1 + 2 * (0 + 2 * 1))] = -0.5f;  // voxel (1, 0, 1)
    CHECK(rejects(vol_file(res, 1, lo, hi, negative), "the value -0.5 of voxel (1, 0, 1) channel 0"));
    std::vector<float> nan = good;
    nan[6] = std::numeric_limits<float>::quiet_NaN();  // voxel (0, 1, 1)
    CHECK(rejects(vol_file(res, 1, lo, hi, nan), "of voxel (0, 1, 1)"));
    std::vector<float> inf = ramp(16);
    inf[3] = std::numeric_limits<float>::infinity();  // voxel 1, channel 1
    CHECK(rejects(vol_file(res, 2, lo, hi, inf), "of voxel (1, 0, 0) channel 1"));
    // A grid of zeros is a valid, empty medium.
    CHECK_NOTHROW((void)nsp::io::parse_vol(vol_file(res, 1, lo, hi, std::vector<float>(8, 0.f)), "test.vol"));
    // A file that is not there.
    const std::string missing = (std::filesystem::temp_directory_path() / "nsp_test_no_such_file.vol").string();
    std::filesystem::remove(missing);
    CHECK_THROWS_WITH_AS((void)nsp::io::load_vol(missing), doctest::Contains("cannot open"), InvalidArgument);
}

TEST_CASE("vol: every truncation and many corruptions of a valid file are rejected cleanly") {
    // The parser's corpus: each prefix of a valid 3 x 2 x 2, 2-channel file, and the file with one
    // byte replaced (every byte of the header with three values, and spread over the data): each
    // parses or throws InvalidArgument; nothing else (a crash, another exception) may happen.
    std::vector<float> values = ramp(24);
    const std::vector<std::byte> good = vol_file({3, 2, 2}, 2, Vec3(-1.f), Vec3(1.f), values);
    int rejected = 0, parsed = 0;
    auto attempt = [&](const std::vector<std::byte>& b) {
        try {
            const VoxelGrid g = nsp::io::parse_vol(b, "corrupt.vol");
            CHECK(g.values.size() == g.voxels() * std::size_t(g.channels));
            ++parsed;
        } catch (const InvalidArgument&) {
            ++rejected;
        }
    };
    for (std::size_t n = 0; n < good.size(); ++n) attempt(std::vector<std::byte>(good.begin(), good.begin() + std::ptrdiff_t(n)));
    CHECK(rejected == int(good.size()));  // every proper prefix is truncated
    for (std::size_t i = 0; i < good.size(); i += (i < 48 ? 1 : 7))
        for (const unsigned v : {0x00u, 0x7fu, 0xffu}) {
            std::vector<std::byte> b = good;
            b[i] = std::byte(v);
            attempt(b);
        }
    CHECK(parsed > 0);
    CHECK(rejected > int(good.size()));
}

}  // namespace
