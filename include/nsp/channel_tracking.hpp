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
#include <array>
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
/// How a segment ends whose path state renormalize found dead (Terminated) or overflowed.
inline SegmentEnd segment_end(StateScale r) noexcept {
    return r == StateScale::Dead ? SegmentEnd::Terminated : SegmentEnd::Overflowed;
}

/// exp(-(tau_c - ref)) per channel, with ref = min(tau_c*, min_c tau_c + 80): every factor is at
/// most e^80 (no overflow) and the sampling channel's at least e^-80 (it never underflows). A
/// common factor of all channels cancels in every ratio the state forms.
template <class Spec>
Spec relative_transmittance(const Spec& tau, int c) noexcept {
    const float ref = std::min(tau[c], tau.minCoeff() + 80.f);
    // An optical depth that overflowed to inf gives inf - inf = NaN: its Tbar is 0 (fuzzer finding 10).
    const Spec d = ref - tau;
    return (d == d).select(d.exp(), Spec::Zero());
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

namespace detail {
/// Every channel's null density mu_c P_n,c of channel_event_densities (the same formula) and its
/// null contribution mu_c - mu_t,c, in double: a product over many nulls of factors within 1e-6
/// of mu_c must not carry float's rounding of each factor (see detail::DoubleSpectrum).
template <SpectralMode S>
struct ChannelNullFactors {
    DoubleSpectrum<typename S::Spectrum> f, density;
};
template <SpectralMode S>
ChannelNullFactors<S> channel_null_factors(const Coefficients<S>& k, const typename S::Spectrum& mu_f) noexcept {
    using D = DoubleSpectrum<typename S::Spectrum>;
    const D mu = mu_f.template cast<double>();
    // Sums in float, as channel_event_densities and the majorants form them: where mu_c = mu_t,c
    // the null factors are exactly 0.
    const D t = (k.sigma_a.max(0.f) + k.sigma_s.max(0.f)).template cast<double>();
    const D n = (mu - t).abs();
    const D denom = t + n;
    return {mu - k.sigma_t().template cast<double>(), (denom > 0.0).select(n * mu / denom, 0.0)};
}
}  // namespace detail

namespace detail {
/// shared_event_probabilities (below) computed in scalar type T: {absorb, scatter, null}.
template <AbsorptionPolicy A, bool weighted, class T, SpectralMode S>
std::array<T, 3> shared_event_probabilities_in(const Coefficients<S>& k, float mu,
                                               const typename S::Spectrum& w) noexcept {
    using Arr = Eigen::Array<T, S::Spectrum::RowsAtCompileTime, 1>;
    const Arr a = k.sigma_a.max(0.f).template cast<T>(), s = k.sigma_s.max(0.f).template cast<T>();
    const Arr n = (Arr::Constant(T(mu)) - (k.sigma_a.max(0.f) + k.sigma_s.max(0.f)).template cast<T>()).abs();
    T pa = 0, ps = 0, pn = 0;
    if constexpr (weighted) {
        const Arr aw = w.abs().template cast<T>();
        pa = (aw * a).sum();
        ps = (aw * s).sum();
        pn = (aw * n).sum();
    }
    if (!(pa + ps + pn > T(0)) || !std::isfinite(pa + ps + pn)) {
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
        pa = 0;
    }
    // Divided in double: a denormal sum (a denormal majorant) made float's 1 / sum overflow
    // (found by the fuzzer). The sum is > 0: some channel has a + s + n >= mu > 0.
    const double sum = double(pa) + double(ps) + double(pn);
    return {T(double(pa) / sum), T(double(ps) / sum), T(double(pn) / sum)};
}
}  // namespace detail

/// The event probabilities of spectral tracking (Kutz et al. 2017) under grey majorant mu > 0:
/// from the channel maxima of mu_a, mu_s and mu_n, or (`weighted`) from sum_c |w_c| mu_x,c with
/// the path throughput w (falling back to the maxima where w is 0).
template <AbsorptionPolicy A, bool weighted, SpectralMode S>
EventProbabilities shared_event_probabilities(const Coefficients<S>& k, float mu,
                                              const typename S::Spectrum& w) noexcept {
    const auto p = detail::shared_event_probabilities_in<A, weighted, float>(k, mu, w);
    return {p[0], p[1], p[2]};
}

namespace detail {
/// Every channel's density mu_bar_c P_x,c of each event at a collision with coefficients k under
/// majorant mu_v (a Spectrum per channel, or a grey float): the channel's own (channel policies
/// with own pdfs) or the one spectral tracking shares, from the throughput w there (0 where the
/// majorant is 0).
template <ChannelPolicy CP, AbsorptionPolicy A, SpectralMode S, class V>
ChannelEventDensities<typename S::Spectrum> channel_densities(const Coefficients<S>& k, const V& mu_v,
                                                              const typename S::Spectrum& w) noexcept {
    using Spec = typename S::Spectrum;
    if constexpr (CP::own_pdfs) {
        return channel_event_densities<A, S>(k, broadcast_majorant<Spec>(mu_v));
    } else {
        static_assert(std::is_same_v<V, float>, "nsp: spectral tracking shares one pdf and needs a grey majorant "
                                                "(GlobalMajorant or GridMajorant)");
        if (!(mu_v > 0.f)) return {Spec::Zero(), Spec::Zero(), Spec::Zero()};
        const EventProbabilities p = shared_event_probabilities<A, CP::throughput_weighted, S>(k, mu_v, w);
        return {Spec::Constant(mu_v * p.absorb), Spec::Constant(mu_v * p.scatter), Spec::Constant(mu_v * p.null)};
    }
}

/// The same under decomposition tracking (THEORY 5.10 with 5.3) with grey control `ctl` and
/// segment majorant `mu_bar`: a real event's density is the sum over the control route (ctl, the
/// lookup scaled to extinction ctl, albedo kept) and the residual route (R = mu_bar - ctl, the
/// lookup scaled to mu_t,c - ctl); a null's is the residual's. Under a minorant, with own pdfs,
/// these are delta tracking's densities under mu_bar (every term is linear); where the control
/// exceeds a channel's extinction the residual has no real event there (its coefficients are
/// negative) and the control route's density is above it.
template <ChannelPolicy CP, AbsorptionPolicy A, SpectralMode S>
ChannelEventDensities<typename S::Spectrum> channel_decomposition_densities(const Coefficients<S>& k, float ctl,
                                                                            float mu_bar,
                                                                            const typename S::Spectrum& w) noexcept {
    using Spec = typename S::Spectrum;
    const float rate = mu_bar - ctl;
    ChannelEventDensities<Spec> d{Spec::Zero(), Spec::Zero(), Spec::Zero()};
    if (rate > 0.f) {
        Coefficients<S> r = k;
        to_residual(r, ctl, rate);
        d = channel_densities<CP, A, S>(r, rate, w);
    }
    if (ctl > 0.f) {
        Coefficients<S> q = k;
        to_control(q, ctl);
        const ChannelEventDensities<Spec> dc = channel_densities<CP, A, S>(q, ctl, w);
        d.absorb += dc.absorb;
        d.scatter += dc.scatter;
    }
    return d;
}
}  // namespace detail

namespace detail {
/// Every channel's densities under its own control ctl_c and majorant mu_c (a per-channel
/// majorant's control, ChannelGridControl; own pdfs): channel_decomposition_densities per channel,
/// a real event's the sum over the control route (ctl_c) and the residual route (mu_c - ctl_c), a
/// null's the residual's. Under a minorant, delta tracking's densities under mu_c.
template <AbsorptionPolicy A, SpectralMode S>
ChannelEventDensities<typename S::Spectrum> channel_control_densities(const Coefficients<S>& k,
                                                                      const typename S::Spectrum& ctl,
                                                                      const typename S::Spectrum& mu) noexcept {
    using Spec = typename S::Spectrum;
    if (!(ctl > 0.f).any()) return channel_event_densities<A, S>(k, mu);  // no control here: delta tracking's
    const Spec rate = (mu - ctl).max(0.f);
    Coefficients<S> r = k;
    to_residual(r, ctl, rate);
    ChannelEventDensities<Spec> d = channel_event_densities<A, S>(r, rate);
    Coefficients<S> q = k;
    to_control(q, ctl);
    const ChannelEventDensities<Spec> dc = channel_event_densities<A, S>(q, ctl);
    d.absorb += dc.absorb;
    d.scatter += dc.scatter;
    return d;
}

/// A null's contribution mu_c - mu_t,c and density R_c P_n,c(residual) under every channel's own
/// control (channel_control_densities' null, `d_null`), from the lookup's own mu_t (`t`): where
/// ctl_c <= mu_t,c <= mu_c the density is delta tracking's mu_c - mu_t,c, formed as it is there,
/// not through the residual's coefficients, whose extra roundings, relative to a difference near 0,
/// reached 1e-3 where a lookup came close to its majorant.
template <class Arr>
struct ControlNulls {
    Arr f, density;
};
template <class T, class Spec>
ControlNulls<Eigen::Array<T, Spec::RowsAtCompileTime, 1>> channel_control_nulls(const Spec& t, const Spec& mu,
                                                                                const Spec& ctl,
                                                                                const Spec& d_null) noexcept {
    using Arr = Eigen::Array<T, Spec::RowsAtCompileTime, 1>;
    const Arr n = mu.template cast<T>() - t.template cast<T>();
    return {n, ((t >= ctl) && (t <= mu)).select(n, d_null.template cast<T>())};
}
}  // namespace detail

/// Every channel's tracking density mu_bar_c P_s,c of a real scattering vertex with coefficients
/// k under majorant mu_v (a Spectrum per channel, or a grey float): the channel's own (channel
/// policies with own pdfs) or the one spectral tracking shares, from the throughput w there. What
/// an equiangular vertex's tracking pdf needs (THEORY 5.4 with 5.3). Under a grey control `ctl` > 0
/// (mu_v grey), decomposition tracking's: the sum over its two routes (THEORY 5.10); under a
/// per-channel majorant's control (`ctl` a Spectrum), every channel's own two routes.
template <ChannelPolicy CP, AbsorptionPolicy A, SpectralMode S, class V, class Ctl = float>
typename S::Spectrum channel_scatter_densities(const Coefficients<S>& k, const V& mu_v, const typename S::Spectrum& w,
                                               const Ctl& ctl = 0.f) noexcept {
    if constexpr (!std::is_same_v<Ctl, float>) {
        static_assert(CP::own_pdfs && !std::is_same_v<V, float>, "a per-channel control goes with own pdfs and a per-channel majorant");
        return detail::channel_control_densities<A, S>(k, ctl, mu_v).scatter;
    } else {
        if constexpr (std::is_same_v<V, float>)
            if (ctl > 0.f) return detail::channel_decomposition_densities<CP, A, S>(k, ctl, mu_v, w).scatter;
        return detail::channel_densities<CP, A, S>(k, mu_v, w).scatter;
    }
}

/// How a per-channel delta-tracked segment ended, and where.
struct ChannelTrack {
    SegmentEnd end = SegmentEnd::Passed;  ///< Passed, Scattered, Absorbed, Terminated (weight 0), Overflowed or Aborted
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
/// `visit(t, coefficients, mu, tbar, st, d)` with every channel's majorant, its Tbar since the last
/// tentative collision (relative, as the state's; ones for a grey majorant), the state before
/// this collision (the collision estimator of emission, THEORY 5.7 with 5.3, uses it) and every
/// channel's event densities there (ChannelEventDensities, the ones the event is chosen by).
///
/// Under a control (`kControlled`, which track_channels_delta_visiting sets where the majorant
/// carries one), decomposition tracking (THEORY 5.10 with 5.3): the sampling channel chooses the
/// event of each control or residual collision with that route's densities, and every channel's
/// pdf of a real vertex is the sum over both routes (its residual nulls' are the residual's). The
/// contributions are the medium's own (mu_s,c at a real vertex, mu_bar - mu_t,c at a null), and
/// the control's exp(-tau_c), the probability of no control collision, joins f and uni (not nee:
/// ratio tracking's pdf of the nulls is the residual's alone). The visitor is then called from
/// before_event at every collision with the medium's own lookup, the full majorant and the state
/// with exp(-tau_c) so far; a visitor with `under_control(R, e)` is told first the collision's
/// residual majorant R and e = exp(-tau_c) so far, and one with `control_end(e)` the segment's
/// exp(-tau_c) to its end (Passed or Scattered) when the tracking is done (per-channel BDPT's null
/// products are the residual's P_n,r = mu_n,r / R times exp(-tau_c), THEORY 5.10).
///
/// Under a per-channel majorant's control (`kChannelControl`, ChannelGridControl), each channel
/// has its own control ctl_c and residual majorant R_c: the loop hands over every channel's route
/// coefficients and rates with its residual depths, and before_event the lookup, majorants,
/// controls and each channel's control depth since the last collision. The sampling channel's route
/// chooses the event; each channel's pdfs are its own decomposition tracking's
/// (detail::channel_control_densities); f and uni take each channel's exp(-tau_c,c) step by step,
/// nee and the equiangular slots (residual ratio tracking's pdfs) do not. A visitor sees the state
/// with exp(-tau_c,c) of the step in f and uni and the residual's Tbar; per-channel BDPT's
/// visitor (`under_control`) does not take one.
template <ChannelPolicy CP, AbsorptionPolicy A, SpectralMode S, UniformRng R, class Rec, bool kEq = false,
          class Visit = NoVisit, bool kControlled = false, bool kChannelControl = false>
struct ChannelDeltaCollision {
    using Spec = typename S::Spectrum;
    static constexpr ControlUse control_use = ControlUse::Collide;
    static_assert(!kChannelControl || (kControlled && CP::own_pdfs),
                  "nsp: a per-channel majorant's control (ChannelGridControl) needs a channel policy with own pdfs "
                  "(channels::SpectralMis or channels::Independent)");
    R& rng;
    Rec& rec;
    ChannelPathState<S, kEq>& st;
    int c;
    bool nee_alternative;
    Visit visit{};
    ChannelTrack out{};
    std::uint32_t nulls = 0;
    /// Under a control, the current collision's own lookup, grey control and majorant
    /// (before_event), from which a real event's densities over both routes are formed: at every
    /// collision for a visitor (which sees them), else once, at the real event.
    struct Kept {
        Coefficients<S> k{};
        float ctl = 0.f;
        float mu_bar = 0.f;
        ChannelEventDensities<Spec> d{};
    };
    /// Under a per-channel majorant's control, the collision's lookup, every channel's majorant and
    /// control, exp(-tau_c,c) of the step and the sampling channel's control depth of the step.
    struct KeptChannels {
        Coefficients<S> k{};
        Spec mu{}, ctl{}, ec{};
        float tau_c = 0.f;
        ChannelEventDensities<Spec> d{};
        Spec tail{};  ///< every channel's control depth from the last collision to tmax (control_tail)
    };
    [[no_unique_address]] std::conditional_t<kChannelControl, KeptChannels,
                                             std::conditional_t<kControlled, Kept, detail::Empty>> kept{};

    /// Under a per-channel majorant's control, the loop's call at every collision before its
    /// coefficients become the route's (see the struct's comment).
    void before_event(const Coefficients<S>& k, const Spec& mu, const Spec& ctl, const Spec& tau_c)
        requires kChannelControl
    {
        kept.k = k;
        kept.mu = mu;
        kept.ctl = ctl;
        kept.ec = detail::channel_control_transmittance(tau_c);
        kept.tau_c = tau_c[c];
    }
    void control_tail(const Spec& tau_c) noexcept
        requires kChannelControl
    {
        kept.tail = tau_c;
    }

    /// Under a control, the loop's call at every collision y, control or residual, before its
    /// coefficients become the route's: keeps the medium's own lookup `k`, `ctl` and `mu_bar`. With
    /// a visitor it forms every channel's densities of a real event at y over both routes, the
    /// control's ctl P_x,c(control) plus the residual's R P_x,c(residual), R = mu_bar - ctl (nulls:
    /// the residual's), and calls the visitor with them, the full majorant `mu_bar` and the state
    /// with exp(-tau_ctl) in f and uni.
    void before_event(float t, const Coefficients<S>& k, float mu_bar, float ctl, double tau_ctl)
        requires(kControlled && !kChannelControl)
    {
        kept.k = k;
        kept.ctl = ctl;
        kept.mu_bar = mu_bar;
        if constexpr (Visit::enabled) {
            kept.d = detail::channel_decomposition_densities<CP, A, S>(k, ctl, mu_bar, st.f);
            const ChannelEventDensities<Spec>& d = kept.d;
            ChannelPathState<S, kEq> here = st;
            const float e = tau_ctl > 0.0 ? float(std::exp(-tau_ctl)) : 1.f;
            if (tau_ctl > 0.0) {
                here.f *= e;
                here.uni *= e;
            }
            if constexpr (requires { visit.under_control(mu_bar, e); }) visit.under_control(mu_bar - ctl, e);
            visit(t, k, Spec(Spec::Constant(mu_bar)), Spec(Spec::Ones()), here, d);
        } else {
            (void)t, (void)tau_ctl;
        }
    }

    template <class V>
    bool operator()(float t, const Coefficients<S>& k, const V& mu_v, const V& tau_v) {
        constexpr bool grey = std::is_same_v<V, float>;
        static_assert(kChannelControl ? !grey : (!kControlled || grey), "a grey majorant's control is grey; ChannelGridControl's per channel");
        const Spec mu = detail::broadcast_majorant<Spec>(mu_v);
        Spec tb;  // every channel's Tbar since the last tentative collision (a grey one cancels)
        if constexpr (!grey) tb = detail::relative_transmittance(tau_v, c);
        // Every channel's density mu_bar_c P_x,c of each event: its own (own pdfs) or the one
        // shared by all channels (spectral tracking). The sampling channel's picks the event
        // (under a control: the route's).
        const ChannelEventDensities<Spec> d = detail::channel_densities<CP, A, S>(k, mu_v, st.f);
        // Under a per-channel control: f and uni's Tbar of the step, the residual's times exp(-tau_c,c).
        [[maybe_unused]] Spec tbf;
        if constexpr (kChannelControl) {
            tbf = tb * kept.ec;
            if constexpr (Visit::enabled) {
                kept.d = detail::channel_control_densities<A, S>(kept.k, kept.ctl, kept.mu);
                ChannelPathState<S, kEq> here = st;
                here.f *= kept.ec;
                here.uni *= kept.ec;
                visit(t, kept.k, kept.mu, tb, here, kept.d);
            }
        }
        if constexpr (Visit::enabled && !kControlled) {
            if constexpr (grey) visit(t, k, mu, Spec(Spec::Ones()), st, d);
            else visit(t, k, mu, tb, st, d);
        }
        // mu_c* > 0: free flight samples nothing where it is 0. In double: a denormal mu_c* made
        // float's 1 / mu_c* overflow (found by the fuzzer).
        const double inv = 1.0 / double(mu[c]);
        const float pa = float(d.absorb[c] * inv), ps = float(d.scatter[c] * inv);
        const float u = rng.uniform();
        SegmentEnd event;
        if (u < pa) event = SegmentEnd::Absorbed;
        else if (u < pa + ps || !(d.null[c] > 0.f)) event = SegmentEnd::Scattered;  // never a null of probability 0
        else event = SegmentEnd::Passed;  // a null
        // Under a control, a real event's densities over both routes (a visitor's before_event
        // formed them already), from the state before this collision as the event's own were.
        if constexpr (kControlled && !Visit::enabled)
            if (event != SegmentEnd::Passed) {
                if constexpr (kChannelControl) kept.d = detail::channel_control_densities<A, S>(kept.k, kept.ctl, kept.mu);
                else kept.d = detail::channel_decomposition_densities<CP, A, S>(kept.k, kept.ctl, kept.mu_bar, st.f);
            }
        if constexpr (Rec::enabled) {
            // Under a control, a real vertex's density is the routes' sum (a null's the residual's).
            const ChannelEventDensities<Spec>& dv = [&]() -> const ChannelEventDensities<Spec>& {
                if constexpr (kControlled) return kept.d;
                else return d;
            }();
            const float p_c = event == SegmentEnd::Absorbed    ? dv.absorb[c]
                              : event == SegmentEnd::Scattered ? dv.scatter[c]
                                                               : d.null[c];
            double tau_c = 0.0;  // the sampling channel's control depth of the step (per-channel control)
            if constexpr (kChannelControl) tau_c = double(kept.tau_c);
            rec.vertex(t, std::log(double(p_c)) - double(channel_of(tau_v, c)) - tau_c);
        }
        if (event == SegmentEnd::Absorbed) {  // the path ends without a contribution
            out = {event, t};
            return false;
        }
        Spec nee_factor = mu;  // ratio tracking's pdf of a null, for the NEE alternative (THEORY 5.1)
        if constexpr (!grey) {  // a grey majorant's Tbar is common to every channel and cancels
            nee_factor *= tb;
            if constexpr (kEq)  // Tbar_c alone at the real vertex: it is not a null
                if (event == SegmentEnd::Scattered) st.eq.vertex *= tb;
        }
        if (event == SegmentEnd::Passed) {
            if (++nulls <= detail::kFloatNulls) {
                Spec fn, pn;
                if constexpr (kChannelControl) {
                    const auto cn = detail::channel_control_nulls<float>(Spec(kept.k.sigma_t()), kept.mu, kept.ctl, d.null);
                    fn = cn.f * tbf;
                    pn = cn.density * tbf;
                } else {
                    fn = mu - k.sigma_t();
                    pn = d.null;
                }
                if constexpr (!grey && !kChannelControl) {
                    fn *= tb;
                    pn *= tb;
                }
                st.f *= fn;
                st.uni *= pn;
            } else {
                // Past kFloatNulls nulls (a loose majorant), a null's contribution and pdf, within
                // 1e-6 of mu_c, are formed and multiplied in in double: the state then rounds once
                // per null (a random walk) instead of carrying each factor's rounding (a bias that
                // grows with the number of nulls; see detail::kFloatNulls).
                using D = detail::DoubleSpectrum<Spec>;
                D fd, pd;
                if constexpr (kChannelControl) {
                    const auto cn = detail::channel_control_nulls<double>(Spec(kept.k.sigma_t()), kept.mu, kept.ctl, d.null);
                    fd = cn.f;
                    pd = cn.density;
                } else if constexpr (CP::own_pdfs) {
                    const auto nf = detail::channel_null_factors<S>(k, mu);
                    fd = nf.f;
                    pd = nf.density;
                } else {
                    fd = mu.template cast<double>() - k.sigma_t().template cast<double>();
                    pd = D::Constant(double(mu_v) * detail::shared_event_probabilities_in<
                                                        A, CP::throughput_weighted, double>(k, mu_v, st.f)[2]);
                }
                if constexpr (!grey) {
                    const D tbd = (kChannelControl ? tbf : tb).template cast<double>();
                    fd *= tbd;
                    pd *= tbd;
                }
                st.f = (st.f.template cast<double>() * fd).template cast<float>();
                st.uni = (st.uni.template cast<double>() * pd).template cast<float>();
            }
            if (nee_alternative) {
                st.nee *= nee_factor;
                if constexpr (kEq) st.eq.nee *= nee_factor;
            }
            if constexpr (kEq) st.eq.vertex *= nee_factor;
        } else {  // a real scattering vertex: mu_s,c Tbar_c and mu_bar_c P_s,c Tbar_c
            if constexpr (kChannelControl) {  // the medium's own mu_s,c, and each channel's routes' densities
                st.f *= kept.k.sigma_s * tbf;
                st.uni *= kept.d.scatter * tbf;
            } else if constexpr (kControlled) {  // the medium's own mu_s,c, and both routes' densities
                st.f *= kept.k.sigma_s;
                st.uni *= kept.d.scatter;
            } else if constexpr (grey) {
                st.f *= k.sigma_s;
                st.uni *= d.scatter;
            } else {
                st.f *= k.sigma_s * tb;
                st.uni *= d.scatter * tb;
            }
        }
        if (const StateScale r = st.template renormalize<CP>(c); r != StateScale::Ok) {
            out = {detail::segment_end(r), t};
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
    constexpr bool kControlled =
        detail::has_control_v<std::remove_cvref_t<decltype(*majorant.iterate(ray, 0.f, tmax, lambda).next())>>;
    constexpr bool kChannelControl = kControlled && is_per_channel_majorant_v<Maj, M>;
    ChannelDeltaCollision<CP, A, S, R, RecT, kEq, Visit, kControlled, kChannelControl> cb{rng, rec, st, c,
                                                                                          nee_alternative,
                                                                                          std::move(visit)};
    const auto f = free_flight(medium, majorant, ray, 0.f, tmax, lambda, rng, counter, cb, kDefaultMaxCollisions, c);
    if (f.aborted) return {aborted_end(f), f.t};
    if constexpr (kControlled) {
        // No control collision before the end: exp(-tau_c) in f and uni (THEORY 5.10).
        if (f.tau_ctl > 0.0 && (f.stopped ? cb.out.end == SegmentEnd::Scattered : true)) {
            const float e = float(std::exp(-f.tau_ctl));
            st.f *= e;
            st.uni *= e;
            if constexpr (requires { cb.visit.control_end(e); }) cb.visit.control_end(e);
            if (const StateScale r = st.template renormalize<CP>(c); r != StateScale::Ok)
                return {detail::segment_end(r), f.stopped ? cb.out.t : tmax};
        }
    }
    if (f.stopped) return cb.out;
    if constexpr (is_per_channel_majorant_v<Maj, M>) {
        const auto tb = detail::relative_transmittance(f.tau_tail, c);
        if constexpr (kChannelControl) {  // each channel's exp(-tau_c,c) of the tail in f and uni
            const typename S::Spectrum ec = (-cb.kept.tail).exp();
            st.f *= ec;
            st.uni *= ec;
        }
        st.f *= tb;
        st.uni *= tb;
        st.nee *= tb;
        if constexpr (kEq) {
            st.eq.vertex *= tb;
            st.eq.nee *= tb;
        }
        if (const StateScale r = st.template renormalize<CP>(c); r != StateScale::Ok)
            return {detail::segment_end(r), tmax};
    }
    if constexpr (RecT::enabled) {
        rec.log_pdf -= double(channel_of(f.tau_tail, c));
        if constexpr (kChannelControl) rec.log_pdf -= double(cb.kept.tail[c]);
    }
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
    SegmentEnd end = SegmentEnd::Passed;  ///< Passed, Terminated (f below FLT_MIN: f, nee and uni set to 0), Overflowed (a value left float's range; zeroed) or Aborted
    Spec f = Spec::Ones();
    Spec nee = Spec::Ones();
    Spec uni = Spec::Ones();
};

/// Ratio tracking with channel c's majorant and every channel's pdfs; see ChannelShadow.
/// `weights` is the path throughput at the segment's start (for throughput-weighted spectral
/// tracking's null probabilities in `uni`). After detail::kFloatNulls nulls the products continue
/// in double; `finish` rounds them.
///
/// Under a per-channel majorant's control (`kChannelControl`, ChannelGridControl): the loop hands
/// over residual collisions at the sampling channel's rate R_c* with every channel's residual
/// coefficients, residual majorant R_c and residual depth, and before_event each channel's control
/// depth since the last collision: f gets (R_c - r_c) Tbar_r,c exp(-tau_c,c), nee R_c Tbar_r,c and
/// uni R_c P_n,c(residual) Tbar_r,c exp(-tau_c,c) per null (each channel's own residual ratio and
/// decomposition tracking, THEORY 5.10 with 5.3).
template <ChannelPolicy CP, AbsorptionPolicy A, SpectralMode S, class Rec, bool kChannelControl = false>
struct ChannelRatioCollision {
    using Spec = typename S::Spectrum;
    static_assert(!kChannelControl || CP::own_pdfs,
                  "nsp: a per-channel majorant's control (ChannelGridControl) needs a channel policy with own pdfs "
                  "(channels::SpectralMis or channels::Independent)");
    /// Under a control, residual ratio tracking (THEORY 5.10): the loop hands over residual
    /// collisions at rate R with the residual's coefficients, so that f gets R - r_c = mu_bar -
    /// mu_t,c, nee R and uni R P_n,c(residual) per null; track_channels_ratio multiplies f and uni
    /// by the control's exp(-tau_c).
    static constexpr ControlUse control_use = ControlUse::ClosedForm;
    using D = detail::DoubleSpectrum<Spec>;
    Rec& rec;
    int c;
    bool uni_alternative;
    Spec weights;
    ChannelShadow<S> out{};
    std::uint32_t nulls = 0;
    D f_d = D::Zero(), nee_d = D::Zero(), uni_d = D::Zero();
    /// exp(tau_c) of the control's optical depth so far, past 20 only (control_depth): 1 otherwise.
    double control_floor = 1.0;

    /// Under a control, the loop's report of the control's optical depth up to the end of the
    /// current segment (past 20): the estimate will be multiplied by exp(-tau), so the stop in
    /// `normalize` must see it, or a shadow ray through a thick controlled medium walks all its
    /// residual nulls (R times its length) for an estimate that rounds to 0.
    void control_depth(double tau) noexcept { control_floor = std::exp(tau); }

    /// Under a per-channel majorant's control: exp(-tau_c,c) of the step to the collision, the
    /// lookup's mu_t, the majorant and the control there, and the tail's control depth.
    struct KeptChannels {
        Spec ec, t, mu, ctl, tail;
    };
    [[no_unique_address]] std::conditional_t<kChannelControl, KeptChannels, detail::Empty> kept{};
    void before_event(const Coefficients<S>& k, const Spec& mu, const Spec& ctl, const Spec& tau_c) noexcept
        requires kChannelControl
    {
        kept.ec = detail::channel_control_transmittance(tau_c);
        kept.t = k.sigma_t();
        kept.mu = mu;
        kept.ctl = ctl;
    }
    void control_tail(const Spec& tau_c) noexcept
        requires kChannelControl
    {
        kept.tail = tau_c;
    }

    template <class V>
    bool operator()(float t, const Coefficients<S>& k, const V& mu_v, const V& tau_v) {
        if constexpr (Rec::enabled) rec.vertex(t, std::log(double(channel_of(mu_v, c))) - double(channel_of(tau_v, c)));
        if (++nulls <= detail::kFloatNulls) return multiply<float>(k, mu_v, tau_v, out.f, out.nee, out.uni);
        if (nulls == detail::kFloatNulls + 1) {
            f_d = out.f.template cast<double>();
            nee_d = out.nee.template cast<double>();
            uni_d = out.uni.template cast<double>();
        }
        return multiply<double>(k, mu_v, tau_v, f_d, nee_d, uni_d);
    }

    /// Multiplies every channel's Tbar over the flight's tail (per-channel majorants).
    void multiply_tail(const Spec& tb) { multiply_tail(tb, tb); }
    /// The same with f's and uni's Tbar `tbf` apart (a per-channel control's: tb exp(-tau_c,c)).
    void multiply_tail(const Spec& tb, const Spec& tbf) {
        if (nulls <= detail::kFloatNulls) {
            out.f *= tbf;
            out.nee *= tb;
            out.uni *= tbf;
            normalize(out.f, out.nee, out.uni);
        } else {
            const D tbd = tb.template cast<double>(), tbfd = tbf.template cast<double>();
            f_d *= tbfd;
            nee_d *= tbd;
            uni_d *= tbfd;
            normalize(f_d, nee_d, uni_d);
        }
    }

    /// The segment's result (rounded to float after long flights: a value past FLT_MAX there is
    /// handled as in `normalize`).
    ChannelShadow<S> finish() noexcept {
        if (nulls <= detail::kFloatNulls) return out;
        ChannelShadow<S> r{out.end, Spec(f_d.template cast<float>()), Spec(nee_d.template cast<float>()),
                           Spec(uni_d.template cast<float>())};
        if (!guard(r.f, r.nee, r.uni)) r.end = out.end;
        return r;
    }

private:
    /// One null's factors, formed and multiplied in T (float or double).
    template <class T, class V, class Arr>
    bool multiply(const Coefficients<S>& k, const V& mu_v, const V& tau_v, Arr& f, Arr& nee, Arr& uni) {
        constexpr bool grey = std::is_same_v<V, float>;
        const Spec mu = detail::broadcast_majorant<Spec>(mu_v);
        // mu_t in float, as the majorants bound it: where mu_c = mu_t,c the null factor is 0.
        Arr nee_factor = mu.template cast<T>();
        Arr f_factor = nee_factor - k.sigma_t().template cast<T>();
        Arr uni_factor = Arr::Ones();
        if constexpr (kChannelControl) {  // mu is R_c here: the medium's mu_bar_c - mu_t,c, and the residual's density
            f_factor = kept.mu.template cast<T>() - kept.t.template cast<T>();
            if (uni_alternative)
                uni_factor = detail::channel_control_nulls<T>(kept.t, kept.mu, kept.ctl,
                                                              channel_event_densities<A, S>(k, mu).null)
                                 .density;
        } else if (uni_alternative) {
            if constexpr (CP::own_pdfs) {
                if constexpr (std::is_same_v<T, float>) uni_factor = channel_event_densities<A, S>(k, mu).null;
                else uni_factor = detail::channel_null_factors<S>(k, mu).density;
            } else {
                const Spec w = weights * f.template cast<float>();
                uni_factor = Arr::Constant(T(mu_v) *
                                           detail::shared_event_probabilities_in<A, CP::throughput_weighted, T>(k, mu_v, w)[2]);
            }
        }
        if constexpr (!grey) {
            const Arr tb = detail::relative_transmittance(tau_v, c).template cast<T>();
            if constexpr (kChannelControl) {  // f's and uni's Tbar take the control's exp(-tau_c,c) too
                const Arr tbf = tb * kept.ec.template cast<T>();
                f_factor *= tbf;
                nee_factor *= tb;
                if (uni_alternative) uni_factor *= tbf;
            } else {
                f_factor *= tb;
                nee_factor *= tb;
                if (uni_alternative) uni_factor *= tb;
            }
        }
        f *= f_factor;
        nee *= nee_factor;
        if (uni_alternative) uni *= uni_factor;
        return normalize(f, nee, uni);
    }

    /// Rescales by the largest ratio-tracking pdf (by channel c's alone for independent tracking);
    /// stops (Terminated) once every estimated channel's contribution is below the smallest normal
    /// float relative to it: the float result could not hold it, and a product of factors above
    /// 1/2 would otherwise never reach 0. Where a pdf, or an estimated contribution relative to
    /// the pdfs, left the range (f / p past FLT_MAX needs mu_t > 2 mu_bar, a majorant that does
    /// not bound), the value cannot be represented: Overflowed, zeroed, the estimate discarded.
    template <class Arr>
    bool normalize(Arr& f, Arr& nee, Arr& uni) {
        using T = typename Arr::Scalar;
        const T k = CP::mis_over_channels ? nee.maxCoeff() : nee[c];
        // Under a control, f will be multiplied by exp(-tau_c) (control_depth): the floor is raised by it.
        const T tiny = T(double(std::numeric_limits<float>::min()) * control_floor);
        const bool negligible = CP::mis_over_channels ? (f.abs() < tiny * k).all() : !(std::abs(f[c]) >= tiny * k);
        if (!(k > T(0)) || !std::isfinite(k) || negligible) {
            // The pdfs go with it: where k overflowed they would be inf (found by the fuzzer).
            zero(f, nee, uni, std::isfinite(k) ? SegmentEnd::Terminated : SegmentEnd::Overflowed);
            return false;
        }
        f /= k;
        nee /= k;
        uni /= k;
        // In float: f / k past FLT_MAX (in double the products have the range to recover).
        if constexpr (std::is_same_v<T, float>) return guard(f, nee, uni);
        return true;
    }

    /// Values past FLT_MAX cannot be represented. Where every channel is estimated (or channel c's
    /// value overflowed) the segment is Overflowed and zeroed; under independent tracking the other
    /// channels are never estimated and are zeroed where they overflow (as ChannelPathState does).
    /// `uni` counts only with uni_alternative (without it nothing reads it, fuzzer finding 8).
    template <class Arr>
    bool guard(Arr& f, Arr& nee, Arr& uni) {
        const bool uni_ok = !uni_alternative || uni.allFinite();
        if (f.allFinite() && nee.allFinite() && uni_ok) [[likely]] return true;
        if constexpr (CP::mis_over_channels) {
            zero(f, nee, uni, SegmentEnd::Overflowed);
            return false;
        } else {
            auto ok = (f.isFinite() && nee.isFinite()).eval();
            if (uni_alternative) ok = ok && uni.isFinite();
            if (!ok[c]) {
                zero(f, nee, uni, SegmentEnd::Overflowed);
                return false;
            }
            f = ok.select(f, 0.f);
            nee = ok.select(nee, 0.f);
            uni = ok.select(uni, 0.f);
            return true;
        }
    }

    template <class Arr>
    void zero(Arr& f, Arr& nee, Arr& uni, SegmentEnd end) {
        f.setZero();
        nee.setZero();
        uni.setZero();
        out.end = end;
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
    constexpr bool kChannelControl =
        detail::has_control_v<std::remove_cvref_t<decltype(*majorant.iterate(ray, 0.f, tmax, lambda).next())>> &&
        is_per_channel_majorant_v<Maj, M>;
    ChannelRatioCollision<CP, A, S, RecT, kChannelControl> cb{rec, c, uni_alternative, weights};
    const auto f = free_flight(medium, majorant, ray, 0.f, tmax, lambda, rng, counter, cb, kDefaultMaxCollisions, c);
    if (f.aborted) {
        ChannelShadow<S> out = cb.finish();
        out.f.setZero();
        out.end = aborted_end(f);
        return out;
    }
    if (f.stopped) return cb.finish();
    if constexpr (kChannelControl) {
        const typename S::Spectrum tb = detail::relative_transmittance(f.tau_tail, c);
        cb.multiply_tail(tb, typename S::Spectrum(tb * (-cb.kept.tail).exp()));
    } else if constexpr (is_per_channel_majorant_v<Maj, M>) {
        cb.multiply_tail(detail::relative_transmittance(f.tau_tail, c));
    }
    if constexpr (RecT::enabled) rec.log_pdf -= double(channel_of(f.tau_tail, c));
    ChannelShadow<S> out = cb.finish();
    if (f.tau_ctl > 0.0 && out.end == SegmentEnd::Passed) {
        // The control's transmittance in closed form, and decomposition tracking's probability of
        // no control collision in uni (THEORY 5.10).
        const float e = float(std::exp(-f.tau_ctl));
        out.f *= e;
        out.uni *= e;
    }
    return out;
}

}  // namespace nsp
