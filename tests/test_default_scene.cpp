// tests/test_default_scene.cpp: every estimator agrees on the mean radiance of the default scene
// (examples/default_scene.hpp, light set-ups A and B, Mono) over a fixed 16 x 16 grid of camera
// rays. The estimators differ wildly in variance (the paper's point, THEORY 7), not in mean.
#include <string>
#include <tuple>
#include <vector>

#include "common.hpp"
#include "default_scene.hpp"

namespace {

using namespace nsp_test;
using nsp_examples::LightSetup;

// k = 5 combined standard errors for each pair of independent runs.
constexpr double kSigmas = 5.0;
constexpr int kPixels = 16;

struct Result {
    std::string name;
    Stat stat;  ///< one sample = the mean radiance of one pass over the 16 x 16 pixels
};

/// Mean image radiance of `passes` independent passes over the pixel grid, one path per pixel
/// and pass. Each pass is one sample of the image mean, so the SE needs no stratification care.
template <class E, class Sc>
Result image_mean(const Sc& scene, int passes, std::uint64_t stream) {
    const E est;
    Result r{estimator_name<E>(), {}};
    Pcg32 rng(2019, stream);
    NoLookupCount none;
    int not_ok = 0;
    for (int p = 0; p < passes; ++p) {
        double sum = 0.0;
        for (int y = 0; y < kPixels; ++y)
            for (int x = 0; x < kPixels; ++x) {
                const Ray ray = nsp_examples::camera_ray((float(x) + 0.5f) / kPixels, (float(y) + 0.5f) / kPixels, 1.f);
                const auto l = est.radiance(scene, ray, Mono::Wavelengths{}, rng, none);
                not_ok += l.status != Status::Ok;
                sum += double(l.value[0]);
            }
        r.stat.add(sum / (kPixels * kPixels));
    }
    CHECK(not_ok == 0);
    return r;
}

/// Runs every estimator of the type list `Estimators` on `scene` and checks that each pair of
/// means agrees within kSigmas combined standard errors.
template <class Estimators, class Sc>
void check_agreement(const Sc& scene, int passes, const std::string& setup_name) {
    std::vector<Result> results;
    std::uint64_t stream = 1;  // independent random streams, so the SEs of a pair combine
    std::apply([&](auto... est) { (results.push_back(image_mean<decltype(est)>(scene, passes, stream++)), ...); },
               Estimators{});
    for (const Result& r : results) {
        MESSAGE("set-up " << setup_name << ": " << r.name << " mean " << r.stat.mean << ", SE " << r.stat.se());
        CHECK(r.stat.mean > 0.0);
    }
    for (std::size_t i = 0; i < results.size(); ++i)
        for (std::size_t j = i + 1; j < results.size(); ++j) {
            const Stat &a = results[i].stat, &b = results[j].stat;
            CAPTURE(setup_name);
            CAPTURE(results[i].name);
            CAPTURE(results[j].name);
            CAPTURE(a.mean);
            CAPTURE(b.mean);
            const double se = std::sqrt(a.se() * a.se() + b.se() * b.se());
            CAPTURE(se);
            CHECK(std::abs(a.mean - b.mean) <= kSigmas * se);
        }
}

/// The estimators that sample lights (all but Unidirectional), with both absorption policies.
template <AbsorptionPolicy A>
using LightSamplingWith = std::tuple<PathEstimator<strategy::NextEvent, mis::None, A>,
                                     PathEstimator<strategy::DirectionalMis, mis::Balance, A>,
                                     PathEstimator<strategy::DirectionalMis, mis::Power, A>,
                                     PathEstimator<strategy::NullScatteringMis, mis::Balance, A>,
                                     PathEstimator<strategy::NullScatteringMis, mis::Power, A>>;
using LightSampling = decltype(std::tuple_cat(LightSamplingWith<absorption::Event>{},
                                              LightSamplingWith<absorption::Weight>{}));

TEST_CASE("default scene, set-up A (small bright light): all light-sampling estimators agree") {
    // 2048 passes: NEE contributions from vertices near the light are heavy-tailed (up to ~1e3 x
    // the mean), so the SE needs many samples to be trustworthy; relative SE ~8 %.
    // Unidirectional is left out here: it reaches the small light A (radius 0.1) a handful of
    // times in 2048 passes (the renderer measures ~50 hits in 8.4M samples over the whole image),
    // so its mean is not normal and a k-SE test is
    // meaningless (it would need ~1e5 passes; the paper's LTUV for it is 10.3 B). Set-up B below
    // tests it sharply.
    check_agreement<LightSampling>(nsp_examples::make_default_scene<Mono>(LightSetup::A), 2048, "A");
}

TEST_CASE("default scene, set-up B (large dim light): every estimator agrees") {
    // 512 passes: relative SE 5e-4 (1.6e-3 for ratio NEE), so a 0.3 % bias in any estimator fails.
    check_agreement<AllEstimators>(nsp_examples::make_default_scene<Mono>(LightSetup::B), 512, "B");
}

/// The equiangular strategies (their target: the sphere light's centre) beside uni + NEE MIS.
using EquiangularAndReference =
    std::tuple<PathEstimator<strategy::NullScatteringMis, mis::Balance, absorption::Weight>,
               PathEstimator<strategy::EquiangularNextEvent, mis::None, absorption::Weight>,
               PathEstimator<strategy::EquiangularNextEvent, mis::None, absorption::Event>,
               PathEstimator<strategy::EquiangularMis, mis::Balance, absorption::Weight>,
               PathEstimator<strategy::EquiangularMis, mis::Power, absorption::Event>>;

TEST_CASE("default scene, set-ups A and B: the equiangular strategies agree with uni + NEE MIS") {
    // Passes as above for B; 1024 for A (relative SE about 10 %, heavy-tailed NEE near the light).
    check_agreement<EquiangularAndReference>(nsp_examples::make_default_scene<Mono>(LightSetup::A), 1024, "A");
    check_agreement<EquiangularAndReference>(nsp_examples::make_default_scene<Mono>(LightSetup::B), 512, "B");
}

/// The fog scene's strategies: NEE from tracked vertices, uni + NEE MIS, and the equiangular ones.
using FogEstimators = std::tuple<PathEstimator<strategy::NextEvent, mis::None, absorption::Weight>,
                                 PathEstimator<strategy::NullScatteringMis, mis::Balance, absorption::Weight>,
                                 PathEstimator<strategy::EquiangularNextEvent, mis::None, absorption::Weight>,
                                 PathEstimator<strategy::EquiangularNextEvent, mis::None, absorption::Event>,
                                 PathEstimator<strategy::EquiangularMis, mis::Balance, absorption::Weight>,
                                 PathEstimator<strategy::EquiangularMis, mis::Power, absorption::Event>>;

TEST_CASE("fog scene (a lamp in, beside and behind dense fog): the equiangular strategies agree with NEE") {
    using nsp_examples::FogSetup;
    // 256 passes: relative SE 1-6 % for NEE from tracked vertices, 1-2 % for the equiangular ones.
    for (const FogSetup s : {FogSetup::F1, FogSetup::F2, FogSetup::F3}) {
        const auto scene = make_scene(nsp_examples::make_fog_medium<Mono>(s),
                                      HenyeyGreensteinPhase(nsp_examples::kFogPhaseG), nsp_examples::fog_lights<Mono>(s));
        check_agreement<FogEstimators>(scene, 256, nsp_examples::name(s));
    }
}

/// The plume scene's strategies: collision-only emission (unidirectional), NEE toward the flame,
/// and their MIS.
using PlumeEstimators = std::tuple<PathEstimator<strategy::Unidirectional, mis::None, absorption::Weight>,
                                   PathEstimator<strategy::NextEvent, mis::None, absorption::Weight>,
                                   PathEstimator<strategy::NullScatteringMis, mis::Balance, absorption::Weight>,
                                   PathEstimator<strategy::NullScatteringMis, mis::Power, absorption::Event>>;

TEST_CASE("plume scene (a flame inside smoke): emission NEE and MIS agree with the collision estimator") {
    // 2048 passes: the flame covers a few of the 16 x 16 pixels, so the collision estimator's
    // relative SE is still ~15 % (NEE's ~3 %); the sharp unbiasedness tests of emission are the
    // furnace and quadrature cases of test_emission_estimators.cpp. This one ties them to the scene.
    const auto scene = make_scene(nsp_examples::make_plume_medium<Mono>(),
                                  HenyeyGreensteinPhase(nsp_examples::kPlumePhaseG), Lights<Mono>{});
    check_agreement<PlumeEstimators>(scene, 2048, "P1");
}

}  // namespace
