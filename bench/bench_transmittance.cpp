// bench/bench_transmittance.cpp: one microbenchmark per transmittance estimator (THEORY 5.10,
// nsp/transmittance.hpp) on the same random rays through the default cloud (Mono): ratio
// tracking under the global and a 16^3 grid majorant, residual ratio tracking under a 16^3 grid
// control (and the loop on the tree majorant's cells without and with their minorants), unbiased
// ray marching under the global and the grid majorant, and per channel on the chromatic cloud the
// channel trackers under a per-channel grid majorant and control. Each iteration is two
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

// Per channel (THEORY 5.10 with 5.3): the chromatic cloud (extinction 1 : 4 : 16), each channel's
// own ratio tracking under a per-channel grid majorant of 16^3 against its own residual ratio
// tracking under the per-channel grid control of the same cells (track_channels_ratio, the
// spectral estimators' shadow rays). Sampling channels in turn; the estimate is the sampling
// channel's f_c / nee_c, its transmittance. The same on an exponential medium over the cloud's box
// (every cell with a floor), where the control pays.
using MRgb = nsp::DenseGridMedium<nsp::Rgb>;
const MRgb& chromatic_cloud() {
    static const MRgb m = nsp_examples::make_chromatic_medium<nsp::Rgb>();
    return m;
}
/// Where every cell has a floor: an exponential medium over the cloud's box, density 1 at its
/// centre falling e^2 along a diagonal, the cloud's 1 : 4 : 16 channels.
using MExp = nsp::ExponentialMedium<nsp::Rgb>;
const MExp& chromatic_exponential() {
    static const MExp m = [] {
        const nsp::Box b = chromatic_cloud().bounds();
        const nsp::Vec3 axis = glm::normalize(b.hi - b.lo);
        const float k = 2.f / glm::length(b.hi - b.lo);
        const float d0 = std::exp(-k * glm::dot(0.5f * (b.hi + b.lo) - b.lo, axis));
        return MExp(b, axis, d0, k, nsp::Rgb::Coefficient(0.05f, 0.2f, 0.8f), nsp::Rgb::Coefficient(0.2f, 0.8f, 3.2f));
    }();
    return m;
}
template <class Maj, class Med>
void BM_Channels(benchmark::State& state, const Med& medium) {
    const Maj maj(medium, 16);
    const auto& rays = tracking_rays();
    nsp::Pcg32 rng(3, 33);
    nsp::LookupCount counter;
    double half_sq = 0.0;
    std::size_t i = 0;
    for (auto _ : state) {
        const int c = int(i % 3);
        const nsp::Ray& ray = rays[i++ & kSetMask];
        double t[2];
        for (double& x : t) {
            const auto sh = nsp::track_channels_ratio<nsp::channels::SpectralMis, nsp::absorption::Weight>(
                medium, maj, ray, kTmax, {}, c, nsp::Rgb::Spectrum::Ones().eval(), true, rng, counter);
            x = sh.nee[c] > 0.f ? double(sh.f[c]) / double(sh.nee[c]) : 0.0;
        }
        half_sq += 0.5 * (t[0] - t[1]) * (t[0] - t[1]);
    }
    const double n = double(state.iterations());
    state.counters["lookups/estimate"] = double(counter.count()) / (2.0 * n);
    state.counters["variance"] = half_sq / n;
}
void BM_ChannelRatio_ChannelGrid16(benchmark::State& state) {
    BM_Channels<nsp::ChannelGridMajorant<MRgb>>(state, chromatic_cloud());
}
void BM_ChannelResidualRatio_ChannelGridControl16(benchmark::State& state) {
    BM_Channels<nsp::ChannelGridControl<MRgb>>(state, chromatic_cloud());
}
void BM_ChannelRatio_ChannelGrid16_Exponential(benchmark::State& state) {
    BM_Channels<nsp::ChannelGridMajorant<MExp>>(state, chromatic_exponential());
}
void BM_ChannelResidualRatio_ChannelGridControl16_Exponential(benchmark::State& state) {
    BM_Channels<nsp::ChannelGridControl<MExp>>(state, chromatic_exponential());
}

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
BENCHMARK(BM_ChannelRatio_ChannelGrid16)->MinTime(kMinTime);
BENCHMARK(BM_ChannelResidualRatio_ChannelGridControl16)->MinTime(kMinTime);
BENCHMARK(BM_ChannelRatio_ChannelGrid16_Exponential)->MinTime(kMinTime);
BENCHMARK(BM_ChannelResidualRatio_ChannelGridControl16_Exponential)->MinTime(kMinTime);

}  // namespace
