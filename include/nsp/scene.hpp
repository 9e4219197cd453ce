// nsp/scene.hpp: media in empty space, the scene the example renderer's default scenes are: one
// medium with its majorant and phase function, lit by Lights<S> (a point, a sphere and an
// environment light). It is a SurfaceScene (surface_scene.hpp) whose geometry is the sphere light
// alone (EmptySpace) and whose medium fills space, so every estimator renders it with the one path
// loop it renders surfaces with.
#pragma once

#include <concepts>
#include <utility>
#include <vector>

#include "bsdf.hpp"
#include "geometry.hpp"
#include "light.hpp"
#include "light_sampler.hpp"
#include "majorant.hpp"
#include "majorants/crossing.hpp"
#include "medium.hpp"
#include "phase.hpp"
#include "surface_scene.hpp"

namespace nsp {

/// The lights of a Scene as a LightSampler: point, sphere and environment, chosen uniformly (the
/// order Lights<S> picks them in).
template <SpectralMode S>
using EmptySpaceLights = LightSampler<S, PointLight<S>, SphereLight<S>, EnvironmentLight<S>>;

/// No materials: media in empty space have no surface with a BSDF.
template <SpectralMode S>
using NoMaterials = Materials<S>;

namespace detail {
template <Medium M, MajorantPolicy<M> Maj, PhaseFunction P>
using SceneBase = SurfaceScene<EmptySpace, M, Maj, P, NoMaterials<typename M::Spectral>,
                               EmptySpaceLights<typename M::Spectral>>;
}  // namespace detail

/// Medium M tracked with majorant policy Maj, scattering with phase function P, lit by `lights`,
/// in empty space: a SurfaceScene (media[0] the medium, filling space; the sphere light its one
/// surface; the lights in a LightSampler). The sphere light must lie outside the medium's bounds
/// (the SurfaceScene checks it).
template <Medium M, MajorantPolicy<M> Maj, PhaseFunction P>
struct Scene : detail::SceneBase<M, Maj, P> {
    using Base = detail::SceneBase<M, Maj, P>;
    using Spectral = typename M::Spectral;

    /// Throws InvalidArgument if the sphere light overlaps the medium's bounds, or on what a
    /// SurfaceScene refuses: a majorant with one value (GlobalMajorant) whose bound policy forbids
    /// it for this medium (e.g. one built for another, less dense medium under
    /// bound::Guaranteed), or one under which a flight would run away (majorants/crossing.hpp).
    Scene(M m, Maj maj, P p, const Lights<Spectral>& l)
        : Base(geometry_of(l), media_of(std::move(m), std::move(maj), std::move(p)), NoMaterials<Spectral>(),
               lights_of(l), 0) {}

    /// The medium, its majorant and its phase function.
    const M& medium() const noexcept { return this->media[0].medium; }
    const Maj& majorant() const noexcept { return this->media[0].majorant; }
    const P& phase() const noexcept { return this->media[0].phase; }

private:
    static EmptySpace geometry_of(const Lights<Spectral>& l) {
        EmptySpace g;
        if (const auto& s = l.sphere()) {
            g.has_sphere = true;
            g.center = s->center;
            g.radius = s->radius;
            g.light = l.point() ? 1 : 0;  // the sampler's order: the point light, the sphere, the environment
        }
        return g;
    }
    /// The one medium, checked here first so that an error names the Scene the host built (the
    /// SurfaceScene's own checks then pass).
    static std::vector<SceneMedium<M, Maj, P>> media_of(M m, Maj maj, P p) {
        if constexpr (requires(const Maj& j) { { j.value() } -> std::convertible_to<float>; })
            detail::require_majorant_value<bound_policy_t<Maj>>(maj.value(), m.max_extinction(),
                                                                "Scene: the majorant value", " of the scene's medium");
        detail::require_trackable(m, maj, "Scene");
        std::vector<SceneMedium<M, Maj, P>> v;
        v.push_back({std::move(m), std::move(maj), std::move(p)});
        return v;
    }
    static EmptySpaceLights<Spectral> lights_of(const Lights<Spectral>& l) {
        std::vector<PointLight<Spectral>> points;
        std::vector<SphereLight<Spectral>> spheres;
        std::vector<EnvironmentLight<Spectral>> environments;
        if (l.point()) points.push_back(*l.point());
        if (l.sphere()) spheres.push_back(*l.sphere());
        if (l.environment()) environments.push_back(*l.environment());
        // Uniform selection needs no scene radius; 1 stands for it.
        return EmptySpaceLights<Spectral>(LightSelection::Uniform, 1.f, std::move(points), std::move(spheres),
                                          std::move(environments));
    }
};

/// A scene with the tightest global majorant of its medium.
template <Medium M, PhaseFunction P>
Scene<M, GlobalMajorant<M>, P> make_scene(M medium, P phase, const Lights<typename M::Spectral>& lights) {
    GlobalMajorant<M> maj(medium);
    return {std::move(medium), maj, std::move(phase), lights};
}

}  // namespace nsp
