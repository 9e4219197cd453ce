// nsp/path_pdf.hpp: the per-channel path-pdf state behind spectral MIS (THEORY 5.1, 5.3, 5.6).
//
// A path is sampled with one channel c* (chosen with probability q_c*), and every channel c keeps
// its own contribution f_c and its own path pdf p_c of the same vertices. nsp never stores
// absolute path pdfs (they underflow): the state holds f_c / K and p_c / K for one common
// normaliser K, rescaled after every vertex so that the largest pdf is 1 (STYLE rule 7: O(C)
// numbers per technique, no C x C matrix). Every estimate is a ratio in which K cancels:
//
//     estimate_lambda = f_lambda / sum_c q_c (p_uni,c + p_nee,c)          (THEORY 5.3 with 5.1)
//
// The channel policies below decide what the pdfs are (each channel's own tracking, or one shared
// pdf) and which channels share a denominator. Equiangular sampling, emissive media and
// volumetric BDPT (ROADMAP 4, 6) add techniques to the same sum.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <type_traits>

#include "core/error.hpp"
#include "recorder.hpp"
#include "spectrum.hpp"

namespace nsp {

// ---------------------------------------------------------------------------------------------
// Channel policies (the tracking axis over channels)

namespace channels {
/// Independent tracking: one channel per path, tracked with its own majorant and event
/// probabilities; the other channels are estimated as zero and the chosen one is divided by its
/// selection probability (unbiased, colour noise).
struct Independent {
    static constexpr const char* name = "independent";
    static constexpr bool own_pdfs = true;           ///< each channel has its own tracking pdf
    static constexpr bool mis_over_channels = false; ///< channel c's estimate uses c's pdf alone
    static constexpr bool throughput_weighted = false;
};
/// Spectral tracking (Kutz et al. 2017), maximum variant: one grey majorant bounding every
/// channel, event probabilities from the channel maxima of mu_a, mu_s, mu_n; one pdf for all
/// channels, per-channel weights mu_x,c / (mu_bar P_x).
struct SpectralTrackingMax {
    static constexpr const char* name = "spectral-tracking-max";
    static constexpr bool own_pdfs = false;
    static constexpr bool mis_over_channels = true;  ///< one shared pdf: the sum is that pdf
    static constexpr bool throughput_weighted = false;
};
/// Spectral tracking, history-aware average variant: probabilities from sum_c |w_c| mu_x,c with
/// w the current path throughput.
struct SpectralTrackingAverage {
    static constexpr const char* name = "spectral-tracking-avg";
    static constexpr bool own_pdfs = false;
    static constexpr bool mis_over_channels = true;
    static constexpr bool throughput_weighted = true;
};
/// Spectral MIS (THEORY 5.3): each channel its own majorant and event probabilities, the channel
/// chosen per path, one-sample balance heuristic over channels.
struct SpectralMis {
    static constexpr const char* name = "spectral-mis";
    static constexpr bool own_pdfs = true;
    static constexpr bool mis_over_channels = true;
    static constexpr bool throughput_weighted = false;
};
}  // namespace channels

/// A channel policy says whether each channel has its own tracking pdf (`own_pdfs`: its own
/// majorant and event probabilities) or all share one, whether one channel's estimate combines
/// every channel's pdf (`mis_over_channels`), and whether shared event probabilities weigh the
/// channels by the path throughput (`throughput_weighted`).
template <class P>
concept ChannelPolicy = requires {
    { P::name } -> std::convertible_to<const char*>;
    { P::own_pdfs } -> std::convertible_to<bool>;
    { P::mis_over_channels } -> std::convertible_to<bool>;
    { P::throughput_weighted } -> std::convertible_to<bool>;
} && (P::own_pdfs || P::mis_over_channels);  // a shared pdf is one technique: nothing to keep apart

static_assert(ChannelPolicy<channels::Independent> && ChannelPolicy<channels::SpectralTrackingMax> &&
              ChannelPolicy<channels::SpectralTrackingAverage> && ChannelPolicy<channels::SpectralMis>);

// ---------------------------------------------------------------------------------------------
// Channel selection

/// The probabilities q_c with which a path's sampling channel is chosen (THEORY 5.3). They are
/// fixed before the path is sampled and may be non-uniform, e.g. proportional to luminance or to
/// a per-pixel estimate of each channel's contribution.
template <SpectralMode S>
class ChannelSelection {
public:
    using Spectrum = typename S::Spectrum;

    /// Uniform selection, q_c = 1 / C.
    ChannelSelection() : q_(Spectrum::Constant(1.f / float(S::channels))) { build_cdf(); }

    /// Selection proportional to `weights`. Throws InvalidArgument unless every weight is finite
    /// and > 0, their sum is finite and no probability rounds to 0: a channel that is never chosen
    /// would not be estimated at all by independent tracking, and spectral MIS would estimate it
    /// from the other channels' pdfs alone.
    explicit ChannelSelection(const Spectrum& weights) {
        for (int c = 0; c < S::channels; ++c)
            if (!std::isfinite(weights[c]) || !(weights[c] > 0.f))
                detail::fail("ChannelSelection weight[", c, "] = ", weights[c],
                             " is not allowed: every channel needs a finite weight > 0");
        const float sum = weights.sum();
        if (!std::isfinite(sum))
            detail::fail("ChannelSelection weights sum to ", sum, ", which is not allowed: the sum must be finite");
        q_ = weights / sum;
        for (int c = 0; c < S::channels; ++c)
            if (!(q_[c] > 0.f))
                detail::fail("ChannelSelection weight[", c, "] = ", weights[c], " is not allowed: its probability ",
                             weights[c], " / ", sum, " rounds to 0; every channel needs a probability > 0");
        build_cdf();
    }

    /// The probabilities q_c (summing to 1).
    const Spectrum& probabilities() const noexcept { return q_; }

    /// The channel chosen by u in [0, 1).
    int sample(float u) const noexcept {
        for (int c = 0; c + 1 < S::channels; ++c)
            if (u < cdf_[c]) return c;
        return S::channels - 1;
    }

private:
    void build_cdf() {
        float acc = 0.f;
        for (int c = 0; c < S::channels; ++c) cdf_[c] = (acc += q_[c]);
        cdf_[S::channels - 1] = 1.f;
    }

    Spectrum q_;
    Spectrum cdf_;
};

// ---------------------------------------------------------------------------------------------
// The state

/// What ChannelPathState::renormalize found.
enum class StateScale : std::uint8_t {
    Ok,          ///< rescaled; the path goes on
    Dead,        ///< no positive pdf was left: the path has weight 0 (the state is zeroed)
    Overflowed,  ///< a value the estimate needs left float's range: the state is zeroed and the sample discarded
};

namespace detail {
/// The equiangular pdf slot of a state whose strategy draws no equiangular vertices: nothing.
struct NoEquiangularPdf {};
}  // namespace detail

/// What a path carries per channel, all relative to one normaliser K (see the file comment):
/// `f` = f_c / K, `uni` = p_c / K of the path as sampled so far by unidirectional tracking with
/// channel c, and `nee` = the pdf / K with which next-event estimation from the last real vertex
/// would have produced the current segment's nulls (ratio tracking with channel c's majorant),
/// without the light pdf, which is only known where the segment ends (THEORY 5.1).
///
/// With `kEquiangular` (THEORY 5.4) the state also carries `eq.vertex` = the pdf / K with which
/// equiangular sampling on the current segment would have produced its nulls (ratio tracking)
/// and its last vertex, without the equiangular density, which the estimator multiplies in; and
/// `eq.nee` = the pdf / K of the path so far with the last real vertex drawn by equiangular
/// sampling and the current segment's nulls by NEE's ratio tracking (the equiangular + NEE
/// alternative of a light the segment hits). Other states carry an empty slot there.
template <SpectralMode S, bool kEquiangular = false>
struct ChannelPathState {
    using Spectrum = typename S::Spectrum;
    struct EquiangularPdfs {
        Spectrum vertex = Spectrum::Zero();
        Spectrum nee = Spectrum::Zero();
    };
    using EquiangularPdf = std::conditional_t<kEquiangular, EquiangularPdfs, detail::NoEquiangularPdf>;
    static constexpr bool equiangular = kEquiangular;

    Spectrum f = Spectrum::Ones();
    Spectrum uni = Spectrum::Ones();
    Spectrum nee = Spectrum::Zero();
    [[no_unique_address]] EquiangularPdf eq{};

    /// Rescales every pdf and f by one factor: by the sampling channel's pdf `uni[c]` when only
    /// that channel is ever estimated (independent tracking), else so that the largest pdf is 1.
    /// A common factor cancels in every ratio the estimate forms; what it cannot rescue is a ratio
    /// beyond float's range (f / p past FLT_MAX, a NaN from an optical depth that overflowed). Then
    /// the sample's value cannot be represented, the state is zeroed and `Overflowed` returned: the
    /// estimator discards the sample and reports it (Status::NonFinite), as it does a non-finite
    /// estimate. Under independent tracking only channel c counts; the others, never estimated,
    /// are zeroed where they overflowed. `Dead` (zeroed) when no positive pdf is left.
    /// Always inlined: it runs at every tentative collision, and GCC left it out of line in
    /// per-channel BDPT's tracking (BM_ChromaticSky: 5% faster inlined).
    template <ChannelPolicy CP>
    [[gnu::always_inline]] inline StateScale renormalize(int c) noexcept {
        float k = CP::mis_over_channels ? std::max(uni.maxCoeff(), nee.maxCoeff()) : uni[c];
        if constexpr (kEquiangular)
            if (CP::mis_over_channels) k = std::max(k, std::max(eq.vertex.maxCoeff(), eq.nee.maxCoeff()));
        if (!(k > 0.f) || !std::isfinite(k)) {
            set_zero();
            return k == 0.f ? StateScale::Dead : StateScale::Overflowed;
        }
        f /= k;
        uni /= k;
        nee /= k;
        if constexpr (kEquiangular) {
            eq.vertex /= k;
            eq.nee /= k;
        }
        if (!all_finite()) [[unlikely]] {  // one test per vertex; the rest only when a value overflowed
            if constexpr (CP::mis_over_channels) {
                set_zero();  // every channel is estimated: the sample is lost (fuzzer finding 10)
                return StateScale::Overflowed;
            } else {
                auto ok = (f.isFinite() && uni.isFinite() && nee.isFinite()).eval();  // before f changes
                if constexpr (kEquiangular) ok = ok && eq.vertex.isFinite() && eq.nee.isFinite();
                if (!ok[c]) {
                    set_zero();
                    return StateScale::Overflowed;
                }
                f = ok.select(f, 0.f);
                uni = ok.select(uni, 0.f);
                nee = ok.select(nee, 0.f);
                if constexpr (kEquiangular) {
                    eq.vertex = ok.select(eq.vertex, 0.f);
                    eq.nee = ok.select(eq.nee, 0.f);
                }
            }
        }
        return StateScale::Ok;
    }

private:
    bool all_finite() const noexcept {
        bool ok = f.allFinite() && uni.allFinite() && nee.allFinite();
        if constexpr (kEquiangular) ok = ok && eq.vertex.allFinite() && eq.nee.allFinite();
        return ok;
    }
    void set_zero() noexcept {
        f.setZero();
        uni.setZero();
        nee.setZero();
        if constexpr (kEquiangular) {
            eq.vertex.setZero();
            eq.nee.setZero();
        }
    }
};

/// The one-sample estimate of every channel from contributions `f` and the summed technique pdfs
/// `pdf` of each channel (same normaliser; sampling channel c, selection probabilities q):
/// f_lambda / sum_c q_c pdf_c with MIS over channels, else f_c / (q_c pdf_c) for c alone and 0
/// for the others. A zero denominator gives 0 (nothing was sampled there). Never NaN from 0/0.
template <ChannelPolicy CP, class Spec>
Spec channel_estimate(const Spec& f, const Spec& pdf, const Spec& q, int c) noexcept {
    if constexpr (CP::mis_over_channels) {
        const float d = (q * pdf).sum();
        return d > 0.f ? Spec(f / d) : Spec(Spec::Zero());
    } else {
        Spec out = Spec::Zero();
        const float d = q[c] * pdf[c];
        if (d > 0.f) out[c] = f[c] / d;
        return out;
    }
}

/// Records a light contribution of the spectral estimators on a MisRecorder (counts.hpp; else
/// nothing): channel_estimate's numerator `f` (every channel, the light's radiance included) and
/// its denominator split into the techniques' pdf sums, tracking that hits the light `uni`, NEE
/// from a tracked vertex or a surface without its count `nee`, and a technique of fixed count
/// `other` (equiangular + NEE). Under either policy the contribution is u / (d_uni + count d_nee +
/// d_other), u the channel mean of the numerator, which is what the learner needs.
template <ChannelPolicy CP, class C, class Spec>
void record_channels(C& counter, const Spec& f, const Spec& uni, const Spec& nee, const Spec& other, const Spec& q,
                     int c, float count, LightTechnique t) noexcept {
    if constexpr (MisRecorder<C>) {
        if constexpr (CP::mis_over_channels) {
            detail::record_light(counter, f.mean(), (q * uni).sum(), (q * nee).sum(), (q * other).sum(), count, t);
        } else {
            detail::record_light(counter, f[c] / float(Spec::SizeAtCompileTime), q[c] * uni[c], q[c] * nee[c],
                                 q[c] * other[c], count, t);
        }
    } else {
        (void)counter, (void)f, (void)uni, (void)nee, (void)other, (void)q, (void)c, (void)count, (void)t;
    }
}

/// Records a volume emission contribution of the spectral estimators on a MisRecorder (else
/// nothing), as record_channels: channel_estimate's numerator `f` and its denominator split into
/// the pdf sums of the collision estimator, the segment technique (with its count `count`, which
/// this divides out) and NEE toward the volume; `t` the technique that drew it.
template <ChannelPolicy CP, class C, class Spec>
void record_emission_channels(C& counter, const Spec& f, const Spec& collision, const Spec& segment, const Spec& nee,
                              const Spec& q, int c, float count, EmissionTechnique t) noexcept {
    if constexpr (MisRecorder<C>) {
        if constexpr (CP::mis_over_channels) {
            detail::record_emission(counter, f.mean(), (q * collision).sum(), (q * segment).sum() / count,
                                    (q * nee).sum(), count, t);
        } else {
            detail::record_emission(counter, f[c] / float(Spec::SizeAtCompileTime), q[c] * collision[c],
                                    q[c] * segment[c] / count, q[c] * nee[c], count, t);
        }
    } else {
        (void)counter, (void)f, (void)collision, (void)segment, (void)nee, (void)q, (void)c, (void)count, (void)t;
    }
}

}  // namespace nsp
