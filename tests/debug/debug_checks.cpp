// tests/debug/debug_checks.cpp: debug mode (NSP_DEBUG=1) on, the kernels' invariant checks hold on
// valid scenes: every estimator kind runs grey and spectral paths through them without a report.
// The sanitizer build (scripts/run-sanitizers.sh) turns the same checks on for the whole suite.
#include <cmath>

#include "common.hpp"

#if !NSP_DEBUG_ENABLED
#error "tests/debug/debug_checks.cpp is built with NSP_DEBUG=1"
#endif

namespace {

using namespace nsp_test;

static_assert(nsp::kDebugChecks);

TEST_CASE_TEMPLATE("debug mode: the invariant checks hold on valid scenes", S, Mono, Rgb) {
    using M = DenseGridMedium<S>;
    const Box box{Vec3(-1.f), Vec3(1.f)};
    std::vector<float> density(4 * 4 * 4);
    for (std::size_t i = 0; i < density.size(); ++i) density[i] = float(i % 7) / 6.f;  // incl. 0 and 1
    const M medium(box, {4, 4, 4}, density, nsp::constant_coefficient<S>(0.3f), nsp::constant_coefficient<S>(2.f));
    Lights<S> lights;
    lights.set(PointLight<S>{Vec3(0.f, 0.f, 1.5f), nsp::constant_coefficient<S>(5.f)});
    // A loose majorant (x4) so flights see many nulls; a tight one (x1) so some P_n are 0.
    for (const float loose : {1.f, 4.f}) {
        CAPTURE(loose);
        const Scene<M, GlobalMajorant<M>, HenyeyGreensteinPhase> scene(
            M(medium), GlobalMajorant<M>(medium, loose * medium.max_extinction()), HenyeyGreensteinPhase(0.5f),
            Lights<S>(lights));
        const Ray ray{Vec3(0.1f, -0.2f, -3.f), glm::normalize(Vec3(0.f, 0.05f, 1.f))};
        auto run = [&](const auto& estimator) {
            Pcg32 rng(7, 77);
            LookupCount lookups;
            int finite = 0;
            for (int i = 0; i < 500; ++i) finite += all_finite(estimator.radiance(scene, ray, {}, rng, lookups).value);
            CHECK(finite == 500);
        };
        run(PathEstimator<strategy::Unidirectional>{});
        run(PathEstimator<strategy::NextEvent>{});
        run(PathEstimator<strategy::NullScatteringMis, mis::Balance>{});
        run(PathEstimator<strategy::DirectionalMis, mis::Power>{});
        run(PathEstimator<strategy::EquiangularMis, mis::Balance>{});
        if constexpr (S::channels > 1) {
            run(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>{});
            run(SpectralPathEstimator<channels::Independent, strategy::EquiangularMis, mis::Balance>{});
        }
    }
}

}  // namespace
