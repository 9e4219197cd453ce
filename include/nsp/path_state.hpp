// nsp/path_state.hpp: the state of one path, grey or per channel, and every update and MIS weight
// the path loop and the technique kernels make with it (THEORY 5.1, 5.3, 5.4, 5.6-5.9).
//
// The channel axis is a value here, not a file: PathState<Ch, St, H, A, S> is chosen by its axis
// `Ch`, channels::Grey (one pdf for every channel, event probabilities from the channel means under
// a grey majorant: PathEstimator) or a ChannelPolicy (every channel's pdfs, THEORY 5.3:
// SpectralPathEstimator). Both keep what a path needs for the MIS weight of whatever it reaches:
//
//     grey:        beta = f / p (the throughput), the last real vertex's roulette survival and
//                  direction pdf (VertexPdf), prod P_n of the nulls since it (THEORY 5.1), and
//                  the equiangular ratio p_eq / p_track of that vertex (THEORY 5.4);
//     per channel: f_c and every technique's p_c relative to one normaliser, as ratios to the
//                  sampling channel's tracking (ChannelPathState, STYLE rule 7).
//
// The loop and the technique kernels (estimators/*.hpp) sample, walk and look up once; what they
// find goes to the state as a plain record (a light sample and its shadow walk, an equiangular or
// emission point), and the state adds its contribution with the weight its axis computes: the
// grey weights of vertex.hpp (weight_among over the techniques' pdfs) or the one-sample balance
// heuristic over channels x techniques (channel_estimate).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

#include "channel_tracking.hpp"
#include "core/counter.hpp"
#include "core/rng.hpp"
#include "majorant.hpp"
#include "mis.hpp"
#include "options.hpp"
#include "path_pdf.hpp"
#include "recorder.hpp"
#include "tracking.hpp"
#include "vertex.hpp"

namespace nsp {

namespace channels {
/// The grey axis: one pdf for every channel, event probabilities from the channel means under a
/// grey majorant (PathEstimator, BdptEstimator<..., Grey>). Exact for Mono and grey media; on
/// chromatic media the channels' weights multiply along a path (use a ChannelPolicy there).
struct Grey {
    static constexpr const char* name = "grey";
};
}  // namespace channels

/// True for the grey axis.
template <class Ch>
inline constexpr bool is_grey_axis_v = std::is_same_v<Ch, channels::Grey>;

/// A channel axis: channels::Grey, or a ChannelPolicy.
template <class Ch>
concept ChannelAxisOf = is_grey_axis_v<Ch> || ChannelPolicy<Ch>;

/// The type of a path's pdfs on axis Ch: one float (grey) or one per channel.
template <class Ch, SpectralMode S>
using PdfOf = std::conditional_t<is_grey_axis_v<Ch>, float, typename S::Spectrum>;

// ---------------------------------------------------------------------------------------------
// What the techniques hand the state

/// One piece of a shadow walk as the state's tracker returns it (ratio tracking through one
/// medium): `f` the piece's contribution (grey: its transmittance estimate; per channel: every
/// channel's prod mu_n,c Tbar_c; 0 where the estimate fell below float's range: the walk is
/// blocked), `nee` ratio tracking's pdf of its nulls and `uni` the pdf with which delta tracking
/// would have passed the same nulls (grey: 1 and prod P_n; per channel: every channel's, relative
/// to one normaliser); `status` a failed flight's.
template <class P, SpectralMode S>
struct ShadowPiece {
    Status status = Status::Ok;
    typename S::Spectrum f = S::Spectrum::Ones();
    P nee{};
    P uni{};
};

namespace detail {
/// One shadow piece on the grey axis: ratio tracking through medium (medium, majorant) with the
/// absorption policy of the kernels `k` (as VertexKernels::shadow), its null product where the
/// strategy weighs by null-scattering pdfs. The tracker is called itself: the flight checks the
/// ray (usable_ray, a NaN distance: Status::InvalidInput), which VertexKernels::shadow, made for a
/// host's rays, would check once more.
template <class K, class Med, class Maj, UniformRng R, LookupCounter C>
ShadowPiece<float, typename Med::Spectral> grey_shadow_piece(const K& k, const Med& medium, const Maj& majorant,
                                                             const Ray& r, float t_max,
                                                             const typename Med::Spectral::Wavelengths& lambda, R& rng,
                                                             C& counter) {
    (void)k;
    ShadowPiece<float, typename Med::Spectral> out;
    out.nee = 1.f;
    out.uni = 1.f;
    if (!(t_max >= 0.f)) [[unlikely]] {  // a negative or NaN distance: nothing to track
        out.status = Status::InvalidInput;
        out.f = Med::Spectral::Spectrum::Zero();
        return out;
    }
    const auto tr = track_ratio<typename K::Absorption, K::Strategy::null_pdfs>(medium, majorant, r, t_max, lambda,
                                                                               rng, counter);
    out.status = flight_status(tr.end);
    if (out.status != Status::Ok || tr.end == SegmentEnd::Terminated) {  // failed, or below float's range: 0
        out.f = Med::Spectral::Spectrum::Zero();
        return out;
    }
    out.f = tr.transmittance;
    out.uni = tr.null_pdf_product;
    return out;
}

/// One shadow piece per channel: ratio tracking with channel c's majorant and every channel's
/// pdfs (track_channels_ratio; `weights` the throughput throughput-weighted spectral tracking
/// needs, `uni_alternative` whether delta tracking's pdf of the nulls is wanted).
template <ChannelPolicy CP, AbsorptionPolicy A, class Med, class Maj, UniformRng R, LookupCounter C>
ShadowPiece<typename Med::Spectral::Spectrum, typename Med::Spectral> channel_shadow_piece(
    const Med& medium, const Maj& majorant, const Ray& r, float t_max, const typename Med::Spectral::Wavelengths& lambda,
    int c, const typename Med::Spectral::Spectrum& weights, bool uni_alternative, R& rng, C& counter) {
    const auto sh = track_channels_ratio<CP, A>(medium, majorant, r, t_max, lambda, c, weights, uni_alternative, rng,
                                                counter);
    ShadowPiece<typename Med::Spectral::Spectrum, typename Med::Spectral> out;
    if (sh.end == SegmentEnd::Passed) {
        out.f = sh.f;
        out.nee = sh.nee;
        out.uni = sh.uni;
    } else {
        out.status = sh.end == SegmentEnd::Terminated ? Status::Ok : flight_status(sh.end);
        out.f.setZero();
        out.nee.setZero();
        out.uni.setZero();
    }
    return out;
}
}  // namespace detail

/// Where a shadow walk ends: at `distance` (kInf: a light at infinity), in any medium, or only
/// where it finds the point inside medium `target` (NEE toward an emitting medium); `margin`: the
/// end is on a surface or light (the last 1e-4 of the way blocks nothing); `with_along`: the
/// segment technique's normaliser W on the last piece, up to the surface beyond the end.
struct WalkEnd {
    float distance = kInf;
    int target = -2;  ///< -2: any medium
    bool margin = true;
    bool with_along = false;
    int light = -1;  ///< the light the walk ends on (a light sample's index), -1: none
};

/// A shadow walk's result (estimators/scene_walk.hpp): its status; `f`, `nee`, `uni` the pieces'
/// products relative to one normaliser (as ShadowPiece); `seg` the segment technique's pdf of the
/// nulls (uni of the pieces before the last, nee of the last one; grey: the null product of the
/// pieces before the last); `reached` whether it got to the
/// end (not blocked, in the target medium); the last piece (`last`.at(`t_last`) is the end), the
/// medium it ends in and W there (with_along).
template <class P, SpectralMode S>
struct ShadowWalk {
    Status status = Status::Ok;
    bool reached = false;
    typename S::Spectrum f = S::Spectrum::Zero();
    P nee{}, uni{}, seg{};
    P uni_last{};  ///< the last piece's own uni (grey: the null product of the end point's piece)
    Ray last{};
    float t_last = 0.f;
    int end_medium = -1;
    float along = 0.f;
};

/// A real vertex as NEE sees it: `f` the path's contribution up to x and the pdfs with which
/// tracking (`p_track`) and equiangular sampling (`p_eq`, 0 where it cannot draw x) draw it, on
/// one scale (grey: relative to the pdf of the technique that drew x, so a tracked vertex has
/// p_track 1 and f the throughput; per channel: the state's normaliser); `survival` the roulette
/// survival tracking's continuation carries there; `eq_drawn`: x is an equiangular vertex (NEE
/// from it has count 1).
template <class P, SpectralMode S>
struct VertexRecord {
    typename S::Spectrum f = S::Spectrum::Zero();
    P p_track{};
    P p_eq{};
    float survival = 1.f;
    bool eq_drawn = false;
};

/// A light sample of NEE from a real vertex and its shadow walk: the vertex's value toward the
/// light (BSDF x cosine or phase) and that direction's pdf there, the light's radiance, solid-angle
/// pdf (selection included) and whether it is a delta light.
template <class P, SpectralMode S>
struct LightNee {
    typename S::Spectrum value = S::Spectrum::Zero();
    float direction_pdf = 0.f;
    typename S::Spectrum radiance = S::Spectrum::Zero();
    float light_pdf = 0.f;
    bool delta = false;
    ShadowWalk<P, S> walk;
};

/// An emission point y on a path's piece (the segment technique) or in the volume (NEE toward it),
/// after the walk to it and the lookup there: mu_a L_e at y (`source`), the majorant there, the
/// point's densities (the power grid's p_V, its medium's selection probability, W on its piece,
/// the distance from the last real vertex) and the walk's factors.
template <class P, SpectralMode S, class Walk = ShadowWalk<P, S>>
struct EmissionPoint {
    typename S::Spectrum source = S::Spectrum::Zero();
    P mu_bar{};
    float p_v = 0.f, select = 0.f, along = 0.f, distance = 0.f;
    float sampled_pdf = 0.f;  ///< the density the technique drew y with (the segment technique's ds.pdf)
    Walk walk{};              ///< a ShadowPiece on the point's own piece (the segment technique) or a ShadowWalk (NEE)
};

// ---------------------------------------------------------------------------------------------

template <class Ch, PathStrategy St, mis::Heuristic H, AbsorptionPolicy A, SpectralMode S, bool kEq = false>
class PathState;

/// The grey state: beta = f / p and the scalars of its weights (see the file comment).
template <PathStrategy St, mis::Heuristic H, AbsorptionPolicy A, SpectralMode S, bool kEq>
class PathState<channels::Grey, St, H, A, S, kEq> {
public:
    using P = float;
    using Spectrum = typename S::Spectrum;
    using Kernels = VertexKernels<St, H, A>;
    using Strategy = St;
    static constexpr bool kGrey = true;

    /// A path from the camera; the grey axis draws no channel (no selection needed).
    template <UniformRng R>
    PathState(const Kernels& k, const ChannelSelection<S>*, R&) noexcept : k_(k) {}

    const Kernels& kernels() const noexcept { return k_; }
    const EstimatorOptions& options() const noexcept { return k_.options(); }

    /// Whether an emitter the current segment reaches counts: always under a strategy that counts
    /// hits, and from the camera or after a delta lobe (where light sampling cannot reach it).
    bool counts_hits() const noexcept { return k_.counts_hit(from_); }
    /// Whether light sampling from the last real vertex could have drawn what the segment reaches
    /// (a combining strategy's NEE alternative): not from the camera or a delta lobe.
    bool nee_alternative() const noexcept { return St::combines && !from_.camera && !from_.delta; }

    /// The last real vertex (the camera ray's origin until there is one) and the distance walked
    /// from it along the current segment to the current piece's origin.
    Vec3 prev{0.f};
    float walked = 0.f;

    // -- Light hits ---------------------------------------------------------------------------

    /// The contribution of an emitter of radiance `le` that the current segment reached, which NEE
    /// from the last real vertex draws with solid-angle pdf `light_pdf` (0 where it cannot): beta
    /// le times the weight against NEE (and, with equiangular sampling, against equiangular + NEE).
    template <class C>
    Spectrum light_hit(const Spectrum& le, float light_pdf, C& counter) const noexcept {
        float w = 1.f;
        if constexpr (St::equiangular && St::combines) {
            if (!from_.camera && !from_.delta && light_pdf > 0.f) {
                const float s = unidirectional_pdf<St>(from_.survival, from_.direction_pdf, nulls_) / light_pdf;
                // Relative to tracking + hit: NEE 1 / s, equiangular + NEE from_eq / s.
                if (s > 0.f)
                    detail::record_light(counter, (beta_ * le).mean(), 1.f, 1.f / s, from_eq_ / s, k_.nee_count(),
                                         LightTechnique::Hit);
                w = equiangular_mis_weight(k_.heuristic(), VertexTechnique::TrackHit, k_.nee_count(), s, from_eq_);
            }
        } else {
            if constexpr (St::combines && MisRecorder<C>) {
                const float p_uni = unidirectional_pdf<St>(from_.survival, from_.direction_pdf, nulls_);
                if (!from_.camera && !from_.delta && p_uni > 0.f && light_pdf > 0.f)
                    detail::record_light(counter, (beta_ * le).mean(), 1.f, light_pdf / p_uni, 0.f, k_.nee_count(),
                                         LightTechnique::Hit);
            } else {
                (void)counter;
            }
            w = k_.hit_weight(from_, nulls_, light_pdf);
        }
        NSP_DEBUG_ASSERT(!(w < 0.f) && !(w > 1.f), "an MIS weight left [0, 1]");
        return beta_ * le * w;
    }

    // -- Tracking -----------------------------------------------------------------------------

    /// Starts a piece of the current segment in a medium (nothing to keep on the grey axis).
    void start_piece() noexcept {}

    /// Delta-tracks the piece `ray` over [0, t_max) through medium m, calling `visit` (an
    /// emission collector of collision_visitor, or NoVisit) at every tentative collision: the
    /// throughput takes the piece's weight, the null product its nulls'. Returns the piece's end;
    /// `eq_density` (select x the equiangular density at a real vertex t, 0 where the technique
    /// cannot draw it) then gives the vertex's equiangular ratio (vertex()).
    template <class Med, class Maj, class Visit, UniformRng R, LookupCounter C>
    SegmentEnd track(const Med& medium, const Maj& majorant, const Ray& ray, float t_max,
                     const typename S::Wavelengths& lambda, R& rng, C& counter, Visit&& visit, float& t) {
        // The tracker itself, not VertexKernels::track: the flight checks the ray (usable_ray, a
        // NaN t_max: SegmentEnd::InvalidInput), and the loop's t_max, a usable hit's, is >= 0.
        DeltaTrack<S> seg;
        if constexpr (std::remove_cvref_t<Visit>::enabled)
            seg = track_delta_visiting<A>(medium, majorant, ray, t_max, lambda, rng, counter,
                                          std::forward<Visit>(visit));
        else
            seg = track_delta<A>(medium, majorant, ray, t_max, lambda, rng, counter);
        if (flight_status(seg.end) != Status::Ok) return seg.end;
        beta_ *= seg.weight;
        nulls_ *= seg.null_pdf_product;
        t = seg.t;
        piece_nulls_ = seg.null_pdf_product;
        event_density_ = seg.event_density;
        return seg.end;
    }

    /// The equiangular technique's pdf, relative to tracking's, of the real vertex the last piece
    /// drew at t, where the technique draws it with density `eq_density` (select x its density
    /// there; THEORY 5.4): inf where the tracking pdf underflowed.
    float vertex_eq(float eq_density) const noexcept {
        return equiangular_over_tracking(eq_density, piece_nulls_, event_density_);
    }

    /// Ends a piece (nothing to keep on the grey axis).
    void end_piece() noexcept {}

    /// A tracker of one shadow piece through (medium, majorant): ratio tracking, its null product
    /// where the strategy weighs by null-scattering pdfs (detail::grey_shadow_piece).
    template <class Med, class Maj, UniformRng R, LookupCounter C>
    ShadowPiece<P, S> shadow_piece(const Med& medium, const Maj& majorant, const Ray& r, float t_max,
                                   const Spectrum&, bool, const typename S::Wavelengths& lambda, R& rng,
                                   C& counter) const {
        return detail::grey_shadow_piece(k_, medium, majorant, r, t_max, lambda, rng, counter);
    }

    /// The weights a shadow walk from the current state starts with (the throughput-weighted
    /// spectral tracking's null probabilities need them; nothing on the grey axis).
    Spectrum walk_weights() const noexcept { return beta_; }

    // -- Real vertices ------------------------------------------------------------------------

    /// The roulette survival at the path's depth-th real vertex (THEORY 5.6), decided before NEE.
    float survival(int depth) const noexcept { return k_.survival(depth, beta_); }

    /// The current real vertex for NEE, tracked (drawn by the segment, with equiangular ratio
    /// `eq` = vertex_eq(...), 0 where the technique cannot draw it).
    VertexRecord<P, S> vertex(float survival, float eq) const noexcept { return {beta_, 1.f, eq, survival, false}; }

    /// Plays roulette with survival q (THEORY 5.6): false when the path ends.
    template <UniformRng R>
    bool roulette(float q, R& rng) noexcept {
        if (q < 1.f) {
            if (!(rng.uniform() < q)) return false;
            beta_ /= q;
        }
        return true;
    }

    /// Continues the path from real vertex x along the direction `next` drew (after roulette with
    /// survival q), whose equiangular ratio was `eq`: Dead when nothing is left to carry.
    template <class Dir>
    StateScale scatter(const Dir& next, float q, float eq, const Vec3& x) noexcept {
        beta_ *= next.value / next.pdf;
        if (!(beta_ != 0.f).any()) return StateScale::Dead;
        from_ = VertexPdf::scattered(q, next.pdf, next.delta);
        from_eq_ = eq;
        nulls_ = 1.f;
        prev = x;
        walked = 0.f;
        return StateScale::Ok;
    }

    /// Whether NEE runs at this vertex (EstimatorOptions::nee_count, THEORY 5.9).
    template <UniformRng R>
    bool draw_nee(R& rng) const {
        return k_.draw_nee(rng);
    }

    // -- Contributions of the techniques ------------------------------------------------------

    /// NEE's contribution from vertex `x` with light sample and walk `s` (reached, not blocked):
    /// against tracking + hit and (equiangular strategies) equiangular + NEE.
    template <class C>
    Spectrum add_nee(const VertexRecord<P, S>& x, const LightNee<P, S>& s, C& counter) const noexcept {
        // NEE from a tracked vertex or a surface ran with the expected count nee_count; from an
        // equiangular vertex always (THEORY 5.9).
        const float count = x.eq_drawn ? 1.f : k_.nee_count();
        const Spectrum contribution = x.f * s.walk.f * s.radiance * s.value / s.light_pdf;
        const float nulls = s.walk.uni;
        float w;
        if constexpr (St::equiangular && St::combines) {
            // Relative to the technique that drew x followed by NEE (uncounted): tracking + NEE (its
            // count), tracking + hit (not for a delta light) and equiangular + NEE.
            const float sh = s.delta ? 0.f : unidirectional_pdf<St>(x.survival, s.direction_pdf, nulls) / s.light_pdf;
            w = equiangular_mis_weight(k_.heuristic(), x.eq_drawn ? VertexTechnique::EquiangularNee : VertexTechnique::TrackNee,
                                       x.p_track * k_.nee_count(), x.p_track * sh, x.p_eq);
            detail::record_light(counter, contribution.mean(), x.p_track * sh, x.p_track, x.p_eq, k_.nee_count(),
                                 x.eq_drawn ? LightTechnique::Other : LightTechnique::Nee);
        } else {
            w = k_.light_weight(x.survival, s.direction_pdf, nulls, s.light_pdf, s.delta);
            if constexpr (St::combines && MisRecorder<C>)
                detail::record_light(counter, contribution.mean(),
                                     s.delta ? 0.f : unidirectional_pdf<St>(x.survival, s.direction_pdf, nulls) / s.light_pdf,
                                     1.f, 0.f, k_.nee_count(), LightTechnique::Nee);
        }
        NSP_DEBUG_ASSERT(!(w < 0.f) && !(w > 1.f), "an MIS weight left [0, 1]");
        return contribution * (w / count);
    }

    /// An equiangular vertex x drawn on the current piece with density `eq_pdf` (select x the
    /// mixture's) after the walk `w` over the nulls before it, coefficients k and majorant mu there
    /// (THEORY 5.4; w: the piece ratio-tracked up to x): the vertex NEE starts from, or nothing
    /// where it carries nothing. Its roulette survival is the one tracking would give x, a
    /// function of the path.
    template <class Coeff, class Mu>
    std::optional<VertexRecord<P, S>> equiangular_vertex(const ShadowPiece<P, S>& w, const Coeff& k, const Mu& mu,
                                                         float eq_pdf, int depth) const noexcept {
        VertexRecord<P, S> x;
        x.f = beta_ * w.f * k.sigma_s / eq_pdf;
        if (!(x.f != 0.f).any()) return std::nullopt;
        x.p_eq = 1.f;
        x.eq_drawn = true;
        if constexpr (St::combines) {
            x.p_track = tracking_over_equiangular<A>(eq_pdf, w.uni, k, mu);
            if (x.p_track > 0.f) x.survival = k_.survival(depth, x.f / x.p_track);
        }
        return x;
    }

    /// The emission pdfs of a point y at `distance` from real vertex `from` (or the camera), reached
    /// through nulls of products `nulls_before` (the pieces before y's, tracked in the collision and
    /// segment techniques' pdfs alike) and `nulls_own` (y's own piece's), majorant mu_bar there,
    /// segment technique density p_seg (0: it does not run) and NEE density p_nee = P(medium) p_V
    /// (THEORY 5.7 with 5.8), on the common scale of emission_pdfs (vertex.hpp).
    static EmissionPdfs emission_pdfs_from(const VertexPdf& from, float nulls_before, float nulls_own, float mu_bar,
                                           float p_seg, float distance, float p_nee) noexcept {
        const float before = St::null_pdfs ? nulls_before : 1.f;
        if (from.camera || from.delta)  // no NEE from the camera or a delta lobe
            return emission_pdfs<St>(1.f, before, nulls_own, mu_bar, p_seg, 0.f, 0.f);
        return emission_pdfs<St>(from.survival, from.direction_pdf * before, nulls_own, mu_bar, p_seg,
                                 distance * distance, p_nee);
    }

    /// The collision estimator's visitor of the current piece (THEORY 5.7): at every tentative
    /// collision y, beta w mu_a L_e / mu_bar, weighed against the segment technique (`along` > 0)
    /// and NEE toward the volume (`select`: the piece's medium's selection probability).
    template <class Med, class C>
    struct Collector {
        static constexpr bool enabled = true;
        const PathState& st;
        const Med& medium;
        const Ray& ray;
        const typename S::Wavelengths& lambda;
        Spectrum& L;
        C& counter;
        float along, select;
        void operator()(float t, const Coefficients<S>& c, float mu_bar, const Spectrum& w, float null_pdf_product) const {
            if (!(c.sigma_a > 0.f).any()) return;
            const Vec3 y = ray.at(t);
            const Spectrum le = medium.emission(y, lambda);
            if (!(le > 0.f).any()) return;
            float wt = 1.f;
            if constexpr (St::combines) {
                const float p_v = medium.emission_pdf(y);
                // The pieces before this one: nulls_ (this piece's is multiplied in after its tracking).
                const EmissionPdfs p = emission_pdfs_from(st.from_, st.nulls_, null_pdf_product, mu_bar,
                                                          segment_density(st.options(), p_v, along), st.walked + t,
                                                          select * p_v);
                wt = emission_weight(st.k_.heuristic(), EmissionTechnique::Collision, p);
                if constexpr (MisRecorder<C>)
                    record_emission_of(counter, (st.beta_ * w * c.sigma_a * le).mean() / mu_bar, p, st.options(),
                                       EmissionTechnique::Collision);
            }
            L += st.beta_ * w * c.sigma_a * le * (wt / mu_bar);
        }
    };
    template <class Med, class C>
    Collector<Med, C> collector(const Med& medium, const Ray& ray, const typename S::Wavelengths& lambda, Spectrum& L,
                                C& counter, float along, float select) const noexcept {
        return {*this, medium, ray, lambda, L, counter, along, select};
    }

    /// The segment technique's contribution (THEORY 5.7): y drawn on the current piece with
    /// density e.sampled_pdf (its count in the options), the nulls before it on its piece
    /// ratio-tracked (e.walk), at e.distance from the piece's origin.
    template <class C>
    Spectrum add_segment(const EmissionPoint<P, S, ShadowPiece<P, S>>& e, C& counter) const noexcept {
        const float count = options().emission_segment_count;
        const EmissionPdfs p = emission_pdfs_from(from_, nulls_, e.walk.uni, e.mu_bar,
                                                  segment_density(options(), e.p_v, e.along), walked + e.distance,
                                                  e.select * e.p_v);
        const float w = emission_weight(k_.heuristic(), EmissionTechnique::Segment, p);
        const Spectrum f = beta_ * e.walk.f * e.source;
        if constexpr (MisRecorder<C>)
            record_emission_of(counter, f.mean() / e.sampled_pdf, p, options(), EmissionTechnique::Segment);
        return f * (w / (count * e.sampled_pdf));
    }

    /// NEE toward the volume from vertex x (THEORY 5.7): y drawn by its medium's power grid (and
    /// the medium by power) at e.distance, the vertex's value toward it `value` with pdf
    /// `direction_pdf`, the walk to it e.walk (reached).
    template <class C>
    Spectrum add_volume_nee(const VertexRecord<P, S>& x, const Spectrum& value, float direction_pdf,
                            const EmissionPoint<P, S>& e, C& counter) const noexcept {
        const float d2 = e.distance * e.distance, p_nee = e.select * e.p_v;
        const Spectrum f = x.f * e.walk.f * e.source * value;
        float w = 1.f;
        if constexpr (St::combines) {
            const EmissionPdfs p = emission_pdfs_from(VertexPdf::scattered(x.survival, direction_pdf), e.walk.seg,
                                                      e.walk.uni_last, e.mu_bar, segment_density(options(), e.p_v, e.along),
                                                      e.distance, p_nee);
            w = emission_weight(k_.heuristic(), EmissionTechnique::Nee, p);
            if constexpr (MisRecorder<C>)
                record_emission_of(counter, f.mean() / (d2 * p_nee), p, options(), EmissionTechnique::Nee);
        } else {
            (void)direction_pdf, (void)counter;
        }
        return f * (w / (d2 * p_nee));
    }

    /// The path's estimate so far (its throughput), for roulette and the status checks.
    const Spectrum& beta() const noexcept { return beta_; }

private:
    const Kernels& k_;
    Spectrum beta_ = Spectrum::Ones();
    VertexPdf from_ = VertexPdf::from_camera();
    float nulls_ = 1.f;              ///< prod P_n of the segments since the last real vertex
    float from_eq_ = 0.f;            ///< p_eq / p_track of the last real vertex (0 on a surface)
    float piece_nulls_ = 1.f;        ///< the last tracked piece's null product
    float event_density_ = 0.f;      ///< mu_bar P_s at its real vertex
};

/// The per-channel state (THEORY 5.3): every channel's contribution and technique pdfs relative to
/// one normaliser (ChannelPathState), the sampling channel c and the selection probabilities q.
template <ChannelPolicy CP, PathStrategy St, mis::Heuristic H, AbsorptionPolicy A, SpectralMode S, bool kEq>
class PathState<CP, St, H, A, S, kEq> {
public:
    using P = typename S::Spectrum;
    using Spectrum = typename S::Spectrum;
    using Kernels = VertexKernels<St, H, A>;
    using Strategy = St;
    static constexpr bool kGrey = false;

    /// A path from the camera with its sampling channel drawn by `selection` (one random number).
    template <UniformRng R>
    PathState(const Kernels& k, const ChannelSelection<S>* selection, R& rng)
        : opts_(k.options()), q_(selection->probabilities()), c_(selection->sample(rng.uniform())) {}

    const EstimatorOptions& options() const noexcept { return opts_; }
    int channel() const noexcept { return c_; }

    /// As the grey state's (see there).
    bool counts_hits() const noexcept { return St::hits_lights || camera_or_delta_; }
    bool nee_alternative() const noexcept { return nee_alternative_; }
    Vec3 prev{0.f};
    float walked = 0.f;

    // -- Light hits ---------------------------------------------------------------------------

    /// The contribution of an emitter of radiance `le` the current segment reached: every
    /// channel's pdf of the path by tracking and (where it exists) by NEE with its expected count,
    /// and equiangular + NEE (count 1), in the one-sample balance heuristic over channels.
    template <class C>
    Spectrum light_hit(const Spectrum& le, float light_pdf, C& counter) const noexcept {
        Spectrum pdf = st_.uni;
        if (nee_alternative_) {
            Spectrum other = Spectrum::Zero();
            if constexpr (St::equiangular) other = light_pdf * st_.eq.nee;
            pdf += opts_.nee_count * light_pdf * st_.nee + other;
            record_channels<CP>(counter, Spectrum(st_.f * le), st_.uni, Spectrum(light_pdf * st_.nee), other, q_, c_,
                                opts_.nee_count, LightTechnique::Hit);
        } else {
            (void)light_pdf, (void)counter;
        }
        return channel_estimate<CP>(st_.f, pdf, q_, c_) * le;
    }

    // -- Tracking -----------------------------------------------------------------------------

    /// Starts a piece: with equiangular or emission slots, eq.vertex takes tracking's pdf at the
    /// piece's start (the prefix of a vertex the piece's equiangular or segment technique draws).
    void start_piece() noexcept {
        if constexpr (kEq) st_.eq.vertex = st_.uni;
    }

    /// Delta-tracks the piece with sampling channel c, every channel's pdfs into the state (see
    /// the grey state's); `t` the real vertex where it scattered.
    template <class Med, class Maj, class Visit, UniformRng R, LookupCounter C>
    SegmentEnd track(const Med& medium, const Maj& majorant, const Ray& ray, float t_max,
                     const typename S::Wavelengths& lambda, R& rng, C& counter, Visit&& visit, float& t) {
        ChannelTrack seg;
        if constexpr (std::remove_cvref_t<Visit>::enabled)
            seg = track_channels_delta_visiting<CP, A>(medium, majorant, ray, t_max, lambda, c_, st_, nee_alternative_,
                                                       rng, counter, std::forward<Visit>(visit));
        else
            seg = track_channels_delta<CP, A>(medium, majorant, ray, t_max, lambda, c_, st_, nee_alternative_, rng,
                                              counter);
        t = seg.t;
        return seg.end;
    }

    /// Every channel's equiangular pdf of the real vertex the last piece drew, drawn with density
    /// `eq_density` (select x the mixture's): eq.vertex (the piece's prefix and nulls) times it.
    Spectrum vertex_eq(float eq_density) const noexcept {
        if constexpr (kEq) return st_.eq.vertex * eq_density;
        else return (void)eq_density, Spectrum(Spectrum::Zero());
    }

    /// Ends a piece: eq.vertex is the piece's alone.
    void end_piece() noexcept {
        if constexpr (kEq) st_.eq.vertex.setZero();
    }

    /// A tracker of one shadow piece: ratio tracking with channel c's majorant and every channel's
    /// pdfs (detail::channel_shadow_piece).
    template <class Med, class Maj, UniformRng R, LookupCounter C>
    ShadowPiece<P, S> shadow_piece(const Med& medium, const Maj& majorant, const Ray& r, float t_max,
                                   const Spectrum& weights, bool uni_alternative, const typename S::Wavelengths& lambda,
                                   R& rng, C& counter) const {
        return detail::channel_shadow_piece<CP, A>(medium, majorant, r, t_max, lambda, c_, weights, uni_alternative, rng,
                                                   counter);
    }

    /// The weights a shadow walk from the current state starts with: the path's f.
    const Spectrum& walk_weights() const noexcept { return st_.f; }

    // -- Real vertices ------------------------------------------------------------------------

    /// The roulette survival (THEORY 5.6) from what the path would contribute per unit of incident
    /// light, its largest channel estimate, as the grey state's max |beta|.
    float survival(int depth) const noexcept {
        if (!opts_.russian_roulette || depth < opts_.rr_start_depth) return 1.f;
        return std::min(opts_.rr_max_survival, channel_estimate<CP>(st_.f, st_.uni, q_, c_).abs().maxCoeff());
    }

    /// The current real vertex for NEE (see the grey state's); `eq` its equiangular pdfs (vertex_eq).
    VertexRecord<P, S> vertex(float survival, const Spectrum& eq) const noexcept {
        return {st_.f, st_.uni, eq, survival, false};
    }

    /// Plays roulette with survival q: false when the path ends (the pdfs take q at scatter()).
    template <UniformRng R>
    bool roulette(float q, R& rng) noexcept {
        return !(q < 1.f) || rng.uniform() < q;
    }

    /// Continues the path along the direction `next` drew at real vertex x after roulette with
    /// survival q; `eq` x's equiangular pdfs. The NEE alternative of the next segment starts from
    /// the prefix without roulette (and, with equiangular sampling, from x's equiangular pdf, kept
    /// apart because NEE toward emission is done from tracked vertices only); a delta lobe has
    /// none. Overflowed where a value left float's range (the path is discarded).
    template <class Dir>
    StateScale scatter(const Dir& next, float q, const Spectrum& eq, const Vec3& x) noexcept {
        camera_or_delta_ = next.delta;
        nee_alternative_ = St::combines && !next.delta;
        if (nee_alternative_) {
            st_.nee = st_.uni;
            if constexpr (St::equiangular) st_.eq.nee = eq;
        } else {
            (void)eq;
        }
        st_.f *= next.value;
        st_.uni *= q * next.pdf;
        if (const StateScale r = st_.template renormalize<CP>(c_); r != StateScale::Ok) return r;
        prev = x;
        walked = 0.f;
        return StateScale::Ok;
    }

    /// Whether NEE runs at this vertex (EstimatorOptions::nee_count, THEORY 5.9).
    template <UniformRng R>
    bool draw_nee(R& rng) const {
        return draw_technique(opts_.nee_count, rng);
    }

    // -- Contributions of the techniques ------------------------------------------------------

    /// NEE's contribution from vertex x: tracking + NEE (its count), tracking + hit, and
    /// equiangular + NEE (count 1), every channel's (THEORY 5.4 with 5.1, 5.3, 5.9).
    template <class C>
    Spectrum add_nee(const VertexRecord<P, S>& x, const LightNee<P, S>& s, C& counter) const noexcept {
        const float n = opts_.nee_count;
        const Spectrum nee = x.p_track * (s.light_pdf * s.walk.nee);
        Spectrum uni = Spectrum::Zero(), other = Spectrum::Zero();
        if (St::combines && !s.delta) uni = x.p_track * ((x.survival * s.direction_pdf) * s.walk.uni);
        if constexpr (St::equiangular) other = x.p_eq * (s.light_pdf * s.walk.nee);
        const Spectrum f = x.f * s.walk.f * s.value;
        record_channels<CP>(counter, Spectrum(f * s.radiance), uni, nee, other, q_, c_, n,
                            x.eq_drawn ? LightTechnique::Other : LightTechnique::Nee);
        return channel_estimate<CP>(f, Spectrum(n * nee + uni + other), q_, c_) * s.radiance;
    }

    /// An equiangular vertex drawn on the current piece (see the grey state's): every channel's
    /// equiangular and tracking pdfs of it, and the survival tracking would give it.
    template <class Coeff, class Mu>
    std::optional<VertexRecord<P, S>> equiangular_vertex(const ShadowPiece<P, S>& w, const Coeff& k, const Mu& mu,
                                                         float eq_pdf, int depth) const noexcept {
        VertexRecord<P, S> x;
        x.f = st_.f * w.f * k.sigma_s;
        if (!(x.f != 0.f).any()) return std::nullopt;
        x.p_eq = st_.uni * w.nee * eq_pdf;
        x.p_track = Spectrum::Zero();
        x.eq_drawn = true;
        if constexpr (St::combines) {
            // Every channel's tracking pdf of the same nulls and of a real scattering vertex at x.
            const Spectrum scatter = channel_scatter_densities<CP, A, S>(k, mu, Spectrum(st_.f * w.f));
            x.p_track = st_.uni * w.uni * scatter;
            // The survival tracking would give x: a function of the path (its f and tracking pdfs).
            if (opts_.russian_roulette && depth >= opts_.rr_start_depth)
                x.survival = std::min(opts_.rr_max_survival, channel_estimate<CP>(x.f, x.p_track, q_, c_).abs().maxCoeff());
        }
        return x;
    }

    /// The collision estimator's visitor of the current piece over channels (THEORY 5.7 with 5.3):
    /// at every tentative collision y, f Tbar mu_a L_e against every channel's pdfs of collision,
    /// NEE toward the volume (`select`) and the segment technique (`along` > 0).
    template <class Med, class C>
    struct Collector {
        static constexpr bool enabled = true;
        const PathState& self;
        const Med& medium;
        const Ray& ray;
        const typename S::Wavelengths& lambda;
        Spectrum& L;
        C& counter;
        float along, select;
        template <class State>
        void operator()(float t, const Coefficients<S>& k, const Spectrum& mu, const Spectrum& tbar, const State& st,
                        const ChannelEventDensities<Spectrum>&) const {
            if (!(k.sigma_a > 0.f).any()) return;
            const Vec3 y = ray.at(t);
            const Spectrum le = medium.emission(y, lambda);
            if (!(le > 0.f).any()) return;
            Spectrum pdf = st.uni * tbar * mu;
            const bool nee_alternative = self.nee_alternative_;
            if (nee_alternative || along > 0.f) {
                const float p_v = medium.emission_pdf(y);
                const float d = self.walked + t;
                if (nee_alternative) pdf += st.nee * tbar * (select * p_v * d * d);
                if (along > 0.f) pdf += st.eq.vertex * tbar * segment_density(self.opts_, p_v, along);
                if constexpr (MisRecorder<C> && St::combines)
                    record_emission_channels<CP>(
                        counter, Spectrum(st.f * tbar * k.sigma_a * le), Spectrum(st.uni * tbar * mu),
                        Spectrum(st.eq.vertex * tbar * segment_density(self.opts_, p_v, along)),
                        Spectrum(st.nee * tbar * (nee_alternative ? select * p_v * d * d : 0.f)), self.q_, self.c_,
                        self.opts_.emission_segment_count, EmissionTechnique::Collision);
            }
            L += channel_estimate<CP, Spectrum>(Spectrum(st.f * tbar * k.sigma_a * le), pdf, self.q_, self.c_);
        }
    };
    template <class Med, class C>
    Collector<Med, C> collector(const Med& medium, const Ray& ray, const typename S::Wavelengths& lambda, Spectrum& L,
                                C& counter, float along, float select) const noexcept {
        return {*this, medium, ray, lambda, L, counter, along, select};
    }

    /// The segment technique's contribution over channels (see the grey state's): the collision
    /// estimator's, the technique's and NEE's pdfs of y for every channel.
    template <class C>
    Spectrum add_segment(const EmissionPoint<P, S, ShadowPiece<P, S>>& e, C& counter) const noexcept {
        const float d = walked + e.distance;
        const float p_seg = segment_density(opts_, e.p_v, e.along);
        Spectrum pdf = st_.uni * e.walk.uni * e.mu_bar;
        pdf += st_.uni * e.walk.nee * p_seg;
        if (nee_alternative_) pdf += st_.nee * e.walk.nee * (e.select * e.p_v * d * d);
        const Spectrum f = st_.f * e.walk.f * e.source;
        if constexpr (MisRecorder<C>)
            record_emission_channels<CP>(counter, f, Spectrum(st_.uni * e.walk.uni * e.mu_bar),
                                         Spectrum(st_.uni * e.walk.nee * p_seg),
                                         Spectrum(st_.nee * e.walk.nee * (nee_alternative_ ? e.select * e.p_v * d * d : 0.f)),
                                         q_, c_, opts_.emission_segment_count, EmissionTechnique::Segment);
        // channel_estimate divides by the techniques' sum, where this one's pdf is count x p_seg:
        // the estimate of a technique run with its count (THEORY 5.9).
        return channel_estimate<CP, Spectrum>(f, pdf, q_, c_);
    }

    /// NEE toward the volume from vertex x over channels (see the grey state's).
    template <class C>
    Spectrum add_volume_nee(const VertexRecord<P, S>& x, const Spectrum& value, float direction_pdf,
                            const EmissionPoint<P, S>& e, C& counter) const noexcept {
        const Spectrum f = x.f * e.walk.f * e.source * value;
        Spectrum pdf = e.walk.nee * (e.select * e.p_v * e.distance * e.distance);
        if constexpr (St::combines) {
            const float dir = x.survival * direction_pdf;
            if constexpr (MisRecorder<C>)
                record_emission_channels<CP>(counter, f, Spectrum(x.p_track * (e.walk.uni * e.mu_bar * dir)),
                                             Spectrum(x.p_track * (e.walk.seg * (dir * segment_density(opts_, e.p_v, e.along)))),
                                             Spectrum(x.p_track * pdf), q_, c_, opts_.emission_segment_count,
                                             EmissionTechnique::Nee);
            pdf += e.walk.uni * e.mu_bar * dir;
            if (e.along > 0.f) pdf += e.walk.seg * (dir * segment_density(opts_, e.p_v, e.along));
        } else {
            (void)direction_pdf;
        }
        return channel_estimate<CP, Spectrum>(f, Spectrum(x.p_track * pdf), q_, c_);
    }

private:
    const EstimatorOptions& opts_;
    Spectrum q_;
    int c_;
    ChannelPathState<S, kEq> st_;
    bool camera_or_delta_ = true;   ///< no real vertex yet, or the last one drew a delta lobe
    bool nee_alternative_ = false;  ///< combining, and light sampling from that vertex could have drawn the segment's end
};

}  // namespace nsp
