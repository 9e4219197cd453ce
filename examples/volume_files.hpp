// examples/volume_files.hpp: the default cloud and the procedural plume as volume files (.vol,
// .nvdb, .vdb), and any of those files loaded as a medium, for nsp_volume and the file tests.
// NanoVDB and OpenVDB are optional: NSP_HAVE_NANOVDB and NSP_HAVE_OPENVDB say what this build has
// (CMake defines them when it finds the packages); a format it lacks is rejected with a message
// that says which package to install.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <nsp/io/vol.hpp>

#include "default_scene.hpp"
#include "tool.hpp"
#include "volume_data.hpp"

#if NSP_HAVE_NANOVDB
#include <nsp/io/nanovdb.hpp>
#endif
#if NSP_HAVE_OPENVDB
#include <nsp/io/openvdb.hpp>
#endif

namespace nsp_examples {

/// The lower-cased extension of path, with its dot ("" if none).
inline std::string extension_of(const std::string& path) {
    const auto dot = path.find_last_of('.'), slash = path.find_last_of('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string e = path.substr(dot);
    for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

/// f(), with the library's nsp::InvalidArgument (a loader's or a constructor's message: a bad file
/// or a value the medium rejects) turned into a usage error.
template <class F>
auto usage_checked(F&& f) {
    try {
        return f();
    } catch (const nsp::InvalidArgument& e) {
        throw UsageError(e.what());
    }
}

/// Fails unless this build reads and writes files of extension `ext`.
inline void require_format(const std::string& path, const std::string& ext) {
    if (ext == ".vol") return;
    if (ext == ".nvdb") {
#if !NSP_HAVE_NANOVDB
        nsp::detail::fail("'", path, "': this build reads no .nvdb files: it was configured without NanoVDB "
                          "(Debian: apt-get install libnanovdb-dev, then configure again)");
#endif
        return;
    }
    if (ext == ".vdb") {
#if !NSP_HAVE_OPENVDB
        nsp::detail::fail("'", path, "': this build reads no .vdb files: it was configured without OpenVDB "
                          "(Debian: apt-get install libopenvdb-dev libboost-iostreams-dev libnanovdb-dev, then configure again)");
#endif
        return;
    }
    nsp::detail::fail("'", path, "' has the unknown format '", ext.empty() ? std::string("(no extension)") : ext,
                      "': nsp reads .vol (Mitsuba), .nvdb (NanoVDB) and .vdb (OpenVDB)");
}

/// The default cloud as a VoxelGrid: 64^3 over [-1, 1]^3.
inline nsp::io::VoxelGrid cloud_voxels() {
    nsp::io::VoxelGrid cloud;
    cloud.bounds = nsp::Box{nsp::Vec3(-1.f), nsp::Vec3(1.f)};
    cloud.resolution = {kGridRes, kGridRes, kGridRes};
    cloud.values = default_cloud_density();
    return cloud;
}

/// The plume as a dense VoxelGrid over [-1, 1]^3 (res^3 floats: for res <= 256 only).
inline nsp::io::VoxelGrid plume_voxels(int res) {
    if (res > 256) nsp::detail::fail("a .vol file is dense: the plume at ", res, "^3 would take ",
                                     double(res) * res * res * 4 / (1 << 20), " MiB; use a resolution <= 256 or .nvdb / .vdb");
    nsp::io::VoxelGrid g;
    g.bounds = nsp::Box{nsp::Vec3(-1.f), nsp::Vec3(1.f)};
    g.resolution = {res, res, res};
    g.values.assign(std::size_t(res) * std::size_t(res) * std::size_t(res), 0.f);
    for_each_plume_voxel(res, [&](int i, int j, int k, float v) {
        g.values[std::size_t(i) + std::size_t(res) * (std::size_t(j) + std::size_t(res) * std::size_t(k))] = v;
    });
    return g;
}

#if NSP_HAVE_NANOVDB
/// The plume as a NanoVDB fog volume named "density" (the index-to-world map of to_nanovdb over
/// [-1, 1]^3), or with `temperature` its temperature grid in kelvin, named "temperature".
inline nsp::io::NanoHandle plume_nanovdb(int res, bool temperature = false) {
    nanovdb::GridBuilder<float> builder(0.f, nanovdb::GridClass::FogVolume);
    builder.setChecksum(nanovdb::ChecksumMode::Full);
    auto acc = builder.getAccessor();
    for_each_plume_voxel(res, [&](int i, int j, int k, float v) {
        const float x = temperature ? plume_temperature(j, res, v) : v;
        if (x > 0.f) acc.setValue(nanovdb::Coord(i, j, k), x);
    });
    const double h = plume_voxel_size(res);
    return builder.getHandle<nanovdb::AbsDiff>(h, nanovdb::Vec3d(-1.0 + 0.5 * h), temperature ? "temperature" : "density");
}
#endif

#if NSP_HAVE_OPENVDB
/// An OpenVDB fog volume named "density" with voxel size h and voxel (0, 0, 0) centred at `origin`.
inline openvdb::FloatGrid::Ptr empty_vdb_grid(double h, const openvdb::Vec3d& origin) {
    openvdb::initialize();
    auto grid = openvdb::FloatGrid::create(0.f);
    grid->setName("density");
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    auto xform = openvdb::math::Transform::createLinearTransform(h);
    xform->postTranslate(origin);
    grid->setTransform(xform);
    return grid;
}

/// A VoxelGrid with cubic voxels as an OpenVDB fog volume (zeros left inactive), the map of to_nanovdb.
inline openvdb::FloatGrid::Ptr voxels_vdb(const nsp::io::VoxelGrid& g) {
    const double h = (double(g.bounds.hi.x) - double(g.bounds.lo.x)) / g.resolution[0];
    auto grid = empty_vdb_grid(h, openvdb::Vec3d(g.bounds.lo.x + 0.5 * h, g.bounds.lo.y + 0.5 * h, g.bounds.lo.z + 0.5 * h));
    auto acc = grid->getAccessor();
    std::size_t n = 0;
    for (int z = 0; z < g.resolution[2]; ++z)
        for (int y = 0; y < g.resolution[1]; ++y)
            for (int x = 0; x < g.resolution[0]; ++x, ++n)
                if (g.values[n] != 0.f) acc.setValue(openvdb::Coord(x, y, z), g.values[n]);
    return grid;
}

/// The plume as an OpenVDB fog volume named "density", or with `temperature` its temperature
/// grid in kelvin, named "temperature".
inline openvdb::FloatGrid::Ptr plume_vdb(int res, bool temperature = false) {
    const double h = plume_voxel_size(res);
    auto grid = empty_vdb_grid(h, openvdb::Vec3d(-1.0 + 0.5 * h));
    if (temperature) grid->setName("temperature");
    auto acc = grid->getAccessor();
    for_each_plume_voxel(res, [&](int i, int j, int k, float v) {
        const float x = temperature ? plume_temperature(j, res, v) : v;
        if (x > 0.f) acc.setValue(openvdb::Coord(i, j, k), x);
    });
    return grid;
}
#endif

/// Writes `voxels` (a VoxelGrid maker) to `path` in the format its extension names.
template <class MakeVoxels>
void write_volume(const std::string& path, MakeVoxels&& voxels, int plume_res, bool plume) {
    const std::string ext = extension_of(path);
    require_format(path, ext);
    if (ext == ".vol") return nsp::io::write_vol(path, voxels());
#if NSP_HAVE_NANOVDB
    if (ext == ".nvdb") {
        std::vector<nsp::io::NanoHandle> grids;
        grids.push_back(plume ? plume_nanovdb(plume_res) : nsp::io::to_nanovdb(voxels()));
        if (plume) grids.push_back(plume_nanovdb(plume_res, true));
        return nsp::io::write_nvdb(path, grids);
    }
#endif
#if NSP_HAVE_OPENVDB
    if (ext == ".vdb") {
        if (plume) return nsp::io::write_vdb(path, {plume_vdb(plume_res), plume_vdb(plume_res, true)});
        return nsp::io::write_vdb(path, {voxels_vdb(voxels())});
    }
#endif
    (void)plume_res, (void)plume;
}

/// nsp_volume's lights and camera around medium `m` (bench_volume times the same): a dim white sky and a small sphere light
/// above (radius 0.15 half-diagonals, 2.2 away: every strategy reaches it); 40 degrees vertical
/// field of view from 2.2 half-diagonals in front of the centre, a little above it.
template <class M>
struct VolumeFraming {
    using S = typename M::Spectral;
    explicit VolumeFraming(const M& m) {
        const nsp::Box b = m.bounds();
        centre = 0.5f * (b.lo + b.hi);
        radius = 0.5f * glm::length(b.hi - b.lo);
        lights.set(nsp::EnvironmentLight<S>{nsp::constant_coefficient<S>(0.1f)});
        lights.set(nsp::SphereLight<S>{centre + radius * nsp::Vec3(0.6f, 2.f, -0.8f), 0.15f * radius,
                                       nsp::constant_coefficient<S>(250.f)});
        eye = centre + radius * nsp::Vec3(0.f, 0.6f, -2.1f);
        f = glm::normalize(centre - eye);
        r = glm::normalize(glm::cross(f, nsp::Vec3(0.f, 1.f, 0.f)));  // right-handed, as nsp::PinholeCamera
        up = glm::cross(r, f);
    }
    nsp::Ray operator()(float u, float v) const {
        return nsp::Ray{eye, glm::normalize(f + (2.f * u - 1.f) * tan_half * r + (2.f * v - 1.f) * tan_half * up)};
    }
    nsp::Vec3 centre, eye, f, r, up;
    float radius = 1.f, tan_half = std::tan(0.5f * 40.f * nsp::kPi / 180.f);
    nsp::Lights<S> lights;
};

}  // namespace nsp_examples
