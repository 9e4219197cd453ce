// nsp/channel_tracking.hpp: tracking with per-channel pdfs (THEORY 5.3), the collision policies
// behind spectral MIS, independent tracking and spectral tracking.
//
// The free-flight loop (tracking.hpp) samples with the sampling channel c*'s majorant and reports
// every channel's majorant optical depth over the same stretches. The callbacks here choose the
// event with c*'s probabilities (or with one shared set, for spectral tracking) and multiply each
// channel's contribution and pdf of that vertex into a ChannelPathState (path_pdf.hpp):
//
//     null:    f_c *= mu_n,c Tbar_c        p_c *= mu_bar_c P_n,c Tbar_c
//     scatter: f_c *= mu_s,c Tbar_c        p_c *= mu_bar_c P_s,c Tbar_c
//
// with Tbar_c taken relative to a common reference so that nothing overflows.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include "core/counter.hpp"
#include "core/rng.hpp"
#include "majorant.hpp"
#include "medium.hpp"
#include "path_pdf.hpp"
#include "tracking.hpp"

namespace nsp {

namespace detail {
/// exp(-(tau_c - ref)) per channel, with ref = min(tau_c*, min_c tau_c + 80): every factor is at
/// most e^80 (no overflow) and the sampling channel's at least e^-80 (it never underflows). A
/// common factor of all channels cancels in every ratio the state forms.
template <class Spec>
Spec relative_transmittance(const Spec& tau, int c) noexcept {
    const float ref = std::min(tau[c], tau.minCoeff() + 80.f);
    return (ref - tau).exp();
}
}  // namespace detail

/// Channel c's density of each event at a collision when channel c is tracked alone with its own
/// majorant mu_c and event probabilities P_x,c of policy A: mu_c P_x,c (= mu_x,c wherever the
/// majorant bounds the extinction). A channel with majorant 0 has density 0 for every event.
template <class Spec>
struct ChannelEventDensities {
    Spec absorb;   ///< 0 with absorption::Weight
    Spec scatter;  ///< real scattering (with absorption::Weight: every real collision)
    Spec null;
};

/// See ChannelEventDensities. Probabilities are |mu_x,c| / (mu_a,c + mu_s,c + |mu_n,c|), as in
/// event_probabilities: where mu_n,c < 0 (bound::Signed) the null keeps a non-zero probability
/// and the contribution mu_n,c carries the sign (THEORY 4).
template <AbsorptionPolicy A, SpectralMode S>
ChannelEventDensities<typename S::Spectrum> channel_event_densities(const Coefficients<S>& k,
                                                                    const typename S::Spectrum& mu) noexcept {
    using Spec = typename S::Spectrum;
    const Spec a = k.sigma_a.max(0.f), s = k.sigma_s.max(0.f), t = a + s;
    const Spec n = (mu - t).abs();
    const Spec denom = t + n;
    const Spec scale = (denom > 0.f).select(mu / denom, 0.f);
    if constexpr (A::as_event) return {a * scale, s * scale, n * scale};
    else return {Spec::Zero(), t * scale, n * scale};
}

/// The event probabilities of spectral tracking (Kutz et al. 2017) under grey majorant mu > 0:
/// from the channel maxima of mu_a, mu_s and mu_n, or (`weighted`) from sum_c |w_c| mu_x,c with
/// the path throughput w (falling back to the maxima where w is 0).
template <AbsorptionPolicy A, bool weighted, SpectralMode S>
EventProbabilities shared_event_probabilities(const Coefficients<S>& k, float mu,
                                              const typename S::Spectrum& w) noexcept {
    using Spec = typename S::Spectrum;
    const Spec a = k.sigma_a.max(0.f), s = k.sigma_s.max(0.f);
    const Spec n = (Spec::Constant(mu) - a - s).abs();
    float pa = 0.f, ps = 0.f, pn = 0.f;
    if constexpr (weighted) {
        const Spec aw = w.abs();
        pa = (aw * a).sum();
        ps = (aw * s).sum();
        pn = (aw * n).sum();
    }
    if (!(pa + ps + pn > 0.f) || !std::isfinite(pa + ps + pn)) {
        if constexpr (A::as_event) {
            pa = a.maxCoeff();
            ps = s.maxCoeff();
        } else {
            ps = (a + s).maxCoeff();
        }
        pn = n.maxCoeff();
    }
    if constexpr (!A::as_event) {
        ps += pa;
        pa = 0.f;
    }
    const float inv = 1.f / (pa + ps + pn);  // > 0: some channel has a + s + n >= mu > 0
    return {pa * inv, ps * inv, pn * inv};
}

/// How a per-channel delta-tracked segment ended, and where.
struct ChannelTrack {
    SegmentEnd end = SegmentEnd::Passed;  ///< Passed, Scattered, Absorbed, Terminated (weight 0) or Aborted
    float t = 0.f;                        ///< the real collision, or tmax
};

/// Delta tracking with channel c's sampling and every channel's pdf (THEORY 5.3): updates the
/// state's f and uni at every vertex and, with `nee_alternative`, nee by ratio tracking's pdf
/// mu_bar_c Tbar_c of each null (the NEE pdf of the same nulls, THEORY 5.1). A state with
/// equiangular slots gets the same null factors there (eq.nee with nee, eq.vertex always), and
/// eq.vertex at the real vertex its Tbar_c since the last null (the equiangular technique's pdf
/// of the segment, without its density; THEORY 5.4).
///
/// A visitor with `enabled` is called at every tentative collision before its event is chosen, as
/// `visit(t, coefficients, mu, tbar, st)` with every channel's majorant, its Tbar since the last
/// tentative collision (relative, as the state's; ones for a grey majorant) and the state before
/// this collision (the collision estimator of emission, THEORY 5.7 with 5.3, uses it).
template <ChannelPolicy CP, AbsorptionPolicy A, SpectralMode S, UniformRng R, class Rec, bool kEq = false,
          class Visit = NoVisit>
struct ChannelDeltaCollision {
    using Spec = typename S::Spectrum;
    R& rng;
    Rec& rec;
    ChannelPathState<S, kEq>& st;
    int c;
    bool nee_alternative;
    Visit visit{};
    ChannelTrack out{};

    template <class V>
    bool operator()(float t, const Coefficients<S>& k, const V& mu_v, const V& tau_v) {
        constexpr bool grey = std::is_same_v<V, float>;
        const Spec mu = detail::broadcast_majorant<Spec>(mu_v);
        Spec tb;  // every channel's Tbar since the last tentative collision (a grey one cancels)
        if constexpr (!grey) tb = detail::relative_transmittance(tau_v, c);
        if constexpr (Visit::enabled) {
            if constexpr (grey) visit(t, k, mu, Spec(Spec::Ones()), st);
            else visit(t, k, mu, tb, st);
        }
        // Every channel's density mu_bar_c P_x,c of each event: its own (own pdfs) or the one
        // shared by all channels (spectral tracking). The sampling channel's picks the event.
        ChannelEventDensities<Spec> d;
        if constexpr (CP::own_pdfs) {
            d = channel_event_densities<A, S>(k, mu);
        } else {
            static_assert(grey, "nsp: spectral tracking shares one pdf and needs a grey majorant "
                                "(GlobalMajorant or GridMajorant)");
            const EventProbabilities p = shared_event_probabilities<A, CP::throughput_weighted, S>(k, mu_v, st.f);
            d = {Spec::Constant(mu_v * p.absorb), Spec::Constant(mu_v * p.scatter), Spec::Constant(mu_v * p.null)};
        }
        const float inv = 1.f / mu[c];  // mu_c* > 0: free flight samples nothing where it is 0
        const float pa = d.absorb[c] * inv, ps = d.scatter[c] * inv;
        const float u = rng.uniform();
        SegmentEnd event;
        Spec f_factor, p_factor;
        if (u < pa) {
            event = SegmentEnd::Absorbed;
            f_factor = k.sigma_a;
            p_factor = d.absorb;
        } else if (u < pa + ps || !(d.null[c] > 0.f)) {  // rounding never picks a null of probability 0
            event = SegmentEnd::Scattered;
            f_factor = k.sigma_s;
            p_factor = d.scatter;
        } else {
            event = SegmentEnd::Passed;  // a null
            f_factor = mu - k.sigma_t();
            p_factor = d.null;
        }
        if constexpr (Rec::enabled)
            rec.vertex(t, std::log(double(p_factor[c])) - double(channel_of(tau_v, c)));
        if (event == SegmentEnd::Absorbed) {  // the path ends without a contribution
            out = {event, t};
            return false;
        }
        Spec nee_factor = mu;  // ratio tracking's pdf of a null, for the NEE alternative (THEORY 5.1)
        if constexpr (!grey) {  // a grey majorant's Tbar is common to every channel and cancels
            f_factor *= tb;
            p_factor *= tb;
            nee_factor *= tb;
            if constexpr (kEq)  // Tbar_c alone at the real vertex: it is not a null
                if (event == SegmentEnd::Scattered) st.eq.vertex *= tb;
        }
        if (event == SegmentEnd::Passed && nee_alternative) {
            st.nee *= nee_factor;
            if constexpr (kEq) st.eq.nee *= nee_factor;
        }
        if constexpr (kEq)
            if (event == SegmentEnd::Passed) st.eq.vertex *= nee_factor;
        st.f *= f_factor;
        st.uni *= p_factor;
        if (!st.template renormalize<CP>(c)) {
            out = {SegmentEnd::Terminated, t};
            return false;
        }
        if (event == SegmentEnd::Scattered) {
            out = {event, t};
            return false;
        }
        return true;
    }
};

/// As track_channels_delta, calling `visit` at every tentative collision (see ChannelDeltaCollision).
template <ChannelPolicy CP, AbsorptionPolicy A, Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C,
          bool kEq, class Visit, class Rec = NoRecord>
ChannelTrack track_channels_delta_visiting(const M& medium, const Maj& majorant, const Ray& ray, float tmax,
                                           const typename M::Spectral::Wavelengths& lambda, int c,
                                           ChannelPathState<typename M::Spectral, kEq>& st, bool nee_alternative,
                                           R& rng, C& counter, Visit visit, Rec&& rec = Rec{}) {
    using S = typename M::Spectral;
    using RecT = std::remove_reference_t<Rec>;
    ChannelDeltaCollision<CP, A, S, R, RecT, kEq, Visit> cb{rng, rec, st, c, nee_alternative, std::move(visit)};
    const auto f = free_flight(medium, majorant, ray, 0.f, tmax, lambda, rng, counter, cb, kDefaultMaxCollisions, c);
    if (f.aborted) return {aborted_end(f), f.t};
    if (f.stopped) return cb.out;
    if constexpr (is_per_channel_majorant_v<Maj, M>) {
        const auto tb = detail::relative_transmittance(f.tau_tail, c);
        st.f *= tb;
        st.uni *= tb;
        st.nee *= tb;
        if constexpr (kEq) {
            st.eq.vertex *= tb;
            st.eq.nee *= tb;
        }
        if (!st.template renormalize<CP>(c)) return {SegmentEnd::Terminated, tmax};
    }
    if constexpr (RecT::enabled) rec.log_pdf -= double(channel_of(f.tau_tail, c));
    return {SegmentEnd::Passed, tmax};
}

/// Delta-tracks `ray` over [0, tmax] with sampling channel c, updating `st` (see
/// ChannelDeltaCollision). On `Passed` the state includes every channel's Tbar to tmax.
template <ChannelPolicy CP, AbsorptionPolicy A, Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C,
          bool kEq, class Rec = NoRecord>
ChannelTrack track_channels_delta(const M& medium, const Maj& majorant, const Ray& ray, float tmax,
                                  const typename M::Spectral::Wavelengths& lambda, int c,
                                  ChannelPathState<typename M::Spectral, kEq>& st, bool nee_alternative, R& rng,
                                  C& counter, Rec&& rec = Rec{}) {
    return track_channels_delta_visiting<CP, A>(medium, majorant, ray, tmax, lambda, c, st, nee_alternative, rng,
                                                counter, NoVisit{}, rec);
}

/// What ratio tracking a shadow segment with per-channel pdfs found, relative to one normaliser:
/// `f` = prod_j mu_n,c(n_j) Tbar_c (the segment's contribution, THEORY 3), `nee` = prod_j mu_bar_c(n_j)
/// Tbar_c (ratio tracking's pdf of the nulls with channel c's majorant) and `uni` = prod_j
/// mu_bar_c P_n,c(n_j) Tbar_c (the pdf with which channel c's delta tracking would have passed
/// through the same nulls; only with `uni_alternative`).
template <SpectralMode S>
struct ChannelShadow {
    using Spec = typename S::Spectrum;
    SegmentEnd end = SegmentEnd::Passed;  ///< Passed, Terminated (f below FLT_MIN: set to 0) or Aborted
    Spec f = Spec::Ones();
    Spec nee = Spec::Ones();
    Spec uni = Spec::Ones();
};

/// Ratio tracking with channel c's majorant and every channel's pdfs; see ChannelShadow.
/// `weights` is the path throughput at the segment's start (for throughput-weighted spectral
/// tracking's null probabilities in `uni`).
template <ChannelPolicy CP, AbsorptionPolicy A, SpectralMode S, class Rec>
struct ChannelRatioCollision {
    using Spec = typename S::Spectrum;
    Rec& rec;
    int c;
    bool uni_alternative;
    Spec weights;
    ChannelShadow<S> out{};

    template <class V>
    bool operator()(float t, const Coefficients<S>& k, const V& mu_v, const V& tau_v) {
        constexpr bool grey = std::is_same_v<V, float>;
        const Spec mu = detail::broadcast_majorant<Spec>(mu_v);
        Spec f_factor = mu - k.sigma_t(), nee_factor = mu, uni_factor = Spec::Ones();
        if (uni_alternative) {
            if constexpr (CP::own_pdfs) {
                uni_factor = channel_event_densities<A, S>(k, mu).null;
            } else {
                const auto p = shared_event_probabilities<A, CP::throughput_weighted, S>(k, mu_v, weights * out.f);
                uni_factor = Spec::Constant(mu_v * p.null);
            }
        }
        if constexpr (Rec::enabled) rec.vertex(t, std::log(double(mu[c])) - double(channel_of(tau_v, c)));
        if constexpr (!grey) {
            const Spec tb = detail::relative_transmittance(tau_v, c);
            f_factor *= tb;
            nee_factor *= tb;
            if (uni_alternative) uni_factor *= tb;
        }
        out.f *= f_factor;
        out.nee *= nee_factor;
        if (uni_alternative) out.uni *= uni_factor;
        return normalize();
    }

    /// Rescales by the largest ratio-tracking pdf (by channel c's alone for independent tracking);
    /// stops once every estimated channel's contribution is below the smallest normal float: a
    /// product of factors above 1/2 would otherwise stall at a denormal and never reach 0.
    bool normalize() {
        const float k = CP::mis_over_channels ? out.nee.maxCoeff() : out.nee[c];
        const bool negligible = CP::mis_over_channels
                                    ? (out.f.abs() < std::numeric_limits<float>::min() * k).all()
                                    : !(std::abs(out.f[c]) >= std::numeric_limits<float>::min() * k);
        if (!(k > 0.f) || !std::isfinite(k) || negligible) {
            out.f.setZero();
            out.end = SegmentEnd::Terminated;
            return false;
        }
        out.f /= k;
        out.nee /= k;
        out.uni /= k;
        return true;
    }
};

/// Ratio-tracks `ray` over [0, tmax] with channel c's majorant; see ChannelShadow.
template <ChannelPolicy CP, AbsorptionPolicy A, Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C,
          class Rec = NoRecord>
ChannelShadow<typename M::Spectral> track_channels_ratio(const M& medium, const Maj& majorant, const Ray& ray,
                                                         float tmax, const typename M::Spectral::Wavelengths& lambda,
                                                         int c, const typename M::Spectral::Spectrum& weights,
                                                         bool uni_alternative, R& rng, C& counter, Rec&& rec = Rec{}) {
    using S = typename M::Spectral;
    using RecT = std::remove_reference_t<Rec>;
    ChannelRatioCollision<CP, A, S, RecT> cb{rec, c, uni_alternative, weights};
    const auto f = free_flight(medium, majorant, ray, 0.f, tmax, lambda, rng, counter, cb, kDefaultMaxCollisions, c);
    if (f.aborted) {
        cb.out.f.setZero();
        cb.out.end = aborted_end(f);
        return cb.out;
    }
    if (f.stopped) return cb.out;
    if constexpr (is_per_channel_majorant_v<Maj, M>) {
        const auto tb = detail::relative_transmittance(f.tau_tail, c);
        cb.out.f *= tb;
        cb.out.nee *= tb;
        cb.out.uni *= tb;
        cb.normalize();
    }
    if constexpr (RecT::enabled) rec.log_pdf -= double(channel_of(f.tau_tail, c));
    return cb.out;
}

}  // namespace nsp
