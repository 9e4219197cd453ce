// examples/catalogue.cpp: the example scenes and their defaults (see catalogue.hpp).
#include "catalogue.hpp"

#include <stdexcept>

namespace nsp_examples {

namespace {

std::vector<SceneEntry> make_catalogue() {
    using K = SceneKind;
    const std::vector<std::string_view> mono{nsp::Mono::name};
    std::vector<SceneEntry> c;

    // The grey cloud: 64x64 at 256 spp. The efficiency tables of docs/efficiency.md were measured
    // at 128x128 (--res 128x128); a quarter of the pixels keeps the per-sample columns within
    // noise and the main job within its time.
    c.push_back({K::Cloud, "cloud",
                 "the grey cloud (extinction 20, albedo 0.9, HG g 0.9); A: a small bright light above "
                 "(NEE should win), B: a large dim light behind (unidirectional should win), D: a bright "
                 "sky and A's light at 1/400 (unidirectional should win)",
                 {{"A", {K::Cloud, LightSetup::A}},
                  {"B", {K::Cloud, LightSetup::B}},
                  // D: where tracking alone is best (the case for NEE count 0), under both majorants
                  {"D", {K::Cloud, LightSetup::D}, 0, true,
                   {"unidirectional_grey_absorb-weight", "ratio-nee_grey_absorb-weight",
                    "uni-nee-mis_grey_balance_absorb-weight", "uni-nee-mis_grey_balance_absorb-weight_learned"},
                   {"global", "grid"}}},
                 mono, 64, 64, 256,
                 // every PathEstimator but the equiangular ones (their lamp is the fog's business)
                 {"unidirectional_grey", "ratio-nee_grey", "directional-mis_grey", "uni-nee-mis_grey",
                  "uni-nee-mis_grey_balance_absorb-weight_learned"},
                 {"global"}, "", false,
                 "A", nsp::Mono::name, "uni-nee-mis_grid_balance_absorb-weight", 128,
                 "uni-nee-mis_balance_absorb-weight", {"unidirectional_absorb-weight", "ratio-nee_absorb-weight"}});

    // The chromatic cloud: its tracking costs several times the grey cloud's lookups per sample,
    // hence the small image (also the size of run-main.sh's heavy-tail comparison, so that a
    // default row is run 1 of it). Rgb by default, to keep the main job short; --spectral hero
    // (or all) renders the Hero<4> tables as well.
    c.push_back({K::Chromatic, "chromatic",
                 "the cloud with extinction 5 : 20 : 80 in R : G : B (hero: a spectrum through them), albedo "
                 "0.95; C1: a white environment, C2: set-up A's small light, C3: set-up D's sky and dim light",
                 {{"C1", {K::Chromatic, LightSetup::A, ChromaticSetup::Env}},
                  {"C2", {K::Chromatic, LightSetup::A, ChromaticSetup::Small}},
                  {"C3", {K::Chromatic, LightSetup::A, ChromaticSetup::SkyLamp}, 0, true,
                   {"unidirectional_spectral-mis_absorb-weight_uniform", "ratio-nee_spectral-mis_absorb-weight_uniform",
                    "uni-nee-mis_spectral-mis_balance_absorb-weight_uniform",
                    "uni-nee-mis_spectral-mis_absorb-weight_uniform_learned"},
                   {"global", "grid"}}},
                 {nsp::Rgb::name}, 32, 32, 128,
                 {"uni-nee-mis_grey_balance_absorb-weight",  // the grey-majorant baseline
                  "unidirectional_independent_absorb-weight_uniform", "uni-nee-mis_independent_absorb-weight",
                  "unidirectional_spectral-tracking-max_absorb-weight", "uni-nee-mis_spectral-tracking-max_absorb-weight",
                  "unidirectional_spectral-tracking-avg_absorb-weight", "uni-nee-mis_spectral-tracking-avg_absorb-weight",
                  "unidirectional_spectral-mis_per-channel_absorb-weight_uniform",
                  "ratio-nee_spectral-mis_per-channel_absorb-weight_uniform",
                  "uni-nee-mis_spectral-mis_per-channel_absorb-weight",
                  "unidirectional_spectral-mis_global_absorb-weight_uniform",
                  "uni-nee-mis_spectral-mis_global_absorb-weight",
                  "uni-nee-mis_spectral-mis_absorb-weight_uniform_learned"},
                 {"global", "per-channel"},
                 // unbiased, finite variance there (one shared pdf under the grey majorant, weights
                 // mu_c / (mu_bar P) bounded), and none of the compared rows
                 "uni-nee-mis_spectral-tracking-avg_global_balance_absorb-weight", false,
                 "C1", nsp::Rgb::name, "uni-nee-mis_spectral-mis_channel-grid_balance_absorb-weight", 32,
                 "uni-nee-mis_spectral-mis_balance_absorb-weight",
                 {"unidirectional_spectral-mis_absorb-weight", "ratio-nee_spectral-mis_absorb-weight"}});

    // The sparse medium: a global majorant spends most lookups on empty space here (extinction 60
    // in ~2% of the box), so a sample costs several times the grey cloud's: a smaller image, and
    // SA at 128 spp (the main job's time).
    c.push_back({K::Sparse, "sparse",
                 "a thin plume and five small dense puffs filling ~2% of the box (grey, extinction 60, albedo "
                 "0.9); SA, SB: set-up A's and B's lights",
                 {{"SA", {K::Sparse, LightSetup::A}, 128}, {"SB", {K::Sparse, LightSetup::B}, 0, false}},
                 mono, 64, 64, 256,
                 {"unidirectional_grey_absorb-weight", "ratio-nee_grey_absorb-weight",
                  "directional-mis_grey_balance_absorb-weight", "uni-nee-mis_grey_balance_absorb-weight",
                  "uni-nee-mis_grey_balance_absorb-weight_learned"},
                 // grid-control: decomposition tracking under the grid's per-cell minorants
                 {"global", "grid", "grid-control"}, "", false,
                 "SA", nsp::Mono::name, "uni-nee-mis_grid_balance_absorb-weight", 64,
                 "uni-nee-mis_balance_absorb-weight", {"unidirectional_absorb-weight", "ratio-nee_absorb-weight"}});

    // The fog: a thin-fog sample is cheap (most camera rays cross without a real collision: at 128
    // spp a row rendered in 0.09 s, too short for its CPU time to rank rows), a dense-fog one costs
    // 30-70 lookups, so F3 gets a quarter of the samples.
    SceneEntry fog{K::Fog, "fog",
                   "a bank of ground fog thinning upward (grey, albedo 0.9, HG g 0.7) lit by a lamp (point "
                   "light, intensity 5); F1: inside the thin fog, F2: beside it, F3: beside 40x denser fog",
                   {}, mono, 64, 64, 256,
                   // tracking + NEE (with a point light uni-nee-mis is the same estimator), equiangular +
                   // NEE and the three-way MIS with both heuristics
                   {"ratio-nee_grey_absorb-weight", "uni-nee-mis_grey_balance_absorb-weight",
                    "equiangular-nee_grey_absorb-weight", "uni-nee-eq-mis_grey_absorb-weight",
                    "uni-nee-eq-mis_grey_balance_absorb-weight_learned"},
                   // grid-control: decomposition tracking, equiangular vertices weighed by its two routes
                   {"global", "grid", "grid-control"},
                   // its NEE from tracked vertices near the lamp is weighted down by the equiangular pdf
                   // there: no 1/r^2 tail, unlike tracking + NEE
                   "uni-nee-eq-mis_balance_absorb-event", false,
                   "F1", nsp::Mono::name, "uni-nee-eq-mis_balance_absorb-weight", 128,
                   "uni-nee-eq-mis_balance_absorb-weight", {"ratio-nee_absorb-weight", "equiangular-nee_absorb-weight"}};
    for (const FogSetup f : {FogSetup::F1, FogSetup::F2, FogSetup::F3}) {
        SceneChoice choice{K::Fog};
        choice.fog = f;
        fog.setups.push_back({name(f), choice, f == FogSetup::F3 ? 64 : 0});
    }
    c.push_back(std::move(fog));

    // The plume: the collision estimator of emission against NEE toward the emitting volume.
    c.push_back({K::Plume, "plume",
                 "the cloud's density with extinction 5, isotropic smoke, and a small flickering flame inside "
                 "behind its dense core (nsp::Emissive; no other light)",
                 {{"P1", {K::Plume}}},
                 {nsp::Rgb::name}, 64, 64, 256,
                 {"unidirectional_grey_absorb-weight", "ratio-nee_grey_absorb-weight", "uni-nee-mis_grey_absorb-weight",
                  "uni-nee-mis_grey_balance_absorb-weight_learned"},
                 // grid-control: decomposition tracking, the collision estimator at every control and
                 // residual collision
                 {"global", "grid", "grid-control"},
                 // directional MIS weights under the grid majorant: they sum to 1 and tame NEE's 1/d^2
                 // near the flame as the null-scattering ones do; none of the default rows
                 "directional-mis_grid_balance_absorb-weight", true,
                 "P1", nsp::Rgb::name, "uni-nee-mis_grid_balance_absorb-weight", 128,
                 "uni-nee-mis_balance_absorb-weight", {"unidirectional_absorb-weight", "ratio-nee_absorb-weight"}});
    return c;
}

}  // namespace

const std::vector<SceneEntry>& catalogue() {
    static const std::vector<SceneEntry> c = make_catalogue();
    return c;
}

const SceneEntry& scene_entry(SceneKind kind) {
    for (const SceneEntry& e : catalogue())
        if (e.kind == kind) return e;
    throw std::logic_error("scene_entry: a scene kind without a catalogue entry");
}

std::vector<std::string> setup_names() {
    std::vector<std::string> names;
    for (const SceneEntry& e : catalogue())
        for (const SetupEntry& s : e.setups) names.push_back(s.name);
    return names;
}

std::vector<std::string> default_setup_names() {
    std::vector<std::string> names;
    for (const SceneEntry& e : catalogue())
        for (const SetupEntry& s : e.setups)
            if (s.in_default_run) names.push_back(s.name);
    return names;
}

}  // namespace nsp_examples
