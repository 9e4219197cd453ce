// examples/volume_cli.cpp: nsp_volume's flags (see volume_cli.hpp), parsed with CLI11 through
// parse_flags (tool.hpp): every number checked here (finite, in range), with a message that names
// the flag, before any medium is built.
#include "volume_cli.hpp"

#include <algorithm>
#include <thread>

#include <CLI/CLI.hpp>

#include "tool.hpp"

namespace nsp_examples {

VolumeOptions parse_volume_flags(int argc, char** argv) {
    VolumeOptions o;
    o.threads = int(std::max(1u, std::thread::hardware_concurrency()));
    CLI::App app("nsp_volume: render a volume file (.vol, .nvdb, .vdb) with nsp's path estimators. Exits 0, 1 if a "
                 "path ended with a failed status or a write failed, 2 on a bad command line or a bad file.",
                 "nsp_volume");
    constexpr double kLarge = 1e30;  // the largest scale a flag takes (a product with a density must stay finite)
    app.add_option("file", o.file, "the volume file to render: .vol (Mitsuba), .nvdb (NanoVDB) or .vdb (OpenVDB)");
    app.add_option("--grid", o.grid, "the .nvdb or .vdb file's density grid");
    app.add_option("--temperature", o.temperature,
                   "the .nvdb or .vdb file's temperature grid: the medium emits blackbody radiance (rendered in Rgb)");
    app.add_option("--temperature-scale", o.temperature_scale, "kelvin per unit of the temperature grid")
        ->check(real_in(0.0, kLarge));
    app.add_option("--emission-scale", o.emission_scale, "factor on Planck's law (W sr^-1 m^-2 nm^-1)")
        ->check(real_in(0.0, kLarge));
    app.add_flag("--normalize-blackbody", o.normalize_blackbody,
                 "divide each temperature's spectrum by its peak (pbrt-v4's convention): temperature sets the colour only");
    app.add_option("--export-cloud", o.export_cloud,
                   "write the default cloud (64^3 over [-1, 1]^3) to this .vol, .nvdb or .vdb file and exit");
    app.add_option("--export-plume", o.export_plume, "write the procedural smoke plume to this .nvdb, .vdb or .vol file and exit");
    app.add_option("--plume-res", o.plume_res, "voxels per axis of the exported plume")->check(integer_in(16, 1024));
    app.add_option("--channel", o.channel, "the .vol file's channel that holds the density")->check(integer_in(0, 1 << 20));
    app.add_option("--density-scale", o.density_scale, "extinction per unit of the file's density")
        ->check(real_in(0.0, kLarge, true));
    app.add_option("--albedo", o.albedo, "single-scattering albedo (grey)")->check(real_in(0.0, 1.0));
    app.add_option("--g", o.g, "Henyey-Greenstein asymmetry")->check(real_in(-0.99, 0.99));
    app.add_option("--majorant", o.majorant,
                   "global (one value), grid (a grid of cell maxima), grid-control (the grid with each cell's minimum beside it: "
                   "decomposition tracking), tree (adaptive, hierarchical), tree-control (the tree with each cell's minimum beside it) or "
                   "tree-nodes (on a VDB grid's nodes)")
        ->check(CLI::IsMember({"global", "grid", "grid-control", "tree", "tree-control", "tree-nodes"}));
    app.add_option("--grid-res", o.grid_res, "cells per axis of the grid majorant")->check(integer_in(1, 256));
    app.add_option("--tree-split", o.tree_split, "cells of the tree majorant per leaf (8 voxels) and axis")
        ->check(CLI::IsMember({1, 2, 4, 8}));
    app.add_option("--tree-step-cost", o.tree_step_cost, "the tree's cost model: a DDA step's cost in lookups")
        ->check(real_in(0.0, 100.0));
    app.add_option("--runs", o.runs, "with --compare-majorants: runs per row (other seeds); each column their median")
        ->check(integer_in(1, 99));
    app.add_flag("--compare-majorants", o.compare,
                 "render uni-nee-mis under the global, grid 16^3 and 64^3 and tree majorants and the tree control");
    app.add_option("--res", o.res, "image width and height in pixels")->check(integer_in(1, 4096));
    app.add_option("--spp", o.spp, "samples per pixel")->check(integer_in(2, 1 << 20));
    app.add_option("--threads", o.threads, "worker threads")->check(integer_in(1, 256));
    app.add_option("--out", o.out, "directory for volume.png, created if missing");
    app.add_flag("--no-png", o.no_png, "write no picture");
    parse_flags(app, argc, argv);

    if (!o.export_cloud.empty() && !o.export_plume.empty())
        throw UsageError("--export-cloud and --export-plume: give one of them (each writes one file and exits)", true);
    if (o.exporting() && !o.file.empty())
        throw UsageError(std::string(o.export_cloud.empty() ? "--export-plume" : "--export-cloud") +
                             " writes a volume and exits; it renders no file, so '" + o.file + "' would be ignored",
                         true);
    if (!o.exporting() && o.file.empty())
        throw UsageError("give a volume file to render, or --export-cloud / --export-plume FILE", true);
    return o;
}

}  // namespace nsp_examples
