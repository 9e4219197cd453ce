// nsp/media/grid.hpp: a dense voxel grid of densities over a box, looked up trilinearly, and the
// lookup and region bound that every dense voxel grid shares (the emission grid of media/emissive.hpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "../medium.hpp"
#include "validate.hpp"

namespace nsp {

namespace detail {

/// The trilinear lookup of a dense voxel grid `v` of resolution `res` over `box` (`inv_extent` =
/// 1 / (box.hi - box.lo)): values at voxel centres, clamped at the faces, zero outside the box.
/// Voxel (x, y, z) is v[x + nx * (y + ny * z)]. Shared by DenseGridMedium and EmissionGrid.
inline float trilinear_lookup(const float* v, const std::array<int, 3>& res, const Box& box,
                              const Vec3& inv_extent, const Vec3& p) noexcept {
    if (!box.contains(p)) return 0.f;
    const Vec3 u = (p - box.lo) * inv_extent;
    int i0[3], i1[3];
    float f[3];
    for (int a = 0; a < 3; ++a) {
        const float x = u[a] * float(res[a]) - 0.5f;
        // floor(x) by truncation and a fix-up: x lies in [-0.5, res - 0.5], where this gives
        // the same index and fraction as std::floor without its slow non-SSE4.1 sequence.
        int i = int(x);
        float fl = float(i);
        if (fl > x) {
            --i;
            fl -= 1.f;
        }
        f[a] = x - fl;
        i0[a] = std::clamp(i, 0, res[a] - 1);
        i1[a] = std::clamp(i + 1, 0, res[a] - 1);
    }
    auto at = [&](int x, int y, int z) {
        return v[std::size_t(x) + std::size_t(res[0]) * (std::size_t(y) + std::size_t(res[1]) * std::size_t(z))];
    };
    // Plain a + f (b - a): std::lerp's exactness branches cost 16% of tracking, and the
    // result may exceed max(a, b) by one rounding at most, which tracking tolerates (a
    // negative null coefficient of that size is weighted, not clamped away).
    auto lerp = [](float a, float b, float t) { return a + t * (b - a); };
    const float c00 = lerp(at(i0[0], i0[1], i0[2]), at(i1[0], i0[1], i0[2]), f[0]);
    const float c10 = lerp(at(i0[0], i1[1], i0[2]), at(i1[0], i1[1], i0[2]), f[0]);
    const float c01 = lerp(at(i0[0], i0[1], i1[2]), at(i1[0], i0[1], i1[2]), f[0]);
    const float c11 = lerp(at(i0[0], i1[1], i1[2]), at(i1[0], i1[1], i1[2]), f[0]);
    return lerp(lerp(c00, c10, f[1]), lerp(c01, c11, f[1]), f[2]);
}

/// The voxels [lo, hi] (inclusive, per axis) that trilinear_lookup (same grid) reads at any p in
/// `region`, the region widened by 1/1000 of a voxel so that a point that rounds just outside it
/// is still covered; false if the region misses the box.
inline bool voxels_read(const std::array<int, 3>& res, const Box& box, const Vec3& inv_extent, const Box& region,
                        int lo[3], int hi[3]) noexcept {
    for (int a = 0; a < 3; ++a) {
        const float r0 = std::max(region.lo[a], box.lo[a]), r1 = std::min(region.hi[a], box.hi[a]);
        if (r0 > r1) return false;
        const float x0 = (r0 - box.lo[a]) * inv_extent[a] * float(res[a]) - 0.5f - 1e-3f;
        const float x1 = (r1 - box.lo[a]) * inv_extent[a] * float(res[a]) - 0.5f + 1e-3f;
        lo[a] = std::clamp(int(std::floor(x0)), 0, res[a] - 1);
        hi[a] = std::clamp(int(std::floor(x1)) + 1, 0, res[a] - 1);
    }
    return true;
}

/// `combine` (max or min) over the voxels voxels_read() lists, from `init`; `none` if the region
/// misses the box.
template <class Combine>
float fold_voxels(const float* v, const std::array<int, 3>& res, const Box& box, const Vec3& inv_extent,
                  const Box& region, float init, float none, Combine combine) noexcept {
    int lo[3], hi[3];
    if (!voxels_read(res, box, inv_extent, region, lo, hi)) return none;
    float m = init;
    for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y) {
            const float* row = &v[std::size_t(res[0]) * (std::size_t(y) + std::size_t(res[1]) * std::size_t(z))];
            for (int x = lo[0]; x <= hi[0]; ++x) m = combine(m, row[x]);
        }
    return m;
}

/// The largest value trilinear_lookup (same grid) can return at any p in `region` (0 if it
/// misses the box): the largest voxel among those the lookups there read.
inline float voxel_bound(const float* v, const std::array<int, 3>& res, const Box& box,
                         const Vec3& inv_extent, const Box& region) noexcept {
    return fold_voxels(v, res, box, inv_extent, region, 0.f, 0.f, [](float a, float b) { return std::max(a, b); });
}

/// The smallest value trilinear_lookup (same grid) can return at any p in `region` inside the
/// box: the smallest voxel among those the lookups there read (a trilinear value is a convex
/// combination of them), less 2^-20 of it for the lookup's rounding; 0 where the region misses
/// the box (a lookup outside it returns 0).
inline float voxel_lower_bound(const float* v, const std::array<int, 3>& res, const Box& box,
                               const Vec3& inv_extent, const Box& region) noexcept {
    const float m = fold_voxels(v, res, box, inv_extent, region, std::numeric_limits<float>::infinity(), 0.f,
                                [](float a, float b) { return std::min(a, b); });
    return m * (1.f - 1.f / 1048576.f);
}

}  // namespace detail

/// A dense density grid: mu_a(p) = density(p) * sigma_a_scale, mu_s(p) = density(p) *
/// sigma_s_scale, density(p) trilinear between voxel centres (clamped at the faces), zero
/// outside `bounds`. Voxel (x, y, z) is at index x + nx * (y + ny * z).
template <SpectralMode S>
class DenseGridMedium {
public:
    using Spectral = S;
    using Spectrum = typename S::Spectrum;
    using Coefficient = typename S::Coefficient;  ///< how coefficients are given (a tabulated spectrum in Hero mode)

    /// Throws InvalidArgument on an empty grid, a size that does not match `resolution`, a
    /// negative or non-finite density or scale, an extinction bound that overflows, or an empty or
    /// non-finite box.
    DenseGridMedium(const Box& bounds, std::array<int, 3> resolution, std::vector<float> density,
                    const Coefficient& sigma_a_scale, const Coefficient& sigma_s_scale)
        : bounds_(bounds), res_(resolution), density_(std::move(density)),
          sigma_a_(sigma_a_scale), sigma_s_(sigma_s_scale) {
        detail::require_box(bounds, "DenseGridMedium bounds");
        for (int a = 0; a < 3; ++a)
            if (res_[a] < 1)
                detail::fail("DenseGridMedium resolution[", a, "] = ", res_[a],
                             " is not allowed: every axis needs at least 1 voxel");
        const std::size_t n = detail::voxel_count(res_, density_.max_size(), "DenseGridMedium");
        if (density_.empty())
            detail::fail("DenseGridMedium: the density grid is empty; resolution ", res_[0], "x", res_[1], "x",
                         res_[2], " needs ", n, " densities");
        if (density_.size() != n)
            detail::fail("DenseGridMedium: ", density_.size(), " densities given, but resolution ",
                         res_[0], "x", res_[1], "x", res_[2], " needs ", n);
        for (std::size_t i = 0; i < n; ++i)
            if (!std::isfinite(density_[i]) || density_[i] < 0.f)
                detail::fail("DenseGridMedium: density[", i, "] = ", density_[i],
                             " is not allowed: densities must be finite and >= 0");
        detail::require_coefficient(sigma_a_, "DenseGridMedium sigma_a_scale");
        detail::require_coefficient(sigma_s_, "DenseGridMedium sigma_s_scale");
        max_density_ = *std::max_element(density_.begin(), density_.end());
        detail::require_finite_extinction(max_extinction(),
                                          "DenseGridMedium extinction bound max(sigma_a_scale + sigma_s_scale) x max density");
        inv_extent_ = 1.f / (bounds_.hi - bounds_.lo);
    }

    Box bounds() const noexcept { return bounds_; }
    std::array<int, 3> resolution() const noexcept { return res_; }
    float max_density() const noexcept { return max_density_; }

    /// The trilinearly interpolated density at p (zero outside the box).
    float density(const Vec3& p) const noexcept {
        return detail::trilinear_lookup(density_.data(), res_, bounds_, inv_extent_, p);
    }

    /// One density lookup, scaled per channel.
    Coefficients<S> coefficients(const Vec3& p, const typename S::Wavelengths& l) const noexcept {
        const float d = density(p);
        return {S::sample(sigma_a_, l) * d, S::sample(sigma_s_, l) * d};
    }

    /// max density times the extinction scale: trilinear weights are convex, so this bounds mu_t.
    Spectrum extinction_bound(const typename S::Wavelengths& l) const noexcept {
        return (S::sample(sigma_a_, l) + S::sample(sigma_s_, l)) * max_density_;
    }

    float max_extinction() const noexcept { return max_value(sigma_a_ + sigma_s_) * max_density_; }

    /// The per-channel extinction bound as a coefficient (what ChannelMajorant stores).
    Coefficient extinction_bound_coefficient() const { return scale<Coefficient>(sigma_a_ + sigma_s_, max_density_); }

    /// mu_t,c(p) = density(p) times this (what grid majorants scale their cells by).
    Coefficient extinction_per_density() const { return sigma_a_ + sigma_s_; }

    /// The largest density a lookup can return at any p in `region` (0 if it misses the box): the
    /// largest voxel among those the trilinear lookups there read. The region is widened by 1/1000
    /// of a voxel so that a point that rounds just outside it is still covered.
    float density_bound(const Box& region) const noexcept {
        return detail::voxel_bound(density_.data(), res_, bounds_, inv_extent_, region);
    }

    /// The smallest density a lookup can return at any p in `region` inside the box (a minorant,
    /// the control of THEORY 5.10): the smallest voxel the lookups there read, less rounding; 0
    /// where the region misses the box.
    float density_lower_bound(const Box& region) const noexcept {
        return detail::voxel_lower_bound(density_.data(), res_, bounds_, inv_extent_, region);
    }

private:
    Box bounds_;
    std::array<int, 3> res_;
    std::vector<float> density_;
    Coefficient sigma_a_, sigma_s_;
    float max_density_ = 0.f;
    Vec3 inv_extent_{1.f};
};

static_assert(Medium<DenseGridMedium<Mono>> && Medium<DenseGridMedium<Rgb>>);

}  // namespace nsp
