// tests/test_equiangular_estimators.cpp: the equiangular path strategies (THEORY 5.4) are
// unbiased: single scattering from a point light against quadrature of the closed-form
// integrand (also in a dense medium, where the three-way MIS draws the equiangular vertex on a
// fraction of the segments), a furnace whose point light aims the equiangular vertices, and
// multiple scattering with roulette and a sphere light against null-scattering MIS; finite at
// the extremes.
#include <array>
#include <cmath>
#include <string>
#include <tuple>

#include "references.hpp"
#include "majorants.hpp"

namespace {

using namespace nsp_test;

// k = 5 standard errors of the mean (estimated from the samples; for a difference of two
// independent runs, the combined sqrt(se1^2 + se2^2)). Fixed seeds: deterministic.
constexpr double kSigmas = 5.0;

/// Checks every channel's mean of `res` against the quadrature `ref` within kSigmas standard errors.
template <class Res>
void check_against_quadrature(const Res& res, const std::array<double, 3>& ref, int channels, const std::string& label) {
    for (int c = 0; c < channels; ++c) {
        const Stat& s = res.stat.ch[c];
        CAPTURE(c);
        MESSAGE(label << ": " << s.mean << " (SE " << s.se() << "), quadrature " << ref[c]);
        CHECK(std::abs(s.mean - ref[c]) <= kSigmas * s.se() + kRoundingFloor);
    }
}

template <AbsorptionPolicy A>
using EquiangularEstimatorsWith = std::tuple<PathEstimator<strategy::EquiangularNextEvent, mis::None, A>,
                                             PathEstimator<strategy::EquiangularMis, mis::Balance, A>,
                                             PathEstimator<strategy::EquiangularMis, mis::Power, A>>;

template <SpectralMode S, template <class> class MT>
using AnalyticCombos = CombosOf<S, MT>;
/// The media with a closed-form optical depth: {Mono, Rgb} x {homogeneous, exponential} x absorption.
using AnalyticMediaCombos = decltype(std::tuple_cat(AnalyticCombos<Mono, HomogeneousMedium>{},
                                                    AnalyticCombos<Mono, ExponentialMedium>{},
                                                    AnalyticCombos<Rgb, HomogeneousMedium>{},
                                                    AnalyticCombos<Rgb, ExponentialMedium>{}));

TEST_CASE_TEMPLATE_DEFINE("equiangular strategies: single scattering from a point light = quadrature", C, eq_single) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    // Optical thickness about 1 across the box, chromatic (Rgb channels differ 3x); the light inside
    // the medium, 0.3 from the camera ray.
    const PointLightSingleScatter<M> setup;
    const M& medium = setup.medium;
    const auto& lights = setup.lights;
    const Ray ray = setup.ray;
    const auto& ref = setup.ref;
    EstimatorOptions opts;
    opts.max_depth = 1;

    auto run = [&](const auto& maj, const std::string& maj_name) {
        const auto scene = Scene(medium, maj, IsotropicPhase{}, lights);
        auto check = [&](const auto& est, int seed) {
            using E = std::remove_cvref_t<decltype(est)>;
            const auto res = estimate_radiance(est, scene, ray, 20000, std::uint64_t(seed));
            CHECK(res.not_ok == 0);
            check_against_quadrature(res, ref, S::channels, combo_name<C>() + " " + maj_name + " " + estimator_name<E>());
        };
        // NEE from tracked vertices is the control: the quadrature must agree with it too.
        check(PathEstimator<strategy::NextEvent, mis::None, A>(opts), 11);
        check(PathEstimator<strategy::EquiangularNextEvent, mis::None, A>(opts), 12);
        check(PathEstimator<strategy::EquiangularMis, mis::Balance, A>(opts), 13);
        check(PathEstimator<strategy::EquiangularMis, mis::Power, A>(opts), 14);
        // Expected counts of the equiangular vertex (THEORY 5.9): 0 removes it from the three-way
        // MIS (NEE from tracked vertices carries the light alone), 0.4 draws it on 40 % of the
        // pieces and divides by that; equiangular-nee's only technique at count 0.5.
        EstimatorOptions none = opts, some = opts, half = opts;
        none.equiangular_count = 0.f;
        some.equiangular_count = 0.4f;
        half.equiangular_count = 0.5f;
        check(PathEstimator<strategy::EquiangularMis, mis::Balance, A>(none), 15);
        check(PathEstimator<strategy::EquiangularMis, mis::Balance, A>(some), 16);
        check(PathEstimator<strategy::EquiangularNextEvent, mis::None, A>(half), 17);
    };
    run(GlobalMajorant<M>(medium), "global");
    for_each_kind<std::tuple<SignedGlobalKind, GridKind, SignedGridKind>, M>(
        [&](auto kind) { run(decltype(kind)::make(medium), decltype(kind)::name); });
}
TEST_CASE_TEMPLATE_APPLY(eq_single, AnalyticMediaCombos);

TEST_CASE("equiangular_probability: min(1, p_eq / mu_bar) at the equiangular density's peak") {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    const Ray ray{Vec3(-3.f, 0.f, 0.f), Vec3(1.f, 0.f, 0.f)};
    const Vec3 light(0.25f, 0.4f, 0.f);  // foot point t = 3.25, D = 0.4; the stretch is [2, 4]
    const EquiangularSampler eq(ray, light, 2.f, 4.f);
    CHECK(eq.peak() == doctest::Approx(3.25f));
    // p_eq(peak) = D / ((theta1 - theta0) D^2) = 1 / ((theta1 - theta0) D).
    const double span = std::atan(0.75 / 0.4) - std::atan(-1.25 / 0.4);
    const double peak_pdf = 1.0 / (span * 0.4);
    for (const float mu : {0.5f, 1.f, 4.f, 40.f}) {
        const auto medium = make_medium<HomogeneousMedium<Mono>>(box, 1.f, grey<Mono>(0.1f * mu), grey<Mono>(0.9f * mu));
        const float p = equiangular_probability<HomogeneousMedium<Mono>>(GlobalMajorant<HomogeneousMedium<Mono>>(medium),
                                                                         ray, eq, {});
        CAPTURE(mu);
        CHECK(p == doctest::Approx(std::min(1.0, peak_pdf / mu)).epsilon(1e-5));
    }
    // The peak clamped to the stretch: the foot point beyond it.
    const EquiangularSampler beyond(ray, Vec3(6.f, 0.5f, 0.f), 2.f, 4.f);
    CHECK(beyond.peak() == 4.f);
    // A majorant of 0 where the density peaks (an empty medium): 1, never NaN.
    const auto empty = make_medium<HomogeneousMedium<Mono>>(box, 0.f, grey<Mono>(0.f), grey<Mono>(0.f));
    CHECK(equiangular_probability<HomogeneousMedium<Mono>>(GlobalMajorant<HomogeneousMedium<Mono>>(empty), ray, eq, {}) ==
          1.f);
}

TEST_CASE_TEMPLATE_DEFINE("equiangular MIS in a dense medium: the vertex drawn on a fraction of the segments, = quadrature",
                          C, eq_dense) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    const Box box{Vec3(-1.f), Vec3(1.f)};
    // Optical thickness about 6-10 across the box: at the equiangular peak the majorant (3-5) is
    // above the density p_eq ~ 1.3 of a light 0.3 from the ray, so the camera segment draws its
    // equiangular vertex with probability p < 1 (about 0.3-0.45, checked), and the equiangular
    // technique's pdf carries that factor in every weight. Both settings must match the quadrature.
    const M medium = make_medium<M>(box, 3.f, spec<S>(0.2f, 0.1f, 0.4f), spec<S>(0.8f, 0.4f, 1.2f));
    const Vec3 light(0.2f, 0.25f, -0.1f);
    Lights<S> lights;
    lights.set(PointLight<S>{light, grey<S>(2.f)});
    const Ray ray{Vec3(-3.f, 0.05f, -0.05f), glm::normalize(Vec3(1.f, 0.01f, -0.02f))};
    const auto ref = single_scatter_reference(medium, ray, light, 2.f);
    EstimatorOptions adaptive, every;
    adaptive.max_depth = every.max_depth = 1;
    every.adaptive_equiangular = false;
    auto run = [&](const auto& maj, const std::string& maj_name) {
        const Interval in = medium.bounds().clip(ray, 0.f, kInf);
        const float p = equiangular_probability<M>(maj, ray, EquiangularSampler(ray, light, in.t0, in.t1), {});
        MESSAGE(maj_name << ": camera segment draws its equiangular vertex with probability " << p);
        CHECK(p > 0.f);
        CHECK(p < 1.f);
        const auto scene = Scene(medium, maj, IsotropicPhase{}, lights);
        auto check = [&](const auto& est, const char* setting, int seed) {
            using E = std::remove_cvref_t<decltype(est)>;
            const auto res = estimate_radiance(est, scene, ray, 20000, std::uint64_t(seed));
            CHECK(res.not_ok == 0);
            for (int c = 0; c < S::channels; ++c) CHECK(ref[c] > 1e-4);  // a non-trivial answer
            check_against_quadrature(res, ref, S::channels,
                                     combo_name<C>() + " " + maj_name + " " + estimator_name<E>() + " " + setting);
        };
        check(PathEstimator<strategy::EquiangularMis, mis::Balance, A>(adaptive), "adaptive", 51);
        check(PathEstimator<strategy::EquiangularMis, mis::Power, A>(adaptive), "adaptive", 52);
        check(PathEstimator<strategy::EquiangularMis, mis::Balance, A>(every), "every segment", 53);
    };
    run(GlobalMajorant<M>(medium), "global");
    for_each_kind<std::tuple<GridKind>, M>([&](auto kind) { run(decltype(kind)::make(medium), decltype(kind)::name); });
}
TEST_CASE_TEMPLATE_APPLY(eq_dense, AnalyticMediaCombos);

TEST_CASE_TEMPLATE_DEFINE("equiangular strategies: furnace with the point light as target gives 1", C, eq_furnace) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    const Box box{Vec3(-1.f), Vec3(1.f)};
    // Albedo 1 under a unit environment: radiance 1 everywhere. A point light of intensity 0 in
    // the medium gives the equiangular vertices a target, so their NEE toward the environment
    // and its three-way weights are exercised.
    const M medium = make_medium<M>(box, 0.8f, grey<S>(0.f), spec<S>(1.f, 0.6f, 1.4f));
    Lights<S> lights;
    lights.set(EnvironmentLight<S>{grey<S>(1.f)});
    lights.set(PointLight<S>{Vec3(0.1f, -0.2f, 0.3f), grey<S>(0.f)});
    const Ray ray{Vec3(-3.f, 0.15f, -0.1f), glm::normalize(Vec3(1.f, 0.02f, 0.03f))};
    auto run = [&](const auto& maj, const std::string& maj_name) {
        const auto scene = Scene(medium, maj, HenyeyGreensteinPhase(0.3f), lights);
        std::apply(
            [&](auto... est) {
                int seed = 20;
                ((void)[&] {
                    using E = decltype(est);
                    const auto res = estimate_radiance(est, scene, ray, 8000, std::uint64_t(++seed));
                    CHECK(res.not_ok == 0);
                    for (int c = 0; c < S::channels; ++c) {
                        const Stat& s = res.stat.ch[c];
                        CAPTURE(c);
                        MESSAGE(combo_name<C>() << " " << maj_name << " " << estimator_name<E>() << ": " << s.mean
                                                << " (SE " << s.se() << ")");
                        CHECK(std::abs(s.mean - 1.0) <= kSigmas * s.se() + kRoundingFloor);
                    }
                }(), ...);
            },
            EquiangularEstimatorsWith<A>{});
    };
    run(GlobalMajorant<M>(medium), "global");
    for_each_kind<std::tuple<GridKind, SignedGridKind>, M>(
        [&](auto kind) { run(decltype(kind)::make(medium), decltype(kind)::name); });
}
TEST_CASE_TEMPLATE_APPLY(eq_furnace, AllCombos);

TEST_CASE_TEMPLATE_DEFINE("equiangular MIS with roulette and a sphere light agrees with uni + NEE MIS", C, eq_sphere) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    const Box box{Vec3(-1.f), Vec3(1.f)};
    // Multiple scattering (albedo 0.8, thickness about 1.2), a sphere light beside the box (the
    // equiangular target is its centre) and a dim environment; roulette from the first real
    // vertex with survival capped at 0.6, so the survival an equiangular vertex assumes for the
    // tracked path matters. Reference: null-scattering MIS (uni + NEE) from a separate run.
    const M medium = make_medium<M>(box, 0.6f, spec<S>(0.2f, 0.3f, 0.1f), spec<S>(0.8f, 0.7f, 0.9f));
    Lights<S> lights;
    lights.set(SphereLight<S>{Vec3(1.6f, 0.4f, 0.2f), 0.3f, grey<S>(10.f)});
    lights.set(EnvironmentLight<S>{grey<S>(0.2f)});
    const Ray ray{Vec3(-3.f, 0.2f, 0.1f), glm::normalize(Vec3(1.f, 0.03f, 0.01f))};
    EstimatorOptions opts;
    opts.rr_start_depth = 1;
    opts.rr_max_survival = 0.6f;
    const auto scene = Scene(medium, GlobalMajorant<M>(medium), HenyeyGreensteinPhase(0.3f), lights);
    const auto ref = estimate_radiance(PathEstimator<strategy::NullScatteringMis, mis::Balance, A>(opts), scene, ray,
                                       40000, 30);
    CHECK(ref.not_ok == 0);
    std::apply(
        [&](auto... est) {
            int seed = 30;
            ((void)[&] {
                using E = decltype(est);
                const auto res = estimate_radiance(E(opts), scene, ray, 40000, std::uint64_t(++seed));
                CHECK(res.not_ok == 0);
                for (int c = 0; c < S::channels; ++c) {
                    const Stat &s = res.stat.ch[c], &r = ref.stat.ch[c];
                    const double se = std::sqrt(s.se() * s.se() + r.se() * r.se());
                    CAPTURE(c);
                    MESSAGE(combo_name<C>() << " " << estimator_name<E>() << ": " << s.mean << " (SE " << s.se()
                                            << "), uni + NEE MIS " << r.mean << " (SE " << r.se() << ")");
                    CHECK(r.mean > 0.05);  // a non-trivial answer
                    CHECK(std::abs(s.mean - r.mean) <= kSigmas * se);
                }
            }(), ...);
        },
        EquiangularEstimatorsWith<A>{});
}
TEST_CASE_TEMPLATE_APPLY(eq_sphere, AllCombos);

TEST_CASE_TEMPLATE_DEFINE("equiangular MIS: a large light and strong roulette make every weight matter", C, eq_roulette) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    const Box box{Vec3(-1.f), Vec3(1.f)};
    // Single scattering (max depth 1) toward a sphere light of radius 1.2 just off the camera
    // ray's line, beyond a box of optical thickness 1 and albedo 0.9, forward scattering (HG 0.9):
    // from a vertex on the ray, hitting the light (phase pdf ~1.4 toward it) is within a few times
    // as likely as sampling its cone (~2.5), and the equiangular vertex about as likely as the
    // tracked one (p_eq ~0.5, mu_bar 0.5), so all three weights matter: a survival probability of
    // 0.3 (roulette from the first vertex) that one side left out moves the equiangular weight by
    // ~15 %. Reference: uni + NEE MIS, a separate run.
    const M medium = make_medium<M>(box, 0.5f, spec<S>(0.1f, 0.15f, 0.05f), spec<S>(0.9f, 0.85f, 0.95f));
    Lights<S> lights;
    lights.set(SphereLight<S>{Vec3(3.2f, 1.6f, 0.1f), 1.2f, grey<S>(1.f)});
    const Ray ray{Vec3(-3.f, 0.3f, 0.1f), Vec3(1.f, 0.f, 0.f)};
    EstimatorOptions opts;
    opts.max_depth = 1;
    opts.rr_start_depth = 1;
    opts.rr_max_survival = 0.3f;
    const auto scene = Scene(medium, GlobalMajorant<M>(medium), HenyeyGreensteinPhase(0.9f), lights);
    const auto ref = estimate_radiance(PathEstimator<strategy::NullScatteringMis, mis::Balance, A>(opts), scene, ray,
                                       200000, 40);
    const auto res = estimate_radiance(PathEstimator<strategy::EquiangularMis, mis::Balance, A>(opts), scene, ray,
                                       200000, 41);
    CHECK(ref.not_ok == 0);
    CHECK(res.not_ok == 0);
    for (int c = 0; c < S::channels; ++c) {
        const Stat &s = res.stat.ch[c], &r = ref.stat.ch[c];
        const double se = std::sqrt(s.se() * s.se() + r.se() * r.se());
        CAPTURE(c);
        MESSAGE(combo_name<C>() << " uni-nee-eq-mis: " << s.mean << " (SE " << s.se() << "), uni + NEE MIS " << r.mean
                                << " (SE " << r.se() << ")");
        CHECK(r.mean > 0.02);
        CHECK(std::abs(s.mean - r.mean) <= kSigmas * se);
    }
}
TEST_CASE_TEMPLATE_APPLY(eq_roulette, AllCombos);

TEST_CASE("equiangular strategies without a point or sphere light are the NEE strategies") {
    // Nothing to aim at: EquiangularNextEvent draws exactly what NextEvent draws (same random
    // numbers, same estimates), and EquiangularMis weighs as NullScatteringMis does.
    const Box box{Vec3(-1.f), Vec3(1.f)};
    const auto medium = make_medium<DenseGridMedium<Rgb>>(box, 0.9f, spec<Rgb>(0.2f, 0.3f, 0.1f),
                                                           spec<Rgb>(0.8f, 0.7f, 0.9f));
    Lights<Rgb> lights;
    lights.set(EnvironmentLight<Rgb>{spec<Rgb>(1.f, 0.5f, 0.25f)});
    const auto scene = make_scene(medium, IsotropicPhase{}, lights);
    const Ray ray{Vec3(-3.f, 0.2f, 0.1f), glm::normalize(Vec3(1.f, 0.03f, 0.01f))};
    const PathEstimator<strategy::NextEvent> nee;
    const PathEstimator<strategy::EquiangularNextEvent> eq_nee;
    const PathEstimator<strategy::NullScatteringMis, mis::Balance> mis;
    const PathEstimator<strategy::EquiangularMis, mis::Balance> eq_mis;
    Pcg32 r1(5, 1), r2(5, 1), r3(6, 1), r4(6, 1);
    NoLookupCount none;
    for (int i = 0; i < 2000; ++i) {
        const auto a = nee.radiance(scene, ray, {}, r1, none), b = eq_nee.radiance(scene, ray, {}, r2, none);
        REQUIRE((a.value == b.value).all());
        const auto c = mis.radiance(scene, ray, {}, r3, none), d = eq_mis.radiance(scene, ray, {}, r4, none);
        for (int ch = 0; ch < 3; ++ch) REQUIRE(d.value[ch] == doctest::Approx(c.value[ch]).epsilon(1e-5));
    }
}

TEST_CASE("equiangular count 0: uni-nee-eq-mis is uni + NEE MIS draw for draw, grey and per channel") {
    // THEORY 5.9: a technique at count 0 is absent from every weight. With a point light (which
    // only NEE reaches) and a sphere light (NEE and hits), multiple scattering and roulette, the
    // three-way MIS at count 0 draws the same random numbers as uni + NEE MIS and weighs every
    // contribution by the two remaining pdfs: the same estimates up to float rounding in the
    // weights (relative 1e-5), sample by sample. At count 1 the equiangular vertex changes them.
    const Box box{Vec3(-1.f), Vec3(1.f)};
    const auto medium = make_medium<DenseGridMedium<Rgb>>(box, 0.9f, spec<Rgb>(0.2f, 0.3f, 0.1f),
                                                           spec<Rgb>(0.8f, 0.7f, 0.9f));
    Lights<Rgb> lights;
    lights.set(PointLight<Rgb>{Vec3(0.2f, 0.5f, -0.1f), spec<Rgb>(2.f, 1.f, 3.f)});
    lights.set(SphereLight<Rgb>{Vec3(1.6f, 0.4f, 0.2f), 0.3f, grey<Rgb>(10.f)});
    const auto scene = make_scene(medium, IsotropicPhase{}, lights);
    const Ray ray{Vec3(-3.f, 0.2f, 0.1f), glm::normalize(Vec3(1.f, 0.03f, 0.01f))};
    EstimatorOptions opts;
    opts.rr_start_depth = 1;
    opts.rr_max_survival = 0.6f;
    EstimatorOptions none = opts;
    none.equiangular_count = 0.f;
    auto same_draws = [&](const auto& reference, const auto& at_0, const auto& at_1, const char* label) {
        Pcg32 r1(5, 1), r2(5, 1), r3(5, 1);
        NoLookupCount no;
        int differ_at_1 = 0;
        for (int i = 0; i < 2000; ++i) {
            const auto a = reference.radiance(scene, ray, {}, r1, no), b = at_0.radiance(scene, ray, {}, r2, no);
            const auto c = at_1.radiance(scene, ray, {}, r3, no);
            CAPTURE(label);
            CAPTURE(i);
            REQUIRE(a.status == Status::Ok);
            REQUIRE(b.status == Status::Ok);
            for (int ch = 0; ch < 3; ++ch) REQUIRE(b.value[ch] == doctest::Approx(a.value[ch]).epsilon(1e-5));
            differ_at_1 += (c.value != a.value).any() ? 1 : 0;
        }
        MESSAGE(std::string(label) << ": at count 1, " << differ_at_1 << " of 2000 estimates differ");
        CHECK(differ_at_1 > 200);  // the check above could fail: count 1 is a different estimator
    };
    same_draws(PathEstimator<strategy::NullScatteringMis, mis::Balance>(opts),
               PathEstimator<strategy::EquiangularMis, mis::Balance>(none),
               PathEstimator<strategy::EquiangularMis, mis::Balance>(opts), "grey");
    same_draws(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>(opts),
               SpectralPathEstimator<channels::SpectralMis, strategy::EquiangularMis, mis::Balance>(none),
               SpectralPathEstimator<channels::SpectralMis, strategy::EquiangularMis, mis::Balance>(opts), "spectral MIS");
}

TEST_CASE("equiangular strategies stay finite at the extremes") {
    // A point light on the camera ray, at the camera itself (distance 0 from the first vertex),
    // at the ray's end inside the medium, and media of density 0 and 1e6.
    const Box box{Vec3(-1.f), Vec3(1.f)};
    const Ray ray{Vec3(-0.5f, 0.f, 0.f), Vec3(1.f, 0.f, 0.f)};
    for (const float density : {0.f, 1.f, 1e6f}) {
        const HomogeneousMedium<Rgb> medium(box, grey<Rgb>(0.3f * density), grey<Rgb>(0.7f * density));
        for (const Vec3 light : {Vec3(0.f, 0.f, 0.f), Vec3(-0.5f, 0.f, 0.f), Vec3(1.f, 0.f, 0.f), Vec3(0.3f, 1e-30f, 0.f)}) {
            CAPTURE(density);
            CAPTURE(light.x);
            Lights<Rgb> lights;
            lights.set(PointLight<Rgb>{light, grey<Rgb>(1.f)});
            const auto scene = make_scene(medium, IsotropicPhase{}, lights);
            auto check = [&](const auto& est) {
                Pcg32 rng(9, 9);
                NoLookupCount none;
                for (int i = 0; i < 3000; ++i) {
                    const auto r = est.radiance(scene, ray, {}, rng, none);
                    REQUIRE(r.status == Status::Ok);
                    REQUIRE(all_finite(r.value));
                }
            };
            check(PathEstimator<strategy::EquiangularNextEvent>{});
            check(PathEstimator<strategy::EquiangularMis, mis::Balance>{});
            check(PathEstimator<strategy::EquiangularMis, mis::Power>{});
        }
    }
}

}  // namespace
