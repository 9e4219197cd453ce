// tests/test_blackbody.cpp: blackbody emission from a temperature grid (media/blackbody.hpp):
// Planck's law against the Stefan-Boltzmann law, Wien's displacement law and the Rayleigh-Jeans
// limit (closed forms that do not use the formula), the Rgb / Mono temperature tables against
// direct integration, the Hero radiance at the path's wavelengths, the rejections, and the
// estimators on an emitting absorber of one temperature against the closed form
// L = L_e (1 - exp(-mu_a d)) per channel or wavelength.
//
// Statistical checks: fixed seeds (deterministic), k = 5 standard errors estimated from the
// samples, plus kRoundingFloor where every sample may equal the expected value.
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "spectral.hpp"

namespace {

using namespace nsp_test;
using doctest::Contains;

constexpr double kSigmas = 5.0;
const Box kBox{Vec3(-1.f), Vec3(1.f)};

/// A constant temperature over kBox: trilinear lookups give exactly `kelvin` inside.
EmissionGrid constant_temperature(float kelvin) { return EmissionGrid(kBox, {2, 2, 2}, std::vector<float>(8, kelvin)); }

TEST_CASE("planck integrates to the Stefan-Boltzmann law: pi int B dlambda = sigma T^4") {
    constexpr double sigma = 5.670374419e-8;  // W m^-2 K^-4 (CODATA 2018)
    for (double t : {300.0, 1000.0, 1800.0, 5800.0, 20000.0}) {
        // Midpoint rule in log(lambda) over [1 nm, 1e8 nm] (B dlambda = B lambda dlog lambda):
        // both tails hold below 1e-9 of the total at these temperatures.
        const int n = 200000;
        const double a = std::log(1.0), b = std::log(1e8), h = (b - a) / n;
        double s = 0.0;
        for (int i = 0; i < n; ++i) {
            const double nm = std::exp(a + (i + 0.5) * h);
            s += planck(nm, t) * nm * h;
        }
        const double expected = sigma * t * t * t * t / std::numbers::pi;  // W m^-2 sr^-1
        CAPTURE(t);
        CHECK(s == doctest::Approx(expected).epsilon(1e-6));
    }
}

TEST_CASE("planck peaks at Wien's wavelength and meets the Rayleigh-Jeans limit; 0 at T <= 0") {
    for (double t : {800.0, 3000.0, 6500.0}) {
        const double peak = wien_peak_nm(t);
        CAPTURE(t);
        CHECK(planck(peak, t) == doctest::Approx(planck_peak(t)));
        CHECK(planck(peak * 0.99, t) < planck(peak, t));
        CHECK(planck(peak * 1.01, t) < planck(peak, t));
    }
    // lambda T >> hc/k: B -> 2 c k T / lambda^4 (per m), relative error about x / 2 with x = hc / (lambda k T).
    const double c = 299792458.0, k = 1.380649e-23, t = 10000.0, nm = 1e6, m = nm * 1e-9;
    const double rj = 2.0 * c * k * t / (m * m * m * m) * 1e-9;
    CHECK(planck(nm, t) == doctest::Approx(rj).epsilon(1e-3));
    CHECK(planck(550.0, 0.0) == 0.0);
    CHECK(planck(550.0, -5.0) == 0.0);
    CHECK(planck(550.0, 1.0) == 0.0);  // underflows: finite, not NaN
}

TEST_CASE_TEMPLATE("BlackbodyEmission's Rgb and Mono tables follow direct integration within 1e-3", S, Mono, Rgb) {
    // A ramp of temperature 0 .. 2500 K along x: the table's entries are 0.61 K apart. Linear
    // interpolation of exp(-c2 / (lambda T)) errs by about (c2 / (lambda T^2) dT)^2 / 8 relative:
    // below 3e-4 at 450 nm for T >= 625 K (T_max / 4), the range checked; colder voxels emit
    // less than 1e-6 of the hottest. The tolerance, 1e-3 of the channel plus 1e-6 of the largest
    // channel (sRGB channels are differences of XYZ and may cancel), leaves room for that error.
    for (bool normalize : {false, true}) {
        const BlackbodyEmission<S> ramp(EmissionGrid(kBox, {2, 1, 1}, {0.f, 2500.f}), 1.f, 1.f, normalize);
        Pcg32 rng(11, 3);
        for (int i = 0; i < 300; ++i) {
            const float u = 0.25f + 0.75f * rng.uniform();
            const Vec3 p(-0.5f + u, 0.f, 0.f);  // voxel centres at x = -0.5 (0 K) and 0.5 (2500 K)
            const float t = ramp.temperature(p);
            CHECK(t == doctest::Approx(2500.f * u).epsilon(1e-5));
            const Eigen::Array3d ref = detail::blackbody_rgb(double(t), normalize);
            const auto got = ramp.radiance(p, {});
            CAPTURE(t);
            CAPTURE(normalize);
            if constexpr (S::channels == 3) {
                for (int c = 0; c < 3; ++c) {
                    CAPTURE(c);
                    CHECK(std::abs(double(got[c]) - ref[c]) <= 1e-3 * ref[c] + 1e-6 * ref.maxCoeff());
                }
            } else {
                const double y = 0.2126 * ref[0] + 0.7152 * ref[1] + 0.0722 * ref[2];
                CHECK(std::abs(double(got[0]) - y) <= 1e-3 * y);
            }
        }
        // At the hottest temperature the lookup is the last entry: exact.
        const auto hot = ramp.radiance(Vec3(0.5f, 0.f, 0.f), {});
        const Eigen::Array3d ref = detail::blackbody_rgb(2500.0, normalize);
        if constexpr (S::channels == 3)
            for (int c = 0; c < 3; ++c) CHECK(hot[c] == doctest::Approx(ref[c]).epsilon(1e-6));
    }
}

TEST_CASE("BlackbodyEmission in Hero mode is Planck's law at the path's wavelengths, times radiance_scale") {
    const BlackbodyEmission<Hero<4>> bb(EmissionGrid(kBox, {2, 1, 1}, {1.f, 3.f}), 1000.f, 0.25f);
    const BlackbodyEmission<Hero<4>> norm(EmissionGrid(kBox, {2, 1, 1}, {1.f, 3.f}), 1000.f, 0.25f, true);
    Pcg32 rng(5, 9);
    for (int i = 0; i < 100; ++i) {
        const auto l = HeroWavelengths<4>::sample(rng.uniform());
        const Vec3 p(-1.f + 2.f * rng.uniform(), 0.f, 0.f);
        const double t = double(bb.temperature(p));
        CHECK(t == doctest::Approx(1000.0 * (1.0 + 2.0 * std::clamp(double(p.x) + 0.5, 0.0, 1.0))).epsilon(1e-6));
        const auto a = bb.radiance(p, l), b = norm.radiance(p, l);
        for (int c = 0; c < 4; ++c) {
            const double nm = double(l.nm[std::size_t(c)]);
            CHECK(a[c] == doctest::Approx(0.25 * planck(nm, t)).epsilon(1e-5));
            CHECK(b[c] == doctest::Approx(0.25 * planck(nm, t) / planck_peak(t)).epsilon(1e-5));
        }
    }
    CHECK((bb.radiance(Vec3(2.f, 0.f, 0.f), {}) == 0.f).all());  // outside the grid
    CHECK(bb.may_emit(Box{Vec3(-1.f), Vec3(0.f)}));
    CHECK_FALSE(bb.may_emit(Box{Vec3(2.f), Vec3(3.f)}));
    CHECK(bb.max_temperature() == doctest::Approx(3000.0));
}

TEST_CASE("BlackbodyEmission rejects bad scales and temperatures, naming the value") {
    const auto g = constant_temperature(1500.f);
    CHECK_THROWS_WITH_AS(BlackbodyEmission<Rgb>(g, -1.f), Contains("temperature_scale = -1"), InvalidArgument);
    CHECK_THROWS_WITH_AS(BlackbodyEmission<Rgb>(g, std::numeric_limits<float>::quiet_NaN()), Contains("temperature_scale = nan"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(BlackbodyEmission<Rgb>(g, 1.f, -2.f), Contains("radiance_scale = -2"), InvalidArgument);
    CHECK_THROWS_WITH_AS(BlackbodyEmission<Hero<4>>(g, 1000.f), Contains("at most 1e+06 K"), InvalidArgument);
    CHECK_THROWS_WITH_AS(BlackbodyEmission<Rgb>(g, 1.f, 3e38f), Contains("must be finite in float"), InvalidArgument);
    CHECK_THROWS_WITH_AS(BlackbodyEmission<Hero<4>>(g, 1.f, 3e38f), Contains("must be finite in float"), InvalidArgument);
}

TEST_CASE_TEMPLATE("Emissive with BlackbodyEmission: power grid only where it is hot, pdf follows emission", S, Mono, Rgb,
                   Hero<4>) {
    // Hot in the x < 0 half only: the power grid gives the cold half's cells probability 0.
    std::vector<float> t{2000.f, 0.f, 2000.f, 0.f};  // 2 x 2 x 1: x = 0 hot, x = 1 cold
    const HomogeneousMedium<S> base(kBox, constant_coefficient<S>(0.5f), constant_coefficient<S>(0.f));
    const Emissive<HomogeneousMedium<S>, BlackbodyEmission<S>> m(
        base, BlackbodyEmission<S>(EmissionGrid(Box{Vec3(-1.f), Vec3(0.f, 1.f, 1.f)}, {2, 2, 1}, t), 1.f, 1.f, true),
        {4, 4, 4});
    static_assert(EmissiveMedium<decltype(m)>);
    CHECK(m.emission_pdf(Vec3(-0.9f, 0.f, 0.f)) > m.emission_pdf(Vec3(-0.1f, 0.f, 0.f)));
    CHECK(m.emission_pdf(Vec3(0.5f, 0.f, 0.f)) == 0.f);  // outside the temperature grid
    Pcg32 rng(3, 1);
    for (int i = 0; i < 1000; ++i) {
        const VolumeSample v = m.sample_emission(rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform());
        REQUIRE(v.pdf > 0.f);
        CHECK(v.p.x <= 0.f);
        CHECK(m.emission_pdf(v.p) == v.pdf);
    }
}

template <ChannelPolicy CP>
using BlackbodyEstimators = std::tuple<SpectralPathEstimator<CP, strategy::Unidirectional, mis::None>,
                                       SpectralPathEstimator<CP, strategy::NextEvent, mis::None>,
                                       SpectralPathEstimator<CP, strategy::NullScatteringMis, mis::Balance>>;
using AllBlackbodyEstimators =
    decltype(std::tuple_cat(BlackbodyEstimators<channels::Independent>{}, BlackbodyEstimators<channels::SpectralMis>{}));

TEST_CASE_TEMPLATE_DEFINE("a blackbody absorber of one temperature: L = L_e (1 - exp(-mu_a d)) per channel", E,
                          blackbody_absorber) {
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    const E est;
    auto run = [&](auto tag) {
        using S = decltype(tag);
        // Chromatic absorption (Rgb: 0.6 : 0.9 : 0.3; Hero: a ramp over wavelength), no scattering,
        // 1800 K everywhere in the unit box: along a ray crossing d = 2 of it, every channel sees
        // L_e,c (1 - exp(-mu_a,c 2)); no light.
        const auto sa = chroma<S>(0.6f, 0.9f, 0.3f);
        const HomogeneousMedium<S> base(kBox, sa, constant_coefficient<S>(0.f));
        const BlackbodyEmission<S> field(constant_temperature(1800.f), 1.f, 1.f, true);
        const Emissive<HomogeneousMedium<S>, BlackbodyEmission<S>> medium(base, field, {4, 4, 4});
        const Ray ray{Vec3(-3.f, 0.1f, -0.2f), Vec3(1.f, 0.f, 0.f)};
        const Vec3 inside(0.f, 0.1f, -0.2f);
        const auto scene = Scene(medium, GlobalMajorant<decltype(medium)>(medium), IsotropicPhase{}, Lights<S>{});
        const auto res = estimate_error(est, scene, ray, 20000, 900, [&](const auto& lambda) {
            const auto mu = S::sample(sa, lambda);
            return typename S::Spectrum(field.radiance(inside, lambda) * (1.f - (-2.f * mu).exp()));
        });
        CHECK(res.not_ok == 0);
        for (int c = 0; c < S::channels; ++c) {
            const Stat& s = res.stat.ch[std::size_t(c)];
            CAPTURE(c);
            MESSAGE(name << " " << std::string(S::name) << ": error " << s.mean << " (SE " << s.se() << ")");
            CHECK(std::abs(s.mean) <= kSigmas * s.se() + kRoundingFloor);
        }
    };
    run(Rgb{});
    run(Hero<4>{});
}
TEST_CASE_TEMPLATE_APPLY(blackbody_absorber, AllBlackbodyEstimators);

}  // namespace
