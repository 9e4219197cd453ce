// nsp/estimators/bdpt.hpp: volumetric bidirectional path tracing over a SurfaceScene with full
// null-vertex MIS (THEORY 5.5), grey (one pdf for every channel, as PathEstimator) or per channel
// (SpectralBdptEstimator: every channel's pdfs, channels x strategies in one denominator, THEORY
// 5.3 with 5.5).
//
// A camera subpath and a light subpath are delta-tracked through the scene's media and surfaces
// (the same VertexKernels and interface crossings as estimators/path.hpp). Every real
// vertex stores the density with which its own subpath drew it and the density with which the
// other side would have drawn it, in area measure on surfaces and volume measure in media, each
// with the segment's null-scattering factors: prod P_n(n_j) of the nulls on the segment it was
// drawn along, and mu_bar P_s at a medium vertex (the Tbar and mu_bar(n_j) factors appear in
// every strategy's pdf of a segment and cancel). Strategies (s, t), s light vertices and t camera
// vertices:
// - s = 0: the camera subpath hits an emitter (a surface light, or the lights at infinity);
// - s = 1: next-event estimation from the camera vertex (the scene's light sampler);
// - s >= 2: a connection between light vertex s-1 and camera vertex t-1, its transmittance and its
//   nulls' P_n product by ratio tracking across the media and null interfaces between them;
// - t = 1 (sample(), with the host's Camera): light vertex s-1 connected to the camera and
//   splatted where it appears on the image (light tracing); radiance() leaves it out, and its
//   weights leave it out for every path alike, so they still sum to 1.
// Each is weighted against every other strategy that could have drawn the same path (bdpt::
// strategy_weight). An emissive medium is a light source too (THEORY 5.7): the camera subpath
// collects its emission at every tentative collision (s = 0), NEE also draws a point in the
// volume (s = 1), and light subpaths start there (one half of them when the scene also has
// lights), so connections and light tracing carry it as well; with null-scattering MIS the
// segment technique also draws one point on every piece of a camera segment in an emitting
// medium (PathPdfs::kSegment). Toward point lights, the equiangular strategy draws a vertex on
// every camera segment and connects it by NEE (PathPdfs::kEquiangular).
//
// Policies: bdpt::NullScattering (the paper's full null-scattering MIS) or bdpt::Directional
// (the baseline: direction pdfs and geometry only, the tracking factors left out, as pbrt's BDPT
// weighs medium vertices), the heuristic (mis::Balance or mis::Power), the absorption policy of
// the tracked segments, and MaxDepth, the longest subpath the fixed-size vertex arrays hold (no
// heap allocation in the kernel). Lights at infinity start light subpaths when the scene's
// LightSampler has a BoundingSphere (their rays from a disk outside it; x_0 is then a direction,
// its densities solid angles, and x_1's the disk's per perpendicular area, converted); without one,
// and for DirectionalLight, paths to them are weighted among s = 0 and s = 1 alone. Russian roulette divides the subpaths'
// throughputs as in PathEstimator, but the weights leave it out (the same for every strategy, so
// they still sum to 1; the survival probability of a subpath read backwards is not defined).
// Expected counts (THEORY 5.9): NEE toward the lights runs at a camera vertex with probability
// EstimatorOptions::nee_count and a light subpath on a sample with light_subpath_probability,
// each folded into its strategies' densities in every weight; with a NeeCountLearner as the
// counter every strategy's contribution is recorded, so both can be learned from a pilot.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <new>
#include <type_traits>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../geometry.hpp"
#include "../camera.hpp"
#include "../media/emissive.hpp"
#include "../channel_tracking.hpp"
#include "../equiangular.hpp"
#include "../mis.hpp"
#include "../path_pdf.hpp"
#include "../surface_scene.hpp"
#include "../options.hpp"
#include "../path_state.hpp"
#include "../recorder.hpp"
#include "../vertex.hpp"
#include "emission.hpp"
#include "scene_walk.hpp"

namespace nsp {

namespace bdpt {

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

/// What one vertex of a subpath is.
enum class VertexKind : std::uint8_t { Camera, Light, Surface, Medium };

/// A real vertex of a camera or light subpath; P the type of its densities (PdfType).
template <SpectralMode S, class P = float>
struct Vertex {
    Vec3 p{0.f};
    Vec3 ng{0.f, 0.f, 1.f}, ns{0.f, 0.f, 1.f};  ///< normals (surfaces; a light vertex: its emitting normal)
    Vec3 wo{0.f, 0.f, 1.f};                      ///< the subpath's direction of travel arriving at p
    typename S::Spectrum beta = S::Spectrum::Zero();  ///< the subpath's throughput up to p
    P pdf_fwd = broadcast<P>(0.f);   ///< density of p drawn by its own subpath (area / volume measure, with N and E)
    P pdf_rev = broadcast<P>(0.f);   ///< density of p drawn from the other side, from the next vertex of its subpath
    P nulls_in = broadcast<P>(1.f);  ///< N: prod P_n of the segment arriving at p (1 under Directional)
    P event = broadcast<P>(1.f);     ///< E: mu_bar P_s at a medium vertex (1 on surfaces and under Directional)
    /// The equiangular strategy's density of p (a medium vertex; 0 elsewhere and when it is off),
    /// drawn from the camera side's vertex before it: a camera subpath's previous vertex, a light
    /// subpath's next one (kept for y_1 alone, the only light vertex that can be x_1).
    P eq = broadcast<P>(0.f);
    /// Per channel: every channel's factor that all strategies share (Tbar_c, the nulls' mu_bar_c)
    /// over the subpath up to p, relative to the largest.
    [[no_unique_address]] GammaOf<P> gamma = unit_gamma<P>();
    int material = -1, medium = -1, medium_front = -1, medium_back = -1, light = -1;
    VertexKind kind = VertexKind::Camera;
    bool delta = false;           ///< a delta lobe was sampled here: no connection may end at p
    bool delta_position = false;  ///< a point light or a directional light's direction: no path hits it
    bool at_infinity = false;     ///< a light at infinity: x_0 is a direction (solid angle), p its ray's origin

    /// The medium a ray leaving p along w travels in.
    int medium_toward(const Vec3& w) const noexcept {
        if (kind != VertexKind::Surface) return medium;
        return glm::dot(w, ng) > 0.f ? medium_front : medium_back;
    }
};

/// The vertices of one strategy's path, for an observer (BdptEstimator::radiance_observed): the
/// light subpath's first s vertices (s >= 2), the camera subpath's first t (z_0 the camera; for
/// s = 0 the emitter hit is not among them), and x_0's position (the light point; for a light at
/// infinity, `x0_at_infinity`, the light subpath's ray origin outside the scene or else the last
/// camera vertex's).
template <SpectralMode S, class P = float>
struct PathVertices {
    const Vertex<S, P>* light = nullptr;
    int s = 0;
    const Vertex<S, P>* camera = nullptr;
    int t = 0;
    Vec3 x0{0.f};
    bool x0_at_infinity = false;
};

/// Converts a solid-angle density at `from` toward vertex `to` into `to`'s measure: |n . w| / d^2
/// on a surface or light, 1 / d^2 in a medium; 0 for a point light and the camera. A light at
/// infinity is a direction: its measure is the solid angle, pdf_dir unchanged (0 for a directional
/// light's one direction).
template <SpectralMode S, class P>
float to_vertex_measure(float pdf_dir, const Vec3& from, const Vertex<S, P>& to) noexcept {
    if (to.at_infinity) return to.delta_position ? 0.f : pdf_dir;
    const Vec3 d = to.p - from;
    const float d2 = glm::dot(d, d);
    if (!(d2 > 0.f)) return 0.f;
    switch (to.kind) {
        case VertexKind::Medium: return pdf_dir / d2;
        case VertexKind::Surface: return pdf_dir * std::abs(glm::dot(to.ng, d)) / (d2 * std::sqrt(d2));
        case VertexKind::Light:
            return to.delta_position ? 0.f : pdf_dir * std::abs(glm::dot(to.ng, d)) / (d2 * std::sqrt(d2));
        default: return 0.f;
    }
}

/// Converts the density of a ray from a light at infinity, per area perpendicular to its direction
/// w, into the measure of the vertex `to` it reaches: x |ng . w| on a surface, x 1 in a medium
/// (the ray's length is the tracking's own measure); 0 for a light and the camera.
template <SpectralMode S, class P>
float from_infinity_measure(float pdf_perpendicular, const Vec3& w, const Vertex<S, P>& to) noexcept {
    switch (to.kind) {
        case VertexKind::Medium: return pdf_perpendicular;
        case VertexKind::Surface: return pdf_perpendicular * std::abs(glm::dot(to.ng, w));
        default: return 0.f;
    }
}

/// The medium a light subpath starting at p along w is in (-3 where the host's hits cannot be
/// used): the side of the first surface ahead that the ray leaves, else of the first surface
/// behind it that faces p, else, where no surface lies on the whole line, the scene's unbounded
/// region: the camera's medium when the geometry has no surface that bounds a medium (nsp::NoSurfaces, nsp::EmptySpace: media
/// in empty space fill it), vacuum otherwise. The camera side's walks see the same media, so both
/// sides of every connection agree.
template <class Sc>
int light_start_medium(const Sc& sc, const Vec3& p, const Vec3& w) noexcept {
    const SurfaceHit ahead = sc.geometry.intersect(Ray{p, w}, kInf);
    if (!detail::usable_hit(sc, ahead)) return -3;
    if (ahead.found()) return ahead.medium_left(w);
    const SurfaceHit behind = sc.geometry.intersect(Ray{p, -w}, kInf);
    if (!detail::usable_hit(sc, behind)) return -3;
    if (behind.found()) return behind.medium_left(-w);
    if constexpr (is_empty_space_v<typename Sc::GeometryType>) return sc.camera_medium;
    else return -1;
}

}  // namespace bdpt

/// Volumetric BDPT (see the header comment): MIS policy Mis, heuristic H, absorption policy A of
/// the tracked segments, subpaths of at most MaxDepth real vertices (EstimatorOptions::max_depth
/// must not exceed it). radiance() has PathEstimator's signature, so a host's pixel loop calls
/// either the same way. Channel axis Ch: bdpt::Grey (one pdf, exact for Mono and grey media, as
/// PathEstimator) or channels::SpectralMis (every channel's pdfs: SpectralBdptEstimator).
template <bdpt::MisPolicy Mis = bdpt::NullScattering, mis::CombiningHeuristic H = mis::Balance,
          AbsorptionPolicy A = absorption::Weight, int MaxDepth = 32, bdpt::ChannelAxis Ch = bdpt::Grey>
class BdptEstimator {
    static_assert(MaxDepth >= 1 && MaxDepth <= 256, "nsp::BdptEstimator: MaxDepth must lie in [1, 256]");
    static_assert(std::same_as<Ch, bdpt::Grey> || Mis::null_pdfs,
                  "nsp::BdptEstimator: per-channel pdfs are null-scattering pdfs (bdpt::NullScattering); "
                  "bdpt::Directional has none");

public:
    using MisType = Mis;
    using HeuristicType = H;
    using Absorption = A;
    using Channels = Ch;
    static constexpr bool kPerChannel = !std::same_as<Ch, bdpt::Grey>;
    static constexpr int kMaxDepth = MaxDepth;
    static constexpr int kMaxPath = 2 * MaxDepth + 3;  ///< most vertices of a path x_0..x_k
    using Pdfs = bdpt::PathPdfs<kMaxPath>;  ///< the grey densities (PdfsFor: a scene's)
    /// The densities of a path through scenes of spectral mode S: one float or one per channel.
    template <SpectralMode S>
    using PdfsFor = bdpt::PathPdfs<kMaxPath, bdpt::PdfType<Ch, S>>;
    template <SpectralMode S>
    using VertexFor = bdpt::Vertex<S, bdpt::PdfType<Ch, S>>;

    /// EstimatorOptions' defaults with max_depth = MaxDepth (theirs, 1000, would not fit).
    static EstimatorOptions default_options() noexcept {
        EstimatorOptions o;
        o.max_depth = MaxDepth;
        return o;
    }

    /// Throws InvalidArgument on invalid roulette settings (see EstimatorOptions) or a max_depth
    /// above MaxDepth (the vertex arrays' size).
    /// `light_subpath_probability` in (0, 1]: the expected number of light subpaths per sample
    /// (THEORY 5.9). Each sample traces one with that probability; every strategy that uses it
    /// (connections, light tracing) then has that probability times its density in every weight
    /// and divides by it, so the estimate stays unbiased for any value. 1 (the default): always.
    /// Throws InvalidArgument on a value outside (0, 1].
    explicit BdptEstimator(EstimatorOptions opts = default_options(), H heuristic = H{},
                           float light_subpath_probability = 1.f)
        : kernels_(checked(opts), heuristic), light_probability_(light_subpath_probability) {
        if (!(light_probability_ > 0.f && light_probability_ <= 1.f))
            detail::fail("BdptEstimator light_subpath_probability = ", light_probability_,
                         " is not allowed: it must lie in (0, 1]");
    }

    float light_subpath_probability() const noexcept { return light_probability_; }

    const EstimatorOptions& options() const noexcept { return kernels_.options(); }

    /// An estimate of the radiance arriving at `ray.o` from direction -ray.d: every strategy
    /// (s, t >= 2) of one camera subpath and one light subpath, MIS-weighted. A camera ray that is
    /// not usable_ray gives 0 and Status::InvalidInput. Never throws.
    template <class Sc, UniformRng R, LookupCounter C>
    RadianceSample<typename Sc::Spectral> radiance(const Sc& scene, const Ray& camera_ray,
                                                   const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                   C& counter) const {
        NoObserver none;
        return radiance_observed(scene, camera_ray, lambda, rng, counter, none);
    }

    /// radiance(), calling `observe(s, t, contribution, weight, pdfs, vertices)` for every
    /// strategy's sample: its unweighted contribution (weight 1), the MIS weight it got, the path's
    /// densities (bdpt::PathPdfs) and its vertices (bdpt::PathVertices). What the tests measure
    /// each strategy alone with.
    template <class Sc, UniformRng R, LookupCounter C, class Observe>
    RadianceSample<typename Sc::Spectral> radiance_observed(const Sc& sc, const Ray& camera_ray,
                                                            const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                            C& counter, Observe& observe) const {
        NoSplat none;
        return trace(sc, camera_ray, static_cast<const NoCamera*>(nullptr), lambda, rng, counter, none, observe);
    }

    /// One sample of the image of `camera` at image coordinates (u, v), with light tracing (t = 1)
    /// among the strategies: returns the camera ray's MIS-weighted estimate for the pixel at
    /// (u, v), and calls `splat(u', v', value)` for each light-tracing contribution, which the host
    /// adds to the pixel at (u', v'). Every pixel's value is then the sum of its samples' returns
    /// and of the splats it received, divided by its own number of samples (the same for every
    /// pixel: the light subpaths are one per camera sample over the whole image). A (u, v) whose
    /// camera ray is not usable_ray (NaN) gives 0 and Status::InvalidInput. Never throws.
    template <class Sc, Camera Cam, UniformRng R, LookupCounter C, class Splat>
    RadianceSample<typename Sc::Spectral> sample(const Sc& sc, const Cam& camera, float u, float v,
                                                 const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                                                 Splat&& splat) const {
        NoObserver none;
        return trace(sc, camera.ray(u, v), &camera, lambda, rng, counter, splat, none);
    }

    /// sample(), with the observer of radiance_observed (t = 1 included: its contribution is the
    /// splat's value before weighting).
    template <class Sc, Camera Cam, UniformRng R, LookupCounter C, class Splat, class Observe>
    RadianceSample<typename Sc::Spectral> sample_observed(const Sc& sc, const Cam& camera, float u, float v,
                                                          const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                          C& counter, Splat&& splat, Observe& observe) const {
        return trace(sc, camera.ray(u, v), &camera, lambda, rng, counter, splat, observe);
    }

private:
    struct NoObserver {
        template <class... T>
        void operator()(const T&...) const noexcept {}
    };
    using NoSplat = NoObserver;
    struct NoCamera {};

    template <class Sc, class Cam, UniformRng R, LookupCounter C, class Splat, class Observe>
    RadianceSample<typename Sc::Spectral> trace(const Sc& sc, const Ray& camera_ray, const Cam* cam,
                                                const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                                                Splat& splat, Observe& observe) const;
    /// One sample of trace: its shared state and its strategies as named parts (defined below).
    template <class Sc, class Cam, class R, class C, class Splat, class Observe>
    struct BdptSample;
    using Kernels = VertexKernels<std::conditional_t<Mis::null_pdfs, strategy::NullScatteringMis, strategy::DirectionalMis>,
                                  H, A>;

    static EstimatorOptions checked(EstimatorOptions o) {
        validate(o);
        if (o.max_depth > MaxDepth)
            detail::fail("BdptEstimator max_depth = ", o.max_depth, " is not allowed: it must be <= ", MaxDepth,
                         " (the estimator's MaxDepth template argument, the size of its vertex arrays)");
        return o;
    }

    template <class Sc>
    static constexpr void check_scene() {
        static_assert(is_surface_scene_v<Sc>, "nsp::BdptEstimator renders a SurfaceScene (NoSurfaces for media alone)");
        if constexpr (!kPerChannel)
            static_assert(!is_per_channel_majorant_v<typename Sc::MajorantType, typename Sc::MediumType>,
                          "nsp::BdptEstimator<..., bdpt::Grey> drives every channel with one pdf and needs a grey "
                          "majorant (channels::SpectralMis: one per channel)");

        static_assert(std::remove_cvref_t<decltype(std::declval<Sc>().lights)>::bidirectional_ready(),
                      "nsp::BdptEstimator: every light model must start light subpaths (EmittingLight: "
                      "sample_emission, emission_pdf) or lie at infinity / be a delta light");
    }

    template <class Sc>
    using VertexT = VertexFor<typename Sc::Spectral>;

    /// A walk's emission callback that does nothing (light subpaths, media without emission).
    struct NoEmission {};

    /// Calls the walk's emission callback at every tentative collision of a tracked piece: `nulls`
    /// the segment's null product before the piece, `along` the segment technique's normaliser
    /// on it (0: the technique does not run).
    template <class Sc, class F>
    struct EmissionVisitor {
        static constexpr bool enabled = true;
        F& f;
        const VertexT<Sc>* path;
        int count, medium;
        const Ray& ray;
        const typename Sc::Spectrum& beta;
        float nulls, pdf_dir, along;
        void operator()(float t, const Coefficients<typename Sc::Spectral>& c, float mu_bar,
                        const typename Sc::Spectrum& w, float null_pdf_product) const {
            f(path, count, medium, ray.at(t), c, mu_bar, mu_bar, typename Sc::Spectrum(beta * w),
              Mis::null_pdfs ? nulls * null_pdf_product : 1.f, pdf_dir, bdpt::NoGamma{}, nulls, along);
        }
    };

    /// Per channel: every channel's null probabilities P_n,c over a tracked piece and its event
    /// density mu_bar_c P_s,c at the piece's real collision, from the coefficients at each
    /// tentative collision (all but a scattering end are nulls).
    template <SpectralMode S>
    struct ChannelNullVisit {
        static constexpr bool enabled = true;
        using Spec = typename S::Spectrum;
        detail::DoubleSpectrum<Spec>* nulls;  // the product of the nulls before the last collision
        Spec* last_null;                      // the last collision's P_n,c, should it be a null
        Spec* last_event;                     // its mu_bar_c P_s,c, should it scatter
        Spec* last_tbar;                      // its Tbar_c since the collision before
        bool* pending;
        template <class State>
        void operator()(float, const Coefficients<S>&, const Spec& mu, const Spec& tbar, const State&,
                        const ChannelEventDensities<Spec>& d) const {
            if (*pending) *nulls *= last_null->template cast<double>();
            *last_null = (mu > 0.f).select(d.null / mu, 0.f);
            *last_event = d.scatter;
            *last_tbar = tbar;
            *pending = true;
        }
    };

    /// Per channel: the walk's visitor of a tracked piece, ChannelNullVisit's bookkeeping and, in an
    /// emissive medium, the collision estimator at every tentative collision y (THEORY 5.7 with
    /// 5.3): the throughput up to y over the sampling channel's density of reaching it, every
    /// channel's null product before y and the subpath's shared factors up to y.
    template <class Sc, class F>
    struct ChannelWalkVisit {
        static constexpr bool enabled = true;
        using S = typename Sc::Spectral;
        using Spec = typename S::Spectrum;
        ChannelNullVisit<S> null_visit;
        F* emission;  // the walk's emission callback (NoEmission: none)
        const VertexT<Sc>* path;
        int count, medium, channel;
        const Ray& ray;
        const Spec& beta0;  // the throughput where the segment started
        const Spec& nulls;  // the segment's null product before this piece
        float pdf_dir;
        float along;  // the segment technique's normaliser on this piece (0: it does not run)
        template <class State>
        void operator()(float t, const Coefficients<S>& k, const Spec& mu, const Spec& tbar, const State& st,
                        const ChannelEventDensities<Spec>& d) const {
            null_visit(t, k, mu, tbar, st, d);
            if constexpr (!std::is_same_v<F, NoEmission>) {
                const float p_here = st.uni[channel] * tbar[channel];
                if (!(p_here > 0.f)) return;
                (*emission)(path, count, medium, ray.at(t), k, mu, mu[channel], Spec(beta0 * st.f * tbar / p_here),
                            Spec(nulls * null_visit.nulls->template cast<float>()), pdf_dir,
                            relative_to_largest<Spec>(path[count - 1].gamma * st.nee * tbar), nulls, along);
            }
        }
    };

    /// Every channel's factors shared by all strategies, relative to the largest (0 where none is
    /// positive).
    template <class Spec>
    static Spec relative_to_largest(const Spec& g) noexcept {
        const float m = g.maxCoeff();
        return m > 0.f && std::isfinite(m) ? Spec(g / m) : Spec(Spec::Zero());
    }

    /// Where the equiangular strategy draws its vertices (THEORY 5.4 in 5.5): on the part of a
    /// camera segment's ray inside the box around every medium, aimed at the point lights (the
    /// light sampler's targets whose lights are delta: LightSampler::equiangular_point, by their
    /// selection probabilities renormalised over them). Lights a path can hit have tracking's
    /// hits and the light subpaths besides NEE; a point light has NEE and the light subpaths alone.
    struct EqRegion {
        Box box;
        float total = 0.f;  ///< the point lights' equiangular_pmf summed

        /// The technique's density per unit length at distance t along `r` (0 outside the box).
        template <class Sc>
        float density(const Sc& sc, const Ray& r, float t) const noexcept {
            const Interval in = box.clip(r, 0.f, kInf);
            if (in.empty()) return 0.f;
            float p = 0.f;
            for (int k = 0; k < sc.lights.equiangular_count(); ++k)
                if (sc.lights.equiangular_is_delta(k))
                    p += sc.lights.equiangular_pmf(k) * EquiangularSampler(r, sc.lights.equiangular_point(k), in.t0, in.t1).pdf(t);
            return p / total;
        }
        /// The same at distance d from o toward direction w.
        template <class Sc>
        float density(const Sc& sc, const Vec3& o, const Vec3& w, float d) const noexcept {
            return density(sc, Ray{o, w}, d);
        }
        /// A distance along `r` in `in`, the ray's part in the box (a point light by u_pick, then
        /// its equiangular distance by u), with the mixture's density there.
        template <class Sc>
        DistanceSample sample(const Sc& sc, const Ray& r, const Interval& in, float u_pick, float u) const noexcept {
            int pick = -1;
            float cdf = 0.f;
            for (int k = 0; k < sc.lights.equiangular_count(); ++k) {
                if (!sc.lights.equiangular_is_delta(k)) continue;
                pick = k;  // the last point light takes what rounding leaves
                cdf += sc.lights.equiangular_pmf(k) / total;
                if (u_pick < cdf) break;
            }
            if (pick < 0) return {};
            DistanceSample ds = EquiangularSampler(r, sc.lights.equiangular_point(pick), in.t0, in.t1).sample(u);
            if (ds.pdf > 0.f) ds.pdf = density(sc, r, ds.t);
            return ds;
        }
    };

    /// A walk's segment or piece callback that does nothing (light subpaths, the technique off).
    struct NoSegment {};

    /// What the segment technique needs of a light subpath's first segment, y_0 (in an emitting
    /// medium) to y_1: the P_n product of the nulls on its pieces after the first (y_0's own, seen
    /// from y_1), where that first piece ends (the first surface from y_0, kInf: none), and y_1's
    /// direction density toward y_0 (arriving from y_2) in y_0's measure.
    template <class Sc>
    struct FirstSegment {
        bdpt::PdfType<Ch, typename Sc::Spectral> later_nulls = bdpt::broadcast<bdpt::PdfType<Ch, typename Sc::Spectral>>(1.f);
        float first_piece_end = kInf;
        float y0_reverse = 0.f;
    };

    /// Tracks a subpath from path[count - 1] (see trace). With `eq` (the equiangular strategy on),
    /// stores its densities: a camera subpath's (`camera_side`) at each medium vertex, a light
    /// subpath's at y_1; `on_segment(path, count, ray, medium, pdf_dir, beta)` runs at the start of
    /// every segment, before it is tracked; `on_piece(path, count, ray, medium, t_max, pdf_dir,
    /// beta, nulls, gamma)` before every piece in a medium is tracked, returning the segment
    /// technique's normaliser on it (which `on_emission` then gets). `first`, if given, receives
    /// the first segment's FirstSegment.
    template <class Sc, UniformRng R, LookupCounter C, class OnHit, class OnEmission = NoEmission,
              class OnSegment = NoSegment, class OnPiece = NoSegment>
    int walk(const Sc& sc, VertexT<Sc>* path, int count, int max_vertices, Ray ray, int medium, float pdf_dir,
             typename Sc::Spectrum beta, const typename Sc::Spectral::Wavelengths& lambda, int channel, R& rng,
             C& counter, OnHit on_hit, Status& status, const EqRegion* eq, bool camera_side,
             OnEmission on_emission = {}, OnSegment on_segment = {}, OnPiece on_piece = {},
             FirstSegment<Sc>* first = nullptr) const;

    Kernels kernels_;
    float light_probability_ = 1.f;
};

// ---------------------------------------------------------------------------------------------

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, UniformRng R, LookupCounter C, class OnHit, class OnEmission, class OnSegment, class OnPiece>
int BdptEstimator<Mis, H, A, MaxDepth, Ch>::walk(const Sc& sc, VertexT<Sc>* path, int count, int max_vertices,
                                                 Ray ray, int medium, float pdf_dir, typename Sc::Spectrum beta,
                                                 const typename Sc::Spectral::Wavelengths& lambda, int channel, R& rng,
                                                 C& counter, OnHit on_hit, Status& status, const EqRegion* eq,
                                                 bool camera_side, OnEmission on_emission, OnSegment on_segment,
                                                 OnPiece on_piece, FirstSegment<Sc>* first) const {
    using namespace bdpt;
    using V = VertexT<Sc>;
    using S = typename Sc::Spectral;
    using Spectrum = typename Sc::Spectrum;
    using P = PdfType<Ch, S>;
    const float beta_scale = float(beta.abs().maxCoeff());
    P nulls = broadcast<P>(1.f);
    int crossings = 0;
    // Per channel: the segment's state since the last real vertex (f_c and p_c of channel c's
    // tracking, and in its nee slot the factor every strategy shares, prod mu_bar_c(n_j) Tbar_c:
    // ratio tracking's pdf of the nulls, which the tracking kernel keeps there as NEE's
    // alternative, times the real vertex's Tbar_c, multiplied in where it scatters), and the
    // throughput where the segment started (THEORY 5.3 with 5.5).
    using State = std::conditional_t<kPerChannel, ChannelPathState<S>, NoGamma>;
    [[maybe_unused]] State st{};
    [[maybe_unused]] Spectrum beta0 = beta;
    if constexpr (kPerChannel) st.nee = Spectrum::Ones();
    // Per channel: the product of the subpath's forward densities (the shared factors apart),
    // relative to the largest channel's: with the vertex's gamma, every channel's density of the
    // subpath, for roulette on the one-sample spectral MIS estimate of its throughput.
    [[maybe_unused]] P prefix = broadcast<P>(1.f);
    // The subpath's shared factors up to the segment's start, and to where it is now.
    auto gamma_here = [&]() {
        if constexpr (kPerChannel) return relative_to_largest<Spectrum>(path[count - 1].gamma * st.nee);
        else return NoGamma{};
    };
    bool segment_start = true;
    while (count < max_vertices) {
        if constexpr (!std::is_same_v<OnSegment, NoSegment>) {
            if (segment_start) on_segment(path, count, ray, medium, pdf_dir, beta);
        }
        segment_start = false;
        const SurfaceHit hit = sc.geometry.intersect(ray, kInf);
        if (!detail::usable_hit(sc, hit)) {
            status = Status::InvalidInput;
            return count;
        }
        if (first && count == 1 && crossings == 0) first->first_piece_end = hit.t;
        V v;
        bool scattered = false;
        // The segment technique's normaliser on this piece (0: it does not run here).
        float along = 0.f;
        (void)along;
        if constexpr (!std::is_same_v<OnPiece, NoSegment>) {
            if (sc.has_medium(medium)) along = on_piece(path, count, ray, medium, hit.t, pdf_dir, beta, nulls, gamma_here());
        }
        if constexpr (kPerChannel) {
            if (sc.has_medium(medium)) {
                const auto& m = sc.media[std::size_t(medium)];
                detail::DoubleSpectrum<Spectrum> piece_nulls = detail::DoubleSpectrum<Spectrum>::Ones();
                Spectrum last_null = Spectrum::Ones(), last_event = Spectrum::Ones(), last_tbar = Spectrum::Ones();
                bool pending = false;
                const ChannelTrack seg = track_channels_delta_visiting<Ch, A>(
                    m.medium, m.majorant, ray, hit.t, lambda, channel, st, true, rng, counter,
                    ChannelWalkVisit<Sc, OnEmission>{{&piece_nulls, &last_null, &last_event, &last_tbar, &pending},
                                                     &on_emission, path, count, medium, channel, ray, beta0, nulls,
                                                     pdf_dir, along});
                if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
                    status = fs;
                    return count;
                }
                if (seg.end != SegmentEnd::Scattered && seg.end != SegmentEnd::Passed) return count;  // absorbed, or no pdf left
                if (seg.end == SegmentEnd::Passed && pending) piece_nulls *= last_null.template cast<double>();
                nulls *= piece_nulls.template cast<float>();
                if (first && count == 1 && crossings > 0) first->later_nulls *= piece_nulls.template cast<float>();
                beta = beta0 * st.f / st.uni[channel];
                if (seg.end == SegmentEnd::Scattered) {
                    scattered = true;
                    v.kind = VertexKind::Medium;
                    v.p = ray.at(seg.t);
                    v.medium = medium;
                    v.event = last_event;
                    st.nee *= last_tbar;  // the real vertex's Tbar_c (not a null's: no mu_bar_c)
                }
            }
        } else if (sc.has_medium(medium)) {  // grey: one pdf for every channel
            const auto& m = sc.media[std::size_t(medium)];
            DeltaTrack<typename Sc::Spectral> seg;
            if constexpr (!std::is_same_v<OnEmission, NoEmission>) {
                // The collision estimator of volume emission: every tentative collision, with the
                // throughput and null product of the nulls before it (THEORY 5.7).
                seg = kernels_.track_visiting(
                    m.medium, m.majorant, ray, hit.t, lambda, rng, counter,
                    EmissionVisitor<Sc, OnEmission>{on_emission, path, count, medium, ray, beta, nulls, pdf_dir, along});
            } else {
                seg = kernels_.track(m.medium, m.majorant, ray, hit.t, lambda, rng, counter);
            }
            if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
                status = fs;
                return count;
            }
            beta *= seg.weight;
            if constexpr (Mis::null_pdfs) {
                nulls *= seg.null_pdf_product;
                if (first && count == 1 && crossings > 0) first->later_nulls *= seg.null_pdf_product;
            }
            if (seg.end == SegmentEnd::Scattered) {
                scattered = true;
                v.kind = VertexKind::Medium;
                v.p = ray.at(seg.t);
                v.medium = medium;
                if constexpr (Mis::null_pdfs) v.event = seg.event_density;
            } else if (seg.end != SegmentEnd::Passed) {
                return count;  // absorbed
            }
        }
        if (!scattered) {
            if (!hit.found()) {
                on_hit(path, count, hit, ray, nulls, beta, gamma_here());  // the lights at infinity
                return count;
            }
            if (hit.light >= 0) on_hit(path, count, hit, ray, nulls, beta, gamma_here());
            if (detail::crosses(sc, hit)) {
                if (++crossings > detail::kMaxInterfaceCrossings) {
                    status = Status::InvalidInput;
                    return count;
                }
                medium = hit.medium_entered(ray.d);
                ray.o = hit.p;
                continue;
            }
            if (hit.material < 0 || sc.materials.passes_through(hit.material)) return count;  // an emitter alone
            v.kind = VertexKind::Surface;
            v.p = hit.p;
            v.ng = hit.ng;
            v.ns = hit.ns;
            v.material = hit.material;
            v.medium_front = hit.medium_front;
            v.medium_back = hit.medium_back;
        }
        V& prev = path[count - 1];
        v.wo = ray.d;
        v.beta = beta;
        v.nulls_in = nulls;
        // From the camera: its own density of the ray (light tracing), or a stand-in of 1 for it,
        // a factor of every strategy with t >= 2 (the equiangular one too), so it cancels.
        const float pd = prev.kind == VertexKind::Camera && !(pdf_dir > 0.f) ? 1.f : pdf_dir;
        if (prev.at_infinity) {
            v.pdf_fwd = from_infinity_measure(pd, ray.d, v) * nulls * v.event;
        } else {
            const float g = to_vertex_measure(pd, prev.p, v);
            v.pdf_fwd = g * nulls * v.event;
            if (camera_side && eq && v.kind == VertexKind::Medium)
                v.eq = broadcast<P>(g * eq->density(sc, prev.p, ray.d, glm::length(v.p - prev.p)));
        }
        if constexpr (kPerChannel) v.gamma = gamma_here();
        path[count] = v;
        V& cur = path[count++];
        if (count >= max_vertices) return count;
        // Roulette on the throughput relative to the subpath's start (a light subpath starts at
        // Le / pdf, not 1). Per channel on the estimate the one-sample MIS over channels makes of
        // it, f / sum_c' q_c' p_c' = beta p_c / sum_c' q_c' p_c' (q_c' = 1 / C), as
        // SpectralPathEstimator's roulette: on beta = f / p_c alone, the sampling channel's, the
        // chromatic cloud under a sky (nsp_room, C1) had 1.2x the variance.
        Spectrum rr_beta = beta;
        if constexpr (kPerChannel) {
            prefix = relative_to_largest<Spectrum>(prefix * cur.pdf_fwd);
            const Spectrum pc = prefix * cur.gamma;
            const float mean = pc.mean();
            if (pc[channel] > 0.f && mean > 0.f) rr_beta *= pc[channel] / mean;
        }
        const float q = kernels_.survival(count - 1, rr_beta / (beta_scale > 0.f ? beta_scale : 1.f));
        if (q < 1.f) {
            if (!(rng.uniform() < q)) return count;
            beta /= q;
        }
        const detail::SceneVertex sv{cur.material, cur.medium, cur.ns};
        const float u1 = rng.uniform(), u2 = rng.uniform();
        const auto next = detail::sample_vertex(sc, sv, ray.d, u1, u2, lambda);
        if (!(next.pdf > 0.f)) return count;
        cur.delta = next.delta;
        // The density with which the other side, arriving along -next.wi, draws prev from cur.
        const float rev = next.delta ? next.pdf : detail::eval_vertex(sc, sv, -next.wi, -ray.d, lambda).pdf;
        const float g_rev = to_vertex_measure(rev, cur.p, prev);
        prev.pdf_rev = g_rev * nulls * prev.event;
        if (first && count == 2) first->y0_reverse = g_rev;
        if (!camera_side && eq && count == 3 && prev.kind == VertexKind::Medium) {  // y_1, drawn from y_2
            const Vec3 d = prev.p - cur.p;
            const float len = glm::length(d);
            prev.eq = broadcast<P>(len > 0.f ? g_rev * eq->density(sc, cur.p, d / len, len) : 0.f);
        }
        beta *= next.value / next.pdf;
        if (!(beta != 0.f).any()) return count;
        if (cur.kind == VertexKind::Surface) medium = cur.medium_toward(next.wi);
        pdf_dir = next.pdf;
        nulls = broadcast<P>(1.f);
        if constexpr (kPerChannel) {
            beta0 = beta;
            st = State{};
            st.nee = Spectrum::Ones();
        }
        crossings = 0;
        ray = Ray{cur.p, next.wi};
        segment_start = true;
    }
    return count;
}

/// One sample of trace: the state its strategies share (the scene, the sample's wavelengths and
/// random numbers, both subpaths, the path's densities, the estimate) and each strategy family
/// as a named part. trace calls the parts in the order their random numbers are drawn.
template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
struct BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample {
    static constexpr bool kLightTracing = !std::is_same_v<Cam, NoCamera>;
    static constexpr bool kEmissive = EmissiveMedium<typename Sc::MediumType>;
    using Spectrum = typename Sc::Spectrum;
    using V = VertexT<Sc>;
    using P = bdpt::PdfType<Ch, typename Sc::Spectral>;
    using PathPdfsT = PdfsFor<typename Sc::Spectral>;
    using GammaT = bdpt::GammaOf<P>;
    static constexpr int kEq = PathPdfsT::kEquiangular;
    static constexpr int kSeg = PathPdfsT::kSegment;

    const BdptEstimator& est;
    const Sc& sc;
    const Cam* cam;
    const typename Sc::Spectral::Wavelengths& lambda;
    R& rng;
    C& counter;
    Splat& splat;
    Observe& observe;
    V* const camera;  // z_0 .. z_{depth+1}
    V* const light;   // y_0 .. y_{depth-1}, y_depth (light tracing)
    const int depth = est.kernels_.options().max_depth;
    Spectrum L = Spectrum::Zero();
    Status status = Status::Ok;
    PathPdfsT pdfs;
    EqRegion eq_region;
    const EqRegion* eq = nullptr;  // the equiangular strategy's region (null: off)
    int channel = 0;               // per channel: the sample's sampling channel
    // A light subpath is traced with probability light_probability_; it starts in the emitting
    // volume with probability q_volume_share, at a light otherwise (both kinds: one half each);
    // every density of a light subpath's start carries both.
    const bool has_volume = kEmissive && sc.select_emission(0.5f) >= 0;
    // Both carry the light subpath's expected count (THEORY 5.9): a start density times it is the
    // density of a light subpath starting there per sample.
    const float q_volume_share = has_volume ? (sc.lights.has_emitters() ? 0.5f : 1.f) : 0.f;
    const float q_volume = est.light_probability_ * q_volume_share;
    const float q_lights = est.light_probability_ * (1.f - q_volume_share);
    // The segment technique (THEORY 5.7 in 5.5): with null-scattering MIS (directional MIS has no
    // distance pdfs to weigh it against tracking by) in emitting media, the option on.
    const bool seg_on = kEmissive && Mis::null_pdfs && est.kernels_.options().emission_along_segments;
    const float seg_count = est.kernels_.options().emission_segment_count;
    const float nee_count = est.kernels_.options().nee_count;

    // The subpaths' lengths, and what the strategies need of the light subpath's start.
    int nc = 0;
    int nl = 0;
    float nee_y0 = 0.f;         // NEE's density of y_0 from y_1 (with its count at a light)
    float eq_nee_y0 = 0.f;      // the same without the count (the equiangular strategy's; 0 in the volume)
    float emit_y0 = 0.f;        // the light subpath's density of y_0
    bool volume_start = true;  // y_0 lies in the emitting volume (else on a light)
    // The segment technique's density of y_0 (in the volume) drawn from y_1, without y_1's
    // direction density (which depends on where x_2 is), and y_1's from y_2 (s >= 3).
    P seg_y0_unit = bdpt::broadcast<P>(0.f);
    FirstSegment<Sc> first_segment;

    BdptSample(const BdptEstimator& e, const Sc& scene, const Cam* c, const typename Sc::Spectral::Wavelengths& lam,
               R& r, C& cnt, Splat& spl, Observe& obs, V* camera_vertices, V* light_vertices)
        : est(e), sc(scene), cam(c), lambda(lam), rng(r), counter(cnt), splat(spl), observe(obs),
          camera(camera_vertices), light(light_vertices) {
        pdfs.light_tracing = kLightTracing;
        // The equiangular strategy: with null-scattering MIS (directional MIS has no distance pdfs
        // to weigh it against tracking by), the option on, a light with a target and a medium.
        if constexpr (Mis::null_pdfs) {
            for (int k = 0; k < sc.lights.equiangular_count(); ++k)
                if (sc.lights.equiangular_is_delta(k)) eq_region.total += sc.lights.equiangular_pmf(k);
            if (est.kernels_.options().bdpt_equiangular && eq_region.total > 0.f && !sc.media.empty()) {
                eq_region.box = sc.media[0].medium.bounds();
                for (const auto& m : sc.media) {
                    const Box b = m.medium.bounds();
                    eq_region.box.lo = glm::min(eq_region.box.lo, b.lo);
                    eq_region.box.hi = glm::max(eq_region.box.hi, b.hi);
                }
                eq = &eq_region;
            }
        }
        // Per channel: the sample's sampling channel, chosen uniformly (THEORY 5.3). Its light
        // subpath, connections and splats use the same channel, so the one-sample weights of every
        // pixel's strategies share one denominator.
        if constexpr (kPerChannel) {
            constexpr int kChannels = int(Spectrum::SizeAtCompileTime);
            channel = std::min(int(rng.uniform() * float(kChannels)), kChannels - 1);
            pdfs.channel = channel;
        }
    }
    BdptSample(const BdptSample&) = delete;
    BdptSample& operator=(const BdptSample&) = delete;

    /// The sample's estimate: L, or 0 and Status::NonFinite where it is not finite.
    RadianceSample<typename Sc::Spectral> result() const {
        if (!all_finite(L)) return {Spectrum::Zero(), Status::NonFinite};
        return {L, status};
    }

    // ---- The path's densities and the estimate ------------------------------------------------

    /// The equiangular strategy's density of `to` drawn from `from` with direction pdf pdf_dir
    /// there (0 off, and where `to` is no medium vertex).
    P eq_from(const Vec3& from, float pdf_dir, const V& to) const {
        using namespace bdpt;
        if (!eq || to.kind != VertexKind::Medium) return broadcast<P>(0.f);
        const Vec3 d = to.p - from;
        const float len = glm::length(d);
        if (!(len > 0.f)) return broadcast<P>(0.f);
        return broadcast<P>(to_vertex_measure(pdf_dir, from, to) * eq->density(sc, from, d / len, len));
    }

    /// The weight of strategy s for the path in p (per channel: its factor of the sampling
    /// channel's throughput).
    auto weight_of(const PathPdfsT& p, int s) const {
        using namespace bdpt;
        if constexpr (kPerChannel) return channel_strategy_weight(est.kernels_.heuristic(), p, s);
        else return strategy_weight(est.kernels_.heuristic(), p, s);
    }

    /// The segment technique's density of x_0 = y drawn from x_1 on y's piece: the direction
    /// density at x_1 in y's measure (g), the nulls of the pieces before y's, p_V(y) / W with W the
    /// normaliser `along`.
    P seg_density(float g, const P& nulls_before, float p_v, float along) const {
        using namespace bdpt;
        if (!seg_on) return broadcast<P>(0.f);
        return nulls_before * (g * segment_density(est.kernels_.options(), p_v, along));
    }

    /// A BdptRecorder (NeeCountLearner) sees every strategy's contribution with the path's pdfs
    /// summed by count group: s = 0 (and NEE toward the volume, `volume_x0`) at count 1, NEE toward
    /// a light at nee_count, s >= 2 and t = 1 at the light subpath probability (THEORY 5.9).
    /// Per channel the sums run over channels x strategies, each channel's weighed by its
    /// selection probability (the one-sample denominator, THEORY 5.3 with 5.9).
    void record(int s, const Spectrum& f, const PathPdfsT& p, bool volume_x0, bool splatted) {
        using namespace bdpt;
        if constexpr (BdptRecorder<C>) {
            const int n = strategy_count(p);
            double p_fixed = 0.0, p_nee = 0.0, p_light = 0.0, own = 0.0;
            auto add_group = [&](const double* q, double selection) {
                // The equiangular strategy (count 1) and the segment technique (its own count).
                p_fixed += selection * (q[0] + q[kEq] + q[kSeg]);
                if (n > 1) (volume_x0 ? p_fixed : p_nee) += selection * q[1];
                for (int r = 2; r < n; ++r) p_light += selection * q[r];
            };
            if constexpr (kPerChannel) {
                constexpr int kChannels = int(Spectrum::SizeAtCompileTime);
                double q[kChannels * PathPdfsT::kSlots];
                if (!channel_strategy_pdfs(p, q)) return;
                for (int ch = 0; ch < kChannels; ++ch) add_group(q + ch * PathPdfsT::kSlots, 1.0 / kChannels);
                own = q[p.channel * PathPdfsT::kSlots + s];
            } else {
                double q[PathPdfsT::kSlots];
                if (!strategy_pdfs(p, q)) return;
                add_group(q, 1.0);
                own = q[s];
            }
            const BdptTechnique group = s == 0 || s == kEq || s == kSeg ? BdptTechnique::Fixed
                                        : s == 1 ? (volume_x0 ? BdptTechnique::Fixed : BdptTechnique::Nee)
                                                 : BdptTechnique::Light;
            detail::record_bdpt(counter, float(double(f.mean()) * own), float(p_fixed),
                                float(p_nee / double(nee_count)), float(p_light / double(est.light_probability_)),
                                nee_count, est.light_probability_, group,
                                splatted);
        } else {
            (void)s, (void)f, (void)p, (void)volume_x0, (void)splatted;
        }
    }

    /// Adds strategy s's contribution f (t camera vertices, x_0 at `x0`) to L with its weight.
    void add(int s, int t, const Spectrum& f, const PathPdfsT& p, const Vec3& x0, bool x0_at_infinity = false,
             bool volume_x0 = false) {
        using namespace bdpt;
        const float w = weight_of(p, s);
        record(s, f, p, volume_x0, false);
        // The equiangular strategy's vertices are s = 1's, the segment technique's s = 0's.
        const int sv = s == kEq ? 1 : s == kSeg ? 0 : s;
        observe(s, t, f, w, p,
                PathVertices<typename Sc::Spectral, P>{light, sv, camera, sv == 0 ? t - 1 : t, x0, x0_at_infinity});
        L += f * w;
    }

    /// The BSDF or phase function at vertex v.
    auto eval_at(const V& v, const Vec3& wo, const Vec3& wi) const {
        return detail::eval_vertex(sc, detail::SceneVertex{v.material, v.medium, v.ns}, wo, wi, lambda);
    }

    /// Fills pdfs with the path of k + 1 vertices made of light[0..s-1] (x_0..x_{s-1}) and
    /// camera[0..nz-1] (x_k..x_{k-nz+1}) from the subpaths' stored densities; the caller then sets
    /// x_0's and the densities that its connection changes.
    void gather(int s, int nz, int k) {
        using namespace bdpt;
        pdfs.k = k;
        pdfs.eq = broadcast<P>(0.f);
        pdfs.seg = broadcast<P>(0.f);
        pdfs.eq_nee = 0.f;
        for (int i = 0; i < s; ++i) {
            pdfs.from_light[i] = light[i].pdf_fwd;
            pdfs.from_camera[i] = light[i].pdf_rev;
            pdfs.connectible[i] = !light[i].delta;
        }
        for (int j = 0; j < nz; ++j) {
            const int i = k - j;
            pdfs.from_camera[i] = camera[j].pdf_fwd;
            pdfs.from_light[i] = camera[j].pdf_rev;
            pdfs.connectible[i] = !camera[j].delta;
        }
        pdfs.connectible[0] = true;
    }

    // ---- Shadow walks -------------------------------------------------------------------------

    /// A shadow ray's (a connection's) transmittance through the scene, ratio-tracked: its
    /// throughput (per channel f_lambda / p_c*), its nulls' P_n product and, per channel, the
    /// factor every strategy of the path shares over it (prod mu_bar_c(n_j) Tbar_c).
    struct Shadow {
        Status status = Status::Ok;
        Spectrum tr = Spectrum::Zero();
        P nulls = bdpt::broadcast<P>(1.f);
        GammaT gamma = bdpt::unit_gamma<P>();
    };

    /// One piece of a shadow walk (ratio tracking through one medium), grey or per channel.
    auto shadow_piece(int m, const Ray& r, float t_max, const Spectrum& f) {
        const auto& med = sc.media[std::size_t(m)];
        if constexpr (kPerChannel)
            return detail::channel_shadow_piece<Ch, A>(med.medium, med.majorant, r, t_max, lambda, channel, f, true, rng,
                                                       counter);
        else
            return (void)f, detail::grey_shadow_piece(est.kernels_, med.medium, med.majorant, r, t_max, lambda, rng,
                                                      counter);
    }

    /// The shadow walk along r up to `distance` from medium `start`. `end_medium`, if given,
    /// receives the medium the ray ends in.
    Shadow shadow(const Ray& r, float distance, int start, int* end_medium = nullptr) {
        using namespace bdpt;
        Shadow out;
        const auto sh = detail::walk_shadow<P>(sc, r, start, WalkEnd{distance}, pieces());
        out.status = sh.status;
        if (sh.status != Status::Ok || !sh.reached) return out;
        if (end_medium) *end_medium = sh.end_medium;
        if constexpr (kPerChannel) {
            // A sampling channel's density below float's range beside another's: its weight is 0.
            if (!(sh.f != 0.f).any() || !(sh.nee[channel] > 0.f)) return out;
            out.tr = sh.f / sh.nee[channel];
            out.nulls = (sh.nee > 0.f).select(sh.uni / sh.nee, 0.f);
            out.gamma = relative_to_largest<Spectrum>(sh.nee);
        } else {
            out.tr = sh.f;
            out.nulls = Mis::null_pdfs ? sh.uni : 1.f;
        }
        return out;
    }

    /// shadow_piece as the callable walk_shadow takes.
    auto pieces() {
        return [this](int m, const Ray& r, float t_max, const Spectrum& f) { return shadow_piece(m, r, t_max, f); };
    }

    /// A shadow ray toward a point drawn in emitting medium `target` (NEE toward the volume): its
    /// throughput, nulls and shared factors as `shadow`'s, whether it reached the point inside
    /// `target`, the point's piece (the point is last.at(t_last)) and, with the segment technique
    /// on, the P_n of the nulls on the pieces before the point's and the technique's normaliser W
    /// on the point's piece.
    struct EmissionShadowT {
        Status status = Status::Ok;
        bool reached = false;
        Spectrum tr = Spectrum::Zero();
        P nulls = bdpt::broadcast<P>(1.f);
        P nulls_before = bdpt::broadcast<P>(1.f);
        GammaT gamma = bdpt::unit_gamma<P>();
        Ray last{};
        float t_last = 0.f;
        float along = 0.f;
    };
    EmissionShadowT shadow_to_emission(const Ray& r, float distance, int start, int target) {
        EmissionShadowT out;
        if constexpr (!kEmissive) {
            (void)r, (void)distance, (void)start, (void)target;
        } else {
            const auto sh = detail::walk_shadow<P>(sc, r, start, WalkEnd{distance, target, false, seg_on}, pieces());
            out.status = sh.status;
            if (sh.status != Status::Ok || !sh.reached || !(sh.f != 0.f).any()) return out;
            if constexpr (kPerChannel) {
                if (!(sh.nee[channel] > 0.f)) return out;
                out.tr = sh.f / sh.nee[channel];
                out.nulls = (sh.nee > 0.f).select(sh.uni / sh.nee, 0.f);
                // sh.seg is uni of the pieces before the point's times nee of its own.
                out.nulls_before = (sh.nee > 0.f).select(sh.seg / sh.nee, 0.f);
                out.gamma = relative_to_largest<Spectrum>(sh.nee);
            } else {
                out.tr = sh.f;
                out.nulls = Mis::null_pdfs ? sh.uni : 1.f;
                out.nulls_before = Mis::null_pdfs ? sh.seg : 1.f;
            }
            out.reached = true;
            out.last = sh.last;
            out.t_last = sh.t_last;
            out.along = sh.along;
        }
        return out;
    }

    /// Transmittance of a connection a -> b through the scene, with its nulls' P_n product and
    /// shared factors (its work the light subpath's).
    Spectrum transmit(const V& a, const V& b, P& nulls, GammaT& gamma) {
        const Vec3 d = b.p - a.p;
        const float dist = glm::length(d);
        if (!(dist > 0.f)) return Spectrum::Zero();
        const Vec3 w = d / dist;
        const double before = detail::recorder_work(counter);
        const Shadow sh = shadow(Ray{a.p, w}, dist, a.medium_toward(w));
        detail::record_light_walk(counter, before);
        if (sh.status != Status::Ok) {
            status = sh.status;
            return Spectrum::Zero();
        }
        nulls = sh.nulls;
        gamma = sh.gamma;
        return sh.tr;
    }

    /// The shared factors of a path made of pieces (per channel), relative to the largest.
    template <class... G>
    auto path_gamma(const G&... g) const {
        if constexpr (kPerChannel) return relative_to_largest<Spectrum>((... * g));
        else return bdpt::NoGamma{};
    }

    // ---- The camera subpath and the strategies that run while it is tracked -----------------

    /// Tracks the camera subpath from camera_ray; s = 0 (hit_emitter, emission_collision), the
    /// equiangular strategy and the segment technique run inside the walk as it goes.
    void trace_camera_subpath(const Ray& camera_ray) {
        using namespace bdpt;
        camera[0] = V{};
        camera[0].kind = VertexKind::Camera;
        camera[0].p = camera_ray.o;
        camera[0].beta = Spectrum::Ones();
        camera[0].medium = sc.camera_medium;
        if constexpr (kPerChannel) camera[0].gamma = Spectrum::Ones();
        float camera_pdf = 0.f;  // the camera's density of the ray's direction (light tracing), else 0
        if constexpr (kLightTracing) camera_pdf = cam->pdf_dir(camera_ray.d);
        auto on_hit = [this](V* path, int count, const SurfaceHit& hit, const Ray& ray, const P& nulls,
                             const Spectrum& beta, const auto& gamma) {
            hit_emitter(path, count, hit, ray, nulls, beta, gamma);
        };
        auto on_segment = [this](V* path, int count, const Ray& ray, int medium, float pdf_dir, const Spectrum& beta) {
            equiangular(path, count, ray, medium, pdf_dir, beta);
        };
        if constexpr (kEmissive) {
            auto on_emission = [this](const V* path, int count, int medium, const Vec3& y,
                                      const Coefficients<typename Sc::Spectral>& c, const P& mu_bar, float mu_sample,
                                      const Spectrum& beta, const P& nulls, float pdf_dir, const auto& gamma,
                                      const P& nulls_before, float along) {
                emission_collision(path, count, medium, y, c, mu_bar, mu_sample, beta, nulls, pdf_dir, gamma,
                                   nulls_before, along);
            };
            auto on_piece = [this](V* path, int count, const Ray& ray, int medium, float t_max, float pdf_dir,
                                   const Spectrum& beta, const P& nulls_before, const auto& gamma) -> float {
                return segment(path, count, ray, medium, t_max, pdf_dir, beta, nulls_before, gamma);
            };
            nc = est.walk(sc, camera, 1, depth + 2, camera_ray, sc.camera_medium, camera_pdf, Spectrum::Ones(), lambda,
                          channel, rng, counter, on_hit, status, eq, true, on_emission, on_segment, on_piece);
        } else {
            nc = est.walk(sc, camera, 1, depth + 2, camera_ray, sc.camera_medium, camera_pdf, Spectrum::Ones(), lambda,
                          channel, rng, counter, on_hit, status, eq, true, NoEmission{}, on_segment);
        }
    }

    /// s = 0: the camera subpath reaches an emitter after camera[0..t-2]; and the lights at
    /// infinity.
    template <class G>
    void hit_emitter(V* path, int count, const SurfaceHit& hit, const Ray& ray, const P& nulls, const Spectrum& beta,
                     const G& gamma) {
        const int t = count + 1;  // the emitter is z_{t-1}
        if (t - 2 > depth) return;
        const V& z = path[count - 1];  // the vertex the segment left (x_1)
        if (!hit.found()) {
            for (const int i : sc.lights.infinite())
                hit_one_emitter(t, z, hit, ray, nulls, beta, gamma, i, sc.lights.emitted(i, ray.d, lambda), kInf);
        } else {
            hit_one_emitter(t, z, hit, ray, nulls, beta, gamma, hit.light, sc.lights.emitted(hit.light, ray.d, lambda),
                            hit.t);
        }
    }

    /// s = 0 for one light: its emission Le toward the camera subpath's vertex z = x_1, at
    /// distance `dist` (kInf: a light at infinity).
    template <class G>
    void hit_one_emitter(int t, const V& z, const SurfaceHit& hit, const Ray& ray, const P& nulls,
                         const Spectrum& beta, const G& gamma, int light_index, const Spectrum& Le, float dist) {
        using namespace bdpt;
        if (!(Le != 0.f).any()) return;
        const Spectrum f = beta * Le;
        if constexpr (kPerChannel) pdfs.gamma = gamma;
        else (void)gamma;
        if (t == 2) {  // the camera sees the emitter: the only strategy
            pdfs.k = 1;
            // Per channel its nulls' P_n,c still weigh the channels; grey, 1 (one strategy).
            if constexpr (kPerChannel) pdfs.from_camera[0] = nulls;
            else pdfs.from_camera[0] = 1.f;
            pdfs.nee = pdfs.emit = 0.f;
            pdfs.seg = broadcast<P>(0.f);
            add(0, 2, f, pdfs, std::isfinite(dist) ? hit.p : z.p, !std::isfinite(dist));
            return;
        }
        gather(0, t - 1, t - 1);  // camera[0..t-2]; the emitter is x_0
        const Vec3 w = ray.d;  // from x_1 toward x_0
        const float pdf_dir_z = z.kind == VertexKind::Camera ? 0.f : eval_at(z, z.wo, w).pdf;
        if (std::isfinite(dist)) {
            const Vec3 d = hit.p - z.p;
            const float d2 = glm::dot(d, d);
            const EmissionDensity e = sc.lights.emission_pdf(light_index, hit.p, -w);
            const float cos0 = std::abs(glm::dot(hit.ng, w));
            pdfs.from_camera[0] = (z.delta ? 1.f : pdf_dir_z) * cos0 / d2 * nulls;
            pdfs.emit = q_lights * e.pdf_pos;
            pdfs.eq_nee = sc.lights.pdf(light_index, z.p, w) * cos0 / d2;
            pdfs.nee = nee_count * pdfs.eq_nee;
            pdfs.from_light[1] = to_vertex_measure(e.pdf_dir, hit.p, z) * nulls * z.event;
        } else {  // x_0 is the direction w; light subpaths (if any) reach z along -w
            const EmissionDensity e = sc.lights.emission_pdf(light_index, z.p, -w);
            pdfs.from_camera[0] = (z.delta ? 1.f : pdf_dir_z) * nulls;
            pdfs.emit = q_lights * e.pdf_pos;
            pdfs.eq_nee = sc.lights.pdf(light_index, z.p, w);
            pdfs.nee = nee_count * pdfs.eq_nee;
            pdfs.from_light[1] = from_infinity_measure(e.pdf_dir, -w, z) * nulls * z.event;
        }
        pdfs.eq = z.eq;
        // z's own density from the light side: from x_1 toward x_2, arriving along -w.
        if (t >= 4) {
            const V& z2 = camera[t - 3];  // x_2
            const float pd = z.delta ? 1.f : eval_at(z, -w, -z.wo).pdf;
            pdfs.from_light[2] = to_vertex_measure(pd, z.p, z2) * z.nulls_in * z2.event;
        }
        add(0, t, f, pdfs, std::isfinite(dist) ? hit.p : z.p, !std::isfinite(dist));
    }

    /// The densities of the path made of the camera subpath camera[0..count-1] and x_0 = y in
    /// emitting medium `medium` (the collision estimator's and the segment technique's paths): y
    /// reached from x_1 = camera[count - 1] with direction density pdf_dir, `nulls` the P_n of
    /// the segment's nulls before y, `nulls_before` those of the pieces before y's, mu_bar the
    /// majorant at y, `along` the segment technique's W on y's piece, `gamma` (per channel) the
    /// shared factors up to y. False where y is x_1 itself (a flight of length 0: no direction).
    template <class G>
    bool emission_path_pdfs(int count, int medium, const Vec3& y, const P& nulls, const P& mu_bar, float pdf_dir,
                            const P& nulls_before, float along, const G& gamma) {
        using namespace bdpt;
        if constexpr (!kEmissive) {
            (void)count, (void)medium, (void)y, (void)nulls, (void)mu_bar, (void)pdf_dir, (void)nulls_before,
                (void)along, (void)gamma;
            return false;
        } else {
            const float p_y = sc.media[std::size_t(medium)].medium.emission_pdf(y);
            if constexpr (kPerChannel) pdfs.gamma = gamma;
            else (void)gamma;
            const int t = count + 1;
            if (t == 2) {  // seen from the camera: the collision estimator and the segment technique
                pdfs.k = 1;
                // Relative to the camera's density of the ray and 1 / d^2, the same for both.
                pdfs.from_camera[0] = nulls * mu_bar;
                pdfs.nee = pdfs.emit = 0.f;
                pdfs.seg = seg_density(1.f, nulls_before, p_y, along);
                return true;
            }
            const V& z = camera[count - 1];  // x_1
            const Vec3 d = y - z.p;
            const float d2 = glm::dot(d, d);
            if (!(d2 > 0.f)) return false;
            gather(0, t - 1, t - 1);
            const float p_v = sc.emission_selection_pdf(medium) * p_y;
            pdfs.from_camera[0] = pdf_dir / d2 * nulls * mu_bar;
            pdfs.seg = seg_density(pdf_dir / d2, nulls_before, p_y, along);
            pdfs.nee = p_v;
            pdfs.emit = q_volume * p_v;
            pdfs.from_light[1] = to_vertex_measure(kInv4Pi, y, z) * nulls * z.event;
            if (t >= 4) {
                const V& z2 = camera[count - 2];  // x_2
                const float pd = z.delta ? 1.f : eval_at(z, -(d / std::sqrt(d2)), -z.wo).pdf;
                pdfs.from_light[2] = to_vertex_measure(pd, z.p, z2) * z.nulls_in * z2.event;
            }
            return true;
        }
    }

    /// s = 0 in an emissive medium: the camera subpath's tentative collision at y, after
    /// camera[0..count-1], collects mu_a L_e / mu_bar (the collision estimator); as a path ending
    /// at y its camera-side density is the direction pdf / d^2 x the nulls' P_n x mu_bar(y).
    /// `mu_bar` the majorant at y (per channel: every channel's), `mu_sample` the sampling
    /// channel's, `beta` the throughput up to y over the density of reaching it, `gamma` (per
    /// channel) the shared factors up to y, `nulls_before` the nulls' P_n on the segment's pieces
    /// before y's and `along` the segment technique's normaliser on y's piece.
    template <class G>
    void emission_collision(const V* path, int count, int medium, const Vec3& y,
                            const Coefficients<typename Sc::Spectral>& c, const P& mu_bar, float mu_sample,
                            const Spectrum& beta, const P& nulls, float pdf_dir, const G& gamma, const P& nulls_before,
                            float along) {
        if constexpr (kEmissive) {
            const int t = count + 1;
            if (t - 2 > depth || !(c.sigma_a > 0.f).any() || !(mu_sample > 0.f)) return;
            const auto& m = sc.media[std::size_t(medium)].medium;
            const Spectrum le = m.emission(y, lambda);
            if (!(le > 0.f).any()) return;
            const Spectrum f = beta * c.sigma_a * le / mu_sample;
            (void)path;  // camera[], which emission_path_pdfs reads
            if (emission_path_pdfs(count, medium, y, nulls, mu_bar, pdf_dir, nulls_before, along, gamma))
                add(0, t, f, pdfs, y, false, true);
        } else {
            (void)path, (void)count, (void)medium, (void)y, (void)c, (void)mu_bar, (void)mu_sample, (void)beta,
                (void)nulls, (void)pdf_dir, (void)gamma, (void)nulls_before, (void)along;
        }
    }

    /// The equiangular strategy (THEORY 5.4 in 5.5) on the camera segment from z = path[count - 1]
    /// along `ray` (in `medium`, throughput `beta` past z's direction sample): x drawn on the ray's
    /// part in the media's box by equiangular sampling toward the lights' targets, the nulls before
    /// it ratio-tracked, stored as z_t-1 = path[count] (the walk writes its own next vertex there
    /// afterwards) and connected to the lights by NEE.
    void equiangular(V* path, int count, const Ray& ray, int medium, float pdf_dir, const Spectrum& beta) {
        using namespace bdpt;
        const int t = count + 1;
        if (!eq || t - 1 > depth) return;
        const V& z = path[count - 1];
        const Interval in = eq->box.clip(ray, 0.f, kInf);
        if (in.empty()) return;
        const float u_pick = rng.uniform(), u = rng.uniform();
        const DistanceSample ds = eq->sample(sc, ray, in, u_pick, u);
        if (!(ds.pdf > 0.f && ds.t > 0.f)) return;
        const double before = detail::recorder_work(counter);
        int at = -1;
        const Shadow sh = shadow(ray, ds.t, medium, &at);
        detail::record_shadow_walk(counter, before, false);
        if (sh.status != Status::Ok) status = sh.status;
        if (sh.status != Status::Ok || !(sh.tr != 0.f).any() || !sc.has_medium(at)) return;
        const auto& m = sc.media[std::size_t(at)];
        const auto c = detail::lookup_untracked(m.medium, m.majorant, ray, ds.t, lambda, counter);
        if (!c) {
            status = Status::Rejected;
            return;
        }
        if (!(c->k.sigma_s > 0.f).any()) return;
        V& x = path[count];
        x = V{};
        x.kind = VertexKind::Medium;
        x.p = ray.at(ds.t);
        x.medium = at;
        x.wo = ray.d;
        x.beta = beta * sh.tr * c->k.sigma_s / ds.pdf;
        x.nulls_in = sh.nulls;
        // Tracking's event density mu_bar P_s at x (per channel, every channel's).
        if constexpr (kPerChannel)
            x.event = channel_event_densities<A, typename Sc::Spectral>(c->k, majorants<P>(c->mu)).scatter;
        else
            x.event = c->mu * event_probabilities<A>(c->k, c->mu).scatter;
        const float pd = z.kind == VertexKind::Camera && !(pdf_dir > 0.f) ? 1.f : pdf_dir;  // as the walk's
        const float g = to_vertex_measure(pd, z.p, x);
        x.pdf_fwd = g * sh.nulls * x.event;
        x.eq = broadcast<P>(g * ds.pdf);
        if constexpr (kPerChannel) x.gamma = path_gamma(z.gamma, sh.gamma);
        if ((x.beta != 0.f).any()) light_nee(t, true);
    }

    /// The segment technique (THEORY 5.7 in 5.5) on a camera segment's piece in emitting medium
    /// `medium` (from z = path[count - 1] along `ray` up to t_max; `pdf_dir` z's direction density,
    /// `beta` the throughput at the piece's start, `nulls_before` the P_n of the segment's nulls
    /// before it, `gamma` the shared factors up to it): x_0 drawn in proportion to the medium's
    /// power grid along the piece (with the count EstimatorOptions::emission_segment_count), the
    /// nulls before it ratio-tracked, mu_a L_e collected there. Returns the piece's normaliser W,
    /// which the collision estimator's weights on the piece need (0: the technique does not run).
    template <class G>
    float segment(V* path, int count, const Ray& ray, int medium, float t_max, float pdf_dir, const Spectrum& beta,
                  const P& nulls_before, const G& gamma) {
        using namespace bdpt;
        if constexpr (kEmissive) {
            (void)path;  // camera[], which emission_path_pdfs reads
            const int t = count + 1;
            if (!seg_on || t - 2 > depth) return 0.f;
            const auto& m = sc.media[std::size_t(medium)];
            const float along = m.medium.emission_along(ray, 0.f, t_max);
            if (!(along > 0.f) || !draw_technique(seg_count, rng)) return along;
            // Its work is a fixed technique's to the learner: it runs whatever the learned counts.
            const double before = detail::recorder_work(counter);
            const DistanceSample ds = m.medium.sample_emission_along(ray, 0.f, t_max, along, rng.uniform());
            if (!(ds.pdf > 0.f && ds.t > 0.f)) return along;
            const Shadow sh = shadow(ray, ds.t, medium);
            if (sh.status != Status::Ok) status = sh.status;
            const auto c = sh.status == Status::Ok && (sh.tr != 0.f).any()
                               ? detail::lookup_untracked(m.medium, m.majorant, ray, ds.t, lambda, counter)
                               : std::nullopt;
            detail::record_shadow_walk(counter, before, false);
            if (sh.status != Status::Ok || !(sh.tr != 0.f).any()) return along;
            if (!c) {
                status = Status::Rejected;
                return along;
            }
            if (!(c->k.sigma_a > 0.f).any()) return along;
            const Vec3 y = ray.at(ds.t);
            const Spectrum le = m.medium.emission(y, lambda);
            if (!(le > 0.f).any()) return along;
            const Spectrum f = beta * sh.tr * c->k.sigma_a * le / (seg_count * ds.pdf);
            if (emission_path_pdfs(count, medium, y, P(nulls_before * sh.nulls), majorants<P>(c->mu), pdf_dir,
                                   nulls_before, along, path_gamma(gamma, sh.gamma)))
                add(kSeg, t, f, pdfs, y, false, true);
            return along;
        } else {
            (void)path, (void)count, (void)ray, (void)medium, (void)t_max, (void)pdf_dir, (void)beta,
                (void)nulls_before, (void)gamma;
            return 0.f;
        }
    }

    // ---- s = 1: next-event estimation -------------------------------------------------------

    /// s = 1 from camera vertex z = camera[t - 1] toward the lights (THEORY 5.9: drawn with the
    /// NEE count), or, `from_eq`, the equiangular strategy's NEE from its vertex there, which
    /// always runs: no count.
    void light_nee(int t, bool from_eq) {
        using namespace bdpt;
        const V& z = camera[t - 1];
        const float count = from_eq ? 1.f : nee_count;
        const double before = detail::recorder_work(counter);
        const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
        const SampledLight<typename Sc::Spectral> ls = sc.lights.sample(z.p, u0, u1, u2, lambda);
        if (!(ls.sample.pdf > 0.f)) return;
        const Vec3 w = ls.sample.wi;
        const auto fz = eval_at(z, z.wo, w);
        if (!(fz.value != 0.f).any()) return;
        V y0;
        y0.kind = VertexKind::Light;
        y0.delta_position = ls.sample.delta;
        const bool at_infinity = !std::isfinite(ls.sample.distance);
        y0.p = at_infinity ? z.p : z.p + ls.sample.distance * w;
        const Shadow sh = shadow(Ray{z.p, w}, ls.sample.distance, z.medium_toward(w));
        detail::record_shadow_walk(counter, before, !from_eq);
        if (sh.status != Status::Ok) status = sh.status;
        if (sh.status != Status::Ok || !(sh.tr != 0.f).any()) return;
        const P& nulls = sh.nulls;
        const Spectrum f = z.beta * fz.value * sh.tr * ls.sample.radiance / (count * ls.sample.pdf);
        gather(0, t, t);  // camera[0..t-1]; the light point is x_0
        if constexpr (kPerChannel) pdfs.gamma = path_gamma(z.gamma, sh.gamma);
        const float d2 = ls.sample.distance * ls.sample.distance;
        if (ls.sample.delta) {  // a point or directional light: no path hits it
            pdfs.from_camera[0] = broadcast<P>(0.f);
            pdfs.eq_nee = ls.sample.pdf;
            // Light subpaths from a directional light (given a BoundingSphere) start on the
            // sphere's disk: pdf_pos its delta, pdf_dir per area across w.
            const EmissionDensity e = sc.lights.emission_pdf(ls.light, at_infinity ? z.p : y0.p, -w);
            pdfs.emit = q_lights * e.pdf_pos;
            pdfs.from_light[1] = (at_infinity ? from_infinity_measure(e.pdf_dir, -w, z)
                                              : to_vertex_measure(e.pdf_dir, y0.p, z)) *
                                 nulls * z.event;
        } else if (at_infinity) {
            const EmissionDensity e = sc.lights.emission_pdf(ls.light, z.p, -w);
            pdfs.from_camera[0] = fz.pdf * nulls;
            pdfs.eq_nee = ls.sample.pdf;
            pdfs.emit = q_lights * e.pdf_pos;
            pdfs.from_light[1] = from_infinity_measure(e.pdf_dir, -w, z) * nulls * z.event;
        } else {
            const EmissionDensity e = sc.lights.emission_pdf(ls.light, y0.p, -w);
            pdfs.from_camera[0] = fz.pdf * e.cos / d2 * nulls;
            pdfs.eq_nee = ls.sample.pdf * e.cos / d2;
            pdfs.emit = q_lights * e.pdf_pos;
            pdfs.from_light[1] = to_vertex_measure(e.pdf_dir, y0.p, z) * nulls * z.event;
        }
        pdfs.nee = nee_count * pdfs.eq_nee;
        pdfs.eq = z.eq;
        if (t >= 3) {
            const V& z2 = camera[t - 2];
            pdfs.from_light[2] = to_vertex_measure(eval_at(z, w * -1.f, -z.wo).pdf, z.p, z2) * z.nulls_in * z2.event;
        }
        add(from_eq ? kEq : 1, t, f, pdfs, y0.p, at_infinity);
    }

    /// s = 1 toward the emitting volume (THEORY 5.7) from camera vertex z = camera[t - 1]: a point
    /// drawn by the power grids, the shadow walk through every medium up to it.
    void volume_nee(int t) {
        using namespace bdpt;
        if constexpr (kEmissive) {
            const V& z = camera[t - 1];
            if (!has_volume) return;
            const auto e = detail::draw_emission_point(sc, z.p, rng);
            if (!e) return;
            const auto& m = sc.media[std::size_t(e->index)];
            const auto fz = eval_at(z, z.wo, e->wi);
            if (!(fz.value != 0.f).any()) return;
            const EmissionShadowT sh = shadow_to_emission(Ray{z.p, e->wi}, e->dist, z.medium_toward(e->wi), e->index);
            if (sh.status != Status::Ok) status = sh.status;
            if (!(sh.status == Status::Ok && sh.reached && (sh.tr != 0.f).any())) return;
            const auto c = detail::lookup_untracked(m.medium, m.majorant, sh.last, sh.t_last, lambda, counter);
            if (!c) {
                status = Status::Rejected;
                return;
            }
            if (!((c->k.sigma_a > 0.f).any() && majorant_at(c->mu, channel) > 0.f)) return;
            const float p_v = e->select * e->y.pdf;
            const Spectrum f =
                z.beta * fz.value * sh.tr * c->k.sigma_a * m.medium.emission(e->y.p, lambda) / (e->dist2 * p_v);
            const P& nulls = sh.nulls;
            gather(0, t, t);  // camera[0..t-1]; the emission point is x_0
            if constexpr (kPerChannel) pdfs.gamma = path_gamma(z.gamma, sh.gamma);
            pdfs.from_camera[0] = fz.pdf / e->dist2 * nulls * majorants<P>(c->mu);
            pdfs.seg = seg_density(fz.pdf / e->dist2, sh.nulls_before, e->y.pdf, sh.along);
            pdfs.nee = p_v;
            pdfs.emit = q_volume * p_v;
            pdfs.from_light[1] = to_vertex_measure(kInv4Pi, e->y.p, z) * nulls * z.event;
            if (t >= 3) {
                const V& z2 = camera[t - 2];
                pdfs.from_light[2] =
                    to_vertex_measure(eval_at(z, -e->wi, -z.wo).pdf, z.p, z2) * z.nulls_in * z2.event;
            }
            add(1, t, f, pdfs, e->y.p, false, true);
        } else {
            (void)t;
        }
    }

    // ---- The light subpath and the strategies that use it -----------------------------------

    /// The light subpath, traced with probability light_probability_ (THEORY 5.9): from the
    /// emitting volume (light_from_volume) or from a light (light_from_emitter).
    void trace_light_subpath() {
        const int light_vertices = kLightTracing ? depth + 1 : depth;
        const bool traced = draw_technique(est.light_probability_, rng);
        const double light_work_before = detail::recorder_work(counter);
        if (traced && depth >= (kLightTracing ? 1 : 2)) {
            const float uq = q_volume_share > 0.f && q_volume_share < 1.f ? rng.uniform() : 0.f;
            if (q_volume_share > 0.f && uq < q_volume_share) light_from_volume(light_vertices);
            else light_from_emitter(light_vertices);
        }
        if (traced) detail::record_light_walk(counter, light_work_before);
    }

    /// A light subpath of at most light_vertices vertices from a point y_0 drawn in the emitting
    /// volume by the media's power, with y_0's densities for NEE and the segment technique.
    void light_from_volume(int light_vertices) {
        using namespace bdpt;
        if constexpr (kEmissive) {
            const float us = rng.uniform(), u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform(),
                        u3 = rng.uniform(), u4 = rng.uniform(), u5 = rng.uniform();
            const int i = sc.select_emission(us);
            const float select = sc.emission_selection_pdf(i);
            const auto& m = sc.media[std::size_t(i)];
            const VolumeSample yv = m.medium.sample_emission(u0, u1, u2, u3);
            const Vec3 w = uniform_sphere(u4, u5);
            // The point counts only inside medium i's surfaces: the first boundary ahead of it
            // must be one it leaves medium i through (as the camera side's NEE walk checks).
            const int start = light_start_medium(sc, yv.p, w);
            if (start == -3) status = Status::InvalidInput;
            const bool inside = start == i;
            if (!(i >= 0 && select > 0.f && yv.pdf > 0.f && inside)) return;
            const auto c = detail::lookup_untracked(m.medium, m.majorant, Ray{yv.p, w}, 0.f, lambda, counter);
            if (!c) {
                status = Status::Rejected;
                return;
            }
            if (!((c->k.sigma_a > 0.f).any() && majorant_at(c->mu, channel) > 0.f)) return;
            const Spectrum source = c->k.sigma_a * m.medium.emission(yv.p, lambda);
            if (!(source > 0.f).any()) return;
            V& y0 = light[0] = V{};
            y0.kind = VertexKind::Medium;
            y0.p = yv.p;
            y0.medium = i;
            y0.event = majorants<P>(c->mu);  // a tentative collision's density there: mu_bar
            if constexpr (kPerChannel) y0.gamma = Spectrum::Ones();
            emit_y0 = q_volume * select * yv.pdf;
            y0.pdf_fwd = broadcast<P>(emit_y0);
            y0.beta = source / emit_y0;
            nl = est.walk(sc, light, 1, light_vertices, Ray{yv.p, w}, i, kInv4Pi, Spectrum(y0.beta * (4.f * kPi)),
                          lambda, channel, rng, counter, [](auto&&...) {}, status, eq, false, NoEmission{},
                          NoSegment{}, NoSegment{}, seg_on ? &first_segment : nullptr);
            nee_y0 = select * yv.pdf;
            if (seg_on && nl >= 2) {
                // y_0's piece seen from y_1: from the last surface between them (the walk's first
                // piece's end, else y_1) through y_0 to the first surface beyond it.
                const float dist = glm::length(light[1].p - yv.p);
                const SurfaceHit behind = sc.geometry.intersect(Ray{yv.p, -w}, kInf);
                if (!detail::usable_hit(sc, behind)) {
                    status = Status::InvalidInput;
                } else {
                    const float a = std::min(first_segment.first_piece_end, dist);
                    const float b = behind.found() ? behind.t : kInf;
                    const float along = m.medium.emission_along(Ray{yv.p + a * w, -w}, 0.f, a + b);
                    seg_y0_unit = seg_density(1.f, first_segment.later_nulls, yv.pdf, along);
                }
            }
        } else {
            (void)light_vertices;
        }
    }

    /// A light subpath of at most light_vertices vertices from a light's emission sample, with
    /// y_0's densities for NEE (and the equiangular strategy's NEE).
    void light_from_emitter(int light_vertices) {
        using namespace bdpt;
        const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform(),
                    u4 = rng.uniform();
        volume_start = false;
        const EmittedLight<typename Sc::Spectral> e = sc.lights.sample_emission(u0, u1, u2, u3, u4, lambda);
        if (!(e.emission.pdf_pos > 0.f && e.emission.pdf_dir > 0.f && (e.emission.radiance != 0.f).any())) return;
        V& y0 = light[0] = V{};
        y0.kind = VertexKind::Light;
        y0.p = e.emission.p;
        y0.ng = y0.ns = e.emission.n;
        y0.light = e.light;
        y0.delta_position = e.emission.delta_position;
        y0.at_infinity = e.emission.at_infinity;
        emit_y0 = q_lights * e.emission.pdf_pos;
        y0.pdf_fwd = broadcast<P>(emit_y0);
        y0.beta = e.emission.radiance / (q_lights * e.emission.pdf_pos);
        if constexpr (kPerChannel) y0.gamma = Spectrum::Ones();
        const int start = light_start_medium(sc, e.emission.p, e.emission.w);
        if (start == -3) status = Status::InvalidInput;
        else
            nl = est.walk(sc, light, 1, light_vertices, Ray{e.emission.p, e.emission.w}, start, e.emission.pdf_dir,
                          Spectrum(y0.beta * (e.emission.cos / e.emission.pdf_dir)), lambda, channel, rng, counter,
                          [](auto&&...) {}, status, eq, false);
        if (nl >= 2) {
            const Vec3 d = y0.p - light[1].p;
            const float d2 = glm::dot(d, d);
            eq_nee_y0 = y0.delta_position ? sc.lights.selection_pdf(y0.light)  // a point or a direction
                        : y0.at_infinity  ? sc.lights.pdf(y0.light, light[1].p, -e.emission.w)  // solid angle
                                            : sc.lights.pdf(y0.light, light[1].p, d / std::sqrt(d2)) *
                                                  std::abs(glm::dot(y0.ng, d)) / (d2 * std::sqrt(d2));
            nee_y0 = nee_count * eq_nee_y0;
        }
    }

    /// s >= 2: connects every light vertex y = y_{s-1} to camera vertex z = camera[t - 1].
    void connect(int t) {
        using namespace bdpt;
        const V& z = camera[t - 1];
        for (int s = 2; s <= nl && s + t - 2 <= depth; ++s) {
            const V& y = light[s - 1];
            if (y.delta) continue;
            const Vec3 d = z.p - y.p;
            const float d2 = glm::dot(d, d);
            if (!(d2 > 0.f)) continue;
            const Vec3 w = d / std::sqrt(d2);
            const auto fy = eval_at(y, y.wo, w);
            if (!(fy.value != 0.f).any()) continue;
            const auto fz = eval_at(z, z.wo, -w);
            if (!(fz.value != 0.f).any()) continue;
            P nulls = broadcast<P>(1.f);
            GammaT gamma = unit_gamma<P>();
            const Spectrum tr = transmit(y, z, nulls, gamma);
            if (!(tr != 0.f).any()) continue;
            const Spectrum f = y.beta * fy.value * tr * fz.value * z.beta / d2;
            gather(s, t, s + t - 1);
            if constexpr (kPerChannel) pdfs.gamma = path_gamma(y.gamma, gamma, z.gamma);
            pdfs.emit = emit_y0;
            pdfs.nee = nee_y0;
            // The four densities the connection changes.
            pdfs.from_light[s] = to_vertex_measure(fy.pdf, y.p, z) * nulls * z.event;
            pdfs.from_camera[s - 1] = to_vertex_measure(fz.pdf, z.p, y) * nulls * y.event;
            if (t >= 3) {
                const V& z2 = camera[t - 2];
                pdfs.from_light[s + 1] = to_vertex_measure(eval_at(z, w, -z.wo).pdf, z.p, z2) * z.nulls_in * z2.event;
            }
            const V& y2 = light[s - 2];
            const float pd_y2 = eval_at(y, -w, -y.wo).pdf;
            pdfs.from_camera[s - 2] = to_vertex_measure(pd_y2, y.p, y2) * y.nulls_in * y2.event;
            // x_1 = y_1 as the equiangular strategy draws it, from x_2 (z, y_2 toward the connection,
            // or y_2 as its light subpath stored).
            pdfs.eq_nee = eq_nee_y0;
            pdfs.eq = s == 2 ? eq_from(z.p, fz.pdf, y) : s == 3 ? eq_from(y.p, pd_y2, y2) : light[1].eq;
            // x_0 = y_0 as the segment technique draws it from x_1 = y_1, arriving there from x_2
            // (z, or y_2 as the light subpath drew it).
            pdfs.seg = seg_y0_unit * (s == 2 ? to_vertex_measure(pd_y2, y.p, y2) : first_segment.y0_reverse);
            add(s, t, f, pdfs, light[0].p, light[0].at_infinity, volume_start);
        }
    }

    /// t = 1 (light tracing): every light vertex y = y_{s-1} seen by the camera, splatted where it
    /// appears on the image.
    void light_trace() {
        using namespace bdpt;
        if constexpr (kLightTracing) {
            const Vec3 eye = cam->position();
            for (int s = 2; s <= nl && s - 1 <= depth; ++s) {
                const V& y = light[s - 1];
                if (y.delta) continue;
                const Vec3 d = eye - y.p;
                const float d2 = glm::dot(d, d);
                if (!(d2 > 0.f)) continue;
                const Vec3 w = d / std::sqrt(d2);  // from y toward the camera
                float u = 0.f, v = 0.f;
                const float pc = cam->pdf_dir(-w);
                if (!(pc > 0.f) || !cam->raster(-w, u, v)) continue;
                const auto fy = eval_at(y, y.wo, w);
                if (!(fy.value != 0.f).any()) continue;
                V eye_vertex;
                eye_vertex.p = eye;
                P nulls = broadcast<P>(1.f);
                GammaT gamma = unit_gamma<P>();
                const Spectrum tr = transmit(y, eye_vertex, nulls, gamma);
                if (!(tr != 0.f).any()) continue;
                const Spectrum f = y.beta * fy.value * tr * (pc / d2);
                gather(s, 0, s);
                if constexpr (kPerChannel) pdfs.gamma = path_gamma(y.gamma, gamma);
                pdfs.emit = emit_y0;
                pdfs.nee = nee_y0;
                pdfs.from_camera[s - 1] = to_vertex_measure(pc, eye, y) * nulls * y.event;
                const V& y2 = light[s - 2];
                const float pd_y2 = eval_at(y, -w, -y.wo).pdf;
                pdfs.from_camera[s - 2] = to_vertex_measure(pd_y2, y.p, y2) * y.nulls_in * y2.event;
                pdfs.eq_nee = eq_nee_y0;
                pdfs.eq = s == 2 ? eq_from(eye, pc, y) : s == 3 ? eq_from(y.p, pd_y2, y2) : light[1].eq;
                pdfs.seg = seg_y0_unit * (s == 2 ? to_vertex_measure(pd_y2, y.p, y2) : first_segment.y0_reverse);
                const float wt = weight_of(pdfs, s);
                record(s, f, pdfs, volume_start, true);
                observe(s, 1, f, wt, pdfs,
                        PathVertices<typename Sc::Spectral, P>{light, s, camera, 1, light[0].p, light[0].at_infinity});
                const Spectrum value = f * wt;
                if (all_finite(value)) splat(u, v, value);
                else status = Status::NonFinite;
            }
        }
    }
};

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, UniformRng R, LookupCounter C, class Splat, class Observe>
RadianceSample<typename Sc::Spectral> BdptEstimator<Mis, H, A, MaxDepth, Ch>::trace(
    const Sc& sc, const Ray& camera_ray, const Cam* cam, const typename Sc::Spectral::Wavelengths& lambda, R& rng,
    C& counter, Splat& splat, Observe& observe) const {
    check_scene<Sc>();
    using Spectrum = typename Sc::Spectrum;
    using V = VertexT<Sc>;
    if (!usable_ray(camera_ray)) return {Spectrum::Zero(), Status::InvalidInput};
    // The subpaths' vertices, each written whole before it is read: a Vertex is an implicit-
    // lifetime aggregate, so the storage is left as it is instead of 67 vertices being set to
    // their defaults per sample (a fifth of a sample's time where the subpaths are short).
    static_assert(std::is_aggregate_v<V> && std::is_trivially_destructible_v<V>, "implicit-lifetime vertices");
    alignas(V) std::byte camera_storage[sizeof(V) * (MaxDepth + 2)];
    alignas(V) std::byte light_storage[sizeof(V) * (MaxDepth + 1)];
    V* const camera = std::launder(reinterpret_cast<V*>(camera_storage));
    V* const light = std::launder(reinterpret_cast<V*>(light_storage));
    BdptSample<Sc, Cam, R, C, Splat, Observe> run(*this, sc, cam, lambda, rng, counter, splat, observe, camera, light);
    run.trace_camera_subpath(camera_ray);  // s = 0, the equiangular strategy, the segment technique
    run.trace_light_subpath();
    const int depth = run.depth;
    for (int t = 2; t <= std::min(run.nc, depth + 1); ++t) {
        if (camera[t - 1].delta) continue;
        // s = 1 toward a light is drawn with the NEE count (THEORY 5.9: its estimate divides by
        // it, every path's NEE density carries it); toward the volume and s >= 2 always run.
        if (draw_technique(run.nee_count, rng)) run.light_nee(t, false);
        run.volume_nee(t);
        run.connect(t);
    }
    run.light_trace();  // t = 1
    return run.result();
}

/// Volumetric BDPT with per-channel pdfs (THEORY 5.3 with 5.5): each sample tracks its subpaths
/// and connections with one channel chosen uniformly, every channel keeps its own densities of
/// every vertex (its majorant and event probabilities in the nulls' and events' factors), and the
/// heuristic runs over channels x strategies with one denominator. Any majorant (per-channel ones
/// are what it is for), emissive media included.
template <mis::CombiningHeuristic H = mis::Balance, AbsorptionPolicy A = absorption::Weight, int MaxDepth = 32>
using SpectralBdptEstimator = BdptEstimator<bdpt::NullScattering, H, A, MaxDepth, channels::SpectralMis>;

}  // namespace nsp
