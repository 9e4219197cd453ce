// examples/render.cpp: nsp_render, the example host renderer and the project's main job.
//
// Renders the example scenes (catalogue.hpp, default_scene.hpp) with the path estimators nsp
// offers and prints an efficiency table per light set-up and spectral mode (THEORY 7: LTUV =
// density lookups per sample x variance of one sample). The files of the driver, one concern
// each: cli (the flags), catalogue (the scenes and their defaults), plan (which rows each table
// renders), stats (what a table measures), report and report_scenes (the tables and the
// summary), pictures (the PNG files). The command-line choices become types once, in
// render_combination<S> (render_job.hpp), whose render loops are monomorphic. This file runs the
// plan: the renders in order, with progress and an estimate of the time left.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "catalogue.hpp"
#include "cli.hpp"
#include "exr_writer.hpp"
#include "pictures.hpp"
#include "plan.hpp"
#include "render_job.hpp"
#include "report.hpp"
#include "stats.hpp"

namespace {

using namespace nsp_examples;

/// The reference's seeds: seed + this (the rows use seed .. seed + runs - 1, runs <= 1000).
constexpr std::uint64_t kReferenceSeedOffset = 1000000;

/// The time left, from the seconds per sample measured so far in each scene (the scenes' costs
/// per sample differ by 20x; a scene not rendered yet is taken at the mean of all so far).
class TimeLeft {
public:
    /// `remaining`: the samples still to render, per scene.
    explicit TimeLeft(std::map<SceneKind, double> remaining) : remaining_(std::move(remaining)) {}

    void done(SceneKind kind, double samples, double seconds) {
        remaining_[kind] -= samples;
        measured_[kind].first += samples;
        measured_[kind].second += seconds;
    }
    /// "about 2 min 10 s left", or "" before anything was measured.
    std::string text() const {
        double samples = 0.0, seconds = 0.0;
        for (const auto& [kind, m] : measured_) samples += m.first, seconds += m.second;
        if (!(samples > 0.0)) return "";
        double left = 0.0;
        for (const auto& [kind, n] : remaining_) {
            const auto m = measured_.find(kind);
            const double rate = m != measured_.end() && m->second.first > 0.0 ? m->second.second / m->second.first
                                                                                : seconds / samples;
            left += std::max(0.0, n) * rate;
        }
        const long s = long(left + 0.5);
        return s >= 60 ? "about " + std::to_string(s / 60) + " min " + std::to_string(s % 60) + " s left"
                       : "about " + std::to_string(s) + " s left";
    }

private:
    std::map<SceneKind, double> remaining_;
    std::map<SceneKind, std::pair<double, double>> measured_;  // samples, seconds
};

double samples_of(const TablePlan& t, int spp) { return double(t.width) * double(t.height) * double(spp); }

int run(const Options& o) {
    if (o.list) {
        list_combinations();
        return 0;
    }
    const std::vector<TablePlan> tables = plan(o);
    if (o.write_exr || o.write_png) std::filesystem::create_directories(o.out);
    const bool pictures = o.write_png && o.picture_res > 0;

    std::size_t total = 0;
    std::map<SceneKind, double> remaining;
    for (const TablePlan& t : tables) {
        total += t.rows.size() * std::size_t(o.runs) + (t.reference ? 1 : 0);
        remaining[t.scene.kind] += double(t.rows.size() * std::size_t(o.runs)) * samples_of(t, t.spp) +
                                   (t.reference ? samples_of(t, *o.reference_spp) : 0.0);
    }
    if (pictures)
        for (const SceneKind kind : o.scenes) ++total, remaining[kind] += picture_samples(kind, o);
    std::fprintf(stderr, "nsp_render: %zu renders in %zu tables on %d threads\n", total, tables.size(), o.threads);
    TimeLeft left(remaining);
    const auto t0 = std::chrono::steady_clock::now();
    std::size_t done = 0;
    auto label = [&](const std::string& name) {
        std::ostringstream os;  // not "[" + std::to_string(..): GCC 12 warns (-Wrestrict, bug 105329)
        os << '[' << ++done << '/' << total << "] " << name;
        if (const std::string eta = left.text(); !eta.empty()) os << " (" << eta << ")";
        return os.str();
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
            rq.label = label(std::string(t.scene.name()) + "_reference_" + std::string(t.mode));
            std::vector<float> rgb;
            reference->stats = render_in_mode(t.mode, t.reference->index, rq, rgb);
            left.done(t.scene.kind, samples_of(t, rq.spp), reference->stats.wall_seconds);
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
                rq.label = label(o.runs > 1 ? file + " run " + std::to_string(run + 1) : file);
                std::vector<float> rgb;
                row.runs.push_back(render_in_mode(t.mode, c.index, rq, rgb));
                left.done(t.scene.kind, samples_of(t, t.spp), row.runs.back().wall_seconds);
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
            picture_paths.push_back(render_scene_picture(kind, o, label(name)));
            left.done(kind, picture_samples(kind, o),
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - p0).count());
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
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const Options o = parse_command_line(argc, argv);
    try {
        return run(o);
    } catch (const std::exception& e) {
        std::cerr << "nsp_render: error: " << e.what() << "\n";
        return 1;
    }
}
