// A host renderer reading volume files through nsp's readers as a consumer links them:
// nsp::nanovdb (nsp/io/nanovdb.hpp) and, where OpenVDB is found, nsp::openvdb (nsp/io/openvdb.hpp).
// One small grid (a ball of density 1 - r^2, 12^3 voxels over [-1, 1]^3) is written as a .vol, as
// a .nvdb uncompressed and with every codec the package compiled in, and as a .vdb; each is read
// back and its medium must give the grid's value at every voxel centre.
// CMakeLists.txt passes what the package should provide (CONSUMER_EXPECT_*): a definition the
// target did not bring fails the build. Exits non-zero if a file does not read back.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nsp/io/nanovdb.hpp>
#include <nsp/io/vol.hpp>
#if CONSUMER_EXPECT_OPENVDB
#include <nsp/io/openvdb.hpp>
#endif

#if !NSP_HAVE_NANOVDB
#error "nsp::nanovdb should define NSP_HAVE_NANOVDB=1"
#endif
#if CONSUMER_EXPECT_OPENVDB && !NSP_HAVE_OPENVDB
#error "nsp::openvdb should define NSP_HAVE_OPENVDB=1"
#endif
#if CONSUMER_EXPECT_ZIP && !defined(NANOVDB_USE_ZIP)
#error "nsp::nanovdb should define NANOVDB_USE_ZIP (zlib was found when nsp was built)"
#endif
#if CONSUMER_EXPECT_BLOSC && !defined(NANOVDB_USE_BLOSC)
#error "nsp::nanovdb should define NANOVDB_USE_BLOSC (c-blosc was found when nsp was built)"
#endif

namespace {

constexpr int kRes = 12;

/// The centre of voxel (x, y, z).
nsp::Vec3 centre(int x, int y, int z) {
    const float h = 2.f / kRes;
    return nsp::Vec3(-1.f + (float(x) + 0.5f) * h, -1.f + (float(y) + 0.5f) * h, -1.f + (float(z) + 0.5f) * h);
}

/// The ball: density 0.8 - r^2 where positive.
nsp::io::VoxelGrid ball() {
    nsp::io::VoxelGrid g;
    g.bounds = nsp::Box{nsp::Vec3(-1.f), nsp::Vec3(1.f)};
    g.resolution = {kRes, kRes, kRes};
    g.values.resize(g.voxels());
    std::size_t n = 0;
    for (int z = 0; z < kRes; ++z)
        for (int y = 0; y < kRes; ++y)
            for (int x = 0; x < kRes; ++x, ++n) {
                const nsp::Vec3 c = centre(x, y, z);
                g.values[n] = std::max(0.f, 0.8f - glm::dot(c, c));  // 0 on the outer layer
            }
    return g;
}

/// Compares density(p) at every voxel centre with the grid's value; prints and counts mismatches.
template <class Density>
int compare(const char* what, const nsp::io::VoxelGrid& g, Density&& density) {
    int bad = 0;
    std::size_t n = 0;
    for (int z = 0; z < kRes; ++z)
        for (int y = 0; y < kRes; ++y)
            for (int x = 0; x < kRes; ++x, ++n) {
                const float d = density(centre(x, y, z));
                if (!(std::abs(d - g.values[n]) <= 1e-5f)) {
                    if (bad++ == 0) std::printf("consumer_volumes: %s: voxel (%d, %d, %d) reads %g, not %g\n", what, x, y, z, d, g.values[n]);
                }
            }
    std::printf("consumer_volumes: %s: %s\n", what, bad == 0 ? "ok" : "FAILED");
    return bad == 0 ? 0 : 1;
}

}  // namespace

int main() {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / "nsp_consumer_volumes";
    fs::create_directories(dir);
    const nsp::io::VoxelGrid g = ball();
    int failures = 0;
    try {
        const std::string vol = (dir / "ball.vol").string();
        nsp::io::write_vol(vol, g);
        const auto dense = nsp::io::to_dense_medium<nsp::Mono>(nsp::io::load_vol(vol), nsp::Mono::Coefficient::Constant(0.1f),
                                                               nsp::Mono::Coefficient::Constant(0.9f));
        failures += compare(".vol", g, [&](const nsp::Vec3& p) { return dense.density(p); });

        using Codec = nanovdb::io::Codec;
        std::vector<Codec> codecs{Codec::NONE};
#ifdef NANOVDB_USE_ZIP
        codecs.push_back(Codec::ZIP);
#endif
#ifdef NANOVDB_USE_BLOSC
        codecs.push_back(Codec::BLOSC);
#endif
        for (const Codec codec : codecs) {
            const std::string name = std::string(".nvdb (") + nanovdb::io::toStr(codec) + ")";
            const std::string path = (dir / (std::string("ball_") + nanovdb::io::toStr(codec) + ".nvdb")).string();
            nsp::io::write_nvdb(path, nsp::io::to_nanovdb(g), codec);
            const nsp::io::NanoVdbMedium<nsp::Mono> medium(nsp::io::load_nvdb(path), nsp::Mono::Coefficient::Constant(0.1f),
                                                           nsp::Mono::Coefficient::Constant(0.9f));
            failures += compare(name.c_str(), g, [&](const nsp::Vec3& p) { return medium.density(p); });
        }
#if CONSUMER_EXPECT_OPENVDB
        openvdb::initialize();
        auto grid = openvdb::FloatGrid::create(0.f);
        grid->setName("density");
        grid->setGridClass(openvdb::GRID_FOG_VOLUME);
        const double h = 2.0 / kRes;
        auto xform = openvdb::math::Transform::createLinearTransform(h);
        xform->postTranslate(openvdb::Vec3d(-1.0 + 0.5 * h));
        grid->setTransform(xform);
        auto acc = grid->getAccessor();
        std::size_t n = 0;
        for (int z = 0; z < kRes; ++z)
            for (int y = 0; y < kRes; ++y)
                for (int x = 0; x < kRes; ++x, ++n)
                    if (g.values[n] != 0.f) acc.setValue(openvdb::Coord(x, y, z), g.values[n]);
        const std::string vdb = (dir / "ball.vdb").string();
        nsp::io::write_vdb(vdb, {grid});
        const auto from_vdb = nsp::io::load_vdb(vdb);
        failures += compare(".vdb", g, [&](const nsp::Vec3& p) { return from_vdb->density(p); });
#endif
    } catch (const nsp::InvalidArgument& e) {
        std::printf("consumer_volumes: FAILED: %s\n", e.what());
        return 1;
    }
    return failures == 0 ? 0 : 1;
}
