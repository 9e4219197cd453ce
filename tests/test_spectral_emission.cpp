// tests/test_spectral_emission.cpp: volume emission over channels (THEORY 5.7 with 5.3):
// SpectralPathEstimator's collision estimator, NEE toward the emitting volume, the segment
// technique (a point drawn along each segment by the power grid) and their MIS are
// unbiased in every channel for every channel policy and majorant: a chromatic emissive furnace
// (L_e equal to the environment gives L_e, Rgb and Hero), with equiangular MIS aiming at a dark
// point light beside it, and a chromatic emitting absorber against quadrature.
//
// Statistical checks: fixed seeds (deterministic), k = 5 standard errors estimated from the
// samples, plus kRoundingFloor where every sample may equal the expected value.
#include <array>
#include <cmath>
#include <string>
#include <tuple>
#include <type_traits>
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
            if constexpr (E::Strategy::combines) {
                // Expected counts (THEORY 5.9): the segment technique on 30% of the segments, NEE
                // toward the lights at half the vertices; every channel's sum takes count x pdf.
                EstimatorOptions few = opts;
                few.emission_segment_count = 0.3f;
                few.nee_count = 0.5f;
                const auto r = estimate_error(E(few), scene, ray, 8000, std::uint64_t(seed + 100),
                                              [&](const auto& lambda) { return S::sample(le, lambda); });
                CHECK(r.not_ok == 0);
                for (int c = 0; c < S::channels; ++c) {
                    const Stat& s = r.stat.ch[std::size_t(c)];
                    CAPTURE(c);
                    MESSAGE(name << " " << std::string(S::name) << " " << std::string(maj_name)
                                 << ", segment count 0.3, NEE count 0.5: error " << s.mean << " (SE " << s.se() << ")");
                    CHECK(std::abs(s.mean) <= kSigmas * s.se() + kRoundingFloor);
                }
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
    // And with the segment technique on a fifth of the segments (an expected count, THEORY 5.9).
    EstimatorOptions few;
    few.emission_segment_count = 0.2f;
    const E est_few(few);
    // And never (count 0): the collision estimator alone on the camera ray.
    EstimatorOptions none;
    none.emission_segment_count = 0.f;
    const E est_none(none);
    for_each_majorant<typename E::Channels>(medium, [&](const auto& maj, const char* maj_name) {
        const auto scene = Scene(medium, maj, IsotropicPhase{}, Lights<Rgb>{});
        for (const E* e_ : {&est, &est_off, &est_few, &est_none}) {
            if (e_ != &est && !E::Strategy::combines) continue;
            const auto res = estimate_radiance(*e_, scene, ray, 20000, std::uint64_t(++seed));
            CHECK(res.not_ok == 0);
            for (int c = 0; c < 3; ++c) {
                const Stat& s = res.stat.ch[std::size_t(c)];
                CAPTURE(c);
                MESSAGE(name << " " << std::string(maj_name) << (e_ == &est_off ? " no segment technique" : e_ == &est_few ? " segment count 0.2" : "") << ": "
                             << s.mean << " (SE " << s.se() << "), quadrature " << ref[std::size_t(c)]);
                CHECK(std::abs(s.mean - ref[std::size_t(c)]) <= kSigmas * s.se() + kRoundingFloor);
            }
        }
    });
}
TEST_CASE_TEMPLATE_APPLY(spectral_emissive_absorber, SpectralEmission);

TEST_CASE_TEMPLATE_DEFINE("spectral emission: the segment count's variance predicted from a count-1 pilot is the one measured",
                          E, spectral_segment_learner) {
    // NeeCountLearner on SpectralPathEstimator (record_emission_channels, for the one-sample MIS
    // over channels and for one channel's pdfs): a chromatic emitting cloud without lights seen
    // from outside. The variance predicted at segment counts 1, 1/4 and 1/64 from 10 x 1000 pilot
    // samples at count 1 against 10 x 1000 samples run at each count: within 5 combined SE (from
    // the batches); the work per sample within 3 %.
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    std::vector<float> density(64), e(64);
    Pcg32 g(9, 3);
    for (float& v : density) v = 2.f * g.uniform();
    for (float& v : e) v = 2.f * g.uniform();
    const DenseGridMedium<Rgb> base(kBox, {4, 4, 4}, density, chroma<Rgb>(0.4f, 1.0f, 0.2f), chroma<Rgb>(0.6f, 0.3f, 1.2f));
    const Emissive<DenseGridMedium<Rgb>> medium(base, EmissionGrid(kBox, {4, 4, 4}, e), chroma<Rgb>(1.f, 0.6f, 0.3f),
                                                {8, 8, 8});
    using Maj = std::conditional_t<E::Channels::own_pdfs, ChannelMajorant<Emissive<DenseGridMedium<Rgb>>>,
                                   GlobalMajorant<Emissive<DenseGridMedium<Rgb>>>>;
    const auto scene = Scene(medium, Maj(medium), HenyeyGreensteinPhase(0.3f), Lights<Rgb>{});
    const Ray ray{Vec3(-3.f, 0.1f, 0.05f), Vec3(1.f, 0.f, 0.f)};
    constexpr int kBatches = 10, kSpp = 1000;
    NeeCountLearner all;
    std::array<Stat, NeeCountLearner::kCandidates> pred;
    const E pilot;
    for (int b = 0; b < kBatches; ++b) {
        NeeCountLearner batch;
        Pcg32 rng(31, std::uint64_t(b));
        for (int i = 0; i < kSpp; ++i) batch.end_sample(double(pilot.radiance(scene, ray, {}, rng, batch).value.mean()));
        batch.end_pixel();
        for (int j = 0; j < NeeCountLearner::kCandidates; ++j) pred[std::size_t(j)].add(batch.predicted_variance(0, j));
        all.merge(batch);
    }
    CHECK(all.segment_work() > 0.0);
    for (const int j : {0, 2, 6}) {
        EstimatorOptions o;
        o.emission_segment_count = NeeCountLearner::candidate(j);
        const E est(o);
        NeeCountLearner work;
        Stat meas;
        for (int b = 0; b < kBatches; ++b) {
            Pcg32 rng(32, std::uint64_t(b * 7 + j));
            Stat s;
            for (int i = 0; i < kSpp; ++i) {
                const double v = double(est.radiance(scene, ray, {}, rng, work).value.mean());
                s.add(v);
                work.end_sample(v);
            }
            meas.add(s.variance());
        }
        const Stat& p = pred[std::size_t(j)];
        CAPTURE(NeeCountLearner::candidate(j));
        CAPTURE(all.predicted_variance(0, j));
        CAPTURE(p.se());
        CAPTURE(meas.mean);
        CAPTURE(meas.se());
        MESSAGE(name << " segment count " << NeeCountLearner::candidate(j) << ": predicted "
                     << all.predicted_variance(0, j) << ", measured " << meas.mean << "; work "
                     << all.predicted_cost(0, j) << " / " << work.predicted_cost(0, 0));
        CHECK(meas.mean > 0.0);
        CHECK(std::abs(all.predicted_variance(0, j) - meas.mean) <= kSigmas * std::hypot(p.se(), meas.se()));
        CHECK(all.predicted_cost(0, j) == doctest::Approx(work.predicted_cost(0, 0)).epsilon(0.03));
    }
}
TEST_CASE_TEMPLATE_APPLY(spectral_segment_learner,
                         std::tuple<SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>,
                                    SpectralPathEstimator<channels::Independent, strategy::NullScatteringMis, mis::Balance>>);

}  // namespace
