// examples/room.cpp: nsp_room, the main job's scene with surfaces (room_scene.hpp): the cloud over
// a diffuse floor in an open room under a small rectangular light and a dim sky, rendered over an
// nsp::SurfaceScene with the efficiency tables the other scenes have (docs/surfaces.md reads
// them): the grey cloud (Mono, 96x96 by default) with every strategy of nsp::PathEstimator that
// renders surfaces (the equiangular ones aimed at the lamp's centre) and nsp::BdptEstimator, then the chromatic cloud
// (Rgb, half the size and spp) with the grey-majorant PathEstimator against
// nsp::SpectralPathEstimator's per-channel pdfs and grey BDPT against nsp::SpectralBdptEstimator,
// then the glowing plume (the cloud's smoke with a
// flame in it, an emissive medium; Mono, half the size and spp) with emission and lights in one MIS,
// then the lantern (the lamp boxed above the cloud, opening into it: the BDPT scene; half the
// size and spp) with the path tracers against BdptEstimator's directional and null-scattering MIS
// and BDPT with its expected counts learned (_learned: nsp::NeeCountLearner over the image), then
// the chromatic lantern (the chromatic cloud in it; Rgb) with the spectral path tracers against
// BDPT with one pdf (directional and null-scattering MIS) and with every channel's pdfs. The
// grey room's and the plume's tables end with uni + NEE MIS at counts learned per 16x16 tile.
// On request (--tables cloud) the main job's cloud in empty space, set-ups A and B, as a
// SurfaceScene (its sphere light a shape the geometry reports), path tracers against BDPT; and
// (--tables sky) the grey room's BDPT with and without light subpaths from the sky.
//
//   nsp_room [--res N] [--spp N] [--threads N] [--out DIR] [--no-png] [--picture-res N]
//            [--tables grey,rgb,plume,lantern,lantern-rgb,cloud,sky] [--seed N]
//
// Writes DIR/room_sheet.png, DIR/room_rgb_sheet.png, DIR/room_plume_sheet.png,
// DIR/lantern_sheet.png and DIR/lantern_rgb_sheet.png (each table's rows at one exposure; with
// --tables sky or cloud also DIR/room_sky_sheet.png, DIR/cloud_bdpt_sheet.png) and
// DIR/room.png (the grey room, uni-nee-mis balance, 128 spp, --picture-res pixels square) unless
// --no-png. Exits 1 if any path ended with a status other than Ok.
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
#include <type_traits>
#include <vector>

#include <CLI/CLI.hpp>

#include "combinations.hpp"
#include "image_render.hpp"
#include "png_writer.hpp"
#include "render_job.hpp"
#include "room_scene.hpp"
#include "scene_choice.hpp"

namespace {

using nsp_examples::Row;

/// The room's image with the room's camera.
template <class Sc, class E>
Row render(const Sc& scene, const E& estimator, const std::string& name, int res, int spp, int threads,
           std::uint64_t seed) {
    return nsp_examples::render_image(scene, estimator, name, res, spp, threads, seed,
                                      [](float u, float v) { return nsp_examples::room_camera_ray(u, v, 1.f); });
}

/// The room's image with light tracing: BdptEstimator::sample through room_pinhole(), splats included.
template <class Sc, class E>
Row render_splatting(const Sc& scene, const E& estimator, const std::string& name, int res, int spp, int threads,
                     std::uint64_t seed) {
    return nsp_examples::render_image_splatting(scene, estimator, nsp_examples::room_pinhole(), name, res, spp, threads,
                                                seed);
}

/// CPU seconds x variance of row i: what cpu-s*var orders by (per sample, up to a common factor).
double cost(const std::vector<Row>& rows, std::size_t i) { return rows[i].cpu_seconds * rows[i].variance; }

/// Prints one efficiency table; `reference` is the row the z column compares with. Returns the
/// number of paths with a failed status.
std::uint64_t print_table(const char* title, const std::vector<Row>& rows, std::size_t reference, int res, int spp,
                          int threads, const char* scene = "the cloud over a floor, a quad light and a sky") {
    const double samples = double(res) * res * spp;
    double best = nsp::kInf;
    for (const Row& r : rows)  // a row that found nothing (variance 0: e.g. unidirectional missing a tiny light) is no best
        if (r.variance > 0.0) best = std::min(best, r.cpu_seconds / samples * r.variance);
    std::printf("\n%s, %dx%d, %d spp, %d threads): %s\n", title, res, res, spp, threads, scene);
    std::printf("%-38s %8s %11s %11s %11s %11s %10s %9s %6s\n", "estimator", "seconds", "lookups/spl", "var/spl",
                "LTUV", "cpu-s*var", "cpu/best", "mean", "z");
    std::uint64_t failed = 0;
    const Row& ref = rows[reference];
    for (const Row& r : rows) {
        const double cpu_var = r.cpu_seconds / samples * r.variance;
        const double z = &r == &ref ? 0.0 : std::abs(r.mean - ref.mean) / std::hypot(r.se, ref.se);
        std::printf("%-38s %8.2f %11.3g %11.3g %11.3g %11.3g %10.3g %9.4g %6.2f\n", r.name.c_str(), r.seconds,
                    r.lookups, r.variance, r.lookups * r.variance, cpu_var, cpu_var / best, r.mean, z);
        failed += r.failed;
    }
    std::printf("var/spl: per-pixel sample variance of the channel mean, averaged over pixels (bdpt rows with light "
                "tracing: from 8 batch images, as their splats land in other pixels); cpu-s*var: thread CPU "
                "seconds per sample x var/spl (lower is better; cpu/best against the best row). z: |mean - mean of %s| "
                "in combined standard errors of the image means. Paths with a failed status: %llu\n",
                ref.name.c_str(), static_cast<unsigned long long>(failed));
    return failed;
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
    std::uint64_t seed_offset = 0;
    app.add_option("--seed", seed_offset, "added to every row's seed (independent runs)");
    std::vector<std::string> tables{"grey", "rgb", "plume", "lantern", "lantern-rgb"};  // "cloud", "sky" on request
    app.add_option("--tables", tables,
                   "which tables to render (default: grey,rgb,plume,lantern,lantern-rgb; cloud: the main job's cloud, set-ups A "
                   "and B, with BDPT; sky: the grey room's BDPT with and without light subpaths from the sky; empty: "
                   "nsp_render's other scenes, SA, F1-F3, C1, C2, P1, with BDPT)")
        ->check(CLI::IsMember({"grey", "rgb", "plume", "lantern", "lantern-rgb", "cloud", "sky", "empty"}))
        ->delimiter(',');
    std::vector<std::string> empty_setups{"SA", "F1", "F2", "F3", "C1", "C2", "P1"};
    app.add_option("--setups", empty_setups, "with --tables empty: which of nsp_render's set-ups to render (default: all)")
        ->check(CLI::IsMember({"SA", "F1", "F2", "F3", "C1", "C2", "P1"}))
        ->delimiter(',');
    CLI11_PARSE(app, argc, argv);
    auto want = [&](const char* t) { return std::find(tables.begin(), tables.end(), t) != tables.end(); };

    using namespace nsp;
    seed_offset *= 1000;  // each row takes the next seed: runs 1000 apart share none
    std::uint64_t seed = 1 + seed_offset;
    std::vector<Row> rows;
    int run_res = res, run_spp = spp;
    auto run = [&](const auto& scene, const auto& estimator, const char* name) {
        rows.push_back(render(scene, estimator, name, run_res, run_spp, threads, seed++));
        std::fprintf(stderr, "  room: %-44s %6.2f s\n", name, rows.back().seconds);
    };
    auto run_splatting = [&](const auto& scene, const auto& estimator, const char* name) {
        rows.push_back(render_splatting(scene, estimator, name, run_res, run_spp, threads, seed++));
        std::fprintf(stderr, "  room: %-44s %6.2f s\n", name, rows.back().seconds);
    };

    std::vector<std::string> learned_notes;  // printed under the table they belong to
    auto print_notes = [&] {
        for (const std::string& n : learned_notes) std::printf("%s\n", n.c_str());
        learned_notes.clear();
    };
    // BDPT (null-scattering MIS, balance, light tracing) with its NEE count and light subpath
    // probability learned for the image from a pilot of spp / 32 samples per pixel (2-16) at
    // counts 1 (THEORY 5.9, nsp::NeeCountLearner); the choice printed under the table.
    // `channels`: bdpt::Grey{}, or channels::SpectralMis{} (per-channel pdfs, SpectralBdptEstimator).
    // `roulette`: EstimatorOptions::russian_roulette.
    auto learned_render = [&](const auto& scene, const nsp::PinholeCamera& camera, const char* name, auto channels,
                              bool roulette = true) {
        using Channels = decltype(channels);
        nsp::TechniqueCounts chosen;
        auto make = [roulette](float nee, float light) {
            nsp::EstimatorOptions o = BdptEstimator<>::default_options();
            o.nee_count = nee;
            o.russian_roulette = roulette;
            return BdptEstimator<bdpt::NullScattering, mis::Balance, absorption::Weight, 32, Channels>(o, {}, light);
        };
        const int pilot = nsp_examples::RenderRequest::pilot_spp(run_spp);
        rows.push_back(nsp_examples::render_image_splatting_learned(scene, make, camera, name, run_res, run_spp, threads,
                                                                    seed++, pilot, &chosen));
        std::fprintf(stderr, "  room: %-44s %6.2f s\n", name, rows.back().seconds);
        char text[256];
        std::snprintf(text, sizeof text,
                      "learned counts (%s, a %d-spp pilot at counts 1 over the image): NEE %g, light subpaths %g", name,
                      pilot, double(chosen.nee), double(chosen.light_subpath));
        learned_notes.emplace_back(text);
    };

    // uni + NEE MIS (balance) with its NEE count and emission segment count learned per 16x16 tile
    // from the same pilot (nsp::NeeCountLearner; per tile: every strategy stays in its pixel).
    auto learned_path_render = [&](const auto& scene) {
        const char* name = "uni-nee-mis_balance_learned";
        std::vector<nsp::TechniqueCounts> chosen;
        auto make = [](float nee, float segment) {
            nsp::EstimatorOptions o;
            o.nee_count = nee;
            o.emission_segment_count = segment;
            return PathEstimator<strategy::NullScatteringMis, mis::Balance>(o);
        };
        const int pilot = nsp_examples::RenderRequest::pilot_spp(run_spp);
        rows.push_back(nsp_examples::render_image_learned(
            scene, make, name, run_res, run_spp, threads, seed++,
            [](float u, float v) { return nsp_examples::room_camera_ray(u, v, 1.f); }, pilot, &chosen));
        std::fprintf(stderr, "  room: %-44s %6.2f s\n", name, rows.back().seconds);
        std::array<int, nsp::NeeCountLearner::kCandidates> nee{}, segment{};
        for (const nsp::TechniqueCounts& c : chosen) {
            ++nee[std::size_t(nsp::NeeCountLearner::candidate_index(c.nee))];
            ++segment[std::size_t(nsp::NeeCountLearner::candidate_index(c.emission_segment))];
        }
        std::string text = "learned counts (" + std::string(name) + ", a " + std::to_string(pilot) +
                           "-spp pilot at counts 1 per 16x16 tile), tiles at 1, 1/2, .., 1/64: NEE";
        for (const int n : nee) text += " " + std::to_string(n);
        text += "; emission segment";
        for (const int n : segment) text += " " + std::to_string(n);
        learned_notes.push_back(text);
    };

    std::uint64_t failed = 0;
    // Table 1: the grey cloud, Mono, one global majorant, every grey strategy.
    const auto grey = nsp_examples::make_room_scene();
    if (want("grey")) {
        run(grey, PathEstimator<strategy::Unidirectional>{}, "unidirectional");
        run(grey, PathEstimator<strategy::NextEvent>{}, "ratio-nee");
        run(grey, PathEstimator<strategy::DirectionalMis, mis::Balance>{}, "directional-mis_balance");
        run(grey, PathEstimator<strategy::DirectionalMis, mis::Power>{}, "directional-mis_power");
        run(grey, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
        run(grey, PathEstimator<strategy::NullScatteringMis, mis::Power>{}, "uni-nee-mis_power");
        run(grey, PathEstimator<strategy::EquiangularNextEvent>{}, "equiangular-nee");  // aimed at the lamp's centre
        run(grey, PathEstimator<strategy::EquiangularMis, mis::Balance>{}, "equiangular-mis_balance");
        run_splatting(grey, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
        learned_path_render(grey);  // rows[9]; appended, so the rows above keep their seeds
        failed += print_table("Room (mono", rows, 4, res, spp, threads);  // z against uni-nee-mis_balance
        const double best_single = std::min(cost(rows, 0), cost(rows, 1));
        std::printf("room: uni-nee-mis_balance / best single strategy (%s) in cpu-s*var: %.3g; unidirectional / ratio-nee: %.3g\n",
                    rows[cost(rows, 0) <= cost(rows, 1) ? 0 : 1].name.c_str(), cost(rows, 4) / best_single,
                    cost(rows, 0) / cost(rows, 1));
        std::printf("room: uni-nee-mis_balance_learned / best single strategy in cpu-s*var: %.3g\n", cost(rows, 9) / best_single);
        double best_path = nsp::kInf;
        for (std::size_t i = 0; i < rows.size(); ++i)
            if (i != 8) best_path = std::min(best_path, cost(rows, i));
        std::printf("room: bdpt_null-mis_balance / best path tracer in cpu-s*var: %.3g\n", cost(rows, 8) / best_path);
        print_notes();
    }

    // Table 2: the chromatic cloud (extinction 5, 20, 80 per unit density), Rgb: the grey-majorant
    // PathEstimator against SpectralPathEstimator's per-channel pdfs, all uni + NEE MIS.
    const std::size_t first = rows.size();
    if (want("rgb")) {
        using CM = DenseGridMedium<Rgb>;
        const CM chroma = nsp_examples::make_chromatic_medium<Rgb>();
        const auto chroma_grey = nsp_examples::make_room_scene(chroma, GlobalMajorant<CM>(chroma));
        const auto chroma_channel = nsp_examples::make_room_scene(chroma, ChannelMajorant<CM>(chroma));
        seed = 7 + seed_offset;  // each table its own seeds: a row added to one table leaves the others' numbers as they were
        run_res = std::max(1, res / 2);  // the chromatic cloud costs about 4x the lookups: half the size, half the spp
        run_spp = std::max(2, spp / 2);
        run(chroma_grey, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_grey_balance");
        run(chroma_grey, SpectralPathEstimator<channels::SpectralTrackingAverage, strategy::NullScatteringMis, mis::Balance>{},
            "uni-nee-mis_spectral-tracking-avg");
        run(chroma_grey, SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>{},
            "uni-nee-mis_spectral-mis_global");
        run(chroma_channel, SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>{},
            "uni-nee-mis_spectral-mis_per-channel");
        // BDPT (light tracing on), grey pdfs under the grey majorant and per-channel pdfs under the
        // per-channel majorant; appended, so the rows above keep their seeds.
        run_splatting(chroma_grey, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_grey_balance");
        run_splatting(chroma_channel, SpectralBdptEstimator<mis::Balance>{}, "bdpt_spectral-mis_per-channel");
        learned_render(chroma_channel, nsp_examples::room_pinhole(), "bdpt_spectral-mis_per-channel_learned",
                       channels::SpectralMis{});
        std::vector<Row> chromatic(rows.begin() + std::ptrdiff_t(first), rows.end());
        failed += print_table("Room, chromatic cloud (rgb", chromatic, 3, run_res, run_spp, threads);
        std::printf("room chromatic: grey-majorant PathEstimator / spectral MIS (per-channel majorant) in cpu-s*var: %.3g "
                    "(the grey estimator's variance is practically infinite on this medium: its sample variance "
                    "understates it; docs/chromatic.md)\n",
                    cost(chromatic, 0) / cost(chromatic, 3));
        std::printf("room chromatic: bdpt_spectral-mis_per-channel / uni-nee-mis_spectral-mis_per-channel in cpu-s*var: "
                    "%.3g; / bdpt_null-mis_grey_balance: %.3g\n",
                    cost(chromatic, 5) / cost(chromatic, 3), cost(chromatic, 5) / cost(chromatic, 4));
        std::printf("room chromatic: bdpt_spectral-mis_per-channel_learned / bdpt_spectral-mis_per-channel in "
                    "cpu-s*var: %.3g\n",
                    cost(chromatic, 6) / cost(chromatic, 5));
        print_notes();
    }

    // Table 3: the plume (the cloud's smoke with a flame inside it, an emissive medium), Mono, in
    // the same room: emission and the lights in one MIS.
    const std::size_t first_plume = rows.size();
    run_res = std::max(1, res / 2);
    run_spp = std::max(2, spp / 2);
    if (want("plume")) {
        using PM = Emissive<DenseGridMedium<Mono>>;
        const PM plume = nsp_examples::make_plume_medium<Mono>();
        const auto plume_room = nsp_examples::make_room_scene(plume, GlobalMajorant<PM>(plume));
        seed = 11 + seed_offset;
        run(plume_room, PathEstimator<strategy::Unidirectional>{}, "unidirectional");
        run(plume_room, PathEstimator<strategy::NextEvent>{}, "ratio-nee");
        run(plume_room, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
        run(plume_room, PathEstimator<strategy::EquiangularMis, mis::Balance>{}, "equiangular-mis_balance");
        run_splatting(plume_room, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
        learned_path_render(plume_room);  // plume_rows[5]
        {  // plume_rows[6]: BDPT without its emission segment technique
            EstimatorOptions no_seg = BdptEstimator<>::default_options();
            no_seg.emission_along_segments = false;
            run_splatting(plume_room, BdptEstimator<bdpt::NullScattering, mis::Balance>(no_seg),
                          "bdpt_null-mis_balance_no-seg");
        }
        std::vector<Row> plume_rows(rows.begin() + std::ptrdiff_t(first_plume), rows.end());
        failed += print_table("Room, glowing plume (mono", plume_rows, 2, run_res, run_spp, threads);
        std::printf("room plume: uni-nee-mis_balance / best single strategy (%s) in cpu-s*var: %.3g\n",
                    plume_rows[cost(plume_rows, 0) <= cost(plume_rows, 1) ? 0 : 1].name.c_str(),
                    cost(plume_rows, 2) / std::min(cost(plume_rows, 0), cost(plume_rows, 1)));
        std::printf("room plume: uni-nee-mis_balance_learned / best single strategy in cpu-s*var: %.3g\n",
                    cost(plume_rows, 5) / std::min(cost(plume_rows, 0), cost(plume_rows, 1)));
        const double best_path = std::min({cost(plume_rows, 0), cost(plume_rows, 1), cost(plume_rows, 2),
                                           cost(plume_rows, 3), cost(plume_rows, 5)});
        std::printf("room plume: bdpt_null-mis_balance / best path tracer in cpu-s*var: %.3g; without the segment "
                    "technique: %.3g\n",
                    cost(plume_rows, 4) / best_path, cost(plume_rows, 6) / best_path);
        print_notes();
    }
    // Table 4: the lantern (the BDPT scene): the lamp shut in a box that opens into the cloud,
    // the path tracers against bidirectional path tracing with directional and with full
    // null-scattering MIS; a quarter of the pixels (BDPT costs several paths a sample).
    const std::size_t first_lantern = rows.size();
    if (want("lantern")) {
        const auto lantern = nsp_examples::make_lantern_scene(nsp_examples::make_default_medium<Mono>(),
                                                              GlobalMajorant<DenseGridMedium<Mono>>(nsp_examples::make_default_medium<Mono>()));
        seed = 13 + seed_offset;
        run(lantern, PathEstimator<strategy::Unidirectional>{}, "unidirectional");
        run(lantern, PathEstimator<strategy::NextEvent>{}, "ratio-nee");
        run(lantern, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
        // Each null-scattering row takes its directional row's seed: the same subpaths (the weights
        // draw no random numbers), so the pair differs by its weights alone (a paired comparison).
        const std::uint64_t paired = seed;
        run_splatting(lantern, BdptEstimator<bdpt::Directional, mis::Balance>{}, "bdpt_directional-mis_balance");
        seed = paired;
        run_splatting(lantern, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
        run_splatting(lantern, BdptEstimator<bdpt::NullScattering, mis::Power>{}, "bdpt_null-mis_power");
        const std::uint64_t paired_no_t1 = seed;
        run(lantern, BdptEstimator<bdpt::Directional, mis::Balance>{}, "bdpt_directional-mis_balance_no-t1");
        seed = paired_no_t1;
        run(lantern, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance_no-t1");
        learned_render(lantern, nsp_examples::room_pinhole(), "bdpt_null-mis_balance_learned", bdpt::Grey{});
        std::vector<Row> lantern_rows(rows.begin() + std::ptrdiff_t(first_lantern), rows.end());
        failed += print_table("Lantern (mono", lantern_rows, 4, run_res, run_spp, threads,
                        "the cloud over a floor, lit only by a lamp in a box that opens downward into it");
        std::printf("lantern: bdpt_null-mis_balance / bdpt_directional-mis_balance in cpu-s*var: %.3g (without light "
                    "tracing: %.3g); / best path tracer: %.3g\n",
                    cost(lantern_rows, 4) / cost(lantern_rows, 3), cost(lantern_rows, 7) / cost(lantern_rows, 6),
                    cost(lantern_rows, 4) / std::min({cost(lantern_rows, 0), cost(lantern_rows, 1), cost(lantern_rows, 2)}));
        std::printf("lantern: bdpt_null-mis_balance_learned / bdpt_null-mis_balance in cpu-s*var: %.3g\n",
                    cost(lantern_rows, 8) / cost(lantern_rows, 4));
        print_notes();
    }

    // Table 4b: the chromatic lantern (the chromatic cloud of table 2 in the lantern), Rgb: the
    // spectral path tracers against BDPT with one pdf for all channels (directional and
    // null-scattering MIS, grey majorant) and with every channel's null-scattering pdfs
    // (SpectralBdptEstimator, per-channel majorants). Directional MIS has no distance pdfs, so no
    // per-channel pdfs either: on a chromatic medium it weighs every channel alike.
    const std::size_t first_lantern_rgb = rows.size();
    if (want("lantern-rgb")) {
        using CM = DenseGridMedium<Rgb>;
        const CM chroma = nsp_examples::make_chromatic_medium<Rgb>();
        const auto lantern_grey = nsp_examples::make_lantern_scene(chroma, GlobalMajorant<CM>(chroma));
        const auto lantern_channel = nsp_examples::make_lantern_scene(chroma, ChannelMajorant<CM>(chroma));
        seed = 31 + seed_offset;
        run(lantern_channel, SpectralPathEstimator<channels::SpectralMis, strategy::Unidirectional>{},
            "unidirectional_spectral-mis_per-channel");
        run(lantern_channel, SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>{},
            "uni-nee-mis_spectral-mis_per-channel");
        const std::uint64_t paired = seed;  // the grey pair on the same subpaths, as in the lantern's table
        run_splatting(lantern_grey, BdptEstimator<bdpt::Directional, mis::Balance>{}, "bdpt_directional-mis_grey_balance");
        seed = paired;
        run_splatting(lantern_grey, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_grey_balance");
        run_splatting(lantern_channel, SpectralBdptEstimator<mis::Balance>{}, "bdpt_spectral-mis_per-channel");
        std::vector<Row> lantern_rgb(rows.begin() + std::ptrdiff_t(first_lantern_rgb), rows.end());
        failed += print_table("Lantern, chromatic cloud (rgb", lantern_rgb, 1, run_res, run_spp, threads,
                              "the chromatic cloud over a floor, lit only by a lamp in a box that opens downward into it");
        std::printf("lantern chromatic: bdpt_spectral-mis_per-channel / bdpt_directional-mis_grey_balance in cpu-s*var: "
                    "%.3g; / best path tracer: %.3g (the grey-pdf rows' variance is practically infinite on this medium: "
                    "their sample variance understates it; docs/chromatic.md)\n",
                    cost(lantern_rgb, 4) / cost(lantern_rgb, 2),
                    cost(lantern_rgb, 4) / std::min(cost(lantern_rgb, 0), cost(lantern_rgb, 1)));
    }

    // Table "sky" (--tables sky only): the grey room, BDPT with the sky reached by hits and NEE
    // alone against BDPT whose light subpaths also start from the sky (a BoundingSphere).
    const std::size_t first_sky = rows.size();
    if (want("sky")) {
        const auto sky_room = nsp_examples::make_room_scene(true);
        seed = 29 + seed_offset;
        run_res = res;
        run_spp = spp;
        run(grey, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
        run_splatting(grey, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
        run_splatting(sky_room, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance_sky-subpaths");
        std::vector<Row> sky_rows(rows.begin() + std::ptrdiff_t(first_sky), rows.end());
        failed += print_table("Room, light subpaths from the sky (mono", sky_rows, 0, run_res, run_spp, threads);
        std::printf("sky: bdpt with sky subpaths / without in cpu-s*var: %.3g; / uni-nee-mis_balance: %.3g\n",
                    cost(sky_rows, 2) / cost(sky_rows, 1), cost(sky_rows, 2) / cost(sky_rows, 0));
    }

    // One row over a scene in empty space through the main job's camera: BDPT (an estimator with
    // kMaxPath) with light tracing, the path tracers along the camera's rays.
    auto pinhole_render = [&](const auto& scene, const nsp::PinholeCamera& camera, const auto& estimator, const char* name) {
        if constexpr (requires { estimator.kMaxPath; })
            rows.push_back(nsp_examples::render_image_splatting(scene, estimator, camera, name, run_res, run_spp, threads, seed++));
        else
            rows.push_back(nsp_examples::render_image(scene, estimator, name, run_res, run_spp, threads, seed++,
                                                      [&](float u, float v) { return camera.ray(u, v); }));
        std::fprintf(stderr, "  room: %-44s %6.2f s\n", name, rows.back().seconds);
    };

    // Tables 5 and 6 (--tables cloud only): the main job's cloud scene, set-ups A and B, as a
    // SurfaceScene: the path tracers against BDPT with light tracing through the same camera.
    const std::size_t first_cloud = rows.size();
    if (want("cloud")) {
        for (const nsp_examples::LightSetup setup : {nsp_examples::LightSetup::A, nsp_examples::LightSetup::B}) {
            const auto cloud = nsp_examples::make_cloud_surface_scene(setup);
            const std::size_t first_setup = rows.size();
            seed = (setup == nsp_examples::LightSetup::A ? 17 : 23) + seed_offset;
            auto cloud_render = [&](const auto& estimator, const char* name) {
                pinhole_render(cloud, nsp_examples::cloud_pinhole(), estimator, name);
            };
            cloud_render(PathEstimator<strategy::Unidirectional>{}, "unidirectional");
            cloud_render(PathEstimator<strategy::NextEvent>{}, "ratio-nee");
            cloud_render(PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
            cloud_render(BdptEstimator<bdpt::Directional, mis::Balance>{}, "bdpt_directional-mis_balance");
            cloud_render(BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
            cloud_render(BdptEstimator<bdpt::NullScattering, mis::Balance>(BdptEstimator<>::default_options(), {}, 0.25f),
                         "bdpt_null-mis_balance_light-0.25");  // a light subpath on 1/4 of the samples
            learned_render(cloud, nsp_examples::cloud_pinhole(), "bdpt_null-mis_balance_learned", bdpt::Grey{});
            std::vector<Row> setup_rows(rows.begin() + std::ptrdiff_t(first_setup), rows.end());
            const bool a = setup == nsp_examples::LightSetup::A;
            failed += print_table(a ? "Cloud, set-up A (mono" : "Cloud, set-up B (mono", setup_rows, 2, run_res, run_spp,
                                  threads,
                                  a ? "the main job's cloud in empty space, a small bright sphere light above it"
                                    : "the main job's cloud in empty space, a large dim sphere light behind it");
            std::printf("cloud %s: bdpt_null-mis_balance / best path tracer in cpu-s*var: %.3g; / "
                        "bdpt_directional-mis_balance: %.3g\n",
                        a ? "A" : "B",
                        cost(setup_rows, 4) / std::min({setup_rows[0].variance > 0.0 ? cost(setup_rows, 0) : nsp::kInf,
                                                        cost(setup_rows, 1), cost(setup_rows, 2)}),
                        cost(setup_rows, 4) / cost(setup_rows, 3));
            std::printf("cloud %s: bdpt_null-mis_balance_learned / best path tracer in cpu-s*var: %.3g\n", a ? "A" : "B",
                        cost(setup_rows, 6) / std::min({setup_rows[0].variance > 0.0 ? cost(setup_rows, 0) : nsp::kInf,
                                                        cost(setup_rows, 1), cost(setup_rows, 2)}));
            print_notes();
        }
    }

    // Tables "empty" (--tables empty only): the main job's other scenes in empty space (nsp_render's
    // SA, F1-F3, C1, C2, P1) as SurfaceScenes through its camera: the path tracers against BDPT
    // with light tracing, plain and with its counts learned over the image.
    const std::size_t first_empty = rows.size();
    if (want("empty")) {
        using nsp_examples::SceneChoice;
        using nsp_examples::SceneKind;
        const nsp::PinholeCamera camera = nsp_examples::cloud_pinhole();
        // The path tracers stop at BDPT's 32 real vertices too, so that every row estimates the same
        // integral (at the default 1000, C1's image is 0.1% brighter: 4 SE of BDPT's at 512 spp).
        const EstimatorOptions depth = BdptEstimator<>::default_options();
        run_res = std::max(1, res / 2);
        run_spp = std::max(2, spp / 2);
        // Rows [from, from + n_path) are the path tracers, then BDPT and BDPT learned.
        auto finish = [&](const SceneChoice& c, const char* mode, std::size_t from, std::size_t n_path) {
            std::vector<Row> t(rows.begin() + std::ptrdiff_t(from), rows.end());
            const std::string title = std::string(c.name()) + " in empty space (" + mode;
            failed += print_table(title.c_str(), t, 2, run_res, run_spp, threads,
                                  "nsp_render's scene as a SurfaceScene, every row's paths at most 32 real vertices");
            double best = nsp::kInf;
            for (std::size_t i = 0; i < n_path; ++i)
                if (t[i].variance > 0.0) best = std::min(best, cost(t, i));
            std::printf("%s: bdpt / best path tracer in cpu-s*var: %.3g; bdpt learned: %.3g", c.name(),
                        cost(t, n_path) / best, cost(t, n_path + 1) / best);
            for (std::size_t i = n_path + 2; i < t.size(); ++i) std::printf("; %s: %.3g", t[i].name.c_str(), cost(t, i) / best);
            std::printf("\n");
            print_notes();
        };
        // The grey pdfs' rows of scene `sc`: the path tracers (with the equiangular one when
        // `equiangular`), BDPT, BDPT learned (and then, where a point light gives BDPT its
        // equiangular strategy, BDPT without it; where an emitting medium gives BDPT its segment
        // technique, BDPT without that).
        auto grey_rows = [&](const auto& sc, const SceneChoice& c, const char* mode, auto equiangular,
                             float fixed_light = 0.f) {
            const std::size_t from = rows.size();
            pinhole_render(sc, camera, PathEstimator<strategy::Unidirectional>(depth), "unidirectional");
            pinhole_render(sc, camera, PathEstimator<strategy::NextEvent>(depth), "ratio-nee");
            pinhole_render(sc, camera, PathEstimator<strategy::NullScatteringMis, mis::Balance>(depth), "uni-nee-mis_balance");
            if constexpr (decltype(equiangular)::value)
                pinhole_render(sc, camera, PathEstimator<strategy::EquiangularMis, mis::Balance>(depth), "uni-nee-eq-mis_balance");
            pinhole_render(sc, camera, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
            learned_render(sc, camera, "bdpt_null-mis_balance_learned", bdpt::Grey{});
            // BDPT with one of its strategies off (`off` clears its option), on the seed the next
            // row takes too: the rows after it keep the seeds they had before it.
            auto without = [&](auto off, const char* name) {
                EstimatorOptions o = depth;
                off(o);
                const std::uint64_t next = seed;
                pinhole_render(sc, camera, BdptEstimator<bdpt::NullScattering, mis::Balance>(o), name);
                seed = next;
            };
            // Without its equiangular strategy, where it has one (a point light).
            bool point_light = false;
            for (int k = 0; k < sc.lights.equiangular_count(); ++k) point_light = point_light || sc.lights.equiangular_is_delta(k);
            if (point_light)
                without([](EstimatorOptions& o) { o.bdpt_equiangular = false; }, "bdpt_null-mis_balance_no-eq");
            // Without its segment technique, where it has one (an emitting medium).
            if constexpr (nsp::EmissiveMedium<typename std::remove_cvref_t<decltype(sc)>::MediumType>)
                without([](EstimatorOptions& o) { o.emission_along_segments = false; }, "bdpt_null-mis_balance_no-seg");
            if (fixed_light > 0.f) {  // a fixed light subpath probability, after the learned row
                const std::string name = "bdpt_null-mis_balance_light-1/" + std::to_string(int(std::lround(1.f / fixed_light)));
                pinhole_render(sc, camera,
                               BdptEstimator<bdpt::NullScattering, mis::Balance>(depth, {}, fixed_light),
                               name.c_str());
            }
            finish(c, mode, from, decltype(equiangular)::value ? 4 : 3);
        };
        // Starts set-up c: its own seeds (37 + 100 i, i its place in SA, F1-F3, C1, C2, P1), so that
        // --setups renders a set-up as the whole table does; whether --setups asks for it.
        auto start_setup = [&](const SceneChoice& c) {
            static constexpr const char* order[] = {"SA", "F1", "F2", "F3", "C1", "C2", "P1"};
            const auto at = std::find_if(std::begin(order), std::end(order),
                                         [&](const char* n) { return std::string(n) == c.name(); });
            seed = 37 + 100 * std::uint64_t(at - std::begin(order)) + seed_offset;
            return std::find(empty_setups.begin(), empty_setups.end(), c.name()) != empty_setups.end();
        };
        // Grey: the sparse medium under set-up A's light, the fog under its lamp; grid majorants (16^3).
        for (const SceneChoice c : {SceneChoice{SceneKind::Sparse, nsp_examples::LightSetup::A},
                                    SceneChoice{SceneKind::Fog, {}, {}, nsp_examples::FogSetup::F1},
                                    SceneChoice{SceneKind::Fog, {}, {}, nsp_examples::FogSetup::F2},
                                    SceneChoice{SceneKind::Fog, {}, {}, nsp_examples::FogSetup::F3}}) {
            if (!start_setup(c)) continue;
            const auto sc = nsp_examples::make_setup_surface_scene<Mono, nsp_examples::DenseGridCloud,
                                                                   nsp_examples::GridMajorantPolicy<>>(c);
            grey_rows(sc, c, "mono, grid majorant", std::true_type{});
        }
        // Chromatic: C1 (a white sky), C2 (set-up A's sphere light); Rgb, per-channel majorants.
        for (const SceneChoice c : {SceneChoice{SceneKind::Chromatic, {}, nsp_examples::ChromaticSetup::Env},
                                    SceneChoice{SceneKind::Chromatic, {}, nsp_examples::ChromaticSetup::Small}}) {
            if (!start_setup(c)) continue;
            const auto sc = nsp_examples::make_setup_surface_scene<Rgb, nsp_examples::DenseGridCloud,
                                                                   nsp_examples::ChannelMajorantPolicy>(c);
            const std::size_t from = rows.size();
            pinhole_render(sc, camera, SpectralPathEstimator<channels::SpectralMis, strategy::Unidirectional>(depth),
                           "unidirectional_spectral-mis");
            pinhole_render(sc, camera, SpectralPathEstimator<channels::SpectralMis, strategy::NextEvent>(depth),
                           "ratio-nee_spectral-mis");
            pinhole_render(sc, camera, SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>(depth),
                           "uni-nee-mis_spectral-mis");
            pinhole_render(sc, camera, SpectralBdptEstimator<mis::Balance>{}, "bdpt_spectral-mis");
            learned_render(sc, camera, "bdpt_spectral-mis_learned", channels::SpectralMis{});
            if (c.chromatic == nsp_examples::ChromaticSetup::Env) {
                // C1 without roulette: under the sky every path that escapes carries its
                // throughput, so roulette's survival on it adds more variance than it saves work.
                EstimatorOptions no_rr = depth;
                no_rr.russian_roulette = false;
                pinhole_render(sc, camera, SpectralPathEstimator<channels::SpectralMis, strategy::Unidirectional>(no_rr),
                               "unidirectional_spectral-mis_no-rr");
                learned_render(sc, camera, "bdpt_spectral-mis_learned_no-rr", channels::SpectralMis{}, false);
            }
            finish(c, "rgb, per-channel majorants", from, 3);
        }
        // The plume (an emissive medium, no other light); Rgb (its flame's colour), grid majorant.
        if (const SceneChoice c{SceneKind::Plume}; start_setup(c)) {
            const auto sc = nsp_examples::make_setup_surface_scene<Rgb, nsp_examples::EmissivePlume,
                                                                   nsp_examples::GridMajorantPolicy<>>(c);
            grey_rows(sc, c, "rgb, grid majorant", std::false_type{}, 1.f / 64.f);  // P1: + light subpaths on 1/64
        }
    }

    if (!no_png) {
        std::filesystem::create_directories(out);
        // One contact sheet per table, each at one exposure.
        auto sheet = [&](const std::string& path, std::size_t from, std::size_t to) {
            if (from == to) return;
            std::vector<nsp_examples::Tile> tiles;
            std::vector<const nsp_examples::Image*> images;
            for (std::size_t i = from; i < to; ++i) {
                tiles.push_back({std::to_string(i - from + 1) + " " + rows[i].name, &rows[i].image});
                images.push_back(&rows[i].image);
            }
            nsp_examples::write_contact_sheet(path, tiles, nsp_examples::exposure_for(images));
            std::fprintf(stderr, "  room: %s\n", path.c_str());
        };
        sheet(out + "/room_sheet.png", 0, first);
        sheet(out + "/room_rgb_sheet.png", first, first_plume);
        sheet(out + "/room_plume_sheet.png", first_plume, first_lantern);
        sheet(out + "/lantern_sheet.png", first_lantern, first_lantern_rgb);
        sheet(out + "/lantern_rgb_sheet.png", first_lantern_rgb, first_sky);
        sheet(out + "/room_sky_sheet.png", first_sky, first_cloud);
        sheet(out + "/cloud_bdpt_sheet.png", first_cloud, first_empty);
        sheet(out + "/empty_bdpt_sheet.png", first_empty, rows.size());
        if (want("grey")) {
        const Row picture = render(grey, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "picture",
                                   picture_res, 128, threads, 99);
        nsp_examples::write_png(out + "/room.png", picture.image, nsp_examples::exposure_for({&picture.image}));
        std::fprintf(stderr, "  room: %s/room.png (%.1f s)\n", out.c_str(), picture.seconds);
        }
    }
    return failed == 0 ? 0 : 1;
}
