// nsp/io/nanovdb_file.hpp: .nvdb files for the media of nanovdb.hpp: the framing checks that run
// before NanoVDB's own reader, loading a density grid by name, converting a VoxelGrid, writing
// grids with any codec this build has. Included by nanovdb.hpp; needs what it needs (NanoVDB's
// headers, and its codecs for compressed files).
#pragma once

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nanovdb/util/GridBuilder.h>
#include <nanovdb/util/IO.h>

#include "nanovdb.hpp"

namespace nsp::io {

namespace detail_nvdb {
inline void require_readable(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec) || !std::ifstream(path, std::ios::binary))
        nsp::detail::fail("cannot open '", path, "': no such file, or it cannot be read");
}

/// True when this build reads and writes .nvdb files compressed with `codec`.
constexpr bool codec_compiled(nanovdb::io::Codec codec) noexcept {
    switch (codec) {
    case nanovdb::io::Codec::NONE: return true;
#ifdef NANOVDB_USE_ZIP
    case nanovdb::io::Codec::ZIP: return true;
#endif
#ifdef NANOVDB_USE_BLOSC
    case nanovdb::io::Codec::BLOSC: return true;
#endif
    default: return false;
    }
}

/// Why this build cannot take `codec`, and what would make it (for messages).
inline std::string codec_missing(nanovdb::io::Codec codec) {
    const unsigned c = unsigned(codec);
    if (codec == nanovdb::io::Codec::ZIP)
        return "NanoVDB's ZIP codec is not compiled into this build: build with nsp::nanovdb (CMake), which "
               "defines NANOVDB_USE_ZIP and links zlib when it finds it (Debian: zlib1g-dev)";
    if (codec == nanovdb::io::Codec::BLOSC)
        return "NanoVDB's Blosc codec is not compiled into this build: build with nsp::nanovdb (CMake), which "
               "defines NANOVDB_USE_BLOSC and links c-blosc when it finds it (Debian: libblosc-dev)";
    return "codec " + std::to_string(c) + " is not one of NanoVDB's (0 none, 1 ZIP, 2 Blosc)";
}

/// Checks a .nvdb file's framing before NanoVDB's reader runs, from the layout io/IO.h documents:
/// segments of a 16-byte header (magic number, version, grid count, codec), per grid 176 bytes of
/// metadata and its name, then each grid's bytes. NanoVDB's reader trusts those fields: a name
/// without its terminating 0 is read past its end, and a Blosc chunk whose own header claims more
/// bytes than the file holds is decompressed from past its buffer. Checks the magic numbers, the
/// codec, each name (inside the file, ending in its 0), that the grids' bytes lie inside the file,
/// and each grid's compressed framing: uncompressed, its bytes are its size; ZIP, one chunk whose
/// length field matches; Blosc, chunks of at most 1 GiB whose lengths and Blosc headers (the
/// uncompressed and compressed sizes) agree with the grid's size and the file. Throws
/// InvalidArgument naming the file, the field and its byte offset.
inline void check_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    const std::uint64_t size = std::filesystem::file_size(path, ec);
    if (ec || !in) nsp::detail::fail("cannot open '", path, "': no such file, or it cannot be read");
    std::uint64_t at = 0;
    auto read = [&](void* out, std::uint64_t n, std::uint64_t limit, const char* what) {
        if (!inside(at, n, limit))
            nsp::detail::fail("'", path, "' is damaged or truncated: ", what, " at byte ", at, " takes ", n,
                              " bytes and would end past byte ", limit, " (the file has ", size, ")");
        in.seekg(std::streamoff(at));
        in.read(static_cast<char*>(out), std::streamsize(n));
        if (!in) nsp::detail::fail("'", path, "' cannot be read at byte ", at);
        at += n;
    };
    auto damaged = [&](const auto&... parts) { nsp::detail::fail("'", path, "' is damaged or truncated: ", parts...); };
    constexpr std::uint64_t kChunk = std::uint64_t(1) << 30;  // NanoVDB's Blosc chunk (io::Internal::MAX_SIZE)
    for (int segment = 0; size - at >= sizeof(nanovdb::io::Header); ++segment) {  // NanoVDB stops at fewer bytes, too
        const std::uint64_t header_at = at;
        nanovdb::io::Header h;
        read(&h, sizeof h, size, "a segment header");
        if (h.magic != NANOVDB_MAGIC_NUMBER) {
            if (segment == 0) nsp::detail::fail("'", path, "' is not a NanoVDB file nsp can read: it does not start with NanoVDB's magic number");
            damaged("the segment header at byte ", header_at, " has no NanoVDB magic number");
        }
        if (h.version.getMajor() != NANOVDB_MAJOR_VERSION_NUMBER)
            damaged("the segment header at byte ", header_at, " has NanoVDB version ", h.version.getMajor(), "; this build reads ",
                    NANOVDB_MAJOR_VERSION_NUMBER, " (convert the file with this NanoVDB's tools)");
        if (std::uint16_t(h.codec) > std::uint16_t(nanovdb::io::Codec::BLOSC))
            damaged("the segment header at byte ", header_at, " has codec ", std::uint16_t(h.codec), "; NanoVDB's are 0 (none), 1 (ZIP) and 2 (Blosc)");
        if (h.gridCount == 0) damaged("the segment header at byte ", header_at, " lists no grid");
        std::vector<nanovdb::io::MetaData> meta(h.gridCount);
        for (auto& m : meta) {
            const std::uint64_t meta_at = at;
            read(&m, sizeof m, size, "a grid's metadata");
            if (m.nameSize == 0) damaged("the grid metadata at byte ", meta_at, " has a name of 0 bytes (it ends in a 0 byte)");
            std::string name(m.nameSize, '\0');
            read(name.data(), m.nameSize, size, "a grid's name");
            if (name.back() != '\0') damaged("the grid name at byte ", at - m.nameSize, " does not end in a 0 byte");
        }
        for (const auto& m : meta) {
            const std::uint64_t grid_at = at, grid_end = at + m.fileSize;
            if (!inside(at, m.fileSize, size))
                damaged("a grid's ", m.fileSize, " bytes from byte ", at, " run past the end of the file (", size, " bytes)");
            if (h.codec == nanovdb::io::Codec::NONE && m.fileSize != m.gridSize)
                damaged("the uncompressed grid at byte ", grid_at, " takes ", m.fileSize, " bytes, but its size is ", m.gridSize);
            if (h.codec == nanovdb::io::Codec::ZIP) {
                std::uint64_t n = 0;
                read(&n, sizeof n, grid_end, "a ZIP chunk's length");
                if (n != m.fileSize - sizeof n)
                    damaged("the ZIP chunk at byte ", grid_at, " says it takes ", n, " bytes, the grid's ", m.fileSize - sizeof n);
            }
            if (h.codec == nanovdb::io::Codec::BLOSC) {
                std::uint64_t residual = m.gridSize;
                do {
                    const std::uint64_t chunk = std::min(residual, kChunk), chunk_at = at;
                    std::uint64_t n = 0;
                    read(&n, sizeof n, grid_end, "a Blosc chunk's length");
                    // A Blosc buffer's own header: version, format, flags, type size, then the
                    // uncompressed, block and compressed sizes (32-bit, little-endian).
                    unsigned char blosc[16];
                    if (n < sizeof blosc) damaged("the Blosc chunk at byte ", chunk_at, " says it takes ", n, " bytes, less than its header");
                    read(blosc, sizeof blosc, grid_end, "a Blosc chunk's header");
                    auto u32 = [&](int i) {
                        return std::uint32_t(blosc[i]) | std::uint32_t(blosc[i + 1]) << 8 | std::uint32_t(blosc[i + 2]) << 16 |
                               std::uint32_t(blosc[i + 3]) << 24;
                    };
                    if (u32(4) != chunk || u32(12) != n)
                        damaged("the Blosc chunk at byte ", chunk_at, " holds ", u32(4), " bytes compressed to ", u32(12),
                                "; the file says ", chunk, " compressed to ", n);
                    at += n - sizeof blosc;
                    if (at > grid_end) damaged("the Blosc chunk at byte ", chunk_at, " runs past its grid's bytes");
                    residual -= chunk;
                } while (residual > 0);
                if (at != grid_end)
                    damaged("the Blosc chunks of the grid at byte ", grid_at, " take ", at - grid_at, " bytes, the grid's ", m.fileSize);
            }
            at = grid_end;
        }
    }
}

/// "'a', 'b'" or "none".
inline std::string list_names(const std::vector<std::string>& names) {
    if (names.empty()) return "none";
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "'" : ", '") + n + "'";
    return s;
}
}  // namespace detail_nvdb

/// The names of the grids in a .nvdb file. Throws InvalidArgument if it cannot be read or is not
/// a NanoVDB file.
inline std::vector<std::string> nvdb_grid_names(const std::string& path) {
    detail_nvdb::require_readable(path);
    detail_nvdb::check_file(path);
    std::vector<std::string> names;
    try {
        for (const auto& m : nanovdb::io::readGridMetaData(path)) names.push_back(m.gridName);
    } catch (const std::exception& e) {
        nsp::detail::fail("'", path, "' is not a NanoVDB file nsp can read: ", e.what());
    }
    return names;
}

/// Loads the float fog volume `grid` from a .nvdb file, uncompressed or compressed with a codec
/// this build has (detail_nvdb::codec_compiled), and validates it: the file's framing before
/// NanoVDB reads it (detail_nvdb::check_file), the grid's layout before NanoVDB validates it
/// (its checksum too), then NanoDensityGrid's checks.
/// Throws InvalidArgument naming the file on a missing or unreadable file, one that is not
/// NanoVDB, no grid of that name (the message lists the grids there are), a codec this build
/// lacks (the message says which package adds it), a truncated or corrupted grid, or any check
/// of NanoDensityGrid.
inline std::shared_ptr<const NanoDensityGrid> load_nvdb(const std::string& path, const std::string& grid = "density") {
    detail_nvdb::require_readable(path);
    detail_nvdb::check_file(path);
    std::vector<nanovdb::io::GridMetaData> meta;
    try {
        meta = nanovdb::io::readGridMetaData(path);
    } catch (const std::exception& e) {
        nsp::detail::fail("'", path, "' is not a NanoVDB file nsp can read: ", e.what());
    }
    std::vector<std::string> names;
    const nanovdb::io::GridMetaData* info = nullptr;
    for (const auto& m : meta) {
        names.push_back(m.gridName);
        if (!info && m.gridName == grid) info = &m;
    }
    if (!info)
        nsp::detail::fail("'", path, "' has no grid named '", grid, "'; its grids are ", detail_nvdb::list_names(names));
    if (!detail_nvdb::codec_compiled(info->codec))
        nsp::detail::fail("cannot read grid '", grid, "' of '", path, "': it is stored compressed, and ",
                          detail_nvdb::codec_missing(info->codec));
    NanoHandle handle;
    try {
        handle = nanovdb::io::readGrid<nanovdb::HostBuffer>(path, grid);
    } catch (const std::exception& e) {
        nsp::detail::fail("cannot read grid '", grid, "' of '", path, "': ", e.what());
    }
    const std::string what = "grid '" + grid + "' of '" + path + "'";
    if (handle.empty()) nsp::detail::fail("cannot read ", what, ": the file ends before the grid does (truncated)");
    // The layout first: NanoVDB's validation follows the offsets in the grid's header.
    if (!nanovdb::isValid(*detail_nvdb::checked_grid(handle, what), true, false))
        nsp::detail::fail(what, " is corrupted or truncated: it fails NanoVDB's validation (checksum or layout)");
    return std::make_shared<const NanoDensityGrid>(std::move(handle), what);
}

/// Channel `channel` of a voxel grid (e.g. a .vol file's, nsp/io/vol.hpp) as a NanoVDB fog
/// volume named `name`: voxel (x, y, z) at index (x, y, z), its centre at world
/// bounds.lo + (x + 1/2, y + 1/2, z + 1/2) * voxel size, zeros left inactive (sparse). Inside the
/// box between the outer voxel centres the medium is the same as to_dense_medium's; beyond them
/// NanoVDB's lookup ramps down to 0 over one voxel where DenseGridMedium clamps to the face, so
/// the two agree everywhere when the outer voxel layer is 0. Throws InvalidArgument on a bad
/// channel or a grid whose values are all 0 (NanoVDB would have no active voxel).
inline NanoHandle to_nanovdb(const VoxelGrid& g, int channel = 0, const std::string& name = "density") {
    const std::vector<float> v = g.channel(channel);
    nanovdb::GridBuilder<float> builder(0.f, nanovdb::GridClass::FogVolume);
    builder.setChecksum(nanovdb::ChecksumMode::Full);  // load_nvdb then detects any corrupted byte
    auto acc = builder.getAccessor();
    std::size_t i = 0, active = 0;
    for (int z = 0; z < g.resolution[2]; ++z)
        for (int y = 0; y < g.resolution[1]; ++y)
            for (int x = 0; x < g.resolution[0]; ++x, ++i)
                if (v[i] != 0.f) {
                    acc.setValue(nanovdb::Coord(x, y, z), v[i]);
                    ++active;
                }
    if (active == 0) nsp::detail::fail("to_nanovdb: channel ", channel, " of the grid is 0 everywhere: a NanoVDB fog volume needs an active voxel");
    double mat[3][3] = {}, inv[3][3] = {}, t[3];
    for (int a = 0; a < 3; ++a) {
        const double h = (double(g.bounds.hi[a]) - double(g.bounds.lo[a])) / double(g.resolution[a]);
        mat[a][a] = h;
        inv[a][a] = 1.0 / h;
        t[a] = double(g.bounds.lo[a]) + 0.5 * h;
    }
    nanovdb::Map map;
    map.set(mat, inv, t, 1.0);
    return builder.getHandle<nanovdb::AbsDiff>(map, name);
}

/// Writes a NanoVDB grid as a .nvdb file, uncompressed or with `codec` (ZIP or BLOSC, if this
/// build has it: detail_nvdb::codec_compiled). Throws InvalidArgument if it cannot.
inline void write_nvdb(const std::string& path, const NanoHandle& handle,
                       nanovdb::io::Codec codec = nanovdb::io::Codec::NONE) {
    if (!detail_nvdb::codec_compiled(codec)) nsp::detail::fail("cannot write '", path, "': ", detail_nvdb::codec_missing(codec));
    try {
        nanovdb::io::writeGrid(path, handle, codec);
    } catch (const std::exception& e) {
        nsp::detail::fail("cannot write '", path, "': ", e.what());
    }
    if (!std::filesystem::exists(path)) nsp::detail::fail("cannot write '", path, "'");
}

/// Writes several NanoVDB grids (e.g. density and temperature) into one .nvdb file, uncompressed
/// or with `codec`.
inline void write_nvdb(const std::string& path, const std::vector<NanoHandle>& handles,
                       nanovdb::io::Codec codec = nanovdb::io::Codec::NONE) {
    if (!detail_nvdb::codec_compiled(codec)) nsp::detail::fail("cannot write '", path, "': ", detail_nvdb::codec_missing(codec));
    try {
        nanovdb::io::writeGrids<nanovdb::HostBuffer, std::vector>(path, handles, codec);
    } catch (const std::exception& e) {
        nsp::detail::fail("cannot write '", path, "': ", e.what());
    }
    if (!std::filesystem::exists(path)) nsp::detail::fail("cannot write '", path, "'");
}

}  // namespace nsp::io
