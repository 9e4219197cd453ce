// examples/volume_cli.hpp: nsp_volume's command line: the options of a run and their parser
// (CLI11). docs/volumes.md explains the flags; --help is the one-screen summary.
#pragma once

#include <string>

namespace nsp_examples {

/// Everything a run of nsp_volume is asked to do.
struct VolumeOptions {
    std::string file;  ///< the volume file to render (empty with an export)
    std::string export_cloud, export_plume;  ///< --export-cloud / --export-plume FILE: write it and exit
    int plume_res = 512;
    // The medium
    std::string grid = "density", temperature;  ///< the .nvdb / .vdb grids (temperature: none when empty)
    int channel = 0;                            ///< the .vol file's density channel
    float density_scale = 10.f, albedo = 0.9f, g = 0.5f;
    float temperature_scale = 1.f, emission_scale = 1.f;
    bool normalize_blackbody = false;
    // The majorant
    std::string majorant = "global";  ///< global, grid, tree or tree-nodes
    int grid_res = 32, tree_split = 1;
    float tree_step_cost = 0.3f;
    bool compare = false;  ///< --compare-majorants
    int runs = 1;
    // The image
    int res = 128, spp = 64, threads = 1;
    std::string out = "out";
    bool no_png = false;

    bool exporting() const { return !export_cloud.empty() || !export_plume.empty(); }
};

/// Parses the command line; throws UsageError (tool.hpp) naming the bad flag or value, or when
/// the flags do not go together (a volume file and an export, both exports, neither a file nor
/// an export); prints the help and exits 0 on --help.
VolumeOptions parse_volume_flags(int argc, char** argv);

}  // namespace nsp_examples
