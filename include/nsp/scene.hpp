// nsp/scene.hpp: what the path estimators render: a medium with its majorant, a phase function
// and the lights, composed at compile time.
#pragma once

#include <concepts>
#include <utility>

#include "light.hpp"
#include "majorant.hpp"
#include "majorants/crossing.hpp"
#include "medium.hpp"
#include "phase.hpp"

namespace nsp {

/// A medium M tracked with majorant policy Maj, scattering with phase function P, lit by
/// `lights`. The sphere light must lie outside the medium's bounds (checked).
template <Medium M, MajorantPolicy<M> Maj, PhaseFunction P>
struct Scene {
    using MediumType = M;
    using MajorantType = Maj;
    using Spectral = typename M::Spectral;
    using Spectrum = typename Spectral::Spectrum;

    M medium;
    Maj majorant;
    P phase;
    Lights<Spectral> lights;

    /// Throws InvalidArgument if the sphere light overlaps the medium's bounds, if a majorant
    /// with one value (GlobalMajorant) has a value its bound policy forbids for this medium (e.g. one
    /// built for another, less dense medium under bound::Guaranteed), or if a flight through the
    /// medium would take more than kMaxFlightCollisions tentative collisions under the majorant
    /// (majorants/crossing.hpp: a render that would run away).
    Scene(M m, Maj maj, P p, Lights<Spectral> l)
        : medium(std::move(m)), majorant(std::move(maj)), phase(std::move(p)), lights(std::move(l)) {
        if constexpr (requires(const Maj& j) { { j.value() } -> std::convertible_to<float>; })
            detail::require_majorant_value<bound_policy_t<Maj>>(majorant.value(), medium.max_extinction(),
                                                                "Scene: the majorant value", " of the scene's medium");
        detail::require_trackable(medium, majorant, "Scene");
        if (const auto& s = lights.sphere()) {
            const Box b = medium.bounds();
            const Vec3 nearest = glm::clamp(s->center, b.lo, b.hi);
            if (glm::length(nearest - s->center) <= s->radius)
                detail::fail("SphereLight (centre ", s->center.x, ", ", s->center.y, ", ", s->center.z,
                             ", radius ", s->radius, ") overlaps the medium bounds; lights must lie "
                             "outside the medium");
        }
    }
};

/// A scene with the tightest global majorant of its medium.
template <Medium M, PhaseFunction P>
Scene<M, GlobalMajorant<M>, P> make_scene(M medium, P phase, Lights<typename M::Spectral> lights) {
    GlobalMajorant<M> maj(medium);
    return {std::move(medium), maj, std::move(phase), std::move(lights)};
}

}  // namespace nsp
