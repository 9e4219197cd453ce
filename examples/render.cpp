// examples/render.cpp: nsp_render, the example host renderer and the project's main job.
//
// Renders the example scenes (catalogue.hpp, default_scene.hpp) with the path estimators nsp
// offers and prints an efficiency table per light set-up and spectral mode (THEORY 7: LTUV =
// density lookups per sample x variance of one sample). The files of the driver, one concern
// each: cli (the flags), catalogue (the scenes and their defaults), plan (which rows each table
// renders), stats (what a table measures), report and report_scenes (the tables and the
// summary), pictures (the PNG files). The command-line choices become types once, in
// render_combination<S> (render_job.hpp), whose render loops are monomorphic. This file runs the
// plan: the renders in order, with a progress line per render and an estimate of the time left
// (progress.hpp).
//
// Exit codes (tool.hpp, the same in nsp_room and nsp_volume): 0; 1 if a path ended with status
// Aborted or NonFinite (Rejected is what the -reject majorants' rows are for) or a write failed;
// 2 on a bad command line (an unknown flag, a bad value, a flag that selects nothing, an --out
// that cannot be created or written), with a message that names the flag.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "catalogue.hpp"
#include "cli.hpp"
#include "exr_writer.hpp"
#include "pictures.hpp"
#include "plan.hpp"
#include "progress.hpp"
#include "render_job.hpp"
#include "report.hpp"
#include "stats.hpp"
#include "tool.hpp"

namespace {

using namespace nsp_examples;

/// The reference's seeds: seed + this (the rows use seed .. seed + runs - 1, runs <= 1000).
constexpr std::uint64_t kReferenceSeedOffset = 1000000;

double samples_of(const TablePlan& t, int spp) { return double(t.width) * double(t.height) * double(spp); }

/// The renders of table `t` in `progress`: a table is a set-up in a mode, a kind a row's name (the
/// same estimator costs alike in another set-up or mode, up to the table's factor).
std::string progress_table(const TablePlan& t) { return std::string(t.scene.name()) + " " + std::string(t.mode); }

int run(int argc, char** argv) {
    const Options o = parse_command_line(argc, argv);
    if (o.list) {
        list_combinations();
        return kExitOk;
    }
    const std::vector<TablePlan> tables = plan(o);
    if (o.write_exr || o.write_png) require_writable_directory("--out", o.out);
    const bool pictures = o.write_png && o.picture_res > 0;

    Progress progress;
    for (const TablePlan& t : tables) {
        if (t.reference) progress.add(progress_table(t), "reference " + t.reference->name, samples_of(t, *o.reference_spp));
        for (const Candidate& c : t.rows)
            for (int run = 0; run < o.runs; ++run) progress.add(progress_table(t), c.name, samples_of(t, t.spp));
    }
    if (pictures)
        for (const SceneKind kind : o.scenes) {
            const SceneEntry& e = scene_entry(kind);
            progress.add(e.picture_setup + " " + std::string(e.picture_mode), e.picture_estimator, picture_samples(kind, o));
        }
    std::fprintf(stderr, "nsp_render: %zu renders in %zu tables on %d threads\n", progress.planned(), tables.size(),
                 o.threads);
    const auto t0 = std::chrono::steady_clock::now();
    std::size_t id = 0;
    std::uint64_t failed = 0;  // paths that ended Aborted or NonFinite (Rejected: the -reject majorants' rows, by design)
    auto done = [&](const RenderStats& s, const std::string& name) {
        failed += s.aborted + s.nonfinite;
        progress.done(id++, name, s.wall_seconds);
    };
    auto request = [&](const TablePlan& t, std::uint64_t seed, SelectionRule selection) {
        RenderRequest rq;
        rq.scene = t.scene;
        rq.lights = o.lights;
        rq.selection = selection;
        rq.width = t.width;
        rq.height = t.height;
        rq.spp = t.spp;
        rq.threads = o.threads;
        rq.seed = seed;
        rq.estimator = o.estimator;
        rq.majorant = o.majorant;
        return rq;
    };

    std::vector<std::string> summary, sheets;
    for (const TablePlan& t : tables) {
        std::optional<Reference> reference;
        if (t.reference) {
            reference.emplace();
            reference->estimator = t.reference->name;
            reference->spp = *o.reference_spp;
            reference->seed = o.seed + kReferenceSeedOffset;
            RenderRequest rq = request(t, reference->seed, SelectionRule::Uniform);
            rq.spp = reference->spp;
            rq.pixel_stats = true;
            const std::string name = std::string(t.scene.name()) + "_reference_" + std::string(t.mode);
            rq.label = progress.next_label(name);
            std::vector<float> rgb;
            reference->stats = render_in_mode(t.mode, t.reference->index, rq, rgb);
            done(reference->stats, name);
        }
        std::vector<Row> rows;
        std::vector<Image> images;
        for (const Candidate& c : t.rows) {
            Row row{c, {}, {}, {}};
            std::string file = std::string(t.scene.name()) + "_" + c.name;
            if (t.mode != nsp::Mono::name) file.append("_").append(t.mode);
            for (int run = 0; run < o.runs; ++run) {
                RenderRequest rq = request(t, o.seed + std::uint64_t(run), c.selection);
                rq.pixel_stats = reference.has_value();
                rq.learn_nee_counts = c.learned;
                const std::string name = o.runs > 1 ? file + " run " + std::to_string(run + 1) : file;
                rq.label = progress.next_label(name);
                std::vector<float> rgb;
                row.runs.push_back(render_in_mode(t.mode, c.index, rq, rgb));
                done(row.runs.back(), name);
                if (reference) {
                    row.effective.push_back(effective_variance(row.runs.back(), t.spp, *reference));
                    row.effective_image.push_back(effective_image_variance(row.runs.back(), t.spp, *reference));
                    row.runs.back().pixel_mean = {};
                    row.runs.back().pixel_variance = {};
                }
                if (run > 0) continue;
                if (o.write_exr)
                    write_exr_rgb((std::filesystem::path(o.out) / (file + ".exr")).string(), t.width, t.height, rgb);
                if (o.write_png) images.push_back({t.width, t.height, std::move(rgb)});
            }
            rows.push_back(std::move(row));
        }
        print_table(t, o, rows, reference ? &*reference : nullptr);
        if (o.write_png) sheets.push_back(write_table_sheet(t, images, o));
        summary.push_back(summary_line(t, rows));
    }
    std::vector<std::string> picture_paths;
    if (pictures)
        for (const SceneKind kind : o.scenes) {
            const SceneEntry& e = scene_entry(kind);
            const std::string name = e.name + " picture (" + e.picture_setup + ", " + e.picture_estimator + ", " +
                                     std::to_string(o.picture_res) + "^2 x " + std::to_string(e.picture_spp) + " spp)";
            const auto p0 = std::chrono::steady_clock::now();
            picture_paths.push_back(render_scene_picture(kind, o, progress.next_label(name)));
            progress.done(id++, name, std::chrono::duration<double>(std::chrono::steady_clock::now() - p0).count());
        }

    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("\nSummary (LTUV and time x variance: lower is better; MIS: the scene's default MIS estimator, "
                "best single strategy: the best of its single strategies in the same table)\n");
    for (const std::string& line : summary) std::printf("  %s\n", line.c_str());
    std::printf("total wall time: %.1f s\n", secs);
    if (o.write_exr) std::printf("EXR images (linear RGB, one per row): %s/\n", o.out.c_str());
    if (!sheets.empty())
        std::printf("contact sheets (every row of a table, in table order): %s/*_sheet.png (%zu files)\n",
                    o.out.c_str(), sheets.size());
    if (!picture_paths.empty()) {
        std::printf("pictures:");
        for (const std::string& p : picture_paths) std::printf(" %s", p.c_str());
        std::printf("\n");
    }
    if (failed == 0) return kExitOk;
    std::fprintf(stderr, "nsp_render: %llu paths ended with status Aborted or NonFinite\n", (unsigned long long)failed);
    return kExitRuntime;
}

}  // namespace

int main(int argc, char** argv) {
    return run_tool("nsp_render", [&] { return run(argc, argv); });
}
