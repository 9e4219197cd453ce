// nsp/vertex.hpp: path-vertex kernels, for a host renderer's own path loop and for nsp's
// estimators alike (THEORY 5.1, 5.6, 5.8). The host owns the geometry, the lights and the loop;
// these kernels own what null-scattering MIS needs from the media: the tracked segment and its
// null-pdf product, the shadow ray's transmittance with the pdf unidirectional tracking would have
// had for it, the roulette survival, and the MIS weights at an emitter hit and at a light sample,
// for a vertex on a surface (BSDF pdf) or in a medium (phase pdf).
//
// One path of a host's loop, grey (one pdf for every channel), with a VertexKernels `k`:
//
//     VertexPdf from = VertexPdf::from_camera();   // the last real vertex, for MIS
//     float nulls = 1;                              // prod P_n of the segments since then
//     for (int depth = 0;;) {
//         hit = host.intersect(ray);                // the surface the ray reaches (t = inf: none)
//         seg = k.track(medium, majorant, ray, hit.t, lambda, rng, counter);
//         if (seg.end is not Passed/Scattered) break;   // absorbed, or a failed flight (status)
//         beta *= seg.weight; nulls *= seg.null_pdf_product;
//         if (seg.end == Passed) {                  // the surface (or nothing) at hit.t
//             if (emitter && k.counts_hit(from)) L += beta * Le * k.hit_weight(from, nulls, light_pdf);
//             if (null interface) { switch media; ray = continue past it; continue; }   // no vertex
//             vertex = surface;                     // else a real surface vertex
//         }                                         // else a real medium vertex at seg.t
//         q = k.survival(++depth, beta);            // before NEE: both continuations share it
//         if (not a delta lobe && k.draw_nee(rng)) {   // draw_nee: always at the default nee_count 1
//             light = host.sample_light(x); sh = k.shadow(medium, majorant, shadow_ray, light.dist, ...);
//             L += beta * sh.transmittance * light.Le * f(wo, light.wi) *
//                  k.light_weight(q, pdf(wo, light.wi), sh.null_pdf_product, light.pdf, light.delta) /
//                  (light.pdf * k.nee_count()); }
//         roulette with q; sample wi from the BSDF or phase function; beta *= value / pdf;
//         from = VertexPdf::scattered(q, pdf, delta); nulls = 1; ray = {x, wi};
//     }
//
// A shadow ray that crosses media boundaries is one `shadow` per medium, their transmittances and
// null-pdf products multiplied; a path segment that crosses them multiplies its segments' products
// likewise. Per-channel path pdfs (SpectralPathEstimator's channel policies) are the business of
// track_channels_delta / track_channels_ratio and ChannelPathState (channel_tracking.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "mis.hpp"
#include "options.hpp"
#include "recorder.hpp"
#include "tracking.hpp"
#include "transmittance.hpp"

namespace nsp {

/// The unidirectional strategy's pdf of a light path segment relative to the shared prefix:
/// q p_w, times prod_j P_n(n_j) when the strategy uses null-scattering pdfs (THEORY 5.1, 5.6).
/// Both weights below use it, so the two sides of one path cannot disagree.
template <PathStrategy St>
float unidirectional_pdf(float survival, float direction_pdf, float null_pdf_product) noexcept {
    if constexpr (St::null_pdfs) return survival * direction_pdf * null_pdf_product;
    else return survival * direction_pdf;
}

/// MIS weight of the unidirectional technique for a path whose last segment, tracked from a real
/// vertex with roulette survival `survival` and direction pdf `direction_pdf` (phase or BSDF),
/// hit a light that NEE samples with solid-angle pdf `light_pdf`. `null_pdf_product` is
/// prod_j P_n(n_j) of the segment's nulls (used by NullScatteringMis only). THEORY 5.1, 5.2, 5.6.
template <PathStrategy St, mis::CombiningHeuristic H>
float unidirectional_weight(const H& h, float survival, float direction_pdf, float null_pdf_product,
                            float light_pdf) noexcept {
    // Both weights through weight_among with the same two pdfs, not h.weight of a ratio and of its
    // inverse: a ratio beyond float range (a denormal p_uni) made the two not sum to 1 under
    // Power with a small exponent (found by the fuzzer, tests/fuzz).
    return mis::weight_among(h, unidirectional_pdf<St>(survival, direction_pdf, null_pdf_product), light_pdf);
}

/// MIS weight of NEE for the same kind of path, sampled by the light (pdf `light_pdf` > 0) with
/// ratio tracking, whose nulls have delta-tracking product `null_pdf_product`. For one path,
/// unidirectional_weight + next_event_weight = 1.
template <PathStrategy St, mis::CombiningHeuristic H>
float next_event_weight(const H& h, float survival, float direction_pdf, float null_pdf_product,
                        float light_pdf) noexcept {
    return mis::weight_among(h, light_pdf, unidirectional_pdf<St>(survival, direction_pdf, null_pdf_product));
}

/// p_equiangular / p_tracking of a real vertex that delta tracking drew at distance t, from the
/// equiangular density there, the nulls' prod P_n and mu_bar(t) P_s(t) (DeltaTrack's
/// `event_density`). The shared factors (prefix, Tbar, mu_bar at the nulls) cancel; inf if the
/// tracking pdf underflowed to 0.
inline float equiangular_over_tracking(float eq_pdf, float null_pdf_product, float event_density) noexcept {
    return eq_pdf / (null_pdf_product * event_density);
}

/// p_tracking / p_equiangular of a real scattering vertex drawn by equiangular sampling with
/// density `eq_pdf` > 0, whose nulls ratio tracking drew with delta-tracking product
/// `null_pdf_product`, coefficients `c` and majorant `mu_bar` there: prod P_n mu_bar P_s / p_eq
/// (THEORY 5.4). 0 where tracking cannot collide (mu_bar = 0).
template <AbsorptionPolicy A, SpectralMode S>
float tracking_over_equiangular(float eq_pdf, float null_pdf_product, const Coefficients<S>& c, float mu_bar) noexcept {
    if (!(mu_bar > 0.f)) return 0.f;
    return null_pdf_product * mu_bar * event_probabilities<A>(c, mu_bar).scatter / eq_pdf;
}

/// The same under a grey control `ctl` > 0 (THEORY 5.10): decomposition tracking's density of the
/// vertex, the sum over its control and residual routes, with the pair's null product
/// exp(-tau_c) prod P_n,r.
template <AbsorptionPolicy A, SpectralMode S>
float tracking_over_equiangular(float eq_pdf, float null_pdf_product, const Coefficients<S>& c, float mu_bar,
                                float ctl) noexcept {
    if (!(ctl > 0.f)) return tracking_over_equiangular<A>(eq_pdf, null_pdf_product, c, mu_bar);
    return null_pdf_product * detail::decomposition_event_densities<A>(c, ctl, mu_bar).scatter / eq_pdf;
}

/// The MIS weight of technique `which` for one path, from the three techniques' pdfs relative to
/// any common reference (`track_nee`, `track_hit` = 0 for a point light, `eq_nee`). The three
/// weights of one path sum to 1.
template <mis::CombiningHeuristic H>
float equiangular_mis_weight(const H& h, VertexTechnique which, float track_nee, float track_hit, float eq_nee) noexcept {
    switch (which) {
        case VertexTechnique::TrackNee: return mis::weight_among(h, track_nee, track_hit, eq_nee);
        case VertexTechnique::TrackHit: return mis::weight_among(h, track_hit, track_nee, eq_nee);
        default: return mis::weight_among(h, eq_nee, track_nee, track_hit);
    }
}

/// The pdfs of the three emission techniques for one path whose last segment, from a real vertex
/// x (or the camera), reaches y at distance d, on a common scale, the largest 1. In volume measure
/// times d^2, the nulls' shared mu_bar Tbar factors left out (they cancel):
/// - collision: q p_w [prod_j P_n(n_j)] mu_bar(y), the product for null-scattering strategies only
///   (directional MIS leaves it out, as it does for lights);
/// - segment:   q p_w p_seg(y), p_seg the segment technique's density along the ray (0 where it
///   does not run);
/// - nee:       d^2 p_V(y) (volume_pdf 0 where NEE has no vertex to start from: the camera).
/// With roulette survival q and phase pdf p_w at x (1 and 1 for the camera ray). In double, so
/// neither the products nor d^2 p_V underflow into 0 / 0 (found by the fuzzer, tests/fuzz). All
/// zero when every pdf is; an infinite pdf stays inf and the others become 0 (emission_weight gives
/// it the whole weight); NaN in, NaN out (and inf x 0, e.g. an infinite p_seg with q = 0).
struct EmissionPdfs {
    float collision = 0.f, segment = 0.f, nee = 0.f;
};

template <PathStrategy St>
EmissionPdfs emission_pdfs(float survival, float phase_pdf, float null_pdf_product, float mu_bar, float segment_pdf,
                           float dist2, float volume_pdf) noexcept {
    const double direction = double(survival) * double(phase_pdf);
    double collision = direction * double(mu_bar);
    if constexpr (St::null_pdfs) collision *= double(null_pdf_product);
    const double segment = direction * double(segment_pdf), nee = double(dist2) * double(volume_pdf);
    const double largest = std::max({collision, segment, nee});
    if (std::isnan(collision + segment + nee)) {
        constexpr float nan = std::numeric_limits<float>::quiet_NaN();
        return {nan, nan, nan};
    }
    if (!(largest > 0.0)) return {};
    if (std::isinf(largest)) {  // an infinite pdf (a float input of inf) takes the weight: keep it inf, the rest 0
        auto keep = [](double x) { return std::isinf(x) ? kInf : 0.f; };
        return {keep(collision), keep(segment), keep(nee)};
    }
    return {float(collision / largest), float(segment / largest), float(nee / largest)};
}

/// The MIS weight of emission technique `which` for a path with pdfs `p`; the three weights of
/// one path sum to 1 (0 for a technique whose pdf is 0).
template <mis::CombiningHeuristic H>
float emission_weight(const H& h, EmissionTechnique which, const EmissionPdfs& p) noexcept {
    switch (which) {
        case EmissionTechnique::Collision: return mis::weight_among(h, p.collision, p.segment, p.nee);
        case EmissionTechnique::Segment: return mis::weight_among(h, p.segment, p.collision, p.nee);
        default: return mis::weight_among(h, p.nee, p.collision, p.segment);
    }
}

/// The segment technique's density of a point in the MIS weights, count x p_V / W (W = `along`,
/// its normaliser on the point's segment; opts.emission_segment_count the count): 0 where the
/// technique does not run (W = 0).
inline float segment_density(const EstimatorOptions& opts, float p_v, float along) noexcept {
    return along > 0.f ? opts.emission_segment_count * (p_v / along) : 0.f;
}

/// Records an emission contribution drawn by technique `t` on a MisRecorder (else nothing):
/// `unweighted` its channel mean without MIS weight or count (f over the drawing technique's
/// density), `p` the three techniques' pdfs on their common scale (emission_pdfs, vertex.hpp), the
/// segment's with opts.emission_segment_count in it.
template <class C, class Pdfs>
void record_emission_of(C& counter, float unweighted, const Pdfs& p, const EstimatorOptions& opts,
                        EmissionTechnique t) noexcept {
    if constexpr (MisRecorder<C>) {
        const float count = opts.emission_segment_count;
        const float p_seg = count > 0.f ? p.segment / count : 0.f;  // at count 0 p.segment is 0 too
        const float drawn = t == EmissionTechnique::Collision ? p.collision
                            : t == EmissionTechnique::Segment ? p_seg
                                                              : p.nee;
        detail::record_emission(counter, unweighted * drawn, p.collision, p_seg, p.nee, count, t);
    } else {
        (void)counter, (void)unweighted, (void)p, (void)opts, (void)t;
    }
}

/// The last real vertex of a path, as the MIS weight of whatever its next segments reach needs it.
struct VertexPdf {
    float survival = 1.f;       ///< the roulette survival probability the path passed there
    float direction_pdf = 0.f;  ///< solid-angle pdf of the direction drawn there (phase or BSDF)
    bool delta = false;         ///< drawn from a delta lobe: light sampling cannot produce it
    bool camera = true;         ///< no real vertex yet: the camera ray (no NEE alternative)

    /// The camera: what its ray reaches is weighted 1.
    static constexpr VertexPdf from_camera() noexcept { return {}; }
    /// A real vertex that drew its outgoing direction with `direction_pdf` after roulette survival.
    static constexpr VertexPdf scattered(float survival, float direction_pdf, bool delta = false) noexcept {
        return {survival, direction_pdf, delta, false};
    }
};

/// A shadow ray's transmittance through one medium, with the pdf ratio that NEE's MIS weight needs.
template <SpectralMode S>
struct ShadowTransmittance {
    typename S::Spectrum transmittance = S::Spectrum::Zero();  ///< unbiased per-channel estimate (ratio tracking)
    float null_pdf_product = 1.f;  ///< prod_j P_n(n_j) that delta tracking would have had at its nulls
    Status status = Status::Ok;    ///< Aborted or Rejected: the flight failed and contributes 0
};

/// The path-vertex kernels of strategy St (which techniques a path combines and whether their
/// pdfs include the nulls), MIS heuristic H (mis::None exactly for single strategies) and
/// absorption policy A of the tracked segments. One object ties the three together, so that a
/// shadow ray's null-pdf product is the one of the same delta tracking the path segments use, and
/// both weights of one path use the same pdfs: for every path, hit_weight + light_weight = 1.
/// Small and trivially copyable; every kernel is const, noexcept and allocates nothing.
template <PathStrategy St, mis::Heuristic H = mis::None, AbsorptionPolicy A = absorption::Weight>
class VertexKernels {
public:
    using Strategy = St;
    using Heuristic = H;
    using Absorption = A;

    /// Throws InvalidArgument on invalid roulette settings or counts (see EstimatorOptions), and
    /// on nee_count 0 with a strategy that reaches the lights by NEE alone and equiangular_count 0
    /// with one whose only NEE is from equiangular vertices.
    explicit VertexKernels(EstimatorOptions opts = {}, H heuristic = H{}) : opts_(opts), heuristic_(heuristic) {
        validate(opts);
        if (St::samples_lights && !St::hits_lights && opts.nee_count == 0.f)
            detail::fail("EstimatorOptions nee_count = 0 is not allowed with strategy ", St::name,
                         ": NEE is its only way to the lights (a count of 0 needs a strategy that also hits them)");
        if (opts.shadow_estimator == ShadowEstimator::RayMarching && (St::null_pdfs || !St::samples_lights))
            detail::fail("EstimatorOptions shadow_estimator = RayMarching is not allowed with strategy ", St::name,
                         St::null_pdfs ? ": its weights need the shadow rays' null-scattering pdfs, which ray marching "
                                         "has not (ratio-nee, directional-mis and equiangular-nee take it)"
                                       : ": it casts no shadow rays");
        if (St::equiangular && !St::combines && opts.equiangular_count == 0.f)
            detail::fail("EstimatorOptions equiangular_count = 0 is not allowed with strategy ", St::name,
                         ": its equiangular vertices are its only way to light scattered in the media (a count of 0 "
                         "needs strategy uni-nee-eq-mis)");
    }

    const EstimatorOptions& options() const noexcept { return opts_; }
    const H& heuristic() const noexcept { return heuristic_; }

    /// Delta-tracks `ray` through `medium` up to `t_max` (the host's surface distance, kInf for
    /// none): Scattered at a real vertex seg.t, Passed at t_max, Absorbed (absorption::Event), or
    /// a failed flight (flight_status(seg.end) says which). seg.weight multiplies the throughput;
    /// seg.null_pdf_product multiplies the path's product since its last real vertex. A ray that is
    /// not usable_ray (a non-finite origin, a direction that is not unit length) or a NaN or
    /// negative t_max ends SegmentEnd::InvalidInput (flight_status: Status::InvalidInput) with
    /// weight 0: bad host input is never tracked as if it were a ray.
    template <Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C>
    DeltaTrack<typename M::Spectral> track(const M& medium, const Maj& majorant, const Ray& ray, float t_max,
                                           const typename M::Spectral::Wavelengths& lambda, R& rng, C& counter) const {
        if (!valid_ray(ray, t_max)) return {SegmentEnd::InvalidInput, 0.f, M::Spectral::Spectrum::Zero(), 1.f};
        return track_delta<A>(medium, majorant, ray, t_max, lambda, rng, counter);
    }

    /// track(), calling `visit(t, coefficients, mu_bar, weight, null_pdf_product)` at every
    /// tentative collision before its event is chosen, with the weight and null-pdf product of
    /// the nulls before it (see DeltaCollision): the collision estimator of volume emission
    /// (THEORY 5.7) is such a visitor. Under a control, at every control and residual collision,
    /// with the medium's own coefficients, the segment's majorant and exp(-tau_c) in the null
    /// product (track_delta_visiting, THEORY 5.10). `Visit` has `static constexpr bool enabled = true`.
    template <Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C, class Visit>
    DeltaTrack<typename M::Spectral> track_visiting(const M& medium, const Maj& majorant, const Ray& ray, float t_max,
                                                    const typename M::Spectral::Wavelengths& lambda, R& rng,
                                                    C& counter, Visit visit) const {
        if (!valid_ray(ray, t_max)) return {SegmentEnd::InvalidInput, 0.f, M::Spectral::Spectrum::Zero(), 1.f};
        return track_delta_visiting<A>(medium, majorant, ray, t_max, lambda, rng, counter, std::move(visit));
    }

    /// The transmittance of a shadow ray through `medium` up to `distance` (ratio tracking; with
    /// EstimatorOptions::shadow_estimator RayMarching and a grey majorant, unbiased ray marching),
    /// and the product of the null probabilities delta tracking with policy A would have had at
    /// its nulls (only where St weighs by null-scattering pdfs; 1 otherwise). Never throws; bad
    /// input as for track() gives transmittance 0 and Status::InvalidInput.
    template <Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C>
    ShadowTransmittance<typename M::Spectral> shadow(const M& medium, const Maj& majorant, const Ray& ray,
                                                     float distance, const typename M::Spectral::Wavelengths& lambda,
                                                     R& rng, C& counter) const {
        if (!valid_ray(ray, distance)) return {M::Spectral::Spectrum::Zero(), 1.f, Status::InvalidInput};
        if constexpr (!St::null_pdfs && !is_per_channel_majorant_v<Maj, M>) {
            if (opts_.shadow_estimator == ShadowEstimator::RayMarching) {
                const auto m = transmittance_ray_marching(medium, majorant, ray, distance, lambda, rng, counter,
                                                          opts_.ray_marching);
                ShadowTransmittance<typename M::Spectral> s;
                s.status = m.status;
                if (m.status == Status::Ok) s.transmittance = m.value;
                return s;
            }
        }
        const auto tr = track_ratio<A, St::null_pdfs>(medium, majorant, ray, distance, lambda, rng, counter);
        ShadowTransmittance<typename M::Spectral> s;
        if (const Status fs = flight_status(tr.end); fs != Status::Ok) {
            s.status = fs;
            return s;
        }
        if (tr.end == SegmentEnd::Terminated) return s;  // every channel below float's range: 0
        s.transmittance = tr.transmittance;
        s.null_pdf_product = tr.null_pdf_product;
        return s;
    }

    /// The roulette survival probability at the path's `depth`-th real vertex (1-based) with
    /// throughput `beta`: 1 before EstimatorOptions::rr_start_depth, else min(rr_max_survival,
    /// max_c |beta_c|) (THEORY 5.6). Decide it before NEE: the unidirectional continuation carries
    /// it, so NEE's weight needs it.
    template <class Spectrum>
    float survival(int depth, const Spectrum& beta) const noexcept {
        if (!opts_.russian_roulette || depth < opts_.rr_start_depth) return 1.f;
        return std::min(opts_.rr_max_survival, float(beta.abs().maxCoeff()));
    }

    /// The expected count of NEE at a real vertex (EstimatorOptions::nee_count, THEORY 5.9): a
    /// light sample's estimate divides by it; hit_weight and light_weight already weigh NEE by it.
    float nee_count() const noexcept { return opts_.nee_count; }

    /// Whether NEE runs at this vertex: always at nee_count 1 (no random number drawn), else with
    /// probability nee_count (draw_technique). Decide it after the roulette survival.
    template <UniformRng R>
    bool draw_nee(R& rng) const {
        return draw_technique(opts_.nee_count, rng);
    }

    /// The MIS weight of an emitter that the path's segments from `from` reached, with the null
    /// products of those segments multiplied into `null_pdf_product`, and `light_pdf` the
    /// solid-angle pdf with which light sampling from `from` picks that point (light selection
    /// included; the weight multiplies it by nee_count()). 1 from the camera, after a delta lobe, or where light sampling cannot reach it
    /// (light_pdf 0); 1 for single strategies (the host adds a hit only if St::hits_lights).
    /// A NaN or negative pdf or product (bad host input) gives 0: the contribution is dropped,
    /// never turned into a NaN.
    float hit_weight(const VertexPdf& from, float null_pdf_product, float light_pdf) const noexcept {
        if constexpr (!St::combines) {
            (void)from, (void)null_pdf_product, (void)light_pdf;
            return 1.f;
        } else {
            if (from.camera || from.delta) return 1.f;
            if (!valid(from.survival, from.direction_pdf, null_pdf_product, light_pdf)) return 0.f;
            if (!(light_pdf > 0.f)) return 1.f;
            return unidirectional_weight<St>(heuristic_, from.survival, from.direction_pdf, null_pdf_product,
                                             light_pdf * opts_.nee_count);
        }
    }

    /// The MIS weight of a light sample drawn with solid-angle pdf `light_pdf` (selection
    /// included) from a real vertex with roulette survival `survival`, whose BSDF or phase
    /// function would draw that direction with `direction_pdf`; `null_pdf_product` from the shadow
    /// rays. 1 for a delta light (nothing else reaches it) and for single strategies; 0 for a NaN
    /// or negative pdf or product, as hit_weight. NEE's pdf is weighed as nee_count() x light_pdf;
    /// the caller still divides the estimate by nee_count().
    float light_weight(float survival, float direction_pdf, float null_pdf_product, float light_pdf,
                       bool delta_light) const noexcept {
        if constexpr (!St::combines) {
            (void)survival, (void)direction_pdf, (void)null_pdf_product, (void)light_pdf, (void)delta_light;
            return 1.f;
        } else {
            if (delta_light) return 1.f;
            if (!valid(survival, direction_pdf, null_pdf_product, light_pdf)) return 0.f;
            return next_event_weight<St>(heuristic_, survival, direction_pdf, null_pdf_product,
                                         light_pdf * opts_.nee_count);
        }
    }

    /// Whether the host adds an emitter that the segments from `from` reach: always under a
    /// strategy that counts hits, and otherwise from the camera and after a delta lobe, the paths
    /// light sampling cannot produce.
    static constexpr bool counts_hit(const VertexPdf& from) noexcept {
        return St::hits_lights || from.camera || from.delta;
    }

private:
    static bool valid_ray(const Ray& r, float t_max) noexcept {
        return usable_ray(r) && t_max >= 0.f;  // a NaN t_max fails the comparison
    }
    static bool valid(float survival, float direction_pdf, float null_pdf_product, float light_pdf) noexcept {
        return survival >= 0.f && direction_pdf >= 0.f && null_pdf_product >= 0.f && light_pdf >= 0.f;
    }

    EstimatorOptions opts_;
    [[no_unique_address]] H heuristic_;
};

}  // namespace nsp
