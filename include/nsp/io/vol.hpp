// nsp/io/vol.hpp: Mitsuba's binary grid volume (.vol), the simple exchange format of research
// code, read and written without any dependency. The layout (little-endian):
//
//     bytes 0-2   'V' 'O' 'L'
//     byte  3     version: 3
//     int32       encoding: 1 = float32 (the only one nsp reads; 2 = float16 and 3 = uint8 exist)
//     int32 x 3   resolution x, y, z (each >= 1)
//     int32       channels (>= 1)
//     float32 x 6 bounding box: x, y, z minimum, then x, y, z maximum
//     float32     x * y * z * channels values, value (x, y, z, c) at ((z * ny + y) * nx + x) * channels + c
//
// nsp reads the values as voxel centres over the box, trilinear between them and clamped at the
// faces (the convention of DenseGridMedium and of Mitsuba 3's grid volumes), so a .vol density
// becomes a DenseGridMedium with `to_dense_medium`. Every bad file is rejected with an
// nsp::InvalidArgument whose message names the file and what is wrong: missing, not a .vol,
// another version or encoding, a bad resolution, channel count or box, truncated or longer than
// its header says, or a value that is negative or not finite (with its voxel). A grid of zeros is
// a valid, empty medium. Loaders run once, outside kernels.
#pragma once

#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "../core/error.hpp"
#include "../media/grid.hpp"

namespace nsp::io {

/// A dense grid of voxel values over a box: what a .vol file holds.
struct VoxelGrid {
    Box bounds;
    std::array<int, 3> resolution{1, 1, 1};
    int channels = 1;
    std::vector<float> values;  ///< value (x, y, z, c) at ((z * ny + y) * nx + x) * channels + c

    std::size_t voxels() const noexcept {
        return std::size_t(resolution[0]) * std::size_t(resolution[1]) * std::size_t(resolution[2]);
    }
    /// Channel c of every voxel, in DenseGridMedium's order (x + nx (y + ny z)).
    std::vector<float> channel(int c) const {
        if (c < 0 || c >= channels)
            detail::fail("VoxelGrid channel ", c, " is not allowed: the grid has ", channels, " channel(s)");
        std::vector<float> out(voxels());
        for (std::size_t i = 0; i < out.size(); ++i) out[i] = values[i * std::size_t(channels) + std::size_t(c)];
        return out;
    }
};

namespace detail_vol {

inline std::uint32_t read_u32(const std::byte* p) noexcept {
    return std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) | (std::uint32_t(p[2]) << 16) | (std::uint32_t(p[3]) << 24);
}
inline std::int32_t read_i32(const std::byte* p) noexcept { return std::bit_cast<std::int32_t>(read_u32(p)); }
inline float read_f32(const std::byte* p) noexcept { return std::bit_cast<float>(read_u32(p)); }
inline void put_u32(std::vector<std::byte>& out, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) out.push_back(std::byte((v >> (8 * k)) & 0xffu));
}

inline constexpr std::size_t kHeaderBytes = 48;  // magic 3 + version 1 + 5 int32 + 6 float32

}  // namespace detail_vol

/// Parses the bytes of a .vol file; `name` (the file's path) goes into every message. Throws
/// nsp::InvalidArgument on anything but a version-3 float32 grid of finite values >= 0 over a
/// finite box of positive extent.
inline VoxelGrid parse_vol(std::span<const std::byte> bytes, std::string_view name) {
    using detail::fail;
    using namespace detail_vol;
    if (bytes.size() < 4 || bytes[0] != std::byte('V') || bytes[1] != std::byte('O') || bytes[2] != std::byte('L'))
        fail("'", name, "' is not a Mitsuba .vol file: it does not start with the bytes 'VOL'");
    if (const int version = int(bytes[3]); version != 3)
        fail("'", name, "': .vol version ", version, " is not supported: nsp reads version 3");
    if (bytes.size() < kHeaderBytes)
        fail("'", name, "' is truncated: its header needs ", kHeaderBytes, " bytes, the file has ", bytes.size());
    const std::byte* p = bytes.data() + 4;
    if (const std::int32_t encoding = read_i32(p); encoding != 1)
        fail("'", name, "': .vol encoding ", encoding, " is not supported: nsp reads 1 (float32); 2 (float16) and 3 "
             "(uint8) are not read");
    VoxelGrid g;
    for (int a = 0; a < 3; ++a) {
        const std::int32_t r = read_i32(p + 4 + 4 * a);
        if (r < 1) fail("'", name, "': resolution[", a, "] = ", r, " is not allowed: every axis needs at least 1 voxel");
        g.resolution[std::size_t(a)] = r;
    }
    g.channels = read_i32(p + 16);
    if (g.channels < 1) fail("'", name, "': ", g.channels, " channels is not allowed: a grid needs at least 1");
    for (int a = 0; a < 3; ++a) {
        g.bounds.lo[a] = read_f32(p + 20 + 4 * a);
        g.bounds.hi[a] = read_f32(p + 32 + 4 * a);
        if (!std::isfinite(g.bounds.lo[a]) || !std::isfinite(g.bounds.hi[a]) || !(g.bounds.hi[a] > g.bounds.lo[a]))
            fail("'", name, "': the bounding box on axis ", a, " is [", g.bounds.lo[a], ", ", g.bounds.hi[a],
                 "], which is not allowed: it must be finite with maximum > minimum");
    }
    // x * y * z * channels values of 4 bytes, counted without overflow.
    const std::size_t cap = (std::numeric_limits<std::size_t>::max() - kHeaderBytes) / 4;
    std::size_t count = std::size_t(g.channels);
    for (int a = 0; a < 3; ++a) {
        if (count > cap / std::size_t(g.resolution[std::size_t(a)]))
            fail("'", name, "': resolution ", g.resolution[0], "x", g.resolution[1], "x", g.resolution[2], " x ",
                 g.channels, " channels has more values than memory can address");
        count *= std::size_t(g.resolution[std::size_t(a)]);
    }
    const std::size_t need = kHeaderBytes + 4 * count;
    if (bytes.size() < need)
        fail("'", name, "' is truncated: resolution ", g.resolution[0], "x", g.resolution[1], "x", g.resolution[2],
             " with ", g.channels, " channel(s) needs ", need, " bytes, the file has ", bytes.size());
    if (bytes.size() > need)
        fail("'", name, "' has ", bytes.size() - need, " bytes more than resolution ", g.resolution[0], "x",
             g.resolution[1], "x", g.resolution[2], " with ", g.channels, " channel(s) needs (", need,
             "): not a float32 grid of that size");
    g.values.resize(count);
    const std::byte* v = bytes.data() + kHeaderBytes;
    for (std::size_t i = 0; i < count; ++i) {
        const float x = read_f32(v + 4 * i);
        if (!std::isfinite(x) || x < 0.f) {
            const std::size_t voxel = i / std::size_t(g.channels), nx = std::size_t(g.resolution[0]),
                              ny = std::size_t(g.resolution[1]);
            fail("'", name, "': the value ", x, " of voxel (", voxel % nx, ", ", (voxel / nx) % ny, ", ",
                 voxel / (nx * ny), ") channel ", i % std::size_t(g.channels),
                 " is not allowed: values must be finite and >= 0");
        }
        g.values[i] = x;
    }
    return g;
}

/// Reads and parses the .vol file at `path` (see parse_vol). Throws nsp::InvalidArgument naming
/// the path when the file cannot be opened or read.
inline VoxelGrid load_vol(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) detail::fail("cannot open '", path, "': no such file, or it cannot be read");
    std::vector<char> chars((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) detail::fail("cannot read '", path, "': the read failed");
    std::vector<std::byte> bytes(chars.size());
    if (!chars.empty()) std::memcpy(bytes.data(), chars.data(), chars.size());
    return parse_vol(bytes, path);
}

/// The bytes of `g` as a version-3 float32 .vol file.
inline std::vector<std::byte> vol_bytes(const VoxelGrid& g) {
    using namespace detail_vol;
    if (g.values.size() != g.voxels() * std::size_t(g.channels))
        detail::fail("VoxelGrid: ", g.values.size(), " values do not match resolution ", g.resolution[0], "x",
                     g.resolution[1], "x", g.resolution[2], " with ", g.channels, " channel(s)");
    std::vector<std::byte> out;
    out.reserve(kHeaderBytes + 4 * g.values.size());
    for (const char c : {'V', 'O', 'L'}) out.push_back(std::byte(c));
    out.push_back(std::byte(3));
    put_u32(out, 1u);
    for (const int r : g.resolution) put_u32(out, std::uint32_t(r));
    put_u32(out, std::uint32_t(g.channels));
    for (int a = 0; a < 3; ++a) put_u32(out, std::bit_cast<std::uint32_t>(g.bounds.lo[a]));
    for (int a = 0; a < 3; ++a) put_u32(out, std::bit_cast<std::uint32_t>(g.bounds.hi[a]));
    for (const float x : g.values) put_u32(out, std::bit_cast<std::uint32_t>(x));
    return out;
}

/// Writes `g` to `path` as a .vol file; throws nsp::InvalidArgument naming the path on failure.
inline void write_vol(const std::string& path, const VoxelGrid& g) {
    const std::vector<std::byte> bytes = vol_bytes(g);
    std::ofstream out(path, std::ios::binary);
    if (!out) detail::fail("cannot write '", path, "'");
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    if (!out) detail::fail("cannot write '", path, "': the write failed");
}

/// A DenseGridMedium of mode S from channel `c` of `g` as its density, with the coefficients per
/// unit density (see DenseGridMedium); the same medium as one built from the same values.
template <SpectralMode S>
DenseGridMedium<S> to_dense_medium(const VoxelGrid& g, const typename S::Coefficient& sigma_a_per_density,
                                   const typename S::Coefficient& sigma_s_per_density, int c = 0) {
    return DenseGridMedium<S>(g.bounds, g.resolution, g.channel(c), sigma_a_per_density, sigma_s_per_density);
}

}  // namespace nsp::io
