// tests/support/spectral.hpp: what the chromatic suites share: the channel-policy and estimator
// type lists, chromatic coefficients in every mode, and per-mode wavelength draws.
#pragma once

#include <string>
#include <tuple>

#include "common.hpp"

namespace nsp_test {

/// A coefficient of mode S from three channel values: Rgb takes them as they are, Hero a
/// piecewise-linear spectrum through b at 450 nm, g at 550 nm and r at 650 nm, Mono takes r.
template <SpectralMode S>
typename S::Coefficient chroma(float r, float g, float b) {
    if constexpr (is_hero_v<S>) return TabulatedSpectrum::from_points({450.f, 550.f, 650.f}, {b, g, r});
    else if constexpr (S::channels == 3) return typename S::Spectrum(r, g, b);
    else return S::Spectrum::Constant(r);
}

/// The wavelength context of one path: drawn per path in Hero mode, empty otherwise.
template <SpectralMode S, UniformRng R>
typename S::Wavelengths draw_wavelengths(R& rng) {
    if constexpr (is_hero_v<S>) return S::Wavelengths::sample(rng.uniform());
    else return {};
}

/// The majorant policy a channel policy is used with: per channel for its own pdfs, grey for
/// spectral tracking.
template <ChannelPolicy CP, Medium M>
using MajorantFor = std::conditional_t<CP::own_pdfs, ChannelMajorant<M>, GlobalMajorant<M>>;

/// The three strategies of a channel policy (absorption policy A).
template <ChannelPolicy CP, AbsorptionPolicy A>
using SpectralEstimatorsOf = std::tuple<SpectralPathEstimator<CP, strategy::Unidirectional, mis::None, A>,
                                        SpectralPathEstimator<CP, strategy::NextEvent, mis::None, A>,
                                        SpectralPathEstimator<CP, strategy::NullScatteringMis, mis::Balance, A>>;

template <AbsorptionPolicy A>
using SpectralEstimatorsWith = decltype(std::tuple_cat(SpectralEstimatorsOf<channels::Independent, A>{},
                                                       SpectralEstimatorsOf<channels::SpectralTrackingMax, A>{},
                                                       SpectralEstimatorsOf<channels::SpectralTrackingAverage, A>{},
                                                       SpectralEstimatorsOf<channels::SpectralMis, A>{}));

/// Every spectral estimator: 4 channel policies x 3 strategies x 2 absorption policies.
using AllSpectralEstimators = decltype(std::tuple_cat(SpectralEstimatorsWith<absorption::Event>{},
                                                      SpectralEstimatorsWith<absorption::Weight>{}));

/// "spectral-mis/uni-nee-mis/absorb-weight".
template <class E>
std::string spectral_estimator_name() {
    return std::string(E::Channels::name) + "/" + E::Strategy::name + "/" + E::Absorption::name;
}

/// n estimates of every channel along `ray`: mean and SE per channel of (estimate - expected(lambda)),
/// with expected(lambda) a spectrum per path (the closed form at the path's wavelengths), and how
/// many were not Status::Ok. Selection q is used for SpectralPathEstimator, ignored otherwise.
template <class E, class Sc, class Expected>
RadianceStats<typename Sc::Spectral> estimate_error(const E& est, const Sc& scene, const Ray& ray, int n,
                                                     std::uint64_t seed, Expected&& expected,
                                                     const ChannelSelection<typename Sc::Spectral>& q = {}) {
    using S = typename Sc::Spectral;
    RadianceStats<S> out;
    Pcg32 rng(seed, 7);
    LookupCount lookups;
    for (int i = 0; i < n; ++i) {
        const auto lambda = draw_wavelengths<S>(rng);
        RadianceSample<S> r;
        if constexpr (requires { est.radiance(scene, ray, lambda, q, rng, lookups); })
            r = est.radiance(scene, ray, lambda, q, rng, lookups);
        else
            r = est.radiance(scene, ray, lambda, rng, lookups);
        out.not_ok += r.status != Status::Ok;
        out.stat.add(typename S::Spectrum(r.value - expected(lambda)));
    }
    out.lookups = lookups.count();
    return out;
}

}  // namespace nsp_test
