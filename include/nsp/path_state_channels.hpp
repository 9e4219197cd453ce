// nsp/path_state_channels.hpp: the path state over channels (a ChannelPolicy; nsp/path_state.hpp
// says what a path state is): every channel's contribution and technique pdfs relative to the
// sampling channel's tracking (ChannelPathState, THEORY 5.3), weighed by the one-sample balance
// heuristic over channels x techniques (channel_estimate).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

#include "path_records.hpp"

namespace nsp {

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

    /// A partly null BSDF's choice (see the grey state's): the null lobe multiplies f by its
    /// weight and every channel's tracking pdf by its probability (NEE's alternative crosses it
    /// with probability 1: its pdf stays); a real vertex multiplies the tracking pdfs by 1 - P.
    StateScale choose_lobe(bool pass, const NullLobe<S>& lobe) noexcept {
        if (pass) {
            st_.f *= lobe.weight;
            st_.uni *= lobe.probability;
        } else {
            st_.uni *= 1.f - lobe.probability;
        }
        return st_.template renormalize<CP>(c_);
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
    template <class Coeff, class Mu, class Ctl = float>
    std::optional<VertexRecord<P, S>> equiangular_vertex(const ShadowPiece<P, S>& w, const Coeff& k, const Mu& mu,
                                                         float eq_pdf, int depth, const Ctl& ctl = 0.f) const noexcept {
        VertexRecord<P, S> x;
        x.f = st_.f * w.f * k.sigma_s;
        if (!(x.f != 0.f).any()) return std::nullopt;
        x.p_eq = st_.uni * w.nee * eq_pdf;
        x.p_track = Spectrum::Zero();
        x.eq_drawn = true;
        if constexpr (St::combines) {
            // Every channel's tracking pdf of the same nulls and of a real scattering vertex at x.
            // Under a control (ctl > 0), decomposition tracking's: both routes' (THEORY 5.10); per
            // channel under a per-channel majorant's.
            const Spectrum scatter = channel_scatter_densities<CP, A, S>(k, mu, Spectrum(st_.f * w.f), ctl);
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
