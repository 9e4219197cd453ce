// examples/image_render.hpp: the square-image render loop of nsp_room and nsp_volume: one Pcg32
// stream per pixel, rows shared among worker threads, per-pixel sample variance, thread CPU time
// and lookups, the image for the PNG writer.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nsp/nsp.hpp>

#include "image_row.hpp"
#include "png_writer.hpp"
#include "tile_learning.hpp"

namespace nsp_examples {

inline double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

namespace detail {

/// make(a, b) at every pair of NeeCountLearner's candidate counts, in its order (a outer).
template <class Make>
auto count_ladder(Make make) {
    constexpr int kC = nsp::NeeCountLearner::kCandidates;
    std::vector<decltype(make(1.f, 1.f))> ladder;
    for (int a = 0; a < kC; ++a)
        for (int b = 0; b < kC; ++b)
            ladder.push_back(make(nsp::NeeCountLearner::candidate(a), nsp::NeeCountLearner::candidate(b)));
    return ladder;
}

/// `run_pool(work)` (work(Out&) on every thread) as a pool that also adds each thread's CPU time
/// to its totals' `cpu`.
template <class Out, class Pool>
auto timed(Pool& run_pool) {
    return [&run_pool](auto& work) {
        auto with_time = [&work](Out& out) {
            const double cpu0 = thread_cpu_seconds();
            work(out);
            out.cpu += thread_cpu_seconds() - cpu0;
        };
        run_pool(with_time);
    };
}

/// The core of render_image and render_image_learned: `ladder` holds the estimator at every
/// candidate pair of counts (NEE x emission segment technique, NeeCountLearner's order), or one
/// estimator; with `pilot` > 0 the counts are learned per 16x16 tile by nsp::TileCounts's protocol
/// (docs/integration.md, tile_learning.hpp; as nsp_render's learned rows, with nsp's default cost
/// model): a scout of 2 samples of one pixel in 16 (streams of their own, not in the image) raises
/// the pilot's counts from `pilot_count` (the segment's too where the medium emits) to those it
/// predicts best; the first `pilot` samples of each pixel run at those counts, in two halves per
/// tile; the rest at the tile's chosen pair (written to `chosen`, a tile per entry, row-major);
/// each pixel's pilot mean weighs as TileCounts::pilot_weight says, and every sample is in the
/// statistics. Per-tile counts are sound here: every strategy of radiance() adds to its own
/// sample's pixel alone.
template <class Sc, class E, class Camera>
Row render_pixels(const Sc& scene, const std::vector<E>& ladder, const std::string& name, int res, int spp, int threads,
                  std::uint64_t seed, const Camera& camera, int pilot, float pilot_count,
                  std::vector<nsp::TechniqueCounts>* chosen) {
    constexpr int kChannels = Sc::Spectral::channels;
    constexpr int kC = nsp::NeeCountLearner::kCandidates, kTile = 16;
    constexpr bool kEmissive = nsp::EmissiveMedium<typename Sc::MediumType>;
    const std::size_t n_pix = std::size_t(res) * std::size_t(res);
    Row row;
    row.name = name;
    row.image.width = row.image.height = res;
    row.image.rgb.assign(n_pix * 3u, 0.f);
    struct Stats {  // the channel mean's running mean and squared deviations, each channel's sum
        int k = 0;
        double mean = 0.0, m2 = 0.0;
        std::array<double, 3> rgb{};
    };
    struct Pixel {
        nsp::Pcg32 rng;
        Stats rest, first;  // the samples after the pilot (all of them without one); the pilot's
    };
    std::vector<Pixel> pixels;
    pixels.reserve(n_pix);
    for (std::size_t p = 0; p < n_pix; ++p) pixels.push_back(Pixel{nsp::Pcg32(seed, p), {}, {}});
    struct Totals {
        std::uint64_t lookups = 0, steps = 0, failed = 0;
        double cpu = 0.0;
    };
    std::vector<Totals> totals(static_cast<std::size_t>(threads));
    const int tiles_x = (res + kTile - 1) / kTile, n_tiles = tiles_x * tiles_x;
    std::vector<std::size_t> tile_pair(std::size_t(n_tiles), 0);  // index into ladder
    if (chosen) chosen->assign(std::size_t(n_tiles), nsp::TechniqueCounts{});
    auto pair_of = [&](const nsp::TechniqueCounts& c) {
        if (ladder.size() != std::size_t(kC * kC)) return std::size_t(0);
        return std::size_t(nsp::NeeCountLearner::candidate_index(c.nee) * kC +
                           nsp::NeeCountLearner::candidate_index(c.emission_segment));
    };
    // One sample of pixel (x, y) from `rng` with `estimator` and `counter`: its value.
    auto one_sample = [&](Totals& out, const E& estimator, auto& counter, nsp::Pcg32& rng, int x, int y) {
        const float u = (float(x) + rng.uniform()) / float(res);
        const float v = 1.f - (float(y) + rng.uniform()) / float(res);
        const auto r = estimator.radiance(scene, camera(u, v), {}, rng, counter);
        if (r.status != nsp::Status::Ok) ++out.failed;
        return r.value;
    };
    // n more samples of pixel (x, y) into its statistics `to`, each one's channel mean to `each`.
    auto run_samples = [&](Totals& out, const E& estimator, auto& counter, int x, int y, int n, Stats Pixel::*to,
                           auto&& each) {
        Pixel& px = pixels[std::size_t(y) * std::size_t(res) + std::size_t(x)];
        Stats& s = px.*to;
        for (int i = 0; i < n; ++i) {
            const auto value = one_sample(out, estimator, counter, px.rng, x, y);
            for (int c = 0; c < 3; ++c) s.rgb[std::size_t(c)] += value[kChannels == 3 ? c : 0];
            const double L = double(value.mean()), d = L - s.mean;
            ++s.k;
            s.mean += d / s.k;
            s.m2 += d * (L - s.mean);
            each(L);
        }
    };
    auto run_pool = [&](auto& work) {
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t) pool.emplace_back(work, std::ref(totals[std::size_t(t)]));
        for (auto& t : pool) t.join();
    };
    auto timed_pool = timed<Totals>(run_pool);
    auto add_work = [](Totals& out, const nsp::NeeCountLearner& l) {
        out.lookups += l.count();
        out.steps += l.steps();
    };
    const auto start = std::chrono::steady_clock::now();
    const int first = std::min(pilot, spp);
    std::optional<nsp::TileCounts> plan;
    if (first > 0) {
        nsp::TechniqueCounts floor;
        floor.nee = pilot_count;
        floor.emission_segment = kEmissive ? pilot_count : 1.f;
        plan.emplace(res, res, kTile, nsp::CostModel{}, floor);
        const E& scout_estimator = ladder[pair_of(floor)];
        const int scout_spp = nsp::TileCounts::scout_spp(spp);
        scout_tiles<Totals>(
            *plan, timed_pool,
            [&](Totals& out, nsp::NeeCountLearner& learner, int x, int y) {
                nsp::Pcg32 rng(seed, n_pix + std::size_t(y) * std::size_t(res) + std::size_t(x));
                for (int k = 0; k < scout_spp; ++k)
                    learner.end_sample(double(one_sample(out, scout_estimator, learner, rng, x, y).mean()));
            },
            add_work);
        const E& pilot_estimator = ladder[pair_of(plan->pilot_counts())];
        pilot_tiles<Totals>(
            *plan, true, timed_pool,
            [&](Totals& out, nsp::NeeCountLearner& learner, int x, int y) {
                run_samples(out, pilot_estimator, learner, x, y, first, &Pixel::first,
                            [&](double v) { learner.end_sample(v); });
            },
            add_work);
        for (int t = 0; t < n_tiles; ++t) {
            const nsp::TechniqueCounts& c = plan->counts(t);
            if (chosen) (*chosen)[std::size_t(t)] = c;
            tile_pair[std::size_t(t)] = pair_of(c);
        }
    }
    std::atomic<int> next{0};
    auto work = [&](Totals& out) {
        const double cpu0 = thread_cpu_seconds();
        nsp::LookupCount counter;
        for (int y; (y = next.fetch_add(1)) < res;)
            for (int x = 0; x < res; ++x) {
                const std::size_t t = std::size_t((y / kTile) * tiles_x + x / kTile);
                run_samples(out, ladder[tile_pair[t]], counter, x, y, spp - first, &Pixel::rest, [](double) {});
            }
        out.lookups += counter.count();
        out.steps += counter.steps;
        out.cpu += thread_cpu_seconds() - cpu0;
    };
    run_pool(work);
    row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double lookups = 0.0, steps = 0.0;
    for (const Totals& t : totals) {
        lookups += double(t.lookups);
        steps += double(t.steps);
        row.cpu_seconds += t.cpu;
        row.failed += t.failed;
    }
    const double n_pixels = double(n_pix), samples = n_pixels * spp;
    double sum_var = 0.0, sum_mean = 0.0;
    for (std::size_t p = 0; p < n_pix; ++p) {
        const Stats &f = pixels[p].first, &r = pixels[p].rest;
        const int x = int(p % std::size_t(res)), y = int(p / std::size_t(res));
        if (f.k >= 2 && r.k >= 2) {  // the pilot's mean weighs a, the rest's 1 - a (TileCounts::pilot_weight)
            const double a = plan->pilot_weight(x, y, f.k, spp);
            for (int c = 0; c < 3; ++c)
                row.image.rgb[3 * p + std::size_t(c)] =
                    float(a * f.rgb[std::size_t(c)] / f.k + (1.0 - a) * r.rgb[std::size_t(c)] / r.k);
            // The weighted mean's variance, per sample (times spp), each side's from its own samples.
            sum_var += (a * a * f.m2 / (f.k - 1) / f.k + (1.0 - a) * (1.0 - a) * r.m2 / (r.k - 1) / r.k) * spp;
            sum_mean += a * f.mean + (1.0 - a) * r.mean;
        } else {  // every sample weighs the same: the two sides' Welford sums merged
            const int n = f.k + r.k;
            const double d = r.mean - f.mean, mean = f.mean + d * r.k / n;
            const double m2 = f.m2 + r.m2 + d * d * double(f.k) * double(r.k) / n;
            for (int c = 0; c < 3; ++c)
                row.image.rgb[3 * p + std::size_t(c)] = float((f.rgb[std::size_t(c)] + r.rgb[std::size_t(c)]) / spp);
            sum_var += m2 / (spp - 1);
            sum_mean += mean;
        }
    }
    row.lookups = lookups / samples;
    row.steps = steps / samples;
    row.variance = sum_var / n_pixels;
    row.mean = sum_mean / n_pixels;
    row.se = std::sqrt(row.variance / samples);  // the image mean's standard error (pixels independent)
    return row;
}

}  // namespace detail

/// Renders `scene` with `estimator` at res x res through `camera(u, v)` ((u, v) in [0, 1)^2, v up),
/// spp samples per pixel, one Pcg32 stream per pixel (seeded by `seed`), rows shared among
/// `threads` workers. The per-pixel statistics are of the channel mean of each sample (Mono: its value).
template <class Sc, class E, class Camera>
Row render_image(const Sc& scene, const E& estimator, const std::string& name, int res, int spp, int threads,
                 std::uint64_t seed, const Camera& camera) {
    return detail::render_pixels(scene, std::vector<E>{estimator}, name, res, spp, threads, seed, camera, 0, 1.f,
                                 nullptr);
}

/// render_image with the NEE count and the emission segment count learned per 16x16 tile (THEORY
/// 5.9, nsp::TileCounts; see detail::render_pixels): a scout, a pilot of `pilot` samples per pixel
/// at `pilot_count` or the counts the scout raised it to, the rest at the tile's pair, the tiles'
/// pairs to `chosen`; `make(nee_count, emission_segment_count)` builds the estimator at a pair.
template <class Sc, class Make, class Camera>
Row render_image_learned(const Sc& scene, Make make, const std::string& name, int res, int spp, int threads,
                         std::uint64_t seed, const Camera& camera, int pilot, float pilot_count,
                         std::vector<nsp::TechniqueCounts>* chosen) {
    return detail::render_pixels(scene, detail::count_ladder(make), name, res, spp, threads, seed, camera, pilot,
                                 pilot_count, chosen);
}

namespace detail {

/// The core of render_image_splatting and render_image_splatting_learned: `ladder` holds the
/// estimator at every candidate pair of counts (NEE x light subpath, NeeCountLearner's order), or
/// one estimator; with `pilot` > 0 the first `pilot` samples of each pixel run ladder[0] (counts
/// 1) with an nsp::NeeCountLearner as their counter, one per 16x16 tile, merged in slot order
/// (pilot_tiles: the counts do not depend on the thread count), and the rest of every pixel's samples the
/// image's chosen pair (written to `chosen`). One pair for
/// the image, not one per tile: a splat's MIS weight takes the counts of the sample that drew its
/// light subpath, and they must be those of the pixel it lands in. The pilot's samples and their
/// splats form an unbiased image at counts 1, the rest one at the chosen counts; every sample is
/// in the statistics.
template <class Sc, class E, class Cam>
Row render_splatting(const Sc& scene, const std::vector<E>& ladder, const Cam& camera, const std::string& name, int res,
                     int spp, int threads, std::uint64_t seed, int pilot, nsp::TechniqueCounts* chosen) {
    constexpr int kChannels = Sc::Spectral::channels;
    constexpr int kBatches = 8;
    constexpr int kC = nsp::NeeCountLearner::kCandidates;
    const std::size_t n_pix = std::size_t(res) * std::size_t(res);
    Row row;
    row.name = name;
    row.image.width = row.image.height = res;
    row.image.rgb.assign(n_pix * 3u, 0.f);
    struct Buffers {
        std::vector<double> batch;  ///< [batch][pixel]: the channel mean's sum, returns and splats
        std::vector<double> rgb;    ///< [pixel][3]
        std::uint64_t lookups = 0, steps = 0, failed = 0;
        double cpu = 0.0;
    };
    std::vector<Buffers> buffers(static_cast<std::size_t>(threads));
    for (Buffers& b : buffers) {
        b.batch.assign(kBatches * n_pix, 0.0);
        b.rgb.assign(3 * n_pix, 0.0);
    }
    std::vector<nsp::Pcg32> rngs;
    rngs.reserve(n_pix);
    for (std::size_t p = 0; p < n_pix; ++p) rngs.emplace_back(seed, p);
    constexpr int kTile = 16;
    std::size_t pair = 0;  // index into ladder
    if (chosen) *chosen = nsp::TechniqueCounts{};
    const auto start = std::chrono::steady_clock::now();
    auto add = [&](Buffers& out, int batch, std::size_t pixel, const auto& value) {
        out.batch[std::size_t(batch) * n_pix + pixel] += double(value.mean());
        for (int c = 0; c < 3; ++c) out.rgb[3 * pixel + std::size_t(c)] += double(value[kChannels == 3 ? c : 0]);
    };
    // Samples k0..k1-1 of pixel (x, y) with `estimator` and `counter`, each one's own value to `each`.
    auto run_samples = [&](Buffers& out, const E& estimator, auto& counter, int x, int y, int k0, int k1, auto&& each) {
        const std::size_t pixel = std::size_t(y) * std::size_t(res) + std::size_t(x);
        nsp::Pcg32& rng = rngs[pixel];
        for (int k = k0; k < k1; ++k) {
            const int batch = k % kBatches;
            auto splat = [&](float u, float v, const auto& value) {
                const int px = std::clamp(int(u * float(res)), 0, res - 1);
                const int py = std::clamp(int((1.f - v) * float(res)), 0, res - 1);
                add(out, batch, std::size_t(py) * std::size_t(res) + std::size_t(px), value);
            };
            const float u = (float(x) + rng.uniform()) / float(res);
            const float v = 1.f - (float(y) + rng.uniform()) / float(res);
            const auto r = estimator.sample(scene, camera, u, v, {}, rng, counter, splat);
            if (r.status != nsp::Status::Ok) ++out.failed;
            add(out, batch, pixel, r.value);
            each(double(r.value.mean()));
        }
    };
    auto run_pool = [&](auto& work) {
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t) pool.emplace_back(work, std::ref(buffers[std::size_t(t)]));
        for (auto& t : pool) t.join();
    };
    const int first = std::min(pilot, spp);
    if (first > 0) {
        // A BDPT pilot runs at counts 1 (one pair for the image: no scout, the halves merged).
        nsp::TileCounts plan(res, res, kTile);
        pilot_tiles<Buffers>(
            plan, false, timed<Buffers>(run_pool),
            [&](Buffers& out, nsp::NeeCountLearner& learner, int x, int y) {
                run_samples(out, ladder[0], learner, x, y, 0, first, [&](double v) { learner.end_sample(v); });
            },
            [](Buffers& out, const nsp::NeeCountLearner& l) {
                out.lookups += l.count();
                out.steps += l.steps();
            });
        const nsp::TechniqueCounts c = plan.image_counts();
        if (chosen) *chosen = c;
        if (ladder.size() == std::size_t(kC * kC))
            pair = std::size_t(nsp::NeeCountLearner::candidate_index(c.nee) * kC +
                               nsp::NeeCountLearner::candidate_index(c.light_subpath));
    }
    std::atomic<int> next{0};
    auto work = [&](Buffers& out) {
        const double cpu0 = thread_cpu_seconds();
        nsp::LookupCount counter;
        for (int y; (y = next.fetch_add(1)) < res;)
            for (int x = 0; x < res; ++x) run_samples(out, ladder[pair], counter, x, y, first, spp, [](double) {});
        out.lookups += counter.count();
        out.steps += counter.steps;
        out.cpu += thread_cpu_seconds() - cpu0;
    };
    run_pool(work);
    row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double lookups = 0.0, steps = 0.0;
    for (const Buffers& b : buffers) {
        lookups += double(b.lookups);
        steps += double(b.steps);
        row.cpu_seconds += b.cpu;
        row.failed += b.failed;
    }
    std::array<double, kBatches> per_batch{};  // samples per pixel in each batch
    for (int k = 0; k < spp; ++k) per_batch[std::size_t(k % kBatches)] += 1.0;
    const int batches = std::min(spp, kBatches);
    std::array<double, kBatches> image_mean{};
    double sum_var = 0.0, sum_mean = 0.0;
    for (std::size_t p = 0; p < n_pix; ++p) {
        double total = 0.0, m = 0.0, m2 = 0.0;
        for (int b = 0; b < batches; ++b) {
            double t = 0.0;
            for (const Buffers& buf : buffers) t += buf.batch[std::size_t(b) * n_pix + p];
            total += t;
            const double mean_b = t / per_batch[std::size_t(b)], d = mean_b - m;
            m += d / (b + 1);
            m2 += d * (mean_b - m);
            image_mean[std::size_t(b)] += mean_b / double(n_pix);
        }
        for (int c = 0; c < 3; ++c) {
            double v = 0.0;
            for (const Buffers& buf : buffers) v += buf.rgb[3 * p + std::size_t(c)];
            row.image.rgb[3 * p + std::size_t(c)] = float(v / spp);
        }
        sum_mean += total / spp;
        if (batches > 1) sum_var += m2 / (batches - 1) * (double(spp) / batches);
    }
    const double samples = double(n_pix) * spp;
    row.lookups = lookups / samples;
    row.steps = steps / samples;
    row.variance = sum_var / double(n_pix);
    row.mean = sum_mean / double(n_pix);
    double m = 0.0, m2 = 0.0;
    for (int b = 0; b < batches; ++b) {
        const double d = image_mean[std::size_t(b)] - m;
        m += d / (b + 1);
        m2 += d * (image_mean[std::size_t(b)] - m);
    }
    row.se = batches > 1 ? std::sqrt(m2 / (batches - 1) / batches) : 0.0;
    return row;
}

}  // namespace detail

/// render_image for an estimator that splats (BdptEstimator::sample with light tracing) through
/// `camera` (an nsp::Camera): each pixel is the sum of its samples' returns and of the splats it
/// received, over spp. A pixel's own samples no longer give its variance (its splats come from
/// other pixels' light subpaths), so the samples are dealt into kBatches batches by index, each
/// batch an independent image, and a pixel's variance of one sample is the variance of its batch
/// means times the batch size; the image mean's standard error is that of the batch images' means.
template <class Sc, class E, class Cam>
Row render_image_splatting(const Sc& scene, const E& estimator, const Cam& camera, const std::string& name, int res,
                           int spp, int threads, std::uint64_t seed) {
    return detail::render_splatting(scene, std::vector<E>{estimator}, camera, name, res, spp, threads, seed, 0, nullptr);
}

/// render_image_splatting with BDPT's NEE count and light subpath probability learned for the
/// image (THEORY 5.9, nsp::NeeCountLearner; see detail::render_splatting): a pilot of `pilot`
/// samples per pixel at counts 1, the rest at the chosen pair, which goes to `chosen`;
/// `make(nee_count, light_subpath_probability)` builds the estimator at a pair.
template <class Sc, class Make, class Cam>
Row render_image_splatting_learned(const Sc& scene, Make make, const Cam& camera, const std::string& name, int res,
                                   int spp, int threads, std::uint64_t seed, int pilot, nsp::TechniqueCounts* chosen) {
    return detail::render_splatting(scene, detail::count_ladder(make), camera, name, res, spp, threads, seed, pilot,
                                    chosen);
}

}  // namespace nsp_examples
