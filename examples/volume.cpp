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
// longest axis of its bounds, split twice into 4^3 where that pays; tree-nodes puts the cells on a NanoVDB grid's nodes (128 -> 32 -> 8 voxels). Writes DIR/volume.png (uni-nee-mis balance, or the tree row) unless --no-png. Exits 1 if
// a path ended with a status other than Ok, 2 on a bad command line or a bad file (with the
// loader's message).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nsp/majorants/tree.hpp>

#include "image_render.hpp"
#include "png_writer.hpp"
#include "volume_files.hpp"

namespace {

using nsp_examples::Row;

struct Options {
    float g = 0.5f;
    int res = 128, spp = 64, threads = 1, runs = 1;
    std::string out = "out";
    bool no_png = false;
};

/// Prints the table of `rows` (time x variance against the best row) with `extra(row)` columns.
template <class Extra>
std::uint64_t print_rows(const std::vector<Row>& rows, double samples, const char* extra_head, Extra&& extra) {
    double best = nsp::kInf;
    for (const Row& row : rows) best = std::min(best, row.cpu_seconds / samples * row.variance);
    std::printf("%-24s %8s %11s %9s %8s %11s %11s %10s %9s %9s%s\n", "row", "seconds", "lookups/spl", "steps/spl",
                "ns/spl", "var/spl", "cpu-s*var", "cpu/best", "mean", "se", extra_head);
    std::uint64_t failed = 0;
    for (const Row& row : rows) {
        const double cv = row.cpu_seconds / samples * row.variance;
        std::printf("%-24s %8.2f %11.3g %9.3g %8.0f %11.3g %11.3g %10.3g %9.4g %9.2g", row.name.c_str(), row.seconds,
                    row.lookups, row.steps, 1e9 * row.cpu_seconds / samples, row.variance, cv, cv / best, row.mean, row.se);
        extra(row);
        std::printf("\n");
        failed += row.failed;
    }
    std::printf("Paths with a failed status: %llu\n", static_cast<unsigned long long>(failed));
    return failed;
}

void write_picture(const Row& row, const Options& o) {
    if (o.no_png) return;
    std::filesystem::create_directories(o.out);
    const std::string path = o.out + "/volume.png";
    nsp_examples::write_png(path, row.image, nsp_examples::exposure_for({&row.image}));
    std::printf("wrote %s\n", path.c_str());
}

/// Renders `medium` under `majorant` with the three strategies and prints the table.
template <class M, class Maj>
std::uint64_t run_strategies(const M& medium, const Maj& majorant, const Options& o) {
    using namespace nsp;
    const nsp_examples::VolumeFraming<M> cam(medium);
    const auto scene = Scene(medium, majorant, HenyeyGreensteinPhase(o.g), cam.lights);
    std::vector<Row> rows;
    rows.push_back(nsp_examples::render_image(scene, PathEstimator<strategy::Unidirectional>{}, "unidirectional", o.res,
                                              o.spp, o.threads, 1, cam));
    rows.push_back(nsp_examples::render_image(scene, PathEstimator<strategy::NextEvent>{}, "ratio-nee", o.res, o.spp,
                                              o.threads, 2, cam));
    rows.push_back(nsp_examples::render_image(scene, PathEstimator<strategy::NullScatteringMis, mis::Balance>{},
                                              "uni-nee-mis_balance", o.res, o.spp, o.threads, 3, cam));
    const std::uint64_t failed = print_rows(rows, double(o.res) * o.res * o.spp, "", [](const Row&) {});
    write_picture(rows.back(), o);
    return failed;
}

/// The tree majorant of medium M: on its own tree, or over its bounds in coarse cells of about 128
/// voxels split into 16^3 (a dense grid).
int g_leaf_split = 1;         ///< --tree-split: cells per leaf and axis
float g_step_cost = 0.3f;     ///< --tree-step-cost: a DDA step's cost in lookups

/// The tree majorant: the adaptive layout over the medium's bounds, or with `on_nodes` the cells
/// on a VDB grid's nodes (128 -> 32 -> 8 voxels, and --tree-split more inside the leaves).
template <class M>
nsp::TreeMajorant<M> tree_majorant(const M& m, bool on_nodes = false) {
    if constexpr (nsp::TreeLayoutMedium<M>) {
        if (on_nodes) {
            nsp::TreeLayout l = m.tree_layout(g_leaf_split);
            l.step_cost = g_step_cost;
            return nsp::TreeMajorant<M>(m, l);
        }
    }
    (void)on_nodes;
    nsp::TreeLayout l = nsp::detail::adaptive_layout(m);
    l.step_cost = g_step_cost;
    return nsp::TreeMajorant<M>(m, l);
}

/// Renders `medium` with uni + NEE MIS (balance) under the global majorant, grids of 16^3 and
/// 64^3 and the tree majorant, and prints the comparison with each majorant's memory and build time.
template <class M>
std::uint64_t compare_majorants(const M& medium, const Options& o) {
    using namespace nsp;
    const nsp_examples::VolumeFraming<M> cam(medium);
    const PathEstimator<strategy::NullScatteringMis, mis::Balance> est;
    std::vector<Row> rows;
    std::vector<std::pair<std::size_t, double>> cost;  // bytes, build milliseconds
    auto timed = [&](auto make) {
        const auto t0 = std::chrono::steady_clock::now();
        auto maj = make();
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        return std::pair{std::move(maj), ms};
    };
    std::uint64_t seed = 1;
    // Each row o.runs times with other seeds; the row reports the median of each column (the
    // variance of one run moves by tens of percent between seeds at these sizes).
    auto run = [&](const auto& maj, double ms, std::size_t bytes, const std::string& name) {
        const auto scene = Scene(medium, maj, HenyeyGreensteinPhase(o.g), cam.lights);
        std::vector<Row> runs;
        for (int k = 0; k < o.runs; ++k)
            runs.push_back(nsp_examples::render_image(scene, est, name, o.res, o.spp, o.threads, seed + 1000u * std::uint64_t(k), cam));
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
        run(maj, ms, sizeof(float), "global");
    }
    // The cost model's pick (nsp/majorants/choose.hpp), rendered as a row of its own when it is
    // a grid the comparison does not already hold.
    const auto [pick, pick_ms] = timed([&] { return nsp::choose_grid_resolution(medium); });
    const int picked = pick.global ? 0 : pick.resolution[0];
    std::printf("cost model (choose_grid_resolution, %.0f ms): %s, %.3g lookups + 0.3 x %.3g steps per random line "
                "(global: %.3g lookups)\n",
                pick_ms, picked ? ("grid " + std::to_string(picked) + "^3").c_str() : "global", pick.lookups, pick.steps,
                nsp::global_majorant_cost(medium).lookups);
    for (const int n : {16, 64}) {
        auto [maj, ms] = timed([&] { return GridMajorant<M>(medium, n); });
        run(maj, ms, maj.memory_bytes(), "grid " + std::to_string(n) + "^3");
    }
    if (picked && picked != 16 && picked != 64) {
        auto [maj, ms] = timed([&] { return GridMajorant<M>(medium, picked); });
        run(maj, ms, maj.memory_bytes(), "grid " + std::to_string(picked) + "^3 (model)");
    }
    auto describe = [](const char* name, const TreeMajorant<M>& t) {
        const auto l = t.layout();
        std::printf("%s: %dx%dx%d coarse cells (%zu empty, %zu split), then %zu and %zu split cells on the next levels\n",
                    name, l.coarse[0], l.coarse[1], l.coarse[2], t.empty_cells(), t.split_cells(0), t.split_cells(1),
                    t.split_cells(2));
    };
    if constexpr (TreeLayoutMedium<M>) {
        auto [nodes, nodes_ms] = timed([&] { return tree_majorant(medium, true); });
        run(nodes, nodes_ms, nodes.memory_bytes(), "tree on VDB nodes");
        describe("tree on VDB nodes", nodes);
    }
    auto [tree, tree_ms] = timed([&] { return tree_majorant(medium); });
    run(tree, tree_ms, tree.memory_bytes(), "tree");
    describe("tree", tree);
    std::size_t i = 0;
    const std::uint64_t failed =
        print_rows(rows, double(o.res) * o.res * o.spp, "  majorant-KiB build-ms", [&](const Row&) {
            std::printf("  %12.1f %8.1f", double(cost[i].first) / 1024.0, cost[i].second);
            ++i;
        });
    write_picture(rows.back(), o);
    return failed;
}

template <class M>
std::uint64_t render(const M& medium, const std::string& majorant, int grid_res, bool compare, const Options& o) {
    if (compare) return compare_majorants(medium, o);
    if (majorant == "grid") return run_strategies(medium, nsp::GridMajorant<M>(medium, grid_res), o);
    if (majorant == "tree") return run_strategies(medium, tree_majorant(medium), o);
    if (majorant == "tree-nodes") return run_strategies(medium, tree_majorant(medium, true), o);
    return run_strategies(medium, nsp::GlobalMajorant<M>(medium), o);
}

std::string majorant_label(const std::string& majorant, int grid_res, bool compare) {
    if (compare) return "majorants compared, uni-nee-mis balance";
    if (majorant == "grid") return "grid " + std::to_string(grid_res) + "^3 majorant";
    return majorant + " majorant";
}

}  // namespace

int main(int argc, char** argv) {
    std::string file, export_cloud, export_plume, majorant = "global", grid_name = "density", temperature;
    int channel = 0, grid_res = 32, plume_res = 512;
    float density_scale = 10.f, albedo = 0.9f, temperature_scale = 1.f, emission_scale = 1.f;
    bool compare = false, normalize_blackbody = false;
    Options o;
    o.threads = int(std::max(1u, std::thread::hardware_concurrency()));
    CLI::App app("nsp_volume: render a volume file (.vol, .nvdb, .vdb) with nsp's path estimators", "nsp_volume");
    app.add_option("file", file, "the volume file to render: .vol (Mitsuba), .nvdb (NanoVDB) or .vdb (OpenVDB)");
    app.add_option("--grid", grid_name, "the .nvdb or .vdb file's density grid");
    app.add_option("--temperature", temperature,
                   "the .nvdb or .vdb file's temperature grid: the medium emits blackbody radiance (rendered in Rgb)");
    app.add_option("--temperature-scale", temperature_scale, "kelvin per unit of the temperature grid")
        ->check(CLI::NonNegativeNumber);
    app.add_option("--emission-scale", emission_scale, "factor on Planck's law (W sr^-1 m^-2 nm^-1)")
        ->check(CLI::NonNegativeNumber);
    app.add_flag("--normalize-blackbody", normalize_blackbody,
                 "divide each temperature's spectrum by its peak (pbrt-v4's convention): temperature sets the colour only");
    app.add_option("--export-cloud", export_cloud, "write the default cloud (64^3 over [-1, 1]^3) to this .vol, .nvdb or .vdb file and exit");
    app.add_option("--export-plume", export_plume, "write the procedural smoke plume to this .nvdb, .vdb or .vol file and exit");
    app.add_option("--plume-res", plume_res, "voxels per axis of the exported plume")->check(CLI::Range(16, 1024));
    app.add_option("--channel", channel, "the .vol file's channel that holds the density")->check(CLI::NonNegativeNumber);
    app.add_option("--density-scale", density_scale, "extinction per unit of the file's density")
        ->check(CLI::PositiveNumber);
    app.add_option("--albedo", albedo, "single-scattering albedo (grey)")->check(CLI::Range(0.f, 1.f));
    app.add_option("--g", o.g, "Henyey-Greenstein asymmetry")->check(CLI::Range(-0.99f, 0.99f));
    app.add_option("--majorant", majorant, "global (one value), grid (a grid of cell maxima), tree (adaptive, hierarchical) or tree-nodes (on a VDB grid's nodes)")
        ->check(CLI::IsMember({"global", "grid", "tree", "tree-nodes"}));
    app.add_option("--grid-res", grid_res, "cells per axis of the grid majorant")->check(CLI::Range(1, 256));
    app.add_option("--tree-split", g_leaf_split, "cells of the tree majorant per leaf (8 voxels) and axis")
        ->check(CLI::IsMember({1, 2, 4, 8}));
    app.add_option("--tree-step-cost", g_step_cost, "the tree's cost model: a DDA step's cost in lookups")
        ->check(CLI::Range(0.f, 100.f));
    app.add_option("--runs", o.runs, "with --compare-majorants: runs per row (other seeds); each column their median")
        ->check(CLI::Range(1, 99));
    app.add_flag("--compare-majorants", compare, "render uni-nee-mis under the global, grid 16^3 and 64^3 and tree majorants");
    app.add_option("--res", o.res, "image width and height in pixels")->check(CLI::Range(1, 4096));
    app.add_option("--spp", o.spp, "samples per pixel")->check(CLI::Range(2, 1 << 20));
    app.add_option("--threads", o.threads, "worker threads")->check(CLI::Range(1, 256));
    app.add_option("--out", o.out, "directory for volume.png");
    app.add_flag("--no-png", o.no_png, "write no picture");
    CLI11_PARSE(app, argc, argv);

    try {
        if (!export_cloud.empty() || !export_plume.empty()) {
            const bool plume = !export_plume.empty();
            const std::string path = plume ? export_plume : export_cloud;
            nsp_examples::write_volume(
                path, [&] { return plume ? nsp_examples::plume_voxels(plume_res) : nsp_examples::cloud_voxels(); },
                plume_res, plume);
            if (plume) std::printf("wrote %s: the smoke plume, %d^3 voxels over [-1, 1]^3\n", path.c_str(), plume_res);
            else std::printf("wrote %s: the default cloud, 64x64x64 voxels over [-1, 1]^3\n", path.c_str());
            return 0;
        }
        if (file.empty()) {
            std::fprintf(stderr, "nsp_volume: give a volume file to render, or --export-cloud / --export-plume FILE\n");
            return 2;
        }
        const std::string ext = nsp_examples::extension_of(file);
        nsp_examples::require_format(file, ext);
        const auto sigma_a = nsp::Mono::Spectrum::Constant(density_scale * (1.f - albedo));
        const auto sigma_s = nsp::Mono::Spectrum::Constant(density_scale * albedo);
        std::string label = majorant_label(majorant, grid_res, compare);
        if (compare && o.runs > 1) label += ", median of " + std::to_string(o.runs) + " runs per row";
        if (ext == ".vol" && !temperature.empty()) {
            std::fprintf(stderr, "nsp_volume: --temperature needs a .nvdb or .vdb file (a temperature grid beside the density); "
                                 "'%s' is a .vol file, which holds one grid\n", file.c_str());
            return 2;
        }
        if (ext == ".vol") {
            const nsp::io::VoxelGrid grid = nsp::io::load_vol(file);
            using M = nsp::DenseGridMedium<nsp::Mono>;
            const M medium = nsp::io::to_dense_medium<nsp::Mono>(grid, sigma_a, sigma_s, channel);
            const nsp::Vec3 lo = grid.bounds.lo, hi = grid.bounds.hi;
            std::printf("%s: %dx%dx%d voxels, %d channel(s), box [%g, %g, %g] - [%g, %g, %g], largest extinction %g, "
                        "%.1f MiB dense\n",
                        file.c_str(), grid.resolution[0], grid.resolution[1], grid.resolution[2], grid.channels, lo.x, lo.y,
                        lo.z, hi.x, hi.y, hi.z, double(medium.max_extinction()), double(grid.voxels()) * 4.0 / (1 << 20));
            std::printf("Volume (mono, %dx%d, %d spp, %d threads, %s): a dim sky and a small sphere light\n", o.res, o.res,
                        o.spp, o.threads, label.c_str());
            return render(medium, majorant, grid_res, compare, o) == 0 ? 0 : 1;
        }
#if NSP_HAVE_NANOVDB
        auto load = [&](const std::string& name) {
            std::shared_ptr<const nsp::io::NanoDensityGrid> g;
#if NSP_HAVE_OPENVDB
            if (ext == ".vdb") g = nsp::io::load_vdb(file, name);
#endif
            if (ext == ".nvdb") g = nsp::io::load_nvdb(file, name);
            return g;
        };
        const std::shared_ptr<const nsp::io::NanoDensityGrid> grid = load(grid_name);
        if (!temperature.empty()) {
            // An emitting medium in Rgb: grey coefficients, blackbody radiance by temperature.
            using S = nsp::Rgb;
            using Base = nsp::io::NanoVdbMedium<S>;
            using Field = nsp::BlackbodyEmission<S, nsp::io::NanoScalarField>;
            const Base base(grid, nsp::constant_coefficient<S>(density_scale * (1.f - albedo)),
                            nsp::constant_coefficient<S>(density_scale * albedo));
            const nsp::Emissive<Base, Field> medium(
                base, Field(nsp::io::NanoScalarField(load(temperature)), temperature_scale, emission_scale, normalize_blackbody));
            const nsp::Box b = medium.power_box();
            std::printf("%s: grid '%s' (density, %llu active voxels), grid '%s' (temperature, hottest %.0f K), emission "
                        "over [%g, %g, %g] - [%g, %g, %g], emitted power estimate %g\n",
                        file.c_str(), grid_name.c_str(), static_cast<unsigned long long>(grid->active_voxels()),
                        temperature.c_str(), medium.emission_field().max_temperature(), b.lo.x, b.lo.y, b.lo.z, b.hi.x,
                        b.hi.y, b.hi.z, double(medium.total_power_estimate()));
            std::printf("Volume (rgb, %dx%d, %d spp, %d threads, %s): an emitting medium, a dim sky and a small sphere light\n",
                        o.res, o.res, o.spp, o.threads, label.c_str());
            return render(medium, majorant, grid_res, compare, o) == 0 ? 0 : 1;
        }
        using M = nsp::io::NanoVdbMedium<nsp::Mono>;
        const M medium(grid, sigma_a, sigma_s);
        const nsp::Box b = medium.bounds();
        const auto lo = grid->nonzero_lo(), hi = grid->nonzero_hi();
        std::printf("%s: grid '%s', %llu active voxels in %u leaves, non-zero over index [%d, %d] x [%d, %d] x [%d, %d] "
                    "(box [%g, %g, %g] - [%g, %g, %g]), largest extinction %g, %.1f MiB NanoVDB\n",
                    file.c_str(), grid_name.c_str(), static_cast<unsigned long long>(grid->active_voxels()), grid->leaf_count(),
                    lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z,
                    double(medium.max_extinction()), double(grid->memory_bytes()) / (1 << 20));
        std::printf("Volume (mono, %dx%d, %d spp, %d threads, %s): a dim sky and a small sphere light\n", o.res, o.res, o.spp,
                    o.threads, label.c_str());
        return render(medium, majorant, grid_res, compare, o) == 0 ? 0 : 1;
#else
        (void)grid_name, (void)temperature_scale, (void)emission_scale, (void)normalize_blackbody;
        return 2;  // require_format rejected it
#endif
    } catch (const nsp::InvalidArgument& e) {
        std::fprintf(stderr, "nsp_volume: %s\n", e.what());
        return 2;
    }
}
