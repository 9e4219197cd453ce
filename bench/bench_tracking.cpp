// bench/bench_tracking.cpp: raw trilinear density lookups on the default cloud grid, and the
// free-flight loop (delta and ratio tracking) on the same grid, both in lookups per second.
//
// The target: tracking runs at >= 70% of the raw lookup rate. Both sides call
// DenseGridMedium::coefficients (density + per-channel scaling) on the same grid; the raw side
// reads its points from a pre-generated set, so it times the lookup alone, while the tracking
// side pays for everything else a lookup costs there (random numbers, the exponential step, the
// collision policy). The raw rate is measured on two point sets (fixtures.hpp):
//   tracked: the very points ratio tracking visits along random rays, in its order (the same
//            cache behaviour as tracking: the fair denominator);
//   uniform: random points in the box in random order (no spatial coherence, more L2/L3 misses).
// Two diagnostics explain the ratio: chained raw lookups (latency, no overlap) and tracking
// through a homogeneous medium (the loop's own cost). bench/report.py prints the ratios.
//
// Grid majorants: delta and ratio tracking on the same cloud and rays under a GridMajorant of 8,
// 16 and 64 cells per axis (Mono): the DDA loop's lookup rate next to the raw rate and the
// global majorant's (bench/report.py, majorant column); steps/call counts the cells the DDA
// crossed per tracked ray.
//
// Every tracker also runs in Hero<4> on the same grey cloud (coefficients tabulated over
// wavelength, four wavelengths drawn per tracked ray): with Mono and Rgb, what each spectral mode
// costs on a medium that does not need it (bench/RESULTS.md, "cost of each spectral mode").
#include <type_traits>
#include <vector>

#include <benchmark/benchmark.h>

#include "fixtures.hpp"

namespace {

using namespace nsp_bench;
using nsp::LookupCount;
using nsp::Mono;
using nsp::NoLookupCount;
using nsp::Rgb;

/// Point sets for the raw-lookup benchmark.
struct UniformPoints {
    static const std::vector<nsp::Vec3>& get() { return uniform_points(); }
};
struct TrackedPoints {
    static const std::vector<nsp::Vec3>& get() { return tracked_points(); }
};

/// The wavelengths of the raw-lookup benchmarks: one fixed draw in Hero mode, empty otherwise.
template <nsp::SpectralMode S>
typename S::Wavelengths lookup_wavelengths() {
    nsp::Pcg32 rng(7, 77);
    return draw_wavelengths<S>(rng);
}

/// kSetSize lookups per iteration, one per point of the set; the coefficients are summed so
/// the compiler cannot drop a lookup, and the sum is consumed once at the end. The lookups are
/// independent, so the CPU overlaps several: this is the lookup's throughput.
template <nsp::SpectralMode S, class Points>
void BM_RawLookup(benchmark::State& state) {
    const auto& medium = default_scene<S>(LightSetup::A).medium();
    const std::vector<nsp::Vec3>& pts = Points::get();
    const typename S::Wavelengths lambda = lookup_wavelengths<S>();
    typename S::Spectrum acc = S::Spectrum::Zero();
    for (auto _ : state) {
        for (const nsp::Vec3& p : pts) {
            const auto c = medium.coefficients(p, lambda);
            acc += c.sigma_a + c.sigma_s;
        }
        benchmark::ClobberMemory();
    }
    benchmark::DoNotOptimize(acc);
    const double lookups = double(state.iterations()) * double(pts.size());
    state.counters["lookups/s"] = benchmark::Counter(lookups, benchmark::Counter::kIsRate);
}

/// A diagnostic, not the target's denominator: the same lookups made one after another (each
/// point is offset by 0 x the previous result), so none overlap: the lookup's latency.
template <nsp::SpectralMode S>
void BM_RawLookupChained(benchmark::State& state) {
    const auto& medium = default_scene<S>(LightSetup::A).medium();
    const std::vector<nsp::Vec3>& pts = tracked_points();
    const typename S::Wavelengths lambda = lookup_wavelengths<S>();
    float prev = 0.f;
    for (auto _ : state) {
        for (const nsp::Vec3& p : pts) {
            const auto c = medium.coefficients(p + nsp::Vec3(0.f * prev), lambda);
            prev = c.sigma_s[0];
        }
    }
    benchmark::DoNotOptimize(prev);
    const double lookups = double(state.iterations()) * double(pts.size());
    state.counters["lookups/s"] = benchmark::Counter(lookups, benchmark::Counter::kIsRate);
}

BENCHMARK_TEMPLATE(BM_RawLookup, Mono, UniformPoints)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_RawLookup, Mono, TrackedPoints)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_RawLookup, Rgb, UniformPoints)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_RawLookup, Rgb, TrackedPoints)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_RawLookupChained, Mono)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_RawLookupChained, Rgb)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_RawLookup, Hero4, UniformPoints)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_RawLookup, Hero4, TrackedPoints)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_RawLookupChained, Hero4)->MinTime(kMinTime);

/// Trackers: one call tracks one ray over [0, kTmax] through the medium's box at wavelengths l.
template <nsp::AbsorptionPolicy A>
struct Delta {
    template <class M, class Maj, class L, class R, class C>
    static auto run(const M& m, const Maj& maj, const nsp::Ray& ray, const L& l, R& rng, C& counter) {
        return nsp::track_delta<A>(m, maj, ray, kTmax, l, rng, counter);
    }
};
template <nsp::AbsorptionPolicy A, bool kNullRatio>
struct Ratio {
    template <class M, class Maj, class L, class R, class C>
    static auto run(const M& m, const Maj& maj, const nsp::Ray& ray, const L& l, R& rng, C& counter) {
        return nsp::track_ratio<A, kNullRatio>(m, maj, ray, kTmax, l, rng, counter);
    }
};
using DeltaEvent = Delta<nsp::absorption::Event>;
using DeltaWeight = Delta<nsp::absorption::Weight>;
using RatioPlain = Ratio<nsp::absorption::Event, false>;  // A is unused without null pdfs
using RatioNullEvent = Ratio<nsp::absorption::Event, true>;
using RatioNullWeight = Ratio<nsp::absorption::Weight, true>;

/// Media to track through: the default cloud with its global majorant, or (a diagnostic) a
/// homogeneous medium in the same box under the same majorant value, whose "lookup" is a box
/// test: what remains is the cost of the loop itself per tentative collision.
struct Cloud {
    template <nsp::SpectralMode S>
    static const auto& medium() { return default_scene<S>(LightSetup::A).medium(); }
    template <nsp::SpectralMode S>
    static const auto& majorant() { return default_scene<S>(LightSetup::A).majorant(); }
};
struct Trivial {
    template <nsp::SpectralMode S>
    static const auto& medium() {
        // mu_t = 1 under a majorant of 20: ratio tracking never terminates, as in thin cloud.
        static const nsp::HomogeneousMedium<S> m(Cloud::medium<S>().bounds(), S::Spectrum::Constant(0.1f),
                                                 S::Spectrum::Constant(0.9f));
        return m;
    }
    template <nsp::SpectralMode S>
    static const auto& majorant() {
        static const nsp::GlobalMajorant<nsp::HomogeneousMedium<S>> maj(medium<S>(),
                                                                         Cloud::majorant<S>().value());
        return maj;
    }
};

/// The default cloud (Mono) under a GridMajorant of R cells per axis, built once.
template <int R>
struct CloudGrid {
    template <nsp::SpectralMode S>
    static const auto& medium() { return Cloud::medium<S>(); }
    template <nsp::SpectralMode S>
    static const auto& majorant() {
        static const nsp::GridMajorant<std::remove_cvref_t<decltype(medium<S>())>> maj(medium<S>(), R);
        return maj;
    }
};
using CloudGrid8 = CloudGrid<8>;
using CloudGrid16 = CloudGrid<16>;
using CloudGrid64 = CloudGrid<64>;

/// One tracked ray per iteration, cycling through tracking_rays(); the generator runs on across
/// iterations, so every pass over the set draws new collisions. Hero mode draws each ray's
/// wavelengths from the same generator.
template <class Tracker, nsp::SpectralMode S, class Media = Cloud, nsp::LookupCounter C = LookupCount>
void BM_Track(benchmark::State& state) {
    const auto& medium = Media::template medium<S>();
    const auto& majorant = Media::template majorant<S>();
    const std::vector<nsp::Ray>& rays = tracking_rays();
    nsp::Pcg32 rng(5, 55);
    C counter;
    std::size_t i = 0;
    for (auto _ : state) {
        const auto lambda = draw_wavelengths<S>(rng);
        auto r = Tracker::run(medium, majorant, rays[i], lambda, rng, counter);
        benchmark::DoNotOptimize(r);
        i = (i + 1) & kSetMask;
    }
    report_lookups(state, counter, "lookups/call");
    if constexpr (requires { counter.steps; })
        if (counter.steps > 0)
            state.counters["steps/call"] = benchmark::Counter(double(counter.steps), benchmark::Counter::kAvgIterations);
}

BENCHMARK_TEMPLATE(BM_Track, DeltaEvent, Mono)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, DeltaWeight, Mono)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioPlain, Mono)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioNullEvent, Mono)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioNullWeight, Mono)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, DeltaEvent, Rgb)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, DeltaWeight, Rgb)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioPlain, Rgb)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioNullEvent, Rgb)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioNullWeight, Rgb)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, DeltaEvent, Hero4)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, DeltaWeight, Hero4)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioPlain, Hero4)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioNullEvent, Hero4)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioNullWeight, Hero4)->MinTime(kMinTime);

// The DDA loop: the same cloud and rays under grid majorants (Mono).
BENCHMARK_TEMPLATE(BM_Track, DeltaWeight, Mono, CloudGrid8)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, DeltaWeight, Mono, CloudGrid16)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, DeltaWeight, Mono, CloudGrid64)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioPlain, Mono, CloudGrid8)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioPlain, Mono, CloudGrid16)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioPlain, Mono, CloudGrid64)->MinTime(kMinTime);

// Diagnostic: the loop's own cost, on the trivial medium.
BENCHMARK_TEMPLATE(BM_Track, DeltaWeight, Mono, Trivial)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioPlain, Mono, Trivial)->MinTime(kMinTime);

// The cost of counting: the same trackers without a counter (compare time per call).
BENCHMARK_TEMPLATE(BM_Track, DeltaEvent, Mono, Cloud, NoLookupCount)->MinTime(kMinTime);
BENCHMARK_TEMPLATE(BM_Track, RatioPlain, Mono, Cloud, NoLookupCount)->MinTime(kMinTime);

}  // namespace
