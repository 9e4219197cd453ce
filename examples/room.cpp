// examples/room.cpp: nsp_room, the main job's scene with surfaces (room_scene.hpp): the cloud over
// a diffuse floor in an open room under a small rectangular light and a dim sky, rendered by
// nsp::PathEstimator over an nsp::SurfaceScene with every strategy that renders surfaces, and the
// efficiency table the other scenes have (docs/renderer.md reads it).
//
//   nsp_room [--res N] [--spp N] [--threads N] [--out DIR] [--no-png] [--picture-res N]
//
// Writes DIR/room_sheet.png (every row at one exposure) and DIR/room.png (uni-nee-mis, balance,
// 128 spp, --picture-res pixels square) unless --no-png.
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "png_writer.hpp"
#include "room_scene.hpp"

namespace {

using nsp_examples::RoomScene;

double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// What one render measured.
struct Row {
    std::string name;
    double seconds = 0.0, cpu_seconds = 0.0, lookups = 0.0, variance = 0.0, mean = 0.0, se = 0.0;
    std::uint64_t failed = 0;  ///< paths with a status other than Ok
    nsp_examples::Image image;
};

/// Renders the room with `estimator` at res x res, spp samples per pixel, one Pcg32 stream per
/// pixel (seeded by `seed`), rows shared among `threads` workers.
template <class E>
Row render(const RoomScene& scene, const E& estimator, const std::string& name, int res, int spp, int threads,
           std::uint64_t seed) {
    Row row;
    row.name = name;
    row.image.width = row.image.height = res;
    row.image.rgb.assign(std::size_t(res) * std::size_t(res) * 3u, 0.f);
    std::vector<double> pixel_var(std::size_t(res) * std::size_t(res), 0.0);
    std::atomic<int> next{0};
    struct Totals {
        std::uint64_t lookups = 0, failed = 0;
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
                for (int k = 1; k <= spp; ++k) {
                    const float u = (float(x) + rng.uniform()) / float(res);
                    const float v = 1.f - (float(y) + rng.uniform()) / float(res);
                    const auto r = estimator.radiance(scene, nsp_examples::room_camera_ray(u, v, 1.f), {}, rng, counter);
                    if (r.status != nsp::Status::Ok) ++out.failed;
                    const double L = r.value[0], d = L - mean;
                    mean += d / k;
                    m2 += d * (L - mean);
                }
                for (int c = 0; c < 3; ++c) row.image.rgb[3 * pixel + std::size_t(c)] = float(mean);
                pixel_var[pixel] = m2 / (spp - 1);
            }
        out.lookups = counter.count();
        out.cpu = thread_cpu_seconds() - cpu0;
    };
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(work, std::ref(totals[std::size_t(t)]));
    for (auto& t : pool) t.join();
    row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double lookups = 0.0;
    for (const Totals& t : totals) {
        lookups += double(t.lookups);
        row.cpu_seconds += t.cpu;
        row.failed += t.failed;
    }
    const double n_pixels = double(res) * res, samples = n_pixels * spp;
    double sum_var = 0.0, sum_mean = 0.0;
    for (std::size_t p = 0; p < pixel_var.size(); ++p) {
        sum_var += pixel_var[p];
        sum_mean += row.image.rgb[3 * p];
    }
    row.lookups = lookups / samples;
    row.variance = sum_var / n_pixels;
    row.mean = sum_mean / n_pixels;
    row.se = std::sqrt(row.variance / samples);  // the image mean's standard error (pixels independent)
    return row;
}

}  // namespace

int main(int argc, char** argv) {
    int res = 96, spp = 256, threads = int(std::max(1u, std::thread::hardware_concurrency())), picture_res = 256;
    std::string out = "out";
    bool no_png = false;
    CLI::App app("nsp_room: the cloud over a floor in an open room, every surface strategy, one efficiency table",
                 "nsp_room");
    app.add_option("--res", res, "image width and height in pixels")->check(CLI::Range(1, 4096));
    app.add_option("--spp", spp, "samples per pixel")->check(CLI::Range(2, 1 << 20));
    app.add_option("--threads", threads, "worker threads")->check(CLI::Range(1, 256));
    app.add_option("--out", out, "directory for the PNG pictures");
    app.add_option("--picture-res", picture_res, "size of room.png")->check(CLI::Range(16, 4096));
    app.add_flag("--no-png", no_png, "write no pictures");
    CLI11_PARSE(app, argc, argv);

    const RoomScene scene = nsp_examples::make_room_scene();
    using namespace nsp;
    std::vector<Row> rows;
    std::uint64_t seed = 1;
    auto run = [&](const auto& estimator, const char* name) {
        rows.push_back(render(scene, estimator, name, res, spp, threads, seed++));
        std::fprintf(stderr, "  room: %-28s %6.2f s\n", name, rows.back().seconds);
    };
    run(PathEstimator<strategy::Unidirectional>{}, "unidirectional");
    run(PathEstimator<strategy::NextEvent>{}, "ratio-nee");
    run(PathEstimator<strategy::DirectionalMis, mis::Balance>{}, "directional-mis_balance");
    run(PathEstimator<strategy::DirectionalMis, mis::Power>{}, "directional-mis_power");
    run(PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
    run(PathEstimator<strategy::NullScatteringMis, mis::Power>{}, "uni-nee-mis_power");
    const std::size_t reference = 4;  // uni-nee-mis_balance: the z column compares every mean with it

    double best = kInf;
    for (const Row& r : rows) best = std::min(best, r.cpu_seconds / (double(res) * res * spp) * r.variance);
    std::printf("\nRoom (mono, %dx%d, %d spp, %d threads): the cloud over a floor, a quad light and a sky\n", res, res,
                spp, threads);
    std::printf("%-28s %8s %11s %11s %11s %11s %10s %9s %6s\n", "estimator", "seconds", "lookups/spl", "var/spl",
                "LTUV", "cpu-s*var", "cpu/best", "mean", "z");
    for (const Row& r : rows) {
        const double cpu_var = r.cpu_seconds / (double(res) * res * spp) * r.variance;
        const Row& ref = rows[reference];
        const double z = &r == &ref ? 0.0 : std::abs(r.mean - ref.mean) / std::hypot(r.se, ref.se);
        std::printf("%-28s %8.2f %11.3g %11.3g %11.3g %11.3g %10.3g %9.4g %6.2f\n", r.name.c_str(), r.seconds,
                    r.lookups, r.variance, r.lookups * r.variance, cpu_var, cpu_var / best, r.mean, z);
    }
    std::uint64_t failed = 0;
    for (const Row& r : rows) failed += r.failed;
    std::printf("var/spl: per-pixel sample variance, averaged over pixels; cpu-s*var: thread CPU seconds per sample x "
                "var/spl (lower is better; cpu/best against the best row). z: |mean - mean of uni-nee-mis_balance| in "
                "combined standard errors of the image means. Paths with a failed status: %llu\n",
                static_cast<unsigned long long>(failed));
    auto cost = [&](std::size_t i) { return rows[i].cpu_seconds * rows[i].variance; };
    const std::size_t best_single = cost(0) <= cost(1) ? 0 : 1;
    std::printf("room: uni-nee-mis_balance / best single strategy (%s) in cpu-s*var: %.3g; unidirectional / ratio-nee: %.3g\n",
                rows[best_single].name.c_str(), cost(reference) / cost(best_single), cost(0) / cost(1));

    if (!no_png) {
        std::filesystem::create_directories(out);
        std::vector<nsp_examples::Tile> tiles;
        std::vector<const nsp_examples::Image*> images;
        for (std::size_t i = 0; i < rows.size(); ++i) {
            tiles.push_back({std::to_string(i + 1) + " " + rows[i].name, &rows[i].image});
            images.push_back(&rows[i].image);
        }
        const float exposure = nsp_examples::exposure_for(images);
        nsp_examples::write_contact_sheet(out + "/room_sheet.png", tiles, exposure);
        const Row picture = render(scene, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "picture",
                                   picture_res, 128, threads, 99);
        nsp_examples::write_png(out + "/room.png", picture.image, nsp_examples::exposure_for({&picture.image}));
        std::fprintf(stderr, "  room: %s/room_sheet.png, %s/room.png (%.1f s)\n", out.c_str(), out.c_str(), picture.seconds);
    }
    return failed == 0 ? 0 : 1;
}
