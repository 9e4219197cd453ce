// nsp/path_state_grey.hpp: the path state on the grey axis (channels::Grey; nsp/path_state.hpp
// says what a path state is): the throughput beta = f / p, the last real vertex's roulette
// survival and direction pdf, the null product since it and its equiangular ratio, and the grey
// MIS weights of vertex.hpp over them.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

#include "path_records.hpp"

namespace nsp {

/// The grey state: beta = f / p and the scalars of its weights (see path_state.hpp).
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

    /// A partly null BSDF's choice at a surface (`lobe.probability` > 0): its null lobe (`pass`:
    /// beta x weight / P, and P joins the segment's null product as a null collision's P_n) or a
    /// real vertex (beta / (1 - P); a factor the vertex's techniques share). Dead where nothing
    /// is left to carry, Overflowed where beta left float's range.
    StateScale choose_lobe(bool pass, const NullLobe<S>& lobe) noexcept {
        if (pass) {
            beta_ *= lobe.weight / lobe.probability;
            nulls_ *= lobe.probability;
        } else {
            beta_ /= 1.f - lobe.probability;
        }
        if (!beta_.allFinite()) return StateScale::Overflowed;
        return (beta_ != 0.f).any() ? StateScale::Ok : StateScale::Dead;
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
    /// (THEORY 5.4; w: the piece ratio-tracked up to x), and under a control the grey control
    /// `ctl` there (tracking's density is then decomposition tracking's, THEORY 5.10): the vertex
    /// NEE starts from, or nothing where it carries nothing. Its roulette survival is the one tracking would give x, a
    /// function of the path.
    template <class Coeff, class Mu>
    std::optional<VertexRecord<P, S>> equiangular_vertex(const ShadowPiece<P, S>& w, const Coeff& k, const Mu& mu,
                                                         float eq_pdf, int depth, float ctl = 0.f) const noexcept {
        VertexRecord<P, S> x;
        x.f = beta_ * w.f * k.sigma_s / eq_pdf;
        if (!(x.f != 0.f).any()) return std::nullopt;
        x.p_eq = 1.f;
        x.eq_drawn = true;
        if constexpr (St::combines) {
            x.p_track = tracking_over_equiangular<A>(eq_pdf, w.uni, k, mu, ctl);
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

}  // namespace nsp
