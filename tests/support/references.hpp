// tests/support/references.hpp: closed-form references (by quadrature in double) of the
// equiangular and emission suites.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "common.hpp"

namespace nsp_test {

/// Single scattering from an isotropic point light of intensity I along `ray`, isotropic phase:
/// L_c = I_c / (4 pi) int T_c(0, t) mu_s,c(t) T_c(x_t, light) / |x_t - light|^2 dt over the part of
/// the ray inside the medium, integrated in the equiangular angle (where the integrand is smooth)
/// by composite Simpson in double with 20000 intervals.
template <class M>
inline std::array<double, 3> single_scatter_reference(const M& medium, const Ray& ray, const Vec3& light, float intensity) {
    using S = typename M::Spectral;
    const Interval in = medium.bounds().clip(ray, 0.f, kInf);
    const Vec3 oc = light - ray.o;
    const double delta = glm::dot(oc, ray.d);
    const double d = glm::length(oc - float(delta) * ray.d);
    const double th0 = std::atan2(double(in.t0) - delta, d), th1 = std::atan2(double(in.t1) - delta, d);
    const int n = 20000;
    std::array<double, 3> sum{};
    for (int i = 0; i <= n; ++i) {
        const double th = th0 + (th1 - th0) * double(i) / n;
        const double t = delta + d * std::tan(th);
        const double dt_dth = d / (std::cos(th) * std::cos(th));
        const Vec3 x = ray.at(float(t));
        const Vec3 to = light - x;
        const float r = glm::length(to);
        const auto tau_cam = medium.optical_depth(ray, 0.f, float(t));
        const auto tau_light = medium.optical_depth(Ray{x, to / r}, 0.f, r);
        const auto k = medium.coefficients(x, typename S::Wavelengths{});
        const double wgt = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        for (int c = 0; c < S::channels; ++c)
            sum[c] += wgt * std::exp(-double(tau_cam[c]) - double(tau_light[c])) * double(k.sigma_s[c]) /
                      (double(r) * double(r)) * dt_dth;
    }
    for (int c = 0; c < 3; ++c) sum[c] *= (th1 - th0) / (3.0 * n) * intensity / (4.0 * kPi);
    return sum;
}

/// An emission grid over `b`, voxel values uniform in [0, 2 mean) from `seed` (all `mean` at
/// seed 0): the emission tests' spatially varying L_e.
inline EmissionGrid make_emission(const Box& b, std::array<int, 3> res, float mean, std::uint64_t seed) {
    std::vector<float> v(std::size_t(res[0] * res[1] * res[2]), mean);
    if (seed != 0) {
        Pcg32 rng(seed, 3);
        for (float& x : v) x = 2.f * mean * rng.uniform();
    }
    return EmissionGrid(b, res, std::move(v));
}

/// Emission of a non-scattering medium along `ray`: L_c = int T_c(0, t) mu_a,c(t) L_e,c(t) dt over
/// the part of the ray inside `base`'s box, with T from base's closed-form optical depth, by
/// composite Simpson in double with 20000 intervals.
template <class Base, class Emitting>
inline std::array<double, 3> emitting_absorber_reference(const Base& base, const Emitting& medium, const Ray& ray) {
    using S = typename Base::Spectral;
    const Interval in = base.bounds().clip(ray, 0.f, kInf);
    std::array<double, 3> ref{};
    const int n = 20000;
    for (int i = 0; i <= n; ++i) {
        const float t = in.t0 + (in.t1 - in.t0) * float(i) / float(n);
        const auto tau = base.optical_depth(ray, 0.f, t);
        const auto k = base.coefficients(ray.at(t), {});
        const auto e = medium.emission(ray.at(t), {});
        const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        for (int c = 0; c < S::channels; ++c)
            ref[std::size_t(c)] += w * std::exp(-double(tau[c])) * double(k.sigma_a[c]) * double(e[c]);
    }
    for (double& r : ref) r *= double(in.t1 - in.t0) / (3.0 * n);
    return ref;
}

/// The single-scattering set-up of the quadrature tests: medium M over [-1, 1]^3 at density 0.5
/// with per-unit-density mu_a (0.2, 0.1, 0.4) and mu_s (0.8, 0.4, 1.2) (optical thickness about 1
/// across the box, channels 3x apart in Rgb), an isotropic point light of intensity 2 inside it, 0.3
/// from the camera ray, and the quadrature of the single scattering along that ray.
template <class M>
struct PointLightSingleScatter {
    using S = typename M::Spectral;
    Box box{Vec3(-1.f), Vec3(1.f)};
    M medium = make_medium<M>(box, 0.5f, spec<S>(0.2f, 0.1f, 0.4f), spec<S>(0.8f, 0.4f, 1.2f));
    Vec3 light{0.2f, 0.25f, -0.1f};
    Lights<S> lights = [this] {
        Lights<S> l;
        l.set(PointLight<S>{light, grey<S>(2.f)});
        return l;
    }();
    Ray ray{Vec3(-3.f, 0.05f, -0.05f), glm::normalize(Vec3(1.f, 0.01f, -0.02f))};
    std::array<double, 3> ref = single_scatter_reference(medium, ray, light, 2.f);
};

/// The emitting absorber of the control suites: medium M over [-1, 1]^3 at density 0.9 with mu_a
/// (0.8, 0.4, 1.5) per unit density and no scattering, emitting over most of the box (a random
/// grid of L_e, mean 1, times (2, 1, 0.5)), and its radiance along `ray` by quadrature:
/// L_c = int T_c mu_a,c L_e,c dt (emitting_absorber_reference).
template <class M>
struct EmittingAbsorber {
    using S = typename M::Spectral;
    using Medium = Emissive<M>;
    Box box{Vec3(-1.f), Vec3(1.f)};
    M base = make_medium<M>(box, 0.9f, spec<S>(0.8f, 0.4f, 1.5f), grey<S>(0.f));
    Medium medium{base, make_emission(Box{Vec3(-1.f, -0.8f, -1.2f), Vec3(0.9f, 1.f, 1.f)}, {5, 3, 4}, 1.f, 77),
                  spec<S>(2.f, 1.f, 0.5f), {6, 5, 4}};
    Ray ray{Vec3(-3.f, 0.25f, -0.3f), glm::normalize(Vec3(1.f, -0.05f, 0.12f))};
    std::array<double, 3> ref = emitting_absorber_reference(base, medium, ray);
};

/// The chromatic emissive furnace of the control suites: an exponential medium over [-1, 1]^3
/// (density 1 at the centre, mu_a (0.5, 0.3, 0.8), mu_s (0.6, 0.9, 0.3) per unit density) emitting
/// L_e = (0.7, 0.4, 1.1) everywhere, under an environment of the same radiance: L = L_e along `ray`
/// for any density and albedo, after many scatterings.
struct EmissiveFurnace {
    using S = Rgb;
    using Medium = Emissive<ExponentialMedium<S>>;
    Box box{Vec3(-1.f), Vec3(1.f)};
    S::Spectrum le = spec<S>(0.7f, 0.4f, 1.1f);
    Lights<S> lights = [this] {
        Lights<S> l;
        l.set(EnvironmentLight<S>{le});
        return l;
    }();
    Ray ray{Vec3(-3.f, 0.15f, -0.1f), glm::normalize(Vec3(1.f, 0.02f, 0.03f))};
    Medium medium{make_medium<ExponentialMedium<S>>(box, 1.f, spec<S>(0.5f, 0.3f, 0.8f), spec<S>(0.6f, 0.9f, 0.3f)),
                  make_emission(box, {3, 2, 4}, 1.f, 0), le, {4, 4, 4}};
    std::array<double, 3> ref() const { return {double(le[0]), double(le[1]), double(le[2])}; }
};

}  // namespace nsp_test
