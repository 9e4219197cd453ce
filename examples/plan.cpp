// examples/plan.cpp: the render plan (see plan.hpp). The only file of the driver that knows the
// compile-time lists of combinations.hpp; it reads them as run-time data (combination_infos).
#include "plan.hpp"

#include <algorithm>
#include <cstdio>
#include <type_traits>

#include "catalogue.hpp"
#include "combinations.hpp"
#include "type_list.hpp"

namespace nsp_examples {

std::vector<std::string_view> mode_names() {
    std::vector<std::string_view> names;
    tl::for_each<SpectralModes>([&]<class S>(std::type_identity<S>) { names.emplace_back(S::name); });
    return names;
}

std::vector<std::string_view> majorant_names() {
    std::vector<std::string_view> names;
    tl::for_each<Majorants>([&]<class M>(std::type_identity<M>) { names.emplace_back(M::name); });
    return names;
}

namespace {

/// The run-time descriptions of every combination of spectral mode `mode`, in index order.
std::vector<CombinationInfo> infos(std::string_view mode) {
    std::vector<CombinationInfo> out;
    tl::for_each<SpectralModes>([&]<class S>(std::type_identity<S>) {
        if (mode == S::name) out.assign(combination_infos<S>().begin(), combination_infos<S>().end());
    });
    return out;
}

/// True when every field of `token` is a field of the row; a learned-count row only for a token
/// that names "learned" (so that the existing tokens select the same rows as before).
bool matches(const Candidate& c, std::string_view token) {
    const auto fields = split(token, '_');
    if (c.learned && std::find(fields.begin(), fields.end(), "learned") == fields.end()) return false;
    if (token == "all") return true;
    for (const auto t : fields)
        if (std::find(c.fields.begin(), c.fields.end(), t) == c.fields.end()) return false;
    return true;
}

/// The reference row of --reference-spp for set-up `setup` of scene `e` in `mode`, with a note
/// on stderr when the scene has none or the mode does not compile it.
std::optional<Candidate> reference_row(const SceneEntry& e, const char* setup, std::string_view mode) {
    if (e.reference_estimator.empty()) {
        std::fprintf(stderr, "nsp_render: --reference-spp: set-up %s has no reference estimator (only the "
                     "chromatic cloud's, the fog's and the plume's tables have one)\n", setup);
        return std::nullopt;
    }
    for (const Candidate& c : candidates(mode, {SelectionRule::Uniform}))
        if (c.emissive == e.emissive && c.name == e.reference_estimator) return c;
    std::fprintf(stderr, "nsp_render: --reference-spp: no reference for set-up %s in %.*s mode (it needs %s)\n",
                 setup, int(mode.size()), mode.data(), e.reference_estimator.c_str());
    return std::nullopt;
}

}  // namespace

std::vector<Candidate> candidates(std::string_view mode, const std::vector<SelectionRule>& rules) {
    std::vector<Candidate> out;
    std::size_t index = 0;
    for (const CombinationInfo& info : infos(mode)) {
        Candidate c;
        c.index = index++;
        c.channels = info.channels;
        c.majorant = info.majorant;
        c.bounding = info.bounding;
        c.per_channel_majorant = info.per_channel_majorant;
        c.strategy = info.strategy;
        c.absorption = info.absorption;
        c.uses_selection = info.uses_selection;
        c.emissive = info.emissive;
        c.name = info.name();
        for (const auto f : split(c.name, '_')) {
            c.fields.emplace_back(f);
            if (f == c.majorant) continue;
            if (!c.key.empty()) c.key += '_';  // not "_" + std::string(f): GCC 12 warns (-Wrestrict, bug 105329)
            c.key += f;
        }
        if (!info.spectral) c.fields.emplace_back("grey");
        if (info.plain_global) c.fields.emplace_back("global");
        if (info.emissive) c.fields.emplace_back("emissive");
        // Each row, then (where it can learn them) the same row with learned NEE counts.
        auto push = [&](Candidate row) {
            out.push_back(row);
            if (!info.learns_nee_count) return;
            row.learned = true;
            row.name += "_learned";
            row.key += "_learned";
            row.fields.emplace_back("learned");
            out.push_back(std::move(row));
        };
        if (!info.uses_selection) {
            push(c);
            continue;
        }
        for (const SelectionRule r : rules) {
            Candidate s = c;
            s.selection = r;
            if (r == SelectionRule::Luminance) {
                s.name += "_lum";
                s.key += "_lum";
                s.fields.emplace_back("lum");
            } else {
                s.fields.emplace_back("uniform");
            }
            push(std::move(s));
        }
    }
    return out;
}

std::vector<TablePlan> plan(const Options& o) {
    std::vector<TablePlan> tables;
    std::vector<bool> used(o.estimators.size(), false);
    std::vector<bool> majorant_used(o.majorants.size(), false);
    for (const SceneKind kind : o.scenes) {
        const SceneEntry& d = scene_entry(kind);
        std::vector<SetupEntry> choices;
        for (const auto& s : o.setups)
            for (const SetupEntry& setup : d.setups)
                if (s == setup.name) choices.push_back(setup);
        const std::vector<std::string_view> modes = o.modes.empty() ? d.modes : o.modes;
        for (const SetupEntry& setup : choices) {
            const std::vector<std::string>& tokens = !o.estimators.empty()       ? o.estimators
                                                     : !setup.estimators.empty() ? setup.estimators
                                                                                 : d.estimators;
            const std::vector<std::string>& majorants = !o.majorants.empty()       ? o.majorants
                                                        : !setup.majorants.empty() ? setup.majorants
                                                                                   : d.majorants;
            for (const auto mode : modes) {
                TablePlan t{setup.choice, mode, o.width.value_or(d.width), o.height.value_or(d.height),
                            o.spp.value_or(setup.spp > 0 ? setup.spp : d.spp), {}, std::nullopt};
                std::vector<bool> token_used(tokens.size(), false);
                const bool marching = o.estimator.shadow_estimator == nsp::ShadowEstimator::RayMarching;
                for (Candidate c : candidates(mode, o.selections)) {
                    if (c.emissive != d.emissive) continue;
                    // --shadow marching: only the rows whose shadow rays need no path pdf (the
                    // library refuses the others), each named as such.
                    if (marching) {
                        if (c.channels != "grey" || c.learned ||
                            (c.strategy != "ratio-nee" && c.strategy != "directional-mis" &&
                             c.strategy != "equiangular-nee"))
                            continue;
                        c.name += "_marched";
                        c.key += "_marched";
                    }
                    const auto maj = std::find(majorants.begin(), majorants.end(), c.majorant);
                    if (maj == majorants.end()) continue;
                    if (!o.majorants.empty()) majorant_used[std::size_t(maj - majorants.begin())] = true;
                    bool any = false;
                    for (std::size_t k = 0; k < tokens.size(); ++k) {
                        if (!matches(c, tokens[k])) continue;
                        any = token_used[k] = true;
                        if (!o.estimators.empty()) used[k] = true;
                    }
                    if (any) t.rows.push_back(c);
                }
                // A scene's default row that this mode does not compile (e.g. the equiangular
                // strategies outside mono) is left out with a note rather than silently.
                // (Not under --shadow marching, which leaves out every row that needs path pdfs.)
                for (std::size_t k = 0; k < tokens.size() && o.estimators.empty() && !marching; ++k)
                    if (!token_used[k] && !t.rows.empty())
                        std::fprintf(stderr, "nsp_render: note: set-up %s, %.*s: no row '%s' (not compiled in this "
                                     "mode, see --list)\n", setup.name.c_str(), int(mode.size()), mode.data(),
                                     tokens[k].c_str());
                if (t.rows.empty()) continue;
                if (o.reference_spp) t.reference = reference_row(d, setup.name.c_str(), mode);
                tables.push_back(std::move(t));
            }
        }
    }
    for (std::size_t k = 0; k < o.estimators.size(); ++k)
        if (!used[k])
            usage_error("--estimators: '" + o.estimators[k] + "' matches no row of the chosen scenes, set-ups, "
                        "spectral modes and majorants (see --list)");
    for (std::size_t k = 0; k < o.majorants.size(); ++k)
        if (!majorant_used[k] && !o.all_majorants)
            usage_error("--majorant: '" + o.majorants[k] + "' has no row in the chosen spectral modes (see --list: "
                        "per-channel majorants need rgb or hero, the non-bounding ones mono)");
    if (tables.empty())
        usage_error("nothing to render: the chosen scenes, set-ups, spectral modes and majorants have no row in "
                    "common (--scene and --setup must share a set-up; see --list: the plume's emissive medium is "
                    "compiled in rgb only, the equiangular strategies in mono only)");
    return tables;
}

void list_combinations() {
    std::printf("%-5s %-21s %-13s %-15s %-9s %-13s %-10s %s\n", "mode", "channels", "majorant", "strategy",
                "heuristic", "absorption", "medium", "name");
    std::size_t total = 0;
    for (const auto mode : mode_names()) {
        const std::vector<CombinationInfo> all = infos(mode);
        for (const CombinationInfo& c : all)
            std::printf("%-5s %-21s %-13s %-15s %-9s %-13s %-10s %s\n", c.mode, c.channels, c.majorant, c.strategy,
                        c.heuristic, c.absorption, c.medium, c.name().c_str());
        std::printf("  %.*s: %zu combinations\n", int(mode.size()), mode.data(), all.size());
        total += all.size();
    }
    std::printf("%zu valid combinations. channels 'grey' is nsp::PathEstimator (a grey majorant: global or grid, "
                "and in mono also the non-bounding global-signed, global-clamp, grid-signed, grid-clamp; grid-control "
                "(a grid with per-cell minorants: decomposition tracking) in mono and rgb (the equiangular strategies "
                "in mono); a "
                "heuristic on a single strategy and mis::None on an MIS strategy are rejected); the others are "
                "nsp::SpectralPathEstimator, only in multi-channel modes: independent tracking with a per-channel "
                "majorant (per-channel, channel-grid, and channel-grid-control in rgb), spectral tracking with a "
                "grey one (global, grid, and grid-control in rgb), spectral-mis with any of the six; no directional-mis; mis::None for single strategies, balance "
                "for uni-nee-mis. Majorants other than global and per-channel: absorb-weight only (build time), "
                "except the equiangular strategies (equiangular-nee, uni-nee-eq-mis), which take both absorption "
                "policies with grid too and are compiled for nsp::PathEstimator in mono only (build time; the "
                "library also has them in nsp::SpectralPathEstimator). Medium 'emissive' (the plume scene's flame, "
                "nsp::Emissive): nsp::PathEstimator in rgb with global or grid, absorb-weight, without the "
                "equiangular strategies (build time; nsp::SpectralPathEstimator takes emissive media too). "
                "Independent and spectral-mis rows are rendered once per --selection rule (luminance rows end in "
                "_lum).\n", total);
}

}  // namespace nsp_examples
