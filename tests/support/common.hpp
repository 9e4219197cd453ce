// tests/support/common.hpp: what every nsp test shares: the type lists the generic suites run
// over (with readable names), medium factories, sample statistics and the chi-square helper.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

#include <doctest/doctest.h>

#include <nsp/nsp.hpp>

namespace nsp_test {

using namespace nsp;

// ---------------------------------------------------------------------------------------------
// Spectra

/// A spectrum of mode S from up to three channel values (Mono takes the first).
template <SpectralMode S>
typename S::Spectrum spec(float r, float g, float b) {
    typename S::Spectrum s;
    if constexpr (S::channels == 1) s << r;
    else s << r, g, b;
    return s;
}

/// A spectrum with every channel equal to v.
template <SpectralMode S>
typename S::Spectrum grey(float v) {
    return S::Spectrum::Constant(v);
}

// ---------------------------------------------------------------------------------------------
// Media: one factory per medium template, so generic suites can build "a medium of kind M with
// mean density about `density`" for any M.

template <class M>
struct MediumKind;

template <SpectralMode S>
struct MediumKind<HomogeneousMedium<S>> {
    static constexpr const char* name = "homogeneous";
    static constexpr bool analytic = true;  ///< has optical_depth()
    static HomogeneousMedium<S> make(const Box& b, float density, const typename S::Coefficient& sa,
                                     const typename S::Coefficient& ss, std::uint64_t /*seed*/) {
        return {b, scale(sa, density), scale(ss, density)};
    }
};

template <SpectralMode S>
struct MediumKind<DenseGridMedium<S>> {
    static constexpr const char* name = "grid";
    static constexpr bool analytic = false;
    /// A small, non-cubic grid (5 x 4 x 6) of densities uniform in [0, 2 density).
    static DenseGridMedium<S> make(const Box& b, float density, const typename S::Coefficient& sa,
                                   const typename S::Coefficient& ss, std::uint64_t seed) {
        const std::array<int, 3> res{5, 4, 6};
        Pcg32 rng(seed, 77);
        std::vector<float> d(std::size_t(res[0] * res[1] * res[2]));
        for (float& v : d) v = 2.f * density * rng.uniform();
        return {b, res, std::move(d), sa, ss};
    }
};

template <SpectralMode S>
struct MediumKind<ExponentialMedium<S>> {
    static constexpr const char* name = "exponential";
    static constexpr bool analytic = true;
    /// Density `density` at the box centre, varying by e^2 along an oblique axis across the box.
    static ExponentialMedium<S> make(const Box& b, float density, const typename S::Coefficient& sa,
                                     const typename S::Coefficient& ss, std::uint64_t /*seed*/) {
        const Vec3 axis = glm::normalize(Vec3(1.f, 0.6f, -0.3f));
        const float k = 2.f / glm::length(b.hi - b.lo);
        const float s_centre = glm::dot(0.5f * (b.hi - b.lo), axis);
        return {b, axis, density * std::exp(-k * s_centre), k, sa, ss};
    }
};

/// A medium of type M over `b` with mean density about `density` and per-unit-density
/// coefficients sa, ss.
template <class M>
M make_medium(const Box& b, float density, const typename M::Spectral::Coefficient& sa,
              const typename M::Spectral::Coefficient& ss, std::uint64_t seed = 1) {
    return MediumKind<M>::make(b, density, sa, ss, seed);
}

// ---------------------------------------------------------------------------------------------
// Type lists

/// One point of the medium x spectral x absorption product.
template <SpectralMode S, template <class> class MT, AbsorptionPolicy A>
struct Combo {
    using Spectral = S;
    using Medium = MT<S>;
    using Absorption = A;
};

template <SpectralMode S, template <class> class MT>
using CombosOf = std::tuple<Combo<S, MT, absorption::Event>, Combo<S, MT, absorption::Weight>>;

template <SpectralMode S>
using CombosOfSpectral = decltype(std::tuple_cat(CombosOf<S, HomogeneousMedium>{},
                                                 CombosOf<S, DenseGridMedium>{},
                                                 CombosOf<S, ExponentialMedium>{}));

/// {Mono, Rgb} x {homogeneous, grid, exponential} x {absorption event, weight}: 12 types.
using AllCombos = decltype(std::tuple_cat(CombosOfSpectral<Mono>{}, CombosOfSpectral<Rgb>{}));

template <AbsorptionPolicy A>
using EstimatorsWith = std::tuple<PathEstimator<strategy::Unidirectional, mis::None, A>,
                                  PathEstimator<strategy::NextEvent, mis::None, A>,
                                  PathEstimator<strategy::DirectionalMis, mis::Balance, A>,
                                  PathEstimator<strategy::DirectionalMis, mis::Power, A>,
                                  PathEstimator<strategy::NullScatteringMis, mis::Balance, A>,
                                  PathEstimator<strategy::NullScatteringMis, mis::Power, A>>;

/// Every estimator type: 6 strategy / heuristic pairs x 2 absorption policies.
using AllEstimators =
    decltype(std::tuple_cat(EstimatorsWith<absorption::Event>{}, EstimatorsWith<absorption::Weight>{}));

template <AbsorptionPolicy A>
using MisEstimatorsWith = std::tuple<PathEstimator<strategy::DirectionalMis, mis::Balance, A>,
                                     PathEstimator<strategy::DirectionalMis, mis::Power, A>,
                                     PathEstimator<strategy::NullScatteringMis, mis::Balance, A>,
                                     PathEstimator<strategy::NullScatteringMis, mis::Power, A>>;

/// The estimators that combine two strategies with MIS: 4 x 2 absorption policies.
using MisEstimators = decltype(std::tuple_cat(MisEstimatorsWith<absorption::Event>{},
                                              MisEstimatorsWith<absorption::Weight>{}));

/// A readable name of an estimator type, e.g. "uni-nee-mis/power/absorb-weight".
template <class E>
std::string estimator_name() {
    return std::string(E::Strategy::name) + "/" + E::HeuristicType::name + "/" + E::Absorption::name;
}

/// A readable name of a combo, e.g. "rgb/grid/absorb-event".
template <class C>
std::string combo_name() {
    return std::string(C::Spectral::name) + "/" + MediumKind<typename C::Medium>::name + "/" +
           C::Absorption::name;
}

// ---------------------------------------------------------------------------------------------
// Statistics

/// Running mean and variance of scalar samples (Welford), in double.
struct Stat {
    double n = 0.0, mean = 0.0, m2 = 0.0;
    void add(double x) {
        n += 1.0;
        const double d = x - mean;
        mean += d / n;
        m2 += d * (x - mean);
    }
    /// Unbiased sample variance of one sample.
    double variance() const { return n > 1.0 ? m2 / (n - 1.0) : 0.0; }
    /// Standard error of the mean, estimated from the samples.
    double se() const { return std::sqrt(variance() / n); }
};

/// A Stat per channel.
template <SpectralMode S>
struct SpecStat {
    std::array<Stat, S::channels> ch;
    void add(const typename S::Spectrum& v) {
        for (int c = 0; c < S::channels; ++c) ch[std::size_t(c)].add(double(v[c]));
    }
};

/// Floor on tolerances of means whose samples may all be equal (SE = 0): float rounding of one
/// estimate is ~1e-6 relative, so 1e-5 absolute is far below any bias a test looks for.
inline constexpr double kRoundingFloor = 1e-5;

/// Checks every channel's mean in `stat` against `expected` within `sigmas` standard errors of the
/// mean (estimated from the samples) plus kRoundingFloor, with a message naming `label`.
template <SpectralMode S>
void check_channel_means(const SpecStat<S>& stat, const typename S::Spectrum& expected, const std::string& label,
                         double sigmas) {
    for (int c = 0; c < S::channels; ++c) {
        const Stat& s = stat.ch[std::size_t(c)];
        CAPTURE(label);
        CAPTURE(c);
        MESSAGE(label << " channel " << c << ": " << s.mean << " (SE " << s.se() << "), closed form " << expected[c]);
        CHECK(std::abs(s.mean - double(expected[c])) <= sigmas * s.se() + kRoundingFloor);
    }
}

/// Pearson's chi-square statistic of `counts` against bin probabilities `prob` (summing to 1)
/// for `n` samples. Checks that every expected count is at least 5 (the usual validity rule).
inline double chi_square(const std::vector<double>& counts, const std::vector<double>& prob, double n) {
    REQUIRE(counts.size() == prob.size());
    double chi2 = 0.0, psum = 0.0;
    for (std::size_t i = 0; i < counts.size(); ++i) {
        const double e = n * prob[i];
        CHECK(e >= 5.0);
        chi2 += (counts[i] - e) * (counts[i] - e) / e;
        psum += prob[i];
    }
    CHECK(psum == doctest::Approx(1.0).epsilon(1e-9));
    return chi2;
}

/// Upper 0.1 % point of the chi-square distribution (p = 1e-3), computed to 3 decimals from the
/// regularised incomplete gamma function, for the degrees of freedom these tests use.
inline double chi_square_critical_p001(int dof) {
    switch (dof) {
        case 9: return 27.877;
        case 10: return 29.588;
        case 14: return 36.123;
        case 15: return 37.697;
        case 19: return 43.820;
        case 20: return 45.315;
        case 24: return 51.179;
        case 29: return 58.301;
        case 30: return 59.703;
        case 39: return 72.055;
        case 40: return 73.402;
        default: FAIL("no chi-square critical value tabulated for dof = " << dof); return 0.0;
    }
}

/// A uniformly random unit direction drawn with `rng`.
template <UniformRng R>
Vec3 random_direction(R& rng) {
    const float u1 = rng.uniform(), u2 = rng.uniform();
    return uniform_sphere(u1, u2);
}

/// A uniformly random point in box b.
template <UniformRng R>
Vec3 random_point(R& rng, const Box& b) {
    const float u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
    return b.lo + Vec3(u1, u2, u3) * (b.hi - b.lo);
}

}  // namespace nsp_test

// Readable test names for every type the generic suites run over.
TYPE_TO_STRING_AS("mono/homogeneous/absorb-event", nsp_test::Combo<nsp::Mono, nsp::HomogeneousMedium, nsp::absorption::Event>);
TYPE_TO_STRING_AS("mono/homogeneous/absorb-weight", nsp_test::Combo<nsp::Mono, nsp::HomogeneousMedium, nsp::absorption::Weight>);
TYPE_TO_STRING_AS("mono/grid/absorb-event", nsp_test::Combo<nsp::Mono, nsp::DenseGridMedium, nsp::absorption::Event>);
TYPE_TO_STRING_AS("mono/grid/absorb-weight", nsp_test::Combo<nsp::Mono, nsp::DenseGridMedium, nsp::absorption::Weight>);
TYPE_TO_STRING_AS("mono/exponential/absorb-event", nsp_test::Combo<nsp::Mono, nsp::ExponentialMedium, nsp::absorption::Event>);
TYPE_TO_STRING_AS("mono/exponential/absorb-weight", nsp_test::Combo<nsp::Mono, nsp::ExponentialMedium, nsp::absorption::Weight>);
TYPE_TO_STRING_AS("rgb/homogeneous/absorb-event", nsp_test::Combo<nsp::Rgb, nsp::HomogeneousMedium, nsp::absorption::Event>);
TYPE_TO_STRING_AS("rgb/homogeneous/absorb-weight", nsp_test::Combo<nsp::Rgb, nsp::HomogeneousMedium, nsp::absorption::Weight>);
TYPE_TO_STRING_AS("rgb/grid/absorb-event", nsp_test::Combo<nsp::Rgb, nsp::DenseGridMedium, nsp::absorption::Event>);
TYPE_TO_STRING_AS("rgb/grid/absorb-weight", nsp_test::Combo<nsp::Rgb, nsp::DenseGridMedium, nsp::absorption::Weight>);
TYPE_TO_STRING_AS("rgb/exponential/absorb-event", nsp_test::Combo<nsp::Rgb, nsp::ExponentialMedium, nsp::absorption::Event>);
TYPE_TO_STRING_AS("rgb/exponential/absorb-weight", nsp_test::Combo<nsp::Rgb, nsp::ExponentialMedium, nsp::absorption::Weight>);

TYPE_TO_STRING_AS("unidirectional/absorb-event", nsp::PathEstimator<nsp::strategy::Unidirectional, nsp::mis::None, nsp::absorption::Event>);
TYPE_TO_STRING_AS("ratio-nee/absorb-event", nsp::PathEstimator<nsp::strategy::NextEvent, nsp::mis::None, nsp::absorption::Event>);
TYPE_TO_STRING_AS("directional-mis/balance/absorb-event", nsp::PathEstimator<nsp::strategy::DirectionalMis, nsp::mis::Balance, nsp::absorption::Event>);
TYPE_TO_STRING_AS("directional-mis/power/absorb-event", nsp::PathEstimator<nsp::strategy::DirectionalMis, nsp::mis::Power, nsp::absorption::Event>);
TYPE_TO_STRING_AS("uni-nee-mis/balance/absorb-event", nsp::PathEstimator<nsp::strategy::NullScatteringMis, nsp::mis::Balance, nsp::absorption::Event>);
TYPE_TO_STRING_AS("uni-nee-mis/power/absorb-event", nsp::PathEstimator<nsp::strategy::NullScatteringMis, nsp::mis::Power, nsp::absorption::Event>);
TYPE_TO_STRING_AS("unidirectional/absorb-weight", nsp::PathEstimator<nsp::strategy::Unidirectional, nsp::mis::None, nsp::absorption::Weight>);
TYPE_TO_STRING_AS("ratio-nee/absorb-weight", nsp::PathEstimator<nsp::strategy::NextEvent, nsp::mis::None, nsp::absorption::Weight>);
TYPE_TO_STRING_AS("directional-mis/balance/absorb-weight", nsp::PathEstimator<nsp::strategy::DirectionalMis, nsp::mis::Balance, nsp::absorption::Weight>);
TYPE_TO_STRING_AS("directional-mis/power/absorb-weight", nsp::PathEstimator<nsp::strategy::DirectionalMis, nsp::mis::Power, nsp::absorption::Weight>);
TYPE_TO_STRING_AS("uni-nee-mis/balance/absorb-weight", nsp::PathEstimator<nsp::strategy::NullScatteringMis, nsp::mis::Balance, nsp::absorption::Weight>);
TYPE_TO_STRING_AS("uni-nee-mis/power/absorb-weight", nsp::PathEstimator<nsp::strategy::NullScatteringMis, nsp::mis::Power, nsp::absorption::Weight>);

TYPE_TO_STRING_AS("mono", nsp::Mono);
TYPE_TO_STRING_AS("rgb", nsp::Rgb);

namespace nsp_test {

/// Radiance statistics of n independent estimates along `ray`, and how many were not Status::Ok.
template <class S>
struct RadianceStats {
    SpecStat<S> stat;
    int not_ok = 0;
    std::uint64_t lookups = 0;
};

/// Runs estimator `est` n times on `scene` along `ray` with a generator seeded (seed, stream).
template <class E, class Sc>
RadianceStats<typename Sc::Spectral> estimate_radiance(const E& est, const Sc& scene, const Ray& ray, int n,
                                                       std::uint64_t seed, std::uint64_t stream = 1) {
    RadianceStats<typename Sc::Spectral> out;
    Pcg32 rng(seed, stream);
    LookupCount lookups;
    for (int i = 0; i < n; ++i) {
        const auto r = est.radiance(scene, ray, typename Sc::Spectral::Wavelengths{}, rng, lookups);
        out.not_ok += r.status != Status::Ok;
        out.stat.add(r.value);
    }
    out.lookups = lookups.count();
    return out;
}

}  // namespace nsp_test
