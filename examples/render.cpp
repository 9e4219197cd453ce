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

/// One render of the run: a combination of a spectral mode, and its request.
struct Job {
    std::string_view mode;
    std::size_t index = 0;
    RenderRequest rq;
};

double samples_of(const RenderRequest& rq) { return double(rq.width) * double(rq.height) * double(rq.spp); }

/// Every render of the run, in the order it runs: per table its reference (--reference-spp),
/// then each row's runs; then the pictures.
std::vector<Job> plan_jobs(const std::vector<TablePlan>& tables, const Options& o, bool pictures) {
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
        rq.pilot_count = o.pilot_count;
        rq.weigh_pilot = o.weigh_pilot;
        rq.lookup_costs = o.lookup_costs;
        rq.scout = o.scout;
        rq.majorant = o.majorant;
        return rq;
    };
    std::vector<Job> jobs;
    for (const TablePlan& t : tables) {
        if (t.reference) {
            Job& j = jobs.emplace_back(Job{t.mode, t.reference->index, request(t, o.seed + kReferenceSeedOffset, SelectionRule::Uniform)});
            j.rq.spp = *o.reference_spp;
            // The reference ratio-tracks its shadow rays whatever --shadow says: one reference
            // for every run, and its estimator may need their path pdfs.
            j.rq.estimator.shadow_estimator = nsp::ShadowEstimator::RatioTracking;
            j.rq.pixel_stats = true;
        }
        for (const Candidate& c : t.rows)
            for (int run = 0; run < o.runs; ++run) {
                Job& j = jobs.emplace_back(Job{t.mode, c.index, request(t, o.seed + std::uint64_t(run), c.selection)});
                j.rq.pixel_stats = t.reference.has_value();
                j.rq.learn_nee_counts = c.learned;
            }
    }
    if (pictures)
        for (const SceneKind kind : o.scenes) {
            const PictureJob p = picture_job(kind, o);
            jobs.push_back({p.mode, p.index, p.rq});
        }
    return jobs;
}

/// Times every job with a pilot at 1/64 of its spp for `progress` (progress.hpp: the costs per
/// sample of the scenes and rows differ by up to 20x, and no rate measured on one predicts
/// another); returns the seconds the pilots took.
double time_jobs(const std::vector<Job>& jobs, Progress& progress) {
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t id = 0; id < jobs.size(); ++id) {
        RenderRequest rq = jobs[id].rq;
        rq.spp = Progress::pilot_spp(rq.spp);
        rq.pixel_stats = false;
        rq.label = "timing the renders: " + std::to_string(id + 1) + "/" + std::to_string(jobs.size());
        std::vector<float> rgb;
        progress.calibrate(id, samples_of(rq), render_in_mode(jobs[id].mode, jobs[id].index, rq, rgb).wall_seconds);
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int run(int argc, char** argv) {
    const Options o = parse_command_line(argc, argv);
    if (o.list) {
        list_combinations();
        return kExitOk;
    }
    const std::vector<TablePlan> tables = plan(o);
    if (o.write_exr || o.write_png) require_writable_directory("--out", o.out);
    const bool pictures = o.write_png && o.picture_res > 0;

    const std::vector<Job> jobs = plan_jobs(tables, o, pictures);
    Progress progress;
    for (const Job& j : jobs) progress.add(samples_of(j.rq));
    std::fprintf(stderr, "nsp_render: %zu renders in %zu tables on %d threads; timing each at 1/64 of its spp\n",
                 jobs.size(), tables.size(), o.threads);
    const auto t0 = std::chrono::steady_clock::now();
    const double pilots = time_jobs(jobs, progress);
    std::fprintf(stderr, "nsp_render: about %s to render (the timing took %.1f s)\n",
                 Progress::duration_text(progress.seconds_left()).c_str(), pilots);
    std::size_t id = 0;
    std::uint64_t failed = 0;  // paths that ended Aborted or NonFinite (Rejected: the -reject majorants' rows, by design)
    // Renders jobs[id] (labelled `name`), counts its failed paths and prints its progress line.
    auto render_job = [&](const std::string& name, std::vector<float>& rgb) {
        RenderRequest rq = jobs[id].rq;
        rq.label = progress.next_label(name);
        const auto start = std::chrono::steady_clock::now();
        const RenderStats s = render_in_mode(jobs[id].mode, jobs[id].index, rq, rgb);
        failed += s.aborted + s.nonfinite;
        progress.done(id++, name, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        return s;
    };

    std::vector<std::string> summary, sheets;
    for (const TablePlan& t : tables) {
        std::optional<Reference> reference;
        if (t.reference) {
            reference.emplace();
            reference->estimator = t.reference->name;
            reference->spp = *o.reference_spp;
            reference->seed = o.seed + kReferenceSeedOffset;
            std::vector<float> rgb;
            reference->stats = render_job(std::string(t.scene.name()) + "_reference_" + std::string(t.mode), rgb);
        }
        std::vector<Row> rows;
        std::vector<Image> images;
        for (const Candidate& c : t.rows) {
            Row row{c, {}, {}, {}};
            std::string file = std::string(t.scene.name()) + "_" + c.name;
            if (t.mode != nsp::Mono::name) file.append("_").append(t.mode);
            for (int run = 0; run < o.runs; ++run) {
                std::vector<float> rgb;
                row.runs.push_back(render_job(o.runs > 1 ? file + " run " + std::to_string(run + 1) : file, rgb));
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
            Image image{o.picture_res, o.picture_res, {}};
            render_job(name, image.rgb);
            picture_paths.push_back(write_scene_picture(kind, o, image));
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
