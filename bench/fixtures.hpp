// bench/fixtures.hpp: the data every nsp benchmark shares, built once, outside the timed loops:
// the default cloud scene (examples/default_scene.hpp), pre-generated point and ray sets, and the
// per-sample wavelength draw of the hero mode.
#pragma once

#include <cstddef>
#include <vector>

#include <benchmark/benchmark.h>
#include <default_scene.hpp>
#include <nsp/nsp.hpp>

namespace nsp_bench {

using nsp_examples::LightSetup;

/// Size of every pre-generated point or ray set (a power of two; sets are cycled with a mask).
/// 16 Ki points take 192 KiB, small beside the 1 MiB grid: a benchmark measures the grid, not a
/// stream of input from DRAM.
inline constexpr std::size_t kSetSize = std::size_t(1) << 14;
inline constexpr std::size_t kSetMask = kSetSize - 1;

/// Minimum time of one repetition of one benchmark, in seconds: with 5 repetitions the main run
/// of bench/run.sh took about three and a half minutes on 2 cores with 148 benchmarks; issue 7's
/// equiangular and emission rows make it 184 (about a minute more).
inline constexpr double kMinTime = 0.2;

/// Far end of every tracked segment: past the cloud's box from any ray origin used here.
inline constexpr float kTmax = 100.f;

/// The default scene of set-up A or B in spectral mode S (one instance of each per process).
template <nsp::SpectralMode S>
const auto& default_scene(LightSetup setup) {
    static const auto a = nsp_examples::make_default_scene<S>(LightSetup::A);
    static const auto b = nsp_examples::make_default_scene<S>(LightSetup::B);
    return setup == LightSetup::A ? a : b;
}

/// Hero<4>, under a name without a comma (BENCHMARK_TEMPLATE arguments, benchmark names).
using Hero4 = nsp::Hero<4>;

/// The wavelength context of one sample: in Hero mode drawn from the benchmark's own generator
/// (one uniform number per sample, part of the timed work, as in a renderer); empty and free in
/// Mono and Rgb, which then consume exactly the random numbers they did before Hero existed.
template <nsp::SpectralMode S, nsp::UniformRng R>
typename S::Wavelengths draw_wavelengths(R& rng) {
    if constexpr (nsp::is_hero_v<S>) return S::Wavelengths::sample(rng.uniform());
    else return {};
}

/// A point drawn uniformly in the box.
inline nsp::Vec3 uniform_in(const nsp::Box& b, nsp::Pcg32& rng) {
    const float x = rng.uniform(), y = rng.uniform(), z = rng.uniform();
    return b.lo + nsp::Vec3(x, y, z) * (b.hi - b.lo);
}

/// kSetSize points uniform in the cloud's box, in random order (every lookup a random voxel).
inline const std::vector<nsp::Vec3>& uniform_points() {
    static const std::vector<nsp::Vec3> pts = [] {
        const nsp::Box box = default_scene<nsp::Mono>(LightSetup::A).medium().bounds();
        nsp::Pcg32 rng(1, 11);
        std::vector<nsp::Vec3> p(kSetSize);
        for (auto& x : p) x = uniform_in(box, rng);
        return p;
    }();
    return pts;
}

/// kSetSize random rays through the cloud's box: origin uniform on the sphere of radius 3 about
/// the box centre, aimed at a point uniform in the box. Their chords average ~1.5 box units.
inline const std::vector<nsp::Ray>& tracking_rays() {
    static const std::vector<nsp::Ray> rays = [] {
        const nsp::Box box = default_scene<nsp::Mono>(LightSetup::A).medium().bounds();
        nsp::Pcg32 rng(2, 22);
        std::vector<nsp::Ray> r(kSetSize);
        for (auto& ray : r) {
            const float u1 = rng.uniform(), u2 = rng.uniform();
            const nsp::Vec3 o = 3.f * nsp::uniform_sphere(u1, u2);
            ray = {o, glm::normalize(uniform_in(box, rng) - o)};
        }
        return r;
    }();
    return rays;
}

/// A medium that forwards to M and appends every point it is looked up at to a vector.
template <nsp::Medium M>
class RecordingMedium {
public:
    using Spectral = typename M::Spectral;
    RecordingMedium(const M& m, std::vector<nsp::Vec3>& out) : m_(&m), out_(&out) {}
    nsp::Box bounds() const noexcept { return m_->bounds(); }
    nsp::Coefficients<Spectral> coefficients(const nsp::Vec3& p,
                                             const typename Spectral::Wavelengths& l) const {
        out_->push_back(p);
        return m_->coefficients(p, l);
    }
    typename Spectral::Spectrum extinction_bound(const typename Spectral::Wavelengths& l) const {
        return m_->extinction_bound(l);
    }
    float max_extinction() const noexcept { return m_->max_extinction(); }

private:
    const M* m_;
    std::vector<nsp::Vec3>* out_;
};

/// The first kSetSize points at which ratio tracking looks the cloud up along tracking_rays(),
/// in the order it visits them: the lookups of the tracking benchmarks, replayed without the
/// tracking (same spatial coherence, same cache behaviour).
inline const std::vector<nsp::Vec3>& tracked_points() {
    static const std::vector<nsp::Vec3> pts = [] {
        const auto& scene = default_scene<nsp::Mono>(LightSetup::A);
        std::vector<nsp::Vec3> p;
        p.reserve(kSetSize + 4096);
        const RecordingMedium rec(scene.medium(), p);
        const nsp::GlobalMajorant maj(rec);
        nsp::Pcg32 rng(3, 33);
        nsp::NoLookupCount none;
        for (std::size_t i = 0; p.size() < kSetSize; ++i)
            nsp::track_ratio<nsp::absorption::Event, false>(rec, maj, tracking_rays()[i & kSetMask],
                                                             kTmax, {}, rng, none);
        p.resize(kSetSize);
        return p;
    }();
    return pts;
}

/// kSetSize camera rays of the example renderer (square image) that cross the cloud: pixels
/// drawn uniformly, kept if the density reaches 0.05 somewhere along the ray (a 256-step march).
inline const std::vector<nsp::Ray>& camera_rays() {
    static const std::vector<nsp::Ray> rays = [] {
        const auto& medium = default_scene<nsp::Mono>(LightSetup::A).medium();
        nsp::Pcg32 rng(4, 44);
        std::vector<nsp::Ray> r;
        r.reserve(kSetSize);
        while (r.size() < kSetSize) {
            const float u = rng.uniform(), v = rng.uniform();
            const nsp::Ray ray = nsp_examples::camera_ray(u, v, 1.f);
            const nsp::Interval in = medium.bounds().clip(ray, 0.f, kTmax);
            bool hits = false;
            for (int k = 0; k < 256 && !in.empty() && !hits; ++k)
                hits = medium.density(ray.at(in.t0 + (float(k) + 0.5f) / 256.f * (in.t1 - in.t0))) >= 0.05f;
            if (hits) r.push_back(ray);
        }
        return r;
    }();
    return rays;
}

/// Reports a counted run's lookups as two counters: per iteration (named `per_iteration`, e.g.
/// "lookups/call") and per second. Does nothing with NoLookupCount.
template <nsp::LookupCounter C>
void report_lookups(benchmark::State& state, const C& counter, const char* per_iteration) {
    if constexpr (C::enabled) {
        const double n = double(counter.count());
        state.counters[per_iteration] = benchmark::Counter(n, benchmark::Counter::kAvgIterations);
        state.counters["lookups/s"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
    }
}

}  // namespace nsp_bench
