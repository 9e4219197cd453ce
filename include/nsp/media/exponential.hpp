// nsp/media/exponential.hpp: an analytic heterogeneous medium with closed-form optical depth.
//
// density(p) = d0 * exp(k * s(p)), with s(p) = dot(p - bounds.lo, axis) for a unit `axis`.
// Along a ray p = o + t d, s is linear in t (s = s0 + b t, b = dot(d, axis)), so the optical
// depth has the closed form d0 e^{k s0} (e^{k b t1} - e^{k b t0}) / (k b). Tests check
// transmittance estimators against it; it is heterogeneous, so majorants are loose somewhere.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "../medium.hpp"
#include "validate.hpp"

namespace nsp {

/// An exponential density ramp along `axis` inside `bounds`, scaled per channel.
template <SpectralMode S>
class ExponentialMedium {
public:
    using Spectral = S;
    using Spectrum = typename S::Spectrum;
    using Coefficient = typename S::Coefficient;  ///< how coefficients are given (a tabulated spectrum in Hero mode)

    /// Throws InvalidArgument on non-finite or negative d0 or scales, non-finite k, a zero or
    /// non-finite axis, an empty or non-finite box, or a density or extinction bound that
    /// overflows. `axis` is normalised.
    ExponentialMedium(const Box& bounds, const Vec3& axis, float d0, float k,
                      const Coefficient& sigma_a_scale, const Coefficient& sigma_s_scale)
        : bounds_(bounds), d0_(d0), k_(k), sigma_a_(sigma_a_scale), sigma_s_(sigma_s_scale) {
        detail::require_box(bounds, "ExponentialMedium bounds");
        detail::require_finite_nonnegative(d0, "ExponentialMedium d0");
        detail::require_finite(k, "ExponentialMedium k");
        const float len = glm::length(axis);
        if (!std::isfinite(len) || len <= 0.f)
            detail::fail("ExponentialMedium axis has length ", len, ": it must be finite and > 0");
        axis_ = axis / len;
        detail::require_coefficient(sigma_a_, "ExponentialMedium sigma_a_scale");
        detail::require_coefficient(sigma_s_, "ExponentialMedium sigma_s_scale");
        // s ranges over [min, max] of dot(corner - lo, axis) over the 8 corners.
        float smax = 0.f, smin = 0.f;
        for (int c = 0; c < 8; ++c) {
            const Vec3 corner((c & 1) ? bounds.hi.x : bounds.lo.x, (c & 2) ? bounds.hi.y : bounds.lo.y,
                              (c & 4) ? bounds.hi.z : bounds.lo.z);
            const float s = glm::dot(corner - bounds.lo, axis_);
            smax = std::max(smax, s);
            smin = std::min(smin, s);
        }
        max_density_ = d0_ * std::max(std::exp(k_ * smax), std::exp(k_ * smin));
        if (!std::isfinite(max_density_))
            detail::fail("ExponentialMedium: the largest density d0 * exp(k * s) in the box (d0 = ", d0, ", k = ", k,
                         ") overflows float; it must be finite: choose a smaller d0, |k| or box");
        detail::require_finite_extinction(max_extinction(),
                                          "ExponentialMedium extinction bound max(sigma_a_scale + sigma_s_scale) x max density");
    }

    Box bounds() const noexcept { return bounds_; }

    /// The scalar density at p (zero outside the box).
    float density(const Vec3& p) const noexcept {
        if (!bounds_.contains(p)) return 0.f;
        return d0_ * std::exp(k_ * glm::dot(p - bounds_.lo, axis_));
    }

    Coefficients<S> coefficients(const Vec3& p, const typename S::Wavelengths& l) const noexcept {
        const float d = density(p);
        return {S::sample(sigma_a_, l) * d, S::sample(sigma_s_, l) * d};
    }

    Spectrum extinction_bound(const typename S::Wavelengths& l) const noexcept {
        return (S::sample(sigma_a_, l) + S::sample(sigma_s_, l)) * max_density_;
    }

    float max_extinction() const noexcept { return max_value(sigma_a_ + sigma_s_) * max_density_; }

    /// The per-channel extinction bound as a coefficient (what ChannelMajorant stores).
    Coefficient extinction_bound_coefficient() const { return scale<Coefficient>(sigma_a_ + sigma_s_, max_density_); }

    /// mu_t,c(p) = density(p) times this (what grid majorants scale their cells by).
    Coefficient extinction_per_density() const { return sigma_a_ + sigma_s_; }

    /// The largest density at any p in `region` (0 if it misses the box): the exponential is
    /// monotone along the axis, so the largest corner value of the region clipped to the box,
    /// with the region widened by 1e-5 of the box and the result padded by 1e-5 for rounding.
    float density_bound(const Box& region) const noexcept {
        Box r;
        for (int a = 0; a < 3; ++a) {
            const float pad = 1e-5f * (bounds_.hi[a] - bounds_.lo[a]);
            r.lo[a] = std::max(region.lo[a], bounds_.lo[a]) - pad;
            r.hi[a] = std::min(region.hi[a], bounds_.hi[a]) + pad;
            if (r.lo[a] > r.hi[a]) return 0.f;
        }
        float m = 0.f;
        for (int c = 0; c < 8; ++c) {
            const Vec3 corner((c & 1) ? r.hi.x : r.lo.x, (c & 2) ? r.hi.y : r.lo.y, (c & 4) ? r.hi.z : r.lo.z);
            m = std::max(m, d0_ * std::exp(k_ * glm::dot(corner - bounds_.lo, axis_)));
        }
        return m * (1.f + 1e-5f);
    }

    /// The smallest density at any p in `region` inside the box (a minorant, the control of THEORY
    /// 5.10): the smallest corner value of the region clipped to the box, widened and shrunk by
    /// 1e-5 as density_bound does; 0 where the region misses the box.
    float density_lower_bound(const Box& region) const noexcept {
        Box r;
        for (int a = 0; a < 3; ++a) {
            const float pad = 1e-5f * (bounds_.hi[a] - bounds_.lo[a]);
            r.lo[a] = std::max(region.lo[a], bounds_.lo[a]);
            r.hi[a] = std::min(region.hi[a], bounds_.hi[a]);
            if (r.lo[a] > r.hi[a]) return 0.f;
            r.lo[a] -= pad;
            r.hi[a] += pad;
        }
        float m = std::numeric_limits<float>::infinity();
        for (int c = 0; c < 8; ++c) {
            const Vec3 corner((c & 1) ? r.hi.x : r.lo.x, (c & 2) ? r.hi.y : r.lo.y, (c & 4) ? r.hi.z : r.lo.z);
            m = std::min(m, d0_ * std::exp(k_ * glm::dot(corner - bounds_.lo, axis_)));
        }
        return m * (1.f - 1e-5f);
    }

    /// The exact optical depth int mu_t dt over [t0, t1] of `ray` clipped to the box at
    /// wavelengths l, in double.
    Spectrum optical_depth(const Ray& ray, float t0, float t1, const typename S::Wavelengths& l = {}) const noexcept {
        const Interval in = bounds_.clip(ray, t0, t1);
        if (in.empty()) return Spectrum::Zero();
        const double s0 = glm::dot(ray.o - bounds_.lo, axis_);
        const double b = glm::dot(ray.d, axis_);
        const double kb = double(k_) * b;
        const double a0 = double(k_) * (s0 + b * in.t0);
        const double len = double(in.t1) - double(in.t0);
        // int_{t0}^{t1} e^{k(s0 + b t)} dt = e^{a0} * (e^{kb len} - 1) / kb, via expm1 for small kb.
        const double integral = std::abs(kb * len) < 1e-12 ? std::exp(a0) * len
                                                            : std::exp(a0) * std::expm1(kb * len) / kb;
        return (S::sample(sigma_a_, l) + S::sample(sigma_s_, l)) * float(double(d0_) * integral);
    }

private:
    Box bounds_;
    Vec3 axis_{1.f, 0.f, 0.f};
    float d0_, k_;
    Coefficient sigma_a_, sigma_s_;
    float max_density_ = 0.f;
};

static_assert(Medium<ExponentialMedium<Mono>> && Medium<ExponentialMedium<Rgb>>);

}  // namespace nsp
