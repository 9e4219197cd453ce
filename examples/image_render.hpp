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

#include "png_writer.hpp"

namespace nsp_examples {

inline double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// What one render measured.
struct Row {
    std::string name;
    double seconds = 0.0, cpu_seconds = 0.0, lookups = 0.0, variance = 0.0, mean = 0.0, se = 0.0;
    double steps = 0.0;  ///< majorant DDA steps per sample (grid and tree majorants)
    std::uint64_t failed = 0;  ///< paths with a status other than Ok
    nsp_examples::Image image;
};

/// Renders `scene` with `estimator` at res x res through `camera(u, v)` ((u, v) in [0, 1)^2, v up),
/// spp samples per pixel, one Pcg32 stream per pixel (seeded by `seed`), rows shared among
/// `threads` workers. The per-pixel statistics are of the channel mean of each sample (Mono: its value).
template <class Sc, class E, class Camera>
Row render_image(const Sc& scene, const E& estimator, const std::string& name, int res, int spp, int threads,
                 std::uint64_t seed, const Camera& camera) {
    constexpr int kChannels = Sc::Spectral::channels;
    Row row;
    row.name = name;
    row.image.width = row.image.height = res;
    row.image.rgb.assign(std::size_t(res) * std::size_t(res) * 3u, 0.f);
    std::vector<double> pixel_var(std::size_t(res) * std::size_t(res), 0.0), pixel_mean(pixel_var.size(), 0.0);
    std::atomic<int> next{0};
    struct Totals {
        std::uint64_t lookups = 0, steps = 0, failed = 0;
        double cpu = 0.0;
    };
    std::vector<Totals> totals(static_cast<std::size_t>(threads));
    const auto start = std::chrono::steady_clock::now();
    auto work = [&](Totals& out) {
        const double cpu0 = thread_cpu_seconds();
        nsp::LookupCount counter;
        for (int y; (y = next.fetch_add(1)) < res;)
            for (int x = 0; x < res; ++x) {
                const std::size_t pixel = std::size_t(y) * std::size_t(res) + std::size_t(x);
                nsp::Pcg32 rng(seed, pixel);
                double mean = 0.0, m2 = 0.0;
                std::array<double, 3> rgb{};
                for (int k = 1; k <= spp; ++k) {
                    const float u = (float(x) + rng.uniform()) / float(res);
                    const float v = 1.f - (float(y) + rng.uniform()) / float(res);
                    const auto r = estimator.radiance(scene, camera(u, v), {}, rng, counter);
                    if (r.status != nsp::Status::Ok) ++out.failed;
                    for (int c = 0; c < 3; ++c) rgb[std::size_t(c)] += r.value[kChannels == 3 ? c : 0];
                    const double L = double(r.value.mean()), d = L - mean;
                    mean += d / k;
                    m2 += d * (L - mean);
                }
                for (int c = 0; c < 3; ++c) row.image.rgb[3 * pixel + std::size_t(c)] = float(rgb[std::size_t(c)] / spp);
                pixel_mean[pixel] = mean;
                pixel_var[pixel] = m2 / (spp - 1);
            }
        out.lookups = counter.count();
        out.steps = counter.steps;
        out.cpu = thread_cpu_seconds() - cpu0;
    };
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(work, std::ref(totals[std::size_t(t)]));
    for (auto& t : pool) t.join();
    row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double lookups = 0.0, steps = 0.0;
    for (const Totals& t : totals) {
        lookups += double(t.lookups);
        steps += double(t.steps);
        row.cpu_seconds += t.cpu;
        row.failed += t.failed;
    }
    const double n_pixels = double(res) * res, samples = n_pixels * spp;
    double sum_var = 0.0, sum_mean = 0.0;
    for (std::size_t p = 0; p < pixel_var.size(); ++p) {
        sum_var += pixel_var[p];
        sum_mean += pixel_mean[p];
    }
    row.lookups = lookups / samples;
    row.steps = steps / samples;
    row.variance = sum_var / n_pixels;
    row.mean = sum_mean / n_pixels;
    row.se = std::sqrt(row.variance / samples);  // the image mean's standard error (pixels independent)
    return row;
}

}  // namespace nsp_examples
