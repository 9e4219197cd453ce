// bench/bench_volume.cpp: majorants over a volume from a file, the sparse smoke plume as a
// NanoVDB grid (examples/volume_files.hpp, 256^3, made at start-up), extinction 100 per unit
// density, albedo 0.9, Mono. Per majorant (global, grid 16^3 and 64^3, the tree on the VDB nodes,
// the adaptive tree):
//   BM_VolumeWalk/<majorant>           the majorant's segments along a ray, nothing tracked:
//                                      what the walk itself costs (steps/ray, segments/ray)
//   BM_VolumeRatio/<majorant>          ratio-tracked transmittance along the ray (lookups/ray)
//   BM_VolumePath/<majorant>           one uni + NEE MIS path sample (PathEstimator, balance)
//                                      under nsp_volume's lights: a dim sky and a sphere light
// on kSetSize rays from nsp_volume's camera that meet the plume's density (a 512-step march), the
// same rays and seeds in every row, so rows differ only in the majorant. Time x variance lives in
// nsp_volume --compare-majorants (docs/volumes.md); this binary times the parts.
// BM_VolumeBuild/<majorant> times building each majorant and reports its memory.
// Run: build/bench/nsp_bench_volume --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "fixtures.hpp"
#include "volume_files.hpp"

namespace {

using namespace nsp_bench;
using NM = nsp::io::NanoVdbMedium<nsp::Mono>;

const NM& plume() {
    static const NM m(std::make_shared<const nsp::io::NanoDensityGrid>(nsp_examples::plume_nanovdb(256), "plume"),
                      nsp::Mono::Spectrum::Constant(10.f), nsp::Mono::Spectrum::Constant(90.f));
    return m;
}

/// nsp_volume's camera and lights around the plume's bounds.
const nsp_examples::VolumeFraming<NM>& framing() {
    static const nsp_examples::VolumeFraming<NM> f(plume());
    return f;
}

/// kSetSize camera rays that meet density >= 0.02 somewhere along their chord of the bounds.
const std::vector<nsp::Ray>& plume_rays() {
    static const std::vector<nsp::Ray> rays = [] {
        nsp::Pcg32 rng(5, 55);
        std::vector<nsp::Ray> out;
        out.reserve(kSetSize);
        while (out.size() < kSetSize) {
            const nsp::Ray ray = framing()(rng.uniform(), rng.uniform());
            const nsp::Interval in = plume().bounds().clip(ray, 0.f, kTmax);
            bool hits = false;
            for (int k = 0; k < 512 && !in.empty() && !hits; ++k)
                hits = plume().density(ray.at(in.t0 + (float(k) + 0.5f) / 512.f * (in.t1 - in.t0))) >= 0.02f;
            if (hits) out.push_back(ray);
        }
        return out;
    }();
    return rays;
}

const nsp::GlobalMajorant<NM>& global() {
    static const nsp::GlobalMajorant<NM> m(plume());
    return m;
}
template <int R>
const nsp::GridMajorant<NM>& grid() {
    static const nsp::GridMajorant<NM> m(plume(), R);
    return m;
}
const nsp::TreeMajorant<NM>& tree() {
    static const nsp::TreeMajorant<NM> m(plume());
    return m;
}
const nsp::TreeMajorant<NM>& tree_nodes() {
    static const nsp::TreeMajorant<NM> m(plume(), plume().tree_layout());
    return m;
}

template <class Get>
void BM_VolumeWalk(benchmark::State& state, Get get) {
    const auto& maj = *get();
    const std::vector<nsp::Ray>& rays = plume_rays();
    std::size_t i = 0;
    double segments = 0.0, steps = 0.0;
    for (auto _ : state) {
        auto it = maj.iterate(rays[i], 0.f, kTmax, {});
        float tau = 0.f;
        while (auto s = it.next()) {
            tau += (s->t1 - s->t0) * s->sigma_maj;
            segments += 1.0;
        }
        if constexpr (requires { it.steps(); }) steps += double(it.steps());
        benchmark::DoNotOptimize(tau);
        i = (i + 1) & kSetMask;
    }
    state.counters["segments/ray"] = benchmark::Counter(segments, benchmark::Counter::kAvgIterations);
    state.counters["steps/ray"] = benchmark::Counter(steps, benchmark::Counter::kAvgIterations);
}

template <class Get>
void BM_VolumeRatio(benchmark::State& state, Get get) {
    const auto& maj = *get();
    const std::vector<nsp::Ray>& rays = plume_rays();
    nsp::Pcg32 rng(7, 77);
    nsp::LookupCount counter;
    std::size_t i = 0;
    for (auto _ : state) {
        auto t = nsp::track_ratio<nsp::absorption::Weight, false>(plume(), maj, rays[i], kTmax, {}, rng, counter);
        benchmark::DoNotOptimize(t);
        i = (i + 1) & kSetMask;
    }
    report_lookups(state, counter, "lookups/ray");
    state.counters["steps/ray"] = benchmark::Counter(double(counter.steps), benchmark::Counter::kAvgIterations);
}

template <class Get>
void BM_VolumePath(benchmark::State& state, Get get) {
    const auto& maj = *get();
    const auto scene = nsp::Scene(plume(), maj, nsp::HenyeyGreensteinPhase(0.5f), framing().lights);
    const nsp::PathEstimator<nsp::strategy::NullScatteringMis, nsp::mis::Balance> est;
    const std::vector<nsp::Ray>& rays = plume_rays();
    nsp::Pcg32 rng(9, 99);
    nsp::LookupCount counter;
    std::size_t i = 0;
    for (auto _ : state) {
        auto r = est.radiance(scene, rays[i], {}, rng, counter);
        benchmark::DoNotOptimize(r);
        i = (i + 1) & kSetMask;
    }
    report_lookups(state, counter, "lookups/sample");
    state.counters["steps/sample"] = benchmark::Counter(double(counter.steps), benchmark::Counter::kAvgIterations);
}

template <class Make>
void BM_VolumeBuild(benchmark::State& state, Make make) {
    std::size_t bytes = 0;
    for (auto _ : state) {
        auto m = make();
        bytes = m.memory_bytes();
        benchmark::DoNotOptimize(bytes);
    }
    state.counters["KiB"] = double(bytes) / 1024.0;
}

template <class Get>
void register_all(const std::string& name, Get get) {
    benchmark::RegisterBenchmark(("BM_VolumeWalk/" + name).c_str(), [get](benchmark::State& s) { BM_VolumeWalk(s, get); })
        ->MinTime(kMinTime);
    benchmark::RegisterBenchmark(("BM_VolumeRatio/" + name).c_str(), [get](benchmark::State& s) { BM_VolumeRatio(s, get); })
        ->MinTime(kMinTime);
    benchmark::RegisterBenchmark(("BM_VolumePath/" + name).c_str(), [get](benchmark::State& s) { BM_VolumePath(s, get); })
        ->MinTime(kMinTime);
}

const bool registered = [] {
    register_all("global", [] { return &global(); });
    register_all("grid16", [] { return &grid<16>(); });
    register_all("grid64", [] { return &grid<64>(); });
    register_all("tree-nodes", [] { return &tree_nodes(); });
    register_all("tree", [] { return &tree(); });
    benchmark::RegisterBenchmark("BM_VolumeBuild/grid16", [](benchmark::State& s) {
        BM_VolumeBuild(s, [] { return nsp::GridMajorant<NM>(plume(), 16); });
    });
    benchmark::RegisterBenchmark("BM_VolumeBuild/grid64", [](benchmark::State& s) {
        BM_VolumeBuild(s, [] { return nsp::GridMajorant<NM>(plume(), 64); });
    });
    benchmark::RegisterBenchmark("BM_VolumeBuild/tree", [](benchmark::State& s) {
        BM_VolumeBuild(s, [] { return nsp::TreeMajorant<NM>(plume()); });
    });
    return true;
}();

}  // namespace
