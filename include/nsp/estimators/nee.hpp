// nsp/estimators/nee.hpp: next-event estimation toward the scene's lights from a real vertex
// (THEORY 5.1, 5.8): a light sample, the vertex's value and pdf toward it, and the shadow walk to
// it through every medium on the way (scene_walk.hpp). The path state weighs it (path_state.hpp):
// against tracking that hits the light and, with equiangular sampling, equiangular + NEE; grey or
// every channel's pdfs. A host's loop calls it with its own state as the path loop does.
#pragma once

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../path_state.hpp"
#include "../recorder.hpp"
#include "scene_walk.hpp"

namespace nsp {

/// NEE from real vertex v at x (arrived along wo; `x_rec` its record: the path's contribution up to
/// x and its tracking and equiangular pdfs, roulette survival) toward the lights of SurfaceScene
/// `sc`, `start_medium(wi)` the medium a shadow ray along wi starts in: adds the weighted
/// contribution to L. Draws three random numbers (none are drawn again at a delta BSDF, where
/// light sampling cannot reach the path). Returns a failed walk's status (NonFinite: an overflowed
/// flight, the caller discards the path).
template <class State, class Sc, class StartMedium, UniformRng R, LookupCounter C>
[[gnu::always_inline]] inline Status light_nee(
    const State& st, const Sc& sc, const SceneVertex& v, const Vec3& x, const Vec3& wo,
    const VertexRecord<typename State::P, typename Sc::Spectral>& x_rec, StartMedium&& start_medium,
    const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter, typename Sc::Spectrum& L) {
    using P = typename State::P;
    using S = typename Sc::Spectral;
    using Spectrum = typename Sc::Spectrum;
    using St = typename State::Strategy;
    const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
    if (v.on_surface() && sc.materials.is_delta(v.material)) return Status::Ok;
    const SampledLight<S> ls = sc.lights.sample(x, u0, u1, u2, lambda);
    if (!(ls.sample.pdf > 0.f)) return Status::Ok;
    const auto fv = eval_vertex(sc, v, wo, ls.sample.wi, lambda);
    if (!(fv.value != 0.f).any()) return Status::Ok;
    const bool uni_alternative = St::combines && !ls.sample.delta;  // a point light cannot be hit
    const double before = detail::recorder_work(counter);
    const auto walk = walk_shadow<P>(
        sc, Ray{x, fv.wi}, start_medium(fv.wi), WalkEnd{ls.sample.distance, -2, true, false, ls.light},
        [&](int m, const Ray& r, float t_max, const Spectrum& f) {
            const auto& med = sc.media[std::size_t(m)];
            return st.shadow_piece(med.medium, med.majorant, r, t_max, Spectrum(x_rec.f * f), uni_alternative, lambda,
                                   rng, counter);
        });
    detail::record_shadow_walk(counter, before, !x_rec.eq_drawn);
    if (walk.status != Status::Ok) return walk.status;
    if (!walk.reached) return Status::Ok;
    L += st.add_nee(x_rec, LightNee<P, S>{fv.value, fv.pdf, ls.sample.radiance, ls.sample.pdf, ls.sample.delta, walk},
                    counter);
    return Status::Ok;
}

}  // namespace nsp
