// tests/test_transmittance_estimators.cpp: the transmittance estimators beyond ratio tracking
// (THEORY 5.10, nsp/transmittance.hpp) against closed forms: residual ratio tracking under a grid
// control (per-cell minorants) and a global control, unbiased ray marching under global and grid
// majorants; homogeneous (exact, no lookups for the residual tracker), exponential and linear
// densities, grey and per channel; a control of 0 is ratio tracking draw for draw; a control equal
// to the majorant costs no lookup; a control above the density stays unbiased; bad input. And the
// path estimators' ray-marched shadow rays (EstimatorOptions::shadow_estimator): single
// scattering against quadrature, the host's shadow kernel exact in a homogeneous medium, refusals.
#include <cmath>
#include <string>
#include <vector>

#include "references.hpp"

namespace {

using namespace nsp_test;

// k = 5 standard errors of the mean (estimated from the samples): a correct estimator fails one
// channel comparison with probability ~6e-7; fixed seeds make every run the same.
constexpr double kSigmas = 5.0;
constexpr int kSamples = 20000;

template <SpectralMode S>
void check_mean(const SpecStat<S>& stat, const typename S::Spectrum& expected, const std::string& label) {
    check_channel_means(stat, expected, label, kSigmas);
}

/// n estimates of `estimate(rng, counter)` (a TransmittanceSample), every one Ok: their statistics and lookups.
template <SpectralMode S, class F>
std::pair<SpecStat<S>, std::uint64_t> run(F&& estimate, std::uint64_t seed, int n = kSamples) {
    SpecStat<S> stat;
    Pcg32 rng(seed, 3);
    LookupCount lookups;
    for (int i = 0; i < n; ++i) {
        const auto tr = estimate(rng, lookups);
        REQUIRE(tr.status == Status::Ok);
        REQUIRE(all_finite(tr.value));
        stat.add(tr.value);
    }
    return {stat, lookups.count()};
}

/// A linear ramp along x as a 1-D dense grid: voxel i (centre x_i) holds a + b x_i, so between the
/// first and last centres the trilinear lookup is a + b x exactly; its optical depth along the x
/// axis there is the trapezoid.
template <SpectralMode S>
DenseGridMedium<S> linear_ramp(float a, float b, int n, const typename S::Coefficient& sa,
                               const typename S::Coefficient& ss) {
    std::vector<float> d(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) d[std::size_t(i)] = a + b * ((float(i) + 0.5f) / float(n));
    return DenseGridMedium<S>(Box{Vec3(0.f, -1.f, -1.f), Vec3(1.f, 1.f, 1.f)}, {n, 1, 1}, std::move(d), sa, ss);
}

TEST_CASE_TEMPLATE("residual ratio tracking and ray marching: homogeneous media are exact", S, Mono, Rgb) {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    const auto medium = HomogeneousMedium<S>(box, spec<S>(0.3f, 0.1f, 0.9f), spec<S>(0.9f, 0.5f, 1.5f));
    const Ray ray{Vec3(-3.f, 0.1f, 0.2f), glm::normalize(Vec3(1.f, 0.1f, -0.05f))};
    const auto expected = (-medium.optical_depth(ray, 0.f, kInf)).exp().eval();
    // The control is the whole extinction: closed form, and (grey) no lookup at all; per channel
    // the residual majorant covers the channels' spread, and every factor is exactly 1.
    const GlobalControl<HomogeneousMedium<S>> control(medium, medium.extinction_bound_coefficient());
    const auto [rr, rr_lookups] = run<S>(
        [&](Pcg32& rng, LookupCount& n) { return transmittance_residual_ratio(medium, control, ray, kInf, {}, rng, n); }, 1,
        200);
    const auto [rm, rm_lookups] = run<S>(
        [&](Pcg32& rng, LookupCount& n) {
            return transmittance_ray_marching(medium, GlobalMajorant<HomogeneousMedium<S>>(medium), ray, kInf, {}, rng, n);
        },
        2, 200);
    for (int c = 0; c < S::channels; ++c) {
        CAPTURE(c);
        CHECK(rr.ch[std::size_t(c)].mean == doctest::Approx(expected[c]).epsilon(2e-6));
        CHECK(rr.ch[std::size_t(c)].variance() <= 1e-12);
        CHECK(rm.ch[std::size_t(c)].mean == doctest::Approx(expected[c]).epsilon(2e-6));
        CHECK(rm.ch[std::size_t(c)].variance() <= 1e-12);
    }
    if constexpr (S::channels == 1) CHECK(rr_lookups == 0);
    // Ray marching: the pivot comb and one more that finds no difference: 2 combs of
    // ceil(tau_bar) lookups (tau_bar the majorant times the chord, about 2.4 or 4.8).
    const Interval in = box.clip(ray, 0.f, kInf);
    const double tau_bar = double(medium.max_extinction()) * double(in.t1 - in.t0);
    MESSAGE("ray marching: " << double(rm_lookups) / 200.0 << " lookups per estimate, tau_bar " << tau_bar);
    CHECK(rm_lookups == 200u * 2u * std::uint64_t(std::ceil(tau_bar)));
}

TEST_CASE_TEMPLATE("residual ratio tracking and ray marching are unbiased on exponential media", S, Mono, Rgb) {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    // Density 1.5 at the centre, e^2 across the box; extinction per density 0.8, 0.25, 1.7.
    const auto medium = make_medium<ExponentialMedium<S>>(box, 1.5f, spec<S>(0.2f, 0.05f, 0.5f), spec<S>(0.6f, 0.2f, 1.2f));
    using M = ExponentialMedium<S>;
    struct Case {
        const char* name;
        Ray ray;
        float tmax;
    };
    const Case cases[] = {
        {"through the box", {Vec3(-3.f, 0.1f, 0.2f), glm::normalize(Vec3(1.f, 0.05f, 0.02f))}, kInf},
        {"from inside, stopping inside", {Vec3(-0.5f, 0.5f, -0.5f), glm::normalize(Vec3(1.f, 0.2f, 0.3f))}, 0.9f},
    };
    const GridControl<M> grid_control(medium, 8);
    const GridMajorant<M> grid(medium, 8);
    const GlobalMajorant<M> global(medium);
    // A control of half the smallest density (at a corner) everywhere, and one of the centre's
    // density, above it over half the box (the residual there is negative, its factors above 1).
    const float d_min = medium.density_lower_bound(box);
    CHECK(d_min > 0.15f);  // 1.5 / e at the nearest corner's end of the axis, about 0.3
    const GlobalControl<M> low(medium, medium.extinction_per_density() * (0.5f * d_min));
    const GlobalControl<M> above(medium, medium.extinction_per_density() * 1.5f);
    std::uint64_t seed = 10;
    for (const Case& c : cases) {
        const auto expected = (-medium.optical_depth(c.ray, 0.f, c.tmax)).exp().eval();
        const std::string name = c.name;
        auto rr = [&](const auto& ctl, const char* what) {
            const auto [stat, lookups] = run<S>(
                [&](Pcg32& rng, LookupCount& n) { return transmittance_residual_ratio(medium, ctl, c.ray, c.tmax, {}, rng, n); },
                ++seed);
            check_mean(stat, expected, name + ", residual ratio tracking, " + what);
            return lookups;
        };
        auto rm = [&](const auto& maj, const char* what) {
            const auto [stat, lookups] = run<S>(
                [&](Pcg32& rng, LookupCount& n) { return transmittance_ray_marching(medium, maj, c.ray, c.tmax, {}, rng, n); },
                ++seed);
            check_mean(stat, expected, name + ", ray marching, " + what);
            return lookups;
        };
        const std::uint64_t with_grid_control = rr(grid_control, "grid control (8^3)");
        rr(low, "global control");
        rr(above, "a control above the density");
        rm(global, "global majorant");
        rm(grid, "grid majorant (8^3)");
        // Against ratio tracking under the same grid's majorant: the control removes most of it.
        const auto [ratio, ratio_lookups] = run<S>(
            [&](Pcg32& rng, LookupCount& n) { return transmittance_ratio(medium, grid, c.ray, c.tmax, {}, rng, n); }, ++seed);
        check_mean(ratio, expected, name + ", ratio tracking, grid majorant");
        MESSAGE(name << ": lookups per estimate, residual ratio tracking " << double(with_grid_control) / kSamples
                     << ", ratio tracking " << double(ratio_lookups) / kSamples);
        CHECK(double(with_grid_control) < 0.5 * double(ratio_lookups));
    }
}

TEST_CASE_TEMPLATE("residual ratio tracking and ray marching are unbiased on a linear density", S, Mono, Rgb) {
    // A 1-D ramp 0.2 + 3 x over x in [0, 1] (64 voxels), a ray along x between the first and last
    // voxel centres: optical depth u_c (0.2 len + 1.5 (x1^2 - x0^2)) in closed form.
    const auto medium = linear_ramp<S>(0.2f, 3.f, 64, spec<S>(0.2f, 0.1f, 0.4f), spec<S>(0.6f, 0.3f, 1.2f));
    using M = DenseGridMedium<S>;
    const float x0 = 0.5f / 64.f, x1 = 1.f - 0.5f / 64.f;
    const Ray ray{Vec3(x0, 0.f, 0.f), Vec3(1.f, 0.f, 0.f)};
    const float len = x1 - x0;
    const double depth_per_unit = 0.2 * double(len) + 1.5 * (double(x1) * x1 - double(x0) * x0);
    typename S::Spectrum expected;
    for (int c = 0; c < S::channels; ++c)
        expected[c] = float(std::exp(-depth_per_unit * double(medium.extinction_per_density()[c])));
    const GridControl<M> control(medium, std::array<int, 3>{16, 1, 1});
    const auto [rr, rr_lookups] = run<S>(
        [&](Pcg32& rng, LookupCount& n) { return transmittance_residual_ratio(medium, control, ray, len, {}, rng, n); }, 31);
    check_mean(rr, expected, "linear ramp, residual ratio tracking, grid control 16");
    const auto [rm, rm_lookups] = run<S>(
        [&](Pcg32& rng, LookupCount& n) {
            return transmittance_ray_marching(medium, GridMajorant<M>(medium, std::array<int, 3>{16, 1, 1}), ray, len, {},
                                              rng, n);
        },
        32);
    check_mean(rm, expected, "linear ramp, ray marching, grid majorant 16");
    MESSAGE("linear ramp: lookups per estimate, residual ratio tracking " << double(rr_lookups) / kSamples
                                                                       << ", ray marching " << double(rm_lookups) / kSamples);
}

TEST_CASE("residual ratio tracking with a control of 0 is ratio tracking, draw for draw") {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    const auto medium = make_medium<ExponentialMedium<Rgb>>(box, 1.5f, spec<Rgb>(0.2f, 0.05f, 0.5f),
                                                             spec<Rgb>(0.6f, 0.2f, 1.2f));
    using M = ExponentialMedium<Rgb>;
    const GlobalControl<M> zero(medium, Rgb::Spectrum::Zero());
    const GlobalMajorant<M> maj(medium);
    const Ray ray{Vec3(-3.f, 0.1f, 0.2f), glm::normalize(Vec3(1.f, 0.05f, 0.02f))};
    Pcg32 a(7, 1), b(7, 1);
    LookupCount na, nb;
    for (int i = 0; i < 2000; ++i) {
        const auto r = transmittance_residual_ratio(medium, zero, ray, kInf, {}, a, na);
        const auto t = transmittance_ratio(medium, maj, ray, kInf, {}, b, nb);
        for (int c = 0; c < 3; ++c) REQUIRE(r.value[c] == doctest::Approx(t.value[c]).epsilon(1e-5));
    }
    CHECK(na.count() == nb.count());
    CHECK(na.count() > 2000u);
}

TEST_CASE("transmittance estimators: bad input and the extremes") {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    using M = ExponentialMedium<Mono>;
    const auto medium = make_medium<M>(box, 1.5f, grey<Mono>(0.2f), grey<Mono>(0.6f));
    const GridControl<M> control(medium, 4);
    const GlobalMajorant<M> maj(medium);
    Pcg32 rng(1, 1);
    LookupCount n;
    const Ray bad{Vec3(0.f), Vec3(2.f, 0.f, 0.f)};  // not unit length
    const Ray good{Vec3(-3.f, 0.f, 0.f), Vec3(1.f, 0.f, 0.f)};
    CHECK(transmittance_residual_ratio(medium, control, bad, kInf, {}, rng, n).status == Status::InvalidInput);
    CHECK(transmittance_ray_marching(medium, maj, bad, kInf, {}, rng, n).status == Status::InvalidInput);
    CHECK(transmittance_residual_ratio(medium, control, good, std::nanf(""), {}, rng, n).status == Status::InvalidInput);
    CHECK(transmittance_ray_marching(medium, maj, good, std::nanf(""), {}, rng, n).status == Status::InvalidInput);
    // A ray that misses the medium: 1, no lookup.
    const Ray miss{Vec3(-3.f, 5.f, 0.f), Vec3(1.f, 0.f, 0.f)};
    const std::uint64_t before = n.count();
    CHECK(transmittance_residual_ratio(medium, control, miss, kInf, {}, rng, n).value[0] == 1.f);
    CHECK(transmittance_ray_marching(medium, maj, miss, kInf, {}, rng, n).value[0] == 1.f);
    CHECK(n.count() == before);
    // A collision limit reached: Aborted, value 0. With a control of 0 the residual majorant's
    // optical depth along `good` is about 6.5: every estimate but one in e^6.5 has a collision.
    const GlobalControl<M> zero(medium, grey<Mono>(0.f));
    int aborted = 0;
    for (int i = 0; i < 100; ++i) {
        const auto capped = transmittance_residual_ratio(medium, zero, good, kInf, {}, rng, n, 0);
        if (capped.status == Status::Aborted) {
            ++aborted;
            CHECK(capped.value[0] == 0.f);
        }
    }
    CHECK(aborted >= 95);
    // An empty medium (density 0): a control of 0 and no lookups, transmittance 1.
    const auto empty = make_medium<HomogeneousMedium<Mono>>(box, 0.f, grey<Mono>(0.f), grey<Mono>(0.f));
    const GlobalControl<HomogeneousMedium<Mono>> none(empty, grey<Mono>(0.f));
    CHECK(transmittance_residual_ratio(empty, none, good, kInf, {}, rng, n).value[0] == 1.f);
    CHECK(transmittance_ray_marching(empty, GlobalMajorant<HomogeneousMedium<Mono>>(empty), good, kInf, {}, rng, n)
              .value[0] == 1.f);
    // A dense medium (optical depth 2e6): the control takes it all, exp underflows to 0 exactly.
    const auto dense = HomogeneousMedium<Mono>(box, grey<Mono>(1e5f), grey<Mono>(9e5f));
    const GlobalControl<HomogeneousMedium<Mono>> all(dense, dense.extinction_bound_coefficient());
    const auto d = transmittance_residual_ratio(dense, all, good, kInf, {}, rng, n);
    CHECK(d.status == Status::Ok);
    CHECK(d.value[0] == 0.f);
    // Ray marching there: the comb is capped at max_lookups and the estimate stays finite.
    RayMarchingOptions few;
    few.max_lookups = 64;
    const auto m = transmittance_ray_marching(dense, GlobalMajorant<HomogeneousMedium<Mono>>(dense), good, kInf, {}, rng, n,
                                              few);
    CHECK(m.status == Status::Ok);
    CHECK(m.value[0] == 0.f);
    // Constructors and options name the bad value.
    CHECK_THROWS_WITH_AS(GlobalControl<M>(medium, grey<Mono>(-1.f)), doctest::Contains("GlobalControl control"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(GlobalControl<M>(medium, grey<Mono>(1e3f)),
                         doctest::Contains("exceeds the medium's extinction bound"), InvalidArgument);
    CHECK_THROWS_WITH_AS(GridControl<M>(medium, 0), doctest::Contains("GridControl"), InvalidArgument);
    RayMarchingOptions o;
    o.lookups_per_depth = 0.f;
    CHECK_THROWS_WITH_AS(validate(o), doctest::Contains("lookups_per_depth = 0"), InvalidArgument);
    o = {};
    o.min_lookups = 0;
    CHECK_THROWS_WITH_AS(validate(o), doctest::Contains("min_lookups = 0"), InvalidArgument);
    o = {};
    o.term_scale = std::nanf("");
    CHECK_THROWS_WITH_AS(validate(o), doctest::Contains("term_scale"), InvalidArgument);
}

TEST_CASE_TEMPLATE("ray-marched shadow rays: NEE single scattering from a point light = quadrature", S, Mono, Rgb) {
    // EstimatorOptions::shadow_estimator = RayMarching in the strategies without null-scattering
    // pdfs: ratio-nee, equiangular-nee (the nulls before its vertex too) and directional MIS (the
    // point light is reached by NEE alone), under the global and a grid majorant, every channel
    // against the quadrature of the closed-form integrand (exponential medium, optical thickness
    // about 1). The lookups differ from ratio tracking's: the option took effect.
    using M = ExponentialMedium<S>;
    const PointLightSingleScatter<M> setup;
    const M& medium = setup.medium;
    const auto& lights = setup.lights;
    const Ray ray = setup.ray;
    const auto& ref = setup.ref;
    EstimatorOptions ratio, marched;
    ratio.max_depth = marched.max_depth = 1;
    marched.shadow_estimator = ShadowEstimator::RayMarching;
    std::uint64_t seed = 60;
    auto run_all = [&](const auto& maj, const char* maj_name) {
        const auto scene = Scene(medium, maj, IsotropicPhase{}, lights);
        auto check = [&](const auto& est, const auto& with_ratio, const char* name) {
            const auto res = estimate_radiance(est, scene, ray, 20000, ++seed);
            const auto base = estimate_radiance(with_ratio, scene, ray, 20000, seed);
            CHECK(res.not_ok == 0);
            typename S::Spectrum mean;
            for (int c = 0; c < S::channels; ++c) mean[c] = float(ref[std::size_t(c)]);
            check_mean(res.stat, mean, std::string(name) + " (ray-marched shadows), " + maj_name);
            const std::string label = std::string(name) + ", " + maj_name;
            MESSAGE(label << ": lookups per sample " << double(res.lookups) / 20000.0 << " (ratio tracking's "
                          << double(base.lookups) / 20000.0 << ")");
            CHECK(res.lookups != base.lookups);
        };
        check(PathEstimator<strategy::NextEvent>(marched), PathEstimator<strategy::NextEvent>(ratio), "ratio-nee");
        check(PathEstimator<strategy::EquiangularNextEvent>(marched), PathEstimator<strategy::EquiangularNextEvent>(ratio),
              "equiangular-nee");
        check(PathEstimator<strategy::DirectionalMis, mis::Balance>(marched),
              PathEstimator<strategy::DirectionalMis, mis::Balance>(ratio), "directional-mis");
    };
    run_all(GlobalMajorant<M>(medium), "global majorant");
    run_all(GridMajorant<M>(medium, 8), "grid majorant 8^3");
}

TEST_CASE("ray-marched shadow rays: the host's shadow kernel, and the estimators that refuse them") {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    using M = HomogeneousMedium<Rgb>;
    const M medium(box, spec<Rgb>(0.3f, 0.1f, 0.9f), spec<Rgb>(0.9f, 0.5f, 1.5f));
    EstimatorOptions marched;
    marched.shadow_estimator = ShadowEstimator::RayMarching;
    const VertexKernels<strategy::NextEvent> k(marched);
    const Ray ray{Vec3(-0.5f, 0.f, 0.f), Vec3(1.f, 0.f, 0.f)};
    Pcg32 rng(5, 5);
    LookupCount n;
    const auto sh = k.shadow(medium, GlobalMajorant<M>(medium), ray, 1.2f, {}, rng, n);
    const auto expected = (-medium.optical_depth(ray, 0.f, 1.2f)).exp().eval();
    CHECK(sh.status == Status::Ok);
    for (int c = 0; c < 3; ++c) CHECK(sh.transmittance[c] == doctest::Approx(expected[c]).epsilon(2e-6));
    CHECK(n.count() == 2u * std::uint64_t(std::ceil(2.4 * 1.2)));  // two combs of ceil(tau_bar)
    auto refused = [&](auto make, const char* what) {
        CHECK_THROWS_WITH_AS(make(), doctest::Contains(what), InvalidArgument);
    };
    refused([&] { return PathEstimator<strategy::NullScatteringMis, mis::Balance>(marched); },
            "shadow_estimator = RayMarching is not allowed with strategy uni-nee-mis");
    refused([&] { return PathEstimator<strategy::EquiangularMis, mis::Balance>(marched); },
            "shadow_estimator = RayMarching is not allowed with strategy uni-nee-eq-mis");
    refused([&] { return PathEstimator<strategy::Unidirectional>(marched); }, "it casts no shadow rays");
    refused([&] { return SpectralPathEstimator<channels::SpectralMis, strategy::NextEvent>(marched); },
            "not allowed with nsp::SpectralPathEstimator");
    refused([&] { return BdptEstimator<bdpt::Directional, mis::Balance>(marched); }, "not allowed with nsp::BdptEstimator");
    EstimatorOptions bad;
    bad.ray_marching.max_order = 0;
    refused([&] { return PathEstimator<strategy::NextEvent>(bad); }, "RayMarchingOptions max_order = 0");
}

TEST_CASE("GridControl: per-cell minorants bound the density from below") {
    // Every lookup inside a cell lies in [control, control + residual majorant] and below the majorant in every channel.
    const Box box{Vec3(-1.f), Vec3(1.f)};
    using M = DenseGridMedium<Rgb>;
    const auto medium = make_medium<M>(box, 1.f, spec<Rgb>(0.2f, 0.1f, 0.4f), spec<Rgb>(0.6f, 0.3f, 1.2f));
    const GridControl<M> control(medium, 6);
    Pcg32 rng(3, 3);
    int checked = 0;
    for (int i = 0; i < 200; ++i) {
        const Vec3 o(-3.f, 2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f);
        const Ray ray{o, glm::normalize(Vec3(1.f, 0.4f * rng.uniform() - 0.2f, 0.4f * rng.uniform() - 0.2f))};
        auto it = control.iterate(ray, 0.f, kInf, {});
        while (auto seg = it.next()) {
            for (int k = 0; k < 4; ++k) {
                const float t = seg->t0 + (seg->t1 - seg->t0) * rng.uniform();
                const auto mu = medium.coefficients(ray.at(t), {}).sigma_t();
                const auto res = (mu - seg->sigma_ctl).eval();
                REQUIRE((res >= -1e-6f * mu).all());
                REQUIRE((res <= seg->sigma_res * (1.f + 1e-5f)).all());
                REQUIRE((mu <= seg->sigma_maj * (1.f + 1e-5f)).all());
                ++checked;
            }
        }
    }
    CHECK(checked > 1000);
    MESSAGE("controlled fraction of the noise-grid medium at 6^3: " << control.controlled_fraction());
    CHECK(control.controlled_fraction() > 0.0);
    CHECK(control.controlled_fraction() < 1.0);
    CHECK(control.memory_bytes() == 2 * 216 * sizeof(float));
}

TEST_CASE("TreeControl: the tree majorant's cells, each with its minorant") {
    // A TreeControl walks the cells of the TreeMajorant of its layout (the same stretches and
    // majorants, draw for draw), every lookup inside a cell lies in [control, control + residual
    // majorant], control_value_at is the control of the segment there, a medium without a lower
    // bound gets a control of 0, and the cells cost two floats each.
    const Box box{Vec3(-1.f), Vec3(1.f)};
    using M = DenseGridMedium<Rgb>;
    const auto medium = make_medium<M>(box, 1.f, spec<Rgb>(0.2f, 0.1f, 0.4f), spec<Rgb>(0.6f, 0.3f, 1.2f));
    const TreeLayout layout{box, {4, 4, 4}, {4, 2, 0}, 0.f, 0.f};  // split wherever the bound varies
    const TreeControl<M> control(medium, layout);
    const TreeMajorant<M> majorant(medium, layout);
    REQUIRE(control.split_cells(0) > 0);
    REQUIRE(control.split_cells(1) > 0);
    CHECK(control.memory_bytes() == 2 * majorant.memory_bytes());
    Pcg32 rng(3, 4);
    int checked = 0, positive = 0;
    for (int i = 0; i < 200; ++i) {
        const Vec3 o(-3.f, 2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f);
        const Ray ray{o, glm::normalize(Vec3(1.f, 0.4f * rng.uniform() - 0.2f, 0.4f * rng.uniform() - 0.2f))};
        auto it = control.iterate(ray, 0.f, kInf, {});
        auto plain = majorant.iterate(ray, 0.f, kInf, {});
        while (auto seg = it.next()) {
            const auto m = plain.next();
            REQUIRE(m);
            CHECK(seg->t0 == m->t0);
            CHECK(seg->t1 == m->t1);
            CHECK(seg->sigma_maj == m->sigma_maj);
            positive += seg->sigma_ctl.minCoeff() > 0.f;
            const Vec3 mid = ray.at(0.5f * (seg->t0 + seg->t1));
            CHECK((control.control_value_at(mid, {}) == seg->sigma_ctl).all());
            CHECK(control.value_at(mid, {}) == seg->sigma_maj);
            for (int k = 0; k < 4; ++k) {
                const float t = seg->t0 + (seg->t1 - seg->t0) * rng.uniform();
                const auto mu = medium.coefficients(ray.at(t), {}).sigma_t();
                const auto res = (mu - seg->sigma_ctl).eval();
                REQUIRE((res >= -1e-6f * mu).all());
                REQUIRE((res <= seg->sigma_res * (1.f + 1e-5f)).all());
                REQUIRE((mu <= seg->sigma_maj * (1.f + 1e-5f)).all());
                ++checked;
            }
        }
        CHECK_FALSE(plain.next());
        CHECK(it.steps() == plain.steps());
    }
    CHECK(checked > 1000);
    MESSAGE("tree-control segments with a positive control: " << positive << " of " << checked / 4);
    CHECK(positive > checked / 40);
    // Outside the medium: no majorant, no control.
    CHECK(control.value_at(Vec3(2.f), {}) == 0.f);
    CHECK((control.control_value_at(Vec3(2.f), {}) == 0.f).all());

    // A medium without a density lower bound: the tree's cells with a control of 0.
    struct Unbounded : M {
        explicit Unbounded(const M& m) : M(m) {}
        float density_lower_bound(const Box&) const = delete;
    };
    static_assert(LowerBoundedMedium<M> && !LowerBoundedMedium<Unbounded> && CellBoundedMedium<Unbounded>);
    const Unbounded unbounded(medium);
    const TreeControl<Unbounded> zero(unbounded, layout);
    const Ray ray{Vec3(-3.f, 0.1f, -0.2f), glm::normalize(Vec3(1.f, 0.05f, 0.1f))};
    auto it = zero.iterate(ray, 0.f, kInf, {});
    auto plain = majorant.iterate(ray, 0.f, kInf, {});
    int segments = 0;
    while (auto seg = it.next()) {
        const auto m = plain.next();
        REQUIRE(m);
        CHECK(seg->sigma_maj == m->sigma_maj);
        CHECK((seg->sigma_ctl == 0.f).all());
        CHECK(seg->sigma_res == seg->sigma_maj);
        ++segments;
    }
    CHECK(segments > 4);
}

}  // namespace
