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
#include <string>
#include <thread>
#include <vector>

#include <nsp/nsp.hpp>

#include "image_row.hpp"
#include "png_writer.hpp"

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

/// The pilot of render_pixels and render_splatting on `plan` (nsp::TileCounts, the protocol of
/// docs/integration.md): threads take whole slots (`run_pool(work)` runs work(Out&) on each
/// thread's totals), a slot's tiles in order, so the counts do not depend on the thread count;
/// `pilot_pixel(out, learner, x, y)` runs pixel (x, y)'s pilot samples with the tile's learner as
/// their counter (and end_sample after each). Each tile's lookups, steps and the thread CPU time
/// go to the thread's totals. Ends with plan.choose().
template <class Out, class Pool, class PilotPixel>
void learn_tiles(nsp::TileCounts& plan, Pool&& run_pool, PilotPixel&& pilot_pixel) {
    std::atomic<int> next_slot{0};
    auto learn = [&](Out& out) {
        const double cpu0 = thread_cpu_seconds();
        for (int j; (j = next_slot.fetch_add(1)) < nsp::TileCounts::kSlots;)
            for (const int t : plan.slot_tiles(j)) {
                nsp::NeeCountLearner learner = plan.learner();
                const nsp::TileCounts::Rect r = plan.tile_rect(t);
                for (int y = r.y0; y < r.y1; ++y)
                    for (int x = r.x0; x < r.x1; ++x) {
                        pilot_pixel(out, learner, x, y);
                        learner.end_pixel();
                    }
                plan.add(t, learner);
                out.lookups += learner.count();
                out.steps += learner.steps();
            }
        out.cpu += thread_cpu_seconds() - cpu0;
    };
    run_pool(learn);
    plan.choose();
}

/// The core of render_image and render_image_learned: `ladder` holds the estimator at every
/// candidate pair of counts (NEE x emission segment technique, NeeCountLearner's order), or one
/// estimator; with `pilot` > 0 the first `pilot` samples of each pixel run ladder[0] (counts 1)
/// with an nsp::NeeCountLearner per 16x16 tile as their counter (tiles handed to threads in fixed
/// slots, so the counts do not depend on the thread count), the rest the tile's chosen pair
/// (written to `chosen`, a tile per entry, row-major): its own where its pilot shows it pays,
/// else the image's (all tiles' pilots merged) where its pilot predicts that no worse than counts
/// 1; every sample is in the statistics. Per-tile counts are
/// sound here: every strategy of radiance() adds to its own sample's pixel alone.
template <class Sc, class E, class Camera>
Row render_pixels(const Sc& scene, const std::vector<E>& ladder, const std::string& name, int res, int spp, int threads,
                  std::uint64_t seed, const Camera& camera, int pilot, std::vector<nsp::TechniqueCounts>* chosen) {
    constexpr int kChannels = Sc::Spectral::channels;
    constexpr int kC = nsp::NeeCountLearner::kCandidates, kTile = 16;
    const std::size_t n_pix = std::size_t(res) * std::size_t(res);
    Row row;
    row.name = name;
    row.image.width = row.image.height = res;
    row.image.rgb.assign(n_pix * 3u, 0.f);
    struct Pixel {
        nsp::Pcg32 rng;
        int k = 0;
        double mean = 0.0, m2 = 0.0;
        std::array<double, 3> rgb{};
    };
    std::vector<Pixel> pixels;
    pixels.reserve(n_pix);
    for (std::size_t p = 0; p < n_pix; ++p) pixels.push_back(Pixel{nsp::Pcg32(seed, p)});
    struct Totals {
        std::uint64_t lookups = 0, steps = 0, failed = 0;
        double cpu = 0.0;
    };
    std::vector<Totals> totals(static_cast<std::size_t>(threads));
    const int tiles_x = (res + kTile - 1) / kTile, n_tiles = tiles_x * tiles_x;
    std::vector<std::size_t> tile_pair(std::size_t(n_tiles), 0);  // index into ladder
    if (chosen) chosen->assign(std::size_t(n_tiles), nsp::TechniqueCounts{});
    // Samples of pixel (x, y) up to the k1-th with `estimator` and `counter`, each one's value to `each`.
    auto run_samples = [&](Totals& out, const E& estimator, auto& counter, int x, int y, int k1, auto&& each) {
        Pixel& px = pixels[std::size_t(y) * std::size_t(res) + std::size_t(x)];
        while (px.k < k1) {
            const float u = (float(x) + px.rng.uniform()) / float(res);
            const float v = 1.f - (float(y) + px.rng.uniform()) / float(res);
            const auto r = estimator.radiance(scene, camera(u, v), {}, px.rng, counter);
            if (r.status != nsp::Status::Ok) ++out.failed;
            for (int c = 0; c < 3; ++c) px.rgb[std::size_t(c)] += r.value[kChannels == 3 ? c : 0];
            const double L = double(r.value.mean()), d = L - px.mean;
            ++px.k;
            px.mean += d / px.k;
            px.m2 += d * (L - px.mean);
            each(L);
        }
    };
    auto run_pool = [&](auto& work) {
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t) pool.emplace_back(work, std::ref(totals[std::size_t(t)]));
        for (auto& t : pool) t.join();
    };
    const auto start = std::chrono::steady_clock::now();
    const int first = std::min(pilot, spp);
    if (first > 0) {
        // Each tile keeps its own counts where its pilot shows they pay, else takes the image's
        // where its pilot predicts them no worse than counts 1 (nsp::TileCounts).
        nsp::TileCounts plan(res, res, kTile);
        learn_tiles<Totals>(plan, run_pool, [&](Totals& out, nsp::NeeCountLearner& learner, int x, int y) {
            run_samples(out, ladder[0], learner, x, y, first, [&](double v) { learner.end_sample(v); });
        });
        for (int t = 0; t < n_tiles; ++t) {
            const nsp::TechniqueCounts& c = plan.counts(t);
            if (chosen) (*chosen)[std::size_t(t)] = c;
            if (ladder.size() == std::size_t(kC * kC))
                tile_pair[std::size_t(t)] = std::size_t(nsp::NeeCountLearner::candidate_index(c.nee) * kC +
                                                        nsp::NeeCountLearner::candidate_index(c.emission_segment));
        }
    }
    std::atomic<int> next{0};
    auto work = [&](Totals& out) {
        const double cpu0 = thread_cpu_seconds();
        nsp::LookupCount counter;
        for (int y; (y = next.fetch_add(1)) < res;)
            for (int x = 0; x < res; ++x) {
                const std::size_t t = std::size_t((y / kTile) * tiles_x + x / kTile);
                run_samples(out, ladder[tile_pair[t]], counter, x, y, spp, [](double) {});
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
        const Pixel& px = pixels[p];
        for (int c = 0; c < 3; ++c) row.image.rgb[3 * p + std::size_t(c)] = float(px.rgb[std::size_t(c)] / spp);
        sum_var += px.m2 / (spp - 1);
        sum_mean += px.mean;
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
    return detail::render_pixels(scene, std::vector<E>{estimator}, name, res, spp, threads, seed, camera, 0, nullptr);
}

/// render_image with the NEE count and the emission segment count learned per 16x16 tile (THEORY
/// 5.9, nsp::NeeCountLearner; see detail::render_pixels): a pilot of `pilot` samples per pixel at
/// counts 1, the rest at the tile's pair, the tiles' pairs to `chosen`;
/// `make(nee_count, emission_segment_count)` builds the estimator at a pair.
template <class Sc, class Make, class Camera>
Row render_image_learned(const Sc& scene, Make make, const std::string& name, int res, int spp, int threads,
                         std::uint64_t seed, const Camera& camera, int pilot, std::vector<nsp::TechniqueCounts>* chosen) {
    return detail::render_pixels(scene, detail::count_ladder(make), name, res, spp, threads, seed, camera, pilot, chosen);
}

namespace detail {

/// The core of render_image_splatting and render_image_splatting_learned: `ladder` holds the
/// estimator at every candidate pair of counts (NEE x light subpath, NeeCountLearner's order), or
/// one estimator; with `pilot` > 0 the first `pilot` samples of each pixel run ladder[0] (counts
/// 1) with an nsp::NeeCountLearner as their counter, one per 16x16 tile, merged by learn_tiles
/// (so the counts do not depend on the thread count), and the rest of every pixel's samples the
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
        nsp::TileCounts plan(res, res, kTile);
        learn_tiles<Buffers>(plan, run_pool, [&](Buffers& out, nsp::NeeCountLearner& learner, int x, int y) {
            run_samples(out, ladder[0], learner, x, y, 0, first, [&](double v) { learner.end_sample(v); });
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
