// tests/test_decomposition_estimators.cpp: PathEstimator under a control (THEORY 5.10):
// decomposition tracking for the path's segments, residual ratio tracking for its shadow rays,
// and null-scattering MIS between them with the null product exp(-tau_c) prod P_n,r. Unbiased
// against closed forms: the furnace (albedo 1 under a unit environment gives 1, multiple
// scattering, where every hit of the environment is weighed against NEE) and single scattering
// from a point light against quadrature; grid and global controls (one above the density in places:
// signed residuals), Mono and Rgb, both absorption policies, every strategy without equiangular
// sampling. Volume emission under a control (the collision estimator, the segment technique, NEE
// toward the volume and their MIS): an emitting absorber against quadrature and the emissive
// furnace. SpectralPathEstimator under a control (every channel's pdfs over both routes), every
// channel policy with a grey majorant, against the same closed forms.
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

#include "references.hpp"

namespace {

using namespace nsp_test;

// k = 5 standard errors of the mean (estimated from the samples); fixed seeds: deterministic.
constexpr double kSigmas = 5.0;
// The largest standard error a run may have, relative to its expected value (the largest seen
// here is 0.13: the Rgb emissive furnace's dim channel under roulette).
constexpr double kMaxRelativeSe = 0.15;

template <AbsorptionPolicy A>
using ControlEstimators = std::tuple<PathEstimator<strategy::Unidirectional, mis::None, A>,
                                     PathEstimator<strategy::NextEvent, mis::None, A>,
                                     PathEstimator<strategy::DirectionalMis, mis::Balance, A>,
                                     PathEstimator<strategy::NullScatteringMis, mis::Balance, A>,
                                     PathEstimator<strategy::NullScatteringMis, mis::Power, A>>;

template <class Res>
void check_channels(const Res& res, const std::array<double, 3>& ref, int channels, const std::string& label) {
    CHECK(res.not_ok == 0);
    for (int c = 0; c < channels; ++c) {
        const Stat& s = res.stat.ch[std::size_t(c)];
        CAPTURE(label);
        CAPTURE(c);
        MESSAGE(label << " channel " << c << ": " << s.mean << " (SE " << s.se() << "), expected " << ref[c]);
        CHECK(std::abs(s.mean - ref[c]) <= kSigmas * s.se() + kRoundingFloor);
        // A check whose SE is a large part of the answer could not fail: every run here must
        // resolve its answer to kMaxRelativeSe.
        CHECK(s.se() <= kMaxRelativeSe * std::abs(ref[c]));
    }
}

/// A control of `f` times the medium's density lower bound over its box, per channel.
template <class M>
typename M::Spectral::Coefficient box_control(const M& medium, float f) {
    return scale(medium.extinction_per_density(), f * medium.density_lower_bound(medium.bounds()));
}

/// The furnaces' media and controls: `run_all(medium, control, name, seed)` on an exponential
/// medium and a noise grid over `box`, albedo 1 (mu_a = 0), optical thickness a few across, mildly
/// chromatic in Rgb. The grey axis drives every channel with one pdf, and under the grey control
/// (the smallest channel's) a channel far above it carries null weights far from 1: at 1 : 0.5 : 2
/// the densest channel's furnace estimates were heavy-tailed under the grid majorant too (channel
/// 2 of three seeds at 40000 paths: 0.93, 0.96, 0.88 with SEs 0.05), so the sample SE of 4000
/// paths understated the error. Chromatic residuals are checked against quadrature below and
/// against closed forms in test_decomposition.cpp. Controls: grid (both media), global below the
/// density, and global a fifth of the way from the density's lower to its upper bound: above the
/// density near the lower bound's side only. Further up, multiple scattering through negative
/// residuals multiplies null weights above 1 over many nulls: at halfway the furnace's SEs were
/// 20-100x the answer. And the noise grid under a tree control (its adaptive layout). Seeds seed0,
/// seed0 + step, ...
template <SpectralMode S, class F>
void furnace_controls(const Box& box, F&& run_all, int seed0, int step) {
    using Exp = ExponentialMedium<S>;
    using Grid = DenseGridMedium<S>;
    const auto exp_medium = make_medium<Exp>(box, 1.5f, spec<S>(0.f, 0.f, 0.f), spec<S>(1.f, 0.8f, 1.25f));
    const auto grid_medium = make_medium<Grid>(box, 1.5f, spec<S>(0.f, 0.f, 0.f), spec<S>(1.f, 0.8f, 1.25f));
    run_all(exp_medium, GridControl<Exp>(exp_medium, 8), "exponential, grid control", std::uint64_t(seed0));
    run_all(exp_medium, GlobalControl<Exp>(exp_medium, box_control(exp_medium, 0.9f)), "exponential, global control",
            std::uint64_t(seed0 + step));
    run_all(grid_medium, GridControl<Grid>(grid_medium, 8), "noise grid, grid control", std::uint64_t(seed0 + 2 * step));
    const float lo = exp_medium.density_lower_bound(box);
    const float above = lo + 0.2f * (exp_medium.density_bound(box) - lo);
    run_all(exp_medium, GlobalControl<Exp>(exp_medium, scale(exp_medium.extinction_per_density(), above)),
            "exponential, global control above the density", std::uint64_t(seed0 + 3 * step));
    run_all(grid_medium, TreeControl<Grid>(grid_medium), "noise grid, tree control", std::uint64_t(seed0 + 4 * step));
}

/// "spectral-mis/uni-nee-mis/balance/absorb-weight" for a SpectralPathEstimator (its channel
/// policy first), "uni-nee-mis/balance/absorb-weight" for a PathEstimator.
template <class E>
std::string any_estimator_name() {
    if constexpr (requires { typename E::Channels; }) return std::string(E::Channels::name) + "/" + estimator_name<E>();
    else return estimator_name<E>();
}

/// The albedo-1 furnace under a unit environment (L = 1, multiple scattering; every hit of the
/// environment is weighed against NEE) in mode S, from outside the box and from inside, 4000
/// paths each, under furnace_controls' media and controls (seeds seed0, seed0 + step, ...): every
/// estimator that `for_each_estimator(each)` hands to `each`.
template <SpectralMode S, class ForEach>
void check_furnace(int seed0, int step, ForEach&& for_each_estimator) {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    Lights<S> lights;
    lights.set(EnvironmentLight<S>{grey<S>(1.f)});
    const Ray rays[] = {
        {Vec3(-3.f, 0.2f, 0.1f), glm::normalize(Vec3(1.f, -0.05f, 0.02f))},  // from outside
        {Vec3(0.1f, -0.2f, 0.3f), glm::normalize(Vec3(0.3f, 0.9f, -0.2f))},  // from inside
    };
    auto run_all = [&](const auto& medium, const auto& control, const std::string& name, std::uint64_t seed) {
        const Scene scene(medium, control, HenyeyGreensteinPhase(0.5f), lights);
        auto each = [&](const auto& est) {
            using E = std::remove_cvref_t<decltype(est)>;
            for (int r = 0; r < 2; ++r) {
                const auto res = estimate_radiance(est, scene, rays[r], 4000, seed + std::uint64_t(r));
                CHECK(res.lookups > 0);
                check_channels(res, {1.0, 1.0, 1.0}, S::channels,
                               std::string(S::name) + " " + name + " " + any_estimator_name<E>() + " ray " +
                                   std::to_string(r));
            }
        };
        for_each_estimator(each);
    };
    furnace_controls<S>(box, run_all, seed0, step);
}

TEST_CASE_TEMPLATE("furnace under a control: albedo 1 under a unit environment gives 1", S, Mono, Rgb) {
    check_furnace<S>(40, 2, [](auto&& each) {
        std::apply([&](const auto&... e) { (each(e), ...); }, ControlEstimators<absorption::Weight>{});
        each(PathEstimator<strategy::NullScatteringMis, mis::Balance, absorption::Event>{});
    });
}

/// The media with a closed-form optical depth: {Mono, Rgb} x {homogeneous, exponential} x absorption.
using AnalyticMediaCombos = decltype(std::tuple_cat(CombosOf<Mono, HomogeneousMedium>{}, CombosOf<Mono, ExponentialMedium>{},
                                                    CombosOf<Rgb, HomogeneousMedium>{}, CombosOf<Rgb, ExponentialMedium>{}));

/// Runs `run(control, name, seed)` under the controls of the analytic media: on a homogeneous
/// medium (kHomogeneous) its extinction itself, no null anywhere and one lookup per real
/// collision; else a grid control of 8^3, a tree control (TreeControl's adaptive layout), a global
/// control below the density (0.9 of its lower bound) and one above it over part of the box
/// (halfway between its bounds: negative residuals, whose real events and nulls are weighed by
/// sign, THEORY 5.10). Seeds from seed0, 10 apart.
template <bool kHomogeneous, class M, class F>
void for_each_control(const M& medium, const Box& box, int seed0, F&& run) {
    if constexpr (kHomogeneous) {
        run(GlobalControl<M>(medium, medium.coefficients(Vec3(0.f), {}).sigma_t()), "global control = extinction", seed0);
    } else {
        run(GridControl<M>(medium, 8), "grid control (8^3)", seed0);
        run(TreeControl<M>(medium), "tree control (adaptive layout)", seed0 + 30);
        run(GlobalControl<M>(medium, box_control(medium, 0.9f)), "global control", seed0 + 10);
        const float above = 0.5f * (medium.density_lower_bound(box) + medium.density_bound(box));
        run(GlobalControl<M>(medium, scale(medium.extinction_per_density(), above)), "global control above the density",
            seed0 + 20);
    }
}

TEST_CASE_TEMPLATE_DEFINE("single scattering under a control from a point light = quadrature", C, ctl_single) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    // Optical thickness about 1 across the box, chromatic in Rgb (channels differ 3x).
    const PointLightSingleScatter<M> setup;
    const Box& box = setup.box;
    const M& medium = setup.medium;
    const auto& lights = setup.lights;
    const Ray ray = setup.ray;
    const auto& ref = setup.ref;
    EstimatorOptions opts;
    opts.max_depth = 1;
    for_each_control<std::is_same_v<M, HomogeneousMedium<S>>>(medium, box, 50, [&](const auto& control,
                                                                                      const std::string& name, int) {
        const auto scene = Scene(medium, control, IsotropicPhase{}, lights);
        auto check = [&](const auto& est, int seed) {
            using E = std::remove_cvref_t<decltype(est)>;
            const auto res = estimate_radiance(est, scene, ray, 20000, std::uint64_t(seed));
            check_channels(res, ref, S::channels, combo_name<C>() + " " + name + " " + estimator_name<E>());
        };
        check(PathEstimator<strategy::NextEvent, mis::None, A>(opts), 51);
        check(PathEstimator<strategy::DirectionalMis, mis::Balance, A>(opts), 52);
        check(PathEstimator<strategy::NullScatteringMis, mis::Balance, A>(opts), 53);
        check(PathEstimator<strategy::NullScatteringMis, mis::Power, A>(opts), 54);
    });
}
TEST_CASE_TEMPLATE_APPLY(ctl_single, AnalyticMediaCombos);

// Volume emission under a control: the collision estimator visits every collision, control and
// residual, with the medium's own coefficients, the rate mu_c + mu_bar_r and the null product
// exp(-tau_c) prod P_n,r (docs/theory.md 5.10); the segment technique and NEE toward the volume
// ratio-track their nulls by residual ratio tracking. Every strategy's estimate and MIS among the
// three techniques must stay unbiased.

/// An emitting absorber of combo C (no scattering: L_c = int T_c mu_a,c L_e,c dt along the ray,
/// references.hpp, Simpson in double) under each control of for_each_control (seeds from seed0):
/// every estimator that `for_each_estimator(each)` hands to `each` against it, 20000 paths, and a
/// combining one also without the segment technique (the collision estimator alone on the camera
/// ray).
template <class C, class ForEach>
void check_emitting_absorber(int seed0, ForEach&& for_each_estimator) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    const EmittingAbsorber<M> setup;
    const auto& [box, base, medium, ray, ref] = setup;
    auto run = [&](const auto& control, const std::string& name, int first_seed) {
        const auto scene = Scene(medium, control, IsotropicPhase{}, Lights<S>{});
        EstimatorOptions off;  // the collision estimator alone on the camera ray
        off.emission_along_segments = false;
        int seed = first_seed;
        auto each = [&](const auto& est) {
            using E = std::remove_cvref_t<decltype(est)>;
            const std::string label = combo_name<C>() + " " + name + " " + any_estimator_name<E>();
            const auto res = estimate_radiance(est, scene, ray, 20000, std::uint64_t(++seed));
            check_channels(res, ref, S::channels, label);
            if constexpr (E::Strategy::combines) {
                const auto r2 = estimate_radiance(E(off), scene, ray, 20000, std::uint64_t(++seed));
                check_channels(r2, ref, S::channels, label + " no segment technique");
            }
        };
        for_each_estimator(each);
    };
    for_each_control<std::is_same_v<M, HomogeneousMedium<S>>>(medium, box, seed0, run);
}

TEST_CASE_TEMPLATE_DEFINE("emitting absorber under a control = quadrature", C, ctl_absorber) {
    check_emitting_absorber<C>(60, [](auto&& each) {
        std::apply([&](const auto&... e) { (each(e), ...); }, ControlEstimators<typename C::Absorption>{});
    });
}
TEST_CASE_TEMPLATE_APPLY(ctl_absorber, AnalyticMediaCombos);

TEST_CASE_TEMPLATE("emissive furnace under a control: L_e equal to the environment gives L_e", S, Mono, Rgb) {
    // Constant L_e inside a box lit by an environment of the same radiance: L = L_e for any
    // density, albedo and phase function; the paths scatter many times, and every technique's
    // contributions are weighed against the others'. NEE alone is left out: where its paths
    // scatter inside the emitter its volume NEE has infinite variance (test_emission_estimators.cpp,
    // Run::kFiniteVariance).
    const Box box{Vec3(-1.f), Vec3(1.f)};
    const auto le = spec<S>(0.7f, 0.4f, 1.1f);
    Lights<S> lights;
    lights.set(EnvironmentLight<S>{le});
    const Ray ray{Vec3(-3.f, 0.15f, -0.1f), glm::normalize(Vec3(1.f, 0.02f, 0.03f))};
    auto run_all = [&](const auto& medium, const auto& control, const std::string& name, std::uint64_t seed) {
        const Scene scene(medium, control, HenyeyGreensteinPhase(0.3f), lights);
        EstimatorOptions rr;  // roulette from the first real vertex: both MIS sides carry it
        rr.rr_start_depth = 1;
        rr.rr_max_survival = 0.6f;
        auto each = [&](const auto& est) {
            using E = std::remove_cvref_t<decltype(est)>;
            if constexpr (!(E::Strategy::samples_lights && !E::Strategy::combines)) {
                for (const bool roulette : {false, true}) {
                    const auto res = estimate_radiance(roulette ? E(rr) : est, scene, ray, 6000, seed++);
                    check_channels(res, {double(le[0]), double(le[S::channels > 1 ? 1 : 0]), double(le[S::channels - 1])},
                                   S::channels,
                                   std::string(S::name) + " " + name + " " + estimator_name<E>() +
                                       (roulette ? " roulette" : ""));
                }
            }
        };
        std::apply([&](const auto&... e) { (each(e), ...); }, ControlEstimators<absorption::Weight>{});
        each(PathEstimator<strategy::NullScatteringMis, mis::Balance, absorption::Event>{});
    };
    using Exp = Emissive<ExponentialMedium<S>>;
    using Grid = Emissive<DenseGridMedium<S>>;
    const auto emission = make_emission(box, {3, 2, 4}, 1.f, 0);
    const Exp exp_medium(make_medium<ExponentialMedium<S>>(box, 1.f, spec<S>(0.5f, 0.3f, 0.8f), spec<S>(0.6f, 0.9f, 0.3f)),
                         emission, le, {4, 4, 4});
    const Grid grid_medium(make_medium<DenseGridMedium<S>>(box, 1.f, spec<S>(0.5f, 0.3f, 0.8f), spec<S>(0.6f, 0.9f, 0.3f)),
                           emission, le, {4, 4, 4});
    run_all(exp_medium, GridControl<Exp>(exp_medium, 8), "exponential, grid control", 400);
    run_all(grid_medium, GridControl<Grid>(grid_medium, 8), "noise grid, grid control", 500);
    // A fifth of the way from the density's lower to its upper bound: above the density near the
    // lower bound's side only. Further up, multiple scattering through negative residuals multiplies
    // null weights above 1 over many nulls: at halfway the furnace's SEs were 20-100x the answer.
    const float lo = exp_medium.density_lower_bound(box);
    const float above = lo + 0.2f * (exp_medium.density_bound(box) - lo);
    run_all(exp_medium, GlobalControl<Exp>(exp_medium, scale(exp_medium.extinction_per_density(), above)),
            "exponential, global control above the density", 600);
}

}  // namespace

namespace {

// Equiangular sampling under a control: the tracked vertex's density is decomposition tracking's,
// the sum over its control and residual routes (detail::decomposition_event_densities), on the
// tracked side (DeltaTrack::event_density) and on the equiangular side (tracking_over_equiangular
// with the control at the point) alike; the equiangular vertex's nulls are residual ratio
// tracking's. The three-way MIS must stay unbiased.
template <AbsorptionPolicy A>
using EquiangularControlEstimators = std::tuple<PathEstimator<strategy::EquiangularNextEvent, mis::None, A>,
                                                PathEstimator<strategy::EquiangularMis, mis::Balance, A>,
                                                PathEstimator<strategy::EquiangularMis, mis::Power, A>>;

TEST_CASE_TEMPLATE_DEFINE("equiangular strategies under a control: single scattering = quadrature", C, ctl_eq_single) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    const PointLightSingleScatter<M> setup;
    const Box& box = setup.box;
    const M& medium = setup.medium;
    EstimatorOptions opts;
    opts.max_depth = 1;
    auto run = [&](const auto& control, const std::string& name, int seed0) {
        const auto scene = Scene(medium, control, IsotropicPhase{}, setup.lights);
        int seed = seed0;
        auto each = [&](const auto& est) {
            using E = std::remove_cvref_t<decltype(est)>;
            const auto res = estimate_radiance(E(opts), scene, setup.ray, 20000, std::uint64_t(++seed));
            check_channels(res, setup.ref, S::channels, combo_name<C>() + " " + name + " " + estimator_name<E>());
        };
        std::apply([&](const auto&... e) { (each(e), ...); }, EquiangularControlEstimators<A>{});
        // The equiangular vertex on 40 % of the pieces (THEORY 5.9): its count in every weight.
        EstimatorOptions some = opts;
        some.equiangular_count = 0.4f;
        each(PathEstimator<strategy::EquiangularMis, mis::Balance, A>(some));
    };
    for_each_control<std::is_same_v<M, HomogeneousMedium<S>>>(medium, box, 90, run);
}
TEST_CASE_TEMPLATE_APPLY(ctl_eq_single, AnalyticMediaCombos);

TEST_CASE_TEMPLATE("equiangular furnace under a control: albedo 1 with a point light as target gives 1", S, Mono, Rgb) {
    // Albedo 1 under a unit environment: radiance 1 everywhere, after many scatterings. A point
    // light of intensity 0 gives the equiangular vertices a target, so their NEE toward the
    // environment and the three-way weights of every tracked vertex are exercised.
    const Box box{Vec3(-1.f), Vec3(1.f)};
    Lights<S> lights;
    lights.set(EnvironmentLight<S>{grey<S>(1.f)});
    lights.set(PointLight<S>{Vec3(0.1f, -0.2f, 0.3f), grey<S>(0.f)});
    const Ray ray{Vec3(-3.f, 0.15f, -0.1f), glm::normalize(Vec3(1.f, 0.02f, 0.03f))};
    auto run_all = [&](const auto& medium, const auto& control, const std::string& name, std::uint64_t seed) {
        const Scene scene(medium, control, HenyeyGreensteinPhase(0.3f), lights);
        auto each = [&](const auto& est) {
            using E = std::remove_cvref_t<decltype(est)>;
            const auto res = estimate_radiance(est, scene, ray, 6000, seed++);
            check_channels(res, {1.0, 1.0, 1.0}, S::channels, std::string(S::name) + " " + name + " " + estimator_name<E>());
        };
        std::apply([&](const auto&... e) { (each(e), ...); }, EquiangularControlEstimators<absorption::Weight>{});
        each(PathEstimator<strategy::EquiangularMis, mis::Balance, absorption::Event>{});
    };
    furnace_controls<S>(box, run_all, 700, 20);
}

TEST_CASE("decomposition_event_densities: delta tracking's mu_bar P_x under a minorant, both routes' sum above it") {
    // Under a control below the extinction in every channel, each route's density is linear in the
    // coefficients, so the sum is delta tracking's mu_bar P_x (float rounding at the scale of the
    // extinction, from which the residual's mu_a = r - mu_s is a difference: 1e-5 x mu_bar).
    // Above it the residual's events are drawn by |r| and the sum is the two routes' densities
    // computed here independently from THEORY 5.10: the control route ctl P_s = ctl mean(a_s)
    // (albedo a_s = mu_s / mu_t kept, no null), the residual route R P_s = R mean|r a_s| /
    // (mean|r a_a| + mean|r a_s| + mean|R - r|), R = mu_bar - ctl.
    Pcg32 rng(17, 5);
    for (int i = 0; i < 2000; ++i) {
        CAPTURE(i);
        const float sa0 = 3.f * rng.uniform(), ss0 = 3.f * rng.uniform();
        Coefficients<Rgb> k{Rgb::Spectrum(sa0, 0.7f * sa0, 1.3f * sa0), Rgb::Spectrum(ss0, 1.2f * ss0, 0.6f * ss0)};
        const float t_min = k.sigma_t().minCoeff(), t_max = k.sigma_t().maxCoeff();
        const float mu_bar = t_max * (1.f + 2.f * rng.uniform()) + 1e-3f;
        const float below = t_min * rng.uniform();
        const auto full = event_probabilities<absorption::Event>(k, mu_bar);
        const auto d = detail::decomposition_event_densities<absorption::Event>(k, below, mu_bar);
        CHECK(d.scatter == doctest::Approx(mu_bar * full.scatter).epsilon(1e-5).scale(mu_bar));
        CHECK(d.absorb == doctest::Approx(mu_bar * full.absorb).epsilon(1e-5).scale(mu_bar));
        const auto fw = event_probabilities<absorption::Weight>(k, mu_bar);
        const auto dw = detail::decomposition_event_densities<absorption::Weight>(k, below, mu_bar);
        CHECK(dw.scatter == doctest::Approx(mu_bar * fw.scatter).epsilon(1e-5).scale(mu_bar));
        // Above the extinction of every channel (r < 0 everywhere), below the majorant.
        const float over = t_max + (mu_bar - t_max) * rng.uniform();
        const auto du = detail::decomposition_event_densities<absorption::Event>(k, over, mu_bar);
        const Eigen::Array3d t = k.sigma_t().cast<double>();
        const Eigen::Array3d a_s = (t > 0.0).select(k.sigma_s.cast<double>() / t, 0.0), a_a = 1.0 - a_s;
        const Eigen::Array3d r = t - double(over);  // < 0 in every channel
        const double big_r = double(mu_bar) - double(over);
        const double ctl_part = double(over) * a_s.mean();
        const double res_part = big_r > 0.0 ? big_r * (r * a_s).abs().mean() /
                                                  ((r * a_a).abs().mean() + (r * a_s).abs().mean() + (big_r - r).abs().mean())
                                            : 0.0;
        CHECK(double(du.scatter) == doctest::Approx(ctl_part + res_part).epsilon(1e-4).scale(1e-6));
        CHECK(double(du.scatter) >= double(mu_bar * full.scatter) - 1e-5);  // never below delta tracking's
    }
}

}  // namespace

namespace {

// SpectralPathEstimator under a control (THEORY 5.10 with 5.3): the sampling channel's
// decomposition tracking chooses each control or residual collision's event with that route's
// densities; every channel's pdf of a real vertex is the sum over both routes (a residual null's
// the residual's), the contributions the medium's own, and exp(-tau_c) joins f and uni; shadow rays
// and the equiangular and emission techniques' nulls by residual ratio tracking. Every channel
// policy that takes a grey majorant, against the same closed forms as PathEstimator above.

/// Runs `each(est)` over spectral MIS's three strategies and, under null-scattering MIS, the other
/// channel policies with a grey majorant: independent tracking (each channel its own pdf, one
/// estimated per path) and spectral tracking (one shared pdf: channel maxima, and the
/// throughput-weighted average).
template <AbsorptionPolicy A, class F>
void for_each_spectral(F&& each) {
    each(SpectralPathEstimator<channels::SpectralMis, strategy::Unidirectional, mis::None, A>{});
    each(SpectralPathEstimator<channels::SpectralMis, strategy::NextEvent, mis::None, A>{});
    each(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance, A>{});
    each(SpectralPathEstimator<channels::Independent, strategy::NullScatteringMis, mis::Balance, A>{});
    each(SpectralPathEstimator<channels::SpectralTrackingMax, strategy::NullScatteringMis, mis::Balance, A>{});
    each(SpectralPathEstimator<channels::SpectralTrackingAverage, strategy::NullScatteringMis, mis::Balance, A>{});
}

TEST_CASE("spectral estimators under a control: albedo 1 under a unit environment gives 1") {
    // The furnace of PathEstimator's test above (multiple scattering, two rays, the same media
    // and controls), Rgb: every channel's own pdfs (spectral MIS, independent) or one shared one.
    check_furnace<Rgb>(1040, 2, [](auto&& each) {
        for_each_spectral<absorption::Weight>(each);
        each(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance, absorption::Event>{});
    });
}

TEST_CASE_TEMPLATE_DEFINE("spectral estimators under a control: single scattering from a point light = quadrature", C,
                          spectral_ctl_single) {
    using M = typename C::Medium;
    using A = typename C::Absorption;
    const PointLightSingleScatter<M> setup;
    EstimatorOptions opts;
    opts.max_depth = 1;
    // 100000 paths each: with the full majorant's scattering density at the equiangular vertex in
    // place of the two routes' sum, the three-way MIS under the control above the density is
    // about 1% high: 2-3 SE at 20000 paths, 6-8 SE here.
    for_each_control<false>(setup.medium, setup.box, 1050, [&](const auto& control, const std::string& name, int seed0) {
        const auto scene = Scene(setup.medium, control, IsotropicPhase{}, setup.lights);
        int seed = seed0;
        auto each = [&](const auto& est) {
            using E = std::remove_cvref_t<decltype(est)>;
            const auto res = estimate_radiance(E(opts), scene, setup.ray, 100000, std::uint64_t(++seed));
            check_channels(res, setup.ref, 3, combo_name<C>() + " " + name + " " + any_estimator_name<E>());
        };
        each(SpectralPathEstimator<channels::SpectralMis, strategy::NextEvent, mis::None, A>{});
        each(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance, A>{});
        each(SpectralPathEstimator<channels::SpectralTrackingMax, strategy::NullScatteringMis, mis::Balance, A>{});
        // Equiangular sampling: its vertex weighs against every channel's sum over both routes.
        each(SpectralPathEstimator<channels::SpectralMis, strategy::EquiangularNextEvent, mis::None, A>{});
        each(SpectralPathEstimator<channels::SpectralMis, strategy::EquiangularMis, mis::Balance, A>{});
        each(SpectralPathEstimator<channels::SpectralTrackingAverage, strategy::EquiangularMis, mis::Balance, A>{});
    });
}
TEST_CASE_TEMPLATE_APPLY(spectral_ctl_single, decltype(CombosOf<Rgb, ExponentialMedium>{}));

TEST_CASE_TEMPLATE_DEFINE("spectral estimators under a control: emitting absorber = quadrature", C, spectral_ctl_absorber) {
    // PathEstimator's emitting absorber above, Rgb: the collision estimator at every control and
    // residual collision with every channel's pdfs, the segment technique and NEE toward the volume.
    check_emitting_absorber<C>(1060, [](auto&& each) { for_each_spectral<typename C::Absorption>(each); });
}
TEST_CASE_TEMPLATE_APPLY(spectral_ctl_absorber, decltype(CombosOf<Rgb, ExponentialMedium>{}));

TEST_CASE("spectral estimators under a control: the emissive furnace gives L_e") {
    // PathEstimator's emissive furnace above (L_e equal to the environment: L = L_e after many
    // scatterings), Rgb, spectral MIS with and without roulette.
    const EmissiveFurnace setup;
    using Exp = EmissiveFurnace::Medium;
    const Box& box = setup.box;
    const auto& le = setup.le;
    const auto& lights = setup.lights;
    const Ray& ray = setup.ray;
    const Exp& medium = setup.medium;
    const float lo = medium.density_lower_bound(box);
    const float above = lo + 0.2f * (medium.density_bound(box) - lo);
    auto run = [&](const auto& control, const std::string& name, std::uint64_t seed) {
        const Scene scene(medium, control, HenyeyGreensteinPhase(0.3f), lights);
        EstimatorOptions rr;
        rr.rr_start_depth = 1;
        rr.rr_max_survival = 0.6f;
        auto each = [&](const auto& est) {
            using E = std::remove_cvref_t<decltype(est)>;
            for (const bool roulette : {false, true}) {
                const auto res = estimate_radiance(roulette ? E(rr) : est, scene, ray, 6000, seed++);
                check_channels(res, {double(le[0]), double(le[1]), double(le[2])}, 3,
                               name + " " + any_estimator_name<E>() + (roulette ? " roulette" : ""));
            }
        };
        each(SpectralPathEstimator<channels::SpectralMis, strategy::Unidirectional, mis::None, absorption::Weight>{});
        each(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance, absorption::Weight>{});
        each(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance, absorption::Event>{});
    };
    run(GridControl<Exp>(medium, 8), "exponential, grid control", 1100);
    run(GlobalControl<Exp>(medium, scale(medium.extinction_per_density(), above)),
        "exponential, global control above the density", 1200);
}

TEST_CASE("channel_decomposition_densities: every channel's delta-tracking densities under a minorant, both routes above it") {
    // Under a control below every channel's extinction each route's density is linear in the
    // coefficients, so every channel's sum is its own delta-tracking density mu_bar P_x,c
    // (channel_event_densities under mu_bar), float rounding at the scale of mu_bar. Above every
    // channel's extinction the residual has no real event (its coefficients are negative, clamped
    // at 0) and a null of density R, so the sum is the control route's: ctl times each channel's
    // albedo (scattering) and its complement (absorption), computed here from THEORY 5.10.
    Pcg32 rng(19, 5);
    const Rgb::Spectrum w = Rgb::Spectrum::Ones();
    for (int i = 0; i < 2000; ++i) {
        CAPTURE(i);
        const float sa0 = 3.f * rng.uniform(), ss0 = 3.f * rng.uniform();
        Coefficients<Rgb> k{Rgb::Spectrum(sa0, 0.7f * sa0, 1.3f * sa0), Rgb::Spectrum(ss0, 1.2f * ss0, 0.6f * ss0)};
        const float t_min = k.sigma_t().minCoeff(), t_max = k.sigma_t().maxCoeff();
        const float mu_bar = t_max * (1.f + 2.f * rng.uniform()) + 1e-3f;
        const float below = t_min * rng.uniform();
        const auto full = channel_event_densities<absorption::Event, Rgb>(k, Rgb::Spectrum::Constant(mu_bar));
        const auto d = detail::channel_decomposition_densities<channels::SpectralMis, absorption::Event, Rgb>(k, below, mu_bar, w);
        for (int c = 0; c < 3; ++c) {
            CAPTURE(c);
            CHECK(d.scatter[c] == doctest::Approx(full.scatter[c]).epsilon(1e-5).scale(mu_bar));
            CHECK(d.absorb[c] == doctest::Approx(full.absorb[c]).epsilon(1e-5).scale(mu_bar));
            CHECK(d.null[c] == doctest::Approx(full.null[c]).epsilon(1e-5).scale(mu_bar));
        }
        const float over = t_max + (mu_bar - t_max) * rng.uniform();
        const auto du = detail::channel_decomposition_densities<channels::SpectralMis, absorption::Event, Rgb>(k, over, mu_bar, w);
        for (int c = 0; c < 3; ++c) {
            CAPTURE(c);
            const double t = double(k.sigma_t()[c]);
            const double a_s = t > 0.0 ? double(k.sigma_s[c]) / t : 0.0;
            CHECK(double(du.scatter[c]) == doctest::Approx(double(over) * a_s).epsilon(1e-5).scale(mu_bar));
            CHECK(double(du.absorb[c]) == doctest::Approx(double(over) * (1.0 - a_s)).epsilon(1e-5).scale(mu_bar));
            CHECK(double(du.null[c]) == doctest::Approx(double(mu_bar) - double(over)).epsilon(1e-5).scale(mu_bar));
        }
    }
}

}  // namespace
