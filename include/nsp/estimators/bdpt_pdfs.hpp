// nsp/estimators/bdpt_pdfs.hpp: BDPT's policies and its pdf bookkeeping (THEORY 5.5, with 5.3
// per channel): the MIS and channel-axis policies, PathPdfs (the densities of one path under every
// strategy) and the strategy weights over them, grey and per channel. Used by bdpt.hpp; a host
// that weighs its own bidirectional strategies can use them alone.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <type_traits>

#include "../channel_tracking.hpp"
#include "../mis.hpp"
#include "../options.hpp"
#include "../spectrum.hpp"

namespace nsp::bdpt {

/// Full null-scattering MIS over the (s, t) strategies (THEORY 5.5).
struct NullScattering {
    static constexpr const char* name = "bdpt-null-mis";
    static constexpr bool null_pdfs = true;
};
/// The baseline: the strategies weighted by direction pdfs and geometry alone (THEORY 5.2, 5.5).
struct Directional {
    static constexpr const char* name = "bdpt-directional-mis";
    static constexpr bool null_pdfs = false;
};

template <class T>
concept MisPolicy = requires {
    { T::name } -> std::convertible_to<const char*>;
    { T::null_pdfs } -> std::convertible_to<bool>;
};

/// One pdf for every channel (the default): the path is tracked with grey event probabilities
/// and a grey majorant, as PathEstimator tracks it.
struct Grey {
    static constexpr const char* name = "grey";
};

/// What the channel axis of BdptEstimator may be: Grey, or channels::SpectralMis (each channel its
/// own majorant and event probabilities, one sampling channel per sample chosen uniformly, the
/// one-sample balance or power heuristic over channels x strategies, THEORY 5.3 with 5.5).
template <class T>
concept ChannelAxis = std::same_as<T, Grey> || std::same_as<T, channels::SpectralMis>;

/// Where a grey path keeps no per-channel factor.
struct NoGamma {};

/// The type of a vertex's densities: one float (Grey) or one per channel.
template <class Ch, SpectralMode S>
using PdfType = std::conditional_t<std::same_as<Ch, Grey>, float, typename S::Spectrum>;

/// The type of a path's per-channel shared factors: nothing for Grey.
template <class P>
using GammaOf = std::conditional_t<std::is_same_v<P, float>, NoGamma, P>;

/// Shared factors of 1 in every channel (a path with no segment yet).
template <class P>
GammaOf<P> unit_gamma() noexcept {
    if constexpr (std::is_same_v<P, float>) return NoGamma{};
    else return P::Ones();
}

/// A majorant lookup's value (a float, or one per channel) as densities of type P.
template <class P, class V>
P majorants(const V& mu) noexcept {
    if constexpr (std::is_same_v<P, float>) return float(mu);
    else return nsp::detail::broadcast_majorant<P>(mu);
}

/// A majorant lookup's value in channel c (a grey majorant's in every channel).
template <class V>
float majorant_at(const V& mu, int c) noexcept {
    if constexpr (std::is_same_v<V, float>) return mu;
    else return mu[c];
}

/// Broadcasts a density common to every channel (a light's emission, a direction pdf) into P.
template <class P>
P broadcast(float v) noexcept {
    if constexpr (std::is_same_v<P, float>) return v;
    else return P::Constant(v);
}

/// The densities of one path x_0 (on a light, or at infinity) .. x_k (the camera) under every
/// strategy, as the weights need them (k <= N - 1):
/// - from_light[i], i in 1..k-1: the density of x_i drawn from x_{i-1} on the light side;
/// - from_camera[i], i in 0..k-1: the density of x_i drawn from x_{i+1} on the camera side
///   (from_camera[k-1] = 1: the camera's own, the same in every strategy with t >= 2);
/// - emit: the density of x_0 under light subpaths (the light sampler's emission, selection
///   included; solid angle at infinity, 0 there when the sampler has no BoundingSphere); nee: its
///   density under NEE from x_1 (solid angle at infinity, area measure otherwise, a point light's
///   selection probability);
/// - connectible[i]: x_i is not a delta vertex (a mirror), so a connection may end there;
/// - light_tracing: strategy s = k (t = 1, x_{k-1} connected to the camera) is among them; then
///   from_camera[k-1] is the camera's own density of x_{k-1} (its pdf_dir converted), else any
///   value > 0 (it is the same in every strategy and cancels).
/// Strategy s draws x_0..x_{s-1} from the light and x_s..x_k from the camera.
///
/// - eq, eq_nee: the equiangular strategy (BdptEstimator with EstimatorOptions::bdpt_equiangular),
///   s = 1 with x_1 drawn from x_2 by equiangular sampling toward the lights' targets instead of
///   by tracking: eq the density of x_1 so drawn (volume measure, the segment's nulls ratio-tracked,
///   so its only tracking factor is the equiangular density per unit length; 0 where x_1 is no
///   medium vertex or the technique is off), eq_nee the density of x_0 under NEE from it (NEE
///   from an equiangular vertex always runs: no count; 0 where NEE does not draw x_0 there). Its
///   index among the strategies is kEquiangular (k >= 2 only).
/// - seg: the segment technique (THEORY 5.7 in 5.5; BdptEstimator with
///   EstimatorOptions::emission_along_segments), s = 0 with x_0 drawn from x_1 on its piece of
///   the segment (the part in one medium between surfaces or null interfaces) in proportion to
///   the medium's power grid along it instead of by tracking: the density of x_0 so drawn
///   (volume measure; its count, EstimatorOptions::emission_segment_count, included), with the
///   P_n of the nulls on the pieces before x_0's (tracked) and none for x_0's own (ratio-tracked,
///   their Tbar and mu_bar shared with every strategy); 0 where x_0 is not in an emitting
///   medium or the technique is off. Its index is kSegment; q arrays hold kSlots entries.
///
/// Per channel (P a Spectrum, THEORY 5.3 with 5.5), from_light and from_camera hold every
/// channel's density (its own majorant and event probabilities in the null and event factors),
/// `gamma` every channel's factor that all strategies of the path share (its Tbar_c and the
/// nulls' mu_bar_c), relative to the largest, and `channel` the sample's sampling channel.
template <int N, class P = float>
struct PathPdfs {
    /// The equiangular strategy's index (above every (s, t) strategy's, s <= k <= N - 1).
    static constexpr int kEquiangular = N;
    /// The segment technique's index.
    static constexpr int kSegment = N + 1;
    /// The size of a q array of strategy_pdfs (per channel: of each channel's part).
    static constexpr int kSlots = N + 2;
    int k = 0;
    bool light_tracing = false;
    float emit = 0.f, nee = 0.f, eq_nee = 0.f;
    P from_light[N] = {};
    P from_camera[N] = {};
    P eq = broadcast<P>(0.f);
    P seg = broadcast<P>(0.f);
    bool connectible[N] = {};
    [[no_unique_address]] GammaOf<P> gamma = unit_gamma<P>();
    [[no_unique_address]] std::conditional_t<std::is_same_v<P, float>, NoGamma, int> channel{};
};

/// How many strategies the path has: s = 0..k-1, and s = k (t = 1, light tracing) when
/// `light_tracing` and k >= 2.
template <int N, class P>
int strategy_count(const PathPdfs<N, P>& p) noexcept {
    return p.light_tracing && p.k >= 2 ? p.k + 1 : p.k;
}

/// Whether strategy s is one of the path's: s < strategy_count(p), the equiangular strategy or
/// the segment technique.
template <int N, class P>
bool is_strategy(const PathPdfs<N, P>& p, int s) noexcept {
    return (s >= 0 && s < strategy_count(p)) || s == PathPdfs<N, P>::kEquiangular || s == PathPdfs<N, P>::kSegment;
}

/// Strategy s's pdf of the path relative to the largest of all strategies' (each in [0, 1]; 0
/// where s cannot draw it), written into q[0..k-1] (q[0..k] with light tracing), the
/// equiangular strategy's into q[N] and the segment technique's into q[N + 1] (q has N + 2 =
/// PathPdfs::kSlots entries). Each vertex's
/// two densities are scaled by their larger one (an infinite one, an overflowed density, wins)
/// and the products taken in double, so long paths neither overflow nor underflow. Returns false
/// when no strategy can draw the path. NaN densities give NaN.
template <int N>
bool strategy_pdfs(const PathPdfs<N>& p, double* q) noexcept {
    const int k = p.k;
    if (k < 1 || k >= N) return false;
    // Scales numbers >= 0 by their largest: an infinite one (a density that overflowed) becomes
    // 1 and takes the place of every finite one, which become 0; all 0 stays 0.
    // A NaN makes them all NaN.
    auto scale = [](double* v, int n) {
        bool inf = false, nan = false;
        double m = 0.0;
        for (int i = 0; i < n; ++i) {
            inf = inf || std::isinf(v[i]);
            nan = nan || std::isnan(v[i]);
            m = std::max(m, v[i]);
        }
        for (int i = 0; i < n; ++i)
            v[i] = nan ? v[i] * 0.0 + std::numeric_limits<double>::quiet_NaN()
                       : inf ? (std::isinf(v[i]) ? 1.0 : 0.0) : (m > 0.0 ? v[i] / m : 0.0);
    };
    double l[N], c[N], eq1 = 0.0;
    for (int i = 1; i < k; ++i) {
        double v[3] = {double(p.from_light[i]), double(p.from_camera[i]), i == 1 ? double(p.eq) : 0.0};
        scale(v, 3);
        l[i] = v[0];
        c[i] = v[1];
        if (i == 1) eq1 = v[2];
    }
    // suffix[j] = prod_{i=j}^{k-1} c_i
    double suffix[N + 1];
    suffix[k] = 1.0;
    for (int i = k - 1; i >= 1; --i) suffix[i] = suffix[i + 1] * c[i];
    // x_0 under s = 0, 1, >= 2, the equiangular strategy and the segment technique
    double x0[5] = {double(p.from_camera[0]), double(p.nee), double(p.emit), double(p.eq_nee), double(p.seg)};
    scale(x0, 5);
    const int last = strategy_count(p);
    double prefix = 1.0, largest = 0.0;  // prefix = prod_{i=1}^{s-1} l_i
    q[N] = k >= 2 && p.connectible[1] ? x0[3] * eq1 * suffix[2] : 0.0;
    q[N + 1] = x0[4] * suffix[1];  // drawn along x_1's sampled direction, as s = 0: x_1 may be delta
    if (std::isnan(q[N]) || std::isnan(q[N + 1])) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        for (int r = 0; r <= N + 1; ++r) q[r] = nan;
        return true;
    }
    largest = std::max(q[N], q[N + 1]);
    for (int s = 0; s < last; ++s) {
        if (s >= 2) prefix *= l[s - 1];
        double v = 0.0;
        if (s == 0) v = x0[0] * suffix[1];
        else if (s == 1) v = p.connectible[1] ? x0[1] * suffix[1] : 0.0;
        else if (s == k) v = p.connectible[k - 1] ? x0[2] * prefix : 0.0;  // t = 1
        else if (p.connectible[s - 1] && p.connectible[s]) v = x0[2] * prefix * suffix[s];
        q[s] = v;
        if (std::isnan(v)) {  // a NaN density: every strategy's pdf is NaN
            for (int r = 0; r <= N + 1; ++r) q[r] = v;
            return true;
        }
        largest = std::max(largest, v);
    }
    if (!(largest > 0.0)) return false;
    for (int s = 0; s < last; ++s) q[s] /= largest;
    q[N] /= largest;
    q[N + 1] /= largest;
    return true;
}

/// The MIS weight of strategy s for the path: power(p_s) / sum_s' power(p_s') over the strategies
/// that can draw it (THEORY 5.5). The weights of all strategies of one path sum to 1; 0 where s
/// cannot draw it. NaN densities give NaN (the estimator reports Status::NonFinite).
template <mis::CombiningHeuristic H, int N>
float strategy_weight(const H& h, const PathPdfs<N>& p, int s) noexcept {
    const int n = strategy_count(p);
    if (!is_strategy(p, s)) return 0.f;
    double q[N + 2];
    if (!strategy_pdfs(p, q)) return 0.f;
    if (!(q[s] > 0.0)) return std::isnan(q[s]) ? q[s] : 0.f;
    double sum = q[N] > 0.0 ? double(h.power(float(q[N]))) : 0.0;
    if (q[N + 1] > 0.0) sum += double(h.power(float(q[N + 1])));
    for (int i = 0; i < n; ++i) sum += double(h.power(float(q[i])));
    return float(double(h.power(float(q[s]))) / sum);
}

/// Per channel (THEORY 5.3 with 5.5): every channel's pdf of the path under every strategy,
/// gamma_c x the strategy's product of densities, written into q[c * (N + 2) + s] (the equiangular
/// strategy's into q[c * (N + 2) + N], the segment technique's into q[c * (N + 2) + N + 1]), all relative
/// to one scale (each vertex's densities scaled by the largest over both directions and every
/// channel, the products in double, the whole divided by the largest), as strategy_pdfs does for
/// one channel. Returns false when no strategy of any channel can draw the path. NaN gives NaN.
template <int N, class P>
bool channel_strategy_pdfs(const PathPdfs<N, P>& p, double* q) noexcept {
    constexpr int C = int(P::SizeAtCompileTime);
    const int k = p.k;
    if (k < 1 || k >= N) return false;
    const int last = strategy_count(p);
    // Every vertex's scale, common to its channels and directions: an infinite density wins.
    auto scale_of = [](const P& a, const P& b, bool& nan) {
        nan = nan || a.isNaN().any() || b.isNaN().any();
        return std::max(double(a.maxCoeff()), double(b.maxCoeff()));
    };
    bool nan = false;
    double inv[N];  // 1 / the scale of vertex i (0 where all its densities are 0)
    bool inf[N];
    for (int i = 1; i < k; ++i) {
        double m = scale_of(p.from_light[i], p.from_camera[i], nan);
        if (i == 1) {
            nan = nan || p.eq.isNaN().any();
            m = std::max(m, double(p.eq.maxCoeff()));
        }
        inf[i] = std::isinf(m);
        inv[i] = m > 0.0 && !inf[i] ? 1.0 / m : 0.0;
    }
    const double m0 = std::max({double(p.from_camera[0].maxCoeff()), double(p.nee), double(p.emit), double(p.eq_nee),
                                double(p.seg.maxCoeff())});
    nan = nan || p.from_camera[0].isNaN().any() || std::isnan(p.nee) || std::isnan(p.emit) || std::isnan(p.eq_nee) ||
          p.seg.isNaN().any() || p.gamma.isNaN().any();
    if (nan) {
        for (int i = 0; i < C * (N + 2); ++i) q[i] = std::numeric_limits<double>::quiet_NaN();
        return true;
    }
    const bool inf0 = std::isinf(m0);
    const double inv0 = m0 > 0.0 && !inf0 ? 1.0 / m0 : 0.0;
    // A density relative to its vertex's scale: an infinite one becomes 1, a finite one beside it 0.
    auto rel = [](double v, double iv, bool is_inf) { return is_inf ? (std::isinf(v) ? 1.0 : 0.0) : v * iv; };
    double largest = 0.0;
    for (int ch = 0; ch < C; ++ch) {
        double* qc = q + ch * (N + 2);
        double suffix[N + 1];
        suffix[k] = 1.0;
        for (int i = k - 1; i >= 1; --i) suffix[i] = suffix[i + 1] * rel(double(p.from_camera[i][ch]), inv[i], inf[i]);
        const double x0[4] = {rel(double(p.from_camera[0][ch]), inv0, inf0), rel(double(p.nee), inv0, inf0),
                              rel(double(p.emit), inv0, inf0), rel(double(p.eq_nee), inv0, inf0)};
        const double g = double(p.gamma[ch]);
        qc[N] = k >= 2 && p.connectible[1] ? g * x0[3] * rel(double(p.eq[ch]), inv[1], inf[1]) * suffix[2] : 0.0;
        qc[N + 1] = g * rel(double(p.seg[ch]), inv0, inf0) * suffix[1];
        largest = std::max({largest, qc[N], qc[N + 1]});
        double prefix = 1.0;
        for (int s = 0; s < last; ++s) {
            if (s >= 2) prefix *= rel(double(p.from_light[s - 1][ch]), inv[s - 1], inf[s - 1]);
            double v = 0.0;
            if (s == 0) v = x0[0] * suffix[1];
            else if (s == 1) v = p.connectible[1] ? x0[1] * suffix[1] : 0.0;
            else if (s == k) v = p.connectible[k - 1] ? x0[2] * prefix : 0.0;
            else if (p.connectible[s - 1] && p.connectible[s]) v = x0[2] * prefix * suffix[s];
            qc[s] = g * v;
            largest = std::max(largest, qc[s]);
        }
    }
    if (!(largest > 0.0)) return false;
    for (int ch = 0; ch < C; ++ch) {
        for (int s = 0; s < last; ++s) q[ch * (N + 2) + s] /= largest;
        q[ch * (N + 2) + N] /= largest;
        q[ch * (N + 2) + N + 1] /= largest;
    }
    return true;
}

/// Per channel: the factor by which the sampling channel's sample of strategy s multiplies its
/// throughput f_lambda / p_(s,c*) (THEORY 5.3 with 5.5): w_(s,c*) / q_(c*) with w_(s,c) =
/// power(q_c p_(s,c)) / sum over channels c' and strategies s' of power(q_c' p_(s',c')), uniform
/// selection q_c = 1 / C. `p.gamma` must lie in [0, 1] (relative to its largest channel). Under the balance heuristic the estimate is f_lambda / sum_c q_c sum_s'
/// p_(s',c). The w of all channels and strategies of a path sum to 1. 0 where s cannot draw it in
/// channel c*; NaN densities give NaN.
template <mis::CombiningHeuristic H, int N, class P>
float channel_strategy_weight(const H& h, const PathPdfs<N, P>& p, int s) noexcept {
    constexpr int C = int(P::SizeAtCompileTime);
    const int n = strategy_count(p);
    if (!is_strategy(p, s) || p.channel < 0 || p.channel >= C) return 0.f;
    double q[C * (N + 2)];
    if (!channel_strategy_pdfs(p, q)) return 0.f;
    const double own = q[p.channel * (N + 2) + s];
    if (!(own > 0.0)) return std::isnan(own) ? float(own) : 0.f;
    // With one selection probability for every channel it factors out of the heuristic (balance
    // and power are homogeneous): the pdfs enter as they are, the largest 1, so the sum is at
    // least 1 (q_c x the largest under a power of 100 would underflow to 0).
    double sum = 0.0;
    for (int ch = 0; ch < C; ++ch) {
        const double* qc = q + ch * (N + 2);
        for (int r = 0; r < n; ++r) sum += double(h.power(float(qc[r])));
        if (qc[N] > 0.0) sum += double(h.power(float(qc[N])));
        if (qc[N + 1] > 0.0) sum += double(h.power(float(qc[N + 1])));
    }
    return float(double(h.power(float(own))) / sum * double(C));
}

}  // namespace nsp::bdpt
