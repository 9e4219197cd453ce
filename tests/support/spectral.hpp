// tests/support/spectral.hpp: what the chromatic suites share: the channel-policy and estimator
// type lists, chromatic coefficients in every mode, and per-mode wavelength draws.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "common.hpp"
#include "surfaces.hpp"

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

/// Single scattering from two point lights of chromatic intensity in a chromatic cube [-1, 1]^3
/// (HG 0.4) behind null interfaces over a Lambertian floor at y = -1.5 of chromatic albedo, seen
/// along one camera ray that passes 0.15 from light 0, paths of one real vertex (max_depth 1).
/// Per channel, with T_c(l) = exp(-sigma_t,c l):
///   L_c = sum_i int sigma_s,c f_p T_c(s - s_in) I_i,c T_c(r_i) / r_i^2 ds
///         + T_c(s_out - s_in) sum_i rho_c / pi I_i,c cos_i T_c(c_i) / d_i^2
/// (composite Simpson in double, 20000 intervals).
struct TwoPointLights {
    nsp::Rgb::Spectrum sigma_s{0.8f, 0.5f, 1.1f}, sigma_a{0.2f, 0.4f, 0.1f}, rho{0.6f, 0.3f, 0.8f};
    nsp::Box cube{nsp::Vec3(-1.f), nsp::Vec3(1.f)};
    std::vector<nsp::PointLight<nsp::Rgb>> points{{nsp::Vec3(0.1f, -0.7f, -0.45f), nsp::Rgb::Spectrum(2.f, 1.f, 1.5f)},
                                                  {nsp::Vec3(-0.5f, -0.3f, 0.6f), nsp::Rgb::Spectrum(0.5f, 1.f, 0.8f)}};
    nsp::Vec3 eye{0.1f, 0.8f, -4.f};
    nsp::Vec3 dir = glm::normalize(nsp::Vec3(-0.1f, -2.3f, 5.f));
    float g = 0.4f;

    nsp::Rgb::Spectrum expected() const {
        using namespace nsp;
        const Rgb::Spectrum sigma_t = sigma_s + sigma_a;
        const double s_in = (-1.0 - eye.z) / dir.z, s_out = (-1.0 - eye.y) / dir.y, s_floor = (-1.5 - eye.y) / dir.y;
        const HenyeyGreensteinPhase phase{g};
        Rgb::Spectrum out;
        for (int c = 0; c < 3; ++c) {
            const double st = sigma_t[c];
            auto single = [&](double s) {
                const Vec3 x = eye + float(s) * dir;
                double sum = 0.0;
                for (const auto& l : points) {
                    const Vec3 to = l.position - x;
                    const double r = glm::length(to);
                    sum += double(sigma_s[c]) * phase.eval(dir, to / float(r)) * std::exp(-st * (s - s_in)) *
                           l.intensity[c] * std::exp(-st * r) / (r * r);
                }
                return sum;
            };
            const int n = 20000;
            const double h = (s_out - s_in) / n;
            double integral = single(s_in) + single(s_out);
            for (int i = 1; i < n; ++i) integral += (i % 2 ? 4.0 : 2.0) * single(s_in + i * h);
            integral *= h / 3.0;
            const Vec3 f = eye + float(s_floor) * dir;
            double floor_term = 0.0;
            for (const auto& l : points) {
                const Vec3 to = l.position - f;
                const double dist = glm::length(to);
                const Vec3 w = to / float(dist);
                floor_term += rho[c] / kPi * l.intensity[c] * w.y * std::exp(-st * exit_distance(cube, l.position, -w)) /
                              (dist * dist);
            }
            out[c] = float(integral + std::exp(-st * (s_out - s_in)) * floor_term);
        }
        return out;
    }
};

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
