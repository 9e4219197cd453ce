// tests/support/stability.hpp: what the stability suite (issue 8) shares: the majorant-kind x
// bound-policy x spectral-mode product the kernel suites run over, a factory that builds any
// kind at a chosen ratio to the medium's extinction bound, the transmittance estimators that
// apply to a kind (grey kinds: ratio and delta tracking and the per-channel trackers; per-channel
// kinds: the per-channel trackers), and the closed form each policy promises on a medium of
// uniform density.
//
// Float precision: every closed form here is computed in double; estimates are float. Each test
// states the precision its case needs next to the case.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "common.hpp"
#include "spectral.hpp"

namespace nsp_test::stab {

using namespace nsp;

/// k standard errors for every closed-form comparison of the suite (fixed seeds: a pass is
/// reproducible; at k = 5 a correct estimator fails one comparison in ~2 million).
constexpr double kSigmas = 5.0;

// ---------------------------------------------------------------------------------------------
// Majorant kinds: each builds its policy with bound policy B at `ratio` x the tight bound.

/// One grey value: ratio x the medium's max extinction (ratio 1: exactly the extinction of a
/// uniform medium, up to the rounding of sa d + ss d against (sa + ss) d).
struct GlobalK {
    static constexpr const char* name = "global";
    static constexpr bool per_channel = false;
    template <class M, class B> using type = GlobalMajorant<M, B>;
    template <class B, class M> static type<M, B> make(const M& m, float ratio) {
        return type<M, B>(m, ratio * m.max_extinction());
    }
};
/// One value per channel: ratio x each channel's extinction bound.
struct ChannelK {
    static constexpr const char* name = "per-channel";
    static constexpr bool per_channel = true;
    template <class M, class B> using type = ChannelMajorant<M, B>;
    template <class B, class M> static type<M, B> make(const M& m, float ratio) { return type<M, B>(m, ratio); }
};
/// A grey grid (3 x 4 x 2 cells, not aligned with the medium's voxels), cells padded by 2^-16.
struct GridK {
    static constexpr const char* name = "grid";
    static constexpr bool per_channel = false;
    template <class M, class B> using type = GridMajorant<M, B>;
    template <class B, class M> static type<M, B> make(const M& m, float ratio) {
        return type<M, B>(m, std::array<int, 3>{3, 4, 2}, ratio);
    }
};
/// A per-channel grid, same cells.
struct ChannelGridK {
    static constexpr const char* name = "channel-grid";
    static constexpr bool per_channel = true;
    template <class M, class B> using type = ChannelGridMajorant<M, B>;
    template <class B, class M> static type<M, B> make(const M& m, float ratio) {
        return type<M, B>(m, std::array<int, 3>{3, 4, 2}, ratio);
    }
};

/// One point of majorant kind x bound policy x spectral mode.
template <class K, BoundPolicy B, SpectralMode S>
struct Track {
    using Kind = K;
    using Bound = B;
    using Spectral = S;
    using Medium = DenseGridMedium<S>;
    using Majorant = typename K::template type<Medium, B>;
    static constexpr bool reject = std::is_same_v<B, bound::Reject>;
    static constexpr bool clamp = std::is_same_v<B, bound::Clamp>;
    static std::string name() { return std::string(K::name) + "/" + B::name + "/" + S::name; }
};

template <class K, class S>
using TracksOfKind = std::tuple<Track<K, bound::Guaranteed, S>, Track<K, bound::Signed, S>, Track<K, bound::Clamp, S>,
                                Track<K, bound::Reject, S>>;
template <class S>
using TracksOfMode = decltype(std::tuple_cat(TracksOfKind<GlobalK, S>{}, TracksOfKind<ChannelK, S>{},
                                             TracksOfKind<GridK, S>{}, TracksOfKind<ChannelGridK, S>{}));

/// Every majorant kind x bound policy for the modes listed: 16 types per mode.
using TracksMono = TracksOfMode<Mono>;
using TracksRgb = TracksOfMode<Rgb>;
using TracksHero = TracksOfMode<Hero<4>>;

/// True when the rejection of bound::Reject is observable: in a debug build it asserts instead.
inline constexpr bool kRejectReports =
#if defined(NDEBUG) && !defined(NSP_DEBUG)
    true;
#else
    false;
#endif

// ---------------------------------------------------------------------------------------------
// Media

/// A grid medium of uniform density `d` over `box` (2 x 2 x 2 voxels: trilinear lookups return
/// d exactly, a + f (a - a) = a), so T_c = exp(-d ext_c len) in closed form.
template <SpectralMode S>
DenseGridMedium<S> uniform_grid(const Box& box, float d, const typename S::Coefficient& sa,
                                const typename S::Coefficient& ss) {
    return {box, {2, 2, 2}, std::vector<float>(8, d), sa, ss};
}

/// Coefficients per unit density with extinction 0.5 : 0.75 : 1 (albedo 0.8): mildly chromatic,
/// so a majorant at kBelow x the bound lies below the extinction in some channel of every path
/// (Hero: the extinction is 1 for lambda <= 450 nm and a stratified draw of 4 wavelengths always
/// has one below 478 nm, where it is > 0.93 > 0.75).
template <SpectralMode S>
typename S::Coefficient base_sa() { return chroma<S>(0.1f, 0.15f, 0.2f); }
template <SpectralMode S>
typename S::Coefficient base_ss() { return chroma<S>(0.4f, 0.6f, 0.8f); }

/// The ratio of a majorant below the extinction: 0.75 x the bound. Not 0.5: under bound::Signed
/// a null factor (mu_bar - mu_t) / mu_bar is then -1/3, not -1, so ratio tracking in a dense
/// medium still underflows and stops (a factor of -1 would keep |T| = 1 for 1e6 collisions).
inline constexpr float kBelow = 0.75f;

// ---------------------------------------------------------------------------------------------
// Closed forms

/// What a policy's estimate converges to on a uniform medium whose extinction at the path's
/// wavelengths is `mu_t` and whose majorant there is `mu_bar` (per channel; a grey one in every
/// channel), over `len` inside the medium:
/// - a majorant that bounds (any policy) or bound::Signed (unbiased below): exp(-mu_t len);
/// - bound::Clamp below: the clamped medium, exp(-min(mu_t, mu_bar) len) per channel;
/// - bound::Reject below: every collision is rejected (mu_t > mu_bar in some channel, see
///   base_sa), so only flights without a collision count, exp(-mu_bar len) for each channel's
///   own estimate (THEORY 4; the per-channel estimators' f / sum q p reduce to the same).
template <class Tr, class Spec>
double expected_transmittance(const Spec& mu_t, const Spec& mu_bar, double len, int c, bool below) {
    const double t = mu_t[c], m = mu_bar[c];
    if (!below) return std::exp(-t * len);
    if constexpr (Tr::clamp) return std::exp(-std::min(t, m) * len);
    else if constexpr (Tr::reject) return std::exp(-m * len);
    else return std::exp(-t * len);
}

/// The majorant of the first segment of [0, tmax] on `ray`, per channel (zero if there is none).
template <class M, class Maj>
typename M::Spectral::Spectrum first_majorant(const Maj& maj, const Ray& ray, float tmax,
                                              const typename M::Spectral::Wavelengths& l) {
    using Spec = typename M::Spectral::Spectrum;
    auto it = maj.iterate(ray, 0.f, tmax, l);
    if (auto seg = it.next()) return nsp::detail::broadcast_majorant<Spec>(seg->sigma_maj);
    return Spec::Zero();
}

// ---------------------------------------------------------------------------------------------
// Transmittance estimators of a track

/// Which estimator of T an entry of `estimate` is.
enum class Est : int { Ratio, Delta, ChannelRatio, ChannelDelta, IndependentRatio, IndependentDelta };

inline const char* est_name(Est e) {
    switch (e) {
        case Est::Ratio: return "ratio";
        case Est::Delta: return "delta";
        case Est::ChannelRatio: return "channel-ratio (spectral MIS)";
        case Est::ChannelDelta: return "channel-delta (spectral MIS / spectral tracking avg)";
        case Est::IndependentRatio: return "channel-ratio (independent)";
        default: return "channel-delta (independent)";
    }
}

/// The estimators that apply to track Tr: grey kinds ratio, delta (absorption events), per-channel
/// ratio with spectral MIS over channels and per-channel delta with throughput-weighted spectral
/// tracking (one shared pdf; needs the grey majorant); per-channel kinds the per-channel trackers
/// with spectral MIS and with independent tracking.
template <class Tr>
std::vector<Est> estimators_of() {
    if constexpr (Tr::Kind::per_channel)
        return {Est::ChannelRatio, Est::ChannelDelta, Est::IndependentRatio, Est::IndependentDelta};
    else return {Est::Ratio, Est::Delta, Est::ChannelRatio, Est::ChannelDelta};
}

/// One estimate of T along `ray` over [0, tmax] and how its flight ended.
template <SpectralMode S>
struct TrEstimate {
    typename S::Spectrum value;
    SegmentEnd end = SegmentEnd::Passed;
};

/// Runs estimator `e` once. The per-channel estimators pick the sampling channel uniformly with
/// one random number and estimate every channel by channel_estimate (f / sum_c q_c p_c; for
/// independent tracking f_c / (q_c p_c) in the sampled channel, 0 elsewhere).
template <class Tr, class M, class Maj, class R, class C>
TrEstimate<typename Tr::Spectral> estimate(Est e, const M& medium, const Maj& maj, const Ray& ray, float tmax,
                                           const typename Tr::Spectral::Wavelengths& l, R& rng, C& counter) {
    using S = typename Tr::Spectral;
    using Spec = typename S::Spectrum;
    const ChannelSelection<S> q;
    auto channel_ratio = [&](auto cp) -> TrEstimate<S> {
        using CP = decltype(cp);
        const int c = q.sample(rng.uniform());
        const auto sh = track_channels_ratio<CP, absorption::Weight>(medium, maj, ray, tmax, l, c,
                                                                     Spec(Spec::Ones()), true, rng, counter);
        return {channel_estimate<CP>(sh.f, sh.nee, q.probabilities(), c), sh.end};
    };
    auto channel_delta = [&](auto cp) -> TrEstimate<S> {
        using CP = decltype(cp);
        const int c = q.sample(rng.uniform());
        ChannelPathState<S> st;
        const ChannelTrack tr = track_channels_delta<CP, absorption::Event>(medium, maj, ray, tmax, l, c, st, false,
                                                                            rng, counter);
        if (tr.end != SegmentEnd::Passed) return {Spec::Zero(), tr.end};
        return {channel_estimate<CP>(st.f, st.uni, q.probabilities(), c), tr.end};
    };
    if constexpr (!Tr::Kind::per_channel) {
        if (e == Est::Ratio) {
            const auto r = track_ratio<absorption::Weight, true>(medium, maj, ray, tmax, l, rng, counter);
            return {r.transmittance, r.end};
        }
        if (e == Est::Delta) {
            const auto d = track_delta<absorption::Event>(medium, maj, ray, tmax, l, rng, counter);
            return {d.end == SegmentEnd::Passed ? d.weight : Spec(Spec::Zero()), d.end};
        }
        if (e == Est::ChannelRatio) return channel_ratio(channels::SpectralMis{});
        return channel_delta(channels::SpectralTrackingAverage{});
    } else {
        switch (e) {
            case Est::ChannelRatio: return channel_ratio(channels::SpectralMis{});
            case Est::ChannelDelta: return channel_delta(channels::SpectralMis{});
            case Est::IndependentRatio: return channel_ratio(channels::Independent{});
            default: return channel_delta(channels::Independent{});
        }
    }
}

/// True when `end` is a status estimator `e` may report: ratio trackers pass or terminate (weight
/// below FLT_MIN), delta trackers pass, scatter or absorb (per-channel ones also terminate when no
/// pdf is left); bound::Reject adds Rejected where the majorant lies below. Never Aborted here:
/// every flight of these cases is far below 2^24 collisions.
inline bool status_allowed(Est e, SegmentEnd end, bool may_reject) {
    if (end == SegmentEnd::Rejected) return may_reject;
    if (end == SegmentEnd::Aborted) return false;
    switch (e) {
        case Est::Ratio:
        case Est::ChannelRatio:
        case Est::IndependentRatio: return end == SegmentEnd::Passed || end == SegmentEnd::Terminated;
        case Est::Delta: return end == SegmentEnd::Passed || end == SegmentEnd::Scattered || end == SegmentEnd::Absorbed;
        default: return end != SegmentEnd::Rejected;
    }
}

/// Per-channel statistics of (estimate - expected) over n estimates, with counts of non-finite
/// estimates, disallowed statuses, rejected flights and the lookups paid.
template <SpectralMode S>
struct ErrStats {
    SpecStat<S> err;
    SpecStat<S> value;
    int non_finite = 0, bad_status = 0, rejected = 0, out_of_range = 0;
    double expected_rejections = 0.0, rejection_var = 0.0;
    std::uint64_t lookups = 0;
};

/// Checks the statistics of one estimator: every estimate finite, every status allowed, and the
/// mean error within kSigmas standard errors plus `floor` (the float resolution of the case).
template <SpectralMode S>
void check_stats(const ErrStats<S>& s, double floor) {
    CHECK(s.non_finite == 0);
    CHECK(s.bad_status == 0);
    CHECK(s.out_of_range == 0);
    for (int c = 0; c < S::channels; ++c) {
        const Stat& e = s.err.ch[std::size_t(c)];
        CAPTURE(c);
        CAPTURE(s.value.ch[std::size_t(c)].mean);
        CAPTURE(e.mean);
        CAPTURE(e.se());
        CHECK(std::abs(e.mean) <= kSigmas * e.se() + floor);
    }
}

}  // namespace nsp_test::stab
