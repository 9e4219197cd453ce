// tests/test_spectral_emission.cpp: volume emission over channels (THEORY 5.7 with 5.3):
// SpectralPathEstimator's collision estimator, NEE toward the emitting volume, the segment
// technique (a point drawn along each segment by the power grid) and their MIS are
// unbiased in every channel for every channel policy and majorant: a chromatic emissive furnace
// (L_e equal to the environment gives L_e, Rgb and Hero), with equiangular MIS aiming at a dark
// point light beside it, and a chromatic emitting absorber against quadrature.
//
// Statistical checks: fixed seeds (deterministic), k = 5 standard errors estimated from the
// samples, plus kRoundingFloor where every sample may equal the expected value.
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "majorants.hpp"
#include "references.hpp"
#include "spectral.hpp"

namespace {

using namespace nsp_test;

constexpr double kSigmas = 5.0;
const Box kBox{Vec3(-1.f), Vec3(1.f)};

template <ChannelPolicy CP, AbsorptionPolicy A>
using EmissionOf = std::tuple<SpectralPathEstimator<CP, strategy::Unidirectional, mis::None, A>,
                              SpectralPathEstimator<CP, strategy::NextEvent, mis::None, A>,
                              SpectralPathEstimator<CP, strategy::NullScatteringMis, mis::Balance, A>,
                              SpectralPathEstimator<CP, strategy::EquiangularMis, mis::Balance, A>>;

template <AbsorptionPolicy A>
using EmissionWith = decltype(std::tuple_cat(EmissionOf<channels::Independent, A>{},
                                             EmissionOf<channels::SpectralTrackingAverage, A>{},
                                             EmissionOf<channels::SpectralMis, A>{}));

/// 3 channel policies x 4 strategies x 2 absorption policies.
using SpectralEmission = decltype(std::tuple_cat(EmissionWith<absorption::Event>{}, EmissionWith<absorption::Weight>{}));

/// Calls f(majorant, name) for every majorant channel policy CP takes on medium m.
template <ChannelPolicy CP, class M, class F>
void for_each_majorant(const M& m, F&& f) {
    f(GlobalMajorant<M>(m), "global");
    f(GridMajorant<M>(m, kTestGridRes), "grid");
    if constexpr (CP::own_pdfs) {
        f(ChannelMajorant<M>(m), "per-channel");
        f(ChannelGridMajorant<M>(m, kTestGridRes), "channel-grid");
    }
}

TEST_CASE_TEMPLATE_DEFINE("spectral emissive furnace: L_e equal to the environment gives L_e per channel (Rgb, Hero)", E,
                          spectral_emissive_furnace) {
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    EstimatorOptions opts;
    opts.rr_start_depth = 1;  // roulette from the first vertex, survival at most 0.6: both MIS sides carry it
    opts.rr_max_survival = 0.6f;
    const E est(opts);
    auto run = [&](auto tag) {
        using S = decltype(tag);
        // Chromatic absorption 0.5 : 1.2 : 0.2 and scattering 0.6 : 0.3 : 1.1 per unit density over
        // a random 4 x 3 x 5 density grid; constant L_e = the environment's radiance: L = L_e.
        const auto le = chroma<S>(0.7f, 0.4f, 1.1f);
        std::vector<float> density(60);
        Pcg32 rng(5, 17);
        for (float& v : density) v = 1.6f * rng.uniform();
        const DenseGridMedium<S> base(kBox, {4, 3, 5}, density, chroma<S>(0.5f, 1.2f, 0.2f), chroma<S>(0.6f, 0.3f, 1.1f));
        const Emissive<DenseGridMedium<S>> medium(base, EmissionGrid(kBox, {2, 2, 2}, std::vector<float>(8, 1.f)), le,
                                                  {4, 4, 4});
        Lights<S> lights;
        lights.set(EnvironmentLight<S>{le});
        // A point light of intensity 0 beside the box: the equiangular target of EquiangularMis.
        lights.set(PointLight<S>{Vec3(0.2f, 1.3f, -0.1f), constant_coefficient<S>(0.f)});
        const Ray ray{Vec3(-3.f, 0.15f, -0.1f), glm::normalize(Vec3(1.f, 0.02f, 0.03f))};
        int seed = 400;
        for_each_majorant<typename E::Channels>(medium, [&](const auto& maj, const char* maj_name) {
            const auto scene = Scene(medium, maj, HenyeyGreensteinPhase(0.3f), lights);
            const auto res = estimate_error(est, scene, ray, 8000, std::uint64_t(++seed),
                                            [&](const auto& lambda) { return S::sample(le, lambda); });
            CHECK(res.not_ok == 0);
            for (int c = 0; c < S::channels; ++c) {
                const Stat& s = res.stat.ch[std::size_t(c)];
                CAPTURE(c);
                MESSAGE(name << " " << std::string(S::name) << " " << std::string(maj_name) << ": error " << s.mean
                             << " (SE " << s.se() << ")");
                CHECK(std::abs(s.mean) <= kSigmas * s.se() + kRoundingFloor);
            }
        });
    };
    run(Rgb{});
    run(Hero<4>{});
}
TEST_CASE_TEMPLATE_APPLY(spectral_emissive_furnace, SpectralEmission);

TEST_CASE_TEMPLATE_DEFINE("spectral emitting absorber = quadrature per channel", E, spectral_emissive_absorber) {
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    const E est;
    // No scattering, absorption 0.8 : 0.2 : 1.6 per unit density of an exponential medium, L_e
    // varying over a 5 x 3 x 4 grid: L_c = int T_c mu_a,c L_e,c dt by composite Simpson (double).
    const auto base = make_medium<ExponentialMedium<Rgb>>(kBox, 0.9f, spec<Rgb>(0.8f, 0.2f, 1.6f), grey<Rgb>(0.f));
    std::vector<float> e(60);
    Pcg32 rng(7, 71);
    for (float& v : e) v = 2.f * rng.uniform();
    const Emissive<ExponentialMedium<Rgb>> medium(base, EmissionGrid(Box{Vec3(-1.f, -0.8f, -1.2f), Vec3(0.9f, 1.f, 1.f)},
                                                                     {5, 3, 4}, e),
                                                  spec<Rgb>(2.f, 1.f, 0.5f), {6, 5, 4});
    const Ray ray{Vec3(-3.f, 0.25f, -0.3f), glm::normalize(Vec3(1.f, -0.05f, 0.12f))};
    const auto ref = emitting_absorber_reference(base, medium, ray);
    int seed = 500;
    // The combining strategies with the segment technique (the default, the only sampler of the
    // camera ray's emission besides collisions) and without it.
    EstimatorOptions off;
    off.emission_along_segments = false;
    const E est_off(off);
    for_each_majorant<typename E::Channels>(medium, [&](const auto& maj, const char* maj_name) {
        const auto scene = Scene(medium, maj, IsotropicPhase{}, Lights<Rgb>{});
        for (const E* e_ : {&est, &est_off}) {
            if (e_ == &est_off && !E::Strategy::combines) continue;
            const auto res = estimate_radiance(*e_, scene, ray, 20000, std::uint64_t(++seed));
            CHECK(res.not_ok == 0);
            for (int c = 0; c < 3; ++c) {
                const Stat& s = res.stat.ch[std::size_t(c)];
                CAPTURE(c);
                MESSAGE(name << " " << std::string(maj_name) << (e_ == &est_off ? " no segment technique" : "") << ": "
                             << s.mean << " (SE " << s.se() << "), quadrature " << ref[std::size_t(c)]);
                CHECK(std::abs(s.mean - ref[std::size_t(c)]) <= kSigmas * s.se() + kRoundingFloor);
            }
        }
    });
}
TEST_CASE_TEMPLATE_APPLY(spectral_emissive_absorber, SpectralEmission);

}  // namespace
