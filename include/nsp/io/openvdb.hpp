// nsp/io/openvdb.hpp: .vdb files through OpenVDB, converted to NanoVDB density grids.
//
// Optional: needs OpenVDB (Debian: libopenvdb-dev and libboost-iostreams-dev, linked as CMake's
// nsp::openvdb target, which the project defines when it finds them) and NanoVDB's headers.
// `nsp/nsp.hpp` does not include it. A grid read here becomes a NanoDensityGrid (nsp/io/nanovdb.hpp),
// checked as every NanoVDB grid is, so a .vdb and the .nvdb converted from it give the same medium.
//
// OpenVDB's reader trusts its input: a damaged .vdb can crash the process inside libopenvdb
// (docs/volumes.md has the numbers). Before handing a file to it, check_vdb_file checks what can be
// checked cheaply from the format without reading the grids: the header (magic number, file
// version, flags, UUID), the file's metadata, and each grid descriptor's offsets against the file's
// size and against each other, with the grid's compression flags, metadata and transform type.
// Damage inside a grid's topology or leaf buffers passes those checks, and a .vdb has no checksum.
// `.nvdb` files (a checksum over the whole grid) are the hardened path: convert once with
// NanoVDB's nanovdb_convert, or nanovdb::openToNanoVDB and write_nvdb.
#pragma once

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
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

/// A .vdb file's layout as its header and grid descriptors state it: what check_vdb_file checked.
struct VdbLayout {
    /// One grid descriptor: the grid's names and where its parts lie in the file (byte offsets).
    struct Grid {
        std::string name;             ///< unique name (OpenVDB appends "\x1e" and a number to repeated names)
        std::string type;             ///< e.g. "Tree_float_5_4_3", with "_HalfFloat" when stored as half
        std::string instance_parent;  ///< the grid whose tree this one shares, or empty
        std::uint64_t descriptor = 0; ///< where the descriptor starts
        std::uint64_t grid = 0;       ///< compression flags, metadata, transform, topology
        std::uint64_t blocks = 0;     ///< leaf buffers (0 for an instance, which has none)
        std::uint64_t end = 0;        ///< one past the grid's last byte
    };
    std::uint64_t size = 0;      ///< bytes in the file
    std::uint32_t version = 0;   ///< the file format version (OpenVDB 2.0 to 10 write 222 to 224)
    bool has_offsets = true;     ///< false: a stream without grid offsets, grids not listed here
    std::vector<Grid> grids;
};

namespace detail_vdb {

/// Little-endian reads of a file's bytes, each within a limit (the end of the file or of the part
/// being read): a field that would cross it fails, naming the field and where it lies.
class BoundedReader {
public:
    explicit BoundedReader(const std::string& path) : path_(path), in_(path, std::ios::binary) {
        std::error_code ec;
        size_ = std::filesystem::file_size(path, ec);
        if (ec || !in_) nsp::detail::fail("cannot open '", path, "': no such file, or it cannot be read");
    }
    std::uint64_t size() const noexcept { return size_; }
    std::uint64_t pos() const noexcept { return pos_; }
    void seek(std::uint64_t p) {
        pos_ = p;
        in_.clear();
        in_.seekg(std::streamoff(p));
    }
    /// Fails unless `n` bytes of field `what` from here end by byte `limit` (`part` names that end).
    void require(std::uint64_t n, const std::string& what, std::uint64_t limit, const char* part) const {
        if (n > limit || pos_ > limit - n)
            damaged(what, " at byte ", pos_, " takes ", n, " bytes and would end past ", part, " (byte ", limit, ")");
    }
    /// Reads `n` bytes of field `what`, which must end by byte `limit`.
    void read(void* out, std::uint64_t n, const std::string& what, std::uint64_t limit, const char* part) {
        require(n, what, limit, part);
        in_.read(static_cast<char*>(out), std::streamsize(n));
        if (!in_) damaged(what, " at byte ", pos_, " cannot be read");
        pos_ += n;
    }
    template <class T>
    T value(const std::string& what, std::uint64_t limit, const char* part) {
        T v{};
        read(&v, sizeof(T), what, limit, part);
        return v;
    }
    /// OpenVDB's string: a 32-bit length, then that many bytes.
    std::string string(const std::string& what, std::uint64_t limit, const char* part) {
        const auto n = value<std::uint32_t>(what + "'s length", limit, part);
        require(n, what + " (" + std::to_string(n) + " bytes)", limit, part);
        std::string s(n, '\0');
        read(s.data(), n, what, limit, part);
        return s;
    }
    void skip(std::uint64_t n, const std::string& what, std::uint64_t limit, const char* part) {
        require(n, what, limit, part);
        seek(pos_ + n);
    }
    template <class... A>
    [[noreturn]] void damaged(const A&... a) const {
        nsp::detail::fail("'", path_, "' is damaged or truncated: ", a...);
    }

private:
    std::string path_;
    std::ifstream in_;
    std::uint64_t size_ = 0, pos_ = 0;
};

/// Skips a metadata map (a count, then per entry a name, a type name, a 32-bit size and that many
/// bytes: the size OpenVDB writes is the value's), which must end by `limit`.
inline void skip_metadata(BoundedReader& r, const std::string& what, std::uint64_t limit, const char* part) {
    const std::uint64_t at = r.pos();
    const auto count = r.value<std::uint32_t>(what + "'s entry count", limit, part);
    if (count > (limit - r.pos()) / 12)  // an entry takes at least 12 bytes
        r.damaged(what, " at byte ", at, " claims ", count, " entries, more than fit before ", part, " (byte ", limit, ")");
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::string name = r.string(what + " entry " + std::to_string(i) + "'s name", limit, part);
        const std::string type = r.string(what + " '" + name + "''s type name", limit, part);
        const auto bytes = r.value<std::uint32_t>(what + " '" + name + "''s size", limit, part);
        r.skip(bytes, what + " '" + name + "' (" + type + ")", limit, part);
    }
}

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

/// The grids of a .vdb file as OpenVDB lists them, without check_vdb_file.
inline std::vector<VdbGridInfo> read_grid_list(const std::string& path) {
    openvdb::io::File file(path);
    open(file, path);
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

/// load_vdb without check_vdb_file: what OpenVDB's reader makes of the file, then nsp's grid checks.
inline std::shared_ptr<const NanoDensityGrid> read_grid(const std::string& path, const std::string& grid) {
    const std::vector<VdbGridInfo> grids = read_grid_list(path);
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
    open(file, path);
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

}  // namespace detail_vdb

/// Checks a .vdb file's layout before OpenVDB reads it, from the format as OpenVDB writes it
/// (io::Archive): the magic number; a file version from 222 (OpenVDB 2.0) to 255; the "has grid
/// offsets" flag (0 or 1); the UUID (36 hex digits and dashes); the file's metadata entries within
/// the file; a grid count that fits; per grid descriptor, its strings within the file, its data
/// starting right after it (where a streaming reader finds it), its leaf buffers inside its bytes,
/// its end within the file (a truncated file fails here), then its compression flags (OpenVDB's
/// three bits), metadata within its first part and a transform type OpenVDB knows. Returns the
/// layout. Throws InvalidArgument naming the file, the field and its byte offset. What it cannot
/// see: damage inside a grid's transform values, topology or leaf buffers (OpenVDB's reader trusts
/// those; see the header comment).
inline VdbLayout check_vdb_file(const std::string& path) {
    detail_nvdb::require_readable(path);
    openvdb::initialize();  // the map registry, for the transform types
    detail_vdb::BoundedReader r(path);
    VdbLayout layout;
    layout.size = r.size();
    const std::uint64_t end = r.size();
    const char* eof = "the end of the file";
    if (end < 8 || r.value<std::int64_t>("magic number", end, eof) != std::int64_t(openvdb::OPENVDB_MAGIC))
        nsp::detail::fail("'", path, "' is not an OpenVDB file nsp can read: it does not start with OpenVDB's magic number");
    layout.version = r.value<std::uint32_t>("the file format version", end, eof);
    if (layout.version < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION || layout.version > 255)
        r.damaged("its file format version (byte 8) is ", layout.version, "; nsp reads versions 222 (OpenVDB 2.0) to 255 "
                  "(OpenVDB ", int(openvdb::OPENVDB_LIBRARY_MAJOR_VERSION), " writes ", openvdb::OPENVDB_FILE_VERSION,
                  "): a file older than OpenVDB 2.0 can be saved again with a current OpenVDB");
    r.skip(8, "the library version", end, eof);
    const auto offsets = r.value<std::uint8_t>("the 'has grid offsets' flag", end, eof);
    if (offsets > 1) r.damaged("its 'has grid offsets' flag (byte 20) is ", int(offsets), ", not 0 or 1");
    layout.has_offsets = offsets == 1;
    char uuid[36];
    r.read(uuid, sizeof uuid, "the UUID", end, eof);
    for (int i = 0; i < 36; ++i) {
        const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
        if (dash ? uuid[i] != '-' : !std::isxdigit(static_cast<unsigned char>(uuid[i])))
            r.damaged("its UUID (bytes 21 to 56) has the byte value ", int(static_cast<unsigned char>(uuid[i])), " at byte ",
                      21 + i, "; it is 36 hex digits with dashes after the 8th, 12th, 16th and 20th");
    }
    detail_vdb::skip_metadata(r, "the file's metadata", end, eof);
    if (!layout.has_offsets) return layout;  // a stream: grids follow one another, no descriptor says where
    const std::uint64_t count_at = r.pos();
    const auto count = r.value<std::int32_t>("the grid count", end, eof);
    if (count < 0 || std::uint64_t(count) > (end - r.pos()) / 36)  // a descriptor takes at least 36 bytes
        r.damaged("its grid count (byte ", count_at, ") is ", count, ", more than the file's ", end - r.pos(),
                  " remaining bytes can describe");
    for (std::int32_t i = 0; i < count; ++i) {
        VdbLayout::Grid g;
        g.descriptor = r.pos();
        const std::string which = "grid descriptor " + std::to_string(i) + " (byte " + std::to_string(g.descriptor) + ")";
        g.name = r.string(which + "'s name", end, eof);
        const std::string grid = "grid '" + g.name.substr(0, g.name.find('\x1e')) + "' (descriptor at byte " +
                                 std::to_string(g.descriptor) + ")";
        g.type = r.string(grid + "'s type", end, eof);
        g.instance_parent = r.string(grid + "'s instance parent", end, eof);
        const auto positions_at = r.pos();
        const auto grid_pos = r.value<std::int64_t>(grid + "'s data offset", end, eof);
        const auto block_pos = r.value<std::int64_t>(grid + "'s leaf data offset", end, eof);
        const auto end_pos = r.value<std::int64_t>(grid + "'s end offset", end, eof);
        if (grid_pos != std::int64_t(r.pos()))
            r.damaged(grid, " says its data starts at byte ", grid_pos, " (field at byte ", positions_at, "); it starts "
                      "right after the descriptor, at byte ", r.pos(), ", where a streaming reader finds it");
        if (end_pos < grid_pos || std::uint64_t(end_pos) > end)
            r.damaged(grid, " says it ends at byte ", end_pos, " (field at byte ", positions_at + 16, "), outside its data "
                      "(from byte ", grid_pos, ") and the file (", end, " bytes): the file is truncated, or the field damaged");
        const bool instance = !g.instance_parent.empty();
        if (instance ? block_pos != 0 && (block_pos < grid_pos || block_pos > end_pos)
                     : block_pos <= grid_pos || block_pos > end_pos)
            r.damaged(grid, " says its leaf data starts at byte ", block_pos, " (field at byte ", positions_at + 8,
                      "), outside its own bytes ", grid_pos, " to ", end_pos);
        g.grid = std::uint64_t(grid_pos);
        g.blocks = std::uint64_t(block_pos);
        g.end = std::uint64_t(end_pos);
        // The grid's first part: compression flags, metadata and the transform's type, which end
        // before its topology and leaf buffers (an instance has neither: before its end).
        const std::uint64_t part_end = instance ? g.end : g.blocks;
        const char* part = "the grid's leaf data";
        const auto flags = r.value<std::uint32_t>(grid + "'s compression flags", part_end, part);
        if (flags & ~std::uint32_t(openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK | openvdb::io::COMPRESS_BLOSC))
            r.damaged(grid, "'s compression flags (byte ", g.grid, ") are ", flags, "; OpenVDB's are 1 (zip), 2 (active "
                      "mask) and 4 (blosc)");
        detail_vdb::skip_metadata(r, grid + "'s metadata", part_end, part);
        const std::string map = r.string(grid + "'s transform type", part_end, part);
        if (!openvdb::math::MapRegistry::isRegistered(map))
            r.damaged(grid, "'s transform type (byte ", r.pos() - map.size(), ") is '", map, "', not one OpenVDB knows");
        layout.grids.push_back(std::move(g));
        r.seek(std::uint64_t(end_pos));
    }
    return layout;
}

/// The grids of a .vdb file. Throws InvalidArgument if it cannot be read, is not OpenVDB, or fails
/// check_vdb_file.
inline std::vector<VdbGridInfo> vdb_grids(const std::string& path) {
    check_vdb_file(path);
    return detail_vdb::read_grid_list(path);
}

/// Loads the float fog volume `grid` from a .vdb file as a NanoVDB density grid. Throws
/// InvalidArgument naming the file on a missing or unreadable file, one that is not OpenVDB, one
/// that fails check_vdb_file, no grid of that name (the message lists the grids there are, with
/// their types), a grid that is not float or is a level set, a truncated file, or any check of
/// NanoDensityGrid (negative or non-finite values, an empty grid, a rotated transform). A file
/// damaged inside a grid's topology or leaf buffers can still crash inside OpenVDB's reader.
inline std::shared_ptr<const NanoDensityGrid> load_vdb(const std::string& path, const std::string& grid = "density") {
    check_vdb_file(path);
    return detail_vdb::read_grid(path, grid);
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
