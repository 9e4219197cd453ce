// examples/catalogue.hpp: the scene catalogue of nsp_render: every example scene with its light
// set-ups and what the renderer does with it when the flags do not say (spectral modes, image size,
// samples, estimators, majorants, the reference estimator of --reference-spp, the larger picture,
// and which rows the end-of-run summary compares). A new scene is one entry here plus its medium
// and lights in default_scene.hpp.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scene_choice.hpp"

namespace nsp_examples {

/// One light set-up of a scene, as --setup names it.
struct SetupEntry {
    SetupEntry(std::string name_, SceneChoice choice_, int spp_ = 0, bool in_default_run_ = true,
               std::vector<std::string> estimators_ = {}, std::vector<std::string> majorants_ = {})
        : name(std::move(name_)), choice(choice_), spp(spp_), in_default_run(in_default_run_),
          estimators(std::move(estimators_)), majorants(std::move(majorants_)) {}

    std::string name;  ///< "A", "C1", "F3", ...
    SceneChoice choice;
    int spp = 0;                  ///< 0: the scene's
    bool in_default_run = true;   ///< rendered when --setup is not given
    std::vector<std::string> estimators;  ///< empty: the scene's
    std::vector<std::string> majorants;   ///< empty: the scene's
};

/// One example scene and its defaults.
struct SceneEntry {
    SceneKind kind;
    std::string name;         ///< as --scene names it
    std::string description;  ///< one line, for --list and the summary
    std::vector<SetupEntry> setups;
    std::vector<std::string_view> modes;  ///< spectral modes by default
    int width = 0, height = 0, spp = 0;
    std::vector<std::string> estimators;  ///< --estimators filter tokens by default
    std::vector<std::string> majorants;   ///< --majorant names by default
    /// --reference-spp: the row that renders the reference image (finite variance there, none of
    /// the default rows), or empty: the scene's tables get no reference.
    std::string reference_estimator;
    bool emissive = false;  ///< renders the emissive medium's combinations (and only those)
    /// The larger picture (--picture-res): the set-up, mode, row and samples per pixel it uses (a
    /// grid majorant where the medium leaves empty space: the picture should be cheap and clean).
    std::string picture_setup;
    std::string_view picture_mode;
    std::string picture_estimator;
    int picture_spp = 0;
    /// The summary: the scene's default MIS estimator and its single strategies, as row keys (a
    /// row's name without its majorant); the summary compares the best MIS row with the best
    /// single-strategy row of each table.
    std::string mis_key;
    std::vector<std::string> single_keys;
};

/// Every example scene, in the order of the default run.
const std::vector<SceneEntry>& catalogue();

/// The entry of scene `kind`.
const SceneEntry& scene_entry(SceneKind kind);

/// Every set-up name of every scene, in catalogue order (what --setup accepts besides 'all').
std::vector<std::string> setup_names();

/// The set-ups of the default run.
std::vector<std::string> default_setup_names();

}  // namespace nsp_examples
