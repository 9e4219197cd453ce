// examples/scene_choice.hpp: which scene and light set-up a render uses, as plain values the
// driver's files share (the catalogue, the plan, the report) without the compile-time lists of
// combinations.hpp.
#pragma once

#include <nsp/nsp.hpp>

#include "default_scene.hpp"

namespace nsp_examples {

/// Which of the scenes of default_scene.hpp a render uses.
enum class SceneKind {
    Cloud,      ///< the grey cloud (set-ups A, B, D)
    Chromatic,  ///< the chromatic cloud, extinction 1 : 4 : 16 (set-ups C1, C2, C3)
    Sparse,     ///< the sparse grey medium, a plume and five puffs (set-ups SA, SB: A's and B's lights)
    Fog,        ///< a fog bank lit by a lamp (set-ups F1, F2, F3)
    Plume,      ///< a flame inside the cloud, an emissive medium (set-up P1)
};

/// One light set-up of one scene: A, B or D of the grey cloud, C1, C2 or C3 of the chromatic cloud, SA or
/// SB of the sparse medium (set-up A's or B's lights), F1, F2 or F3 of the fog, P1 of the plume.
struct SceneChoice {
    SceneKind kind = SceneKind::Cloud;
    LightSetup cloud = LightSetup::A;                ///< with SceneKind::Cloud and SceneKind::Sparse
    ChromaticSetup chromatic = ChromaticSetup::Env;  ///< with SceneKind::Chromatic
    FogSetup fog = FogSetup::F1;                     ///< with SceneKind::Fog

    /// "A", "B", "D", "C1", "C2", "C3", "SA", "SB", "F1", "F2", "F3" or "P1".
    const char* name() const {
        switch (kind) {
            case SceneKind::Chromatic: return nsp_examples::name(chromatic);
            case SceneKind::Sparse: return cloud == LightSetup::A ? "SA" : "SB";
            case SceneKind::Fog: return nsp_examples::name(fog);
            case SceneKind::Plume: return "P1";
            default: return nsp_examples::name(cloud);
        }
    }
};

/// The Henyey-Greenstein asymmetry of a scene: the clouds' kPhaseG, the fog's kFogPhaseG, the
/// plume's smoke kPlumePhaseG.
inline float phase_g(SceneKind kind) {
    return kind == SceneKind::Fog ? kFogPhaseG : kind == SceneKind::Plume ? kPlumePhaseG : kPhaseG;
}

/// The lights of set-up `choice` (the plume has none: the flame is its light).
template <nsp::SpectralMode S>
nsp::Lights<S> scene_lights(const SceneChoice& choice) {
    switch (choice.kind) {
        case SceneKind::Chromatic: return chromatic_lights<S>(choice.chromatic);
        case SceneKind::Fog: return fog_lights<S>(choice.fog);
        case SceneKind::Plume: return {};
        default: return default_lights<S>(choice.cloud);
    }
}

/// The run-time values of the majorant policies (flags --grid-res and --majorant-scale).
struct MajorantSettings {
    int grid_res = 16;   ///< cells per axis of the grid majorants
    float scale = 0.5f;  ///< of the non-bounding majorants: the fraction of the bound they use
};

/// Hero wavelengths, four per path.
using Hero4 = nsp::Hero<4>;

}  // namespace nsp_examples
