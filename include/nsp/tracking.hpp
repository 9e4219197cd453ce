// nsp/tracking.hpp: the free-flight loop and the per-collision tracking policies (THEORY 4).
//
// There is one loop, `free_flight`: it walks the majorant segments of a ray, draws tentative
// collisions with density mu_bar(t) Tbar(0, t), looks the medium up at each, and hands the
// collision to a callback that decides absorb / scatter / null. Delta tracking and ratio
// tracking are such callbacks; so is anything a host renderer writes.
#pragma once

#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/counter.hpp"
#include "core/rng.hpp"
#include "core/status.hpp"
#include "majorant.hpp"
#include "medium.hpp"

namespace nsp {

// ---------------------------------------------------------------------------------------------
// Absorption policies (THEORY 4.3, last bullet)

namespace absorption {
/// Absorption is an event with probability mu_a / mu_bar: the path ends there.
struct Event {
    static constexpr bool as_event = true;
    static constexpr const char* name = "absorb-event";
};
/// Absorption is a weight: real collisions scatter with P_s = mu_t / mu_bar and the throughput
/// is multiplied by the albedo mu_s / mu_t. Same mean, less variance on grey media.
struct Weight {
    static constexpr bool as_event = false;
    static constexpr const char* name = "absorb-weight";
};
}  // namespace absorption

/// An absorption policy says whether absorption is sampled as an event (`as_event`).
template <class A>
concept AbsorptionPolicy = requires {
    { A::as_event } -> std::convertible_to<bool>;
    { A::name } -> std::convertible_to<const char*>;
};

/// The probabilities of the three collision events; they sum to 1.
struct EventProbabilities {
    float absorb = 0.f;
    float scatter = 0.f;
    float null = 0.f;
};

namespace detail {
/// The coefficient that drives a real event's probability: the channel mean of |mu_x,c|. A
/// medium's mu_a and mu_s are >= 0 and this is their mean; a residual under a control above the
/// density is negative (THEORY 5.10), and its real events are then drawn by |mu_x| and weighed
/// mu_x / (mu_bar P_x), negative, as bound::Signed weighs negative nulls; clamped at 0 they would
/// be lost, and decomposition tracking's control collisions would carry the whole control. The
/// mean of |.|, not |mean|: channels of both signs must not cancel.
template <class Spec>
float event_coefficient(const Spec& sigma) noexcept {
    if constexpr (Spec::SizeAtCompileTime == 1) return std::abs(sigma[0]);
    else return sampling_scalar(Spec(sigma.abs()));
}

/// The null coefficient that drives delta tracking's null probability: the channel mean of
/// |mu_bar - mu_t,c|, which is mu_bar - mean(mu_t) wherever the majorant bounds every channel.
/// Not |mu_bar - mean(mu_t)|: under bound::Signed on a chromatic medium that is 0 where the
/// channels' excesses and deficits cancel, no null is ever drawn there, and the channels' null
/// terms were lost (T_red 0.21 against 0.37; found by the stability suite). mu_t in float as
/// mu_bar - (a + s) everywhere, so event_probabilities and null_probability agree on whether it is
/// 0 (where they differed, a null was chosen with P_n > 0 in float and weighed with P_n = 0: NaN;
/// found by the fuzzer).
template <SpectralMode S>
float null_coefficient(const Coefficients<S>& c, float mu_bar) noexcept {
    if constexpr (S::channels == 1) return std::abs(mu_bar - (c.sigma_a[0] + c.sigma_s[0]));
    else return sampling_scalar(typename S::Spectrum((mu_bar - c.sigma_t()).abs()));
}
}  // namespace detail

/// The event probabilities delta tracking uses at a collision with coefficients `c` under
/// majorant `mu_bar` > 0. One pdf serves all channels, driven by the channel means (of mu_a, mu_s
/// and |mu_n,c|, see detail::null_coefficient). They are |mu_x| / (mu_a + mu_s + |mu_n|): mu_x /
/// mu_bar where the majorant bounds the extinction, and
/// where it does not (mu_n < 0, bound::Signed) still in [0, 1] with a null probability that is
/// not 0, so the tracking weights mu_x / (mu_bar P_x) carry the sign and the estimate stays
/// unbiased (THEORY 1, 4.3). Clamping P_n at 0 there would drop the negative null term.
template <AbsorptionPolicy A, SpectralMode S>
EventProbabilities event_probabilities(const Coefficients<S>& c, float mu_bar) noexcept {
    const float a = detail::event_coefficient(c.sigma_a);
    const float s = detail::event_coefficient(c.sigma_s);
    const float n = detail::null_coefficient(c, mu_bar);
    // In double: where a + s + n is below 2^-126 (a denormal majorant, met at a zero-length step
    // from u = 0) the float 1 / (a + s + n) overflowed and the probabilities were inf or NaN
    // (found by the fuzzer, tests/fuzz).
    const double inv = 1.0 / (double(a) + double(s) + double(n));  // > 0 because mu_bar > 0
    if constexpr (A::as_event) return {float(a * inv), float(s * inv), float(n * inv)};
    else return {0.f, float((double(a) + double(s)) * inv), float(n * inv)};
}

namespace detail {
/// Products over the nulls of one flight are formed in double: always by the grey trackers here
/// (for one to a few channels double costs no more than float), and after the first kFloatNulls
/// nulls by the channel trackers (channel_tracking.hpp, whose wider state costs more in double).
/// A null factor mu_n / mu_bar under a majorant 1e6 times the extinction is 1 - 1e-6, which float
/// rounds by up to 3% of its distance to 1, the same way at every null of a homogeneous stretch:
/// over 1e6 nulls that was a 3% bias of ratio tracking (a random walk of float roundings of the
/// product would only be ~1e-5). In double the factor is exact to 1e-10 of that distance. Float
/// rounds each factor by at most 2^-24 of itself, so over the first 1024 nulls its bias is below
/// 1024 x 2^-24 = 6e-5 of the product (far less where the roundings differ in sign), below any
/// estimate's noise: ordinary flights (a few to a few hundred nulls) keep float arithmetic.
inline constexpr std::uint32_t kFloatNulls = 1024;

/// A spectrum of doubles with Spec's channels (see kFloatNulls).
template <class Spec>
using DoubleSpectrum = Eigen::Array<double, Spec::RowsAtCompileTime, 1>;

/// Every channel's mu_n / mu_bar = 1 - mu_t / mu_bar at a collision, in double (see DoubleSpectrum).
template <SpectralMode S>
DoubleSpectrum<typename S::Spectrum> null_ratio(const Coefficients<S>& c, float mu_bar) noexcept {
    // mu_t in float, as the majorants bound it: where mu_bar = mu_t the factor is exactly 0.
    const double mu = mu_bar;
    return (mu - c.sigma_t().template cast<double>()) / mu;
}

/// The null probability P_n of event_probabilities<A> (the same formula), in double.
template <AbsorptionPolicy A, SpectralMode S>
double null_probability(const Coefficients<S>& c, float mu_bar) noexcept {
    const float a = event_coefficient(c.sigma_a);
    const float s = event_coefficient(c.sigma_s);
    const double t = a + s;  // in float, as event_probabilities forms it
    const double n = null_coefficient(c, mu_bar);
    return n / (t + n);
}
}  // namespace detail

// ---------------------------------------------------------------------------------------------
// Recording sampled vertices (for pdf tests and debugging; compiled out by default)

/// Records nothing.
struct NoRecord {
    static constexpr bool enabled = false;
    void vertex(float, double) noexcept {}
};

/// Records the distances of the vertices a tracker creates and the log of the pdf with which it
/// sampled them (majorant density, Tbar since the previous vertex and event probability).
struct SegmentRecord {
    static constexpr bool enabled = true;
    std::vector<float> t;   ///< distance of each vertex the tracker created, nulls first
    double log_pdf = 0.0;   ///< log of the product of the per-vertex pdfs, incl. the end term
    void vertex(float tv, double log_p) {
        t.push_back(tv);
        log_pdf += log_p;
    }
};

// ---------------------------------------------------------------------------------------------
// The free-flight loop

/// How a call of `free_flight` ended. V is the majorant's value type (float, or a Spectrum for a
/// per-channel majorant).
template <class V = float>
struct FlightEnd {
    bool stopped = false;   ///< the callback stopped at `t`; otherwise the ray passed tmax
    bool aborted = false;   ///< gave up after `max_collisions` tentative collisions, rejected, or invalid
    bool rejected = false;  ///< bound::Reject found mu_t > mu_bar at `t` (then `aborted` is set too)
    float t = 0.f;          ///< the stopping distance
    V tau_tail{};           ///< majorant optical depth from the last collision to tmax if passed
    bool invalid = false;   ///< the ray was not usable_ray or tmin / tmax NaN: nothing was tracked (`aborted` is set too)
    /// The control's optical depth over the flight (up to `t` where it stopped), where the
    /// callback took a grey majorant's control (ControlUse::ClosedForm or Collide); 0 otherwise.
    double tau_ctl = 0.0;
};

/// The default limit on tentative collisions in one flight. It only matters where a majorant is
/// so loose over so long a ray that tracking would not finish; the caller sees `aborted`.
inline constexpr std::uint32_t kDefaultMaxCollisions = 1u << 24;

/// A collision callback: `cb(t, coefficients, mu_bar, tau)` returns true to go on (a null
/// collision) or false to stop at t; `tau` is the majorant optical depth since the previous
/// tentative collision (or the origin), so exp(-tau) is Tbar between them. mu_bar and tau are
/// floats for a grey majorant and Spectra (one per channel) for a per-channel one.
template <class F, class S, class V = float>
concept CollisionCallback = requires(F& f, float t, const Coefficients<S>& c, const V& v) {
    { f(t, c, v, v) } -> std::same_as<bool>;
};

/// How a collision callback takes the control of a majorant policy whose segments carry one
/// (ControlSegment, majorants/control.hpp; THEORY 5.10), stated as its
/// `static constexpr ControlUse control_use` (Ignore where it states nothing). Under ClosedForm and
/// Collide the loop splits the extinction into the grey control mu_c (the segment's smallest
/// channel's) and the residual mu_t - mu_c, and hands the callback residual tentative collisions
/// at rate mu_bar - mu_c with the coefficients scaled to the residual extinction mu_t,c - mu_c in
/// every channel (albedo kept; negative where a control exceeds the extinction, all absorption
/// where mu_t,c = 0), their `mu_bar` the residual majorant.
enum class ControlUse : std::uint8_t {
    Ignore,      ///< track under the full majorant, as without a control
    ClosedForm,  ///< ratio tracking: only the residual is tracked; exp(-FlightEnd::tau_ctl) is the control's transmittance
    /// Decomposition tracking: control collisions at rate mu_c beside the residual's tentative ones,
    /// the first of them real. One lookup there (for the albedo); the callback sees coefficients
    /// scaled to extinction mu_c and `mu_bar` = mu_c, so that its null probability is 0.
    Collide,
};

namespace detail {
/// What callback F states (ControlUse::Ignore where it states nothing).
template <class F>
constexpr ControlUse control_use_of() noexcept {
    using G = std::remove_cvref_t<F>;
    if constexpr (requires { { G::control_use } -> std::convertible_to<ControlUse>; }) return G::control_use;
    else return ControlUse::Ignore;
}

/// True for a majorant segment that carries a control (ControlSegment).
template <class Seg>
inline constexpr bool has_control_v = requires(const Seg& s) { s.sigma_ctl; };

/// A segment's grey control: its smallest channel's, kept within [0, mu_bar].
template <class Spec>
float grey_control(const Spec& ctl, float mu_bar) noexcept {
    return std::min(std::max(ctl.minCoeff(), 0.f), mu_bar);
}
/// Under a per-channel majorant mu_bar (ChannelGridControl), every channel's own control, kept
/// within [0, mu_bar,c].
template <class Spec>
Spec channel_controls(const Spec& ctl, const Spec& mu_bar) noexcept {
    return ctl.max(0.f).min(mu_bar.max(0.f));
}
/// exp(-tau_c) per channel of a per-channel control's depths `tau_c` over a step: the probability
/// of no control collision there (1 where no channel had a control, without evaluating exp).
template <class Spec>
Spec channel_control_transmittance(const Spec& tau_c) noexcept {
    return (tau_c > 0.f).any() ? Spec((-tau_c).exp()) : Spec(Spec::Ones());
}

/// Scales coefficients `k` (after the bound policy) to extinction mu_t,c - `ctl` in every channel,
/// albedo kept (ControlUse): where mu_t,c = 0 the residual -ctl is all absorption. mu_s is scaled
/// and mu_a is the rest, so that the residual extinction is the difference to within one rounding;
/// where that rounding put it above `rate` = mu_bar - ctl (which mu_t <= mu_bar excludes), mu_a
/// gives the excess back (as clamp_to_majorant).
template <SpectralMode S>
void to_residual(Coefficients<S>& k, float ctl, float rate) noexcept {
    using Spec = typename S::Spectrum;
    if (!(ctl > 0.f)) return;  // no control here: the lookup as it is (a control of 0 is today's tracker, bit for bit)
    const Spec t = k.sigma_t();
    const Spec r = t - ctl;
    // r times the albedo s / t (in [0, 1]), not s times r / t: under a control far above a
    // subnormal extinction r / t overflowed and made the probabilities NaN (found by the fuzzer).
    k.sigma_s = (t > 0.f).select(r * (k.sigma_s / t), 0.f);
    k.sigma_a = r - k.sigma_s;
    const Spec over = k.sigma_t() - rate;
    if ((over > 0.f).any()) [[unlikely]]
        k.sigma_a = (over > 0.f).select(k.sigma_a - over, k.sigma_a);
}

/// to_residual with every channel's own control `ctl` and residual majorant `rate` (a per-channel
/// majorant's control): channel c as to_residual with ctl_c and rate_c; a channel whose control is
/// 0 keeps its lookup.
template <SpectralMode S>
void to_residual(Coefficients<S>& k, const typename S::Spectrum& ctl, const typename S::Spectrum& rate) noexcept {
    using Spec = typename S::Spectrum;
    const auto on = (ctl > 0.f).eval();
    if (!on.any()) return;
    const Spec t = k.sigma_t();
    const Spec r = t - ctl;
    const Spec s = (t > 0.f).select(r * (k.sigma_s / t), 0.f);
    k.sigma_s = on.select(s, k.sigma_s);
    k.sigma_a = on.select(r - s, k.sigma_a);
    const Spec over = k.sigma_t() - rate;
    const auto fix = (on && over > 0.f).eval();
    if (fix.any()) [[unlikely]]
        k.sigma_a = fix.select(k.sigma_a - over, k.sigma_a);
}

/// Scales coefficients `k` to extinction `ctl` in every channel, albedo kept (a control collision,
/// ControlUse::Collide): where mu_t,c = 0 it is all absorption. `ctl` is grey or per channel.
template <SpectralMode S, class Ctl>
void to_control(Coefficients<S>& k, const Ctl& ctl) noexcept {
    using Spec = typename S::Spectrum;
    const Spec t = k.sigma_t();
    k.sigma_s = (t > 0.f).select(ctl * (k.sigma_s / t), 0.f).min(ctl);  // the albedo first, as to_residual
    k.sigma_a = ctl - k.sigma_s;
}

/// A real absorption's and a real scattering's density at a point (decomposition_event_densities).
struct EventDensities {
    float absorb = 0.f, scatter = 0.f;
};

/// Nothing, in a member that a policy without a control does not keep.
struct Empty {};

/// The densities, over the shared null factors, with which decomposition tracking (THEORY 5.10)
/// draws a real absorption and a real scattering event at a point whose lookup is `k` (after the
/// bound policy), grey control `ctl` and segment majorant `mu_bar`: the control route's
/// ctl P_x(control) plus the residual route's R P_x(residual), R = mu_bar - ctl. Under a minorant
/// (every channel's residual >= 0) every term is linear in the coefficients and the sum is delta
/// tracking's mu_bar P_x; where the control exceeds the extinction the residual's events are drawn
/// by |r| and the sum is larger. A control of 0 gives delta tracking's densities.
template <AbsorptionPolicy A, SpectralMode S>
EventDensities decomposition_event_densities(const Coefficients<S>& k, float ctl, float mu_bar) noexcept {
    const float rate = mu_bar - ctl;
    EventDensities d;
    if (rate > 0.f) {
        Coefficients<S> r = k;
        to_residual(r, ctl, rate);
        const EventProbabilities p = event_probabilities<A>(r, rate);
        d = {rate * p.absorb, rate * p.scatter};
    }
    if (ctl > 0.f) {
        Coefficients<S> c = k;
        to_control(c, ctl);
        const EventProbabilities p = event_probabilities<A>(c, ctl);
        d.absorb += ctl * p.absorb;
        d.scatter += ctl * p.scatter;
    }
    return d;
}

/// bound::Clamp: scales a lookup's coefficients, albedo kept, so that mu_t <= mu_bar in every
/// channel (mu_bar grey or per channel).
template <SpectralMode S, class V>
void clamp_to_majorant(Coefficients<S>& k, const V& mu) noexcept {
    using Spec = typename S::Spectrum;
    const Spec t = k.sigma_t();
    const Spec m = broadcast_majorant<Spec>(mu);
    const Spec f = (t > m).select(m / t, Spec::Ones());
    k.sigma_a *= f;
    k.sigma_s *= f;
    // Rounding can leave a + s above m; under a majorant of a few subnormal ulps by a whole ulp, so
    // that a tracking weight came out 4/3 (found by the fuzzer, tests/fuzz). The excess comes off
    // sigma_s (m - a is exact there: subnormal subtraction does not round).
    const Spec over = (k.sigma_a + k.sigma_s) - m;
    if ((over > 0.f).any()) [[unlikely]] {
        k.sigma_a = k.sigma_a.min(m);
        k.sigma_s = (over > 0.f).select((m - k.sigma_a).max(0.f), k.sigma_s);
    }
}

/// bound::Reject: true when mu_t exceeds mu_bar by more than rounding in some channel.
template <SpectralMode S, class V>
bool exceeds_majorant(const Coefficients<S>& k, const V& mu) noexcept {
    using Spec = typename S::Spectrum;
    return (k.sigma_t() > broadcast_majorant<Spec>(mu) * (1.f + kBoundSlack)).any();
}

/// Reports the DDA steps a majorant iterator took to a counter that records them.
template <class It, class C>
struct StepReport {
    const It& it;
    C& counter;
    ~StepReport() {
        if constexpr (requires(C& c, const It& i) { c.majorant_steps(i.steps()); }) counter.majorant_steps(it.steps());
    }
};
}  // namespace detail

/// Samples tentative collisions with density mu_bar(t) Tbar(tmin, t) along `ray` over
/// [tmin, tmax], segment by segment, and calls `on_collision` at each (THEORY 4.1). With a
/// per-channel majorant, `channel` is the sampling channel c*: distances are drawn with its
/// majorant and every channel's optical depth is accumulated over the same stretches
/// (THEORY 5.3). The majorant's bound policy acts on each lookup before the callback sees it
/// (bound::Clamp clamps it, bound::Reject ends the flight with `rejected`). Counts one density
/// lookup per tentative collision, and the DDA steps of a grid majorant if the counter records
/// them. A ray that is not usable_ray (a non-finite origin, a direction that is not unit length) or
/// a NaN tmin or tmax ends the flight at once with `invalid` (and `aborted`): nothing is tracked.
/// Never throws.
template <Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C, class F>
    requires CollisionCallback<F, typename M::Spectral, MajorantValue<Maj, M>>
FlightEnd<MajorantValue<Maj, M>> free_flight(const M& medium, const Maj& majorant, const Ray& ray, float tmin,
                                             float tmax, const typename M::Spectral::Wavelengths& lambda, R& rng,
                                             C& counter, F&& on_collision,
                                             std::uint32_t max_collisions = kDefaultMaxCollisions,
                                             int channel = 0) {
    using V = MajorantValue<Maj, M>;
    using B = bound_policy_t<Maj>;
    constexpr bool grey = std::is_same_v<V, float>;
    // A control (THEORY 5.10): the segments carry one and the callback takes it (ControlUse).
    using Seg = std::remove_cvref_t<decltype(*majorant.iterate(ray, tmin, tmax, lambda).next())>;
    constexpr ControlUse use = detail::has_control_v<Seg> ? detail::control_use_of<F>() : ControlUse::Ignore;
    constexpr bool residual = use != ControlUse::Ignore;
    constexpr bool collide = use == ControlUse::Collide;
    // Under a per-channel majorant's control (ChannelGridControl), the sampling channel tracks its
    // own residual and control; the callback sees every channel's residual coefficients, residual
    // majorant and depth, and first, in before_event, the lookup, majorants, controls and control
    // depths since the last collision (THEORY 5.10 with 5.3).
    constexpr bool channel_ctl = residual && !grey;
    // At the end of a flight that passed tmax the callback is told every channel's control depth
    // from the last collision (control_tail); `tau_tail` is then the residual's.
    if constexpr (channel_ctl)
        static_assert(requires(const Coefficients<typename M::Spectral>& k, const V& v) {
            on_collision.before_event(k, v, v, v);
            on_collision.control_tail(v);
        }, "nsp: this collision policy does not take a per-channel majorant's control (ChannelGridControl)");
    if (!usable_ray(ray) || tmin != tmin || tmax != tmax) [[unlikely]] {  // NaN != NaN
        FlightEnd<V> bad{false, true, false, 0.f, V{}, true};
        if constexpr (!grey) bad.tau_tail.setZero();
        return bad;
    }
    auto segments = majorant.iterate(ray, tmin, tmax, lambda);
    const detail::StepReport<decltype(segments), C> report{segments, counter};
    V tau{};                    // majorant optical depth since the last tentative collision
    if constexpr (!grey) tau.setZero();
    // Adds the optical depth of a stretch of `len` on a segment (per channel: 0 * inf stays 0).
    auto add_depth = [&](const V& mu, float len) {
        if constexpr (grey) tau += mu * len;
        else tau += (mu > 0.f).select(mu * len, 0.f);
    };
    std::uint32_t collisions = 0;
    // The majorant optical depth left to the next tentative collision (< 0: draw a new one). A
    // step that leaves a segment carries what it did not use into the next segment instead of
    // drawing again: the same exponential distribution, one log and one random number less per
    // grid cell crossed.
    float e = -1.f;
    [[maybe_unused]] double tau_ctl = 0.0;  // the control's optical depth so far (ControlUse)
    [[maybe_unused]] float e_ctl = -1.f;    // the control depth left to the next control collision (Collide)
    // Per-channel controls: every channel's control depth since the last collision, and the
    // segment's controls and residual majorants.
    [[maybe_unused]] V tau_c{}, ctl_v{}, res_v{};
    if constexpr (channel_ctl) tau_c.setZero();
    auto add_ctl_depth = [&](float len) {
        if constexpr (channel_ctl) tau_c += (ctl_v > 0.f).select(ctl_v * len, 0.f);
        else (void)len;
    };
    while (auto seg = segments.next()) {
        float mu_bar = channel_of(seg->sigma_maj, channel);
        [[maybe_unused]] float ctl = 0.f;
        if constexpr (channel_ctl) {
            ctl_v = detail::channel_controls(seg->sigma_ctl, seg->sigma_maj);
            res_v = (seg->sigma_maj - ctl_v).max(0.f);
            ctl = ctl_v[channel];
            mu_bar = res_v[channel];  // the sampling channel's residual majorant
        } else if constexpr (residual) {
            ctl = detail::grey_control(seg->sigma_ctl, mu_bar);
            mu_bar -= ctl;  // the residual majorant
            if constexpr (!collide) {
                tau_ctl += double(ctl) * double(seg->t1 - seg->t0);
                if constexpr (requires { on_collision.control_depth(tau_ctl); })
                    if (tau_ctl > 20.0) on_collision.control_depth(tau_ctl);
            }
        }
        if constexpr (channel_ctl) {
            if (!(mu_bar > 0.f) && (!collide || !(ctl > 0.f))) {  // the other channels' depths only
                add_depth(res_v, seg->t1 - seg->t0);
                add_ctl_depth(seg->t1 - seg->t0);
                continue;
            }
        } else if constexpr (collide) {
            if (!(mu_bar > 0.f) && !(ctl > 0.f)) continue;
        } else if (!(mu_bar > 0.f)) {  // nothing to collide with on this segment
            if constexpr (!grey) add_depth(seg->sigma_maj, seg->t1 - seg->t0);
            continue;
        }
        float t = seg->t0;
        for (;;) {
            // Exponential step: E = -ln(1 - u) majorant optical depths. logf, not log1pf: 1 - u is
            // exact for u on Pcg32's 2^-24 grid, so E agrees with -log1pf(-u) within 1 ulp (within
            // 2^-24 for finer u), and glibc's log1pf took 30% of this loop (bench/RESULTS.md).
            float dt;
            [[maybe_unused]] bool control_first = false;
            if constexpr (collide) {
                dt = kInf;
                if (mu_bar > 0.f) {
                    if (!(e > 0.f)) e = -std::log(1.f - rng.uniform());
                    dt = e / mu_bar;
                }
                if (ctl > 0.f) {
                    if (!(e_ctl > 0.f)) e_ctl = -std::log(1.f - rng.uniform());
                    if (const float dc = e_ctl / ctl; dc < dt) {
                        dt = dc;
                        control_first = true;
                    }
                }
            } else {
                if (!(e > 0.f)) e = -std::log(1.f - rng.uniform());
                dt = e / mu_bar;
            }
            if (!(dt < seg->t1 - t)) {  // the step leaves the segment (also catches inf)
                const float len = seg->t1 - t;
                if constexpr (channel_ctl) {
                    if (mu_bar > 0.f) e -= mu_bar * len;  // <= 0 after rounding at the boundary: draw anew
                    if constexpr (collide)
                        if (ctl > 0.f) e_ctl -= ctl * len;
                    add_depth(res_v, len);
                    add_ctl_depth(len);
                } else if constexpr (collide) {
                    if (mu_bar > 0.f) e -= mu_bar * len;  // <= 0 after rounding at the boundary: draw anew
                    if (ctl > 0.f) e_ctl -= ctl * len;
                    tau += (mu_bar + ctl) * len;
                    tau_ctl += double(ctl) * double(len);
                } else {
                    if constexpr (grey) tau += mu_bar * len;  // the residual's, under a control
                    else add_depth(seg->sigma_maj, len);
                    e -= mu_bar * len;  // <= 0 after rounding at the boundary: draw anew
                }
                break;
            }
            t += dt;
            [[maybe_unused]] float rate = mu_bar;  // the callback's majorant under a control
            if constexpr (channel_ctl) {
                add_depth(res_v, dt);
                add_ctl_depth(dt);
                if constexpr (collide) {
                    if (control_first) {
                        if (mu_bar > 0.f && e > 0.f) e -= mu_bar * dt;
                        e_ctl = -1.f;
                    } else {
                        if (ctl > 0.f && e_ctl > 0.f) e_ctl -= ctl * dt;
                        e = -1.f;
                    }
                } else {
                    e = -1.f;
                }
            } else if constexpr (collide) {
                tau += (mu_bar + ctl) * dt;
                tau_ctl += double(ctl) * double(dt);
                if (control_first) {  // a control collision: real (THEORY 5.10)
                    if (mu_bar > 0.f && e > 0.f) e -= mu_bar * dt;
                    e_ctl = -1.f;
                    rate = ctl;
                } else {
                    if (ctl > 0.f && e_ctl > 0.f) e_ctl -= ctl * dt;
                    e = -1.f;
                }
            } else {
                if constexpr (grey) tau += e;
                else add_depth(seg->sigma_maj, dt);
                e = -1.f;
            }
            if (++collisions > max_collisions) return {false, true, false, t, V{}};
            counter.lookup();
            auto coeff = medium.coefficients(ray.at(t), lambda);
            NSP_DEBUG_ASSERT((coeff.sigma_a >= 0.f).all() && (coeff.sigma_s >= 0.f).all() &&
                                 all_finite(coeff.sigma_a) && all_finite(coeff.sigma_s),
                             "the medium returned a negative or non-finite coefficient");
            if constexpr (std::is_same_v<B, bound::Clamp>) {
                detail::clamp_to_majorant(coeff, seg->sigma_maj);
            } else if constexpr (std::is_same_v<B, bound::Reject>) {
                if (detail::exceeds_majorant(coeff, seg->sigma_maj)) return {false, true, true, t, V{}};
            }
            if constexpr (channel_ctl) {
                // Every channel's lookup, majorant, control and control depth since the last
                // collision, then the route's coefficients (a control collision's under Collide).
                on_collision.before_event(coeff, seg->sigma_maj, ctl_v, tau_c);
                tau_c.setZero();
                if (control_first) detail::to_control(coeff, ctl_v);
                else detail::to_residual(coeff, ctl_v, res_v);
            } else if constexpr (collide) {
                // The callback may keep the medium's own coefficients (a real vertex's density, a
                // visitor's estimate) before they become the control's or the residual's.
                if constexpr (requires { on_collision.before_event(t, coeff, 0.f, 0.f, 0.0); })
                    on_collision.before_event(t, coeff, channel_of(seg->sigma_maj, channel), ctl, tau_ctl);
                if (control_first) detail::to_control(coeff, ctl);
                else detail::to_residual(coeff, ctl, mu_bar);
            } else if constexpr (residual) {
                detail::to_residual(coeff, ctl, mu_bar);
            }
            const V tau_step = tau;
            if constexpr (grey) tau = 0.f;
            else tau.setZero();
            if constexpr (channel_ctl) {
                if (!on_collision(t, coeff, control_first ? ctl_v : res_v, tau_step))
                    return {true, false, false, t, V{}};
            } else if constexpr (residual) {
                if (!on_collision(t, coeff, rate, tau_step)) {
                    FlightEnd<V> end{true, false, false, t, 0.f};
                    end.tau_ctl = tau_ctl;
                    return end;
                }
            } else if (!on_collision(t, coeff, seg->sigma_maj, tau_step)) {
                return {true, false, false, t, V{}};
            }
        }
    }
    if constexpr (channel_ctl) {
        on_collision.control_tail(tau_c);
        return {false, false, false, tmax, tau};
    } else if constexpr (residual) {
        FlightEnd<V> end{false, false, false, tmax, tau};
        end.tau_ctl = tau_ctl;
        return end;
    } else {
        return {false, false, false, tmax, tau};
    }
}

// ---------------------------------------------------------------------------------------------
// Tracking strategies as collision policies

/// How a tracked segment ended.
enum class SegmentEnd : std::uint8_t {
    Passed,      ///< reached tmax (a surface, a light or the end of the medium)
    Scattered,   ///< a real scattering collision at t
    Absorbed,    ///< an absorption event at t (only with absorption::Event)
    Terminated,  ///< ratio tracking: every channel's weight fell below the smallest normal float (set to 0)
    Aborted,     ///< the collision limit was reached; the estimate is discarded (weight 0)
    Rejected,    ///< bound::Reject met mu_t > mu_bar; the estimate is discarded (weight 0)
    Overflowed,  ///< per-channel tracking: a contribution or pdf left float's range; the estimate is discarded (weight 0)
    InvalidInput,  ///< the ray was not usable_ray, or its distance NaN (negative, for VertexKernels); nothing was tracked (weight 0)
};

/// How an aborted flight ends a segment: InvalidInput, Rejected (bound::Reject) or Aborted
/// (collision limit).
template <class V>
SegmentEnd aborted_end(const FlightEnd<V>& f) noexcept {
    return f.invalid ? SegmentEnd::InvalidInput : f.rejected ? SegmentEnd::Rejected : SegmentEnd::Aborted;
}

/// The status of a path one of whose flights ended with `end`: Aborted, Rejected and InvalidInput
/// as themselves, Overflowed as NonFinite, everything else Ok.
inline Status flight_status(SegmentEnd end) noexcept {
    switch (end) {
        case SegmentEnd::Aborted: return Status::Aborted;
        case SegmentEnd::Rejected: return Status::Rejected;
        case SegmentEnd::Overflowed: return Status::NonFinite;
        case SegmentEnd::InvalidInput: return Status::InvalidInput;
        default: return Status::Ok;
    }
}

/// The outcome of delta tracking one segment.
template <SpectralMode S>
struct DeltaTrack {
    SegmentEnd end = SegmentEnd::Passed;
    float t = 0.f;                     ///< distance of the real collision, or tmax
    typename S::Spectrum weight;       ///< product of per-vertex f/p factors (1 on grey media with a bounding majorant)
    float null_pdf_product = 1.f;      ///< prod_j P_n(n_j): the ratio p_track / p_ratio of the nulls (THEORY 5.1); under a control, times exp(-tau_c) (5.10)
    /// mu_bar(t) P_event(t) at a real collision: its pdf over Tbar (THEORY 5.4). It is 0 where the
    /// product lies below float's range (an event of subnormal probability under a majorant below
    /// 1/2, fuzzer finding 15); `equiangular_over_tracking` then gives inf, as it should. Under a
    /// control it is the vertex's density, the sum over decomposition tracking's two routes to it
    /// (detail::decomposition_event_densities), whichever drew it.
    float event_density = 0.f;
};

/// Visits nothing (the default of `DeltaCollision`).
struct NoVisit {
    static constexpr bool enabled = false;
};

/// Delta (Woodcock) tracking (THEORY 4.3): at each collision choose absorb / scatter / null with
/// the probabilities of `event_probabilities<A>`; per-channel weights are mu_x,c / (mu_bar P_x).
/// A visitor with `enabled` is called at every tentative collision before its event is chosen,
/// as `visit(t, coefficients, mu_bar, weight, null_pdf_product)` with the weight and null-pdf
/// product of the nulls before it (the collision estimator of emission, THEORY 5.7, uses it).
/// Under a control, decomposition tracking (THEORY 5.10); with `kControlled` (track_delta_visiting
/// sets it when the majorant carries a control) the loop calls before_event at every collision,
/// and the visitor is called from there instead.
template <AbsorptionPolicy A, SpectralMode S, UniformRng R, class Rec, class Visit = NoVisit,
          bool kControlled = false>
struct DeltaCollision {
    static constexpr ControlUse control_use = ControlUse::Collide;
    R& rng;
    Rec& rec;
    Visit visit{};
    DeltaTrack<S> out{SegmentEnd::Passed, 0.f, S::Spectrum::Ones(), 1.f};
    /// Under a control, the current collision's own lookup, grey control and segment majorant.
    struct Kept {
        Coefficients<S> k{};
        float ctl = 0.f, mu_bar = 0.f;
    };
    [[no_unique_address]] std::conditional_t<kControlled, Kept, detail::Empty> kept{};
    // The weight and P_n product accumulate in double (see detail::kFloatNulls; for one to a few
    // channels double costs no more than float); `finish` rounds them into `out`.
    detail::DoubleSpectrum<typename S::Spectrum> weight = decltype(weight)::Ones();
    double null_pdf_product = 1.0;

    bool operator()(float t, const Coefficients<S>& c, float mu_bar, float tau) {
        if constexpr (Visit::enabled && !kControlled)
            visit(t, c, mu_bar, typename S::Spectrum(weight.template cast<float>()), float(null_pdf_product));
        const EventProbabilities p = event_probabilities<A>(c, mu_bar);
        NSP_DEBUG_ASSERT(p.absorb >= 0.f && p.scatter >= 0.f && p.null >= 0.f &&
                             std::abs(p.absorb + p.scatter + p.null - 1.f) < 1e-5f,
                         "delta tracking's event probabilities must lie in [0, 1] and sum to 1");
        const float u = rng.uniform();
        float p_event;
        if (u < p.absorb) {
            out.end = SegmentEnd::Absorbed;
            weight *= real_weight(c.sigma_a, mu_bar, p.absorb);
            p_event = p.absorb;
        } else if (u < p.absorb + p.scatter || !(p.null > 0.f)) {
            // The second test keeps rounding from picking a null of probability 0.
            out.end = SegmentEnd::Scattered;
            weight *= real_weight(c.sigma_s, mu_bar, p.scatter);
            p_event = p.scatter;
        } else {
            const double p_null = detail::null_probability<A>(c, mu_bar);
            const double mu = mu_bar;
            weight *= (mu - c.sigma_t().template cast<double>()) * (1.0 / (mu * p_null));
            null_pdf_product *= p_null;
            if constexpr (Rec::enabled) rec.vertex(t, std::log(double(mu_bar) * p.null) - tau);
            return true;
        }
        NSP_DEBUG_ASSERT(p_event > 0.f, "delta tracking chose a real event of probability 0");
        out.t = t;
        if constexpr (kControlled) {  // the vertex's density: both routes' (see DeltaTrack)
            const detail::EventDensities d = detail::decomposition_event_densities<A>(kept.k, kept.ctl, kept.mu_bar);
            out.event_density = out.end == SegmentEnd::Absorbed ? d.absorb : d.scatter;
        } else {
            out.event_density = mu_bar * p_event;  // 0 where it lies below float's range (see DeltaTrack)
        }
        if constexpr (Rec::enabled) rec.vertex(t, std::log(double(mu_bar) * p_event) - tau);
        return false;
    }

    /// Under a control, the loop's call at every collision y, control or residual, before its
    /// coefficients become the control's or the residual's: keeps the medium's own lookup `c`, the
    /// grey control `ctl` and the segment's majorant `mu_bar` = mu_c + mu_bar_r (the rate of
    /// collisions there) for a real vertex's density, and calls the visitor with them and the null
    /// product with the control's exp(-tau_c) up to y (`tau_ctl`). The collision estimator of
    /// emission is then unbiased and its pdf is the full majorant's formula with the residual's null
    /// product (THEORY 5.10).
    void before_event(float t, const Coefficients<S>& c, float mu_bar, float ctl, double tau_ctl)
        requires kControlled
    {
        kept = {c, ctl, mu_bar};
        if constexpr (Visit::enabled)
            visit(t, c, mu_bar, typename S::Spectrum(weight.template cast<float>()),
                  float(null_pdf_product * std::exp(-tau_ctl)));
        else
            (void)t, (void)tau_ctl;
    }

    /// sigma / (mu_bar P) of the chosen real event. In float where mu_bar P is a normal float (the
    /// results of every earlier version, to the bit); in double below that, where the float
    /// product underflows and would give an infinite weight (fuzzer finding 15).
    static detail::DoubleSpectrum<typename S::Spectrum> real_weight(const typename S::Spectrum& sigma, float mu_bar,
                                                                    float p) noexcept {
        const float density = mu_bar * p;
        if (density >= std::numeric_limits<float>::min()) return (sigma / density).template cast<double>();
        return sigma.template cast<double>() * (1.0 / (double(mu_bar) * double(p)));
    }

    /// `out` with the accumulated weight and null-pdf product rounded to float.
    DeltaTrack<S> finish() const noexcept {
        DeltaTrack<S> r = out;
        r.weight = weight.template cast<float>();
        r.null_pdf_product = float(null_pdf_product);
        return r;
    }
};

/// The outcome of ratio tracking one segment.
template <SpectralMode S>
struct RatioTrack {
    SegmentEnd end = SegmentEnd::Passed;  ///< Passed, Terminated (weight 0), Aborted or Rejected
    typename S::Spectrum transmittance;   ///< prod_j mu_n,c(n_j) / mu_bar(n_j): unbiased estimate of T
    float null_pdf_product = 1.f;         ///< prod_j P_n(n_j) of delta tracking with policy A, if asked for
};

/// Ratio tracking (THEORY 4.3, P_n = 1): every collision is null and multiplies the weight by
/// mu_n / mu_bar. With `kNullRatio` it also multiplies the P_n that delta tracking with policy A
/// would have used at the same nulls, the factor that makes null-scattering MIS work (THEORY 5.1).
template <AbsorptionPolicy A, bool kNullRatio, SpectralMode S, class Rec>
struct RatioCollision {
    /// Under a control, residual ratio tracking (THEORY 5.10).
    static constexpr ControlUse control_use = ControlUse::ClosedForm;
    Rec& rec;
    SegmentEnd end = SegmentEnd::Passed;
    // The products accumulate in double (see detail::kFloatNulls; for one to a few channels
    // double costs no more than float); `finish` rounds them.
    detail::DoubleSpectrum<typename S::Spectrum> transmittance = decltype(transmittance)::Ones();
    double null_pdf_product = 1.0;
    /// The product below which the estimate is lost: the smallest normal float, over the control's
    /// transmittance where a control's closed form will multiply it (control_depth).
    double floor = double(std::numeric_limits<float>::min());

    /// Under a control, the loop's report of the control's optical depth up to the end of the
    /// current segment (past 20 only: below, the floor would stay under 1e-29): the estimate will
    /// be multiplied by exp(-tau), so the stop below must see it, or a shadow ray through a thick
    /// controlled medium walks to its end for an estimate that rounds to 0.
    void control_depth(double tau) noexcept { floor = double(std::numeric_limits<float>::min()) * std::exp(tau); }

    bool operator()(float t, const Coefficients<S>& c, float mu_bar, float tau) {
        transmittance *= detail::null_ratio(c, mu_bar);
        if constexpr (kNullRatio) null_pdf_product *= detail::null_probability<A>(c, mu_bar);
        if constexpr (Rec::enabled) rec.vertex(t, std::log(double(mu_bar)) - tau);
        // Stop once every channel is below the smallest normal float, what the float result can
        // hold: a float product of factors above 1/2 stalls at the smallest denormal and never
        // reaches 0, which made thick media cost a lookup per majorant optical depth.
        if ((transmittance.abs() < floor).all()) {
            transmittance.setZero();
            end = SegmentEnd::Terminated;
            return false;
        }
        return true;
    }

    /// The segment's result, rounded to float.
    RatioTrack<S> finish() const noexcept {
        return {end, typename S::Spectrum(transmittance.template cast<float>()), float(null_pdf_product)};
    }
};

/// Delta-tracks `ray` over [0, tmax] as `track_delta` does, calling `visit` at every tentative
/// collision (see DeltaCollision); under a control at every control and residual collision, with
/// the medium's own coefficients, the segment's majorant and the null product with exp(-tau_c) so
/// far (DeltaCollision::before_event).
template <AbsorptionPolicy A, Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C, class Visit,
          class Rec = NoRecord>
DeltaTrack<typename M::Spectral> track_delta_visiting(const M& medium, const Maj& majorant, const Ray& ray,
                                                      float tmax, const typename M::Spectral::Wavelengths& lambda,
                                                      R& rng, C& counter, Visit visit, Rec&& rec = Rec{}) {
    using S = typename M::Spectral;
    constexpr bool kControlled =
        detail::has_control_v<std::remove_cvref_t<decltype(*majorant.iterate(ray, 0.f, tmax, lambda).next())>>;
    DeltaCollision<A, S, R, std::remove_reference_t<Rec>, Visit, kControlled> cb{rng, rec, std::move(visit)};
    const auto f = free_flight(medium, majorant, ray, 0.f, tmax, lambda, rng, counter, cb);
    if (f.aborted) return {aborted_end(f), f.t, S::Spectrum::Zero(), 1.f};
    if (!f.stopped) {
        cb.out.end = SegmentEnd::Passed;
        cb.out.t = tmax;
        if constexpr (std::remove_reference_t<Rec>::enabled) rec.log_pdf -= f.tau_tail;
    }
    // Under a control, no control collision before the end: exp(-tau_c) joins the null product
    // (THEORY 5.10: p_uni / p_nee = (p_w / p_l) exp(-tau_c) prod P_n,r).
    if (f.tau_ctl > 0.0) cb.null_pdf_product *= std::exp(-f.tau_ctl);
    return cb.finish();
}

/// Delta-tracks `ray` over [0, tmax] inside the medium. A `Passed` result means the ray reached
/// tmax; its weight is then the transmittance weight of the nulls (1 on grey bounded media).
template <AbsorptionPolicy A, Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C,
          class Rec = NoRecord>
DeltaTrack<typename M::Spectral> track_delta(const M& medium, const Maj& majorant, const Ray& ray,
                                             float tmax, const typename M::Spectral::Wavelengths& lambda,
                                             R& rng, C& counter, Rec&& rec = Rec{}) {
    return track_delta_visiting<A>(medium, majorant, ray, tmax, lambda, rng, counter, NoVisit{}, rec);
}

/// Ratio-tracks `ray` over [0, tmax]: an unbiased per-channel transmittance estimate, and with
/// `kNullRatio` the product of delta tracking's (policy A) null probabilities at its nulls.
template <AbsorptionPolicy A, bool kNullRatio, Medium M, MajorantPolicy<M> Maj, UniformRng R,
          LookupCounter C, class Rec = NoRecord>
RatioTrack<typename M::Spectral> track_ratio(const M& medium, const Maj& majorant, const Ray& ray,
                                             float tmax, const typename M::Spectral::Wavelengths& lambda,
                                             R& rng, C& counter, Rec&& rec = Rec{}) {
    using S = typename M::Spectral;
    RatioCollision<A, kNullRatio, S, std::remove_reference_t<Rec>> cb{rec};
    const auto f = free_flight(medium, majorant, ray, 0.f, tmax, lambda, rng, counter, cb);
    if (f.aborted) return {aborted_end(f), S::Spectrum::Zero(), 1.f};
    if constexpr (std::remove_reference_t<Rec>::enabled)
        if (!f.stopped) rec.log_pdf -= f.tau_tail;
    // Under a control (residual ratio tracking, THEORY 5.10): the control's transmittance in closed
    // form, and decomposition tracking's probability of no control collision in the null product.
    if (f.tau_ctl > 0.0 && cb.end == SegmentEnd::Passed) {
        const double t_ctl = std::exp(-f.tau_ctl);
        cb.transmittance *= t_ctl;
        cb.null_pdf_product *= t_ctl;
    }
    return cb.finish();
}

/// A transmittance estimate and its status: `value` 0 unless the status is Ok.
template <SpectralMode S>
struct TransmittanceSample {
    typename S::Spectrum value;
    Status status = Status::Ok;
};

/// Ratio-tracking transmittance estimate between two points (Novak et al. 2014) along `ray` over
/// [0, tmax]; status InvalidInput (value 0) for a ray that is not usable_ray or a NaN tmax, Aborted
/// or Rejected where the flight failed.
template <Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C>
TransmittanceSample<typename M::Spectral> transmittance_ratio(const M& medium, const Maj& majorant, const Ray& ray,
                                                              float tmax, const typename M::Spectral::Wavelengths& lambda,
                                                              R& rng, C& counter) {
    const auto r = track_ratio<absorption::Event, false>(medium, majorant, ray, tmax, lambda, rng, counter);
    return {r.transmittance, flight_status(r.end)};
}

/// Delta-tracking transmittance estimate: the null weight if the ray passes tmax, else 0; the
/// status as transmittance_ratio's.
template <Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C>
TransmittanceSample<typename M::Spectral> transmittance_delta(const M& medium, const Maj& majorant, const Ray& ray,
                                                              float tmax, const typename M::Spectral::Wavelengths& lambda,
                                                              R& rng, C& counter) {
    const auto d = track_delta<absorption::Event>(medium, majorant, ray, tmax, lambda, rng, counter);
    using Spec = typename M::Spectral::Spectrum;
    return {d.end == SegmentEnd::Passed ? d.weight : Spec(Spec::Zero()), flight_status(d.end)};
}

}  // namespace nsp
