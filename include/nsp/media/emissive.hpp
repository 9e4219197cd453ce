// nsp/media/emissive.hpp: emissive media (THEORY 5.7): a voxel grid of emission strength, a
// wrapper that adds emission L_e(p) to any medium, and a sampler of points in proportion to a
// coarse grid of emitted power, the volume pdf p_V(y) of next-event estimation toward the volume.
//
// The volume source term is mu_a(p) L_e(p). Estimators branch with `if constexpr
// (EmissiveMedium<M>)`, so a medium without emission compiles no emission code (STYLE rule 4).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "../core/error.hpp"
#include "../equiangular.hpp"
#include "../majorant.hpp"
#include "../majorants/grid.hpp"
#include "../majorants/tree.hpp"
#include "../medium.hpp"
#include "grid.hpp"
#include "validate.hpp"

namespace nsp {

/// A point drawn in volume measure and its density there, per unit volume (pdf 0: no sample).
struct VolumeSample {
    Vec3 p{0.f};
    float pdf = 0.f;
};

/// A medium that also emits. Besides the Medium requirements it provides:
/// - `emission(p, lambda)`: the emitted radiance L_e(p) per channel, finite and >= 0 (the source
///   term of the transport equation is mu_a(p) L_e(p));
/// - `sample_emission(u0, u1, u2, u3)`: a point y with its volume pdf p_V(y), > 0 wherever
///   mu_a L_e can be > 0 (pdf 0 when nothing emits);
/// - `emission_pdf(p)`: the density with which sample_emission draws p, equal to the pdf it
///   reports for that point;
/// - `emission_along(ray, t0, t1)`: W, the integral of emission_pdf(ray.at(t)) over [t0, t1)
///   (ray.d a unit vector), and `sample_emission_along(ray, t0, t1, W, u)`: a distance drawn with
///   density emission_pdf(ray.at(t)) / W there, the segment technique of the estimators.
template <class M>
concept EmissiveMedium = Medium<M> &&
    requires(const M& m, const Vec3& p, const typename M::Spectral::Wavelengths& l, float u, const Ray& r) {
        { m.emission(p, l) } -> std::same_as<typename M::Spectral::Spectrum>;
        { m.sample_emission(u, u, u, u) } -> std::same_as<VolumeSample>;
        { m.emission_pdf(p) } -> std::same_as<float>;
        { m.emission_along(r, u, u) } -> std::same_as<float>;
        { m.sample_emission_along(r, u, u, u, u) } -> std::same_as<DistanceSample>;
    };

/// A dense scalar grid over a box, e.g. an emission strength derived from temperature, stored
/// beside the density like a flame: value(p) trilinear between voxel centres, clamped at the
/// faces, zero outside `bounds` (the convention of DenseGridMedium::density). Voxel (x, y, z) is
/// at index x + nx * (y + ny * z). Read-only after construction.
class EmissionGrid {
public:
    /// Throws InvalidArgument on an empty or non-finite box, a resolution below 1 (or with more
    /// voxels than a vector holds), an empty grid, a size that does not match `resolution`, or a
    /// negative or non-finite value.
    EmissionGrid(const Box& bounds, std::array<int, 3> resolution, std::vector<float> values)
        : bounds_(bounds), res_(resolution), values_(std::move(values)) {
        detail::require_box(bounds, "EmissionGrid bounds");
        for (int a = 0; a < 3; ++a)
            if (res_[a] < 1)
                detail::fail("EmissionGrid resolution[", a, "] = ", res_[a],
                             " is not allowed: every axis needs at least 1 voxel");
        const std::size_t n = detail::voxel_count(res_, values_.max_size(), "EmissionGrid");
        if (values_.empty())
            detail::fail("EmissionGrid: the value grid is empty; resolution ", res_[0], "x", res_[1], "x", res_[2],
                         " needs ", n, " values");
        if (values_.size() != n)
            detail::fail("EmissionGrid: ", values_.size(), " values given, but resolution ", res_[0], "x",
                         res_[1], "x", res_[2], " needs ", n);
        for (std::size_t i = 0; i < n; ++i)
            if (!std::isfinite(values_[i]) || values_[i] < 0.f)
                detail::fail("EmissionGrid: value[", i, "] = ", values_[i],
                             " is not allowed: emission values must be finite and >= 0");
        max_ = *std::max_element(values_.begin(), values_.end());
        inv_extent_ = 1.f / (bounds_.hi - bounds_.lo);
    }

    Box bounds() const noexcept { return bounds_; }
    std::array<int, 3> resolution() const noexcept { return res_; }

    /// The trilinearly interpolated value at p (zero outside the box).
    float value(const Vec3& p) const noexcept {
        return detail::trilinear_lookup(values_.data(), res_, bounds_, inv_extent_, p);
    }

    /// The largest value a lookup can return at any p in `region` (0 if it misses the box), with
    /// the region widened by 1/1000 of a voxel for rounding (as DenseGridMedium::density_bound).
    float bound(const Box& region) const noexcept {
        return detail::voxel_bound(values_.data(), res_, bounds_, inv_extent_, region);
    }

    /// The largest voxel value (bounds value(p) everywhere: trilinear weights are convex).
    float max_value() const noexcept { return max_; }

private:
    Box bounds_;
    std::array<int, 3> res_;
    std::vector<float> values_;
    float max_ = 0.f;
    Vec3 inv_extent_{1.f};
};

/// Where and how much a medium emits: the emission field an Emissive medium carries. It provides
/// - `radiance(p, lambda)`: L_e(p) per channel at the path's wavelengths, finite and >= 0;
/// - `may_emit(region)`: false only where radiance is 0 everywhere in the box `region` (the power
///   grid gives every other cell a floor, so NEE toward the volume stays unbiased);
/// - `bounds()`: a box outside which radiance is 0.
template <class E, class S>
concept EmissionField = requires(const E& e, const Vec3& p, const typename S::Wavelengths& l, const Box& b) {
    { e.radiance(p, l) } -> std::same_as<typename S::Spectrum>;
    { e.may_emit(b) } -> std::same_as<bool>;
    { e.bounds() } -> std::same_as<Box>;
};

/// The default emission field: a grid of emission strength times a fixed spectrum,
/// L_e(p) = grid.value(p) * radiance_scale (per channel, or at the path's wavelengths in Hero mode).
template <SpectralMode S>
class GridEmission {
public:
    using Spectrum = typename S::Spectrum;
    using Coefficient = typename S::Coefficient;

    /// Throws InvalidArgument on a negative or non-finite radiance_scale channel, or a largest
    /// emission (grid max x radiance_scale max) that overflows.
    GridEmission(EmissionGrid grid, const Coefficient& radiance_scale)
        : grid_(std::move(grid)), scale_(radiance_scale) {
        detail::require_coefficient(scale_, "Emissive radiance_scale");
        const float le_max = grid_.max_value() * max_value(scale_);
        if (!std::isfinite(le_max))
            detail::fail("Emissive: the largest emission L_e = emission grid max ", grid_.max_value(),
                         " x radiance_scale max ", max_value(scale_), " = ", le_max,
                         " is not allowed: it must be finite (at most ", std::numeric_limits<float>::max(), ")");
    }

    Spectrum radiance(const Vec3& p, const typename S::Wavelengths& l) const noexcept {
        const float v = grid_.value(p);
        if (v == 0.f) return Spectrum::Zero();
        return S::sample(scale_, l) * v;
    }
    bool may_emit(const Box& region) const noexcept { return max_value(scale_) > 0.f && grid_.bound(region) > 0.f; }
    Box bounds() const noexcept { return grid_.bounds(); }

    const EmissionGrid& grid() const noexcept { return grid_; }
    const Coefficient& radiance_scale() const noexcept { return scale_; }

private:
    EmissionGrid grid_;
    Coefficient scale_;
};

namespace detail {

/// Power-grid build: sub-points per cell and axis (4 x 4 x 4 = 64 stratified lookups per cell).
inline constexpr int kPowerSubpoints = 4;
/// Power-grid build, Hero modes: at least this many wavelengths, evenly spread over the range.
inline constexpr int kPowerWavelengths = 16;
/// The floor added to every cell that may emit, relative to the mean estimate of the cells whose
/// estimate is positive (see Emissive).
inline constexpr double kPowerFloor = 1e-3;

}  // namespace detail

/// Medium M with emission L_e(p) from an emission field E: by default (GridEmission)
/// emission.value(p) * radiance_scale per channel (at the path's wavelengths in Hero mode); a
/// temperature grid's blackbody radiance with BlackbodyEmission. M's coefficients, bounds and
/// majorant support are forwarded unchanged, so every majorant that takes M takes Emissive<M, E>
/// and tracks it identically.
///
/// At construction a coarse grid of emitted power is built over the intersection of the emission
/// field's box and the medium's bounds (`power_resolution` cells), for sample_emission. Per cell the
/// estimate is the cell volume times the mean, over 4 x 4 x 4 stratified sub-points (sub-cell
/// centres), of mean_c mu_a,c(p) L_e,c(p), the channel mean. Mono and Rgb evaluate it at their
/// channels; Hero<N> averages it over ceil(16 / N) wavelength sets that together place 16 or more
/// wavelengths at the centres of equal bins of [kLambdaMin, kLambdaMax] (N ceil(16 / N) bins).
///
/// The estimate may miss emission between sub-points (or between those wavelengths), so every cell
/// that may emit gets a floor added: 1e-3 of the mean estimate over the cells whose estimate is
/// positive (or 1, i.e. uniform over such cells, when every estimate is 0). A cell may emit when
/// the field says it may (for GridEmission: the grid's bound over it is > 0 and max over
/// wavelengths of radiance_scale is > 0) and the medium may be non-zero there: its density bound over the cell is > 0 (a RegionBoundedMedium M)
/// or max_extinction() > 0 (any other M). So the pdf is > 0 wherever mu_a L_e can be > 0 and NEE
/// toward emission stays unbiased. Cell probabilities are floats: one below 2^-24 (the resolution
/// of a float uniform u0) is chosen with a rounded probability.
template <Medium M, EmissionField<typename M::Spectral> E = GridEmission<typename M::Spectral>>
class Emissive {
public:
    using Spectral = typename M::Spectral;
    using Spectrum = typename Spectral::Spectrum;
    using Wavelengths = typename Spectral::Wavelengths;
    using Coefficient = typename Spectral::Coefficient;
    using Field = E;

    /// Medium M emitting as `field` says (e.g. BlackbodyEmission, media/blackbody.hpp). Throws
    /// InvalidArgument on a power_resolution outside [1, 256] on some axis, or a power grid whose
    /// cells are too thin to be told apart in float.
    Emissive(M medium, E field, std::array<int, 3> power_resolution = {16, 16, 16})
        : medium_(std::move(medium)), field_(std::move(field)), res_(power_resolution) {
        for (int a = 0; a < 3; ++a)
            if (res_[a] < 1 || res_[a] > 256)
                detail::fail("Emissive power_resolution[", a, "] = ", res_[a],
                             " is not allowed: it must lie in [1, 256]");
        build_power_grid();
    }

    /// The default field: L_e(p) = emission.value(p) * radiance_scale. Throws InvalidArgument on a
    /// negative or non-finite radiance_scale channel, a largest emission (grid max x
    /// radiance_scale max) that overflows, or as the constructor above.
    Emissive(M medium, EmissionGrid emission, const Coefficient& radiance_scale,
             std::array<int, 3> power_resolution = {16, 16, 16})
        requires std::same_as<E, GridEmission<Spectral>>
        : Emissive(std::move(medium), E(std::move(emission), radiance_scale), power_resolution) {}

    /// The wrapped medium.
    const M& base() const noexcept { return medium_; }
    /// The emission field.
    const E& emission_field() const noexcept { return field_; }
    /// The emission grid and L_e per unit grid value (the default field).
    const EmissionGrid& emission_grid() const noexcept
        requires std::same_as<E, GridEmission<Spectral>>
    {
        return field_.grid();
    }
    const Coefficient& radiance_scale() const noexcept
        requires std::same_as<E, GridEmission<Spectral>>
    {
        return field_.radiance_scale();
    }

    // The Medium API, forwarded.
    Box bounds() const noexcept { return medium_.bounds(); }
    Coefficients<Spectral> coefficients(const Vec3& p, const Wavelengths& l) const noexcept {
        return medium_.coefficients(p, l);
    }
    Spectrum extinction_bound(const Wavelengths& l) const noexcept { return medium_.extinction_bound(l); }
    float max_extinction() const noexcept { return medium_.max_extinction(); }

    // The optional majorant support of M (ChannelBoundedMedium, RegionBoundedMedium,
    // ExtinctionBoundedMedium), forwarded.
    Coefficient extinction_bound_coefficient() const
        requires ChannelBoundedMedium<M>
    {
        return medium_.extinction_bound_coefficient();
    }
    float density_bound(const Box& region) const noexcept
        requires RegionBoundedMedium<M>
    {
        return medium_.density_bound(region);
    }
    float density_lower_bound(const Box& region) const noexcept
        requires RegionBoundedMedium<M> && requires(const M& m, const Box& b) { m.density_lower_bound(b); }
    {
        return medium_.density_lower_bound(region);
    }
    Coefficient extinction_per_density() const
        requires RegionBoundedMedium<M>
    {
        return medium_.extinction_per_density();
    }
    Coefficient extinction_bound_over(const Box& region) const
        requires ExtinctionBoundedMedium<M>
    {
        return medium_.extinction_bound_over(region);
    }
    /// The layout of M's own tree (TreeLayoutMedium), with whatever arguments M takes.
    template <class... A>
        requires requires(const M& m, A... a) {
            { m.tree_layout(a...) } -> std::same_as<TreeLayout>;
        }
    TreeLayout tree_layout(A... a) const noexcept {
        return medium_.tree_layout(a...);
    }

    /// The emitted radiance L_e(p) at wavelengths l, per channel (0 outside the emission grid).
    Spectrum emission(const Vec3& p, const Wavelengths& l) const noexcept { return field_.radiance(p, l); }

    /// A point y drawn in proportion to the power grid: a cell chosen by its probability (u0),
    /// then a uniform point in it (u1, u2, u3), all in [0, 1). pdf = P(cell) / cell volume, per
    /// unit volume; pdf 0 when no cell may emit. The point lies in the chosen cell as emission_pdf
    /// locates it, so emission_pdf(y) equals the pdf returned.
    VolumeSample sample_emission(float u0, float u1, float u2, float u3) const noexcept {
        if (prob_.empty()) return {};
        // The cell whose CDF interval [cdf[i], cdf[i + 1]) holds u0: zero-probability cells have
        // empty intervals and cdf[n] = 1 > u0, so the cell found has a positive probability.
        const float u = unit(u0);
        const std::size_t n = prob_.size();
        std::size_t i = std::size_t(std::upper_bound(cdf_.begin() + 1, cdf_.end(), u) - cdf_.begin()) - 1;
        i = std::min(i, n - 1);
        const std::size_t nx = std::size_t(res_[0]), ny = std::size_t(res_[1]);
        const int c[3] = {int(i % nx), int((i / nx) % ny), int(i / (nx * ny))};
        const float uu[3] = {unit(u1), unit(u2), unit(u3)};
        Vec3 p;
        for (int a = 0; a < 3; ++a) {
            const float x0 = plane(a, c[a]), x1 = plane(a, c[a] + 1);
            float x = std::max(x0 + uu[a] * (x1 - x0), x0);
            // Cells are half-open [x0, x1) except the last, which holds its far face: keep the
            // rounded point in the cell that cell_on_axis finds.
            if (c[a] + 1 < res_[a]) {
                if (x >= x1) x = std::nextafter(x1, x0);
            } else {
                x = std::min(x, x1);
            }
            p[a] = x;
        }
        return {p, prob_[i] * inv_cell_volume_};
    }

    /// The density per unit volume with which sample_emission draws p (0 outside the power grid
    /// or when nothing emits).
    float emission_pdf(const Vec3& p) const noexcept {
        if (prob_.empty() || !box_.contains(p)) return 0.f;
        const std::size_t i = std::size_t(cell_on_axis(0, p.x)) +
                              std::size_t(res_[0]) * (std::size_t(cell_on_axis(1, p.y)) +
                                                      std::size_t(res_[1]) * std::size_t(cell_on_axis(2, p.z)));
        return prob_[i] * inv_cell_volume_;
    }

    /// W = the integral of emission_pdf(ray.at(t)) over t in [t0, t1) (ray.d a unit vector): the
    /// normaliser of the segment technique, which draws a point on a ray in proportion to the
    /// power grid (THEORY 5.7). Walked cell by cell through the power grid; 0 when the stretch
    /// meets no cell that may emit (or t0 >= t1).
    float emission_along(const Ray& ray, float t0, float t1) const noexcept {
        if (prob_.empty()) return 0.f;
        detail::GridWalk walk(box_, res_, cell_, ray, box_.clip(ray, t0, t1));
        double sum = 0.0;  // prob x length: the cell volume divides once at the end
        std::size_t i;
        float a, b;
        while (walk.next(i, a, b)) sum += double(prob_[i]) * double(b - a);
        return float(sum * double(inv_cell_volume_));
    }

    /// A distance t in [t0, t1) on `ray` drawn from u in [0, 1) with density emission_pdf(ray.at(t))
    /// / total, where total = emission_along(ray, t0, t1): a cell of the walk chosen in proportion
    /// to prob x length, then t uniform in its stretch. The pdf returned is that cell's density
    /// over total (where t lies on a cell face within rounding, emission_pdf may locate ray.at(t)
    /// in the neighbour). pdf 0 when total is not > 0.
    DistanceSample sample_emission_along(const Ray& ray, float t0, float t1, float total, float u) const noexcept {
        if (prob_.empty() || !(total > 0.f)) return {};
        detail::GridWalk walk(box_, res_, cell_, ray, box_.clip(ray, t0, t1));
        const double target = double(unit(u)) * double(total) / double(inv_cell_volume_);
        double run = 0.0;
        std::size_t i;
        float a, b;
        DistanceSample last;
        while (walk.next(i, a, b)) {
            const double m = double(prob_[i]) * double(b - a);
            if (!(m > 0.0)) continue;
            const float pdf = prob_[i] * inv_cell_volume_ / total;
            const float end = std::nextafter(b, a);  // b > a here: the stretch is [a, b)
            if (run + m > target) {
                const float t = a + float((target - run) / double(prob_[i]));
                return {std::clamp(t, a, end), pdf};
            }
            run += m;
            last = {end, pdf};
        }
        return last;  // target rounded past the last cell: the end of the last one that may emit
    }

    /// The estimated integral over the power grid of the channel mean of mu_a L_e (radiance
    /// times area), before the floor: 0 when the sub-points saw no emission.
    float total_power_estimate() const noexcept { return float(total_power_); }
    /// Cells of the power grid per axis.
    std::array<int, 3> power_resolution() const noexcept { return res_; }
    /// The power grid's box: the emission grid's box clipped to the medium's bounds.
    Box power_box() const noexcept { return box_; }
    /// Bytes of power-grid storage (a probability and a CDF entry per cell).
    std::size_t power_memory_bytes() const noexcept { return (prob_.size() + cdf_.size()) * sizeof(float); }

private:
    /// Plane k of axis a of the power grid (k = res is the box's far face, exactly).
    float plane(int a, int k) const noexcept { return k == res_[a] ? box_.hi[a] : box_.lo[a] + float(k) * cell_[a]; }

    /// The cell k of axis a with plane(k) <= x < plane(k + 1) (the last cell also holds its far
    /// face), for x inside the box: a rounded guess, fixed up against the planes themselves.
    int cell_on_axis(int a, float x) const noexcept {
        int k = std::clamp(int(std::floor((x - box_.lo[a]) / cell_[a])), 0, res_[a] - 1);
        while (k > 0 && x < plane(a, k)) --k;
        while (k < res_[a] - 1 && x >= plane(a, k + 1)) ++k;
        return k;
    }

    /// u clamped to [0, 1) (NaN to 0), so a host generator that returns 1 cannot leave the grid.
    static float unit(float u) noexcept { return u >= 0.f ? std::min(u, 0x1.fffffep-1f) : 0.f; }

    /// The scalar the power grid integrates at p: mean_c mu_a,c(p) L_e,c(p), in double (THEORY 5.7).
    double power_density(const Vec3& p) const {
        auto at = [&](const Wavelengths& l) {
            const Spectrum le = field_.radiance(p, l);
            if (!(le > 0.f).any()) return 0.0;
            const Spectrum sa = medium_.coefficients(p, l).sigma_a;
            double s = 0.0;
            for (int c = 0; c < Spectral::channels; ++c) s += double(sa[c]) * double(le[c]);
            return s / double(Spectral::channels);
        };
        if constexpr (is_hero_v<Spectral>) {
            constexpr int n = Spectral::channels, sets = (detail::kPowerWavelengths + n - 1) / n;
            // Set k rotates the hero wavelengths by (k + 1/2) / (sets n): together the sets place one
            // wavelength at the centre of each of sets * n equal bins of the range.
            double s = 0.0;
            for (int k = 0; k < sets; ++k) s += at(Wavelengths::sample((float(k) + 0.5f) / float(sets * n)));
            return s / double(sets);
        } else {
            return at(Wavelengths{});
        }
    }

    /// True when the medium may be non-zero somewhere in `cell` (a superset of where mu_a > 0).
    bool medium_may_absorb(const Box& cell) const {
        if constexpr (RegionBoundedMedium<M>)
            return medium_.density_bound(cell) > 0.f && max_value(medium_.extinction_per_density()) > 0.f;
        else if constexpr (ExtinctionBoundedMedium<M>)
            return max_value(medium_.extinction_bound_over(cell)) > 0.f;
        else
            return medium_.max_extinction() > 0.f;
    }

    void build_power_grid() {
        const Box mb = medium_.bounds(), eb = field_.bounds();
        for (int a = 0; a < 3; ++a) {
            box_.lo[a] = std::max(mb.lo[a], eb.lo[a]);
            box_.hi[a] = std::min(mb.hi[a], eb.hi[a]);
            if (!(box_.lo[a] < box_.hi[a])) return;  // no overlap, or one of zero volume: nothing emits
        }
        for (int a = 0; a < 3; ++a) {
            cell_[a] = (box_.hi[a] - box_.lo[a]) / float(res_[a]);
            for (int k = 0; k < res_[a]; ++k)
                if (!(plane(a, k) < plane(a, k + 1)))
                    detail::fail("Emissive: the power grid over [", box_.lo[a], ", ", box_.hi[a], "] on axis ", a,
                                 " has cells too thin for float at power_resolution[", a, "] = ", res_[a],
                                 "; choose a lower resolution");
        }
        inv_cell_volume_ = 1.f / (cell_[0] * cell_[1] * cell_[2]);
        if (!std::isfinite(inv_cell_volume_))
            detail::fail("Emissive: the power grid's cells have volume ", cell_[0] * cell_[1] * cell_[2],
                         ", too small for a float pdf: 1 / volume must be finite; choose a lower power_resolution "
                         "or a larger box");

        // Step 1: per cell, the estimate (mean of the sub-point values) and whether it may emit.
        const std::size_t n = std::size_t(res_[0]) * std::size_t(res_[1]) * std::size_t(res_[2]);
        std::vector<double> estimate(n, 0.0);
        std::vector<char> may_emit(n, 0);
        constexpr int s = detail::kPowerSubpoints;
        std::size_t i = 0;
        for (int z = 0; z < res_[2]; ++z)
            for (int y = 0; y < res_[1]; ++y)
                for (int x = 0; x < res_[0]; ++x, ++i) {
                    const int c[3] = {x, y, z};
                    Box cell;
                    for (int a = 0; a < 3; ++a) {
                        cell.lo[a] = plane(a, c[a]);
                        cell.hi[a] = plane(a, c[a] + 1);
                    }
                    may_emit[i] = field_.may_emit(cell) && medium_may_absorb(cell);
                    if (!may_emit[i]) continue;
                    double sum = 0.0;
                    for (int k = 0; k < s * s * s; ++k) {
                        const int sub[3] = {k % s, (k / s) % s, k / (s * s)};
                        Vec3 p;
                        for (int a = 0; a < 3; ++a)
                            p[a] = cell.lo[a] + (float(sub[a]) + 0.5f) / float(s) * (cell.hi[a] - cell.lo[a]);
                        sum += power_density(p);
                    }
                    estimate[i] = sum / double(s * s * s);
                }

        // Step 2: the floor, 1e-3 of the mean positive estimate (1 if none is positive).
        double positive_sum = 0.0, positive_count = 0.0;
        for (double e : estimate)
            if (e > 0.0) positive_sum += e, positive_count += 1.0;
        total_power_ = positive_sum * double(cell_[0]) * double(cell_[1]) * double(cell_[2]);
        const double floor = positive_count > 0.0 ? detail::kPowerFloor * positive_sum / positive_count : 1.0;
        double weight_sum = 0.0;
        for (std::size_t j = 0; j < n; ++j) {
            estimate[j] = may_emit[j] ? estimate[j] + floor : 0.0;
            weight_sum += estimate[j];
        }
        if (!(weight_sum > 0.0)) return;  // no cell may emit: sample_emission returns pdf 0

        // Step 3: float probabilities (the pdf reads these) and a CDF accumulated in double; the
        // entries after the last cell that may emit are exactly 1.
        prob_.resize(n);
        cdf_.assign(n + 1, 1.f);
        cdf_[0] = 0.f;
        std::size_t last = 0;
        for (std::size_t j = 0; j < n; ++j)
            if (estimate[j] > 0.0) last = j;
        double run = 0.0;
        for (std::size_t j = 0; j < n; ++j) {
            prob_[j] = float(estimate[j] / weight_sum);
            run += estimate[j];
            if (j < last) cdf_[j + 1] = std::min(1.f, float(run / weight_sum));
        }
    }

    M medium_;
    E field_;
    std::array<int, 3> res_;
    Box box_;                      ///< the power grid's box
    Vec3 cell_{1.f};               ///< its cell size per axis
    float inv_cell_volume_ = 0.f;  ///< 1 / (cell_.x cell_.y cell_.z)
    std::vector<float> prob_;      ///< per cell, the probability of choosing it (empty: nothing emits)
    std::vector<float> cdf_;       ///< n + 1 entries, cdf_[i] = sum of the probabilities of cells < i
    double total_power_ = 0.0;
};

static_assert(EmissiveMedium<Emissive<DenseGridMedium<Mono>>> && EmissiveMedium<Emissive<DenseGridMedium<Rgb>>> &&
              EmissiveMedium<Emissive<DenseGridMedium<Hero<4>>>>);
static_assert(!EmissiveMedium<DenseGridMedium<Rgb>>, "a medium without emission must not look emissive");
// The majorant support of the base medium carries over: every majorant takes the wrapper.
static_assert(RegionBoundedMedium<Emissive<DenseGridMedium<Rgb>>> &&
              ChannelBoundedMedium<Emissive<DenseGridMedium<Hero<4>>>>);
static_assert(MajorantPolicy<GlobalMajorant<Emissive<DenseGridMedium<Rgb>>>, Emissive<DenseGridMedium<Rgb>>> &&
              MajorantPolicy<ChannelMajorant<Emissive<DenseGridMedium<Rgb>>>, Emissive<DenseGridMedium<Rgb>>> &&
              MajorantPolicy<GridMajorant<Emissive<DenseGridMedium<Rgb>>>, Emissive<DenseGridMedium<Rgb>>> &&
              MajorantPolicy<ChannelGridMajorant<Emissive<DenseGridMedium<Rgb>>>, Emissive<DenseGridMedium<Rgb>>>);

}  // namespace nsp
