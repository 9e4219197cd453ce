// tests/test_spectral_estimators.cpp: every spectral estimator (independent tracking, spectral
// tracking max / average, spectral MIS; unidirectional, NEE and their null-scattering MIS; both
// absorption policies) is unbiased in every channel, in Rgb and Hero<4>: against closed-form
// transmittance with channels 1e4 apart and one of zero extinction, the furnace, an Rgb medium
// rendered as three Mono media, and a grey medium in every mode. Hero wavelengths integrate
// known spectra to the right CIE XYZ.
//
// Statistical checks: fixed seeds (deterministic), k = 5 standard errors estimated from the
// samples, plus kRoundingFloor where every sample may be exactly the expected value.
#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "spectral.hpp"

namespace {

using namespace nsp_test;

constexpr double kSigmas = 5.0;
const Box kBox{Vec3(-1.f), Vec3(1.f)};

/// Checks that every channel's mean error is within kSigmas SE of 0.
template <SpectralMode S>
void check_unbiased(const RadianceStats<S>& res, double floor = kRoundingFloor) {
    CHECK(res.not_ok == 0);
    for (int c = 0; c < S::channels; ++c) {
        CAPTURE(c);
        const Stat& s = res.stat.ch[std::size_t(c)];
        CAPTURE(s.mean);
        CAPTURE(s.se());
        CHECK(std::abs(s.mean) <= kSigmas * s.se() + floor);
    }
}

/// Lights: a unit white environment.
template <SpectralMode S>
Lights<S> unit_environment() {
    Lights<S> l;
    l.set(EnvironmentLight<S>{constant_coefficient<S>(1.f)});
    return l;
}

/// The scene of estimator E's channel policy for medium m (its majorant kind), HG g = 0.5.
template <class E, Medium M>
auto scene_for(const M& m, Lights<typename M::Spectral> lights) {
    using Maj = MajorantFor<typename E::Channels, M>;
    return Scene<M, Maj, HenyeyGreensteinPhase>(m, Maj(m), HenyeyGreensteinPhase(0.5f), std::move(lights));
}

TEST_CASE_TEMPLATE_DEFINE("spectral estimators: directly transmitted light equals exp(-tau_c) per channel, channels "
                          "1e4 apart and one of zero extinction", E, transmitted) {
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    EstimatorOptions opts;
    opts.max_depth = 0;  // the camera segment only: a closed form whatever the strategy
    const E est(opts);
    auto run = [&](auto tag, const auto& medium, const char* medium_name) {
        using S = decltype(tag);
        CAPTURE(medium_name);
        const std::string mode = S::name;
        CAPTURE(mode);
        const auto scene = scene_for<E>(medium, unit_environment<S>());
        const Ray ray{Vec3(-3.f, 0.1f, 0.2f), glm::normalize(Vec3(1.f, 0.05f, -0.1f))};
        const auto res = estimate_error(est, scene, ray, 20000, 31, [&](const typename S::Wavelengths& l) {
            return typename S::Spectrum((-medium.optical_depth(ray, 0.f, kInf, l)).exp());
        });
        check_unbiased(res);
    };
    auto for_mode = [&](auto tag) {
        using S = decltype(tag);
        // Extinction per unit density 2e-4, 0 and 2 (R, G, B; Hero: 650, 550, 450 nm): optical
        // depths about 4e-4, 0 and 4 across the box.
        const auto sa = chroma<S>(1e-4f, 0.f, 1.f), ss = chroma<S>(1e-4f, 0.f, 1.f);
        run(tag, make_medium<HomogeneousMedium<S>>(kBox, 1.f, sa, ss), "homogeneous");
        run(tag, make_medium<ExponentialMedium<S>>(kBox, 1.f, sa, ss), "exponential");
    };
    for_mode(Rgb{});
    for_mode(Hero<4>{});
}

TEST_CASE_TEMPLATE_APPLY(transmitted, AllSpectralEstimators);

TEST_CASE_TEMPLATE_DEFINE("spectral estimators: furnace (albedo 1, unit environment) gives 1 in every channel", E, spectral_furnace) {
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    const E est;
    auto run = [&](auto tag, const auto& medium, const char* medium_name) {
        using S = decltype(tag);
        CAPTURE(medium_name);
        const std::string mode = S::name;
        CAPTURE(mode);
        const auto scene = scene_for<E>(medium, unit_environment<S>());
        const Ray ray{Vec3(-3.f, 0.2f, 0.1f), glm::normalize(Vec3(1.f, -0.05f, 0.02f))};
        const auto res = estimate_error(est, scene, ray, 10000, 32,
                                        [](const typename S::Wavelengths&) { return S::Spectrum::Ones().eval(); });
        check_unbiased(res);
        CHECK(res.lookups > 0);
    };
    auto for_mode = [&](auto tag) {
        using S = decltype(tag);
        // Extinction 0.5, 0 and 1.5 per unit density (4x apart, one channel empty), sigma_a = 0.
        const auto zero = constant_coefficient<S>(0.f), ss = chroma<S>(0.5f, 0.f, 1.5f);
        run(tag, make_medium<HomogeneousMedium<S>>(kBox, 1.f, zero, ss), "homogeneous");
        run(tag, make_medium<DenseGridMedium<S>>(kBox, 1.f, zero, ss, 42), "grid");
    };
    for_mode(Rgb{});
    for_mode(Hero<4>{});
}

TEST_CASE_TEMPLATE_APPLY(spectral_furnace, AllSpectralEstimators);

/// Lights of the comparison scenes: an environment of 0.5 and a sphere light of radiance 5.
template <SpectralMode S>
Lights<S> env_and_sphere() {
    Lights<S> l;
    l.set(EnvironmentLight<S>{constant_coefficient<S>(0.5f)});
    l.set(SphereLight<S>{Vec3(0.5f, 2.5f, -0.3f), 0.4f, constant_coefficient<S>(5.f)});
    return l;
}

/// Mono reference of one channel: uni + NEE null-scattering MIS on the grey medium with that
/// channel's coefficients, n samples.
Stat mono_reference(float sa, float ss, const Ray& ray, int n, bool grid) {
    const HenyeyGreensteinPhase phase(0.5f);
    const PathEstimator<strategy::NullScatteringMis, mis::Balance> est;
    auto stat_of = [&](const auto& medium) {
        const auto scene = make_scene(medium, phase, env_and_sphere<Mono>());
        return estimate_radiance(est, scene, ray, n, 77).stat.ch[0];
    };
    if (grid) return stat_of(make_medium<DenseGridMedium<Mono>>(kBox, 1.f, grey<Mono>(sa), grey<Mono>(ss), 43));
    return stat_of(make_medium<HomogeneousMedium<Mono>>(kBox, 1.f, grey<Mono>(sa), grey<Mono>(ss)));
}

/// Estimator `est` on an Rgb medium against three Mono media at NEE count 1, one per channel.
template <class E>
void check_rgb_as_three_mono(const E& est) {
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    CAPTURE(est.options().nee_count);
    // Albedo 0.8, extinction 0.5 : 1 : 2 per unit density.
    const float ext[3] = {0.5f, 1.f, 2.f};
    const Ray ray{Vec3(0.2f, -0.1f, -3.f), glm::normalize(Vec3(-0.05f, 0.1f, 1.f))};
    for (const bool grid : {false, true}) {
        CAPTURE(grid);
        const auto sa = spec<Rgb>(0.2f * ext[0], 0.2f * ext[1], 0.2f * ext[2]);
        const auto ss = spec<Rgb>(0.8f * ext[0], 0.8f * ext[1], 0.8f * ext[2]);
        const HenyeyGreensteinPhase phase(0.5f);
        auto rgb_stats = [&](const ChannelSelection<Rgb>& q) {
            auto run = [&](const auto& medium) {
                return estimate_error(est, scene_for<E>(medium, env_and_sphere<Rgb>()), ray, 20000, 33,
                                      [](const Rgb::Wavelengths&) { return Rgb::Spectrum::Zero().eval(); }, q);
            };
            return grid ? run(make_medium<DenseGridMedium<Rgb>>(kBox, 1.f, sa, ss, 43))
                        : run(make_medium<HomogeneousMedium<Rgb>>(kBox, 1.f, sa, ss));
        };
        for (const bool uniform : {true, false}) {
            CAPTURE(uniform);
            const auto res = rgb_stats(uniform ? ChannelSelection<Rgb>() : ChannelSelection<Rgb>(spec<Rgb>(1.f, 2.f, 5.f)));
            CHECK(res.not_ok == 0);
            for (int c = 0; c < 3; ++c) {
                CAPTURE(c);
                const Stat ref = mono_reference(sa[c], ss[c], ray, 40000, grid);
                const Stat& s = res.stat.ch[std::size_t(c)];
                CAPTURE(s.mean);
                CAPTURE(s.se());
                CAPTURE(ref.mean);
                CAPTURE(ref.se());
                CHECK(std::abs(s.mean - ref.mean) <= kSigmas * std::sqrt(s.se() * s.se() + ref.se() * ref.se()));
            }
        }
    }
}

TEST_CASE_TEMPLATE_DEFINE("spectral estimators: an Rgb medium agrees with three Mono media, one per channel "
                          "(uniform and non-uniform channel selection)", E, rgb_as_three_mono) {
    check_rgb_as_three_mono(E{});
}

TEST_CASE_TEMPLATE_DEFINE("spectral estimators at NEE count 0.3 (THEORY 5.9) agree with three Mono media at count 1",
                          E, rgb_counts) {
    EstimatorOptions o;
    o.nee_count = 0.3f;
    check_rgb_as_three_mono(E(o));
}

using AbsorbWeightSpectralEstimators = SpectralEstimatorsWith<absorption::Weight>;
TEST_CASE_TEMPLATE_APPLY(rgb_as_three_mono, AbsorbWeightSpectralEstimators);
TEST_CASE_TEMPLATE_APPLY(rgb_counts, AbsorbWeightSpectralEstimators);

TEST_CASE_TEMPLATE_DEFINE("a grey medium gives the same mean in every mode and tracker", E, grey_every_mode) {
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    const E est;
    const Ray ray{Vec3(0.2f, -0.1f, -3.f), glm::normalize(Vec3(-0.05f, 0.1f, 1.f))};
    const Stat ref = mono_reference(0.2f, 0.8f, ray, 40000, true);
    auto run = [&](auto tag) {
        using S = decltype(tag);
        const std::string mode = S::name;
        CAPTURE(mode);
        const auto medium = make_medium<DenseGridMedium<S>>(kBox, 1.f, constant_coefficient<S>(0.2f),
                                                            constant_coefficient<S>(0.8f), 43);
        const auto res = estimate_error(est, scene_for<E>(medium, env_and_sphere<S>()), ray, 20000, 34,
                                        [](const typename S::Wavelengths&) { return S::Spectrum::Zero().eval(); });
        CHECK(res.not_ok == 0);
        for (int c = 0; c < S::channels; ++c) {
            CAPTURE(c);
            const Stat& s = res.stat.ch[std::size_t(c)];
            CAPTURE(s.mean);
            CAPTURE(ref.mean);
            CHECK(std::abs(s.mean - ref.mean) <= kSigmas * std::sqrt(s.se() * s.se() + ref.se() * ref.se()));
        }
    };
    run(Rgb{});
    run(Hero<4>{});
}

TEST_CASE_TEMPLATE_APPLY(grey_every_mode, AllSpectralEstimators);

TEST_CASE("the grey PathEstimator on a grey medium gives the Mono mean in Rgb and Hero<4>") {
    const Ray ray{Vec3(0.2f, -0.1f, -3.f), glm::normalize(Vec3(-0.05f, 0.1f, 1.f))};
    const Stat ref = mono_reference(0.2f, 0.8f, ray, 40000, true);
    const PathEstimator<strategy::NullScatteringMis, mis::Balance> est;
    auto run = [&](auto tag) {
        using S = decltype(tag);
        const std::string mode = S::name;
        CAPTURE(mode);
        const auto medium = make_medium<DenseGridMedium<S>>(kBox, 1.f, constant_coefficient<S>(0.2f),
                                                            constant_coefficient<S>(0.8f), 43);
        const auto scene = make_scene(medium, HenyeyGreensteinPhase(0.5f), env_and_sphere<S>());
        const auto res = estimate_error(est, scene, ray, 20000, 35,
                                        [](const typename S::Wavelengths&) { return S::Spectrum::Zero().eval(); });
        CHECK(res.not_ok == 0);
        for (int c = 0; c < S::channels; ++c) {
            const Stat& s = res.stat.ch[std::size_t(c)];
            CHECK(std::abs(s.mean - ref.mean) <= kSigmas * std::sqrt(s.se() * s.se() + ref.se() * ref.se()));
        }
    };
    run(Rgb{});
    run(Hero<4>{});
}

/// CIE XYZ of spectrum `s` by Simpson's rule on 0.1 nm steps over the visible range, divided by
/// int y-bar (the normalisation of hero_to_xyz).
template <class F>
Eigen::Array3d xyz_quadrature(F&& s) {
    const int n = 4700;
    const double h = double(kLambdaMax - kLambdaMin) / n;
    Eigen::Array3d acc = Eigen::Array3d::Zero();
    double y_bar = 0.0;
    for (int i = 0; i <= n; ++i) {
        const double l = double(kLambdaMin) + h * i;
        const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        const Eigen::Array3d cmf = cie_xyz_bar(l);
        acc += w * s(l) * cmf;
        y_bar += w * cmf[1];
    }
    return acc / y_bar;
}

TEST_CASE("hero wavelengths integrate a constant and a Gaussian spectrum to the right XYZ") {
    // The sampled wavelengths are stratified: N = 4 per path, 117.5 nm apart, each uniform.
    Pcg32 rng(40, 1);
    for (int i = 0; i < 1000; ++i) {
        const auto w = Hero<4>::Wavelengths::sample(rng.uniform());
        for (int k = 0; k < 4; ++k) {
            REQUIRE(w.nm[std::size_t(k)] >= kLambdaMin);
            REQUIRE(w.nm[std::size_t(k)] < kLambdaMax);
            const float d = w.nm[std::size_t((k + 1) % 4)] - w.nm[std::size_t(k)];
            REQUIRE(std::abs(d - 117.5f) < 1e-3f + float(d < 0.f) * 1e9f);  // neighbours 117.5 nm apart (mod range)
        }
    }
    auto gaussian = [](double l) { return 2.0 * std::exp(-0.5 * (l - 550.0) * (l - 550.0) / (30.0 * 30.0)); };
    struct Case {
        const char* name;
        TabulatedSpectrum table;
        std::function<double(double)> exact;
    };
    std::vector<float> nm, values;
    for (int l = 360; l <= 830; l += 5) {
        nm.push_back(float(l));
        values.push_back(float(gaussian(l)));
    }
    const Case cases[] = {
        {"constant 1", TabulatedSpectrum::constant(1.f), [](double) { return 1.0; }},
        // The table interpolates the Gaussian linearly every 10 nm: integrate that same curve.
        {"gaussian", TabulatedSpectrum::from_points(nm, values), {}},
    };
    for (const Case& cs : cases) {
        CAPTURE(cs.name);
        const Eigen::Array3d expected = xyz_quadrature([&](double l) { return double(cs.table(float(l))); });
        if (cs.exact) {  // constant 1: Y is 1 by the normalisation
            CHECK(expected[1] == doctest::Approx(1.0).epsilon(1e-9));
        }
        std::array<Stat, 3> st;
        for (int i = 0; i < 100000; ++i) {
            const auto w = Hero<4>::Wavelengths::sample(rng.uniform());
            const Eigen::Array3d xyz = hero_to_xyz<4>(Hero<4>::sample(cs.table, w), w);
            for (int k = 0; k < 3; ++k) st[std::size_t(k)].add(xyz[k]);
        }
        for (int k = 0; k < 3; ++k) {
            CAPTURE(k);
            CAPTURE(st[std::size_t(k)].mean);
            CAPTURE(expected[k]);
            CHECK(std::abs(st[std::size_t(k)].mean - expected[k]) <= kSigmas * st[std::size_t(k)].se() + 1e-6);
        }
    }
    // The Gaussian's table agrees with the Gaussian itself to the interpolation error (~1e-3 of
    // its XYZ), so the test above integrates the spectrum meant, not just the table.
    const Eigen::Array3d g_exact = xyz_quadrature(gaussian);
    const Eigen::Array3d g_table = xyz_quadrature([&](double l) { return double(cases[1].table(float(l))); });
    CHECK((g_exact - g_table).abs().maxCoeff() < 5e-3 * g_exact.abs().maxCoeff());
    // White (equal energy) maps to linear sRGB near (1, 1, 1): E is not D65, so not exactly.
    const Eigen::Array3d white = xyz_to_linear_srgb(xyz_quadrature([](double) { return 1.0; }));
    CHECK((white - 1.0).abs().maxCoeff() < 0.25);
}

TEST_CASE("TabulatedSpectrum: interpolation, and rejected input named") {
    const auto s = TabulatedSpectrum::from_points({400.f, 500.f}, {1.f, 3.f});
    CHECK(s(360.f) == 1.f);
    CHECK(s(450.f) == doctest::Approx(2.f));
    CHECK(s(830.f) == 3.f);
    CHECK(s.max_value() == 3.f);
    CHECK((s + s)(450.f) == doctest::Approx(4.f));
    CHECK_THROWS_WITH_AS(TabulatedSpectrum::from_points({400.f, 500.f}, {1.f}),
                         "nsp: TabulatedSpectrum: 2 wavelengths and 1 values given; both must be non-empty and of equal size",
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(TabulatedSpectrum::from_points({500.f, 400.f}, {1.f, 1.f}),
                         doctest::Contains("wavelength[1] = 400 is not above wavelength[0] = 500"), InvalidArgument);
    CHECK_THROWS_WITH_AS(TabulatedSpectrum::from_points({400.f}, {-1.f}),
                         "nsp: TabulatedSpectrum value = -1 is not allowed: it must be finite and >= 0", InvalidArgument);
    CHECK_THROWS_WITH_AS(TabulatedSpectrum::constant(NAN), doctest::Contains("value = nan"), InvalidArgument);
}

}  // namespace
