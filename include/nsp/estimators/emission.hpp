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

/// The lookup at an emission point y = ray.at(t) that a technique drew and reached (the draw d,
/// a SegmentDraw or VolumeDraw, in medium entry m): d.c, d.drawn where y emits (sigma_a > 0),
/// or d.status Rejected (detail::lookup_untracked).
template <class D, class Entry, class W, LookupCounter C>
void look_up_emission_point(D& d, const Entry& m, const Ray& ray, float t, const W& lambda, C& counter) {
    const auto c = lookup_untracked(m.medium, m.majorant, ray, t, lambda, counter);
    if (!c) {
        d.status = Status::Rejected;
        return;
    }
    d.c = *c;
    d.drawn = (c->k.sigma_a > 0.f).any();
}

}  // namespace detail

/// The segment technique's draw on the piece `ray` over [0, t_max) through emissive medium
/// `index`, which the path state's kernel below and BDPT's segment strategy share: W on the piece
/// (`along`; 0: the technique does not run there); whether it ran there (`ran`, with the expected
/// count `count`, THEORY 5.9); the point y = ray.at(distance.t) drawn by the power grid along the
/// piece, the nulls before it tracked by `piece(ray, t)` (a ShadowPiece through the medium) and
/// the lookup at y. `drawn`: y was reached with sigma_a > 0 there; `status` a failed flight's, or
/// Rejected.
template <class P, SpectralMode S, class U>
struct SegmentDraw {
    Status status = Status::Ok;
    float along = 0.f;
    bool ran = false;  ///< the technique ran on the piece (its work is recorded)
    bool drawn = false;
    DistanceSample distance;
    ShadowPiece<P, S> piece;
    U c{};
};

template <class P, class Sc, class Piece, UniformRng R, LookupCounter C>
auto draw_segment(const Sc& sc, int index, const Ray& ray, float t_max, float count, Piece&& piece,
                  const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter) {
    const auto& m = sc.media[std::size_t(index)];
    SegmentDraw<P, typename Sc::Spectral, detail::SceneUntracked<Sc>> d;
    d.along = m.medium.emission_along(ray, 0.f, t_max);
    if (!(d.along > 0.f) || !draw_technique(count, rng)) return d;
    d.ran = true;
    d.distance = m.medium.sample_emission_along(ray, 0.f, t_max, d.along, rng.uniform());
    if (!(d.distance.pdf > 0.f && d.distance.t > 0.f)) return d;
    d.piece = piece(ray, d.distance.t);
    d.status = d.piece.status;
    if (d.status != Status::Ok || !(d.piece.f != 0.f).any()) return d;
    detail::look_up_emission_point(d, m, ray, d.distance.t, lambda, counter);
    return d;
}

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
        const double before = detail::recorder_work(counter);
        const auto d = draw_segment<P>(
            sc, index, ray, t_max, opts.emission_segment_count,
            [&](const Ray& r, float t) {
                return detail::state_shadow_piece(st, sc, index, r, t, st.walk_weights(), true, lambda, rng, counter);
            },
            lambda, rng, counter);
        if (d.status != Status::Ok) status = d.status;
        if (d.drawn) {
            const Vec3 y = ray.at(d.distance.t);
            EmissionPoint<P, S, ShadowPiece<P, S>> e;
            e.source = d.c.k.sigma_a * m.medium.emission(y, lambda);
            e.mu_bar = detail::majorant_as<P>(d.c.mu);
            e.p_v = m.medium.emission_pdf(y);  // at the point's own cell, as every technique evaluates it
            e.select = St::samples_lights ? sc.emission_selection_pdf(index) : 0.f;
            e.along = d.along;
            e.distance = d.distance.t;
            e.sampled_pdf = d.distance.pdf;
            e.walk = d.piece;
            L += st.add_segment(e, counter);
        }
        if (d.ran) detail::record_segment_walk(counter, before);
        return d.along;
    }
}

/// NEE's draw toward the emitting volume, which the path state's kernel below and BDPT's volume
/// NEE share: the point (detail::draw_emission_point, five random numbers), the vertex's value
/// and pdf toward it, the shadow walk to it (each medium tracked by `piece(medium_index, ray,
/// t_max, f_so_far)`, a ShadowPiece; W on the point's piece where `with_along`) and the lookup at
/// the point. `drawn`: the point was reached inside its medium with sigma_a > 0 there; `status` a
/// failed walk's or Rejected.
template <class P, SpectralMode S, class U>
struct VolumeDraw {
    Status status = Status::Ok;
    bool drawn = false;
    detail::EmissionPoint point;
    VertexDirection<S> vertex;
    ShadowWalk<P, S> walk;
    U c{};
};

template <class P, class Sc, class StartMedium, class Piece, UniformRng R, LookupCounter C>
auto draw_volume_nee(const Sc& sc, const SceneVertex& v, const Vec3& x, const Vec3& wo, StartMedium&& start_medium,
                     bool with_along, Piece&& piece, const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                     C& counter) {
    VolumeDraw<P, typename Sc::Spectral, detail::SceneUntracked<Sc>> d;
    const auto point = detail::draw_emission_point(sc, x, rng);
    if (!point) return d;
    d.point = *point;
    const auto& m = sc.media[std::size_t(point->index)];
    d.vertex = eval_vertex(sc, v, wo, point->wi, lambda);
    if (!(d.vertex.value != 0.f).any()) return d;
    d.walk = walk_shadow<P>(sc, Ray{x, point->wi}, start_medium(point->wi),
                            WalkEnd{point->dist, point->index, false, with_along}, lambda, piece);
    d.status = d.walk.status;
    if (d.status != Status::Ok || !d.walk.reached || !(d.walk.f != 0.f).any()) return d;
    detail::look_up_emission_point(d, m, d.walk.last, d.walk.t_last, lambda, counter);
    return d;
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
    const auto d = draw_volume_nee<P>(
        sc, v, x, wo, start_medium, St::combines && st.options().emission_along_segments,
        [&](int m, const Ray& r, float t_max, const Spectrum& f) {
            return detail::state_shadow_piece(st, sc, m, r, t_max, Spectrum(x_rec.f * f), true, lambda, rng, counter);
        },
        lambda, rng, counter);
    if (!d.drawn) return d.status;
    EmissionPoint<P, S> e;
    e.source = d.c.k.sigma_a * sc.media[std::size_t(d.point.index)].medium.emission(d.point.y.p, lambda);
    e.mu_bar = detail::majorant_as<P>(d.c.mu);
    e.p_v = d.point.y.pdf;
    e.select = d.point.select;
    e.along = d.walk.along;
    e.distance = d.point.dist;
    e.walk = d.walk;
    L += st.add_volume_nee(x_rec, d.vertex.value, d.vertex.pdf, e, counter);
    return Status::Ok;
}

}  // namespace nsp
