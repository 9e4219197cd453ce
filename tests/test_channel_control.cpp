// tests/test_channel_control.cpp: SpectralPathEstimator under a per-channel majorant's control
// (ChannelGridControl; THEORY 5.10 with 5.3). Each channel has its own majorant d_max u_c and
// control d_min u_c; the sampling channel draws decomposition tracking's control and residual
// collisions with its own, shadow rays residual-ratio-track every channel's own residual, and every
// channel's pdfs are its own decomposition and residual ratio tracking's. Unbiased against closed
// forms: the albedo-1 furnace, single scattering from a point light against quadrature (with the
// equiangular techniques), an emitting absorber against quadrature and the emissive furnace, with
// spectral MIS and independent tracking (the channel policies with own pdfs), both absorption
// policies. And what the control is for: fewer lookups than the per-channel grid majorant of the
// same cells, on a strongly chromatic medium.
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>

#include "references.hpp"

namespace {

using namespace nsp_test;

// k = 5 standard errors of the mean (estimated from the samples); fixed seeds: deterministic.
constexpr double kSigmas = 5.0;
// The largest standard error a run may have, relative to its expected value: a check whose SE
// is a large part of the answer could not fail.
constexpr double kMaxRelativeSe = 0.1;

template <class Res>
void check_channels(const Res& res, const std::array<double, 3>& ref, const std::string& label) {
    CHECK(res.not_ok == 0);
    for (int c = 0; c < 3; ++c) {
        const Stat& s = res.stat.ch[std::size_t(c)];
        CAPTURE(label);
        CAPTURE(c);
        MESSAGE(label << " channel " << c << ": " << s.mean << " (SE " << s.se() << "), expected " << ref[c]);
        CHECK(std::abs(s.mean - ref[c]) <= kSigmas * s.se() + 1e-12);
        CHECK(s.se() <= kMaxRelativeSe * std::abs(ref[c]));
    }
}

template <class E>
std::string name_of() {
    return std::string(E::Channels::name) + "/" + estimator_name<E>();
}

/// Runs `each(est)` over the channel policies with own pdfs: spectral MIS's three strategies and
/// independent tracking under null-scattering MIS.
template <AbsorptionPolicy A, class F>
void for_each_own_pdfs(F&& each) {
    each(SpectralPathEstimator<channels::SpectralMis, strategy::Unidirectional, mis::None, A>{});
    each(SpectralPathEstimator<channels::SpectralMis, strategy::NextEvent, mis::None, A>{});
    each(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance, A>{});
    each(SpectralPathEstimator<channels::Independent, strategy::NullScatteringMis, mis::Balance, A>{});
}

TEST_CASE_TEMPLATE("per-channel control: albedo 1 under a unit environment gives 1", A, absorption::Weight,
                   absorption::Event) {
    // Multiple scattering from outside and from inside the box, 4000 paths each, on an
    // exponential medium and a noise grid, channels 1 : 0.4 : 2.5 (each channel's own control and
    // residual differ), under a ChannelGridControl of 8^3, and the noise grid under a
    // ChannelTreeControl (its adaptive layout).
    using S = Rgb;
    const Box box{Vec3(-1.f), Vec3(1.f)};
    Lights<S> lights;
    lights.set(EnvironmentLight<S>{grey<S>(1.f)});
    const Ray rays[] = {
        {Vec3(-3.f, 0.2f, 0.1f), glm::normalize(Vec3(1.f, -0.05f, 0.02f))},
        {Vec3(0.1f, -0.2f, 0.3f), glm::normalize(Vec3(0.3f, 0.9f, -0.2f))},
    };
    std::uint64_t seed = std::is_same_v<A, absorption::Event> ? 2100 : 2000;
    auto run = [&](const auto& medium, const auto& control, const std::string& name) {
        const Scene scene(medium, control, HenyeyGreensteinPhase(0.5f), lights);
        for_each_own_pdfs<A>([&](const auto& est) {
            using E = std::remove_cvref_t<decltype(est)>;
            for (int r = 0; r < 2; ++r) {
                const auto res = estimate_radiance(est, scene, rays[r], 4000, ++seed);
                CHECK(res.lookups > 0);
                check_channels(res, {1.0, 1.0, 1.0}, name + " " + name_of<E>() + " ray " + std::to_string(r));
            }
        });
    };
    using Exp = ExponentialMedium<S>;
    using Grid = DenseGridMedium<S>;
    const auto exp_medium = make_medium<Exp>(box, 1.5f, spec<S>(0.f, 0.f, 0.f), spec<S>(1.f, 0.4f, 2.5f));
    const auto grid_medium = make_medium<Grid>(box, 1.5f, spec<S>(0.f, 0.f, 0.f), spec<S>(1.f, 0.4f, 2.5f));
    run(exp_medium, ChannelGridControl<Exp>(exp_medium, 8), "exponential, channel grid control");
    run(grid_medium, ChannelGridControl<Grid>(grid_medium, 8), "noise grid, channel grid control");
    run(grid_medium, ChannelTreeControl<Grid>(grid_medium), "noise grid, channel tree control");
}

TEST_CASE_TEMPLATE("per-channel control: single scattering from a point light = quadrature", A, absorption::Weight,
                   absorption::Event) {
    // The quadrature set-up of the other suites (channels 3x apart), 100000 paths each: NEE,
    // null-scattering MIS, and the equiangular vertex, whose tracking pdf is every channel's sum
    // over its own two routes.
    const PointLightSingleScatter<ExponentialMedium<Rgb>> setup;
    using M = ExponentialMedium<Rgb>;
    EstimatorOptions opts;
    opts.max_depth = 1;
    std::uint64_t seed = std::is_same_v<A, absorption::Event> ? 2300 : 2200;
    auto run = [&](const auto& control, const std::string& name) {
        const auto scene = Scene(setup.medium, control, IsotropicPhase{}, setup.lights);
        auto each = [&](const auto& est) {
            using E = std::remove_cvref_t<decltype(est)>;
            const auto res = estimate_radiance(E(opts), scene, setup.ray, 100000, ++seed);
            check_channels(res, setup.ref, name + " " + name_of<E>());
        };
        each(SpectralPathEstimator<channels::SpectralMis, strategy::NextEvent, mis::None, A>{});
        each(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance, A>{});
        each(SpectralPathEstimator<channels::Independent, strategy::NullScatteringMis, mis::Balance, A>{});
        each(SpectralPathEstimator<channels::SpectralMis, strategy::EquiangularNextEvent, mis::None, A>{});
        each(SpectralPathEstimator<channels::SpectralMis, strategy::EquiangularMis, mis::Balance, A>{});
    };
    run(ChannelGridControl<M>(setup.medium, 8), "channel grid control");
    run(ChannelTreeControl<M>(setup.medium, TreeLayout{setup.box, {2, 2, 2}, {2, 0, 0}, 0.f, 0.f}), "channel tree control");
}

TEST_CASE("per-channel control: emitting absorber = quadrature") {
    // No scattering: L_c = int T_c mu_a,c L_e,c dt. The collision estimator at every control and
    // residual collision with every channel's own pdfs, the segment technique and NEE toward the
    // volume (their nulls by each channel's residual ratio tracking); 20000 paths, with and without
    // the segment technique.
    // EmittingAbsorber (references.hpp), Rgb, on an exponential medium.
    using S = Rgb;
    const EmittingAbsorber<ExponentialMedium<S>> setup;
    using EM = EmittingAbsorber<ExponentialMedium<S>>::Medium;
    const auto& [box, base, medium, ray, ref] = setup;
    const auto scene = Scene(medium, ChannelGridControl<EM>(medium, 8), IsotropicPhase{}, Lights<S>{});
    EstimatorOptions off;
    off.emission_along_segments = false;
    std::uint64_t seed = 2400;
    auto each = [&](const auto& est) {
        using E = std::remove_cvref_t<decltype(est)>;
        check_channels(estimate_radiance(est, scene, ray, 20000, ++seed), ref, name_of<E>());
        if constexpr (E::Strategy::combines)
            check_channels(estimate_radiance(E(off), scene, ray, 20000, ++seed), ref,
                           name_of<E>() + " no segment technique");
    };
    for_each_own_pdfs<absorption::Weight>(each);
    each(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance, absorption::Event>{});
}

TEST_CASE("per-channel control: the emissive furnace gives L_e, with and without roulette") {
    // EmissiveFurnace (references.hpp): L = L_e after many scatterings, for any density and
    // albedo; every technique's contributions are weighed against the others'.
    const EmissiveFurnace setup;
    using EM = EmissiveFurnace::Medium;
    const Scene scene(setup.medium, ChannelGridControl<EM>(setup.medium, 8), HenyeyGreensteinPhase(0.3f), setup.lights);
    EstimatorOptions rr;
    rr.rr_start_depth = 1;
    rr.rr_max_survival = 0.6f;
    std::uint64_t seed = 2500;
    auto each = [&](const auto& est) {
        using E = std::remove_cvref_t<decltype(est)>;
        for (const bool roulette : {false, true}) {
            const auto res = estimate_radiance(roulette ? E(rr) : est, scene, setup.ray, 6000, ++seed);
            check_channels(res, setup.ref(), name_of<E>() + (roulette ? " roulette" : ""));
        }
    };
    each(SpectralPathEstimator<channels::SpectralMis, strategy::Unidirectional, mis::None, absorption::Weight>{});
    each(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance, absorption::Weight>{});
    each(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance, absorption::Event>{});
    each(SpectralPathEstimator<channels::Independent, strategy::NullScatteringMis, mis::Balance, absorption::Weight>{});
}

TEST_CASE("per-channel control: shadow rays pay lookups for the residual only, unbiased against the closed form") {
    // An exponential medium (density e^2 apart across the box), channels 10x apart, under a
    // ChannelGridMajorant and a ChannelGridControl of the same 8^3 cells. Each channel c's own
    // (residual) ratio tracking estimates T_c = f_c / nee_c along one ray through the box, 20000
    // times: the mean must match exp(-tau_c) in closed form (5 SE), and the control's lookups
    // (tentative collisions at the residual R_c = (d_max - d_min) u_c) must be below half the
    // majorant's (at d_max u_c): a cell's density varies e^(2/8) = 1.28x along the axis, so
    // R_c / mu_bar_c is about 0.22 there.
    using S = Rgb;
    using M = ExponentialMedium<S>;
    const Box box{Vec3(-1.f), Vec3(1.f)};
    const M medium = make_medium<M>(box, 1.f, spec<S>(0.1f, 0.02f, 0.3f), spec<S>(0.5f, 0.08f, 1.5f));
    const Ray ray{Vec3(-3.f, 0.05f, -0.05f), glm::normalize(Vec3(1.f, 0.1f, -0.02f))};
    const auto tau = medium.optical_depth(ray, 0.f, kInf);
    const ChannelGridMajorant<M> majorant(medium, 8);
    const ChannelGridControl<M> control(medium, 8);
    constexpr int n = 20000;
    for (int c = 0; c < 3; ++c) {
        CAPTURE(c);
        auto run = [&](const auto& maj, std::uint64_t seed, std::uint64_t& lookups) {
            Pcg32 rng(seed, 1);
            LookupCount count;
            Stat st;
            for (int i = 0; i < n; ++i) {
                const auto sh = track_channels_ratio<channels::SpectralMis, absorption::Weight>(
                    medium, maj, ray, kInf, {}, c, S::Spectrum::Ones().eval(), false, rng, count);
                REQUIRE(sh.end == SegmentEnd::Passed);
                st.add(double(sh.f[c]) / double(sh.nee[c]));
            }
            lookups = count.count();
            const double expected = std::exp(-double(tau[c]));
            CHECK(std::abs(st.mean - expected) <= kSigmas * st.se());
            CHECK(st.se() <= kMaxRelativeSe * expected);
            return st;
        };
        std::uint64_t l_maj = 0, l_ctl = 0;
        const Stat a = run(majorant, 2700 + std::uint64_t(c), l_maj);
        const Stat b = run(control, 2800 + std::uint64_t(c), l_ctl);
        MESSAGE("channel " << c << ": T = " << std::exp(-double(tau[c])) << "; ratio tracking " << a.mean << " (var "
                           << a.variance() << ", " << double(l_maj) / n << " lookups), residual ratio tracking " << b.mean
                           << " (var " << b.variance() << ", " << double(l_ctl) / n << " lookups)");
        CHECK(double(l_ctl) < 0.5 * double(l_maj));
    }
}

}  // namespace
