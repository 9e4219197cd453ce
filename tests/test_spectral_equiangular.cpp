// tests/test_spectral_equiangular.cpp: the equiangular strategies over channels (THEORY 5.4 with
// 5.3): SpectralPathEstimator with EquiangularNextEvent and EquiangularMis is unbiased in every
// channel for every channel policy, per-channel and grey majorants (global and grid): single
// scattering from a point light in a chromatic medium against quadrature, a chromatic furnace
// whose point light aims the equiangular vertices (Rgb and Hero), and multiple scattering with
// strong roulette and a large sphere light against spectral null-scattering MIS.
//
// Statistical checks: fixed seeds (deterministic), k = 5 standard errors estimated from the
// samples (combined for two independent runs), plus kRoundingFloor where every sample may equal
// the expected value.
#include <array>
#include <cmath>
#include <string>
#include <tuple>

#include "references.hpp"
#include "majorants.hpp"
#include "spectral.hpp"

namespace {

using namespace nsp_test;

constexpr double kSigmas = 5.0;
const Box kBox{Vec3(-1.f), Vec3(1.f)};

/// Checks every channel's mean of `res` against the single-scattering quadrature `ref` x the
/// light's intensity per channel, within kSigmas standard errors.
template <class Res>
void check_against_quadrature(const Res& res, const std::array<double, 3>& ref,
                              const std::array<double, 3>& intensity, const std::string& label) {
    for (int c = 0; c < 3; ++c) {
        const Stat& s = res.stat.ch[std::size_t(c)];
        const double expected = ref[std::size_t(c)] * intensity[std::size_t(c)];
        CAPTURE(c);
        MESSAGE(label << ": " << s.mean << " (SE " << s.se() << "), quadrature " << expected);
        CHECK(std::abs(s.mean - expected) <= kSigmas * s.se() + kRoundingFloor);
    }
}

template <ChannelPolicy CP, AbsorptionPolicy A>
using EquiangularOf = std::tuple<SpectralPathEstimator<CP, strategy::EquiangularNextEvent, mis::None, A>,
                                 SpectralPathEstimator<CP, strategy::EquiangularMis, mis::Balance, A>>;

template <AbsorptionPolicy A>
using EquiangularWith = decltype(std::tuple_cat(EquiangularOf<channels::Independent, A>{},
                                                EquiangularOf<channels::SpectralTrackingAverage, A>{},
                                                EquiangularOf<channels::SpectralMis, A>{}));

/// Every spectral equiangular estimator: 3 channel policies x 2 strategies x 2 absorption policies.
using SpectralEquiangular = decltype(std::tuple_cat(EquiangularWith<absorption::Event>{},
                                                    EquiangularWith<absorption::Weight>{}));

/// Calls f(majorant, name) for every majorant channel policy CP takes on medium m: per-channel
/// global and grid majorants for its own pdfs, the grey global and grid majorants for all.
template <ChannelPolicy CP, class M, class F>
void for_each_majorant(const M& m, F&& f) {
    f(GlobalMajorant<M>(m), "global");
    if constexpr (RegionBoundedMedium<M>) f(GridMajorant<M>(m, kTestGridRes), "grid");
    if constexpr (CP::own_pdfs) {
        f(ChannelMajorant<M>(m), "per-channel");
        if constexpr (RegionBoundedMedium<M>) f(ChannelGridMajorant<M>(m, kTestGridRes), "channel-grid");
    }
}

TEST_CASE_TEMPLATE_DEFINE("spectral equiangular: single scattering from a point light = quadrature, every channel", E,
                          spectral_eq_single) {
    using A = typename E::Absorption;
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    EstimatorOptions opts;
    opts.max_depth = 1;
    const E est(opts);
    const Vec3 light(0.2f, 0.25f, -0.1f);  // inside, 0.3 from the camera ray
    Lights<Rgb> lights;
    lights.set(PointLight<Rgb>{light, Rgb::Spectrum(2.f, 1.f, 3.f)});
    const Ray ray{Vec3(-3.f, 0.05f, -0.05f), glm::normalize(Vec3(1.f, 0.01f, -0.02f))};
    auto run = [&](const auto& medium, const char* medium_name) {
        using M = std::remove_cvref_t<decltype(medium)>;
        const auto ref = single_scatter_reference(medium, ray, light, 1.f);
        const std::array<double, 3> intensity{2.0, 1.0, 3.0};
        int seed = 100;
        for_each_majorant<typename E::Channels>(medium, [&](const auto& maj, const char* maj_name) {
            const auto scene = Scene(medium, maj, IsotropicPhase{}, lights);
            const auto res = estimate_radiance(est, scene, ray, 20000, std::uint64_t(++seed));
            CHECK(res.not_ok == 0);
            check_against_quadrature(res, ref, intensity, name + " " + medium_name + " " + maj_name);
        });
        (void)sizeof(M);
    };
    // Extinction 1 : 3 : 0.4 per channel, albedo 0.75 / 0.5 / 0.9: optical thickness about 1 in R.
    run(make_medium<HomogeneousMedium<Rgb>>(kBox, 0.5f, spec<Rgb>(0.25f, 1.5f, 0.04f), spec<Rgb>(0.75f, 1.5f, 0.36f)),
        "homogeneous");
    run(make_medium<ExponentialMedium<Rgb>>(kBox, 0.5f, spec<Rgb>(0.25f, 1.5f, 0.04f), spec<Rgb>(0.75f, 1.5f, 0.36f)),
        "exponential");
    (void)sizeof(A);
}
TEST_CASE_TEMPLATE_APPLY(spectral_eq_single, SpectralEquiangular);

TEST_CASE("spectral equiangular MIS in a dense medium: the vertex drawn on a fraction of the segments, = quadrature") {
    // The single-scattering set-up above, 4x denser (optical thickness about 4 in R, 12 in G):
    // at the equiangular peak the largest channel's majorant (6) is far above p_eq ~ 1.3, so the
    // camera segment draws its equiangular vertex with probability ~0.2 (checked < 1) and every
    // channel's equiangular pdf carries that factor. Independent tracking and spectral MIS, under
    // the per-channel and the grey global majorant, every channel against quadrature.
    const Vec3 light(0.2f, 0.25f, -0.1f);
    Lights<Rgb> lights;
    lights.set(PointLight<Rgb>{light, Rgb::Spectrum(2.f, 1.f, 3.f)});
    const Ray ray{Vec3(-3.f, 0.05f, -0.05f), glm::normalize(Vec3(1.f, 0.01f, -0.02f))};
    using M = HomogeneousMedium<Rgb>;
    const auto medium = make_medium<M>(kBox, 2.f, spec<Rgb>(0.25f, 1.5f, 0.04f), spec<Rgb>(0.75f, 1.5f, 0.36f));
    const auto ref = single_scatter_reference(medium, ray, light, 1.f);
    const std::array<double, 3> intensity{2.0, 1.0, 3.0};
    EstimatorOptions opts;
    opts.max_depth = 1;
    int seed = 300;
    auto run = [&](const auto& est, const auto& maj, const char* name) {
        const Interval in = medium.bounds().clip(ray, 0.f, kInf);
        const float p = equiangular_probability<M>(maj, ray, EquiangularSampler(ray, light, in.t0, in.t1), {});
        MESSAGE(std::string(name) << ": camera segment draws its equiangular vertex with probability " << p);
        CHECK(p > 0.f);
        CHECK(p < 1.f);
        const auto scene = Scene(medium, maj, IsotropicPhase{}, lights);
        const auto res = estimate_radiance(est, scene, ray, 20000, std::uint64_t(++seed));
        CHECK(res.not_ok == 0);
        for (const double r : ref) CHECK(r > 0.0);
        check_against_quadrature(res, ref, intensity, name);
    };
    const SpectralPathEstimator<channels::SpectralMis, strategy::EquiangularMis, mis::Balance> mis_est(opts);
    const SpectralPathEstimator<channels::Independent, strategy::EquiangularMis, mis::Balance> indep_est(opts);
    run(mis_est, ChannelMajorant<M>(medium), "spectral MIS, per-channel majorant");
    run(mis_est, GlobalMajorant<M>(medium), "spectral MIS, global majorant");
    run(indep_est, ChannelMajorant<M>(medium), "independent, per-channel majorant");
}

TEST_CASE_TEMPLATE_DEFINE("spectral equiangular: chromatic furnace with a point-light target gives 1 (Rgb, Hero)", E,
                          spectral_eq_furnace) {
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    const E est;
    auto run = [&](auto tag) {
        using S = decltype(tag);
        // Albedo 1, scattering 1 : 2.5 : 0.4 per channel, under a unit environment: 1 everywhere.
        // A point light of intensity 0 in the medium is the equiangular target.
        const auto medium = DenseGridMedium<S>(kBox, {4, 3, 5}, std::vector<float>(60, 0.8f), chroma<S>(0.f, 0.f, 0.f),
                                               chroma<S>(1.f, 2.5f, 0.4f));
        Lights<S> lights;
        lights.set(EnvironmentLight<S>{constant_coefficient<S>(1.f)});
        lights.set(PointLight<S>{Vec3(0.1f, -0.2f, 0.3f), constant_coefficient<S>(0.f)});
        const Ray ray{Vec3(-3.f, 0.15f, -0.1f), glm::normalize(Vec3(1.f, 0.02f, 0.03f))};
        int seed = 200;
        for_each_majorant<typename E::Channels>(medium, [&](const auto& maj, const char* maj_name) {
            const auto scene = Scene(medium, maj, HenyeyGreensteinPhase(0.3f), lights);
            const auto res = estimate_error(est, scene, ray, 15000, std::uint64_t(++seed),
                                            [](const auto&) { return S::Spectrum::Ones().eval(); });
            CHECK(res.not_ok == 0);
            for (int c = 0; c < S::channels; ++c) {
                const Stat& s = res.stat.ch[std::size_t(c)];
                CAPTURE(c);
                MESSAGE(name << " " << std::string(S::name) << " " << std::string(maj_name) << ": error " << s.mean << " (SE " << s.se() << ")");
                CHECK(std::abs(s.mean) <= kSigmas * s.se() + kRoundingFloor);
            }
        });
    };
    run(Rgb{});
    run(Hero<4>{});
}
TEST_CASE_TEMPLATE_APPLY(spectral_eq_furnace, SpectralEquiangular);

TEST_CASE_TEMPLATE_DEFINE("spectral equiangular MIS: strong roulette and a large light agree with spectral uni + NEE MIS",
                          CP, spectral_eq_roulette) {
    // As the grey suite's case: single scattering toward a large light just off the camera ray's
    // line, forward scattering, roulette from the first vertex with survival at most 0.3, so every
    // one of the 3 x C techniques matters.
    using A = absorption::Weight;
    const auto medium = make_medium<DenseGridMedium<Rgb>>(kBox, 0.5f, spec<Rgb>(0.1f, 0.15f, 0.05f),
                                                          spec<Rgb>(0.9f, 2.f, 0.5f));
    Lights<Rgb> lights;
    lights.set(SphereLight<Rgb>{Vec3(3.2f, 1.6f, 0.1f), 1.2f, Rgb::Spectrum(1.f, 0.5f, 2.f)});
    const Ray ray{Vec3(-3.f, 0.3f, 0.1f), Vec3(1.f, 0.f, 0.f)};
    EstimatorOptions opts;
    opts.max_depth = 1;
    opts.rr_start_depth = 1;
    opts.rr_max_survival = 0.3f;
    for_each_majorant<CP>(medium, [&](const auto& maj, const char* maj_name) {
        const auto scene = Scene(medium, maj, HenyeyGreensteinPhase(0.9f), lights);
        const auto ref = estimate_radiance(SpectralPathEstimator<CP, strategy::NullScatteringMis, mis::Balance, A>(opts),
                                           scene, ray, 200000, 300);
        const auto res = estimate_radiance(SpectralPathEstimator<CP, strategy::EquiangularMis, mis::Balance, A>(opts),
                                           scene, ray, 200000, 301);
        CHECK(ref.not_ok == 0);
        CHECK(res.not_ok == 0);
        for (int c = 0; c < 3; ++c) {
            const Stat &s = res.stat.ch[std::size_t(c)], &r = ref.stat.ch[std::size_t(c)];
            const double se = std::sqrt(s.se() * s.se() + r.se() * r.se());
            CAPTURE(c);
            MESSAGE(std::string(CP::name) << " " << std::string(maj_name) << " uni-nee-eq-mis: " << s.mean << " (SE " << s.se()
                             << "), uni-nee-mis " << r.mean << " (SE " << r.se() << ")");
            CHECK(r.mean > 0.01);
            CHECK(std::abs(s.mean - r.mean) <= kSigmas * se);
        }
    });
}
TEST_CASE_TEMPLATE_APPLY(spectral_eq_roulette,
                         std::tuple<channels::Independent, channels::SpectralTrackingAverage, channels::SpectralMis>);

}  // namespace
