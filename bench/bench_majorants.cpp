// bench/bench_majorants.cpp: the majorant sweep, what a majorant that fits the medium buys in
// time and what it costs in variance (or, for a majorant that does not bound, in error).
//
// Grey rows: the grey cloud and the sparse medium (examples/default_scene.hpp) in Mono, set-up B
// lights, PathEstimator<NullScatteringMis, Balance, absorb-weight>, under
//   global          GlobalMajorant (the medium's extinction bound; also the reference's),
//   grid<R>         GridMajorant at R = 1, 4, 8, 16, 32, 64 cells per axis (bounding),
//   grid16x0.5-*    GridMajorant at 16 with scale 0.5, under bound::Signed and bound::Clamp,
//   global-mean-*   GlobalMajorant at the medium's mean extinction over its box, same two policies.
// Chromatic rows: the chromatic cloud and a chromatic sparse medium (the sparse density with the
// chromatic cloud's extinction 5 : 20 : 80 and albedo), Rgb, chromatic set-up C1 (white
// environment), SpectralPathEstimator<SpectralMis, NullScatteringMis, Balance>, under
// ChannelMajorant (channel-global) and ChannelGridMajorant at the same resolutions.
// Why B and C1, not A and C2 (the small bright sphere): there the variance of one sample is
// dominated by rare paths that reach the light (samples up to ~1000 against a mean of 0.05), and
// its estimate from 262k samples changed 3x between two seeds on the same row (bench/RESULTS.md);
// under B it agrees within 2%. The variance columns must be comparable across rows.
//
// One iteration renders one sample at the centre of each pixel of a 32 x 32 image of the example
// camera (every pixel, whether its ray meets the medium or not); the iteration count is fixed
// (kPasses samples per pixel), the generator's seed is the same in every row, so rows differ only
// in the majorant. Counters (per sample = per pixel sample):
//   lookups/sample, steps/sample   density lookups and DDA steps (LookupCount in the timed loop)
//   real/sample, null/sample       real and null collisions: an untimed second pass on the same
//                                  rays and seed, majorant and generator wrapped (CountingIterator),
//                                  classifies every flight that stopped at a collision as delta
//                                  tracking's real collision or a ratio-tracking flight whose
//                                  weight reached 0 (ratio_stops/sample); null = lookups - real.
//                                  It must see the timed pass's lookups (lookups_check = 1) and
//                                  leave no flight unclassified (unclassified = 0). A per-channel
//                                  delta flight cut by a failed renormalisation would count as real.
//   ns/sample                      CPU time per sample
//   var                            variance of one sample of a pixel, averaged over the pixels
//                                  (Mono: the value; Rgb: mean of the three channels' variances)
//   LTUV = lookups/sample x var,   ns*var = ns/sample x var (lower is better; "time x variance")
//   img_mean, img_mean_se          mean of the image and its standard error
//   rmse, bias2, mean_z (grey)     against a 4096-spp reference of the same medium rendered once
//                                  per process under the global majorant with another seed: the
//                                  RMSE of this row's kPasses-spp image, the squared bias estimated
//                                  as MSE - var/kPasses - reference noise, and the image-mean
//                                  difference in standard errors (|mean_z| > 4: not noise)
//   bad/sample                     samples whose status was not Ok (aborted, non-finite, rejected)
// BM_MajorantBuild/<medium>/<R> times the construction of a GridMajorant at R and reports its
// memory_bytes(). BM_MajorantChoice/<medium> (cloud, sparse, the fog of F1 and F3) times
// choose_grid_resolution and reports the cost model's pick and its cost of every candidate
// (docs/majorants.md: build/bench/nsp_bench_majorants --benchmark_filter=Choice).
// bench/run_majorants.sh runs this binary and bench/plot_majorants.py plots it.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

#include "fixtures.hpp"

namespace {

using namespace nsp_bench;
using nsp::Mono;
using nsp::Rgb;
using GreyMedium = nsp::DenseGridMedium<Mono>;
using RgbMedium = nsp::DenseGridMedium<Rgb>;

inline constexpr int kImage = 32;                       ///< pixels per side
inline constexpr int kPixels = kImage * kImage;
inline constexpr int kPasses = 256;                     ///< samples per pixel of a sweep row (iterations)
inline constexpr int kReferencePasses = 4096;           ///< samples per pixel of the reference
inline constexpr std::uint64_t kSeed = 9, kStream = 99;  ///< every sweep row's generator
inline constexpr std::uint64_t kReferenceSeed = 10;     ///< the reference's (independent of the rows)

enum class MediumId { Cloud, Sparse };
const char* name(MediumId id) { return id == MediumId::Cloud ? "cloud" : "sparse"; }

const std::vector<float>& density(MediumId id) {
    static const std::vector<float> cloud = nsp_examples::default_cloud_density();
    static const std::vector<float> sparse = nsp_examples::sparse_density();
    return id == MediumId::Cloud ? cloud : sparse;
}

/// The grey medium `id` (Mono), built once.
const GreyMedium& grey_medium(MediumId id) {
    static const GreyMedium cloud = nsp_examples::make_default_medium<Mono>();
    static const GreyMedium sparse = nsp_examples::make_sparse_medium<Mono>();
    return id == MediumId::Cloud ? cloud : sparse;
}

/// The chromatic version of medium `id` (Rgb): the default cloud's make_chromatic_medium, or the
/// sparse density with the same chromatic extinction and albedo.
const RgbMedium& chromatic_medium(MediumId id) {
    static const RgbMedium cloud = nsp_examples::make_chromatic_medium<Rgb>();
    static const RgbMedium sparse = [] {
        const auto ext = nsp_examples::chromatic_extinction<Rgb>();
        constexpr float albedo = nsp_examples::kChromaticAlbedo;
        constexpr int r = nsp_examples::kGridRes;
        return RgbMedium(nsp::Box{nsp::Vec3(-1.f), nsp::Vec3(1.f)}, {r, r, r}, nsp_examples::sparse_density(),
                         nsp::scale(ext, 1.f - albedo), nsp::scale(ext, albedo));
    }();
    return id == MediumId::Cloud ? cloud : sparse;
}

/// The mean extinction of grey medium `id` over its box (mean voxel density x extinction).
float mean_extinction(MediumId id) {
    const std::vector<float>& d = density(id);
    const double mean = std::accumulate(d.begin(), d.end(), 0.0) / double(d.size());
    return float(mean) * nsp::max_value(grey_medium(id).extinction_per_density());
}

/// The camera rays through the pixel centres of the kImage x kImage image, row by row.
const std::vector<nsp::Ray>& pixel_rays() {
    static const std::vector<nsp::Ray> rays = [] {
        std::vector<nsp::Ray> r;
        r.reserve(kPixels);
        for (int y = 0; y < kImage; ++y)
            for (int x = 0; x < kImage; ++x)
                r.push_back(nsp_examples::camera_ray((float(x) + 0.5f) / kImage, 1.f - (float(y) + 0.5f) / kImage, 1.f));
        return r;
    }();
    return rays;
}

// ---------------------------------------------------------------------------------------------
// Counting real collisions without touching the timed code

/// What the counting pass tallies: random numbers drawn and lookups made so far (the iterators
/// read both at the start and the end of each flight), and the flights that stopped at a
/// collision, by kind.
struct Tally {
    std::uint64_t uniforms = 0;
    const std::uint64_t* lookups = nullptr;  ///< the counting pass's LookupCount::n
    std::uint64_t real = 0;         ///< delta-tracking flights that stopped at a real collision
    std::uint64_t ratio_stops = 0;  ///< ratio-tracking flights cut short (weight 0: T underflowed or hit 0)
    std::uint64_t unclassified = 0;
};

/// Pcg32 that counts the random numbers it draws (the same sequence, so the same paths).
class CountingRng {
public:
    CountingRng(std::uint64_t seed, std::uint64_t stream, Tally* t) : rng_(seed, stream), t_(t) {}
    float uniform() noexcept {
        ++t_->uniforms;
        return rng_.uniform();
    }

private:
    nsp::Pcg32 rng_;
    Tally* t_;
};

/// Wraps a majorant iterator. free_flight returns from inside its segment loop exactly when the
/// collision callback stopped the flight (or it was aborted: bad/sample); a flight that passes
/// runs the iterator to its end. A stopped flight of L lookups drew 2L random numbers if it was
/// delta tracking (one step and one event choice per collision: it stopped at a real collision)
/// and L if it was ratio tracking (no event choice: every collision null, stopped because the
/// weight reached 0); a step that leaves a segment carries its remaining optical depth into the
/// next one (29dc1a3) and draws nothing, except after a rounding to <= 0 at the boundary (then the
/// flight is left unclassified and counted). The destructor tells the two apart.
template <class I>
class CountingIterator {
public:
    CountingIterator(I it, Tally* t) noexcept
        : it_(std::move(it)), t_(t), uniforms0_(t->uniforms), lookups0_(*t->lookups) {}
    CountingIterator(const CountingIterator&) = delete;
    CountingIterator& operator=(const CountingIterator&) = delete;
    ~CountingIterator() {
        if (ended_) return;
        const std::uint64_t l = *t_->lookups - lookups0_, u = t_->uniforms - uniforms0_;
        if (l > 0 && u == 2 * l) ++t_->real;
        else if (l > 0 && u == l) ++t_->ratio_stops;
        else ++t_->unclassified;
    }
    auto next() noexcept {
        auto s = it_.next();
        if (!s) ended_ = true;
        return s;
    }
    std::uint32_t steps() const noexcept
        requires requires(const I& i) { i.steps(); }
    {
        return it_.steps();
    }

private:
    I it_;
    Tally* t_;
    std::uint64_t uniforms0_, lookups0_;
    bool ended_ = false;
};

/// Majorant policy Maj with its iterators wrapped in CountingIterator: same segments, same
/// random numbers, so the flights are the timed run's.
template <class Maj>
class CountingMajorant {
public:
    using Bound = nsp::bound_policy_t<Maj>;
    CountingMajorant(Maj inner, Tally* t) : inner_(std::move(inner)), t_(t) {}
    template <class L>
    auto iterate(const nsp::Ray& r, float tmin, float tmax, const L& l) const noexcept {
        return CountingIterator<decltype(inner_.iterate(r, tmin, tmax, l))>(inner_.iterate(r, tmin, tmax, l), t_);
    }

private:
    Maj inner_;
    Tally* t_;
};

// ---------------------------------------------------------------------------------------------
// Rendering the image

/// Per-pixel, per-channel sums of the samples and of their squares.
struct Moments {
    int channels = 1;
    std::vector<double> sum, sum2;
    std::uint64_t bad = 0;
    double largest = 0.0;  ///< the largest |sample| of any channel
    explicit Moments(int c) : channels(c), sum(std::size_t(kPixels) * c, 0.0), sum2(std::size_t(kPixels) * c, 0.0) {}
    template <class Spec>
    void add(int pixel, const Spec& v) {
        for (int c = 0; c < channels; ++c) {
            const double x = double(v[c]);
            largest = std::max(largest, std::abs(x));
            sum[std::size_t(pixel) * channels + c] += x;
            sum2[std::size_t(pixel) * channels + c] += x * x;
        }
    }
    /// Mean of pixel p, channel c, over n samples.
    double mean(std::size_t i, int n) const { return sum[i] / n; }
    /// Unbiased variance of one sample of pixel p, channel c.
    double var(std::size_t i, int n) const { return std::max(0.0, (sum2[i] - sum[i] * sum[i] / n) / (n - 1)); }
};

/// Renders `passes` samples per pixel of scene `sc` with estimator `est` into `m`; counts lookups
/// and DDA steps in `counter`. In a benchmark the passes are the timed iterations.
template <class Est, class Sc, nsp::UniformRng R>
void render_pass(const Est& est, const Sc& sc, R& rng, nsp::LookupCount& counter, Moments& m) {
    const std::vector<nsp::Ray>& rays = pixel_rays();
    for (int p = 0; p < kPixels; ++p) {
        const auto r = est.radiance(sc, rays[std::size_t(p)], {}, rng, counter);
        if (r.status != nsp::Status::Ok) ++m.bad;
        m.add(p, r.value);
    }
}

using GreyEstimator = nsp::PathEstimator<nsp::strategy::NullScatteringMis, nsp::mis::Balance, nsp::absorption::Weight>;
using ChromaticEstimator = nsp::SpectralPathEstimator<nsp::channels::SpectralMis, nsp::strategy::NullScatteringMis,
                                                      nsp::mis::Balance, nsp::absorption::Weight>;

template <class M, class Maj>
using SceneOf = nsp::Scene<M, Maj, nsp::HenyeyGreensteinPhase>;

/// The grey scene of medium `id` under majorant `maj` (set-up B lights).
template <class Maj>
SceneOf<GreyMedium, Maj> grey_scene(MediumId id, Maj maj) {
    return {grey_medium(id), std::move(maj), nsp::HenyeyGreensteinPhase(nsp_examples::kPhaseG),
            nsp_examples::default_lights<Mono>(LightSetup::B)};
}
/// The chromatic scene of medium `id` under majorant `maj` (set-up C1: white environment).
template <class Maj>
SceneOf<RgbMedium, Maj> chromatic_scene(MediumId id, Maj maj) {
    return {chromatic_medium(id), std::move(maj), nsp::HenyeyGreensteinPhase(nsp_examples::kPhaseG),
            nsp_examples::chromatic_lights<Rgb>(nsp_examples::ChromaticSetup::Env)};
}

/// The reference image of grey medium `id`: per pixel mean and variance of the mean, from
/// kReferencePasses samples per pixel under the global majorant, rendered once per process.
struct Reference {
    std::vector<double> mean, var_of_mean;
};
const Reference& reference(MediumId id) {
    auto make = [](MediumId m) {
        const auto sc = grey_scene(m, nsp::GlobalMajorant<GreyMedium>(grey_medium(m)));
        const GreyEstimator est;
        nsp::Pcg32 rng(kReferenceSeed, kStream);
        nsp::LookupCount counter;
        Moments mo(1);
        for (int k = 0; k < kReferencePasses; ++k) render_pass(est, sc, rng, counter, mo);
        Reference r;
        for (std::size_t i = 0; i < std::size_t(kPixels); ++i) {
            r.mean.push_back(mo.mean(i, kReferencePasses));
            r.var_of_mean.push_back(mo.var(i, kReferencePasses) / kReferencePasses);
        }
        return r;
    };
    static const Reference cloud = make(MediumId::Cloud);
    static const Reference sparse = make(MediumId::Sparse);
    return id == MediumId::Cloud ? cloud : sparse;
}

/// The counting pass's tally and lookups, by benchmark name (repetitions run the same passes:
/// counted once).
struct Collisions {
    Tally tally;
    std::uint64_t lookups = 0;
};
std::map<std::string, Collisions>& collision_cache() {
    static std::map<std::string, Collisions> cache;
    return cache;
}

/// The sweep row: kPasses timed passes over the image, then the counters of the file header.
/// `make_scene(maj)` builds the scene around a majorant; `make_majorant()` builds the majorant.
template <class Est, class MakeScene, class MakeMajorant>
void run_row(benchmark::State& state, const std::string& key, std::size_t memory, MakeScene make_scene,
             MakeMajorant make_majorant, const Reference* ref) {
    const auto sc = make_scene(make_majorant());
    const int channels = std::remove_cvref_t<decltype(sc)>::Spectral::channels;
    const Est est;
    nsp::Pcg32 rng(kSeed, kStream);
    nsp::LookupCount counter;
    Moments m(channels);
    for (auto _ : state) render_pass(est, sc, rng, counter, m);
    const int n = int(state.iterations());

    // Untimed: the same passes with the majorant and the generator wrapped, to classify the
    // flights that stopped (CountingIterator).
    auto& cache = collision_cache();
    if (!cache.count(key)) {
        Collisions& c = cache[key];
        nsp::LookupCount counter2;
        c.tally.lookups = &counter2.n;
        const auto counted = make_scene(CountingMajorant(make_majorant(), &c.tally));
        CountingRng rng2(kSeed, kStream, &c.tally);
        Moments m2(channels);
        for (int k = 0; k < n; ++k) render_pass(est, counted, rng2, counter2, m2);
        c.lookups = counter2.n;
        c.tally.lookups = nullptr;
    }
    const Collisions& col = cache[key];

    const double samples = double(n) * kPixels;
    double var = 0.0, img = 0.0, img_var = 0.0;
    for (std::size_t i = 0; i < m.sum.size(); ++i) {
        var += m.var(i, n);
        img += m.mean(i, n);
        img_var += m.var(i, n) / n;
    }
    const double cells = double(m.sum.size());
    var /= cells;
    img /= cells;
    using C = benchmark::Counter;
    state.counters["lookups/sample"] = double(counter.n) / samples;
    state.counters["steps/sample"] = double(counter.steps) / samples;
    state.counters["real/sample"] = double(col.tally.real) / samples;
    state.counters["null/sample"] = (double(counter.n) - double(col.tally.real)) / samples;
    state.counters["ratio_stops/sample"] = double(col.tally.ratio_stops) / samples;
    state.counters["unclassified"] = double(col.tally.unclassified);
    state.counters["lookups_check"] = col.lookups == counter.n ? 1.0 : 0.0;
    state.counters["ns/sample"] = C(samples * 1e-9, C::kIsRate | C::kInvert);
    state.counters["var"] = var;
    state.counters["LTUV"] = double(counter.n) / samples * var;
    state.counters["ns*var"] = C(samples * 1e-9 / var, C::kIsRate | C::kInvert);
    state.counters["img_mean"] = img;
    state.counters["img_mean_se"] = std::sqrt(img_var) / cells;
    state.counters["bad/sample"] = double(m.bad) / samples;
    state.counters["max_sample"] = m.largest;
    state.counters["memory_bytes"] = double(memory);
    if (ref) {
        double mse = 0.0, noise = 0.0, ref_noise = 0.0, diff = 0.0;
        for (std::size_t i = 0; i < std::size_t(kPixels); ++i) {
            const double d = m.mean(i, n) - ref->mean[i];
            mse += d * d;
            diff += d;
            noise += m.var(i, n) / n;
            ref_noise += ref->var_of_mean[i];
        }
        state.counters["rmse"] = std::sqrt(mse / kPixels);
        state.counters["bias2"] = (mse - noise - ref_noise) / kPixels;
        state.counters["ref_noise2"] = ref_noise / kPixels;
        state.counters["mean_z"] = diff / std::sqrt(noise + ref_noise);
    }
}

/// Registers one sweep row under `name`.
template <class F>
void add(const std::string& name, F f) {
    benchmark::RegisterBenchmark(name.c_str(), [f, name](benchmark::State& s) { f(s, name); })
        ->Iterations(kPasses)
        ->Unit(benchmark::kMillisecond);
}

constexpr int kResolutions[] = {1, 4, 8, 16, 32, 64};

template <class B>
void add_grey_global(MediumId id, const std::string& label, float value) {
    using Maj = nsp::GlobalMajorant<GreyMedium, B>;
    add(std::string("BM_Majorant/") + name(id) + "/" + label, [id, value](benchmark::State& s, const std::string& key) {
        run_row<GreyEstimator>(
            s, key, 0, [id](auto maj) { return grey_scene(id, std::move(maj)); },
            [id, value] { return value > 0.f ? Maj(grey_medium(id), value) : Maj(grey_medium(id)); }, &reference(id));
    });
}

template <class B>
void add_grey_grid(MediumId id, const std::string& label, int res, float scale) {
    using Maj = nsp::GridMajorant<GreyMedium, B>;
    add(std::string("BM_Majorant/") + name(id) + "/" + label, [id, res, scale](benchmark::State& s, const std::string& key) {
        const std::size_t bytes = Maj(grey_medium(id), res, scale).memory_bytes();
        run_row<GreyEstimator>(
            s, key, bytes, [id](auto maj) { return grey_scene(id, std::move(maj)); },
            [id, res, scale] { return Maj(grey_medium(id), res, scale); }, &reference(id));
    });
}

template <class Maj, class... Args>
void add_chromatic(MediumId id, const std::string& label, Args... args) {
    add(std::string("BM_ChannelMajorant/") + name(id) + "/" + label, [id, args...](benchmark::State& s, const std::string& key) {
        std::size_t bytes = 0;
        if constexpr (sizeof...(Args) > 0) bytes = Maj(chromatic_medium(id), args...).memory_bytes();
        run_row<ChromaticEstimator>(
            s, key, bytes, [id](auto maj) { return chromatic_scene(id, std::move(maj)); },
            [id, args...] { return Maj(chromatic_medium(id), args...); }, nullptr);
    });
}

/// Construction of a grid majorant at resolution `res` (one per iteration) and its memory.
void BM_MajorantBuild(benchmark::State& state, MediumId id, int res) {
    const GreyMedium& medium = grey_medium(id);
    std::size_t bytes = 0;
    for (auto _ : state) {
        const nsp::GridMajorant<GreyMedium> maj(medium, res);
        bytes = maj.memory_bytes();
        benchmark::DoNotOptimize(bytes);
    }
    state.counters["memory_bytes"] = double(bytes);
    state.counters["cells"] = double(res) * res * res;
}

/// The cost model's pick (nsp/majorants/choose.hpp, one choose_grid_resolution per iteration)
/// over `medium`, with its cost per random line of every candidate as counters (docs/majorants.md
/// compares them with the sweep): cost_global, cost_grid2, ..., cost_grid64, and chosen_cells (0:
/// the global majorant).
void BM_MajorantChoice(benchmark::State& state, const GreyMedium* medium) {
    nsp::MajorantCost best;
    for (auto _ : state) {
        best = nsp::choose_grid_resolution(*medium);
        benchmark::DoNotOptimize(best.cost);
    }
    state.counters["chosen_cells"] = best.global ? 0.0 : double(best.resolution[0]);
    state.counters["cost_global"] = nsp::global_majorant_cost(*medium).cost;
    for (int r = 2; r <= 64; r *= 2)
        state.counters["cost_grid" + std::to_string(r)] = nsp::grid_majorant_cost(*medium, {r, r, r}).cost;
}

const bool registered = [] {
    for (MediumId id : {MediumId::Cloud, MediumId::Sparse}) {
        add_grey_global<nsp::bound::Guaranteed>(id, "global", 0.f);
        for (int r : kResolutions) add_grey_grid<nsp::bound::Guaranteed>(id, "grid" + std::to_string(r), r, 1.f);
        add_grey_grid<nsp::bound::Signed>(id, "grid16x0.5-signed", 16, 0.5f);
        add_grey_grid<nsp::bound::Clamp>(id, "grid16x0.5-clamp", 16, 0.5f);
        add_grey_global<nsp::bound::Signed>(id, "global-mean-signed", mean_extinction(id));
        add_grey_global<nsp::bound::Clamp>(id, "global-mean-clamp", mean_extinction(id));
    }
    for (MediumId id : {MediumId::Cloud, MediumId::Sparse}) {
        add_chromatic<nsp::ChannelMajorant<RgbMedium>>(id, "channel-global");
        for (int r : kResolutions)
            add_chromatic<nsp::ChannelGridMajorant<RgbMedium>>(id, "channel-grid" + std::to_string(r), r);
    }
    for (MediumId id : {MediumId::Cloud, MediumId::Sparse})
        for (int r : kResolutions)
            benchmark::RegisterBenchmark((std::string("BM_MajorantBuild/") + name(id) + "/" + std::to_string(r)).c_str(),
                                         BM_MajorantBuild, id, r)
                ->MinTime(kMinTime)
                ->Unit(benchmark::kMicrosecond);
    static const GreyMedium fog_f1 = nsp_examples::make_fog_medium<Mono>(nsp_examples::FogSetup::F1);
    static const GreyMedium fog_f3 = nsp_examples::make_fog_medium<Mono>(nsp_examples::FogSetup::F3);
    for (const auto& [n, m] : {std::pair<const char*, const GreyMedium*>{"cloud", &grey_medium(MediumId::Cloud)},
                               {"sparse", &grey_medium(MediumId::Sparse)}, {"fog-F1", &fog_f1}, {"fog-F3", &fog_f3}})
        benchmark::RegisterBenchmark((std::string("BM_MajorantChoice/") + n).c_str(), BM_MajorantChoice, m)
            ->MinTime(kMinTime)
            ->Unit(benchmark::kMillisecond);
    return true;
}();

}  // namespace
