// nsp/io/nanovdb.hpp: media from NanoVDB density grids (fog volumes); .nvdb files in nanovdb_file.hpp,
// which it includes.
//
// Optional: needs NanoVDB's headers (Debian: libnanovdb-dev; header-only). Compressed .nvdb files
// need NanoVDB's codecs, which its IO.h compiles only with NANOVDB_USE_ZIP (zlib) and
// NANOVDB_USE_BLOSC (c-blosc) defined and those libraries linked: CMake's nsp::nanovdb target does
// both when it finds zlib1g-dev and libblosc-dev. `nsp/nsp.hpp` does not include it. A NanoVdbMedium is a float density grid, looked up with
// NanoVDB's own trilinear sampler (values at integer index coordinates, the grid's background 0
// beyond them), scaled per channel by a coefficient per unit density as DenseGridMedium is. It is
// a RegionBoundedMedium (so it takes every grid majorant) and a TreeLayoutMedium: TreeMajorant
// puts its coarse cells on the grid's lower internal nodes (128 voxels a side), splits them into
// 32-voxel cells and those into the leaves (8 voxels a side), with every bound widened by the voxel layer a trilinear
// lookup reads across a node's faces. Any float grid of the same checks (a temperature grid, say)
// is a NanoScalarField too, for BlackbodyEmission (media/blackbody.hpp).
//
// Construction and loading validate everything and throw nsp::InvalidArgument with a message
// that names the file or grid and what is wrong; lookups never throw and read no mutable state.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>  // NanoVDB's GridValidator.h uses std::cerr without including it
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridHandle.h>
#include <nanovdb/util/GridValidator.h>
#include <nanovdb/util/HostBuffer.h>
#include <nanovdb/util/SampleFromVoxels.h>

#include "../core/error.hpp"
#include "../majorants/tree.hpp"
#include "../media/blackbody.hpp"
#include "../media/validate.hpp"
#include "../medium.hpp"
#include "vol.hpp"

namespace nsp::io {

using NanoHandle = nanovdb::GridHandle<nanovdb::HostBuffer>;

namespace detail_nvdb {

/// True when `n` bytes from byte `at` lie inside `size` bytes (no overflow).
constexpr bool inside(std::uint64_t at, std::uint64_t n, std::uint64_t size) noexcept { return at <= size && n <= size - at; }

/// The float grid at the start of `handle`'s buffer, once its layout is checked against the
/// buffer: NanoVDB's own checksum and validator walk the node arrays and the root table that the
/// grid's header points to, and trust those offsets, so a damaged header could send them outside
/// the buffer. Checks the magic number, that it is the buffer's first grid and fits it, that it
/// holds float values, that its nodes are laid out breadth-first (the node arrays nsp scans), and
/// that the root, its tile table and each level's node array lie inside the grid, aligned.
/// Throws InvalidArgument naming `what` otherwise. (Child offsets are checked by NanoDensityGrid.)
inline const nanovdb::FloatGrid* checked_grid(const NanoHandle& handle, const std::string& what) {
    using GridData = nanovdb::GridData;
    using TreeData = nanovdb::NanoTree<float>::DataType;
    using RootData = nanovdb::NanoRoot<float>::DataType;
    const std::uint64_t size = handle.size();
    if (handle.empty() || size < sizeof(GridData) + sizeof(TreeData))
        nsp::detail::fail(what, " holds no grid, or is truncated: ", size, " bytes, fewer than a grid's header (",
                          sizeof(GridData) + sizeof(TreeData), ")");
    const auto* data = reinterpret_cast<const GridData*>(handle.data());
    if (data->mMagic != NANOVDB_MAGIC_NUMBER) nsp::detail::fail(what, " is corrupted: its grid does not start with NanoVDB's magic number");
    if (data->mGridIndex != 0 || data->mGridCount == 0 || data->mGridSize > size || data->mGridSize < sizeof(GridData) + sizeof(TreeData))
        nsp::detail::fail(what, " is corrupted: its header says grid ", data->mGridIndex, " of ", data->mGridCount, ", ",
                          data->mGridSize, " bytes, in a buffer of ", size, " bytes");
    if (data->mGridType != nanovdb::GridType::Float) {
        const auto type = data->mGridType;
        nsp::detail::fail(what, " holds ", type < nanovdb::GridType::End ? nanovdb::toStr(type) : "unknown (corrupted?)",
                          " values; nsp reads float density grids (fog volumes)");
    }
    const auto* grid = reinterpret_cast<const nanovdb::FloatGrid*>(data);
    if (!grid->isBreadthFirst())
        nsp::detail::fail(what, " is corrupted, or its nodes are not laid out breadth-first (as every NanoVDB writer "
                          "lays them out): nsp reads the node arrays of breadth-first grids");
    const std::uint64_t end = data->mGridSize, tree = sizeof(GridData);
    const auto* t = reinterpret_cast<const TreeData*>(reinterpret_cast<const char*>(data) + tree);
    auto fail_layout = [&](const char* part, std::uint64_t at, std::uint64_t bytes) {
        nsp::detail::fail(what, " is corrupted: its ", part, " (", bytes, " bytes at byte ", at, ") lies outside its ", end,
                          " bytes or is misaligned");
    };
    const std::uint64_t root = tree + t->mNodeOffset[3];
    if (t->mNodeOffset[3] < sizeof(TreeData) || root % NANOVDB_DATA_ALIGNMENT != 0 || !inside(root, sizeof(RootData), end))
        fail_layout("root node", root, sizeof(RootData));
    const auto table = std::uint64_t(reinterpret_cast<const RootData*>(reinterpret_cast<const char*>(data) + root)->mTableSize);
    if (!inside(root + sizeof(RootData), table * sizeof(typename RootData::Tile), end))
        fail_layout("root table", root + sizeof(RootData), table * sizeof(typename RootData::Tile));
    const std::uint64_t node_bytes[3] = {sizeof(nanovdb::NanoLeaf<float>), sizeof(nanovdb::NanoLower<float>),
                                         sizeof(nanovdb::NanoUpper<float>)};
    const char* node_names[3] = {"leaf array", "lower node array", "upper node array"};
    for (int level = 0; level < 3; ++level) {
        const std::uint64_t count = t->mNodeCount[level], first = tree + t->mNodeOffset[level];
        if (count == 0) continue;
        if (t->mNodeOffset[level] < sizeof(TreeData) || first % NANOVDB_DATA_ALIGNMENT != 0 ||
            !inside(first, count * node_bytes[level], end))
            fail_layout(node_names[level], first, count * node_bytes[level]);
    }
    return grid;
}

}  // namespace detail_nvdb

/// A validated NanoVDB float fog volume and what nsp precomputes over it: the box outside which
/// its density is 0, the largest value and each leaf's largest value (for density bounds).
class NanoDensityGrid {
public:
    /// Takes the grid out of `handle` (its first grid). `what` names it in messages (e.g.
    /// "grid 'density' of 'smoke.nvdb'"). Throws InvalidArgument unless it is a float grid of
    /// class fog volume (or unknown), with background 0, an axis-aligned transform (positive
    /// voxel sizes, no rotation or shear), at least one active voxel, and every value (voxels,
    /// inactive ones included, and tiles) finite and >= 0; and unless its layout is sound, so
    /// that no lookup leaves its buffer whatever its bytes: the header, root and node arrays
    /// inside the buffer (detail_nvdb::checked_grid), every child offset on a node of the level
    /// below, and node origins within +-2^30 voxels of the index origin.
    NanoDensityGrid(NanoHandle handle, std::string what) : handle_(std::move(handle)), what_(std::move(what)) {
        grid_ = detail_nvdb::checked_grid(handle_, what_);
        const nanovdb::GridClass cls = grid_->gridClass();
        if (cls == nanovdb::GridClass::LevelSet)
            nsp::detail::fail(what_, " is a level set (a signed distance field), not a fog volume; convert it to a fog "
                         "volume (e.g. OpenVDB's sdfToFogVolume) first");
        if (cls != nanovdb::GridClass::FogVolume && cls != nanovdb::GridClass::Unknown)
            nsp::detail::fail(what_, " has grid class ", cls < nanovdb::GridClass::End ? nanovdb::toStr(cls) : "unknown (corrupted?)",
                              ", not a fog volume");
        const float background = grid_->tree().background();
        if (background != 0.f)
            nsp::detail::fail(what_, " has background value ", background,
                         ", which is not allowed: a fog volume's density is 0 outside its active voxels");
        if (grid_->activeVoxelCount() == 0) nsp::detail::fail(what_, " is empty: it has no active voxels");
        read_transform();
        scan_values();
    }

    /// The trilinear density at world point p (0 outside bounds()).
    float density(const Vec3& p) const noexcept {
        if (!bounds_.contains(p)) return 0.f;
        const auto acc = grid_->getAccessor();
        const nanovdb::SampleFromVoxels<decltype(acc), 1, false> sample(acc);
        return sample(nanovdb::Vec3f((p.x - t_f_.x) * inv_s_.x, (p.y - t_f_.y) * inv_s_.y, (p.z - t_f_.z) * inv_s_.z));
    }

    /// The largest density a lookup can return in world region `region`: the largest voxel value
    /// among those the trilinear lookups there read (region widened by 1/1000 voxel for rounding).
    float density_bound(const Box& region) const noexcept {
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            const double x0 = (double(region.lo[a]) - t_[a]) / s_[a] - 1e-3, x1 = (double(region.hi[a]) - t_[a]) / s_[a] + 1e-3;
            const double l = std::max(std::floor(x0), double(nz_lo_[a])), h = std::min(std::floor(x1) + 1.0, double(nz_hi_[a]));
            if (!(l <= h)) return 0.f;
            lo[a] = int(l);
            hi[a] = int(h);
        }
        return fold_voxels(lo, hi, 0.f, leaf_max_, [](float a, float b) { return std::max(a, b); });
    }

    /// The smallest density a lookup can return in world region `region` (LowerBoundedMedium,
    /// majorants/control.hpp): the smallest voxel value among those the trilinear lookups there read
    /// (found as density_bound finds the largest: tiles, whole leaves by their minimum, cut leaves
    /// voxel by voxel), less 2^-20 of it for the interpolation's rounding; 0 where the lookups read
    /// past the non-zero values' box (the ramp down to the background).
    float density_lower_bound(const Box& region) const noexcept {
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            const double x0 = (double(region.lo[a]) - t_[a]) / s_[a] - 1e-3, x1 = (double(region.hi[a]) - t_[a]) / s_[a] + 1e-3;
            const double l = std::floor(x0), h = std::floor(x1) + 1.0;
            if (!(l >= double(nz_lo_[a]) && h <= double(nz_hi_[a]))) return 0.f;  // NaN too
            lo[a] = int(l);
            hi[a] = int(h);
        }
        const float m = fold_voxels(lo, hi, std::numeric_limits<float>::infinity(), leaf_min_,
                                    [](float a, float b) { return std::min(a, b); });
        return m > 0.f && m < std::numeric_limits<float>::infinity() ? m * (1.f - 0x1p-20f) : 0.f;
    }

    /// The world box outside which the density is 0: the non-zero values' index box widened by
    /// one voxel (the trilinear ramp down to the background), mapped to world space.
    Box bounds() const noexcept { return bounds_; }
    float max_density() const noexcept { return max_; }

    /// Coarse cells on the lower internal nodes (128^3 voxels, aligned as the tree aligns them),
    /// split into 4^3 cells of 32^3 voxels and those into 4^3 cells on the leaves (8^3 voxels);
    /// with `leaf_split` in {2, 4, 8} each leaf splits once more into leaf_split^3 cells.
    TreeLayout tree_layout(int leaf_split = 1) const noexcept {
        TreeLayout l;
        l.split = {4, 4, leaf_split > 1 ? leaf_split : 0};
        constexpr int C = 128;
        for (int a = 0; a < 3; ++a) {
            // Coarse cell k covers index space [128 k, 128 (k + 1)), the lookups between the voxels
            // of lower node k (a lookup between integer coordinates i and i + 1 reads voxels i and
            // i + 1); a finest cell j covers [8 j, 8 (j + 1)), leaf j's.
            const int k0 = floor_div(nz_lo_[a] - 1, C), k1 = floor_div(nz_hi_[a] + 1, C);
            l.coarse[a] = k1 - k0 + 1;
            l.box.lo[a] = float(t_[a] + s_[a] * (double(C) * k0));
            l.box.hi[a] = float(t_[a] + s_[a] * (double(C) * (k1 + 1)));
            l.box.lo[a] = std::min(l.box.lo[a], bounds_.lo[a]);  // rounding: the box must contain the bounds
            l.box.hi[a] = std::max(l.box.hi[a], bounds_.hi[a]);
        }
        return l;
    }

    /// Index box of the non-zero values, the voxel size and the index-to-world translation.
    std::array<int, 3> nonzero_lo() const noexcept { return nz_lo_; }
    std::array<int, 3> nonzero_hi() const noexcept { return nz_hi_; }
    Vec3 voxel_size() const noexcept { return Vec3(float(s_.x), float(s_.y), float(s_.z)); }
    std::uint64_t active_voxels() const noexcept { return grid_->activeVoxelCount(); }
    std::uint32_t leaf_count() const noexcept { return grid_->tree().nodeCount(0); }
    /// Bytes: the NanoVDB buffer and the leaf maxima.
    std::size_t memory_bytes() const noexcept { return handle_.size() + leaf_max_.size() * sizeof(float); }
    const std::string& name() const noexcept { return what_; }
    const nanovdb::FloatGrid& grid() const noexcept { return *grid_; }

private:
    static int floor_div(int a, int b) noexcept { return a >= 0 ? a / b : -((-a + b - 1) / b); }

    void read_transform() {
        const nanovdb::Map& map = grid_->map();
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) {
                const double m = map.mMatD[3 * r + c];
                if (!std::isfinite(m))
                    nsp::detail::fail(what_, ": its index-to-world transform has the entry ", m, " at (", r, ", ", c,
                                 "); it must be finite");
                if (r != c && std::abs(m) > 1e-9 * (std::abs(map.mMatD[4 * r]) + std::abs(map.mMatD[4 * c])))
                    nsp::detail::fail(what_, ": its index-to-world transform is rotated or sheared (entry ", m, " at (", r, ", ",
                                 c, ")); nsp reads axis-aligned grids: resample it to an axis-aligned transform");
            }
        for (int a = 0; a < 3; ++a) {
            s_[a] = map.mMatD[4 * a];
            t_[a] = map.mVecD[a];
            if (!(s_[a] > 0.0) || !std::isfinite(t_[a]))
                nsp::detail::fail(what_, ": its voxel size on axis ", a, " is ", s_[a], " and its translation ", t_[a],
                             "; the size must be > 0 (no mirroring) and both finite");
            inv_s_[a] = float(1.0 / s_[a]);
        }
        t_f_ = Vec3(float(t_.x), float(t_.y), float(t_.z));
    }

    /// Checks every value, records each leaf's maximum, the largest value and the index box of
    /// the non-zero ones (voxels and tiles).
    void scan_values() {
        const auto& tree = grid_->tree();
        nz_lo_ = {INT32_MAX, INT32_MAX, INT32_MAX};
        nz_hi_ = {INT32_MIN, INT32_MIN, INT32_MIN};
        auto check = [&](float v, const nanovdb::Coord& ijk, const char* kind) {
            if (!std::isfinite(v) || v < 0.f)
                nsp::detail::fail(what_, ": the value ", v, " of the ", kind, " at index (", ijk[0], ", ", ijk[1], ", ", ijk[2],
                             ") is not allowed: densities must be finite and >= 0");
        };
        // Index arithmetic (a node's origin plus up to 4095) stays far inside int32.
        constexpr int kMaxOrigin = 1 << 30;
        auto check_origin = [&](const nanovdb::Coord& o, const char* kind) {
            for (int a = 0; a < 3; ++a)
                if (o[a] < -kMaxOrigin || o[a] > kMaxOrigin)
                    nsp::detail::fail(what_, " is corrupted or too large: the ", kind, " at index (", o[0], ", ", o[1], ", ",
                                      o[2], ") lies more than 2^30 voxels from the index origin, where nsp reads grids");
        };
        // A child offset must land on a node of the array below: lookups follow them unchecked,
        // and a checksum (which covers them) may be partial or absent in files from other tools.
        auto check_child = [&](const void* parent, std::int64_t offset, const void* first, std::uint32_t count,
                               std::size_t bytes, const char* kind, const nanovdb::Coord& o) {
            const std::uintptr_t at = std::uintptr_t(parent) + std::uint64_t(offset), begin = std::uintptr_t(first);
            if (!first || at < begin || (at - begin) % bytes != 0 || (at - begin) / bytes >= count)
                nsp::detail::fail(what_, " is corrupted: the ", kind, " at index (", o[0], ", ", o[1], ", ", o[2],
                                  ") has a child offset (", offset, ") that does not point at a node of the level below");
        };
        auto extend = [&](const nanovdb::Coord& lo, int dim) {
            for (int a = 0; a < 3; ++a) {
                nz_lo_[a] = std::min(nz_lo_[a], lo[a]);
                nz_hi_[a] = std::max(nz_hi_[a], lo[a] + dim - 1);
            }
        };
        const std::uint32_t leaves = tree.nodeCount(0);
        leaf_max_.assign(leaves, 0.f);
        leaf_min_.assign(leaves, 0.f);
        for (std::uint32_t i = 0; i < leaves; ++i) {
            const auto& leaf = tree.getFirstLeaf()[i];
            check_origin(leaf.origin(), "leaf");
            float m = 0.f, low = std::numeric_limits<float>::infinity();
            for (std::uint32_t n = 0; n < 512; ++n) {
                const float v = leaf.getValue(n);
                check(v, leaf.offsetToGlobalCoord(n), "voxel");
                if (v > 0.f) extend(leaf.offsetToGlobalCoord(n), 1);
                m = std::max(m, v);
                low = std::min(low, v);
            }
            leaf_max_[i] = m;
            leaf_min_[i] = low;
            max_ = std::max(max_, m);
        }
        auto tiles = [&](const auto* nodes, std::uint32_t count, std::uint32_t size, int dim, const char* kind, const char* node,
                         const auto* children, std::uint32_t child_count) {
            for (std::uint32_t i = 0; i < count; ++i) {
                check_origin(nodes[i].origin(), node);
                for (std::uint32_t n = 0; n < size; ++n) {
                    if (nodes[i].data()->isChild(n)) {
                        check_child(nodes[i].data(), nodes[i].data()->mTable[n].child, children, child_count, sizeof(*children), node,
                                    nodes[i].origin());
                        continue;
                    }
                    const float v = nodes[i].data()->getValue(n);
                    check(v, nodes[i].offsetToGlobalCoord(n), kind);
                    if (v > 0.f) extend(nodes[i].offsetToGlobalCoord(n), dim);
                    max_ = std::max(max_, v);
                }
            }
        };
        if (tree.nodeCount(1) > 0)
            tiles(tree.getFirstLower(), tree.nodeCount(1), 16 * 16 * 16, 8, "tile (8^3 voxels)", "lower internal node",
                  tree.getFirstLeaf(), leaves);
        if (tree.nodeCount(2) > 0)
            tiles(tree.getFirstUpper(), tree.nodeCount(2), 32 * 32 * 32, 128, "tile (128^3 voxels)", "upper internal node",
                  tree.getFirstLower(), tree.nodeCount(1));
        const auto& root = tree.root();
        for (std::uint32_t i = 0; i < root.tileCount(); ++i) {
            const auto* tile = root.data()->tile(i);
            check_origin(tile->origin(), "root tile");
            if (tile->isChild()) {
                check_child(root.data(), tile->child, tree.getFirstUpper(), tree.nodeCount(2), sizeof(nanovdb::NanoUpper<float>),
                            "root tile", tile->origin());
                continue;
            }
            check(tile->value, tile->origin(), "tile (4096^3 voxels)");
            if (tile->value > 0.f) extend(tile->origin(), 4096);
            max_ = std::max(max_, tile->value);
        }
        if (!(max_ > 0.f)) {  // every value 0: an empty medium over the active voxels' box
            const auto& b = tree.bbox();
            check_origin(b.min(), "bounding box corner");
            check_origin(b.max(), "bounding box corner");
            for (int a = 0; a < 3; ++a) nz_lo_[a] = b.min()[a], nz_hi_[a] = b.max()[a];
        }
        for (int a = 0; a < 3; ++a) {
            bounds_.lo[a] = float(t_[a] + s_[a] * double(nz_lo_[a] - 1));
            bounds_.hi[a] = float(t_[a] + s_[a] * double(nz_hi_[a] + 1));
            if (!(bounds_.lo[a] < bounds_.hi[a]) || !std::isfinite(bounds_.lo[a]) || !std::isfinite(bounds_.hi[a]))
                nsp::detail::fail(what_, ": its world box on axis ", a, " is [", bounds_.lo[a], ", ", bounds_.hi[a],
                             "]; it must be finite and not empty in float");
        }
    }

    /// `op` folded from `init` over the voxel values in index box [lo, hi] (inclusive), block by
    /// block of 8^3: a tile's (or the background's) one value, a whole leaf's `per_leaf` value
    /// (its maximum or minimum), a cut leaf voxel by voxel. density_bound and density_lower_bound.
    template <class Op>
    float fold_voxels(const int (&lo)[3], const int (&hi)[3], float init, const std::vector<float>& per_leaf,
                      Op op) const noexcept {
        const auto acc = grid_->getAccessor();
        const auto* first = grid_->tree().getFirstLeaf();
        float m = init;
        for (int bz = lo[2] & ~7; bz <= hi[2]; bz += 8)
            for (int by = lo[1] & ~7; by <= hi[1]; by += 8)
                for (int bx = lo[0] & ~7; bx <= hi[0]; bx += 8) {
                    const nanovdb::Coord block(bx, by, bz);
                    const auto* leaf = acc.probeLeaf(block);
                    if (!leaf) {  // a tile (or the background): one value over the block
                        m = op(m, acc.getValue(block));
                        continue;
                    }
                    const bool inside = bx >= lo[0] && by >= lo[1] && bz >= lo[2] && bx + 7 <= hi[0] && by + 7 <= hi[1] &&
                                        bz + 7 <= hi[2];
                    if (inside) {
                        m = op(m, per_leaf[std::size_t(leaf - first)]);
                        continue;
                    }
                    for (int z = std::max(bz, lo[2]); z <= std::min(bz + 7, hi[2]); ++z)
                        for (int y = std::max(by, lo[1]); y <= std::min(by + 7, hi[1]); ++y)
                            for (int x = std::max(bx, lo[0]); x <= std::min(bx + 7, hi[0]); ++x)
                                m = op(m, leaf->getValue(nanovdb::Coord(x, y, z)));
                }
        return m;
    }

    NanoHandle handle_;
    std::string what_;
    const nanovdb::FloatGrid* grid_ = nullptr;
    glm::dvec3 s_{1.0}, t_{0.0};  ///< world = s * index + t, per axis
    Vec3 inv_s_{1.f}, t_f_{0.f};
    std::array<int, 3> nz_lo_{}, nz_hi_{};
    Box bounds_;
    float max_ = 0.f;
    std::vector<float> leaf_max_;
    std::vector<float> leaf_min_;  ///< each leaf's smallest voxel value (density_lower_bound)
};

/// A NanoVDB fog volume as a medium: mu_a(p) = density(p) sigma_a_scale, mu_s(p) = density(p)
/// sigma_s_scale. Copies share the grid (read-only).
template <SpectralMode S>
class NanoVdbMedium {
public:
    using Spectral = S;
    using Spectrum = typename S::Spectrum;
    using Coefficient = typename S::Coefficient;

    /// Throws InvalidArgument on a null grid, a negative or non-finite scale, or an extinction
    /// bound that overflows.
    NanoVdbMedium(std::shared_ptr<const NanoDensityGrid> grid, const Coefficient& sigma_a_scale,
                  const Coefficient& sigma_s_scale)
        : grid_(std::move(grid)), sigma_a_(sigma_a_scale), sigma_s_(sigma_s_scale) {
        if (!grid_) nsp::detail::fail("NanoVdbMedium: the density grid is null");
        nsp::detail::require_coefficient(sigma_a_, "NanoVdbMedium sigma_a_scale");
        nsp::detail::require_coefficient(sigma_s_, "NanoVdbMedium sigma_s_scale");
        nsp::detail::require_finite_extinction(max_extinction(),
                                          "NanoVdbMedium extinction bound max(sigma_a_scale + sigma_s_scale) x max density");
    }

    Box bounds() const noexcept { return grid_->bounds(); }
    float density(const Vec3& p) const noexcept { return grid_->density(p); }

    Coefficients<S> coefficients(const Vec3& p, const typename S::Wavelengths& l) const noexcept {
        const float d = grid_->density(p);
        return {S::sample(sigma_a_, l) * d, S::sample(sigma_s_, l) * d};
    }
    /// Trilinear weights are convex: max density times the extinction scale bounds mu_t.
    Spectrum extinction_bound(const typename S::Wavelengths& l) const noexcept {
        return (S::sample(sigma_a_, l) + S::sample(sigma_s_, l)) * grid_->max_density();
    }
    float max_extinction() const noexcept { return max_value(sigma_a_ + sigma_s_) * grid_->max_density(); }
    Coefficient extinction_bound_coefficient() const { return scale<Coefficient>(sigma_a_ + sigma_s_, grid_->max_density()); }
    Coefficient extinction_per_density() const { return sigma_a_ + sigma_s_; }
    float density_bound(const Box& region) const noexcept { return grid_->density_bound(region); }
    float density_lower_bound(const Box& region) const noexcept { return grid_->density_lower_bound(region); }
    TreeLayout tree_layout(int leaf_split = 1) const noexcept { return grid_->tree_layout(leaf_split); }
    const NanoDensityGrid& grid() const noexcept { return *grid_; }

private:
    std::shared_ptr<const NanoDensityGrid> grid_;
    Coefficient sigma_a_, sigma_s_;
};

static_assert(TreeLayoutMedium<NanoVdbMedium<Mono>> && TreeLayoutMedium<NanoVdbMedium<Rgb>>);

/// A NanoVDB float grid as a ScalarField (media/blackbody.hpp): e.g. a temperature grid, for
/// Emissive<NanoVdbMedium<S>, BlackbodyEmission<S, NanoScalarField>>. Shares the grid.
class NanoScalarField {
public:
    /// Throws InvalidArgument on a null grid.
    explicit NanoScalarField(std::shared_ptr<const NanoDensityGrid> grid) : grid_(std::move(grid)) {
        if (!grid_) nsp::detail::fail("NanoScalarField: the grid is null");
    }
    float value(const Vec3& p) const noexcept { return grid_->density(p); }
    float bound(const Box& region) const noexcept { return grid_->density_bound(region); }
    Box bounds() const noexcept { return grid_->bounds(); }
    float max_value() const noexcept { return grid_->max_density(); }
    const NanoDensityGrid& grid() const noexcept { return *grid_; }

private:
    std::shared_ptr<const NanoDensityGrid> grid_;
};

static_assert(ScalarField<NanoScalarField>);

}  // namespace nsp::io

#include "nanovdb_file.hpp"
