// tests/fuzz/fuzz_kernels.cpp: the libFuzzer target of issue 8. It turns arbitrary bytes into a
// spectral mode, a small dense grid medium (values 0, tiny, huge, mixed), a majorant of one of
// 9 types (global / grid / per-channel grid / per-channel, with the four bound policies),
// rays, estimator options and the random numbers themselves, drives the kernels, and aborts on
// any broken invariant (NSP_FUZZ_CHECK, fuzz_input.hpp).
//
// What runs on every input that builds a medium and a majorant within the work budget:
// - the MIS heuristics (Balance, Power) and the weight helpers of estimators/path.hpp;
// - free_flight with a checking callback and a small collision limit;
// - grey majorants: track_delta (Event and Weight, recorded and re-evaluated with
//   delta_segment_log_pdf), track_ratio (recorded, ratio_segment_log_pdf), transmittance_ratio
//   and transmittance_delta;
// - every majorant: track_channels_delta and track_channels_ratio with Independent (Event) and
//   SpectralMis (Weight, with equiangular slots), recorded and re-evaluated with
//   channel_delta_segment_log_pdf; on grey majorants also SpectralTrackingAverage (Event) and
//   SpectralTrackingMax (Weight);
// - one of seven path estimators (a representative subset, see kEstimators below);
// - last (its bytes are read after everything else, so the corpus keeps its meaning): a ray
//   that is not usable_ray (a direction of length 0.5, 1.01 or 2, a zero, NaN or infinite
//   direction, a NaN or infinite origin) or a NaN distance, at every public tracking entry and at
//   both path estimators: each must answer InvalidInput and no estimate (0), never a number;
// - after it, reading no bytes: the trackers under a control (run_controls), decomposition and
//   residual ratio tracking, grey and per channel, and ray marching on the input's medium.
//
// Work is bounded: a case whose majorant optical depth across the medium's box exceeds kBudget
// is skipped, paths are at most 8 real vertices deep, and free_flight's own calls stop after 64
// collisions.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>
#include <vector>

#include <nsp/nsp.hpp>

#include "fuzz_input.hpp"

namespace nsp_fuzz {
namespace {

using namespace nsp;

/// Most majorant optical depth across the medium's box (expected tentative collisions per crossing).
constexpr float kBudget = 256.f;
/// Tolerance of "the weights of one path sum to 1": absolute, about 100 float ulps at 1.
constexpr float kWeightTol = 1e-5f;
/// The smallest positive value among `v` (inf if none; the smallest majorant, for diagnostics).
template <class Spec>
float min_positive(const Spec& v) {
    float m = kInf;
    for (int i = 0; i < v.size(); ++i)
        if (v[i] > 0.f) m = std::min(m, float(v[i]));
    return m;
}

template <class T>
struct Tag {
    using type = T;
};

// ---------------------------------------------------------------------------------------------
// Values

/// A finite value >= 0 (or -0): zero, denormal, tiny, huge, ordinary, or a random one.
float value(Input& in) {
    switch (in.pick(16)) {
        case 0: return 0.f;
        case 1: return 1e-30f;
        case 2: return 1e30f;
        case 3: return 1.f;
        case 4: return 0.5f;
        case 5: return 3.f;
        case 6: return 1e-3f;
        case 7: return 1e3f;
        case 8: return 0x1p-149f;
        case 9: return std::numeric_limits<float>::min();
        case 10: return -0.f;
        case 11: return 1e-20f;
        default: return in.unit() * 4.f;
    }
}

/// A value the constructors must reject.
float bad_value(Input& in) {
    switch (in.pick(5)) {
        case 0: return std::numeric_limits<float>::quiet_NaN();
        case 1: return kInf;
        case 2: return -kInf;
        case 3: return -1.f;
        default: return -1e-30f;
    }
}

/// A pdf ratio in [0, inf].
float ratio(Input& in) {
    switch (in.pick(14)) {
        case 0: return 0.f;
        case 1: return 1.f;
        case 2: return 0x1p-149f;
        case 3: return 1e-30f;
        case 4: return 1e30f;
        case 5: return std::numeric_limits<float>::max();
        case 6: return kInf;
        case 7: return 1e19f;
        case 8: return 1e-19f;
        case 9: return 1.f / std::max(in.unit(), 0x1p-16f);
        default: return in.unit() * 4.f;
    }
}

/// A positive finite pdf or probability factor in (0, max].
float positive(Input& in, float max = std::numeric_limits<float>::max()) {
    float v = ratio(in);
    if (!(v > 0.f) || !std::isfinite(v)) v = 1.f;
    return std::min(v, max);
}

template <SpectralMode S>
typename S::Coefficient coefficient(Input& in) {
    if constexpr (is_hero_v<S>) {
        if (in.flag()) return TabulatedSpectrum::constant(value(in));
        const float nm0 = kLambdaMin + in.unit() * (kLambdaMax - kLambdaMin);
        const float nm1 = nm0 + 1.f + in.unit() * 300.f;
        return TabulatedSpectrum::from_points({nm0, nm1}, {value(in), value(in)});
    } else {
        typename S::Spectrum s;
        for (int c = 0; c < S::channels; ++c) s[c] = value(in);
        return s;
    }
}

template <class Spec>
bool finite_all(const Spec& s) {
    return all_finite(s);
}
template <class Spec>
bool no_nan(const Spec& s) {
    return !s.isNaN().any();
}

// ---------------------------------------------------------------------------------------------
// MIS weights

/// A grey BDPT path's densities from the input: its length, light tracing, each vertex's two
/// densities in [0, inf] and connectibility, NEE's and the light subpaths' densities of x_0.
bdpt::PathPdfs<12> read_path_pdfs(Input& in) {
    bdpt::PathPdfs<12> p;
    p.k = 1 + int(in.pick(11));
    p.light_tracing = in.pick(2) == 1;
    for (int i = 0; i < p.k; ++i) {
        p.from_light[i] = ratio(in);
        p.from_camera[i] = ratio(in);
        p.connectible[i] = in.pick(4) != 0;
    }
    p.nee = ratio(in);
    p.emit = ratio(in);
    return p;
}

/// Every strategy of a BDPT path: the (s, t) ones, the equiangular strategy and the segment technique.
template <class P>
std::vector<int> every_strategy(const bdpt::PathPdfs<12, P>& p) {
    std::vector<int> out;
    for (int s = 0; s < bdpt::strategy_count(p); ++s) out.push_back(s);
    out.push_back(p.kEquiangular);
    out.push_back(p.kSegment);
    return out;
}

template <class H>
void check_heuristic(Input& in, const H& h) {
    g_context = "mis heuristic";
    const float r = ratio(in);
    const float w = h.weight(r), w_inv = h.weight(1.f / r);
    NSP_FUZZ_CHECK(w >= 0.f && w <= 1.f && w_inv >= 0.f && w_inv <= 1.f);
    // weight(r) + weight(1/r) = 1 (mis.hpp) wherever 1/r is a float (not for a denormal r: its
    // inverse overflows, and weight(inf) = 0 is not the weight of the true inverse).
    if (r == 0.f || std::isfinite(1.f / r)) NSP_FUZZ_CHECK(std::abs(w + w_inv - 1.f) <= kWeightTol);

    // Two techniques of one path, unidirectional and NEE (THEORY 5.1, 5.2).
    const float survival = positive(in, 1.f), phase_pdf = positive(in), nulls = positive(in, 1.f);
    const float light_pdf = positive(in);
    const float wu = unidirectional_weight<strategy::NullScatteringMis>(h, survival, phase_pdf, nulls, light_pdf);
    const float wn = next_event_weight<strategy::NullScatteringMis>(h, survival, phase_pdf, nulls, light_pdf);
    NSP_FUZZ_CHECK(std::abs(wu + wn - 1.f) <= kWeightTol);
    const float du = unidirectional_weight<strategy::DirectionalMis>(h, survival, phase_pdf, nulls, light_pdf);
    const float dn = next_event_weight<strategy::DirectionalMis>(h, survival, phase_pdf, nulls, light_pdf);
    NSP_FUZZ_CHECK(std::abs(du + dn - 1.f) <= kWeightTol);

    // Three techniques of one path (THEORY 5.4): the one that sampled it has a pdf > 0.
    const float a = ratio(in), b = ratio(in), c = ratio(in);
    const float wa = equiangular_mis_weight(h, VertexTechnique::TrackNee, a, b, c);
    const float wb = equiangular_mis_weight(h, VertexTechnique::TrackHit, a, b, c);
    const float wc = equiangular_mis_weight(h, VertexTechnique::EquiangularNee, a, b, c);
    for (const float x : {wa, wb, wc}) NSP_FUZZ_CHECK(x >= 0.f && x <= 1.f);
    if (a > 0.f || b > 0.f || c > 0.f) NSP_FUZZ_CHECK(std::abs(wa + wb + wc - 1.f) <= kWeightTol);

    // Emission: the collision estimator, the segment technique and NEE toward the volume (THEORY 5.7).
    const float mu_bar = positive(in), dist2 = positive(in), volume_pdf = positive(in);
    const float segment_pdf = ratio(in);
    const EmissionPdfs ep = emission_pdfs<strategy::NullScatteringMis>(survival, phase_pdf, nulls, mu_bar, segment_pdf,
                                                                       dist2, volume_pdf);
    const float ec = emission_weight(h, EmissionTechnique::Collision, ep);
    const float es = emission_weight(h, EmissionTechnique::Segment, ep);
    const float en = emission_weight(h, EmissionTechnique::Nee, ep);
    for (const float x : {ec, es, en}) NSP_FUZZ_CHECK(x >= 0.f && x <= 1.f);
    if (ep.collision > 0.f || ep.segment > 0.f || ep.nee > 0.f) NSP_FUZZ_CHECK(std::abs(ec + es + en - 1.f) <= kWeightTol);

    // BDPT (THEORY 5.5): the (s, t) strategies of one path (the equiangular one and the segment
    // technique off: weight 0), densities in [0, inf] per vertex, delta vertices, with and without
    // light tracing: every weight in [0, 1], and they sum to 1 where any
    // strategy can draw the path (strategy_pdfs true), to 0 where none can.
    bdpt::PathPdfs<12> p = read_path_pdfs(in);
    double q[bdpt::PathPdfs<12>::kSlots];
    const bool drawable = bdpt::strategy_pdfs(p, q);
    float sum = 0.f;
    for (const int s : every_strategy(p)) {
        const float ws = bdpt::strategy_weight(h, p, s);
        NSP_FUZZ_CHECK(ws >= 0.f && ws <= 1.f);
        sum += ws;
    }
    NSP_FUZZ_CHECK(drawable ? std::abs(sum - 1.f) <= kWeightTol : sum == 0.f);
}

void check_mis(Input& in) {
    check_heuristic(in, mis::Balance{});
    const float betas[] = {1.f, 2.f, 0.5f, 3.f, 10.f, 100.f, 1e-3f, 0.f};
    const float beta = betas[in.pick(8)];
    try {
        const mis::Power power(beta);
        NSP_FUZZ_CHECK(beta > 0.f);
        check_heuristic(in, power);
    } catch (const InvalidArgument&) {
        NSP_FUZZ_CHECK(!(beta > 0.f));
    }
}

/// BDPT's weights per channel (THEORY 5.3 with 5.5): three channels' densities in [0, inf] per
/// vertex, delta vertices, shared factors in [0, 1], balance or a power heuristic of exponent up
/// to 100: q_c times each channel's weight in [0, 1], summing to 1 over channels x strategies
/// where any can draw the path, to 0 where none can. Reads its bytes after everything else, so the
/// corpus's older inputs keep what they drive.
template <class H>
void check_channel_bdpt(Input& in, const H& h) {
    bdpt::PathPdfs<12, Rgb::Spectrum> p;
    p.k = 1 + int(in.pick(11));
    p.light_tracing = in.pick(2) == 1;
    for (int i = 0; i < p.k; ++i) {
        p.from_light[i] = Rgb::Spectrum(ratio(in), ratio(in), ratio(in));
        p.from_camera[i] = Rgb::Spectrum(ratio(in), ratio(in), ratio(in));
        p.connectible[i] = in.pick(4) != 0;
    }
    p.nee = ratio(in);
    p.emit = ratio(in);
    const float gammas[] = {0.f, 1e-30f, 0.5f, 1.f};
    p.gamma = Rgb::Spectrum(gammas[in.pick(4)], gammas[in.pick(4)], 1.f);
    p.eq = Rgb::Spectrum(ratio(in), ratio(in), ratio(in));  // the equiangular strategy
    p.eq_nee = ratio(in);
    p.seg = Rgb::Spectrum(ratio(in), ratio(in), ratio(in));  // the segment technique: read last
    double q[3 * bdpt::PathPdfs<12, Rgb::Spectrum>::kSlots];
    const bool drawable = bdpt::channel_strategy_pdfs(p, q);
    float sum = 0.f;
    for (int c = 0; c < 3; ++c) {
        p.channel = c;
        for (const int s : every_strategy(p)) {
            const float w = bdpt::channel_strategy_weight(h, p, s) / 3.f;
            NSP_FUZZ_CHECK(w >= 0.f && w <= 1.f + kWeightTol);
            sum += w;
        }
    }
    NSP_FUZZ_CHECK(drawable ? std::abs(sum - 1.f) <= kWeightTol : sum == 0.f);
}

/// BDPT's grey weights with the equiangular strategy (THEORY 5.4 in 5.5) and the segment
/// technique (5.7 in 5.5), as check_heuristic's: every weight in [0, 1], summing to 1 where any
/// strategy can draw the path, to 0 where none can. Reads its bytes last (the segment
/// technique's after the rest).
void check_bdpt_equiangular(Input& in) {
    bdpt::PathPdfs<12> p = read_path_pdfs(in);
    p.eq = ratio(in);
    p.eq_nee = ratio(in);
    const float betas[] = {1.f, 2.f, 10.f, 100.f};
    const bool balance = in.pick(2) == 0;
    const mis::Power power(betas[in.pick(4)]);
    p.seg = ratio(in);
    double q[bdpt::PathPdfs<12>::kSlots];
    const bool drawable = bdpt::strategy_pdfs(p, q);
    float sum = 0.f;
    for (const int strategy : every_strategy(p)) {
        const float w = balance ? bdpt::strategy_weight(mis::Balance{}, p, strategy) : bdpt::strategy_weight(power, p, strategy);
        NSP_FUZZ_CHECK(w >= 0.f && w <= 1.f);
        sum += w;
    }
    NSP_FUZZ_CHECK(drawable ? std::abs(sum - 1.f) <= kWeightTol : sum == 0.f);
}

void check_channel_bdpt(Input& in) {
    const float betas[] = {1.f, 2.f, 10.f, 100.f};
    if (in.pick(2) == 0) check_channel_bdpt(in, mis::Balance{});
    else check_channel_bdpt(in, mis::Power(betas[in.pick(4)]));
}

// ---------------------------------------------------------------------------------------------
// The medium

struct BoxChoice {
    Box box;
    bool valid = true;
};

BoxChoice make_box(Input& in) {
    BoxChoice b;
    for (int a = 0; a < 3; ++a) {
        float e;
        switch (in.pick(8)) {
            case 0: e = 1e-3f; break;
            case 1: e = 1e4f; break;
            case 2: e = 1e-6f; break;
            case 3: e = 2.f; break;
            case 4: e = 1e-3f + in.unit() * 10.f; break;
            default: e = 1.f;
        }
        float lo;
        switch (in.pick(8)) {
            case 0: lo = -0.5f * e; break;
            case 1: lo = 1e4f; break;
            case 2: lo = -1e3f; break;
            case 3: lo = in.unit() * 2.f - 1.f; break;
            default: lo = 0.f;
        }
        b.box.lo[a] = lo;
        b.box.hi[a] = lo + e;  // may round to lo: then the box is empty and must be rejected
        b.valid = b.valid && b.box.lo[a] < b.box.hi[a];
    }
    if (in.pick(32) == 0) {  // a corner the constructors must reject
        b.box.hi[in.pick(3)] = in.flag() ? std::numeric_limits<float>::quiet_NaN() : -kInf;
        b.valid = false;
    }
    return b;
}

/// A grid of values of the palette, sometimes with one value the constructor must reject.
std::vector<float> make_voxels(Input& in, const std::array<int, 3>& res, bool& bad) {
    std::vector<float> v(std::size_t(res[0] * res[1] * res[2]));
    const int fill = in.pick(4);  // 0: every voxel its own value; else one value, a few changed
    const float common = value(in);
    for (float& x : v) x = fill == 0 ? value(in) : common;
    if (fill != 0)
        for (int k = in.pick(3); k > 0; --k) v[std::size_t(in.pick(int(v.size())))] = value(in);
    if (in.pick(32) == 0) {
        v[std::size_t(in.pick(int(v.size())))] = bad_value(in);
        bad = true;
    }
    return v;
}

std::array<int, 3> make_res(Input& in, int max) {
    return {1 + in.pick(max), 1 + in.pick(max), 1 + in.pick(max)};
}

// ---------------------------------------------------------------------------------------------
// Majorants: constructed from fuzzed values, checked against their documented rules

enum class MajKind { Global, Grid, ChannelGrid, Channel };

/// A majorant family: its kind and its type for medium M under bound policy B.
template <MajKind K>
struct Family {
    static constexpr MajKind kind = K;
    template <class M, class B>
    static auto make_type() {
        if constexpr (K == MajKind::Global) return Tag<GlobalMajorant<M, B>>{};
        else if constexpr (K == MajKind::Grid) return Tag<GridMajorant<M, B>>{};
        else if constexpr (K == MajKind::ChannelGrid) return Tag<ChannelGridMajorant<M, B>>{};
        else return Tag<ChannelMajorant<M, B>>{};
    }
    template <class M, class B>
    using type = typename decltype(make_type<M, B>())::type;
};

float scale_choice(Input& in) {
    switch (in.pick(12)) {
        case 0: return 1e3f;
        case 1: return 0.5f;
        case 2: return 1e-3f;
        case 3: return 0.f;
        case 4: return 0x1.000002p0f;  // just above 1
        case 5: return 0x1.fffffep-1f; // just below 1
        case 6: return value(in);
        case 7: return bad_value(in);
        default: return 1.f;
    }
}

/// A majorant of family Fam under bound policy B for `medium` built from the input, or nullopt
/// when its constructor rejected the values; values the documented rules reject must be rejected. `maj_max` is the
/// largest majorant value it gives, at wavelengths `lambda`.
template <class Fam, class B, class M>
std::optional<typename Fam::template type<M, B>> make_majorant(Input& in, const M& medium, const typename M::Spectral::Wavelengths& lambda,
                                        float& maj_max, float& maj_min) {
    using Maj = typename Fam::template type<M, B>;
    constexpr MajKind kind = Fam::kind;
    const float ext = medium.max_extinction();
    if constexpr (kind == MajKind::Global) {
        const int mode = in.pick(8);
        float v = ext;
        switch (mode) {
            case 2: v = ext * 1e3f; break;
            case 3: v = ext * 0.5f; break;
            case 4: v = ext * 1e-3f; break;
            case 5: v = 0.f; break;
            case 6: v = value(in); break;
            case 7: v = std::nextafter(ext, 0.f); break;
            default: break;
        }
        bool expect_throw = !std::isfinite(v) || v < 0.f;
        if (mode != 0) {
            if (!B::allows_below) expect_throw = expect_throw || v < ext;
            else expect_throw = expect_throw || (!(v > 0.f) && ext > 0.f);
        }
        try {
            Maj maj = mode == 0 ? Maj(medium) : Maj(medium, v);
            NSP_FUZZ_CHECK(!expect_throw);
            maj_max = maj.value();
            maj_min = maj_max > 0.f ? maj_max : kInf;
            return maj;
        } catch (const InvalidArgument&) {
            return std::nullopt;  // bad values, or a rule beyond those predicted (overflow, rounding to 0)
        }
    } else {
        const float scale = scale_choice(in);
        bool expect_throw = !std::isfinite(scale) || !(scale > 0.f) || (!B::allows_below && scale < 1.f);
        if constexpr (kind == MajKind::Channel) expect_throw = expect_throw || !std::isfinite(ext * scale);
        try {
            if constexpr (kind == MajKind::Channel) {
                Maj maj(medium, scale);
                NSP_FUZZ_CHECK(!expect_throw);
                const auto v = maj.value(lambda);
                NSP_FUZZ_CHECK(finite_all(v) && (v >= 0.f).all());
                maj_max = v.maxCoeff();
                maj_min = min_positive(v);
                return maj;
            } else {
                const std::array<int, 3> res = make_res(in, 5);
                Maj maj(medium, res, scale);
                NSP_FUZZ_CHECK(!expect_throw);
                // Every cell of a majorant is finite and >= 0 (MajorantSegment's contract).
                maj_max = 0.f;
                maj_min = kInf;
                for (int z = 0; z < res[2]; ++z)
                    for (int y = 0; y < res[1]; ++y)
                        for (int x = 0; x < res[0]; ++x) {
                            float m;
                            if constexpr (kind == MajKind::Grid) {
                                m = maj.cell(x, y, z);
                                if (m > 0.f) maj_min = std::min(maj_min, m);
                            } else {
                                const auto v = maj.cell(x, y, z, lambda);
                                NSP_FUZZ_CHECK(no_nan(v));
                                m = v.maxCoeff();
                                maj_min = std::min(maj_min, min_positive(v));
                            }
                            NSP_FUZZ_CHECK(!std::isnan(m) && m >= 0.f);
                            maj_max = std::max(maj_max, m);
                        }
                return maj;
            }
        } catch (const InvalidArgument&) {
            return std::nullopt;  // bad values, or a rule beyond those predicted (overflow, rounding to 0)
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Rays

Ray make_ray(Input& in, const Box& b, const std::array<int, 3>& res) {
    const Vec3 ext = b.hi - b.lo, centre = b.lo + 0.5f * ext;
    const float diag = glm::length(ext);
    Vec3 o;
    switch (in.pick(8)) {
        case 0:  // inside
            for (int a = 0; a < 3; ++a) o[a] = b.lo[a] + in.unit() * ext[a];
            break;
        case 1: {  // on a face
            for (int a = 0; a < 3; ++a) o[a] = b.lo[a] + in.unit() * ext[a];
            const int a = in.pick(3);
            o[a] = in.flag() ? b.lo[a] : b.hi[a];
            break;
        }
        case 2:  // on voxel faces
            for (int a = 0; a < 3; ++a) o[a] = b.lo[a] + ext[a] * float(in.pick(res[a] + 1)) / float(res[a]);
            break;
        case 3:  // a corner
            for (int a = 0; a < 3; ++a) o[a] = in.flag() ? b.lo[a] : b.hi[a];
            break;
        case 4:  // outside, near
            o = centre + Vec3(0.f, 0.f, -2.f * diag);
            break;
        case 5:  // far away
            o = centre + Vec3(1e6f * (in.flag() ? 1.f : -1.f), 0.f, 0.f);
            break;
        case 6:
            o = Vec3(value(in) - 1.f, value(in) - 1.f, value(in) - 1.f);
            break;
        default:
            o = centre;
    }
    Vec3 d;
    switch (in.pick(7)) {
        case 0: {  // axis-aligned
            d = Vec3(0.f);
            d[in.pick(3)] = in.flag() ? 1.f : -1.f;
            break;
        }
        case 1:
            d = uniform_sphere(in.unit(), in.unit());
            break;
        case 2:  // denormal components
            d = Vec3(in.flag() ? 1.f : -1.f, 1e-40f, in.flag() ? 0x1p-149f : -0x1p-149f);
            break;
        case 3:  // almost axis-aligned
            d = glm::normalize(Vec3(1e-7f, in.flag() ? 1.f : -1.f, 1e-7f));
            break;
        case 4:
            d = glm::normalize(Vec3(in.flag() ? 1.f : -1.f, in.flag() ? 1.f : -1.f, in.flag() ? 1.f : -1.f));
            break;
        default: {  // toward the box centre (or a random point in it)
            Vec3 target = centre;
            if (in.flag())
                for (int a = 0; a < 3; ++a) target[a] = b.lo[a] + in.unit() * ext[a];
            const Vec3 v = target - o;
            d = glm::dot(v, v) > 0.f && std::isfinite(glm::dot(v, v)) ? glm::normalize(v) : Vec3(0.f, 0.f, 1.f);
        }
    }
    return {o, d};
}

float make_tmax(Input& in, const Box& b) {
    const float diag = glm::length(b.hi - b.lo);
    switch (in.pick(10)) {
        case 0: return 0.f;
        case 1: return 1e-30f;
        case 2: return 1e-6f;
        case 3: return 1.f;
        case 4: return diag;
        case 5: return 1e6f;
        case 6: return 1e30f;
        case 7: return 2.f * diag * in.unit();
        default: return kInf;
    }
}

// ---------------------------------------------------------------------------------------------
// Tracking kernels

/// Tolerance of a recorded log pdf against its independent evaluation: relative float rounding,
/// plus the rounding of the vertex positions times the majorant (for far-away origins).
double log_pdf_tolerance(double lp, std::size_t vertices, float t_far, float maj_max) {
    return 1e-3 * (1.0 + std::abs(lp)) + 4.0 * double(vertices + 1) * double(t_far) * 0x1p-23 * double(maj_max);
}

/// True when a vertex lies within rounding of a majorant segment's end: free_flight can round a
/// collision onto the end t1 of the segment it was drawn in, where the half-open segments of the
/// pdf evaluation (pdf.hpp) give the next segment's majorant, or 0 past the last one. The pdf
/// re-evaluation is skipped there (finding 4 in the report; the tracking loop is not changed here).
template <class M, class Maj, class Lambda>
bool vertex_on_segment_end(const Maj& maj, const Ray& ray, const Lambda& lambda, const std::vector<float>& ts) {
    auto it = maj.iterate(ray, 0.f, kInf, lambda);
    while (auto seg = it.next())
        for (const float t : ts)
            if (std::abs(t - seg->t1) <= 4.f * std::abs(seg->t1) * 0x1p-23f || t == seg->t0) return true;
    return false;
}

/// True when a null lies where mu_bar - mu_t is at float rounding level in some channel: P_n is
/// formed there from a difference of nearly equal floats, the sampler's float P_n and the
/// re-evaluation's can differ by a factor of 2 (finding 12: mu_n one ulp of mu_bar = 16 against
/// half an ulp), and the pdf comparison is ill-conditioned. It is skipped there, as at segment
/// ends (finding 4); such a null is drawn with probability ~1e-7 and changes no estimate.
template <class M, class Maj, class Lambda>
bool null_at_rounding_level(const M& medium, const Maj& maj, const Ray& ray, const Lambda& lambda,
                            const std::vector<float>& nulls) {
    using Spec = typename M::Spectral::Spectrum;
    for (const float t : nulls) {
        const auto mu_v = majorant_value_at<M>(maj, ray, t, lambda);
        if (!mu_v) continue;
        const Spec mu = detail::broadcast_majorant<Spec>(*mu_v);
        const Spec mu_t = tracked_coefficients(medium, maj, ray, t, lambda).sigma_t();
        if (((mu - mu_t).abs() <= 16.f * 0x1p-23f * mu.abs()).any()) return true;
    }
    return false;
}

/// Prints what a pdf comparison found before NSP_FUZZ_CHECK aborts on it.
inline bool report_pdf(bool ok, double lp, double recorded, std::size_t vertices, float tmax) {
    if (!ok)
        std::fprintf(stderr, "nsp fuzz: re-evaluated log pdf %.17g, recorded %.17g, %zu vertices, tmax %.9g\n", lp,
                     recorded, vertices, double(tmax));
    return ok;
}

template <class Spec>
bool within_unit(const Spec& s, float slack) {
    return (s >= -slack).all() && (s <= 1.f + slack).all();
}

template <class S, class M, class Maj, class Lambda>
void drive_free_flight(Input& in, FuzzRng& rng, const M& medium, const Maj& maj, const Ray& ray, float tmax,
                       const Lambda& lambda) {
    g_context = "free_flight";
    using V = MajorantValue<Maj, M>;
    using B = bound_policy_t<Maj>;
    using Spec = typename S::Spectrum;
    constexpr bool grey = std::is_same_v<V, float>;
    const int channel = grey ? 0 : in.pick(S::channels);
    const std::uint32_t max_collisions = 1u + std::uint32_t(in.pick(64));
    const float tmin = in.flag() ? 0.f : std::min(tmax, in.unit() * glm::length(medium.bounds().hi - medium.bounds().lo));
    const float stop = in.unit();
    std::uint32_t calls = 0;
    float last = tmin;
    LookupCount counter;
    auto cb = [&](float t, const Coefficients<S>& k, const V& mu, const V& tau) -> bool {
        ++calls;
        NSP_FUZZ_CHECK(t >= last && t <= tmax);
        NSP_FUZZ_CHECK(finite_all(k.sigma_a) && finite_all(k.sigma_s));
        NSP_FUZZ_CHECK((k.sigma_a >= 0.f).all() && (k.sigma_s >= 0.f).all());
        const Spec m = detail::broadcast_majorant<Spec>(mu), tv = detail::broadcast_majorant<Spec>(tau);
        NSP_FUZZ_CHECK(finite_all(m) && (m >= 0.f).all() && m[channel] > 0.f);
        NSP_FUZZ_CHECK(finite_all(tv) && (tv >= 0.f).all());
        if constexpr (std::is_same_v<B, bound::Clamp>) NSP_FUZZ_CHECK((k.sigma_t() <= m * 1.000001f).all());
        if constexpr (std::is_same_v<B, bound::Reject>) NSP_FUZZ_CHECK(!detail::exceeds_majorant(k, mu));
        last = t;
        return rng.uniform() >= stop;
    };
    const auto f = free_flight(medium, maj, ray, tmin, tmax, lambda, rng, counter, cb, max_collisions, channel);
    NSP_FUZZ_CHECK(counter.count() <= max_collisions);
    if (f.rejected) NSP_FUZZ_CHECK((std::is_same_v<B, bound::Reject>) && f.aborted);
    if (f.aborted && !f.rejected) NSP_FUZZ_CHECK(calls == max_collisions);
    if (f.stopped) NSP_FUZZ_CHECK(!f.aborted && f.t == last);
    if (!f.stopped && !f.aborted) {
        NSP_FUZZ_CHECK(f.t == tmax);
        const Spec tail = detail::broadcast_majorant<Spec>(f.tau_tail);
        NSP_FUZZ_CHECK(finite_all(tail) && (tail >= 0.f).all());
    }
}

/// Delta and ratio tracking with a grey majorant, and their pdfs re-evaluated from the vertices.
template <class S, class A, class M, class Maj, class Lambda>
void drive_grey(FuzzRng& rng, const M& medium, const Maj& maj, const Ray& ray, float tmax, const Lambda& lambda,
                float maj_max, float maj_min) {
    using B = bound_policy_t<Maj>;
    constexpr bool kSigned = std::is_same_v<B, bound::Signed>;
    constexpr bool kMono = S::channels == 1;
    LookupCount counter;
    {
        g_context = A::as_event ? "track_delta<Event>" : "track_delta<Weight>";
        SegmentRecord rec;
        const auto d = track_delta<A>(medium, maj, ray, tmax, lambda, rng, counter, rec);
        NSP_FUZZ_CHECK(d.end != SegmentEnd::Terminated && d.end != SegmentEnd::Aborted);
        if (d.end == SegmentEnd::Absorbed) NSP_FUZZ_CHECK(A::as_event);
        if (d.end == SegmentEnd::Rejected) NSP_FUZZ_CHECK((std::is_same_v<B, bound::Reject>) && (d.weight == 0.f).all());
        if (!finite_all(d.weight))
            std::fprintf(stderr, "nsp fuzz: delta weight[0] %g, end %d, t %g, tmax %g, P_n product %g, event density %g, "
                         "majorant %g..%g, %zu vertices\n", double(d.weight[0]), int(d.end), double(d.t), double(tmax),
                         double(d.null_pdf_product), double(d.event_density), double(maj_min), double(maj_max),
                         rec.t.size());
        if constexpr (kSigned) NSP_FUZZ_CHECK(no_nan(d.weight));
        else NSP_FUZZ_CHECK(finite_all(d.weight));
        // Grey media with a bounding majorant: the weight is 1 up to rounding-sized negative nulls
        // (which flip its sign, THEORY 4) and the float rounding of the event probabilities it
        // divides by: 1e-4 covers normal floats, but a subnormal probability is rounded to 2^-149
        // absolute (finding 14: P_absorb = 3e-42 drawn from u = 0, its weight 1.0002, unbiased for
        // the probability actually used). event_density / the largest majorant bounds the chosen
        // event's probability from below, and the nulls' product bounds each null's.
        if constexpr (kMono && !kSigned) {
            double tol = 1e-4;
            auto widen = [&](double p) {
                if (p > 0.0 && p < double(std::numeric_limits<float>::min())) tol += 2.0 * 0x1p-149 / p;
            };
            if ((d.end == SegmentEnd::Scattered || d.end == SegmentEnd::Absorbed) && maj_max > 0.f)
                widen(double(d.event_density) / double(maj_max));
            widen(double(d.null_pdf_product));
            // Under a subnormal majorant a null's weight mu_n / (mu_bar P_n) divides by a product
            // rounded to the 2^-149 grid too (finding 17: mu_bar = 2.4e-41, P_n = 6e-5, mu_bar P_n one
            // subnormal ulp, weight -1.0001): the smallest majorant times the nulls' product bounds
            // every null's mu_bar P_n from below.
            if (maj_min > 0.f) widen(double(maj_min) * double(d.null_pdf_product));
            if (d.end != SegmentEnd::Rejected) NSP_FUZZ_CHECK(std::abs(double(d.weight[0])) <= 1.0 + tol);
        }
        NSP_FUZZ_CHECK(d.null_pdf_product >= 0.f && d.null_pdf_product <= 1.f);
        if (d.end == SegmentEnd::Passed) NSP_FUZZ_CHECK(d.t == tmax);
        if (d.end == SegmentEnd::Scattered || d.end == SegmentEnd::Absorbed) {
            // A sample is taken: its pdf is positive and it lies on the segment.
            NSP_FUZZ_CHECK(d.t >= 0.f && d.t <= tmax);
            NSP_FUZZ_CHECK(d.event_density >= 0.f && std::isfinite(d.event_density));
            // 0 only where mu_bar P_event, re-evaluated in double, is below half float's smallest
            // subnormal, so that float rounds it to 0 (finding 15); where the vertex sits on a
            // majorant segment's end, which segment's mu_bar applies is a matter of rounding.
            if (d.event_density == 0.f && !vertex_on_segment_end<M>(maj, ray, lambda, rec.t)) {
                const float mu = majorant_at<M>(maj, ray, d.t, lambda);
                const auto p = event_probabilities<A>(tracked_coefficients(medium, maj, ray, d.t, lambda), mu);
                const double density = double(mu) * double(d.end == SegmentEnd::Absorbed ? p.absorb : p.scatter);
                NSP_FUZZ_CHECK(density <= 0x1p-150);
            }
            NSP_FUZZ_CHECK(!rec.t.empty() && rec.t.back() == d.t);
            NSP_FUZZ_CHECK(rec.log_pdf > -std::numeric_limits<double>::infinity());
        }
        if (d.end != SegmentEnd::Rejected && std::isfinite(rec.log_pdf)) {
            g_context = "delta_segment_log_pdf";
            std::vector<float> nulls = rec.t;
            if (d.end != SegmentEnd::Passed) nulls.pop_back();
            const double lp = delta_segment_log_pdf<A>(medium, maj, ray, tmax, lambda, nulls, d.end, d.t);
            const float t_far = rec.t.empty() ? 0.f : std::abs(rec.t.back()) + std::abs(ray.o.x) + std::abs(ray.o.y) +
                                                          std::abs(ray.o.z);
            if (!vertex_on_segment_end<M>(maj, ray, lambda, rec.t) && !null_at_rounding_level(medium, maj, ray, lambda, nulls))
                NSP_FUZZ_CHECK(report_pdf(std::abs(lp - rec.log_pdf) <= log_pdf_tolerance(rec.log_pdf, rec.t.size(), t_far, maj_max),
                                          lp, rec.log_pdf, rec.t.size(), tmax));
        }
    }
    {
        g_context = "track_ratio";
        SegmentRecord rec;
        const auto r = track_ratio<A, true>(medium, maj, ray, tmax, lambda, rng, counter, rec);
        NSP_FUZZ_CHECK(r.end == SegmentEnd::Passed || r.end == SegmentEnd::Terminated || r.end == SegmentEnd::Rejected);
        if (r.end == SegmentEnd::Rejected) NSP_FUZZ_CHECK((std::is_same_v<B, bound::Reject>));
        if (r.end != SegmentEnd::Passed) NSP_FUZZ_CHECK((r.transmittance == 0.f).all());
        if constexpr (kSigned) NSP_FUZZ_CHECK(no_nan(r.transmittance));
        else {
            // Each factor (mu_bar - mu_t) / mu_bar lies in [0, 1] up to float rounding: 2e-5 for
            // normal majorants. Under a subnormal majorant mu_t is rounded to the 2^-149 grid, so a
            // factor may leave [0, 1] by d = 2^-149 / mu_bar, and n of them by (1 + d)^n - 1
            // (finding 16: mu_bar = 2.4e-41, one null, T = -6e-5 = -2^-149 / mu_bar).
            double slack = 2e-5;
            if (maj_min > 0.f && maj_min < std::numeric_limits<float>::min())
                slack += std::pow(1.0 + 0x1p-149 / double(maj_min), double(rec.t.size())) - 1.0;
            NSP_FUZZ_CHECK(within_unit(r.transmittance, float(std::min(slack, 1e30))));
        }
        NSP_FUZZ_CHECK(r.null_pdf_product >= 0.f && r.null_pdf_product <= 1.f);
        if (r.end == SegmentEnd::Passed && std::isfinite(rec.log_pdf)) {
            g_context = "ratio_segment_log_pdf";
            const double lp = ratio_segment_log_pdf(medium, maj, ray, tmax, lambda, rec.t);
            const float t_far = (rec.t.empty() ? 0.f : std::abs(rec.t.back())) + std::abs(ray.o.x) +
                                std::abs(ray.o.y) + std::abs(ray.o.z);
            if (!vertex_on_segment_end<M>(maj, ray, lambda, rec.t))
                NSP_FUZZ_CHECK(report_pdf(std::abs(lp - rec.log_pdf) <= log_pdf_tolerance(rec.log_pdf, rec.t.size(), t_far, maj_max),
                                          lp, rec.log_pdf, rec.t.size(), tmax));
        }
    }
    if constexpr (A::as_event) {
        g_context = "transmittance_ratio / transmittance_delta";
        const auto trs = transmittance_ratio(medium, maj, ray, tmax, lambda, rng, counter);
        const auto tds = transmittance_delta(medium, maj, ray, tmax, lambda, rng, counter);
        // A failed flight (or an unusable ray) reports its status and no estimate.
        NSP_FUZZ_CHECK(trs.status == Status::Ok || (trs.value == 0.f).all());
        NSP_FUZZ_CHECK(tds.status == Status::Ok || (tds.value == 0.f).all());
        NSP_FUZZ_CHECK((trs.status == Status::InvalidInput) == !usable_ray(ray));
        const auto& tr = trs.value;
        const auto& td = tds.value;
        if constexpr (kSigned) {
            NSP_FUZZ_CHECK(no_nan(tr) && no_nan(td));
        } else {
            // Under a subnormal majorant the ratio factors may leave [0, 1] by 2^-149 / mu_bar each
            // (finding 16); transmittance_ratio reports no null count to bound their product with,
            // so there only finiteness is checked: track_ratio above checks the same products
            // against (1 + 2^-149 / mu_bar)^n - 1 with its n.
            if (maj_min >= std::numeric_limits<float>::min()) NSP_FUZZ_CHECK(within_unit(tr, 2e-5f));
            NSP_FUZZ_CHECK(finite_all(tr) && finite_all(td));
            if constexpr (kMono) NSP_FUZZ_CHECK(std::abs(td[0]) <= 1.f + 1e-4f);
        }
    }
}

/// Delta and ratio tracking with per-channel pdfs (channel policy CP, absorption A).
template <class S, class CP, class A, bool kEq, class M, class Maj, class Lambda>
void drive_channels(Input& in, FuzzRng& rng, const M& medium, const Maj& maj, const Ray& ray, float tmax,
                    const Lambda& lambda, float maj_max) {
    using B = bound_policy_t<Maj>;
    using Spec = typename S::Spectrum;
    constexpr bool kSigned = std::is_same_v<B, bound::Signed>;
    const int c = in.pick(S::channels);
    const bool nee_alternative = in.flag();
    LookupCount counter;
    {
        g_context = "track_channels_delta";
        ChannelPathState<S, kEq> st;
        if (nee_alternative) st.nee = st.uni;
        if constexpr (kEq) st.eq.vertex = st.uni;
        SegmentRecord rec;
        const ChannelTrack tr =
            track_channels_delta<CP, A>(medium, maj, ray, tmax, lambda, c, st, nee_alternative, rng, counter, rec);
        NSP_FUZZ_CHECK(tr.end != SegmentEnd::Aborted);
        if (tr.end == SegmentEnd::Absorbed) NSP_FUZZ_CHECK(A::as_event);
        if (tr.end == SegmentEnd::Rejected) NSP_FUZZ_CHECK((std::is_same_v<B, bound::Reject>));
        if (tr.end == SegmentEnd::Passed) NSP_FUZZ_CHECK(tr.t == tmax);
        // A state that ends dead or overflowed is zeroed (finding 10: f / p overflowed float).
        if (tr.end == SegmentEnd::Terminated || tr.end == SegmentEnd::Overflowed)
            NSP_FUZZ_CHECK((st.f == 0.f).all() && (st.uni == 0.f).all() && (st.nee == 0.f).all());
        // Pdfs are finite and >= 0; contributions finite (any sign under bound::Signed).
        NSP_FUZZ_CHECK(finite_all(st.uni) && (st.uni >= 0.f).all());
        NSP_FUZZ_CHECK(finite_all(st.nee) && (st.nee >= 0.f).all());
        if constexpr (kEq) NSP_FUZZ_CHECK(finite_all(st.eq.vertex) && (st.eq.vertex >= 0.f).all());
        NSP_FUZZ_CHECK(finite_all(st.f));
        if (tr.end == SegmentEnd::Scattered || tr.end == SegmentEnd::Passed) {
            // A sample is taken (or the segment passed): the pdf the estimate divides by is > 0.
            NSP_FUZZ_CHECK(tr.t >= 0.f && tr.t <= tmax);
            const Spec q = Spec::Constant(1.f / float(S::channels));
            if constexpr (CP::mis_over_channels) NSP_FUZZ_CHECK((q * st.uni).sum() > 0.f);
            else NSP_FUZZ_CHECK(st.uni[c] > 0.f);
        }
        if constexpr (CP::own_pdfs) {
            if ((tr.end == SegmentEnd::Scattered || tr.end == SegmentEnd::Passed || tr.end == SegmentEnd::Absorbed) &&
                std::isfinite(rec.log_pdf)) {
                g_context = "channel_delta_segment_log_pdf";
                std::vector<float> nulls = rec.t;
                if (tr.end != SegmentEnd::Passed) nulls.pop_back();
                const double lp =
                    channel_delta_segment_log_pdf<A>(medium, maj, ray, tmax, lambda, c, nulls, tr.end, tr.t);
                const float t_far = (rec.t.empty() ? 0.f : std::abs(rec.t.back())) + std::abs(ray.o.x) +
                                    std::abs(ray.o.y) + std::abs(ray.o.z);
                if (!vertex_on_segment_end<M>(maj, ray, lambda, rec.t) &&
                    !null_at_rounding_level(medium, maj, ray, lambda, nulls))
                    NSP_FUZZ_CHECK(report_pdf(std::abs(lp - rec.log_pdf) <=
                                                  log_pdf_tolerance(rec.log_pdf, rec.t.size(), t_far, maj_max),
                                              lp, rec.log_pdf, rec.t.size(), tmax));
            }
        }
    }
    {
        g_context = "track_channels_ratio";
        Spec weights;
        for (int k = 0; k < S::channels; ++k) weights[k] = value(in);
        const bool uni_alternative = in.flag();
        const auto sh = track_channels_ratio<CP, A>(medium, maj, ray, tmax, lambda, c, weights, uni_alternative, rng,
                                                    counter);
        NSP_FUZZ_CHECK(sh.end == SegmentEnd::Passed || sh.end == SegmentEnd::Terminated ||
                       sh.end == SegmentEnd::Overflowed || sh.end == SegmentEnd::Rejected);
        if (sh.end == SegmentEnd::Rejected) NSP_FUZZ_CHECK((std::is_same_v<B, bound::Reject>));
        if (sh.end != SegmentEnd::Passed) NSP_FUZZ_CHECK((sh.f == 0.f).all());
        if constexpr (kSigned) NSP_FUZZ_CHECK(no_nan(sh.f));
        else NSP_FUZZ_CHECK(finite_all(sh.f));
        NSP_FUZZ_CHECK(finite_all(sh.nee) && (sh.nee >= 0.f).all());
        // uni is only kept with uni_alternative (ChannelShadow); without it, it is rescaled but
        // never multiplied, and overflows on a long flight (finding 8: no bug, nothing reads it).
        if (uni_alternative) NSP_FUZZ_CHECK(finite_all(sh.uni) && (sh.uni >= 0.f).all());
        if (sh.end == SegmentEnd::Passed) {
            // The NEE estimate divides by ratio tracking's pdf: it is > 0.
            if constexpr (CP::mis_over_channels) NSP_FUZZ_CHECK(sh.nee.maxCoeff() > 0.f);
            else NSP_FUZZ_CHECK(sh.nee[c] > 0.f);
        }
    }
}

template <class S, class M, class Maj, class Lambda>
void drive_tracking(Input& in, FuzzRng& rng, const M& medium, const Maj& maj, const Ray& ray, float tmax,
                    const Lambda& lambda, float maj_max, float maj_min) {
    drive_free_flight<S>(in, rng, medium, maj, ray, tmax, lambda);
    if constexpr (!is_per_channel_majorant_v<Maj, M>) {
        drive_grey<S, absorption::Event>(rng, medium, maj, ray, tmax, lambda, maj_max, maj_min);
        drive_grey<S, absorption::Weight>(rng, medium, maj, ray, tmax, lambda, maj_max, maj_min);
        drive_channels<S, channels::SpectralTrackingAverage, absorption::Event, false>(in, rng, medium, maj, ray, tmax,
                                                                                       lambda, maj_max);
        drive_channels<S, channels::SpectralTrackingMax, absorption::Weight, false>(in, rng, medium, maj, ray, tmax,
                                                                                    lambda, maj_max);
    }
    drive_channels<S, channels::Independent, absorption::Event, false>(in, rng, medium, maj, ray, tmax, lambda,
                                                                       maj_max);
    drive_channels<S, channels::SpectralMis, absorption::Weight, true>(in, rng, medium, maj, ray, tmax, lambda,
                                                                       maj_max);
}

/// Builds a majorant of family Fam under bound policy B and, within the budget, drives every tracking kernel on a
/// few rays.
template <class S, class Fam, class B, class M, class Lambda>
void run_tracking(Input& in, FuzzRng& rng, const M& medium, const std::array<int, 3>& res, const Lambda& lambda) {
    float maj_max = 0.f, maj_min = kInf;
    const auto maj = make_majorant<Fam, B>(in, medium, lambda, maj_max, maj_min);
    if (!maj) return;
    const Box b = medium.bounds();
    if (!(maj_max * glm::length(b.hi - b.lo) <= kBudget)) return;
    for (int i = 1 + in.pick(3); i > 0; --i) {
        const Ray ray = make_ray(in, b, res);
        const float tmax = make_tmax(in, b);
        drive_tracking<S>(in, rng, medium, *maj, ray, tmax, lambda, maj_max, maj_min);
    }
}

/// The majorant types the tracking kernels run with (9 of the 16 kind x bound policy pairs, to
/// keep the build short): the global majorant with every bound policy, the grid with Guaranteed
/// and Clamp, the per-channel grid with Signed and Reject, the per-channel constant with Guaranteed.
template <class S, class M, class Lambda>
void run_tracking_any(Input& in, FuzzRng& rng, const M& medium, const std::array<int, 3>& res, const Lambda& lambda) {
    using Global = Family<MajKind::Global>;
    switch (in.pick(9)) {
        case 0: return run_tracking<S, Global, bound::Guaranteed>(in, rng, medium, res, lambda);
        case 1: return run_tracking<S, Global, bound::Signed>(in, rng, medium, res, lambda);
        case 2: return run_tracking<S, Global, bound::Clamp>(in, rng, medium, res, lambda);
        case 3: return run_tracking<S, Global, bound::Reject>(in, rng, medium, res, lambda);
        case 4: return run_tracking<S, Family<MajKind::Grid>, bound::Guaranteed>(in, rng, medium, res, lambda);
        case 5: return run_tracking<S, Family<MajKind::Grid>, bound::Clamp>(in, rng, medium, res, lambda);
        case 6: return run_tracking<S, Family<MajKind::ChannelGrid>, bound::Signed>(in, rng, medium, res, lambda);
        case 7: return run_tracking<S, Family<MajKind::ChannelGrid>, bound::Reject>(in, rng, medium, res, lambda);
        default: return run_tracking<S, Family<MajKind::Channel>, bound::Guaranteed>(in, rng, medium, res, lambda);
    }
}

// ---------------------------------------------------------------------------------------------
// Path estimators: a representative subset (estimator, medium, majorant type), one per input.

template <class Est, bool kEmissive, MajKind K, class B>
struct EstimatorCase {
    using Estimator = Est;
    static constexpr bool emissive = kEmissive;
    using Fam = Family<K>;
    using Bound = B;
};

using kEstimators = std::tuple<
    EstimatorCase<PathEstimator<strategy::NullScatteringMis, mis::Balance, absorption::Weight>, false, MajKind::Grid,
                  bound::Guaranteed>,
    EstimatorCase<PathEstimator<strategy::EquiangularMis, mis::Power, absorption::Event>, true, MajKind::Global,
                  bound::Signed>,
    EstimatorCase<PathEstimator<strategy::Unidirectional, mis::None, absorption::Weight>, false, MajKind::Global,
                  bound::Reject>,
    EstimatorCase<SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>, false,
                  MajKind::ChannelGrid, bound::Guaranteed>,
    EstimatorCase<SpectralPathEstimator<channels::SpectralMis, strategy::EquiangularMis, mis::Balance,
                                        absorption::Event>,
                  true, MajKind::Channel, bound::Clamp>,
    EstimatorCase<SpectralPathEstimator<channels::SpectralTrackingAverage, strategy::NextEvent, mis::None,
                                        absorption::Event>,
                  false, MajKind::Global, bound::Reject>,
    EstimatorCase<SpectralPathEstimator<channels::Independent, strategy::EquiangularNextEvent, mis::None>, true,
                  MajKind::Grid, bound::Clamp>>;

template <SpectralMode S>
Lights<S> make_lights(Input& in, const Box& b) {
    Lights<S> lights;
    const Vec3 ext = b.hi - b.lo, centre = b.lo + 0.5f * ext;
    const float diag = glm::length(ext);
    if (in.flag()) {
        Vec3 p;
        switch (in.pick(4)) {
            case 0:
                for (int a = 0; a < 3; ++a) p[a] = b.lo[a] + in.unit() * ext[a];
                break;
            case 1: p = b.hi; break;
            case 2: p = centre; break;
            default: p = centre + Vec3(0.f, 2.f * diag, 0.f);
        }
        lights.set(PointLight<S>{p, coefficient<S>(in)});
    }
    if (in.flag()) {
        const float radii[] = {0.1f, 1e-6f, 1.f, 0.49f, 2.f};
        const float dist = 0.5f * diag + diag * radii[in.pick(5)] * (1.f + in.unit());
        const Vec3 dir = uniform_sphere(in.unit(), in.unit());
        lights.set(SphereLight<S>{centre + dist * dir, diag * radii[in.pick(5)], coefficient<S>(in)});
    }
    if (in.flag()) lights.set(EnvironmentLight<S>{coefficient<S>(in)});
    return lights;
}

EstimatorOptions make_options(Input& in, bool& valid) {
    EstimatorOptions o;
    const int depths[] = {-1, 0, 1, 2, 5, 8};
    o.max_depth = depths[in.pick(6)];
    o.russian_roulette = in.flag();
    const int starts[] = {0, 1, 2, 3};
    o.rr_start_depth = starts[in.pick(4)];
    const float survival[] = {0.f, 1e-30f, 0.5f, 0.95f, 1.f, 1.5f, std::numeric_limits<float>::quiet_NaN(), 0x1p-149f};
    o.rr_max_survival = survival[in.pick(8)];
    valid = o.max_depth >= 0 && o.rr_start_depth >= 1 && o.rr_max_survival > 0.f && o.rr_max_survival <= 1.f;
    return o;
}

template <class S, class Case, class Base, class Lambda>
void run_estimator(Input& in, FuzzRng& rng, const Base& base, const Box& box, const Lambda& lambda) {
    using Est = typename Case::Estimator;
    g_context = "path estimator setup";
    const auto go = [&](const auto& medium) {
        using M = std::remove_cvref_t<decltype(medium)>;
        using Maj = typename Case::Fam::template type<M, typename Case::Bound>;
        float maj_max = 0.f, maj_min = kInf;
        auto maj = make_majorant<typename Case::Fam, typename Case::Bound>(in, medium, lambda, maj_max, maj_min);
        // Path estimators track many segments: a tenth of the tracking budget per crossing.
        if (!maj || !(maj_max * glm::length(box.hi - box.lo) <= 0.1f * kBudget)) return;
        const float gs[] = {0.f, 0.5f, -0.9f, 0.999f, 1e-4f};
        const HenyeyGreensteinPhase phase(gs[in.pick(5)]);
        Lights<S> lights = make_lights<S>(in, box);
        std::optional<Scene<M, Maj, HenyeyGreensteinPhase>> scene;
        try {
            scene.emplace(medium, *maj, phase, std::move(lights));
        } catch (const InvalidArgument&) {
            return;  // the sphere light overlaps the medium
        }
        bool valid = false;
        const EstimatorOptions opts = make_options(in, valid);
        std::optional<Est> est;
        try {
            est.emplace(opts);
            NSP_FUZZ_CHECK(valid);
        } catch (const InvalidArgument&) {
            NSP_FUZZ_CHECK(!valid);
            return;
        }
        const Ray ray = make_ray(in, box, {1, 1, 1});
        LookupCount counter;
        for (int i = 0; i < 2; ++i) {
            g_context = "path estimator radiance";
            RadianceSample<S> r;
            if constexpr (requires { typename Est::Channels; }) {
                std::optional<ChannelSelection<S>> sel;
                if (in.flag()) {
                    typename S::Spectrum w;
                    for (int c = 0; c < S::channels; ++c) w[c] = value(in);
                    try {
                        sel.emplace(w);
                        NSP_FUZZ_CHECK((w > 0.f).all());
                    } catch (const InvalidArgument&) {
                        // a weight <= 0, or weights whose probabilities round to 0
                    }
                }
                if (!sel) sel.emplace();
                r = est->radiance(*scene, ray, lambda, *sel, rng, counter);
            } else {
                r = est->radiance(*scene, ray, lambda, rng, counter);
            }
            // Status (core/status.hpp): the value is always finite; NonFinite replaced it by
            // 0; Rejected only under bound::Reject; Aborted needs 2^24 collisions, beyond the budget.
            NSP_FUZZ_CHECK(finite_all(r.value));
            if (r.status == Status::NonFinite) NSP_FUZZ_CHECK((r.value == 0.f).all());
            if (r.status == Status::Rejected) NSP_FUZZ_CHECK((std::is_same_v<typename Case::Bound, bound::Reject>));
            NSP_FUZZ_CHECK(r.status != Status::Aborted);
        }
    };
    if constexpr (Case::emissive) {
        bool bad = false;
        const BoxChoice eb = in.flag() ? BoxChoice{box, true} : make_box(in);
        const std::array<int, 3> res = make_res(in, 3);
        std::vector<float> v = make_voxels(in, res, bad);
        const auto le = coefficient<S>(in);
        const std::array<int, 3> power = make_res(in, 4);
        std::optional<Emissive<Base>> medium;
        try {
            medium.emplace(base, EmissionGrid(eb.box, res, std::move(v)), le, power);
            NSP_FUZZ_CHECK(!bad && eb.valid);
        } catch (const InvalidArgument&) {
            return;  // bad values, or a power grid too thin to tell its cells apart
        }
        go(*medium);
    } else {
        go(base);
    }
}

template <class S, class Base, class Lambda, std::size_t... I>
void run_estimator_any(Input& in, FuzzRng& rng, const Base& base, const Box& box, const Lambda& lambda,
                       std::index_sequence<I...>) {
    const int which = in.pick(int(sizeof...(I)));
    ((which == int(I) ? run_estimator<S, std::tuple_element_t<I, kEstimators>>(in, rng, base, box, lambda) : void()),
     ...);
}


/// A ray the kernels must refuse, from a usable one (see usable_ray), or a NaN distance.
struct BadRay {
    Ray ray;
    float tmax;
};

BadRay make_unusable(Input& in, Ray r, float tmax) {
    constexpr float nan = std::numeric_limits<float>::quiet_NaN();
    switch (in.pick(9)) {
        case 0: r.d *= 0.5f; break;
        case 1: r.d *= 1.01f; break;  // |d|^2 = 1.0201: outside kUnitTolerance
        case 2: r.d *= 2.f; break;
        case 3: r.d = Vec3(0.f); break;
        case 4: r.d.y = nan; break;
        case 5: r.d = Vec3(kInf, 0.f, 0.f); break;
        case 6: r.o.x = nan; break;
        case 7: r.o.z = -kInf; break;
        default: tmax = nan;
    }
    return {r, tmax};
}

/// Every public tracking entry and both path estimators on an unusable ray (see the header):
/// InvalidInput, no lookup and no estimate.
template <SpectralMode S, class M, class Lambda>
void run_unusable(Input& in, FuzzRng& rng, const M& medium, const std::array<int, 3>& res, const Lambda& lambda) {
    if (!in.flag()) return;  // also where the input has ended: the stage is new, the corpus predates it
    g_context = "unusable rays";
    using Spec = typename S::Spectrum;
    std::optional<GlobalMajorant<M>> maj;
    try {
        maj.emplace(medium);
    } catch (const InvalidArgument&) {
        return;
    }
    const Box b = medium.bounds();
    const BadRay bad = make_unusable(in, make_ray(in, b, res), make_tmax(in, b));
    const Ray& r = bad.ray;
    const float tmax = bad.tmax;
    LookupCount counter;
    auto none = [](float, const auto&, const auto&, const auto&) { return true; };
    const auto f = free_flight(medium, *maj, r, 0.f, tmax, lambda, rng, counter, none);
    NSP_FUZZ_CHECK(f.invalid && f.aborted && !f.stopped);
    const auto d = track_delta<absorption::Weight>(medium, *maj, r, tmax, lambda, rng, counter);
    NSP_FUZZ_CHECK(d.end == SegmentEnd::InvalidInput && (d.weight == 0.f).all());
    const auto t = track_ratio<absorption::Event, true>(medium, *maj, r, tmax, lambda, rng, counter);
    NSP_FUZZ_CHECK(t.end == SegmentEnd::InvalidInput && (t.transmittance == 0.f).all());
    for (const auto& sample : {transmittance_ratio(medium, *maj, r, tmax, lambda, rng, counter),
                               transmittance_delta(medium, *maj, r, tmax, lambda, rng, counter)})
        NSP_FUZZ_CHECK(sample.status == Status::InvalidInput && (sample.value == 0.f).all());
    ChannelPathState<S> st;
    const auto cd = track_channels_delta<channels::SpectralMis, absorption::Weight>(medium, *maj, r, tmax, lambda, 0, st,
                                                                                    true, rng, counter);
    NSP_FUZZ_CHECK(cd.end == SegmentEnd::InvalidInput);
    const auto cr = track_channels_ratio<channels::SpectralMis, absorption::Weight>(medium, *maj, r, tmax, lambda, 0,
                                                                                    Spec::Ones(), true, rng, counter);
    NSP_FUZZ_CHECK(cr.end == SegmentEnd::InvalidInput && (cr.f == 0.f).all());
    const VertexKernels<strategy::NullScatteringMis, mis::Balance> k;
    NSP_FUZZ_CHECK(k.track(medium, *maj, r, tmax, lambda, rng, counter).end == SegmentEnd::InvalidInput);
    NSP_FUZZ_CHECK(k.shadow(medium, *maj, r, tmax, lambda, rng, counter).status == Status::InvalidInput);
    NSP_FUZZ_CHECK(counter.count() == 0);
    if (std::isnan(tmax)) return;  // the estimators take a camera ray alone
    std::optional<Scene<M, GlobalMajorant<M>, IsotropicPhase>> scene;
    try {
        scene.emplace(medium, *maj, IsotropicPhase{}, Lights<S>{});
    } catch (const InvalidArgument&) {
        return;  // a majorant under which flights would run away (majorants/crossing.hpp)
    }
    const RadianceSample<S> p =
        PathEstimator<strategy::NullScatteringMis, mis::Balance>{}.radiance(*scene, r, lambda, rng, counter);
    NSP_FUZZ_CHECK(p.status == Status::InvalidInput && (p.value == 0.f).all());
    const RadianceSample<S> c = SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>{}
                                    .radiance(*scene, r, lambda, rng, counter);
    NSP_FUZZ_CHECK(c.status == Status::InvalidInput && (c.value == 0.f).all());
}

/// The trackers under a control (THEORY 5.10) on the input's medium, with a local generator (no
/// bytes read, so the corpus keeps its meaning): GridControl at the medium's resolution, a
/// TreeControl of its voxels (coarse 2^3 split wherever the bound varies), a ChannelGridControl
/// and a ChannelTreeControl (per channel) and GlobalControl at 0 (today's trackers) and at half the extinction bound (above the density where
/// the medium is thin: negative residuals). Decomposition tracking (track_delta, VertexKernels::track),
/// residual ratio tracking (track_ratio, VertexKernels::shadow, transmittance_residual_ratio) and
/// ray marching under the grid majorant: statuses Ok, Aborted or NonFinite, estimates and null
/// products finite, null products in [0, 1] and transmittances >= 0 up to rounding under the grid
/// control (a minorant: no negative residual). Skipped past the work budget, as the majorant cases are.
template <SpectralMode S, class M, class Lambda>
void run_controls(const M& medium, const std::array<int, 3>& res, const Lambda& lambda) {
    g_context = "controls";
    const Box b = medium.bounds();
    if (!(medium.max_extinction() * glm::length(b.hi - b.lo) <= kBudget)) return;
    std::optional<GridControl<M>> grid;
    std::optional<ChannelGridControl<M>> channel_grid;
    std::optional<ChannelTreeControl<M>> channel_tree;
    std::optional<TreeControl<M>> tree;
    std::optional<GridMajorant<M>> gmaj;
    std::optional<GlobalControl<M>> zero, half;
    try {
        grid.emplace(medium, res);
        channel_grid.emplace(medium, res);
        channel_tree.emplace(medium, TreeLayout{b, {2, 2, 2}, {2, 2, 0}, 0.f, 0.f});
        tree.emplace(medium, TreeLayout{b, {2, 2, 2}, {2, 2, 0}, 0.f, 0.f});
        gmaj.emplace(medium, res);
        zero.emplace(medium, constant_coefficient<S>(0.f));
        half.emplace(medium, constant_coefficient<S>(0.5f * medium.max_extinction()));
    } catch (const InvalidArgument&) {
        return;
    }
    const std::uint64_t seed = std::uint64_t(res[0]) * 131u + std::uint64_t(res[1]) * 17u + std::uint64_t(res[2]);
    Pcg32 rng(seed, 11);
    LookupCount counter;
    const VertexKernels<strategy::NullScatteringMis, mis::Balance> k;
    auto ok = [](Status st) { return st == Status::Ok || st == Status::Aborted || st == Status::NonFinite; };
    for (int i = 0; i < 4; ++i) {
        Vec3 d(2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f);
        d = glm::length(d) > 1e-3f ? glm::normalize(d) : Vec3(1.f, 0.f, 0.f);
        const Vec3 p = b.lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (b.hi - b.lo);
        const Ray ray{p - 2.f * glm::length(b.hi - b.lo) * d, d};
        const float tmax = i % 2 ? kInf : 2.f * glm::length(b.hi - b.lo) * rng.uniform();
        // Under a minorant every factor (R - r) / R lies in [0, 1] up to rounding (the control sits
        // 2^-20 below the density); a product of them is then >= -2e-5, the rounding-sized negative
        // null ratio tracking has (drive_grey; clang found -6e-8 under a control of 0). Where a
        // segment's majorant is below 1e-30 its residual majorant (>= 2^-20 of it) may be
        // subnormal and rounded to the 2^-149 grid: no sign is checked there.
        auto normal = [&](const auto& control) {
            auto it = control.iterate(ray, 0.f, tmax, lambda);
            while (auto s = it.next())
                if (s->sigma_maj > 0.f && s->sigma_maj < 1e-30f) return false;
            return true;
        };
        auto drive = [&](const auto& control, bool minorant_arg) {
            const bool minorant = minorant_arg && normal(control);
            const auto dt = track_delta<absorption::Weight>(medium, control, ray, tmax, lambda, rng, counter);
            NSP_FUZZ_CHECK(ok(flight_status(dt.end)) && all_finite(dt.weight) && std::isfinite(dt.null_pdf_product));
            NSP_FUZZ_CHECK(dt.null_pdf_product >= 0.f && dt.null_pdf_product <= 1.f);
            const auto rt = track_ratio<absorption::Event, true>(medium, control, ray, tmax, lambda, rng, counter);
            NSP_FUZZ_CHECK(ok(flight_status(rt.end)) && all_finite(rt.transmittance));
            NSP_FUZZ_CHECK(rt.null_pdf_product >= 0.f && rt.null_pdf_product <= 1.f);
            if (minorant) NSP_FUZZ_CHECK((rt.transmittance >= -2e-5f).all());
            const auto kt = k.track(medium, control, ray, tmax, lambda, rng, counter);
            NSP_FUZZ_CHECK(ok(flight_status(kt.end)) && all_finite(kt.weight));
            const auto ks = k.shadow(medium, control, ray, tmax, lambda, rng, counter);
            NSP_FUZZ_CHECK(ok(ks.status) && all_finite(ks.transmittance) && std::isfinite(ks.null_pdf_product));
            const auto rr = transmittance_residual_ratio(medium, control, ray, tmax, lambda, rng, counter, 4096);
            NSP_FUZZ_CHECK(ok(rr.status) && all_finite(rr.value));
            if (minorant) NSP_FUZZ_CHECK((rr.value >= -2e-5f).all());
            // Per channel (spectral MIS's trackers): finite states, pdfs >= 0.
            ChannelPathState<S> cst;
            const auto cd = track_channels_delta<channels::SpectralMis, absorption::Weight>(medium, control, ray, tmax,
                                                                                            lambda, 0, cst, true, rng, counter);
            NSP_FUZZ_CHECK(ok(flight_status(cd.end)) && all_finite(cst.f) && all_finite(cst.uni) && all_finite(cst.nee));
            NSP_FUZZ_CHECK((cst.uni >= 0.f).all() && (cst.nee >= 0.f).all());
            const auto cr = track_channels_ratio<channels::SpectralMis, absorption::Weight>(
                medium, control, ray, tmax, lambda, 0, S::Spectrum::Ones(), true, rng, counter);
            NSP_FUZZ_CHECK(ok(flight_status(cr.end)) && all_finite(cr.f) && all_finite(cr.nee) && all_finite(cr.uni));
            NSP_FUZZ_CHECK((cr.uni >= 0.f).all() && (cr.nee >= 0.f).all());
        };
        drive(*grid, true);
        drive(*tree, true);
        drive(*zero, true);
        drive(*half, false);
        // The per-channel grid and tree controls (each channel's own control and residual): the
        // channel trackers with every sampling channel, and transmittance_residual_ratio.
        auto drive_channels = [&](const auto& control) {
            for (int c = 0; c < S::channels; ++c) {
                ChannelPathState<S> cst;
                const auto cd = track_channels_delta<channels::SpectralMis, absorption::Weight>(
                    medium, control, ray, tmax, lambda, c, cst, true, rng, counter);
                NSP_FUZZ_CHECK(ok(flight_status(cd.end)) && all_finite(cst.f) && all_finite(cst.uni) &&
                               all_finite(cst.nee));
                NSP_FUZZ_CHECK((cst.uni >= 0.f).all() && (cst.nee >= 0.f).all());
                const auto cr = track_channels_ratio<channels::SpectralMis, absorption::Event>(
                    medium, control, ray, tmax, lambda, c, S::Spectrum::Ones(), true, rng, counter);
                NSP_FUZZ_CHECK(ok(flight_status(cr.end)) && all_finite(cr.f) && all_finite(cr.nee) && all_finite(cr.uni));
                NSP_FUZZ_CHECK((cr.uni >= 0.f).all() && (cr.nee >= 0.f).all());
            }
            const auto crr = transmittance_residual_ratio(medium, control, ray, tmax, lambda, rng, counter, 4096);
            NSP_FUZZ_CHECK(ok(crr.status) && all_finite(crr.value));
        };
        drive_channels(*channel_grid);
        drive_channels(*channel_tree);
        const auto rm = transmittance_ray_marching(medium, *gmaj, ray, tmax, lambda, rng, counter);
        NSP_FUZZ_CHECK(ok(rm.status) && all_finite(rm.value));
    }
}

// ---------------------------------------------------------------------------------------------

template <SpectralMode S>
void run(Input& in) {
    FuzzRng rng(in);
    g_context = "DenseGridMedium";
    const BoxChoice b = make_box(in);
    const std::array<int, 3> res = make_res(in, 4);
    bool bad = false;
    std::vector<float> density = make_voxels(in, res, bad);
    std::optional<DenseGridMedium<S>> medium;
    try {
        const auto sa = coefficient<S>(in);
        const auto ss = coefficient<S>(in);
        medium.emplace(b.box, res, std::move(density), sa, ss);
        NSP_FUZZ_CHECK(!bad && b.valid);
    } catch (const InvalidArgument&) {
        return;  // bad values, or values whose products overflow (media/validate.hpp)
    }
    typename S::Wavelengths lambda{};
    if constexpr (is_hero_v<S>) lambda = S::Wavelengths::sample(in.unit());
    run_tracking_any<S>(in, rng, *medium, res, lambda);
    run_estimator_any<S>(in, rng, *medium, b.box, lambda, std::make_index_sequence<std::tuple_size_v<kEstimators>>{});
    run_unusable<S>(in, rng, *medium, res, lambda);
    run_controls<S>(*medium, res, lambda);
}

}  // namespace
}  // namespace nsp_fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace nsp_fuzz;
    Input in(data, size);
    check_mis(in);
    // The spectral mode: a runtime index turned into a type once.
    switch (in.pick(3)) {
        case 0: run<nsp::Mono>(in); break;
        case 1: run<nsp::Rgb>(in); break;
        default: run<nsp::Hero<4>>(in); break;
    }
    check_channel_bdpt(in);
    check_bdpt_equiangular(in);
    return 0;
}
