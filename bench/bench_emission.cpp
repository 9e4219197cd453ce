// bench/bench_emission.cpp: what volume emission costs per sample (THEORY 5.7). The default cloud
// made emissive: an emission grid (16^3 over the cloud's box) that is non-zero in a ball of radius
// 0.5 below the centre, radiance scale 20, no other light. One benchmark per strategy x mode:
// BM_Emission/<strategy[:heuristic]>/<mode>: time per radiance() call (one sample) and density
// lookups per sample (NEE toward the volume counts its lookup at the emitting point). The
// collision estimator looks emission up at every tentative collision where mu_a > 0; NEE adds a
// power-grid sample, a shadow flight and two lookups per real vertex; the combining strategies also
// draw a point on every segment that crosses the power grid (the segment technique: a DDA over the
// power grid, a ratio-tracked flight, a lookup), measured against the same MIS without it
// (`:no-segments`) and at the segment count 1/4 (`:segment-count-1/4`). Which of them wins per unit
// of variance is the plume table's business (examples, README); the rows here separate the cost.
#include <string>

#include <benchmark/benchmark.h>

#include "fixtures.hpp"

namespace {

using namespace nsp_bench;

/// The emission strength of the ball: 1 at its centre, falling linearly to 0 at radius 0.5.
std::vector<float> ball_emission(int n) {
    std::vector<float> v(std::size_t(n) * n * n);
    std::size_t i = 0;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x, ++i) {
                const nsp::Vec3 p = (nsp::Vec3(float(x), float(y), float(z)) + 0.5f) / float(n) * 2.f - 1.f;
                v[i] = std::max(0.f, 1.f - glm::length(p - nsp::Vec3(0.f, -0.3f, 0.f)) / 0.5f);
            }
    return v;
}

template <nsp::SpectralMode S>
const auto& emissive_scene() {
    static const auto scene = [] {
        const nsp::Box box{nsp::Vec3(-1.f), nsp::Vec3(1.f)};
        nsp::Emissive<nsp::DenseGridMedium<S>> medium(nsp_examples::make_default_medium<S>(),
                                                      nsp::EmissionGrid(box, {16, 16, 16}, ball_emission(16)),
                                                      nsp::constant_coefficient<S>(20.f));
        return nsp::make_scene(std::move(medium), nsp::HenyeyGreensteinPhase(nsp_examples::kPhaseG), nsp::Lights<S>{});
    }();
    return scene;
}

template <nsp::PathStrategy St, nsp::mis::Heuristic H, nsp::SpectralMode S, bool kSegments = true,
          float kSegmentCount = 1.f>
void BM_Emission(benchmark::State& state) {
    const auto& scene = emissive_scene<S>();
    const std::vector<nsp::Ray>& rays = camera_rays();
    nsp::EstimatorOptions opts;
    opts.emission_along_segments = kSegments;
    opts.emission_segment_count = kSegmentCount;
    const nsp::PathEstimator<St, H> estimator(opts);
    nsp::Pcg32 rng(7, 77);
    nsp::LookupCount counter;
    std::size_t i = 0;
    for (auto _ : state) {
        const auto lambda = draw_wavelengths<S>(rng);
        auto r = estimator.radiance(scene, rays[i], lambda, rng, counter);
        benchmark::DoNotOptimize(r);
        i = (i + 1) & kSetMask;
    }
    report_lookups(state, counter, "lookups/sample");
}

template <nsp::PathStrategy St, nsp::mis::Heuristic H = nsp::mis::None>
void register_emission() {
    const std::string kind = H::combines ? std::string(St::name) + ":" + H::name : std::string(St::name);
    benchmark::RegisterBenchmark(("BM_Emission/" + kind + "/mono").c_str(), BM_Emission<St, H, nsp::Mono>)->MinTime(kMinTime);
    benchmark::RegisterBenchmark(("BM_Emission/" + kind + "/rgb").c_str(), BM_Emission<St, H, nsp::Rgb>)->MinTime(kMinTime);
}

const bool registered = [] {
    register_emission<nsp::strategy::Unidirectional>();
    register_emission<nsp::strategy::NextEvent>();
    register_emission<nsp::strategy::NullScatteringMis, nsp::mis::Balance>();
    // The same MIS without the segment technique: collisions and NEE toward the volume only.
    using NoSegments = nsp::strategy::NullScatteringMis;
    benchmark::RegisterBenchmark("BM_Emission/uni-nee-mis:balance:no-segments/mono",
                                 BM_Emission<NoSegments, nsp::mis::Balance, nsp::Mono, false>)->MinTime(kMinTime);
    benchmark::RegisterBenchmark("BM_Emission/uni-nee-mis:balance:no-segments/rgb",
                                 BM_Emission<NoSegments, nsp::mis::Balance, nsp::Rgb, false>)->MinTime(kMinTime);
    // The segment technique on a quarter of the segments (EstimatorOptions::emission_segment_count).
    benchmark::RegisterBenchmark("BM_Emission/uni-nee-mis:balance:segment-count-1/4/mono",
                                 BM_Emission<NoSegments, nsp::mis::Balance, nsp::Mono, true, 0.25f>)->MinTime(kMinTime);
    return true;
}();

}  // namespace
