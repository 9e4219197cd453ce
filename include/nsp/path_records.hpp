// nsp/path_records.hpp: what the technique kernels hand the path state (nsp/path_state.hpp): the
// channel axes, one shadow piece and one shadow walk as the state's tracker returns them, where a
// walk ends, a real vertex as NEE sees it, a light sample with its walk and an emission point.
// Plain records, the same for the grey state and the per-channel one.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

#include "channel_tracking.hpp"
#include "core/counter.hpp"
#include "core/rng.hpp"
#include "majorant.hpp"
#include "mis.hpp"
#include "options.hpp"
#include "path_pdf.hpp"
#include "recorder.hpp"
#include "tracking.hpp"
#include "vertex.hpp"

namespace nsp {

namespace channels {
/// The grey axis: one pdf for every channel, event probabilities from the channel means under a
/// grey majorant (PathEstimator, BdptEstimator<..., Grey>). Exact for Mono and grey media; on
/// chromatic media the channels' weights multiply along a path (use a ChannelPolicy there).
struct Grey {
    static constexpr const char* name = "grey";
};
}  // namespace channels

/// True for the grey axis.
template <class Ch>
inline constexpr bool is_grey_axis_v = std::is_same_v<Ch, channels::Grey>;

/// A channel axis: channels::Grey, or a ChannelPolicy.
template <class Ch>
concept ChannelAxisOf = is_grey_axis_v<Ch> || ChannelPolicy<Ch>;

/// The type of a path's pdfs on axis Ch: one float (grey) or one per channel.
template <class Ch, SpectralMode S>
using PdfOf = std::conditional_t<is_grey_axis_v<Ch>, float, typename S::Spectrum>;

// ---------------------------------------------------------------------------------------------
// What the techniques hand the state

/// One piece of a shadow walk as the state's tracker returns it (ratio tracking through one
/// medium): `f` the piece's contribution (grey: its transmittance estimate; per channel: every
/// channel's prod mu_n,c Tbar_c; 0 where the estimate fell below float's range: the walk is
/// blocked), `nee` ratio tracking's pdf of its nulls and `uni` the pdf with which delta tracking
/// would have passed the same nulls (grey: 1 and prod P_n; per channel: every channel's, relative
/// to one normaliser); `status` a failed flight's.
template <class P, SpectralMode S>
struct ShadowPiece {
    Status status = Status::Ok;
    typename S::Spectrum f = S::Spectrum::Ones();
    P nee{};
    P uni{};
};

namespace detail {
/// One shadow piece on the grey axis: ratio tracking through medium (medium, majorant) with the
/// absorption policy of the kernels `k` (as VertexKernels::shadow), its null product where the
/// strategy weighs by null-scattering pdfs. The tracker is called itself: the flight checks the
/// ray (usable_ray, a NaN distance: Status::InvalidInput), which VertexKernels::shadow, made for a
/// host's rays, would check once more.
template <class K, class Med, class Maj, UniformRng R, LookupCounter C>
ShadowPiece<float, typename Med::Spectral> grey_shadow_piece(const K& k, const Med& medium, const Maj& majorant,
                                                             const Ray& r, float t_max,
                                                             const typename Med::Spectral::Wavelengths& lambda, R& rng,
                                                             C& counter) {
    (void)k;
    ShadowPiece<float, typename Med::Spectral> out;
    out.nee = 1.f;
    out.uni = 1.f;
    if (!(t_max >= 0.f)) [[unlikely]] {  // a negative or NaN distance: nothing to track
        out.status = Status::InvalidInput;
        out.f = Med::Spectral::Spectrum::Zero();
        return out;
    }
    if constexpr (!K::Strategy::null_pdfs && !is_per_channel_majorant_v<Maj, Med>) {
        if (k.options().shadow_estimator == ShadowEstimator::RayMarching) {  // no pdf needed (THEORY 5.10)
            const auto m = transmittance_ray_marching(medium, majorant, r, t_max, lambda, rng, counter,
                                                      k.options().ray_marching);
            out.status = m.status;
            out.f = m.status == Status::Ok ? m.value : Med::Spectral::Spectrum::Zero();
            return out;
        }
    }
    const auto tr = track_ratio<typename K::Absorption, K::Strategy::null_pdfs>(medium, majorant, r, t_max, lambda,
                                                                               rng, counter);
    out.status = flight_status(tr.end);
    if (out.status != Status::Ok || tr.end == SegmentEnd::Terminated) {  // failed, or below float's range: 0
        out.f = Med::Spectral::Spectrum::Zero();
        return out;
    }
    out.f = tr.transmittance;
    out.uni = tr.null_pdf_product;
    return out;
}

/// One shadow piece per channel: ratio tracking with channel c's majorant and every channel's
/// pdfs (track_channels_ratio; `weights` the throughput throughput-weighted spectral tracking
/// needs, `uni_alternative` whether delta tracking's pdf of the nulls is wanted).
template <ChannelPolicy CP, AbsorptionPolicy A, class Med, class Maj, UniformRng R, LookupCounter C>
ShadowPiece<typename Med::Spectral::Spectrum, typename Med::Spectral> channel_shadow_piece(
    const Med& medium, const Maj& majorant, const Ray& r, float t_max, const typename Med::Spectral::Wavelengths& lambda,
    int c, const typename Med::Spectral::Spectrum& weights, bool uni_alternative, R& rng, C& counter) {
    const auto sh = track_channels_ratio<CP, A>(medium, majorant, r, t_max, lambda, c, weights, uni_alternative, rng,
                                                counter);
    ShadowPiece<typename Med::Spectral::Spectrum, typename Med::Spectral> out;
    if (sh.end == SegmentEnd::Passed) {
        out.f = sh.f;
        out.nee = sh.nee;
        out.uni = sh.uni;
    } else {
        out.status = sh.end == SegmentEnd::Terminated ? Status::Ok : flight_status(sh.end);
        out.f.setZero();
        out.nee.setZero();
        out.uni.setZero();
    }
    return out;
}
}  // namespace detail

/// Where a shadow walk ends: at `distance` (kInf: a light at infinity), in any medium, or only
/// where it finds the point inside medium `target` (NEE toward an emitting medium); `margin`: the
/// end is on a surface or light (the last 1e-4 of the way blocks nothing); `with_along`: the
/// segment technique's normaliser W on the last piece, up to the surface beyond the end.
struct WalkEnd {
    float distance = kInf;
    int target = -2;  ///< -2: any medium
    bool margin = true;
    bool with_along = false;
    int light = -1;  ///< the light the walk ends on (a light sample's index), -1: none
};

/// A shadow walk's result (estimators/scene_walk.hpp): its status; `f`, `nee`, `uni` the pieces'
/// products relative to one normaliser (as ShadowPiece); `seg` the segment technique's pdf of the
/// nulls (uni of the pieces before the last, nee of the last one; grey: the null product of the
/// pieces before the last); `reached` whether it got to the
/// end (not blocked, in the target medium); the last piece (`last`.at(`t_last`) is the end), the
/// medium it ends in and W there (with_along).
template <class P, SpectralMode S>
struct ShadowWalk {
    Status status = Status::Ok;
    bool reached = false;
    typename S::Spectrum f = S::Spectrum::Zero();
    P nee{}, uni{}, seg{};
    P uni_last{};  ///< the last piece's own uni (grey: the null product of the end point's piece)
    Ray last{};
    float t_last = 0.f;
    int end_medium = -1;
    float along = 0.f;
};

/// A real vertex as NEE sees it: `f` the path's contribution up to x and the pdfs with which
/// tracking (`p_track`) and equiangular sampling (`p_eq`, 0 where it cannot draw x) draw it, on
/// one scale (grey: relative to the pdf of the technique that drew x, so a tracked vertex has
/// p_track 1 and f the throughput; per channel: the state's normaliser); `survival` the roulette
/// survival tracking's continuation carries there; `eq_drawn`: x is an equiangular vertex (NEE
/// from it has count 1).
template <class P, SpectralMode S>
struct VertexRecord {
    typename S::Spectrum f = S::Spectrum::Zero();
    P p_track{};
    P p_eq{};
    float survival = 1.f;
    bool eq_drawn = false;
};

/// A light sample of NEE from a real vertex and its shadow walk: the vertex's value toward the
/// light (BSDF x cosine or phase) and that direction's pdf there, the light's radiance, solid-angle
/// pdf (selection included) and whether it is a delta light.
template <class P, SpectralMode S>
struct LightNee {
    typename S::Spectrum value = S::Spectrum::Zero();
    float direction_pdf = 0.f;
    typename S::Spectrum radiance = S::Spectrum::Zero();
    float light_pdf = 0.f;
    bool delta = false;
    ShadowWalk<P, S> walk;
};

/// An emission point y on a path's piece (the segment technique) or in the volume (NEE toward it),
/// after the walk to it and the lookup there: mu_a L_e at y (`source`), the majorant there, the
/// point's densities (the power grid's p_V, its medium's selection probability, W on its piece,
/// the distance from the last real vertex) and the walk's factors.
template <class P, SpectralMode S, class Walk = ShadowWalk<P, S>>
struct EmissionPoint {
    typename S::Spectrum source = S::Spectrum::Zero();
    P mu_bar{};
    float p_v = 0.f, select = 0.f, along = 0.f, distance = 0.f;
    float sampled_pdf = 0.f;  ///< the density the technique drew y with (the segment technique's ds.pdf)
    Walk walk{};              ///< a ShadowPiece on the point's own piece (the segment technique) or a ShadowWalk (NEE)
};

// ---------------------------------------------------------------------------------------------

template <class Ch, PathStrategy St, mis::Heuristic H, AbsorptionPolicy A, SpectralMode S, bool kEq = false>
class PathState;

}  // namespace nsp
