// nsp/majorants/tree.hpp: majorants that follow a sparse volume's tree, walked hierarchically
// (THEORY 4, step 1, over several levels).
//
// A coarse grid over the medium (by default 16 cells along its longest axis; on a NanoVDB grid,
// optionally, its lower internal nodes of 128 voxels a side) whose cells are each empty, uniform
// (one value: a constant tile, or a cell whose parts all bound the same) or split into n^3 cells
// of the next level where a surface-area cost model says the steps pay for the lookups they
// save, down to the finest level (by default up to two splits of 4^3; on a VDB tree 128 -> 32 ->
// 8 voxels, its leaves). Every value is the medium's density bound over the cell (widened by the
// voxels a trilinear lookup reads across the cell's faces, as RegionBoundedMedium promises),
// padded for rounding. Along a ray one DDA per level walks the cells, entering a split cell's
// node only where the ray crosses it: an empty cell costs one step however fine the levels below
// it would be, and memory is what the split cells need. The iterator keeps one walk per level in
// fixed arrays (no heap).
//
// A medium that knows its tree says where the nodes are (`tree_layout()`, e.g.
// io/nanovdb.hpp's NanoVdbMedium); any other RegionBoundedMedium takes a layout of the caller's
// choice over its bounds. Grey (TreeMajorant) and per channel (ChannelTreeMajorant), as the
// grid majorants of majorants/grid.hpp, whose DDA this walk reuses at every level.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "../core/error.hpp"
#include "../majorant.hpp"
#include "../media/validate.hpp"
#include "../medium.hpp"
#include "grid.hpp"

namespace nsp {

/// Most levels below the coarse grid a tree majorant may have.
inline constexpr int kMaxTreeSplits = 3;

/// Where a tree majorant's cells lie: `coarse` cells over `box`; where a cell's bound is neither 0
/// nor the same over its parts, it splits into split[0]^3 cells, those into split[1]^3, and so
/// on (a 0 ends the list). `box` must contain the medium's bounds.
///
/// A cell splits only where that pays: by a surface-area cost model (as bounding volume
/// hierarchies are built), a random ray crossing a cell costs one DDA step plus mu_bar times its
/// mean chord (4 V / S) tentative collisions, each a lookup; split, it costs the step plus each
/// part's cost weighted by the part's share of the cell's surface (the chance a ray through the
/// cell crosses it), plus a descent into the cell's node. `step_cost` is a DDA step's cost in
/// lookups and `descent_cost` a descent's (both 0: split wherever the bound varies); the
/// defaults, 0.3 and 1, are what this machine measured (a step about 20 ns, a descent, which
/// starts a new DDA, about 100 ns before the walk kept the ray's part once, a tracked trilinear
/// lookup 75 to 150 ns).
struct TreeLayout {
    Box box;
    std::array<int, 3> coarse{1, 1, 1};
    std::array<int, kMaxTreeSplits> split{8, 0, 0};
    float step_cost = 0.3f;
    float descent_cost = 1.f;  ///< entering a split cell's node (a new DDA), in lookups

    /// The number of levels below the coarse grid.
    int splits() const noexcept {
        int n = 0;
        while (n < kMaxTreeSplits && split[std::size_t(n)] > 0) ++n;
        return n;
    }
};

/// A medium that states the layout of its own sparse tree (coarse cells on its internal nodes,
/// the finest cells on its leaves).
template <class M>
concept TreeLayoutMedium = CellBoundedMedium<M> && requires(const M& m) {
    { m.tree_layout() } -> std::same_as<TreeLayout>;
};

namespace detail {

/// The storage shared by the grey and per-channel tree majorants: the coarse grid's cells, then
/// per level the nodes (split cells), each n^3 cells of that level's split n; every cell holds its
/// padded bound and the node it splits into (-1 for none: empty or uniform).
template <CellBoundedMedium M>
class MajorantTree {
public:
    /// With `lower`, every cell that is not split also keeps the medium's density lower bound over
    /// it (LowerBoundedMedium's; 0 for a medium without that query), in arrays parallel to the
    /// packed cells (TreeControl): the layout is the same either way.
    MajorantTree(const M& medium, const TreeLayout& layout, float scale, const char* what, bool lower = false)
        : bounds_(medium.bounds()), layout_(layout), levels_(layout.splits() + 1), with_lower_(lower) {
        std::size_t n = 1;
        for (int a = 0; a < 3; ++a) {
            if (layout.coarse[a] < 1 || layout.coarse[a] > 4096)
                fail(what, " coarse resolution[", a, "] = ", layout.coarse[a], " is not allowed: it must lie in [1, 4096]");
            n *= std::size_t(layout.coarse[a]);
        }
        if (n > (std::size_t(1) << 24))
            fail(what, " coarse resolution ", layout.coarse[0], "x", layout.coarse[1], "x", layout.coarse[2], " has ", n,
                 " cells; at most 2^24 are allowed");
        for (int l = 0; l < kMaxTreeSplits; ++l) {
            const int k = layout.split[std::size_t(l)];
            if (k < 0 || k > 64)
                fail(what, " split[", l, "] = ", k, " cells per axis is not allowed: it must lie in [1, 64] (0 ends the list)");
            if (l >= levels_ - 1 && k != 0)
                fail(what, " split[", l, "] = ", k, " follows a 0: the split list ends at its first 0");
        }
        const Box& box = layout.box;
        for (int a = 0; a < 3; ++a) {
            if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || !(box.lo[a] < box.hi[a]))
                fail(what, ": the layout's box on axis ", a, " is [", box.lo[a], ", ", box.hi[a],
                     "]; it must be finite with lo < hi");
            if (!(box.lo[a] <= bounds_.lo[a] && bounds_.hi[a] <= box.hi[a]))
                fail(what, ": the layout's box on axis ", a, " is [", box.lo[a], ", ", box.hi[a],
                     "], which does not contain the medium's bounds [", bounds_.lo[a], ", ", bounds_.hi[a], "]");
            cell_[0][a] = (box.hi[a] - box.lo[a]) / float(layout.coarse[a]);
            for (int l = 1; l < levels_; ++l) cell_[l][a] = cell_[l - 1][a] / float(layout.split[std::size_t(l - 1)]);
            for (int l = 0; l < levels_; ++l) {
                if (!std::isfinite(cell_[l][a]) || !(cell_[l][a] > 0.f) || !std::isfinite(1.f / cell_[l][a]))
                    fail(what, " cell size of level ", l, " on axis ", a, " = ", cell_[l][a],
                         " is not allowed: it must be finite and > 0");
                inv_cell_[l][a] = 1.f / cell_[l][a];
            }
        }
        if (!std::isfinite(layout.step_cost) || layout.step_cost < 0.f)
            fail(what, " step_cost = ", layout.step_cost, " is not allowed: it must be finite and >= 0 (lookups per DDA step)");
        if (!std::isfinite(layout.descent_cost) || layout.descent_cost < 0.f)
            fail(what, " descent_cost = ", layout.descent_cost,
                 " is not allowed: it must be finite and >= 0 (lookups per descent into a split cell)");
        const CellBounds<M> bounds(medium, what);
        unit_ = max_value(bounds.unit());
        pad_ = kGridMajorantPad * scale;
        scale_ = scale;
        cells_[0].assign(n, 0u);
        if (with_lower_) lower_[0].assign(n, 0.f);
        std::size_t i = 0;
        for (int z = 0; z < layout.coarse[2]; ++z)
            for (int y = 0; y < layout.coarse[1]; ++y)
                for (int x = 0; x < layout.coarse[0]; ++x, ++i) {
                    const int c[3] = {x, y, z};
                    const Built b = build(medium, bounds, 0, cell_box(box, 0, c, layout.coarse), c, what);
                    cells_[0][i] = b.packed();
                    if (with_lower_) lower_[0][i] = b.lower;
                }
        for (auto& v : cells_) v.shrink_to_fit();
        for (auto& v : lower_) v.shrink_to_fit();
        for (int l = 0; l < levels_; ++l) {
            res_[l] = res(l);
            stride_[l] = per_node(l);
        }
    }

    /// Cell c of a level-l grid of `res` cells over `parent` (the last cell's faces on parent's).
    Box cell_box(const Box& parent, int l, const int* c, const std::array<int, 3>& res) const noexcept {
        Box b;
        for (int a = 0; a < 3; ++a) {
            b.lo[a] = c[a] == 0 ? parent.lo[a] : parent.lo[a] + float(c[a]) * cell_[l][a];
            b.hi[a] = c[a] + 1 == res[a] ? parent.hi[a] : parent.lo[a] + float(c[a] + 1) * cell_[l][a];
        }
        return b;
    }
    /// The cells per axis of a node of level l (l >= 1), or of the coarse grid.
    std::array<int, 3> res(int l) const noexcept {
        if (l == 0) return layout_.coarse;
        const int k = layout_.split[std::size_t(l - 1)];
        return {k, k, k};
    }

    /// The medium's bounds (the walk clips the ray to them) and the cells' extent per level.
    const Box& bounds() const noexcept { return bounds_; }
    const Vec3& cell_size(int l) const noexcept { return cell_[l]; }
    const Vec3& inverse_cell_size(int l) const noexcept { return inv_cell_[l]; }

    /// The cells of node `node` of level l (the coarse grid: node 0 of level 0), packed: a split
    /// cell is kSplit | the node it splits into (of level l + 1), any other its bound's bits (a
    /// float >= 0, so the sign bit is free). One load per step tells the walk both.
    static constexpr std::uint32_t kSplit = 0x80000000u;
    const std::uint32_t* node_cells(int l, std::int32_t node) const noexcept {
        return cells_[l].data() + std::size_t(node) * stride_[l];
    }
    /// The cells per axis of level l's nodes (precomputed).
    const std::array<int, 3>& level_res(int l) const noexcept { return res_[l]; }
    /// The density lower bounds of node `node`'s cells of level l, parallel to node_cells (0 for a
    /// split cell); only on a tree built with `lower`.
    const float* node_lower(int l, std::int32_t node) const noexcept {
        return lower_[l].data() + std::size_t(node) * stride_[l];
    }
    bool has_lower() const noexcept { return with_lower_; }

    /// The value of the finest cell holding p (0 outside the medium's bounds).
    float at_point(const Vec3& p) const noexcept { return find(p).value; }
    /// The density lower bound of the finest cell holding p (0 outside the medium's bounds, or on
    /// a tree built without `lower`).
    float lower_at_point(const Vec3& p) const noexcept { return find(p).lower; }

private:
    struct Found {
        float value, lower;
    };
    Found find(const Vec3& p) const noexcept {
        if (!bounds_.contains(p)) return {0.f, 0.f};
        Box b = layout_.box;
        std::int32_t node = 0;
        for (int l = 0;; ++l) {
            const auto r = res(l);
            int c[3];
            for (int a = 0; a < 3; ++a) c[a] = std::clamp(int((p[a] - b.lo[a]) * inv_cell_[l][a]), 0, r[a] - 1);
            const std::size_t i = std::size_t(c[0]) + std::size_t(r[0]) * (std::size_t(c[1]) + std::size_t(r[1]) * std::size_t(c[2]));
            const std::uint32_t cell = node_cells(l, node)[i];
            if (!(cell & kSplit)) return {std::bit_cast<float>(cell), with_lower_ ? node_lower(l, node)[i] : 0.f};
            b = cell_box(b, l, c, r);
            node = std::int32_t(cell & ~kSplit);
        }
    }

public:

    TreeLayout layout() const noexcept { return layout_; }
    std::size_t coarse_cells() const noexcept { return cells_[0].size(); }
    /// Split cells of level l (nodes of level l + 1).
    std::size_t split_cells(int l = 0) const noexcept { return l + 1 < levels_ ? cells_[l + 1].size() / per_node(l + 1) : 0; }
    std::size_t empty_cells() const noexcept {
        std::size_t k = 0;
        for (const std::uint32_t c : cells_[0]) k += !(c & kSplit) && !(std::bit_cast<float>(c) > 0.f);
        return k;
    }
    /// Bytes of storage: 4 per cell of every level (8 with lower bounds).
    std::size_t memory_bytes() const noexcept {
        std::size_t b = 0;
        for (int l = 0; l < levels_; ++l) b += cells_[l].size() * sizeof(std::uint32_t) + lower_[l].size() * sizeof(float);
        return b;
    }

private:
    std::size_t per_node(int l) const noexcept {
        if (l == 0) return 0;  // one node: the coarse grid
        const std::size_t k = std::size_t(layout_.split[std::size_t(l - 1)]);
        return k * k * k;
    }

    /// What build() decides for a cell: its padded bound, the node it splits into (-1: none) and
    /// its expected cost per crossing in lookups (the surface-area cost model of TreeLayout).
    struct Built {
        float value;
        std::int32_t node;
        double cost;
        float lower = 0.f;  ///< the density lower bound of a cell that is not split (with_lower_)
        std::uint32_t packed() const noexcept { return node >= 0 ? kSplit | std::uint32_t(node) : std::bit_cast<std::uint32_t>(value); }
    };

    /// Builds cell `region` of level l: its bound and, where that pays, its split (children first).
    Built build(const M& medium, const CellBounds<M>& bounds, int l, const Box& region, const int* c, const char* what) {
        const float d = bounds.density(region);
        if (!std::isfinite(d) || d < 0.f)
            fail(what, " level-", l, " cell (", c[0], ", ", c[1], ", ", c[2], "): the medium's density bound = ", d,
                 " is not allowed: it must be finite and >= 0");
        float lo = 0.f;
        if constexpr (requires { { medium.density_lower_bound(region) } -> std::same_as<float>; }) {
            if (with_lower_) {
                lo = medium.density_lower_bound(region);
                if (!std::isfinite(lo) || lo < 0.f)
                    fail(what, " level-", l, " cell (", c[0], ", ", c[1], ", ", c[2], "): the medium's density lower bound = ",
                         lo, " is not allowed: it must be finite and >= 0");
                if (lo > d)
                    fail(what, " level-", l, " cell (", c[0], ", ", c[1], ", ", c[2], "): the medium's density lower bound = ",
                         lo, " exceeds its upper bound ", d);
            }
        }
        const float v = d * pad_;
        if (!std::isfinite(v * unit_))
            fail(what, " level-", l, " cell (", c[0], ", ", c[1], ", ", c[2], ") majorant = density bound ", d, " x scale ",
                 scale_, " x extinction per density ", unit_, " is not allowed: it must be finite");
        if (d * unit_ > 0.f && !(v * unit_ > 0.f))
            fail(what, " level-", l, " cell (", c[0], ", ", c[1], ", ", c[2], ") majorant = density bound ", d, " x scale ",
                 scale_, " x extinction per density ", unit_, " rounds to 0 where the extinction may be ", d * unit_,
                 "; it must be > 0 there");
        // As one cell: a step, and mu_bar times the mean chord tentative collisions.
        const double step = double(layout_.step_cost);
        const double as_leaf = step + double(v) * double(unit_) * mean_chord(region);
        if (!(v > 0.f) || l + 1 >= levels_) return {v, -1, as_leaf, lo};  // empty, or a finest cell
        const auto r = res(l + 1);
        const std::size_t k = per_node(l + 1);
        // Nodes the children add below: dropped again if the cell stays whole.
        std::size_t mark[kMaxTreeSplits + 1];
        for (int m = l + 1; m < levels_; ++m) mark[m] = cells_[m].size();
        std::vector<std::uint32_t> parts(k);
        std::vector<float> part_lower(with_lower_ ? k : 0);
        float first = 0.f, lowest = std::numeric_limits<float>::infinity();
        bool uniform = true;
        // The step into the cell and the descent into its node, then each child in proportion to
        // its surface.
        double as_split = step + double(layout_.descent_cost);
        const double area = box_surface(region);
        std::size_t j = 0;
        for (int z = 0; z < r[2]; ++z)
            for (int y = 0; y < r[1]; ++y)
                for (int x = 0; x < r[0]; ++x, ++j) {
                    const int g[3] = {x, y, z};
                    const Box part = cell_box(region, l + 1, g, r);
                    const Built b = build(medium, bounds, l + 1, part, g, what);
                    parts[j] = b.packed();
                    if (with_lower_) part_lower[j] = b.lower;
                    lowest = std::min(lowest, b.lower);
                    if (j == 0) first = b.value;
                    as_split += box_surface(part) / area * b.cost;
                    uniform = uniform && b.node < 0 && b.value == first;
                }
        if (uniform || !(as_split < as_leaf)) {  // a constant tile, or a split that does not pay
            for (int m = l + 1; m < levels_; ++m) {
                cells_[m].resize(mark[m]);
                if (with_lower_) lower_[m].resize(mark[m]);
            }
            // A constant tile's parts all bound it from below too: the tightest of them (or the
            // cell's own lower bound, where that is tighter).
            return uniform ? Built{first, -1, step + double(first) * double(unit_) * mean_chord(region),
                                   std::min(first, std::max(lo, lowest))}
                           : Built{v, -1, as_leaf, lo};
        }
        if (cells_[l + 1].size() / k >= std::size_t(kSplit))
            fail(what, ": more than 2^31 nodes at level ", l + 1, "; a coarser layout is needed");
        const auto node = std::int32_t(cells_[l + 1].size() / k);
        cells_[l + 1].insert(cells_[l + 1].end(), parts.begin(), parts.end());
        if (with_lower_) lower_[l + 1].insert(lower_[l + 1].end(), part_lower.begin(), part_lower.end());
        return {v, node, as_split};
    }

    Box bounds_;
    TreeLayout layout_;
    int levels_;
    bool with_lower_ = false;
    Vec3 cell_[kMaxTreeSplits + 1]{}, inv_cell_[kMaxTreeSplits + 1]{};
    float unit_ = 1.f, pad_ = 1.f, scale_ = 1.f;
    /// Per level, its nodes' cells one after another, packed (node_cells).
    std::vector<std::uint32_t> cells_[kMaxTreeSplits + 1];
    /// Per level, parallel to cells_, each cell's density lower bound (only with_lower_).
    std::vector<float> lower_[kMaxTreeSplits + 1];
    // What the walk reads per step, precomputed.
    std::array<int, 3> res_[kMaxTreeSplits + 1]{};
    std::size_t stride_[kMaxTreeSplits + 1]{};
};

/// Walks a MajorantTree depth first: a DDA per level, entering a split cell's node where the
/// walk crosses it; yields the segments with a non-zero bound, each with value bound * unit.
/// The ray's part of every level's DDA (origin, direction, 1 / direction, steps) is stored once
/// and the walk's t is shared: a level holds only its node's origin, cells and next crossings, so
/// entering a node costs a few multiplications per axis (the walk held a full GridWalk per level
/// before, and cost twice a grid's walk per step). With kLower (a tree built with lower bounds),
/// `lower()` is the density lower bound of the cell of the segment `next` gave last (TreeControl).
template <CellBoundedMedium M, class V, bool kLower = false>
class TreeSegmentIterator {
public:
    TreeSegmentIterator() = default;
    TreeSegmentIterator(const MajorantTree<M>* tree, const Ray& r, float tmin, float tmax, const V& unit) noexcept
        : tree_(tree), unit_(unit) {
        const Interval in = tree->bounds().clip(r, tmin, tmax);
        if (!(in.t0 < in.t1)) return;  // depth_ = -1: nothing to walk
        t_ = in.t0;
        for (int a = 0; a < 3; ++a) {
            o_[a] = r.o[a];
            d_[a] = r.d[a];
            inv_[a] = dda_inverse(r.d[a]);
            step_[a] = dda_step(r.d[a]);
        }
        Level& L = level_[0];
        const Box& box = tree->layout().box;
        const Vec3& h = tree->cell_size(0);
        const auto& res = tree->level_res(0);
        for (int a = 0; a < 3; ++a) {
            L.lo[a] = box.lo[a];
            L.h[a] = h[a];
            L.res[a] = res[a];
            const int i = std::clamp(int(std::floor((r.o[a] + r.d[a] * t_ - box.lo[a]) / h[a])), 0, res[a] - 1);
            axis(L, a).locate(i, t_, L.cell[a], L.next[a]);
        }
        L.t_end = in.t1;
        L.done = false;
        L.cells = tree->node_cells(0, 0);
        if constexpr (kLower) L.lower = tree->node_lower(0, 0);
        depth_ = 0;
    }

    std::optional<MajorantSegment<V>> next() noexcept {
        while (depth_ >= 0) {
            Level& L = level_[depth_];
            if (L.done) {
                --depth_;
                continue;
            }
            ++steps_;
            int a = dda_axis(L.next);
            // A step that would leave the node before t_end is rounding (as in GridWalk).
            while (L.next[a] < L.t_end && (L.cell[a] + step_[a] < 0 || L.cell[a] + step_[a] >= L.res[a])) [[unlikely]] {
                L.next[a] = std::numeric_limits<float>::infinity();
                a = dda_axis(L.next);
            }
            const int c[3] = {L.cell[0], L.cell[1], L.cell[2]};
            const std::size_t i = std::size_t(c[0]) + std::size_t(L.res[0]) * (std::size_t(c[1]) + std::size_t(L.res[1]) * std::size_t(c[2]));
            const float t0 = t_, t1 = std::max(t_, std::min(L.next[a], L.t_end));
            t_ = t1;
            if (!(t1 < L.t_end)) {
                L.done = true;
            } else {
                L.cell[a] += step_[a];
                L.next[a] = axis(L, a).exit_t(L.cell[a]);
            }
            const std::uint32_t cell = L.cells[i];
            if (cell & MajorantTree<M>::kSplit) {  // a split cell: walk its node over [t0, t1]
                if (t1 > t0) enter(c, std::int32_t(cell & ~MajorantTree<M>::kSplit), t0, t1);
                continue;
            }
            const float v = std::bit_cast<float>(cell);
            if (v > 0.f && t1 > t0) {
                if constexpr (kLower) lower_ = L.lower[i];
                return MajorantSegment<V>{t0, t1, V(unit_ * v)};
            }
        }
        return std::nullopt;
    }

    /// DDA steps taken so far, at every level (empty cells included).
    std::uint32_t steps() const noexcept { return steps_; }
    /// The density lower bound of the last segment's cell (kLower only).
    float lower() const noexcept
        requires kLower
    {
        return lower_;
    }

private:
    /// One level's walk: its node's origin, cell size and cells per axis, the cell the walk is in
    /// and where it leaves it per axis, and where the walk of this node ends.
    struct Level {
        float lo[3], h[3], next[3];
        int res[3], cell[3];
        float t_end;
        bool done;
        const std::uint32_t* cells;  ///< the node's cells, packed (MajorantTree::node_cells)
        const float* lower;          ///< their density lower bounds (kLower only)
    };

    DdaAxis axis(const Level& L, int a) const noexcept { return {L.lo[a], L.h[a], o_[a], d_[a], inv_[a], L.res[a], step_[a]}; }

    /// Enters node `node` of the next level, which splits cell c of the current one, over [t0, t1].
    void enter(const int* c, std::int32_t node, float t0, float t1) noexcept {
        const Level& P = level_[depth_];
        const int l = depth_ + 1;
        Level& L = level_[l];
        const Vec3& h = tree_->cell_size(l);
        const Vec3& inv_h = tree_->inverse_cell_size(l);
        const auto& res = tree_->level_res(l);
        t_ = t0;
        for (int a = 0; a < 3; ++a) {
            L.lo[a] = P.lo[a] + float(c[a]) * P.h[a];  // the cell's corner, as MajorantTree::cell_box
            L.h[a] = h[a];
            L.res[a] = res[a];
            const int guess = std::clamp(int((o_[a] + d_[a] * t0 - L.lo[a]) * inv_h[a]), 0, res[a] - 1);
            axis(L, a).locate_near(guess, t0, L.cell[a], L.next[a]);
        }
        L.t_end = t1;
        L.done = false;
        L.cells = tree_->node_cells(l, node);
        if constexpr (kLower) L.lower = tree_->node_lower(l, node);
        depth_ = l;
    }

    const MajorantTree<M>* tree_ = nullptr;
    V unit_{};
    float o_[3]{}, d_[3]{}, inv_[3]{};
    int step_[3]{};
    float t_ = 0.f;
    int depth_ = -1;
    std::uint32_t steps_ = 0;
    float lower_ = 0.f;  ///< kLower only
    /// Left uninitialised until the walk enters that level: an iterator is made per flight, and
    /// zeroing every level each time cost more than the walk (measured).
    Level level_[kMaxTreeSplits + 1];
};

/// A layout over a medium's own bounds: `coarse` cells, each split once into brick^3.
template <CellBoundedMedium M>
TreeLayout layout_over_bounds(const M& medium, std::array<int, 3> coarse, int brick) {
    if (brick < 1 || brick > 64)
        fail("TreeMajorant brick = ", brick, " cells per coarse cell and axis is not allowed: it must lie in [1, 64]");
    return {medium.bounds(), coarse, {brick, 0, 0}, 0.3f};
}

/// The default layout over a medium's bounds: cubic-ish coarse cells, 16 along the longest axis
/// and proportionally fewer (at least 1) along the others (where the best grid majorant of
/// docs/majorants.md lies), each splitting into 4^3 and again into 4^3 where the cost model says
/// it pays (finest cells 1/256 of the longest extent). Measured on the sparse plume and the dense
/// cloud (docs/volumes.md), this adapts better than cells on a VDB tree's nodes, which ignore
/// where in a node the density lies, and than 8 coarse cells, which descend too often.
template <CellBoundedMedium M>
TreeLayout adaptive_layout(const M& medium) {
    const Box b = medium.bounds();
    const Vec3 e = b.hi - b.lo;
    const float longest = std::max({e.x, e.y, e.z});
    TreeLayout l{b, {1, 1, 1}, {4, 4, 0}, 0.3f, 1.f};
    for (int a = 0; a < 3; ++a)
        l.coarse[a] = longest > 0.f && std::isfinite(longest) ? std::clamp(int(std::lround(16.f * e[a] / longest)), 1, 16) : 1;
    return l;
}

}  // namespace detail

/// A grey tree majorant: per cell the bound of the density times the largest extinction per
/// unit density over every channel (and wavelength). `scale` multiplies every cell: >= 1 under
/// bound::Guaranteed; any value > 0 under bound::Signed, Clamp or Reject.
template <CellBoundedMedium M, BoundPolicy B = bound::Guaranteed>
class TreeMajorant {
public:
    using Bound = B;

    /// The adaptive layout over the medium's bounds (detail::adaptive_layout). For a medium with
    /// its own tree, TreeMajorant(medium, medium.tree_layout()) puts the cells on its nodes instead.
    explicit TreeMajorant(const M& medium, float scale = 1.f)
        : TreeMajorant(medium, detail::adaptive_layout(medium), scale) {}
    /// Over the medium's bounds: `coarse` cells per axis, each split into `brick`^3.
    TreeMajorant(const M& medium, std::array<int, 3> coarse, int brick, float scale = 1.f)
        : TreeMajorant(medium, detail::layout_over_bounds(medium, coarse, brick), scale) {}
    /// Throws InvalidArgument on a layout outside [1, 4096] coarse cells per axis (2^24 in all) or
    /// [1, 64] cells per split and axis, a box that does not contain the medium's
    /// bounds, a scale the policy does not allow, or a cell majorant that overflows, or rounds to
    /// 0 where the density is not 0.
    TreeMajorant(const M& medium, const TreeLayout& layout, float scale = 1.f)
        : tree_(medium, layout, detail::require_majorant_scale<B>(scale, "TreeMajorant scale"), "TreeMajorant"),
          unit_(max_value(detail::CellBounds<M>(medium, "TreeMajorant").unit())) {}

    detail::TreeSegmentIterator<M, float> iterate(const Ray& r, float tmin, float tmax,
                                                  const typename M::Spectral::Wavelengths&) const noexcept {
        return {&tree_, r, tmin, tmax, unit_};
    }

    /// The majorant at point p (its finest cell's; 0 outside the medium's bounds).
    float value_at(const Vec3& p, const typename M::Spectral::Wavelengths&) const noexcept {
        return tree_.at_point(p) * unit_;
    }
    TreeLayout layout() const noexcept { return tree_.layout(); }
    /// Coarse cells in all, split (per level l), and empty (the rest are uniform).
    std::size_t coarse_cells() const noexcept { return tree_.coarse_cells(); }
    std::size_t split_cells(int l = 0) const noexcept { return tree_.split_cells(l); }
    std::size_t empty_cells() const noexcept { return tree_.empty_cells(); }
    std::size_t memory_bytes() const noexcept { return tree_.memory_bytes(); }

private:
    detail::MajorantTree<M> tree_;
    float unit_;
};

/// A per-channel tree majorant: the tree's density bounds times each channel's extinction
/// per unit density at the path's wavelengths (THEORY 5.3). `scale` as for TreeMajorant.
template <CellBoundedMedium M, BoundPolicy B = bound::Guaranteed>
class ChannelTreeMajorant {
public:
    using Bound = B;
    using Spectral = typename M::Spectral;
    using Spectrum = typename Spectral::Spectrum;

    /// The adaptive layout over the medium's bounds, as TreeMajorant's.
    explicit ChannelTreeMajorant(const M& medium, float scale = 1.f)
        : ChannelTreeMajorant(medium, detail::adaptive_layout(medium), scale) {}
    ChannelTreeMajorant(const M& medium, std::array<int, 3> coarse, int brick, float scale = 1.f)
        : ChannelTreeMajorant(medium, detail::layout_over_bounds(medium, coarse, brick), scale) {}
    /// Throws as TreeMajorant does.
    ChannelTreeMajorant(const M& medium, const TreeLayout& layout, float scale = 1.f)
        : tree_(medium, layout, detail::require_majorant_scale<B>(scale, "ChannelTreeMajorant scale"),
                "ChannelTreeMajorant"),
          unit_(detail::CellBounds<M>(medium, "ChannelTreeMajorant").unit()) {}

    detail::TreeSegmentIterator<M, Spectrum> iterate(const Ray& r, float tmin, float tmax,
                                                     const typename Spectral::Wavelengths& l) const noexcept {
        return {&tree_, r, tmin, tmax, Spectral::sample(unit_, l)};
    }

    /// Every channel's majorant at point p (its finest cell's; 0 outside the medium's bounds).
    Spectrum value_at(const Vec3& p, const typename Spectral::Wavelengths& l) const noexcept {
        return Spectral::sample(unit_, l) * tree_.at_point(p);
    }
    TreeLayout layout() const noexcept { return tree_.layout(); }
    std::size_t coarse_cells() const noexcept { return tree_.coarse_cells(); }
    std::size_t split_cells(int l = 0) const noexcept { return tree_.split_cells(l); }
    std::size_t empty_cells() const noexcept { return tree_.empty_cells(); }
    std::size_t memory_bytes() const noexcept { return tree_.memory_bytes(); }

private:
    detail::MajorantTree<M> tree_;
    typename Spectral::Coefficient unit_;
};

}  // namespace nsp
