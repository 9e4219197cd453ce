// nsp/io/openvdb.hpp: .vdb files through OpenVDB, converted to NanoVDB density grids.
//
// Optional: needs OpenVDB (Debian: libopenvdb-dev and libboost-iostreams-dev, linked as CMake's
// nsp::openvdb target, which the project defines when it finds them) and NanoVDB's headers.
// `nsp/nsp.hpp` does not include it. A grid read here becomes a NanoDensityGrid (nsp/io/nanovdb.hpp),
// checked as every NanoVDB grid is, so a .vdb and the .nvdb converted from it give the same medium.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <openvdb/openvdb.h>
#include <nanovdb/util/OpenToNanoVDB.h>

#include "nanovdb.hpp"

namespace nsp::io {

/// A grid of a .vdb file: its name, value type ("float", "vec3s", ...) and class.
struct VdbGridInfo {
    std::string name, type, grid_class;
};

namespace detail_vdb {
/// Opens `path` as a VDB file, or throws InvalidArgument naming it.
inline void open(openvdb::io::File& file, const std::string& path) {
    detail_nvdb::require_readable(path);
    openvdb::initialize();
    try {
        file.open(false);  // no delayed loading: a truncated file fails here or in readGrid
    } catch (const std::exception& e) {
        nsp::detail::fail("'", path, "' is not an OpenVDB file nsp can read: ", e.what());
    }
}
}  // namespace detail_vdb

/// The grids of a .vdb file. Throws InvalidArgument if it cannot be read or is not OpenVDB.
inline std::vector<VdbGridInfo> vdb_grids(const std::string& path) {
    openvdb::io::File file(path);
    detail_vdb::open(file, path);
    std::vector<VdbGridInfo> grids;
    try {
        const openvdb::GridPtrVecPtr meta = file.readAllGridMetadata();
        for (const auto& g : *meta)
            grids.push_back({g->getName(), g->valueType(), openvdb::GridBase::gridClassToString(g->getGridClass())});
    } catch (const std::exception& e) {
        nsp::detail::fail("cannot read the grid list of '", path, "': ", e.what());
    }
    file.close();
    return grids;
}

/// Loads the float fog volume `grid` from a .vdb file as a NanoVDB density grid. Throws
/// InvalidArgument naming the file on a missing or unreadable file, one that is not OpenVDB, no
/// grid of that name (the message lists the grids there are, with their types), a grid that is
/// not float or is a level set, a truncated file, or any check of NanoDensityGrid (negative or
/// non-finite values, an empty grid, a rotated transform).
inline std::shared_ptr<const NanoDensityGrid> load_vdb(const std::string& path, const std::string& grid = "density") {
    const std::vector<VdbGridInfo> grids = vdb_grids(path);
    const VdbGridInfo* info = nullptr;
    for (const auto& g : grids)
        if (g.name == grid) info = &g;
    if (!info) {
        std::string list;
        for (const auto& g : grids) list += (list.empty() ? "'" : ", '") + g.name + "' (" + g.type + ", " + g.grid_class + ")";
        nsp::detail::fail("'", path, "' has no grid named '", grid, "'; its grids are ", list.empty() ? "none" : list);
    }
    const std::string what = "grid '" + grid + "' of '" + path + "'";
    if (info->type != "float")
        nsp::detail::fail(what, " holds ", info->type, " values; nsp reads float density grids (fog volumes)");
    if (info->grid_class == openvdb::GridBase::gridClassToString(openvdb::GRID_LEVEL_SET))
        nsp::detail::fail(what, " is a level set (a signed distance field), not a fog volume; convert it to a fog "
                          "volume (openvdb::tools::sdfToFogVolume) first");
    openvdb::io::File file(path);
    detail_vdb::open(file, path);
    openvdb::FloatGrid::Ptr g;
    try {
        g = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(grid));
    } catch (const std::exception& e) {
        nsp::detail::fail("cannot read ", what, " (truncated or corrupted?): ", e.what());
    }
    file.close();
    if (!g) nsp::detail::fail("cannot read ", what, " as a float grid");
    if (g->activeVoxelCount() == 0) nsp::detail::fail(what, " is empty: it has no active voxels");
    NanoHandle handle;
    try {
        handle = nanovdb::openToNanoVDB<nanovdb::HostBuffer>(*g);
    } catch (const std::exception& e) {
        nsp::detail::fail("cannot convert ", what, " to NanoVDB: ", e.what());
    }
    return std::make_shared<const NanoDensityGrid>(std::move(handle), what);
}

/// Writes float grids to a .vdb file. Throws InvalidArgument if it cannot.
inline void write_vdb(const std::string& path, const std::vector<openvdb::FloatGrid::Ptr>& grids) {
    openvdb::initialize();
    openvdb::GridPtrVec out(grids.begin(), grids.end());
    try {
        openvdb::io::File file(path);
        file.write(out);
        file.close();
    } catch (const std::exception& e) {
        nsp::detail::fail("cannot write '", path, "': ", e.what());
    }
}

}  // namespace nsp::io
