// examples/volume.cpp: nsp_volume renders a user's volume file (Mitsuba .vol, NanoVDB .nvdb or
// OpenVDB .vdb, examples/volume_files.hpp) with a camera that frames the medium's bounds, under a
// dim white sky and a small sphere light above it, with three strategies of nsp::PathEstimator,
// and prints their efficiency table; or compares the majorants (global, grid 16^3 and 64^3, tree)
// on one strategy; or exports the default cloud or the procedural plume as a file, the data the
// tests, the main job and this example's smoke tests read.
//
//   nsp_volume FILE [--grid NAME] [--channel C] [--density-scale S] [--albedo A] [--g G]
//              [--temperature NAME [--temperature-scale K] [--emission-scale E] [--normalize-blackbody]]
//              [--majorant global|grid|tree|tree-nodes] [--grid-res N] [--tree-step-cost C]
//              [--tree-split N] [--compare-majorants [--runs N]]
//              [--res N] [--spp N] [--threads N] [--out DIR] [--no-png]
//   nsp_volume --export-cloud FILE      (.vol, .nvdb or .vdb)
//   nsp_volume --export-plume FILE [--plume-res N]
//
// The file's values are densities; the medium's extinction is density x density-scale, its albedo
// `albedo` (grey), its phase function Henyey-Greenstein g. A .vol file is a DenseGridMedium (its
// values at voxel centres over its box, clamped at the faces); .nvdb and .vdb grids are
// NanoVdbMedium (values at index points, 0 beyond the active voxels); with --temperature the
// medium also emits blackbody radiance by a second grid's temperature (nsp/media/blackbody.hpp),
// rendered in Rgb. The tree majorant follows a medium's density: 16 coarse cells along the
// longest axis of its bounds, split twice into 4^3 where that pays; tree-nodes puts the cells on
// a NanoVDB grid's nodes (128 -> 32 -> 8 voxels). Writes DIR/volume.png (uni-nee-mis balance, or
// the tree row) unless --no-png; DIR is created, and checked to be writable, before the file is
// read. The table's z column is each row's mean against the reference row's (uni-nee-mis balance;
// with --compare-majorants the global majorant's) in combined standard errors; a row with z > 4
// is flagged and left out of cpu/best (its variance missed a heavy tail at this spp). The flags
// are volume_cli's.
//
// Exit codes (tool.hpp, the same in nsp_render and nsp_room): 0; 1 if a path ended with a status
// other than Ok or a write failed; 2 on a bad command line (an unknown flag, a bad value, a file
// together with an export, an --out that cannot be created or written) or a bad input file
// (missing, a directory, an unknown format, or one its loader rejects, with the loader's message).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nsp/majorants/tree.hpp>

#include "agreement.hpp"
#include "image_render.hpp"
#include "png_writer.hpp"
#include "progress.hpp"
#include "tool.hpp"
#include "volume_cli.hpp"
#include "volume_files.hpp"

namespace {

using nsp_examples::Row;
using nsp_examples::VolumeOptions;

/// Prints the table of `rows` (time x variance against the best row, z against rows[reference])
/// with `extra(row)` columns, then a note on each flagged row.
template <class Extra>
std::uint64_t print_rows(const std::vector<Row>& rows, std::size_t reference, double samples, const char* extra_head,
                         Extra&& extra) {
    std::size_t at = 0;
    nsp_examples::best_cost(rows, reference, {}, &at);
    const double best = at < rows.size() ? rows[at].cpu_seconds / samples * rows[at].variance : nsp::kInf;
    std::printf("%-24s %8s %11s %9s %8s %11s %11s %10s %9s %9s %6s%s\n", "row", "seconds", "lookups/spl", "steps/spl",
                "ns/spl", "var/spl", "cpu-s*var", "cpu/best", "mean", "se", "z", extra_head);
    std::uint64_t failed = 0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const Row& row = rows[i];
        const double cv = row.cpu_seconds / samples * row.variance;
        std::printf("%-24s %8.2f %11.3g %9.3g %8.0f %11.3g %11.3g %10.3g %9.4g %9.2g %6.2f", row.name.c_str(), row.seconds,
                    row.lookups, row.steps, 1e9 * row.cpu_seconds / samples, row.variance, cv, cv / best, row.mean, row.se,
                    nsp_examples::z_score(row, rows[reference]));
        extra(row);
        std::printf("%s\n", nsp_examples::flagged(rows, i, reference) ? " !" : "");
        failed += row.failed;
    }
    std::printf("z: |mean - mean of %s| in combined standard errors of the image means. Paths with a failed status: %llu\n",
                rows[reference].name.c_str(), static_cast<unsigned long long>(failed));
    nsp_examples::print_flag_notes(rows, reference);
    return failed;
}

void write_picture(const Row& row, const VolumeOptions& o) {
    if (o.no_png) return;
    const std::string path = o.out + "/volume.png";
    nsp_examples::write_png(path, row.image, nsp_examples::exposure_for({&row.image}));
    std::printf("wrote %s\n", path.c_str());
}

/// Renders `medium` under `majorant` with the three strategies and prints the table (z against
/// uni-nee-mis balance).
template <class M, class Maj>
std::uint64_t run_strategies(const M& medium, const Maj& majorant, const VolumeOptions& o) {
    using namespace nsp;
    const nsp_examples::VolumeFraming<M> cam(medium);
    const auto scene = Scene(medium, majorant, HenyeyGreensteinPhase(o.g), cam.lights);
    const double samples = double(o.res) * o.res * o.spp;
    // The rows: f(estimator, name, seed) for each.
    auto each_row = [](auto&& f) {
        f(PathEstimator<strategy::Unidirectional>{}, "unidirectional", 1);
        f(PathEstimator<strategy::NextEvent>{}, "ratio-nee", 2);
        f(PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance", 3);
    };
    // Each timed first with a pilot at 1/64 of the spp, for the estimate of the time left.
    nsp_examples::Progress progress;
    each_row([&](const auto& estimator, const char*, std::uint64_t seed) {
        const std::size_t id = progress.add(samples);
        const int spp = nsp_examples::Progress::pilot_spp(o.spp);
        progress.calibrate(id, double(o.res) * o.res * spp,
                           nsp_examples::render_image(scene, estimator, "pilot", o.res, spp, o.threads, seed, cam).seconds);
    });
    std::vector<Row> rows;
    each_row([&](const auto& estimator, const char* name, std::uint64_t seed) {
        rows.push_back(nsp_examples::render_image(scene, estimator, name, o.res, o.spp, o.threads, seed, cam));
        progress.done(rows.size() - 1, name, rows.back().seconds);
    });
    const std::uint64_t failed = print_rows(rows, 2, samples, "", [](const Row&) {});
    write_picture(rows.back(), o);
    return failed;
}

/// The tree majorant: the adaptive layout over the medium's bounds, or with `on_nodes` the cells
/// on a VDB grid's nodes (128 -> 32 -> 8 voxels, and --tree-split more inside the leaves).
template <class M>
nsp::TreeMajorant<M> tree_majorant(const M& m, const VolumeOptions& o, bool on_nodes = false) {
    if constexpr (nsp::TreeLayoutMedium<M>) {
        if (on_nodes) {
            nsp::TreeLayout l = m.tree_layout(o.tree_split);
            l.step_cost = o.tree_step_cost;
            return nsp::TreeMajorant<M>(m, l);
        }
    }
    (void)on_nodes;
    nsp::TreeLayout l = nsp::detail::adaptive_layout(m);
    l.step_cost = o.tree_step_cost;
    return nsp::TreeMajorant<M>(m, l);
}

/// The tree control (nsp::TreeControl) of tree_majorant's adaptive layout: the same cells, each
/// with the medium's density lower bound beside its upper bound.
template <class M>
nsp::TreeControl<M> tree_control(const M& m, const VolumeOptions& o) {
    nsp::TreeLayout l = nsp::detail::adaptive_layout(m);
    l.step_cost = o.tree_step_cost;
    return nsp::TreeControl<M>(m, l);
}

/// Renders `medium` with uni + NEE MIS (balance) under the global majorant, grids of 16^3 and
/// 64^3, the tree majorant and (for a medium with a density lower bound) the tree control, and prints the comparison with each majorant's memory and build
/// time (z against the global majorant's row).
template <class M>
std::uint64_t compare_majorants(const M& medium, const VolumeOptions& o) {
    using namespace nsp;
    const nsp_examples::VolumeFraming<M> cam(medium);
    const PathEstimator<strategy::NullScatteringMis, mis::Balance> est;
    auto timed = [&](auto make) {
        const auto t0 = std::chrono::steady_clock::now();
        auto maj = make();
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        return std::pair{std::move(maj), ms};
    };
    // The cost model's pick (nsp/majorants/choose.hpp), rendered as a row of its own when it is
    // a grid the comparison does not already hold.
    const auto [pick, pick_ms] = timed([&] { return nsp::choose_grid_resolution(medium); });
    const int picked = pick.global ? 0 : pick.resolution[0];
    const bool model_row = picked && picked != 16 && picked != 64;
    std::vector<std::string> names{"global", "grid 16^3", "grid 64^3"};
    if (model_row) names.push_back("grid " + std::to_string(picked) + "^3 (model)");
    if constexpr (TreeLayoutMedium<M>) names.push_back("tree on VDB nodes");
    names.push_back("tree");
    if constexpr (LowerBoundedMedium<M>) names.push_back("tree-control");
    const double samples = double(o.res) * o.res * o.spp;
    nsp_examples::Progress progress;
    for (std::size_t i = 0; i < names.size() * std::size_t(o.runs); ++i) progress.add(samples);  // no pilots: by samples

    std::vector<Row> rows;
    std::vector<std::pair<std::size_t, double>> cost;  // bytes, build milliseconds
    std::uint64_t seed = 1;
    // Each row o.runs times with other seeds; the row reports the median of each column (the
    // variance of one run moves by tens of percent between seeds at these sizes).
    auto run = [&](const auto& maj, double ms, std::size_t bytes) {
        const std::string& name = names[rows.size()];
        const auto scene = Scene(medium, maj, HenyeyGreensteinPhase(o.g), cam.lights);
        std::vector<Row> runs;
        for (int k = 0; k < o.runs; ++k) {
            runs.push_back(nsp_examples::render_image(scene, est, name, o.res, o.spp, o.threads, seed + 1000u * std::uint64_t(k), cam));
            progress.done(rows.size() * std::size_t(o.runs) + std::size_t(k), o.runs > 1 ? name + " run " + std::to_string(k + 1) : name,
                          runs.back().seconds);
        }
        ++seed;
        auto median = [&](double Row::*field) {
            std::vector<double> v;
            for (const Row& r : runs) v.push_back(r.*field);
            std::sort(v.begin(), v.end());
            return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
        };
        Row row = runs.front();
        for (double Row::*f : {&Row::seconds, &Row::cpu_seconds, &Row::lookups, &Row::steps, &Row::variance, &Row::mean, &Row::se})
            row.*f = median(f);
        for (std::size_t k = 1; k < runs.size(); ++k) row.failed += runs[k].failed;
        rows.push_back(std::move(row));
        cost.emplace_back(bytes, ms);
    };
    {
        auto [maj, ms] = timed([&] { return GlobalMajorant<M>(medium); });
        run(maj, ms, sizeof(float));
    }
    std::printf("cost model (choose_grid_resolution, %.0f ms): %s, %.3g lookups + 0.3 x %.3g steps per random line "
                "(global: %.3g lookups)\n",
                pick_ms, picked ? ("grid " + std::to_string(picked) + "^3").c_str() : "global", pick.lookups, pick.steps,
                nsp::global_majorant_cost(medium).lookups);
    for (const int n : {16, 64}) {
        auto [maj, ms] = timed([&] { return GridMajorant<M>(medium, n); });
        run(maj, ms, maj.memory_bytes());
    }
    if (model_row) {
        auto [maj, ms] = timed([&] { return GridMajorant<M>(medium, picked); });
        run(maj, ms, maj.memory_bytes());
    }
    auto describe = [](const char* name, const TreeMajorant<M>& t) {
        const auto l = t.layout();
        std::printf("%s: %dx%dx%d coarse cells (%zu empty, %zu split), then %zu and %zu split cells on the next levels\n",
                    name, l.coarse[0], l.coarse[1], l.coarse[2], t.empty_cells(), t.split_cells(0), t.split_cells(1),
                    t.split_cells(2));
    };
    if constexpr (TreeLayoutMedium<M>) {
        auto [nodes, nodes_ms] = timed([&] { return tree_majorant(medium, o, true); });
        run(nodes, nodes_ms, nodes.memory_bytes());
        describe("tree on VDB nodes", nodes);
    }
    auto [tree, tree_ms] = timed([&] { return tree_majorant(medium, o); });
    run(tree, tree_ms, tree.memory_bytes());
    describe("tree", tree);
    if constexpr (LowerBoundedMedium<M>) {  // the tree's cells with their minorants: decomposition tracking
        auto [ctl, ctl_ms] = timed([&] { return tree_control(medium, o); });
        run(ctl, ctl_ms, ctl.memory_bytes());
    }
    std::size_t i = 0;
    const std::uint64_t failed = print_rows(rows, 0, samples, "  majorant-KiB build-ms", [&](const Row&) {
        std::printf("  %12.1f %8.1f", double(cost[i].first) / 1024.0, cost[i].second);
        ++i;
    });
    write_picture(rows.back(), o);
    return failed;
}

/// Renders `medium` as the options ask (the three strategies under one majorant, or the majorants
/// compared) under the title line "Volume (<mode>, ..., <label>): <scene>"; the exit code.
template <class M>
int render(const M& medium, const VolumeOptions& o, const char* mode, const char* scene) {
    std::string label = o.compare ? "majorants compared, uni-nee-mis balance"
                        : o.majorant == "grid" ? "grid " + std::to_string(o.grid_res) + "^3 majorant"
                        : o.majorant == "grid-control" ? "grid " + std::to_string(o.grid_res) + "^3 majorant and control"
                                               : o.majorant + " majorant";
    if (o.compare && o.runs > 1) label += ", median of " + std::to_string(o.runs) + " runs per row";
    std::printf("Volume (%s, %dx%d, %d spp, %d threads, %s): %s\n", mode, o.res, o.res, o.spp, o.threads, label.c_str(),
                scene);
    std::uint64_t failed = 0;
    if (o.compare) failed = compare_majorants(medium, o);
    else if (o.majorant == "grid") failed = run_strategies(medium, nsp::GridMajorant<M>(medium, o.grid_res), o);
    else if (o.majorant == "grid-control") {
        // Decomposition tracking (THEORY 5.10), over media with a density lower bound.
        if constexpr (nsp::LowerBoundedMedium<M>)
            failed = run_strategies(medium, nsp::GridControl<M>(medium, o.grid_res), o);
        else
            throw nsp_examples::UsageError("--majorant grid-control takes a medium with a density lower bound");
    }
    else if (o.majorant == "tree") failed = run_strategies(medium, tree_majorant(medium, o), o);
    else if (o.majorant == "tree-control") {
        if constexpr (nsp::LowerBoundedMedium<M>)
            failed = run_strategies(medium, tree_control(medium, o), o);
        else
            throw nsp_examples::UsageError("--majorant tree-control takes a medium with a density lower bound");
    }
    else if (o.majorant == "tree-nodes") failed = run_strategies(medium, tree_majorant(medium, o, true), o);
    else failed = run_strategies(medium, nsp::GlobalMajorant<M>(medium), o);
    if (failed == 0) return nsp_examples::kExitOk;
    std::fprintf(stderr, "nsp_volume: %llu paths ended with a status other than Ok\n", static_cast<unsigned long long>(failed));
    return nsp_examples::kExitRuntime;
}

using nsp_examples::usage_checked;

/// --export-cloud / --export-plume: the path checked first (format, directory), then written.
int export_volume(const VolumeOptions& o) {
    const bool plume = !o.export_plume.empty();
    const std::string& path = plume ? o.export_plume : o.export_cloud;
    const char* flag = plume ? "--export-plume" : "--export-cloud";
    const std::string ext = nsp_examples::extension_of(path);
    usage_checked([&] { nsp_examples::require_format(path, ext); });
    if (plume && ext == ".vol" && o.plume_res > 256)
        throw nsp_examples::UsageError("--plume-res " + std::to_string(o.plume_res) +
                                       ": a .vol file is dense; use a resolution <= 256 or .nvdb / .vdb");
    nsp_examples::require_writable_file(flag, path);
    nsp_examples::write_volume(
        path, [&] { return plume ? nsp_examples::plume_voxels(o.plume_res) : nsp_examples::cloud_voxels(); }, o.plume_res,
        plume);
    if (plume) std::printf("wrote %s: the smoke plume, %d^3 voxels over [-1, 1]^3\n", path.c_str(), o.plume_res);
    else std::printf("wrote %s: the default cloud, 64x64x64 voxels over [-1, 1]^3\n", path.c_str());
    return nsp_examples::kExitOk;
}

/// A .vol file as a DenseGridMedium, rendered.
int render_vol(const VolumeOptions& o) {
    using M = nsp::DenseGridMedium<nsp::Mono>;
    const nsp::io::VoxelGrid grid = usage_checked([&] { return nsp::io::load_vol(o.file); });
    const M medium = usage_checked([&] {
        return nsp::io::to_dense_medium<nsp::Mono>(grid, nsp::Mono::Spectrum::Constant(o.density_scale * (1.f - o.albedo)),
                                                   nsp::Mono::Spectrum::Constant(o.density_scale * o.albedo), o.channel);
    });
    const nsp::Vec3 lo = grid.bounds.lo, hi = grid.bounds.hi;
    std::printf("%s: %dx%dx%d voxels, %d channel(s), box [%g, %g, %g] - [%g, %g, %g], largest extinction %g, "
                "%.1f MiB dense\n",
                o.file.c_str(), grid.resolution[0], grid.resolution[1], grid.resolution[2], grid.channels, lo.x, lo.y, lo.z,
                hi.x, hi.y, hi.z, double(medium.max_extinction()), double(grid.voxels()) * 4.0 / (1 << 20));
    return render(medium, o, "mono", "a dim sky and a small sphere light");
}

#if NSP_HAVE_NANOVDB
/// A .nvdb or .vdb file's grids as a NanoVdbMedium (Mono), or with --temperature an emitting
/// medium (Rgb: grey coefficients, blackbody radiance by temperature), rendered.
int render_nanovdb(const VolumeOptions& o, const std::string& ext) {
    auto load = [&](const std::string& name) {
        return usage_checked([&] {
            std::shared_ptr<const nsp::io::NanoDensityGrid> g;
#if NSP_HAVE_OPENVDB
            if (ext == ".vdb") g = nsp::io::load_vdb(o.file, name);
#endif
            if (ext == ".nvdb") g = nsp::io::load_nvdb(o.file, name);
            return g;
        });
    };
    const std::shared_ptr<const nsp::io::NanoDensityGrid> grid = load(o.grid);
    const float sigma_a = o.density_scale * (1.f - o.albedo), sigma_s = o.density_scale * o.albedo;
    if (!o.temperature.empty()) {
        using S = nsp::Rgb;
        using Base = nsp::io::NanoVdbMedium<S>;
        using Field = nsp::BlackbodyEmission<S, nsp::io::NanoScalarField>;
        const auto temperature = load(o.temperature);
        const auto medium = usage_checked([&] {
            const Base base(grid, nsp::constant_coefficient<S>(sigma_a), nsp::constant_coefficient<S>(sigma_s));
            return nsp::Emissive<Base, Field>(base, Field(nsp::io::NanoScalarField(temperature), o.temperature_scale,
                                                          o.emission_scale, o.normalize_blackbody));
        });
        const nsp::Box b = medium.power_box();
        std::printf("%s: grid '%s' (density, %llu active voxels), grid '%s' (temperature, hottest %.0f K), emission "
                    "over [%g, %g, %g] - [%g, %g, %g], emitted power estimate %g\n",
                    o.file.c_str(), o.grid.c_str(), static_cast<unsigned long long>(grid->active_voxels()),
                    o.temperature.c_str(), medium.emission_field().max_temperature(), b.lo.x, b.lo.y, b.lo.z, b.hi.x,
                    b.hi.y, b.hi.z, double(medium.total_power_estimate()));
        return render(medium, o, "rgb", "an emitting medium, a dim sky and a small sphere light");
    }
    using M = nsp::io::NanoVdbMedium<nsp::Mono>;
    const M medium = usage_checked(
        [&] { return M(grid, nsp::Mono::Spectrum::Constant(sigma_a), nsp::Mono::Spectrum::Constant(sigma_s)); });
    const nsp::Box b = medium.bounds();
    const auto lo = grid->nonzero_lo(), hi = grid->nonzero_hi();
    std::printf("%s: grid '%s', %llu active voxels in %u leaves, non-zero over index [%d, %d] x [%d, %d] x [%d, %d] "
                "(box [%g, %g, %g] - [%g, %g, %g]), largest extinction %g, %.1f MiB NanoVDB\n",
                o.file.c_str(), o.grid.c_str(), static_cast<unsigned long long>(grid->active_voxels()), grid->leaf_count(),
                lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z,
                double(medium.max_extinction()), double(grid->memory_bytes()) / (1 << 20));
    return render(medium, o, "mono", "a dim sky and a small sphere light");
}
#endif

/// The volume file: its format, that it is a regular file and the output directory checked
/// before it is read; then loaded and rendered.
int render_file(const VolumeOptions& o) {
    const std::string ext = nsp_examples::extension_of(o.file);
    usage_checked([&] { nsp_examples::require_format(o.file, ext); });
    nsp_examples::require_regular_file(o.file, "a volume file");
    if (ext == ".vol" && !o.temperature.empty())
        throw nsp_examples::UsageError("--temperature needs a .nvdb or .vdb file (a temperature grid beside the density); '" +
                                       o.file + "' is a .vol file, which holds one grid");
    if (!o.no_png) nsp_examples::require_writable_directory("--out", o.out);
    if (ext == ".vol") return render_vol(o);
#if NSP_HAVE_NANOVDB
    return render_nanovdb(o, ext);
#else
    return nsp_examples::kExitUsage;  // require_format rejected it
#endif
}

int run(int argc, char** argv) {
    const VolumeOptions o = nsp_examples::parse_volume_flags(argc, argv);
    return o.exporting() ? export_volume(o) : render_file(o);
}

}  // namespace
int main(int argc, char** argv) {
    return nsp_examples::run_tool("nsp_volume", [&] { return run(argc, argv); });
}
