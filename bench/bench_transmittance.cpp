// bench/bench_transmittance.cpp: one microbenchmark per transmittance estimator (THEORY 5.10,
// nsp/transmittance.hpp) on the same random rays through the default cloud (Mono): ratio
// tracking under the global and a 16^3 grid majorant, residual ratio tracking under a 16^3 grid
// control (and the loop on the tree majorant's cells without and with their minorants), unbiased ray marching under the global and the grid majorant. Each iteration is two
// independent estimates along the same ray (the next of the set): the time is per 2 estimates, the
// counters give lookups per estimate and the estimator's variance, the mean of (a - b)^2 / 2 over
// the pairs (unbiased, and free of the spread between rays), so time x variance per estimator
// comes from one run. The machine-independent comparison (lookups x variance) is
// nsp_transmittance's (docs/transmittance.md).
#include <cmath>

#include <benchmark/benchmark.h>

#include "fixtures.hpp"

namespace {

using namespace nsp_bench;
using M = nsp::DenseGridMedium<nsp::Mono>;

const M& cloud() { return default_scene<nsp::Mono>(LightSetup::A).medium(); }

/// Two estimates per iteration along tracking_rays() in turn, by `estimate(ray, rng, counter)`.
template <class F>
void run(benchmark::State& state, F&& estimate) {
    const auto& rays = tracking_rays();
    nsp::Pcg32 rng(3, 33);
    nsp::LookupCount counter;
    double sum = 0.0, half_sq = 0.0;
    std::size_t i = 0, failed = 0;
    for (auto _ : state) {
        const nsp::Ray& ray = rays[i++ & kSetMask];
        const auto a = estimate(ray, rng, counter);
        const auto b = estimate(ray, rng, counter);
        failed += (a.status != nsp::Status::Ok) + (b.status != nsp::Status::Ok);
        const double d = double(a.value[0]) - double(b.value[0]);
        sum += 0.5 * (double(a.value[0]) + double(b.value[0]));
        half_sq += 0.5 * d * d;
    }
    const double n = double(state.iterations());
    state.counters["lookups/estimate"] = double(counter.count()) / (2.0 * n);
    state.counters["steps/estimate"] = double(counter.steps) / (2.0 * n);
    state.counters["mean"] = sum / n;
    state.counters["variance"] = half_sq / n;
    if (failed > 0) state.SkipWithError("an estimate failed");
}

void BM_Ratio_Global(benchmark::State& state) {
    const nsp::GlobalMajorant<M> maj(cloud());
    run(state, [&](const nsp::Ray& r, nsp::Pcg32& rng, nsp::LookupCount& c) {
        return nsp::transmittance_ratio(cloud(), maj, r, kTmax, {}, rng, c);
    });
}
void BM_Ratio_Grid16(benchmark::State& state) {
    const nsp::GridMajorant<M> maj(cloud(), 16);
    run(state, [&](const nsp::Ray& r, nsp::Pcg32& rng, nsp::LookupCount& c) {
        return nsp::transmittance_ratio(cloud(), maj, r, kTmax, {}, rng, c);
    });
}
void BM_ResidualRatio_GridControl16(benchmark::State& state) {
    const nsp::GridControl<M> control(cloud(), 16);
    run(state, [&](const nsp::Ray& r, nsp::Pcg32& rng, nsp::LookupCount& c) {
        return nsp::transmittance_residual_ratio(cloud(), control, r, kTmax, {}, rng, c);
    });
}
void BM_RayMarching_Global(benchmark::State& state) {
    const nsp::GlobalMajorant<M> maj(cloud());
    run(state, [&](const nsp::Ray& r, nsp::Pcg32& rng, nsp::LookupCount& c) {
        return nsp::transmittance_ray_marching(cloud(), maj, r, kTmax, {}, rng, c);
    });
}
void BM_RayMarching_Grid16(benchmark::State& state) {
    const nsp::GridMajorant<M> maj(cloud(), 16);
    run(state, [&](const nsp::Ray& r, nsp::Pcg32& rng, nsp::LookupCount& c) {
        return nsp::transmittance_ray_marching(cloud(), maj, r, kTmax, {}, rng, c);
    });
}

// The free-flight loop under a control (THEORY 5.10) against the same loop under the grid majorant
// of the same cells: residual ratio tracking (transmittance_ratio under a GridControl) and
// decomposition tracking (transmittance_delta's passing weight), at 16^3 and 64^3. Their time per
// lookup and step gives the control's step cost that choose_majorant assumes.
template <int R>
void BM_Ratio_Grid(benchmark::State& state) {
    const nsp::GridMajorant<M> maj(cloud(), R);
    run(state, [&](const nsp::Ray& r, nsp::Pcg32& rng, nsp::LookupCount& c) {
        return nsp::transmittance_ratio(cloud(), maj, r, kTmax, {}, rng, c);
    });
}
template <int R>
void BM_Ratio_GridControl(benchmark::State& state) {
    const nsp::GridControl<M> control(cloud(), R);
    run(state, [&](const nsp::Ray& r, nsp::Pcg32& rng, nsp::LookupCount& c) {
        return nsp::transmittance_ratio(cloud(), control, r, kTmax, {}, rng, c);
    });
}
template <int R>
void BM_Delta_Grid(benchmark::State& state) {
    const nsp::GridMajorant<M> maj(cloud(), R);
    run(state, [&](const nsp::Ray& r, nsp::Pcg32& rng, nsp::LookupCount& c) {
        return nsp::transmittance_delta(cloud(), maj, r, kTmax, {}, rng, c);
    });
}
template <int R>
void BM_Delta_GridControl(benchmark::State& state) {
    const nsp::GridControl<M> control(cloud(), R);
    run(state, [&](const nsp::Ray& r, nsp::Pcg32& rng, nsp::LookupCount& c) {
        return nsp::transmittance_delta(cloud(), control, r, kTmax, {}, rng, c);
    });
}

// The same loop on the tree's cells (the adaptive layout), without and with their minorants.
template <class Maj, bool kRatio>
void BM_Tree(benchmark::State& state) {
    const Maj maj(cloud());
    run(state, [&](const nsp::Ray& r, nsp::Pcg32& rng, nsp::LookupCount& c) {
        if constexpr (kRatio) return nsp::transmittance_ratio(cloud(), maj, r, kTmax, {}, rng, c);
        else return nsp::transmittance_delta(cloud(), maj, r, kTmax, {}, rng, c);
    });
}
void BM_Ratio_Tree(benchmark::State& state) { BM_Tree<nsp::TreeMajorant<M>, true>(state); }
void BM_Ratio_TreeControl(benchmark::State& state) { BM_Tree<nsp::TreeControl<M>, true>(state); }
void BM_Delta_Tree(benchmark::State& state) { BM_Tree<nsp::TreeMajorant<M>, false>(state); }
void BM_Delta_TreeControl(benchmark::State& state) { BM_Tree<nsp::TreeControl<M>, false>(state); }

BENCHMARK(BM_Ratio_Global)->MinTime(kMinTime);
BENCHMARK(BM_Ratio_Grid16)->MinTime(kMinTime);
BENCHMARK(BM_ResidualRatio_GridControl16)->MinTime(kMinTime);
BENCHMARK(BM_RayMarching_Global)->MinTime(kMinTime);
BENCHMARK(BM_RayMarching_Grid16)->MinTime(kMinTime);

BENCHMARK(BM_Ratio_Grid<64>)->MinTime(kMinTime);
BENCHMARK(BM_Ratio_GridControl<16>)->MinTime(kMinTime);
BENCHMARK(BM_Ratio_GridControl<64>)->MinTime(kMinTime);
BENCHMARK(BM_Delta_Grid<16>)->MinTime(kMinTime);
BENCHMARK(BM_Delta_Grid<64>)->MinTime(kMinTime);
BENCHMARK(BM_Delta_GridControl<16>)->MinTime(kMinTime);
BENCHMARK(BM_Delta_GridControl<64>)->MinTime(kMinTime);
BENCHMARK(BM_Ratio_Tree)->MinTime(kMinTime);
BENCHMARK(BM_Ratio_TreeControl)->MinTime(kMinTime);
BENCHMARK(BM_Delta_Tree)->MinTime(kMinTime);
BENCHMARK(BM_Delta_TreeControl)->MinTime(kMinTime);

}  // namespace
