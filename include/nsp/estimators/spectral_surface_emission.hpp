// nsp/estimators/spectral_surface_emission.hpp: volume emission in SpectralPathEstimator's loop
// over a SurfaceScene (THEORY 5.7 with 5.3 and 5.8): surface_emission.hpp's three techniques
// (collision estimator, segment technique, NEE toward the volume across null interfaces) with
// every channel's pdfs, as spectral.hpp has them in media in empty space. One ChannelPathState
// runs through the pieces of a segment, one per medium: `uni` the tracked path's pdf, `nee` the
// pdf of the same nulls ratio-tracked from the last real vertex (NEE's), and `eq.vertex` (the
// state's second pdf slot, which the equiangular strategies use in media) the segment technique's:
// `uni` at the piece's start, the piece's nulls ratio-tracked. A point y of a piece gets, relative
// to one normaliser: collision uni Tbar mu_bar(y), segment eq.vertex Tbar p_seg(y), NEE
// nee Tbar d^2 P(medium) p_V(y) with d = |y - x|.
#pragma once

#include <algorithm>
#include <cmath>

#include "../channel_tracking.hpp"
#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../media/emissive.hpp"
#include "../path_pdf.hpp"
#include "../surface_scene.hpp"
#include "common.hpp"
#include "surface_emission.hpp"
#include "surface_walk.hpp"

namespace nsp::detail {

/// The collision estimator of one piece in an emissive medium, over channels: at every tentative
/// collision y, f Tbar mu_a L_e against every channel's three pdfs (see the header).
template <ChannelPolicy CP, class Sc, class C, bool kRecord>
struct ChannelPieceEmission {
    static constexpr bool enabled = true;
    using S = typename Sc::Spectral;
    using Spec = typename S::Spectrum;
    const typename Sc::MediumType& medium;
    const Ray& ray;
    const typename S::Wavelengths& lambda;
    const Spec& q;
    int c;
    Spec& L;
    const EstimatorOptions& opts;
    C& counter;            ///< with kRecord (a combining strategy), a MisRecorder records the contribution
    bool nee_alternative;  ///< NEE toward the volume from the last real vertex could have drawn y
    float along, select, walked;

    template <class State>
    void operator()(float t, const Coefficients<S>& k, const Spec& mu, const Spec& tbar, const State& st,
                    const ChannelEventDensities<Spec>&) const {
        if (!(k.sigma_a > 0.f).any()) return;
        const Vec3 y = ray.at(t);
        const Spec le = medium.emission(y, lambda);
        if (!(le > 0.f).any()) return;
        Spec pdf = st.uni * tbar * mu;
        if (nee_alternative || along > 0.f) {
            const float p_v = medium.emission_pdf(y);
            const float d = walked + t;
            if (nee_alternative) pdf += st.nee * tbar * (select * p_v * d * d);
            if (along > 0.f) pdf += st.eq.vertex * tbar * segment_density(opts, p_v, along);
            if constexpr (MisRecorder<C> && kRecord)
                record_emission_channels<CP>(
                    counter, Spec(st.f * tbar * k.sigma_a * le), Spec(st.uni * tbar * mu),
                    Spec(st.eq.vertex * tbar * segment_density(opts, p_v, along)),
                    Spec(st.nee * tbar * (nee_alternative ? select * p_v * d * d : 0.f)), q, c,
                    opts.emission_segment_count, EmissionTechnique::Collision);
        }
        L += channel_estimate<CP, Spec>(Spec(st.f * tbar * k.sigma_a * le), pdf, q, c);
    }
};

/// Tracks one piece of a path segment through emissive medium `index` over channels up to
/// `t_max`, collecting its emission (see track_emissive_piece for the grey loop): the segment
/// technique where the strategy combines, then the collision estimator where it counts what the
/// piece reaches (`counts`). `st` must hold, in eq.vertex, its uni at the piece's start.
template <ChannelPolicy CP, PathStrategy St, AbsorptionPolicy A, class Sc, class State, UniformRng R, LookupCounter C>
ChannelTrack track_emissive_piece_channels(const EstimatorOptions& opts, const Sc& sc, int index, const Ray& ray,
                                           float t_max, bool counts, bool nee_alternative, float walked,
                                           const typename Sc::Spectral::Wavelengths& lambda,
                                           const typename Sc::Spectrum& q, int c, State& st, R& rng, C& counter,
                                           typename Sc::Spectrum& L, Status& status) {
    using Spectrum = typename Sc::Spectrum;
    const auto& m = sc.media[std::size_t(index)];
    const float select = St::samples_lights ? sc.emission_selection_pdf(index) : 0.f;
    float along = 0.f;
    if constexpr (St::combines) {
        if (opts.emission_along_segments) along = m.medium.emission_along(ray, 0.f, t_max);
        // With the expected count EstimatorOptions::emission_segment_count (THEORY 5.9): the
        // techniques' sum takes count x p_seg, which makes channel_estimate the count's estimate.
        if (along > 0.f && draw_technique(opts.emission_segment_count, rng)) {
            const double before = recorder_work(counter);
            const DistanceSample ds = m.medium.sample_emission_along(ray, 0.f, t_max, along, rng.uniform());
            if (ds.pdf > 0.f) {
                const auto sh = track_channels_ratio<CP, A>(m.medium, m.majorant, ray, ds.t, lambda, c, st.f, true, rng,
                                                            counter);
                if (sh.end != SegmentEnd::Passed && sh.end != SegmentEnd::Terminated) {
                    status = flight_status(sh.end);
                } else if (sh.end == SegmentEnd::Passed) {
                    const auto v = lookup_untracked(m.medium, m.majorant, ray, ds.t, lambda, counter);
                    if (!v) {
                        status = Status::Rejected;
                    } else if ((v->k.sigma_a > 0.f).any()) {
                        const Vec3 y = ray.at(ds.t);
                        const float p_v = m.medium.emission_pdf(y);
                        const float d = walked + ds.t;
                        Spectrum pdf = st.uni * sh.uni * broadcast_majorant<Spectrum>(v->mu);
                        pdf += st.uni * sh.nee * segment_density(opts, p_v, along);
                        if (nee_alternative) pdf += st.nee * sh.nee * (select * p_v * d * d);
                        const Spectrum f = st.f * sh.f * v->k.sigma_a * m.medium.emission(y, lambda);
                        if constexpr (MisRecorder<C>)
                            record_emission_channels<CP>(
                                counter, f, Spectrum(st.uni * sh.uni * broadcast_majorant<Spectrum>(v->mu)),
                                Spectrum(st.uni * sh.nee * segment_density(opts, p_v, along)),
                                Spectrum(st.nee * sh.nee * (nee_alternative ? select * p_v * d * d : 0.f)), q, c,
                                opts.emission_segment_count, EmissionTechnique::Segment);
                        L += channel_estimate<CP, Spectrum>(f, pdf, q, c);
                    }
                }
            }
            record_segment_walk(counter, before);
        }
    }
    if (counts)
        return track_channels_delta_visiting<CP, A>(
            m.medium, m.majorant, ray, t_max, lambda, c, st, nee_alternative, rng, counter,
            ChannelPieceEmission<CP, Sc, C, St::combines>{m.medium, ray, lambda, q, c, L, opts, counter, nee_alternative,
                                                          along, select, walked});
    return track_channels_delta<CP, A>(m.medium, m.majorant, ray, t_max, lambda, c, st, nee_alternative, rng, counter);
}

/// A shadow ray's per-channel factors toward a point drawn in emissive medium `target` (see
/// ChannelShadow), with `seg`: the segment technique's pdf of its nulls (uni of the pieces before
/// the point's own, nee of that one).
template <SpectralMode S>
struct ChannelEmissionShadow {
    using Spec = typename S::Spectrum;
    SegmentEnd end = SegmentEnd::Passed;  ///< Passed, or a failed piece's end, or InvalidInput for a bad hit
    bool reached = false;                 ///< the walk found the point inside `target`
    Spec f = Spec::Zero(), nee = Spec::Zero(), uni = Spec::Zero(), seg = Spec::Zero();
    float along = 0.f;  ///< the segment technique's normaliser on the point's piece (if asked for)
    Ray last{};         ///< the point's piece: the point is last.at(t_last)
    float t_last = 0.f;
};

/// Walks the shadow ray r from a point in medium `medium` over `distance` to a point drawn in
/// `target` (see emission_shadow, the grey walk), ratio tracking with channel c's majorant.
template <ChannelPolicy CP, AbsorptionPolicy A, class Sc, UniformRng R, LookupCounter C>
ChannelEmissionShadow<typename Sc::Spectral> channel_emission_shadow(
    const Sc& sc, Ray r, float distance, int medium, int target, bool with_along,
    const typename Sc::Spectral::Wavelengths& lambda, int c, const typename Sc::Spectrum& weights, R& rng, C& counter) {
    using Sp = typename Sc::Spectral;
    using Spec = typename Sp::Spectrum;
    ChannelEmissionShadow<Sp> out;
    auto fail = [](SegmentEnd e) {
        ChannelEmissionShadow<Sp> b;
        b.end = e;
        return b;
    };
    Spec f = Spec::Ones(), nee = Spec::Ones(), uni = Spec::Ones();  // the pieces so far
    for (int crossing = 0; crossing <= kMaxInterfaceCrossings; ++crossing) {
        const SurfaceHit h = sc.geometry.intersect(r, with_along ? kInf : distance);
        if (!usable_hit(sc, h)) return fail(SegmentEnd::InvalidInput);
        const bool last = !h.found() || h.t >= distance;
        if (sc.has_medium(medium)) {
            const auto& m = sc.media[std::size_t(medium)];
            const auto s = track_channels_ratio<CP, A>(m.medium, m.majorant, r, last ? distance : h.t, lambda, c,
                                                       Spec(weights * f), true, rng, counter);
            if (s.end == SegmentEnd::Terminated) return fail(SegmentEnd::Passed);
            if (s.end != SegmentEnd::Passed) return fail(s.end);
            if (last) out.seg = uni * s.nee;
            f *= s.f;
            nee *= s.nee;
            uni *= s.uni;
            // One common factor keeps many pieces inside float's range; it cancels.
            const float k = std::max(nee.maxCoeff(), uni.maxCoeff());
            if (k > 0.f && std::isfinite(k)) {
                f /= k;
                nee /= k;
                uni /= k;
                if (last) out.seg /= k;
            }
        }
        if (last) {
            if (medium != target) return fail(SegmentEnd::Passed);
            out.reached = true;
            out.f = f;
            out.nee = nee;
            out.uni = uni;
            out.last = r;
            out.t_last = distance;
            if (with_along) out.along = sc.media[std::size_t(target)].medium.emission_along(r, 0.f, h.t);
            return out;
        }
        if (!crosses(sc, h)) return fail(SegmentEnd::Passed);
        medium = h.medium_entered(r.d);
        r.o = h.p;
        distance -= h.t;
    }
    return fail(SegmentEnd::InvalidInput);
}

/// NEE toward the emitting volume over channels from real vertex `v` at x (arrived along wo,
/// roulette survival rr; `st` the state at x before roulette and the next direction;
/// `start_medium(wi)` the medium a shadow ray along wi starts in). Returns a failed flight's status.
template <ChannelPolicy CP, PathStrategy St, AbsorptionPolicy A, class Sc, class State, class StartMedium,
          UniformRng R, LookupCounter C>
Status channel_emission_event(const EstimatorOptions& opts, const Sc& sc, const SceneVertex& v, const Vec3& x,
                              const Vec3& wo, float rr, StartMedium start_medium,
                              const typename Sc::Spectral::Wavelengths& lambda, const typename Sc::Spectrum& q, int c,
                              const State& st, R& rng, C& counter, typename Sc::Spectrum& L) {
    using Spectrum = typename Sc::Spectrum;
    const auto e = draw_emission_point(sc, x, rng);
    if (!e) return Status::Ok;
    const auto& [i, select, y, dist, dist2, wi] = *e;
    const auto& m = sc.media[std::size_t(i)];
    const auto fv = eval_vertex(sc, v, wo, wi, lambda);
    if (!(fv.value != 0.f).any()) return Status::Ok;
    const bool with_along = St::combines && opts.emission_along_segments;
    const auto sh = channel_emission_shadow<CP, A>(sc, Ray{x, wi}, dist, start_medium(wi), i, with_along, lambda, c,
                                                   st.f, rng, counter);
    if (sh.end != SegmentEnd::Passed) return flight_status(sh.end);
    if (!sh.reached || !(sh.f != 0.f).any()) return Status::Ok;
    const auto k = lookup_untracked(m.medium, m.majorant, sh.last, sh.t_last, lambda, counter);
    if (!k) return Status::Rejected;
    if (!(k->k.sigma_a > 0.f).any()) return Status::Ok;
    const Spectrum f = st.f * sh.f * k->k.sigma_a * m.medium.emission(y.p, lambda) * fv.value;
    Spectrum pdf = sh.nee * (select * y.pdf * dist2);
    if constexpr (St::combines) {
        const float dir = rr * fv.pdf;
        if constexpr (MisRecorder<C>)
            record_emission_channels<CP>(counter, f, Spectrum(st.uni * (sh.uni * broadcast_majorant<Spectrum>(k->mu) * dir)),
                                         Spectrum(st.uni * (sh.seg * (dir * segment_density(opts, y.pdf, sh.along)))),
                                         Spectrum(st.uni * pdf), q, c, opts.emission_segment_count,
                                         EmissionTechnique::Nee);
        pdf += sh.uni * broadcast_majorant<Spectrum>(k->mu) * dir;
        if (sh.along > 0.f) pdf += sh.seg * (dir * segment_density(opts, y.pdf, sh.along));
    }
    L += channel_estimate<CP, Spectrum>(f, Spectrum(st.uni * pdf), q, c);
    return Status::Ok;
}

}  // namespace nsp::detail
