// examples/plan.hpp: the render plan of nsp_render: which rows (run-time names of compile-time
// combinations, combinations.hpp) each table renders, from the options and the scene catalogue.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli.hpp"
#include "render_job.hpp"
#include "scene_choice.hpp"

namespace nsp_examples {

/// One row of a table: a combination of one mode with a selection rule, and its names.
struct Candidate {
    std::size_t index = 0;  ///< into CombinationsOf<S>
    SelectionRule selection = SelectionRule::Uniform;
    std::string name;                 ///< e.g. uni-nee-mis_spectral-mis_per-channel_balance_absorb-weight_lum
    std::vector<std::string> fields;  ///< the name's '_'-separated fields and the implied ones (grey, global, uniform)
    std::string channels;             ///< the channel policy ("grey" for PathEstimator)
    std::string majorant;             ///< the majorant policy's name (global, grid, grid-signed, ...)
    std::string key;                  ///< the name without the majorant: rows that differ only in it share it
    bool bounding = true;             ///< false for the non-bounding majorants (bound::Signed, Clamp)
    bool per_channel_majorant = false;  ///< per-channel or channel-grid
    std::string strategy;
    std::string absorption;
    bool uses_selection = false;
    bool emissive = false;  ///< the emissive medium (the plume scene's)
    /// The NEE count learned per pixel tile from a pilot (nsp::NeeCountLearner): the row's name
    /// ends in "_learned"; only tokens that name "learned" select it.
    bool learned = false;
};

/// The renders of one table: one set-up of one scene in one spectral mode.
struct TablePlan {
    SceneChoice scene;
    std::string_view mode;
    int width = 0, height = 0, spp = 0;
    std::vector<Candidate> rows;
    /// --reference-spp: the combination that renders the table's reference image, if it has one.
    std::optional<Candidate> reference;
};

/// The spectral mode names, in the order of SpectralModes (mono, rgb, hero).
std::vector<std::string_view> mode_names();

/// The majorant policy names, in the order of Majorants.
std::vector<std::string_view> majorant_names();

/// Every row spectral mode `mode` offers with selection rules `rules`, in list order (a row that
/// uses the selection once per rule, the luminance one right after the uniform one).
std::vector<Candidate> candidates(std::string_view mode, const std::vector<SelectionRule>& rules);

/// The tables of a run, in order. Exits with a usage error when a flag selects nothing (an
/// --estimators token or a --majorant that matches no row, or no table at all).
std::vector<TablePlan> plan(const Options& o);

/// Prints every compiled policy combination (--list).
void list_combinations();

}  // namespace nsp_examples
