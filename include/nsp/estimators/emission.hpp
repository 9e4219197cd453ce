// nsp/estimators/emission.hpp: volume emission's sampling techniques over a SurfaceScene (THEORY
// 5.7 with 5.8), beside the collision estimator the path state's tracker runs at every tentative
// collision (PathState::collector):
// - the segment technique: a point drawn on a piece of a segment (the part in one medium between
//   surfaces or null interfaces) in proportion to its medium's power grid along it, the nulls
//   before it ratio-tracked;
// - NEE toward the volume from a real vertex (in a medium or on a surface): a medium picked in
//   proportion to its emitted power (SurfaceScene::select_emission), a point drawn by its power
//   grid, the shadow walk to it; the point counts only where the walk finds it inside the medium
//   that drew it (the host's surfaces bound each medium).
// The three are weighed by their analytic pdfs (the path state: grey or per channel).
#pragma once

#include <cmath>
#include <optional>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../media/emissive.hpp"
#include "../path_state.hpp"
#include "../recorder.hpp"
#include "scene_walk.hpp"

namespace nsp {

namespace detail {
/// A majorant lookup's value (a float, or one per channel) as densities of type P (float for
/// grey paths, a spectrum per channel; a grey majorant broadcasts to every channel).
template <class P, class V>
P majorant_as(const V& mu) noexcept {
    if constexpr (std::is_same_v<P, float>) return float(mu);
    else return broadcast_majorant<P>(mu);
}
}  // namespace detail

namespace detail {

/// A point of an emissive medium drawn for volume NEE from x (THEORY 5.7 with 5.8): the medium
/// `index`, picked with probability `select`, the point with its power-grid pdf, and the way to it.
struct EmissionPoint {
    int index = -1;
    float select = 0.f;
    VolumeSample y;
    float dist = 0.f, dist2 = 0.f;
    Vec3 wi{0.f, 0.f, 1.f};  ///< unit direction from x toward y
};

/// Picks an emissive medium by power and draws a point from its power grid with five random
/// numbers; std::nullopt when nothing emits or the point is x itself.
template <class Sc, UniformRng R>
std::optional<EmissionPoint> draw_emission_point(const Sc& sc, const Vec3& x, R& rng) noexcept {
    const float us = rng.uniform(), u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
    EmissionPoint e;
    e.index = sc.select_emission(us);
    if (e.index < 0) return std::nullopt;
    e.select = sc.emission_selection_pdf(e.index);
    e.y = sc.media[std::size_t(e.index)].medium.sample_emission(u0, u1, u2, u3);
    if (!(e.y.pdf > 0.f) || !(e.select > 0.f)) return std::nullopt;
    const Vec3 dv = e.y.p - x;
    e.dist2 = glm::dot(dv, dv);
    if (!(e.dist2 > 0.f) || !std::isfinite(e.dist2)) return std::nullopt;
    e.dist = std::sqrt(e.dist2);
    e.wi = dv / e.dist;
    return e;
}

}  // namespace detail

/// The segment technique on the piece `ray` over [0, t_max) through emissive medium `index`
/// (combining strategies, EstimatorOptions::emission_along_segments): y drawn with the expected
/// count emission_segment_count, the nulls before it ratio-tracked, its weighted contribution
/// added to L; a failed flight sets `status`. Returns W, the technique's normaliser on the piece
/// (0: it does not run there), which the collision estimator's weights on the piece need.
template <class State, class Sc, UniformRng R, LookupCounter C>
float emission_segment(const State& st, const Sc& sc, int index, const Ray& ray, float t_max,
                       const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter, typename Sc::Spectrum& L,
                       Status& status) {
    using St = typename State::Strategy;
    using P = typename State::P;
    using S = typename Sc::Spectral;
    if constexpr (!St::combines) {
        (void)st, (void)sc, (void)index, (void)ray, (void)t_max, (void)lambda, (void)rng, (void)counter, (void)L,
            (void)status;
        return 0.f;
    } else {
        const auto& m = sc.media[std::size_t(index)];
        const EstimatorOptions& opts = st.options();
        if (!opts.emission_along_segments) return 0.f;
        const float along = m.medium.emission_along(ray, 0.f, t_max);
        // With the expected count EstimatorOptions::emission_segment_count (THEORY 5.9).
        if (!(along > 0.f) || !draw_technique(opts.emission_segment_count, rng)) return along;
        const double before = detail::recorder_work(counter);
        const DistanceSample ds = m.medium.sample_emission_along(ray, 0.f, t_max, along, rng.uniform());
        if (ds.pdf > 0.f) {
            const auto piece = st.shadow_piece(m.medium, m.majorant, ray, ds.t, st.walk_weights(), true, lambda, rng,
                                               counter);
            if (piece.status != Status::Ok) {
                status = piece.status;
            } else if ((piece.f != 0.f).any()) {
                const auto v = detail::lookup_untracked(m.medium, m.majorant, ray, ds.t, lambda, counter);
                if (!v) {
                    status = Status::Rejected;
                } else if ((v->k.sigma_a > 0.f).any()) {
                    const Vec3 y = ray.at(ds.t);
                    EmissionPoint<P, S, ShadowPiece<P, S>> e;
                    e.source = v->k.sigma_a * m.medium.emission(y, lambda);
                    e.mu_bar = detail::majorant_as<P>(v->mu);
                    e.p_v = m.medium.emission_pdf(y);  // at the point's own cell, as every technique evaluates it
                    e.select = St::samples_lights ? sc.emission_selection_pdf(index) : 0.f;
                    e.along = along;
                    e.distance = ds.t;
                    e.sampled_pdf = ds.pdf;
                    e.walk = piece;
                    L += st.add_segment(e, counter);
                }
            }
        }
        detail::record_segment_walk(counter, before);
        return along;
    }
}

/// NEE toward the emitting volume from real vertex v at x (arrived along wo; `x_rec` its record,
/// see light_nee; `start_medium(wi)` the medium a shadow ray along wi starts in): adds the
/// weighted contribution to L. Draws five random numbers. Returns a failed walk's status.
template <class State, class Sc, class StartMedium, UniformRng R, LookupCounter C>
Status volume_nee(const State& st, const Sc& sc, const SceneVertex& v, const Vec3& x, const Vec3& wo,
                  const VertexRecord<typename State::P, typename Sc::Spectral>& x_rec, StartMedium&& start_medium,
                  const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter, typename Sc::Spectrum& L) {
    using St = typename State::Strategy;
    using P = typename State::P;
    using S = typename Sc::Spectral;
    using Spectrum = typename Sc::Spectrum;
    const auto point = detail::draw_emission_point(sc, x, rng);
    if (!point) return Status::Ok;
    const auto& m = sc.media[std::size_t(point->index)];
    const auto fv = eval_vertex(sc, v, wo, point->wi, lambda);
    if (!(fv.value != 0.f).any()) return Status::Ok;
    const bool with_along = St::combines && st.options().emission_along_segments;
    const auto walk = walk_shadow<P>(
        sc, Ray{x, point->wi}, start_medium(point->wi), WalkEnd{point->dist, point->index, false, with_along},
        [&](int i, const Ray& r, float t_max, const Spectrum& f) {
            const auto& med = sc.media[std::size_t(i)];
            return st.shadow_piece(med.medium, med.majorant, r, t_max, Spectrum(x_rec.f * f), true, lambda, rng,
                                   counter);
        });
    if (walk.status != Status::Ok) return walk.status;
    if (!walk.reached || !(walk.f != 0.f).any()) return Status::Ok;
    const auto c = detail::lookup_untracked(m.medium, m.majorant, walk.last, walk.t_last, lambda, counter);
    if (!c) return Status::Rejected;
    if (!(c->k.sigma_a > 0.f).any()) return Status::Ok;
    EmissionPoint<P, S> e;
    e.source = c->k.sigma_a * m.medium.emission(point->y.p, lambda);
    e.mu_bar = detail::majorant_as<P>(c->mu);
    e.p_v = point->y.pdf;
    e.select = point->select;
    e.along = walk.along;
    e.distance = point->dist;
    e.walk = walk;
    L += st.add_volume_nee(x_rec, fv.value, fv.pdf, e, counter);
    return Status::Ok;
}

}  // namespace nsp
