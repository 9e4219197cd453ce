// nsp/estimators/surface_emission.hpp: volume emission in PathEstimator's loop over a SurfaceScene
// (THEORY 5.7 with 5.8). The three techniques of the media loop (estimators/path.hpp), across the
// null interfaces that cut a path's segment into pieces, one per medium:
// - the collision estimator: mu_a L_e / mu_bar at every tentative collision of a piece's delta
//   tracking (a visitor of VertexKernels::track_visiting);
// - the segment technique: a point drawn on a piece in proportion to its medium's power grid along
//   it, the nulls before it ratio-tracked;
// - NEE toward the volume from a real vertex (in a medium or on a surface): a medium picked in
//   proportion to its emitted power (SurfaceScene::select_emission), a point drawn by its power
//   grid, the shadow ray tracked piece by piece up to it; the point counts only where the walk
//   finds it inside the medium that drew it (the host's surfaces bound each medium).
// The three pdfs of a point y, reached from the last real vertex x through the pieces before
// y's, on the common scale of emission_pdfs (vertex.hpp): the pieces before y's share their
// tracking pdfs with the collision and the segment techniques, so only their nulls' P_n product
// (`nulls_before`) stays in those two, where the strategy weighs by null-scattering pdfs; NEE
// has its own, d^2 P(medium) p_V(y), with d = |y - x| the sum of the pieces' lengths.
#pragma once

#include <cmath>
#include <optional>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../geometry.hpp"
#include "../media/emissive.hpp"
#include "../surface_scene.hpp"
#include "../vertex.hpp"
#include "common.hpp"
#include "surface_walk.hpp"

namespace nsp::detail {

/// Where a piece of a path segment starts, seen from the segment's last real vertex: what the
/// MIS weights of emission on the piece need.
struct PieceStart {
    VertexPdf from;           ///< the last real vertex (or the camera)
    float nulls_before = 1.f; ///< prod P_n of the pieces between it and this one
    float distance = 0.f;     ///< the distance from it to this piece's origin
};

/// The three emission pdfs of a point at `distance` from the vertex `from`, whose own piece's
/// nulls before it have delta-tracking product `null_pdf_product`, majorant mu_bar there, segment
/// density p_seg (0: the technique does not run) and NEE density p_nee = P(medium) p_V (0: none).
template <PathStrategy St>
EmissionPdfs piece_emission_pdfs(const PieceStart& s, float null_pdf_product, float mu_bar, float p_seg,
                                 float distance, float p_nee) noexcept {
    const float before = St::null_pdfs ? s.nulls_before : 1.f;
    if (s.from.camera || s.from.delta)  // no NEE from the camera or a delta lobe
        return emission_pdfs<St>(1.f, before, null_pdf_product, mu_bar, p_seg, 0.f, 0.f);
    return emission_pdfs<St>(s.from.survival, s.from.direction_pdf * before, null_pdf_product, mu_bar, p_seg,
                             distance * distance, p_nee);
}

/// The collision estimator of one piece in emissive medium `medium` (index `index` of the scene):
/// beta w mu_a L_e / mu_bar at every tentative collision, weighted against the segment technique
/// (`along` > 0: its normaliser on this piece) and NEE.
template <PathStrategy St, class H, class Sc, class C>
struct PieceEmissionCollector {
    static constexpr bool enabled = true;
    using S = typename Sc::Spectral;
    const typename Sc::MediumType& medium;
    const Ray& ray;
    const typename S::Wavelengths& lambda;
    const typename S::Spectrum& beta;
    typename S::Spectrum& L;
    const H& heuristic;
    const EstimatorOptions& opts;
    C& counter;  ///< a MisRecorder records the contribution (counts.hpp)
    PieceStart start;
    float along, select;

    void operator()(float t, const Coefficients<S>& c, float mu_bar, const typename S::Spectrum& w,
                    float null_pdf_product) const {
        if (!(c.sigma_a > 0.f).any()) return;
        const Vec3 y = ray.at(t);
        const typename S::Spectrum le = medium.emission(y, lambda);
        if (!(le > 0.f).any()) return;
        float wt = 1.f;
        if constexpr (St::combines) {
            const float p_v = medium.emission_pdf(y);
            const EmissionPdfs p = piece_emission_pdfs<St>(start, null_pdf_product, mu_bar,
                                                           segment_density(opts, p_v, along), start.distance + t,
                                                           select * p_v);
            wt = emission_weight(heuristic, EmissionTechnique::Collision, p);
            if constexpr (MisRecorder<C>)
                record_emission_of(counter, (beta * w * c.sigma_a * le).mean() / mu_bar, p, opts,
                                   EmissionTechnique::Collision);
        }
        L += beta * w * c.sigma_a * le * (wt / mu_bar);
    }
};

/// Delta-tracks one piece of a path segment through emissive medium `index` up to `t_max` (the
/// next surface), collecting its emission: the segment technique first (combining strategies,
/// where EmissionOptions allow it), then the collision estimator where the strategy counts what
/// the piece reaches. A failed emission flight sets `status`; the piece's tracking is returned.
template <class K, class Sc, UniformRng R, LookupCounter C>
DeltaTrack<typename Sc::Spectral> track_emissive_piece(const K& k, const Sc& sc, int index, const Ray& ray, float t_max,
                                                       const PieceStart& start,
                                                       const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                       C& counter, const typename Sc::Spectrum& beta,
                                                       typename Sc::Spectrum& L, Status& status) {
    using St = typename K::Strategy;
    const auto& m = sc.media[std::size_t(index)];
    const float select = St::samples_lights ? sc.emission_selection_pdf(index) : 0.f;
    float along = 0.f;
    if constexpr (St::combines) {
        if (k.options().emission_along_segments) along = m.medium.emission_along(ray, 0.f, t_max);
        // With the expected count EstimatorOptions::emission_segment_count (THEORY 5.9).
        const float count = k.options().emission_segment_count;
        if (along > 0.f && draw_technique(count, rng)) {
            const double before = recorder_work(counter);
            const DistanceSample ds = m.medium.sample_emission_along(ray, 0.f, t_max, along, rng.uniform());
            if (ds.pdf > 0.f) {
                const auto tr = k.shadow(m.medium, m.majorant, ray, ds.t, lambda, rng, counter);
                if (tr.status != Status::Ok) {
                    status = tr.status;
                } else if ((tr.transmittance != 0.f).any()) {
                    const auto v = lookup_untracked(m.medium, m.majorant, ray, ds.t, lambda, counter);
                    if (!v) {
                        status = Status::Rejected;
                    } else if ((v->k.sigma_a > 0.f).any()) {
                        const Vec3 y = ray.at(ds.t);
                        const float p_v = m.medium.emission_pdf(y);
                        const EmissionPdfs p =
                            piece_emission_pdfs<St>(start, tr.null_pdf_product, v->mu,
                                                    segment_density(k.options(), p_v, along), start.distance + ds.t,
                                                    select * p_v);
                        const float w = emission_weight(k.heuristic(), EmissionTechnique::Segment, p);
                        const typename Sc::Spectrum f = beta * tr.transmittance * v->k.sigma_a * m.medium.emission(y, lambda);
                        if constexpr (MisRecorder<C>)
                            record_emission_of(counter, f.mean() / ds.pdf, p, k.options(), EmissionTechnique::Segment);
                        L += f * (w / (count * ds.pdf));
                    }
                }
            }
            record_segment_walk(counter, before);
        }
    }
    if (k.counts_hit(start.from))
        return k.track_visiting(m.medium, m.majorant, ray, t_max, lambda, rng, counter,
                                PieceEmissionCollector<St, typename K::Heuristic, Sc, C>{
                                    m.medium, ray, lambda, beta, L, k.heuristic(), k.options(), counter, start, along,
                                    select});
    return k.track(m.medium, m.majorant, ray, t_max, lambda, rng, counter);
}

/// A shadow ray toward a point drawn in emissive medium `target`, tracked piece by piece.
template <SpectralMode S>
struct EmissionShadow {
    typename S::Spectrum transmittance = S::Spectrum::Zero();
    float nulls_before = 1.f;      ///< prod P_n of the nulls of the pieces before the point's own
    float nulls_own = 1.f;         ///< and of the point's own piece
    float along = 0.f;             ///< the segment technique's normaliser on the point's piece (if asked for)
    Ray last{};                    ///< the point's piece: the point is last.at(t_last)
    float t_last = 0.f;
    bool reached = false;          ///< the walk found the point inside `target`
    Status status = Status::Ok;
};

/// Walks the shadow ray r from a point in medium `medium` over `distance` to a point drawn in
/// medium `target`: ratio tracking through every medium between the null interfaces it crosses.
/// Not reached where a surface that is not a null interface blocks it or the point lies in
/// another medium than `target`. With `with_along`, the segment technique's normaliser on the
/// point's piece, which runs to the next surface beyond the point, as the path's own piece would.
template <class K, class Sc, UniformRng R, LookupCounter C>
EmissionShadow<typename Sc::Spectral> emission_shadow(const K& k, const Sc& sc, Ray r, float distance, int medium,
                                                      int target, bool with_along,
                                                      const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                      C& counter) {
    using Sp = typename Sc::Spectral;
    EmissionShadow<Sp> out;
    out.transmittance = Sp::Spectrum::Ones();
    auto fail = [](Status s) {
        EmissionShadow<Sp> f;
        f.status = s;
        return f;
    };
    for (int crossing = 0; crossing <= kMaxInterfaceCrossings; ++crossing) {
        const SurfaceHit h = sc.geometry.intersect(r, with_along ? kInf : distance);
        if (!usable_hit(sc, h)) return fail(Status::InvalidInput);
        const bool last = !h.found() || h.t >= distance;
        if (sc.has_medium(medium)) {
            const auto& m = sc.media[std::size_t(medium)];
            const auto s = k.shadow(m.medium, m.majorant, r, last ? distance : h.t, lambda, rng, counter);
            if (s.status != Status::Ok) return fail(s.status);
            out.transmittance *= s.transmittance;
            (last ? out.nulls_own : out.nulls_before) *= s.null_pdf_product;
            if (!(out.transmittance != 0.f).any()) return fail(Status::Ok);
        }
        if (last) {
            if (medium != target) return fail(Status::Ok);
            out.reached = true;
            out.last = r;
            out.t_last = distance;
            if (with_along) out.along = sc.media[std::size_t(target)].medium.emission_along(r, 0.f, h.t);
            return out;
        }
        if (!crosses(sc, h)) return fail(Status::Ok);
        medium = h.medium_entered(r.d);
        r.o = h.p;
        distance -= h.t;
    }
    return fail(Status::InvalidInput);
}

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

/// NEE toward the emitting volume from real vertex `v` at x (arrived along wo, roulette survival
/// q, throughput beta; `side_medium` the medium a shadow ray in direction wi starts in, given by
/// `start_medium(wi)`): adds the weighted contribution to L; returns a failed flight's status.
template <class K, class Sc, class StartMedium, UniformRng R, LookupCounter C>
Status emission_event(const K& k, const Sc& sc, const SceneVertex& v, const Vec3& x, const Vec3& wo, float q,
                      StartMedium start_medium, const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                      const typename Sc::Spectrum& beta, typename Sc::Spectrum& L) {
    using St = typename K::Strategy;
    const auto e = draw_emission_point(sc, x, rng);
    if (!e) return Status::Ok;
    const auto& [i, select, y, dist, dist2, wi] = *e;
    const auto& m = sc.media[std::size_t(i)];
    const auto f = eval_vertex(sc, v, wo, wi, lambda);
    if (!(f.value != 0.f).any()) return Status::Ok;
    const bool with_along = St::combines && k.options().emission_along_segments;
    const auto sh = emission_shadow(k, sc, Ray{x, wi}, dist, start_medium(wi), i, with_along, lambda, rng, counter);
    if (sh.status != Status::Ok) return sh.status;
    if (!sh.reached || !(sh.transmittance != 0.f).any()) return Status::Ok;
    const auto c = lookup_untracked(m.medium, m.majorant, sh.last, sh.t_last, lambda, counter);
    if (!c) return Status::Rejected;
    if (!(c->k.sigma_a > 0.f).any()) return Status::Ok;
    float w = 1.f;
    if constexpr (St::combines) {
        const EmissionPdfs p =
            piece_emission_pdfs<St>(PieceStart{VertexPdf::scattered(q, f.pdf), sh.nulls_before, 0.f}, sh.nulls_own,
                                    c->mu, segment_density(k.options(), y.pdf, sh.along), dist, select * y.pdf);
        w = emission_weight(k.heuristic(), EmissionTechnique::Nee, p);
        if constexpr (MisRecorder<C>)
            record_emission_of(counter,
                               (beta * sh.transmittance * c->k.sigma_a * m.medium.emission(y.p, lambda) * f.value).mean() /
                                   (dist2 * select * y.pdf),
                               p, k.options(), EmissionTechnique::Nee);
    }
    L += beta * sh.transmittance * c->k.sigma_a * m.medium.emission(y.p, lambda) * f.value *
         (w / (dist2 * select * y.pdf));
    return Status::Ok;
}

}  // namespace nsp::detail
