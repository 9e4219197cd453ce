// nsp/estimators/nee.hpp: next-event estimation toward the scene's lights from a real vertex
// (THEORY 5.1, 5.8): a light sample, the vertex's value and pdf toward it, and the shadow walk to
// it through every medium on the way (scene_walk.hpp). The path state weighs it (path_state.hpp):
// against tracking that hits the light and, with equiangular sampling, equiangular + NEE; grey or
// every channel's pdfs. A host's loop calls it with its own state as the path loop does.
#pragma once

#include <optional>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../path_state.hpp"
#include "../recorder.hpp"
#include "scene_walk.hpp"

namespace nsp {

/// NEE's draw toward the lights, which the path state's kernel below and BDPT's NEE strategy
/// share: the light sample, the vertex's value and pdf toward it and the shadow walk to it.
template <class P, SpectralMode S>
struct LightDraw {
    SampledLight<S> light;
    VertexDirection<S> vertex;
    ShadowWalk<P, S> walk;  ///< its status a failed flight's; reached: the light is seen
};

/// Draws NEE toward the lights of SurfaceScene `sc` from real vertex v at x (arrived along wo):
/// a light sampled with three random numbers (drawn also at a delta BSDF, where light sampling
/// cannot reach the path, so that the random stream does not depend on it), v's value and pdf
/// toward it, and the shadow walk from medium `start_medium(wi)`, each medium on the way tracked
/// by `piece(medium_index, ray, t_max, f_so_far, toward_delta)` (a ShadowPiece; toward_delta:
/// the light is a point or a direction, which no path can hit). The walk's work is recorded as a
/// shadow walk, NEE's own where `nee_counted`. std::nullopt: nothing drawn (no light, or v's
/// value toward it is 0).
template <class P, class Sc, class StartMedium, class Piece, UniformRng R, LookupCounter C>
[[gnu::always_inline]] inline std::optional<LightDraw<P, typename Sc::Spectral>> draw_light_nee(
    const Sc& sc, const SceneVertex& v, const Vec3& x, const Vec3& wo, StartMedium&& start_medium, Piece&& piece,
    bool nee_counted, const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter) {
    using Spectrum = typename Sc::Spectrum;
    const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
    if (v.on_surface() && sc.materials.is_delta(v.material)) return std::nullopt;
    LightDraw<P, typename Sc::Spectral> d;
    d.light = sc.lights.sample(x, u0, u1, u2, lambda);
    if (!(d.light.sample.pdf > 0.f)) return std::nullopt;
    d.vertex = eval_vertex(sc, v, wo, d.light.sample.wi, lambda);
    if (!(d.vertex.value != 0.f).any()) return std::nullopt;
    const bool toward_delta = d.light.sample.delta;
    const double before = detail::recorder_work(counter);
    d.walk = walk_shadow<P>(sc, Ray{x, d.vertex.wi}, start_medium(d.vertex.wi),
                            WalkEnd{d.light.sample.distance, -2, true, false, d.light.light}, lambda,
                            [&](int m, const Ray& r, float t_max, const Spectrum& f) {
                                return piece(m, r, t_max, f, toward_delta);
                            });
    detail::record_shadow_walk(counter, before, nee_counted);
    return d;
}

/// NEE from real vertex v at x (arrived along wo; `x_rec` its record: the path's contribution up to
/// x and its tracking and equiangular pdfs, roulette survival) toward the lights of SurfaceScene
/// `sc`, `start_medium(wi)` the medium a shadow ray along wi starts in: adds the weighted
/// contribution to L. Draws three random numbers (draw_light_nee). Returns a failed walk's status
/// (NonFinite: an overflowed flight, the caller discards the path).
template <class State, class Sc, class StartMedium, UniformRng R, LookupCounter C>
[[gnu::always_inline]] inline Status light_nee(
    const State& st, const Sc& sc, const SceneVertex& v, const Vec3& x, const Vec3& wo,
    const VertexRecord<typename State::P, typename Sc::Spectral>& x_rec, StartMedium&& start_medium,
    const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter, typename Sc::Spectrum& L) {
    using P = typename State::P;
    using S = typename Sc::Spectral;
    using Spectrum = typename Sc::Spectrum;
    using St = typename State::Strategy;
    const auto d = draw_light_nee<P>(
        sc, v, x, wo, start_medium,
        [&](int m, const Ray& r, float t_max, const Spectrum& f, bool toward_delta) {
            // Tracking's null pdfs matter only where tracking can reach the light too.
            return detail::state_shadow_piece(st, sc, m, r, t_max, Spectrum(x_rec.f * f), St::combines && !toward_delta,
                                              lambda, rng, counter);
        },
        !x_rec.eq_drawn, lambda, rng, counter);
    if (!d) return Status::Ok;
    if (d->walk.status != Status::Ok) return d->walk.status;
    if (!d->walk.reached) return Status::Ok;
    const LightSample<S>& ls = d->light.sample;
    L += st.add_nee(x_rec, LightNee<P, S>{d->vertex.value, d->vertex.pdf, ls.radiance, ls.pdf, ls.delta, d->walk},
                    counter);
    return Status::Ok;
}

}  // namespace nsp
