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

    /// Throws InvalidArgument if a coefficient is negative or non-finite or the box is empty.
    HomogeneousMedium(const Box& bounds, const Spectrum& sigma_a, const Spectrum& sigma_s)
        : bounds_(bounds), coeff_{sigma_a, sigma_s} {
        detail::require_box(bounds, "HomogeneousMedium bounds");
        detail::require_coefficient(sigma_a, "HomogeneousMedium sigma_a");
        detail::require_coefficient(sigma_s, "HomogeneousMedium sigma_s");
    }

    Box bounds() const noexcept { return bounds_; }

    /// The constant coefficients (zero outside the box).
    Coefficients<S> coefficients(const Vec3& p, const typename S::Wavelengths&) const noexcept {
        if (!bounds_.contains(p)) return {Spectrum::Zero(), Spectrum::Zero()};
        return coeff_;
    }

    Spectrum extinction_bound(const typename S::Wavelengths&) const noexcept {
        return coeff_.sigma_t();
    }

    /// mu_t over [t0, t1] of `ray` clipped to the box: the exact optical depth.
    Spectrum optical_depth(const Ray& ray, float t0, float t1) const noexcept {
        const Interval in = bounds_.clip(ray, t0, t1);
        if (in.empty()) return Spectrum::Zero();
        return coeff_.sigma_t() * (in.t1 - in.t0);
    }

private:
    Box bounds_;
    Coefficients<S> coeff_;
};

static_assert(Medium<HomogeneousMedium<Mono>> && Medium<HomogeneousMedium<Rgb>>);

}  // namespace nsp
