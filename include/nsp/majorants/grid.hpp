// nsp/majorants/grid.hpp: voxel-grid majorants walked by a 3D DDA (THEORY 4, step 1).
//
// A coarse grid over the medium's box stores, per cell, a bound of the density over that cell;
// along a ray the DDA visits the cells the ray crosses in order and yields one majorant segment
// per cell, so the free-flight loop (tracking.hpp) samples with a majorant that follows the
// medium. Cells whose bound is 0 are skipped: no collision is drawn there, so no lookup is paid.
// Only media that can bound their extinction over a region take a grid majorant (CellBoundedMedium:
// a density bound times a per-channel coefficient, RegionBoundedMedium, or a bound per channel,
// ExtinctionBoundedMedium, for media made of several grids): a homogeneous medium keeps its single
// segment and compiles no DDA code.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "../core/error.hpp"
#include "../majorant.hpp"
#include "../media/validate.hpp"
#include "../medium.hpp"

namespace nsp {

/// A medium whose extinction is a scalar density times a per-channel coefficient,
/// mu_t,c(p) = density(p) * extinction_per_density()_c, and that can bound the density its
/// lookup returns over any axis-aligned region (`density_bound(region)`, rounding included).
template <class M>
concept RegionBoundedMedium = ChannelBoundedMedium<M> && requires(const M& m, const Box& b) {
    { m.density_bound(b) } -> std::same_as<float>;
    { m.extinction_per_density() } -> std::same_as<typename M::Spectral::Coefficient>;
};

/// A medium whose extinction is not one density times a coefficient (several grids, a grid per
/// channel, an albedo grid beside a density) and that can bound its extinction per channel over
/// any axis-aligned region: `extinction_bound_over(region)` (rounding included). Only for spectral
/// modes whose coefficients are the channels themselves (Mono, Rgb).
template <class M>
concept ExtinctionBoundedMedium =
    ChannelBoundedMedium<M> && std::same_as<typename M::Spectral::Coefficient, typename M::Spectral::Spectrum> &&
    requires(const M& m, const Box& b) {
        { m.extinction_bound_over(b) } -> std::same_as<typename M::Spectral::Coefficient>;
    };

/// What grid and tree majorants need: a medium that bounds its extinction over any region, as a
/// density times a per-channel coefficient (RegionBoundedMedium) or per channel
/// (ExtinctionBoundedMedium).
template <class M>
concept CellBoundedMedium = RegionBoundedMedium<M> || ExtinctionBoundedMedium<M>;

namespace detail {

/// A CellBoundedMedium's bounds in the form the majorants store, a density per region times a
/// per-channel unit: a RegionBoundedMedium's own, or for an ExtinctionBoundedMedium the unit
/// u = its bound over its whole box and the density max_c bound_c(region) / u_c, so that density
/// x u_c >= bound_c in every channel (equal in the channel that sets it; where the channels do
/// not vary together the others get a looser bound).
template <CellBoundedMedium M>
class CellBounds {
public:
    using Coefficient = typename M::Spectral::Coefficient;

    CellBounds(const M& medium, const char* what) : medium_(medium), what_(what) {
        if constexpr (RegionBoundedMedium<M>) {
            unit_ = medium.extinction_per_density();
            require_coefficient(unit_, (std::string(what) + ": the medium's extinction per unit density").c_str());
        } else {
            unit_ = medium.extinction_bound_over(medium.bounds());
            require_coefficient(unit_, (std::string(what) + ": the medium's extinction bound over its bounds").c_str());
        }
    }

    const Coefficient& unit() const noexcept { return unit_; }

    /// The density bound over `region`; throws on a bound that is not finite and >= 0, or (per
    /// channel) one above 0 in a channel whose bound over the whole box is 0.
    float density(const Box& region) const {
        if constexpr (RegionBoundedMedium<M>) {
            return medium_.density_bound(region);
        } else {
            const Coefficient b = medium_.extinction_bound_over(region);
            float d = 0.f;
            for (int c = 0; c < int(b.size()); ++c) {
                if (!std::isfinite(b[c]) || b[c] < 0.f)
                    fail(what_, ": the medium's extinction bound over a cell = ", b[c], " in channel ", c,
                         " is not allowed: it must be finite and >= 0");
                if (!(b[c] > 0.f)) continue;
                if (!(unit_[c] > 0.f))
                    fail(what_, ": the medium's extinction bound over a cell = ", b[c], " in channel ", c,
                         " exceeds its bound over its whole box, ", unit_[c], ": a region's bound must not");
                d = std::max(d, b[c] / unit_[c]);
            }
            return d;
        }
    }

private:
    const M& medium_;
    const char* what_;
    Coefficient unit_{};
};

/// Relative padding of every grid-majorant cell over the density bound the medium states: it
/// covers the rounding of the product density * coefficient and of the channel sums (a few ulps;
/// this is 2^-16, about 500 ulps, so the bound holds for what the lookup actually returns).
inline constexpr float kGridMajorantPad = 1.f + 1.f / 65536.f;

/// The surface of box b, and a random line's mean chord through it, 4 V / S (Cauchy): what the
/// surface-area cost models of the tree majorant and of choose_grid_resolution weigh cells by.
inline double box_surface(const Box& b) noexcept {
    const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return 2.0 * (x * y + y * z + z * x);
}
inline double mean_chord(const Box& b) noexcept {
    const double x = double(b.hi.x) - b.lo.x, y = double(b.hi.y) - b.lo.y, z = double(b.hi.z) - b.lo.z;
    return 2.0 * x * y * z / (x * y + y * z + z * x);
}

/// One axis of a DDA: the planes lo + k h (k = 0 .. res) crossed by the ray o + t d, with inv =
/// 1 / d where that is finite (0 where d is 0 or denormal: the division is kept there) and step
/// the sign of d. Shared by GridWalk and the tree majorant's walk, so that both cross every plane
/// at the same t.
struct DdaAxis {
    float lo, h, o, d, inv;
    int res, step;

    /// Plane k, lo + k h: a cell face.
    float plane(int k) const noexcept { return lo + float(k) * h; }
    /// Where the ray crosses plane k (d != 0).
    float plane_t(int k) const noexcept { return inv != 0.f ? (plane(k) - o) * inv : (plane(k) - o) / d; }
    /// Where the ray leaves cell k, walking in the direction of d.
    float exit_t(int k) const noexcept { return plane_t(step > 0 ? k + 1 : k); }

    /// From a first guess i, the cell the walk is in at t (by the same plane crossings every walk
    /// of the ray computes) and the t at which it leaves it.
    void locate(int i, float t, int& cell, float& next) const noexcept {
        if (step > 0) {  // cell i spans [plane(i), plane(i + 1)) in t
            while (i > 0 && plane_t(i) > t) --i;
            while (i < res - 1 && plane_t(i + 1) <= t) ++i;
            next = plane_t(i + 1);
        } else if (step < 0) {  // cell i spans [plane(i + 1), plane(i)) in t
            while (i < res - 1 && plane_t(i + 1) > t) ++i;
            while (i > 0 && plane_t(i) <= t) --i;
            next = plane_t(i);
        } else {  // parallel: the cell holding o; a ray on a face takes the higher cell
            while (i < res - 1 && o >= plane(i + 1)) ++i;
            while (i > 0 && o < plane(i)) --i;
            next = std::numeric_limits<float>::infinity();
        }
        cell = i;
    }

    /// locate() for a guess at most one cell off (what a brick's entry computes), without
    /// branches on the ray's direction: one correction by selects, then a check that falls back to
    /// locate() where the guess was further off. Random directions made locate()'s loops a
    /// mispredicted branch per axis, most of a brick's entry cost (measured: 114 ns against 22 ns
    /// for repeated rays).
    void locate_near(int i, float t, int& cell, float& next) const noexcept {
        if (step == 0 || res == 1) [[unlikely]] {
            locate(i, t, cell, next);
            return;
        }
        const bool pos = step > 0;
        const float ta = plane_t(i), tb = plane_t(i + 1);
        // d > 0: cell i spans [t(i), t(i + 1)); d < 0: [t(i + 1), t(i)).
        const int down = pos ? int(ta > t) : int(ta <= t);
        const int up = pos ? int(tb <= t) : int(tb > t);
        const int j = std::clamp(i + up - down, 0, res - 1);
        const float lo_t = plane_t(j), hi_t = plane_t(j + 1);
        const bool ok = pos ? ((j == 0) | (lo_t <= t)) & ((j == res - 1) | (t < hi_t))
                            : ((j == res - 1) | (hi_t <= t)) & ((j == 0) | (t < lo_t));
        if (!ok) [[unlikely]] {
            locate(j, t, cell, next);
            return;
        }
        cell = j;
        next = pos ? hi_t : lo_t;
    }
};

/// 1 / d for a DDA (DdaAxis::inv): 0 where d is 0 or denormal (1 / d would be inf). Multiplying
/// by it instead of dividing saves a third of a DDA step.
inline float dda_inverse(float d) noexcept { return std::abs(d) >= std::numeric_limits<float>::min() ? 1.f / d : 0.f; }
/// The sign of d as a DDA's step.
inline int dda_step(float d) noexcept { return d > 0.f ? 1 : (d < 0.f ? -1 : 0); }

/// The index of the first of the three next-plane crossings (ties to the later axis, as the walk
/// has always stepped).
inline int dda_axis(const float* next) noexcept {
    return next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
}

/// The cells of a regular grid of `res` cells over `box` that a ray crosses within [t0, t1] (the
/// part of the ray inside the box), in increasing t (Amanatides and Woo 1987). Every cell face is
/// crossed at t = (plane - o) / d for its plane, whichever cell the walk starts in, so walks of
/// the same ray from different starts agree on every boundary they share. Rays parallel to an
/// axis (d = 0 there) never cross that axis' planes.
class GridWalk {
public:
    GridWalk() = default;

    GridWalk(const Box& box, const std::array<int, 3>& res, const Vec3& cell, const Ray& r, Interval in) noexcept
        : t_(in.t0), t_end_(in.t1), done_(!(in.t0 < in.t1)) {
        if (done_) return;
        for (int a = 0; a < 3; ++a) {
            lo_[a] = box.lo[a];
            h_[a] = cell[a];
            o_[a] = r.o[a];
            d_[a] = r.d[a];
            inv_[a] = dda_inverse(r.d[a]);
            res_[a] = res[a];
            step_[a] = dda_step(r.d[a]);
            const float p = r.o[a] + r.d[a] * t_;
            const int i = std::clamp(int(std::floor((p - box.lo[a]) / cell[a])), 0, res[a] - 1);
            axis(a).locate(i, t_, cell_[a], next_[a]);
        }
    }

    /// The next cell crossed (flat index x + nx (y + ny z)) and its stretch [t0, t1); false at the end.
    bool next(std::size_t& index, float& t0, float& t1) noexcept {
        if (done_) return false;
        ++steps_;
        int a = dda_axis(next_);
        // A step that would leave the grid before t_end is rounding (t_end is where the ray leaves
        // the grid's box): the cell covers the rest on that axis, so no stretch of [t0, t_end) is
        // left without a majorant, and the cell is not repeated.
        while (next_[a] < t_end_ && (cell_[a] + step_[a] < 0 || cell_[a] + step_[a] >= res_[a])) [[unlikely]] {
            next_[a] = std::numeric_limits<float>::infinity();
            a = dda_axis(next_);
        }
        index = std::size_t(cell_[0]) + std::size_t(res_[0]) * (std::size_t(cell_[1]) + std::size_t(res_[1]) * std::size_t(cell_[2]));
        t0 = t_;
        t1 = std::max(t_, std::min(next_[a], t_end_));
        t_ = t1;
        if (!(t1 < t_end_)) {
            done_ = true;
        } else {
            cell_[a] += step_[a];
            next_[a] = axis(a).exit_t(cell_[a]);
        }
        return true;
    }

    /// Cells visited so far (DDA steps).
    std::uint32_t steps() const noexcept { return steps_; }

private:
    DdaAxis axis(int a) const noexcept { return {lo_[a], h_[a], o_[a], d_[a], inv_[a], res_[a], step_[a]}; }

    float lo_[3]{}, h_[3]{}, o_[3]{}, d_[3]{}, inv_[3]{}, next_[3]{};
    int res_[3]{}, cell_[3]{}, step_[3]{};
    float t_ = 0.f, t_end_ = 0.f;
    std::uint32_t steps_ = 0;
    bool done_ = true;
};

/// The storage shared by the grey and per-channel grid majorants: per cell, a bound of the
/// density over the cell times kGridMajorantPad times the caller's scale.
template <CellBoundedMedium M>
class MajorantGrid {
public:
    MajorantGrid(const M& medium, std::array<int, 3> res, float scale, const char* what)
        : box_(medium.bounds()), res_(res) {
        const CellBounds<M> bounds(medium, what);
        std::size_t n = 1;
        for (int a = 0; a < 3; ++a) {
            if (res[a] < 1 || res[a] > 4096)
                fail(what, " resolution[", a, "] = ", res[a], " is not allowed: it must lie in [1, 4096]");
            n *= std::size_t(res[a]);
        }
        if (n > (std::size_t(1) << 28))
            fail(what, " resolution ", res[0], "x", res[1], "x", res[2], " has ", n,
                 " cells; at most 2^28 are allowed");
        // A host medium's bounds are not validated by nsp: the DDA divides by the cell size.
        for (int a = 0; a < 3; ++a) {
            if (!std::isfinite(box_.lo[a]) || !std::isfinite(box_.hi[a]) || !(box_.lo[a] < box_.hi[a]))
                fail(what, ": the medium's bounds on axis ", a, " are [", box_.lo[a], ", ", box_.hi[a],
                     "]; they must be finite with lo < hi");
            cell_[a] = (box_.hi[a] - box_.lo[a]) / float(res[a]);
            if (!std::isfinite(cell_[a]) || !(cell_[a] > 0.f))
                fail(what, " cell size on axis ", a, " = ", cell_[a], " (bounds [", box_.lo[a], ", ", box_.hi[a],
                     "] over resolution[", a, "] = ", res[a], ") is not allowed: it must be finite and > 0");
        }
        const float unit = max_value(bounds.unit());
        values_.resize(n);
        const float pad = kGridMajorantPad * scale;
        std::size_t i = 0;
        for (int z = 0; z < res[2]; ++z)
            for (int y = 0; y < res[1]; ++y)
                for (int x = 0; x < res[0]; ++x, ++i) {
                    const float d = bounds.density(region(x, y, z));
                    if (!std::isfinite(d) || d < 0.f)
                        fail(what, " cell (", x, ", ", y, ", ", z, "): the medium's density bound = ", d,
                             " is not allowed: it must be finite and >= 0");
                    values_[i] = d * pad;
                    // The policy's majorant must stay finite, and > 0 wherever the density may be.
                    if (!std::isfinite(values_[i] * unit))
                        fail(what, " cell (", x, ", ", y, ", ", z, ") majorant = density bound ", d, " x scale ",
                             scale, " x extinction per density ", unit, " = ", values_[i] * unit,
                             " is not allowed: it must be finite");
                    if (d * unit > 0.f && !(values_[i] * unit > 0.f))
                        fail(what, " cell (", x, ", ", y, ", ", z, ") majorant = density bound ", d, " x scale ",
                             scale, " x extinction per density ", unit, " rounds to 0 where the extinction may be ",
                             d * unit, "; it must be > 0 there (no collision would be sampled)");
                }
    }

    GridWalk walk(const Ray& r, float tmin, float tmax) const noexcept {
        return {box_, res_, cell_, r, box_.clip(r, tmin, tmax)};
    }

    /// The region of cell (x, y, z): its faces at lo + k cell, the last one on each axis ending
    /// at the box's face (so that the cells cover the box exactly).
    Box region(int x, int y, int z) const noexcept {
        const int c[3] = {x, y, z};
        Box r;
        for (int a = 0; a < 3; ++a) {
            r.lo[a] = box_.lo[a] + float(c[a]) * cell_[a];
            r.hi[a] = c[a] + 1 == res_[a] ? box_.hi[a] : box_.lo[a] + float(c[a] + 1) * cell_[a];
        }
        return r;
    }

    /// The value of the cell holding point p (faces rounded to the cell above, clamped to the
    /// grid), 0 outside the box.
    float at_point(const Vec3& p) const noexcept { return box_.contains(p) ? values_[index_at(p)] : 0.f; }

    /// The index into data() of the cell holding point p of the box (faces rounded to the cell
    /// above, clamped to the grid).
    std::size_t index_at(const Vec3& p) const noexcept {
        int c[3];
        for (int a = 0; a < 3; ++a) c[a] = std::clamp(int((p[a] - box_.lo[a]) / cell_[a]), 0, res_[a] - 1);
        return std::size_t(c[0]) + std::size_t(res_[0]) * (std::size_t(c[1]) + std::size_t(res_[1]) * std::size_t(c[2]));
    }

    /// The value of cell (x, y, z).
    float at(int x, int y, int z) const noexcept {
        return values_[std::size_t(x) + std::size_t(res_[0]) * (std::size_t(y) + std::size_t(res_[1]) * std::size_t(z))];
    }
    const float* data() const noexcept { return values_.data(); }
    std::array<int, 3> resolution() const noexcept { return res_; }
    std::size_t memory_bytes() const noexcept { return values_.size() * sizeof(float); }
    Box box() const noexcept { return box_; }
    Vec3 cell_size() const noexcept { return cell_; }

private:
    Box box_;
    std::array<int, 3> res_;
    Vec3 cell_{1.f};
    std::vector<float> values_;
};

/// Walks a MajorantGrid and yields the segments of the cells with a non-zero bound, each with
/// value bound * unit (a float, or one value per channel).
template <class V>
class GridSegmentIterator {
public:
    GridSegmentIterator() = default;
    GridSegmentIterator(const float* values, GridWalk walk, const V& unit) noexcept
        : values_(values), walk_(walk), unit_(unit) {}

    std::optional<MajorantSegment<V>> next() noexcept {
        std::size_t i;
        float t0, t1;
        while (walk_.next(i, t0, t1)) {
            const float v = values_[i];
            if (v > 0.f && t1 > t0) return MajorantSegment<V>{t0, t1, V(unit_ * v)};
        }
        return std::nullopt;
    }

    /// DDA steps taken so far (every cell crossed, skipped ones included).
    std::uint32_t steps() const noexcept { return walk_.steps(); }

private:
    const float* values_ = nullptr;
    GridWalk walk_;
    V unit_{};
};

}  // namespace detail

/// A grey voxel-grid majorant: one float per cell, the bound of the density over the cell times
/// the largest extinction per unit density over every channel (and wavelength), walked by a DDA.
/// `scale` multiplies every cell: >= 1 under bound::Guaranteed; any value > 0 under bound::Signed,
/// Clamp or Reject (e.g. 0.5 to go faster with a majorant that does not bound the density).
template <CellBoundedMedium M, BoundPolicy B = bound::Guaranteed>
class GridMajorant {
public:
    using Bound = B;

    /// Throws InvalidArgument on a resolution outside [1, 4096] per axis (2^28 cells in all), a
    /// scale the policy does not allow, a medium whose bounds are not finite, or a cell majorant
    /// that overflows, or rounds to 0 where the density is not 0.
    GridMajorant(const M& medium, std::array<int, 3> resolution, float scale = 1.f)
        : grid_(medium, resolution, detail::require_majorant_scale<B>(scale, "GridMajorant scale"), "GridMajorant"),
          unit_(max_value(detail::CellBounds<M>(medium, "GridMajorant").unit())) {}
    GridMajorant(const M& medium, int resolution, float scale = 1.f)
        : GridMajorant(medium, {resolution, resolution, resolution}, scale) {}

    detail::GridSegmentIterator<float> iterate(const Ray& r, float tmin, float tmax,
                                               const typename M::Spectral::Wavelengths&) const noexcept {
        return {grid_.data(), grid_.walk(r, tmin, tmax), unit_};
    }

    /// The majorant of cell (x, y, z).
    float cell(int x, int y, int z) const noexcept { return grid_.at(x, y, z) * unit_; }
    /// The majorant at point p (its cell's; 0 outside the medium's box): one lookup, no walk.
    float value_at(const Vec3& p, const typename M::Spectral::Wavelengths&) const noexcept {
        return grid_.at_point(p) * unit_;
    }
    std::array<int, 3> resolution() const noexcept { return grid_.resolution(); }
    Vec3 cell_size() const noexcept { return grid_.cell_size(); }
    /// Bytes of cell storage (one float per cell).
    std::size_t memory_bytes() const noexcept { return grid_.memory_bytes(); }

private:
    detail::MajorantGrid<M> grid_;
    float unit_;
};

/// A per-channel voxel-grid majorant (THEORY 5.3 with a grid): one float per cell, the bound of
/// the density over the cell, times each channel's extinction per unit density at the path's
/// wavelengths; every channel's majorant follows the medium and its own coefficient. `scale` as
/// for GridMajorant.
template <CellBoundedMedium M, BoundPolicy B = bound::Guaranteed>
class ChannelGridMajorant {
public:
    using Bound = B;
    using Spectral = typename M::Spectral;
    using Spectrum = typename Spectral::Spectrum;

    /// Throws as GridMajorant does.
    ChannelGridMajorant(const M& medium, std::array<int, 3> resolution, float scale = 1.f)
        : grid_(medium, resolution, detail::require_majorant_scale<B>(scale, "ChannelGridMajorant scale"), "ChannelGridMajorant"),
          unit_(detail::CellBounds<M>(medium, "ChannelGridMajorant").unit()) {}
    ChannelGridMajorant(const M& medium, int resolution, float scale = 1.f)
        : ChannelGridMajorant(medium, {resolution, resolution, resolution}, scale) {}

    detail::GridSegmentIterator<Spectrum> iterate(const Ray& r, float tmin, float tmax,
                                                  const typename Spectral::Wavelengths& l) const noexcept {
        return {grid_.data(), grid_.walk(r, tmin, tmax), Spectral::sample(unit_, l)};
    }

    /// Every channel's majorant in cell (x, y, z) at wavelengths l.
    Spectrum cell(int x, int y, int z, const typename Spectral::Wavelengths& l) const noexcept {
        return Spectral::sample(unit_, l) * grid_.at(x, y, z);
    }
    /// Every channel's majorant at point p (its cell's; 0 outside the medium's box).
    Spectrum value_at(const Vec3& p, const typename Spectral::Wavelengths& l) const noexcept {
        return Spectral::sample(unit_, l) * grid_.at_point(p);
    }
    std::array<int, 3> resolution() const noexcept { return grid_.resolution(); }
    Vec3 cell_size() const noexcept { return grid_.cell_size(); }
    /// Bytes of cell storage (one float per cell; the channels share it).
    std::size_t memory_bytes() const noexcept { return grid_.memory_bytes(); }

private:

    detail::MajorantGrid<M> grid_;
    typename Spectral::Coefficient unit_;
};

}  // namespace nsp
