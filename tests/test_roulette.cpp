// tests/test_roulette.cpp: Russian roulette and MIS (THEORY 5.6). With roulette from the first
// real vertex and survival capped at 0.6, so q < 1 at every vertex, every MIS estimator stays
// unbiased: in a furnace (= 1) and on a homogeneous box of albedo 0.8 under a constant
// environment, where it must agree with the same estimator without roulette.
#include "common.hpp"

namespace {

using namespace nsp_test;

// k = 5 standard errors (estimated from the samples; combined sqrt(se1^2 + se2^2) for a
// difference of two independent runs).
constexpr double kSigmas = 5.0;
constexpr int kSamples = 20000;

EstimatorOptions roulette(bool on) {
    EstimatorOptions o;
    o.russian_roulette = on;
    o.rr_start_depth = 1;
    o.rr_max_survival = 0.6f;
    return o;
}

TEST_CASE_TEMPLATE_DEFINE("roulette with q < 1 keeps MIS estimators unbiased", E, roulette_mis) {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    Lights<Mono> env;
    env.set(EnvironmentLight<Mono>{grey<Mono>(1.f)});
    const Ray ray{Vec3(-3.f, 0.15f, -0.1f), glm::normalize(Vec3(1.f, 0.02f, 0.03f))};
    const E with_rr(roulette(true)), without_rr(roulette(false));

    SUBCASE("furnace: albedo 1 gives 1") {
        // Exponential density, optical thickness ~1.2 across the box (0.5 to 4 times that along the
        // density axis), HG g = 0.3. Thin enough that the chance of another real vertex stays well
        // below q = 0.6: the 1/q^k weights then have finite variance, so the SE is trustworthy
        // (at thickness ~3 it is not: the mean of 2e4 samples sits a few "SE" low).
        const auto scene = make_scene(make_medium<ExponentialMedium<Mono>>(box, 0.6f, grey<Mono>(0.f), grey<Mono>(1.f)),
                                      HenyeyGreensteinPhase(0.3f), env);
        const auto res = estimate_radiance(with_rr, scene, ray, kSamples, 61);
        const Stat& s = res.stat.ch[0];
        MESSAGE(estimator_name<E>() << " furnace with roulette: mean " << s.mean << ", SE " << s.se());
        CHECK(res.not_ok == 0);
        CHECK(std::abs(s.mean - 1.0) <= kSigmas * s.se() + kRoundingFloor);
    }
    SUBCASE("homogeneous box, albedo 0.8: roulette on = roulette off") {
        // mu_t = 1 (optical thickness 2 across the box), isotropic phase.
        const auto scene = make_scene(HomogeneousMedium<Mono>(box, grey<Mono>(0.2f), grey<Mono>(0.8f)),
                                      IsotropicPhase{}, env);
        const auto on = estimate_radiance(with_rr, scene, ray, kSamples, 62);
        const auto off = estimate_radiance(without_rr, scene, ray, kSamples, 63);
        const Stat &a = on.stat.ch[0], &b = off.stat.ch[0];
        const double se = std::sqrt(a.se() * a.se() + b.se() * b.se());
        MESSAGE(estimator_name<E>() << " albedo 0.8: roulette on " << a.mean << " (SE " << a.se() << "), off "
                                    << b.mean << " (SE " << b.se() << "), difference " << (a.mean - b.mean) / se
                                    << " combined SE");
        CHECK(on.not_ok == 0);
        CHECK(off.not_ok == 0);
        CHECK(a.mean > 0.1);  // a non-trivial answer
        CHECK(std::abs(a.mean - b.mean) <= kSigmas * se);
    }
}

TEST_CASE_TEMPLATE_APPLY(roulette_mis, MisEstimators);

}  // namespace
