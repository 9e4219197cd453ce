// nsp/medium.hpp: the medium concept, what the free-flight loop needs of a participating medium.
#pragma once

#include <concepts>

#include "core/math.hpp"
#include "spectrum.hpp"

namespace nsp {

/// Absorption and scattering coefficients at one point, per channel (THEORY 1).
template <SpectralMode S>
struct Coefficients {
    typename S::Spectrum sigma_a;
    typename S::Spectrum sigma_s;
    /// Extinction mu_t = mu_a + mu_s.
    typename S::Spectrum sigma_t() const { return sigma_a + sigma_s; }
};

/// A medium provides:
/// - `Spectral`: its spectral mode;
/// - `bounds()`: a box outside which all coefficients are zero (tracking clips rays to it);
/// - `coefficients(p, lambda)`: mu_a and mu_s at p, finite and >= 0 (one density lookup);
/// - `extinction_bound(lambda)`: per channel, an upper bound of mu_t over the bounds, from which
///   a per-channel majorant is built;
/// - `max_extinction()`: an upper bound of mu_t over the bounds and every channel or wavelength,
///   from which a grey global majorant is built.
/// Media are read-only after construction; their constructors reject bad input.
template <class M>
concept Medium = requires(const M& m, const Vec3& p, const typename M::Spectral::Wavelengths& l) {
    requires SpectralMode<typename M::Spectral>;
    { m.bounds() } -> std::same_as<Box>;
    { m.coefficients(p, l) } -> std::same_as<Coefficients<typename M::Spectral>>;
    { m.extinction_bound(l) } -> std::same_as<typename M::Spectral::Spectrum>;
    { m.max_extinction() } -> std::same_as<float>;
};

}  // namespace nsp
