// nsp/media/homogeneous.hpp: constant coefficients inside a box.
#pragma once

#include "../medium.hpp"
#include "validate.hpp"

namespace nsp {

/// A homogeneous medium: the same mu_a and mu_s everywhere in `bounds`, zero outside.
/// Its transmittance over a length d inside the box is exp(-mu_t d), the closed form tests use.
template <SpectralMode S>
class HomogeneousMedium {
public:
    using Spectral = S;
    using Spectrum = typename S::Spectrum;
    using Coefficient = typename S::Coefficient;  ///< how coefficients are given (a tabulated spectrum in Hero mode)

    /// Throws InvalidArgument if a coefficient is negative or non-finite, their sum overflows, or
    /// the box is empty or not finite.
    HomogeneousMedium(const Box& bounds, const Coefficient& sigma_a, const Coefficient& sigma_s)
        : bounds_(bounds), sigma_a_(sigma_a), sigma_s_(sigma_s) {
        detail::require_box(bounds, "HomogeneousMedium bounds");
        detail::require_coefficient(sigma_a, "HomogeneousMedium sigma_a");
        detail::require_coefficient(sigma_s, "HomogeneousMedium sigma_s");
        detail::require_finite_extinction(max_extinction(), "HomogeneousMedium extinction bound max(sigma_a + sigma_s)");
    }

    Box bounds() const noexcept { return bounds_; }

    /// The constant coefficients (zero outside the box).
    Coefficients<S> coefficients(const Vec3& p, const typename S::Wavelengths& l) const noexcept {
        if (!bounds_.contains(p)) return {Spectrum::Zero(), Spectrum::Zero()};
        return {S::sample(sigma_a_, l), S::sample(sigma_s_, l)};
    }

    Spectrum extinction_bound(const typename S::Wavelengths& l) const noexcept {
        return S::sample(sigma_a_, l) + S::sample(sigma_s_, l);
    }

    float max_extinction() const noexcept { return max_value(sigma_a_ + sigma_s_); }

    /// The per-channel extinction as a coefficient (what ChannelMajorant stores).
    Coefficient extinction_bound_coefficient() const { return sigma_a_ + sigma_s_; }

    /// mu_t over [t0, t1] of `ray` clipped to the box at wavelengths l: the exact optical depth.
    Spectrum optical_depth(const Ray& ray, float t0, float t1, const typename S::Wavelengths& l = {}) const noexcept {
        const Interval in = bounds_.clip(ray, t0, t1);
        if (in.empty()) return Spectrum::Zero();
        return extinction_bound(l) * (in.t1 - in.t0);
    }

private:
    Box bounds_;
    Coefficient sigma_a_, sigma_s_;
};

static_assert(Medium<HomogeneousMedium<Mono>> && Medium<HomogeneousMedium<Rgb>>);

}  // namespace nsp
