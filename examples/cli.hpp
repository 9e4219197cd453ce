// examples/cli.hpp: nsp_render's command line: the options of a run and their parser (CLI11).
// docs/renderer.md explains every flag at length; --help is the one-screen summary.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "render_job.hpp"
#include "scene_choice.hpp"

namespace nsp_examples {

/// Everything a run of nsp_render is asked to do.
struct Options {
    std::optional<int> width, height, spp;  ///< empty: the scene's default
    int threads = 1;                        ///< default: hardware concurrency
    std::uint64_t seed = 1;
    int runs = 1;
    float pilot_count = 0.25f;  ///< --pilot-count: the learned rows' pilot NEE and segment count
    bool weigh_pilot = true;  ///< --pilot-weight variance (true) or equal
    bool lookup_costs = true; ///< --count-cost lookups (true) or model
    bool scout = true;        ///< --scout on (true) or off
    std::optional<int> reference_spp;  ///< --reference-spp: effective (error-based) variance
    nsp::EstimatorOptions estimator;   ///< max depth, equiangular and emission-segment settings
    std::string out = "out";
    bool write_exr = true;
    bool write_png = true;
    int picture_res = 256;  ///< the larger picture of each scene; 0: none
    bool list = false;
    std::vector<SceneKind> scenes;        ///< default: every scene of the catalogue
    std::vector<std::string> setups;      ///< default: the catalogue's default set-ups
    std::vector<std::string> majorants;   ///< majorant names (empty: the scene's defaults)
    bool all_majorants = false;           ///< --majorant all: names without a row in a mode are no error
    MajorantSettings majorant;            ///< --grid-res, --majorant-scale
    std::vector<std::string_view> modes;  ///< empty: the scene's default modes
    std::vector<std::string> estimators;  ///< filter tokens (empty: the scene's defaults)
    std::vector<SelectionRule> selections{SelectionRule::Uniform, SelectionRule::Luminance};
    LightOverrides lights;
};

/// Parses the command line. Prints the help and exits 0 on --help; throws UsageError (tool.hpp:
/// main prints it and exits 2) with a message naming the bad flag or value and what is allowed.
Options parse_command_line(int argc, char** argv);

/// Throws UsageError(msg) with the pointer to --help: "nsp_render: msg", exit 2 (also for the
/// planner's errors, which only show once the flags are combined).
[[noreturn]] void usage_error(const std::string& msg);

/// The parts of `s` between separators `sep` (an empty part where two separators meet).
std::vector<std::string_view> split(std::string_view s, char sep);

}  // namespace nsp_examples
