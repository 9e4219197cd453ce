// nsp/estimators/common.hpp: what every path estimator shares: the path strategies (which
// techniques run and how they combine), run-time options, and the result type.
#pragma once

#include <cmath>
#include <concepts>
#include <cstdint>
#include <optional>
#include <type_traits>

#include "../core/error.hpp"
#include "../core/status.hpp"
#include "../options.hpp"
#include "../recorder.hpp"
#include "../equiangular.hpp"
#include "../light.hpp"
#include "../media/emissive.hpp"
#include "../pdf.hpp"
#include "../spectrum.hpp"
#include "../tracking.hpp"

namespace nsp {

/// What tracking would see at a vertex it did not draw itself (an equiangular or emission sample).
template <Medium M, class Maj>
struct UntrackedVertex {
    Coefficients<typename M::Spectral> k;  ///< the lookup, clamped to the majorant under bound::Clamp
    MajorantValue<Maj, M> mu;              ///< the majorant there (grey or per channel)
};

/// The probability with which the three-way MIS (strategy::EquiangularMis) draws an equiangular
/// vertex on a segment: min(1, p_eq(t*) / mu_bar(t*)) at the equiangular density's peak t*, with
/// the largest channel's majorant there. p_eq(t*) / mu_bar(t*) compares the equiangular density
/// with the largest density tracking can have where equiangular sampling concentrates: above 1
/// (a thin medium at the scale of the light's distance from the ray) tracking rarely puts a vertex
/// where the light's 1 / r^2 peaks, and every segment draws one; below it (a dense medium) tracking
/// already does, and an equiangular vertex, which costs a second flight and a second shadow ray,
/// is drawn on that fraction of the segments. One-sample MIS with an expected sample count (Veach
/// 1997, 9.2): the equiangular technique's pdf is this probability x its density in every weight
/// and every pdf sum, which keeps the estimator unbiased for any probability in (0, 1]. A function
/// of the segment alone (ray, stretch, light, majorant), so every technique evaluates the same
/// value. 1 where the majorant is 0 at the peak.
template <Medium M, MajorantPolicy<M> Maj>
float equiangular_probability(const Maj& majorant, const Ray& ray, const EquiangularSampler& eq,
                              const typename M::Spectral::Wavelengths& lambda) noexcept {
    const float t = eq.peak();
    const auto mu = majorant_value_at_point<M>(majorant, ray, t, lambda);
    float mu_max;
    if constexpr (std::is_same_v<std::remove_cvref_t<decltype(mu)>, float>) mu_max = mu;
    else mu_max = mu.maxCoeff();
    const float r = eq.pdf(t) / mu_max;  // inf where mu_max = 0; NaN only for pdf 0 and mu 0
    return r < 1.f ? r : 1.f;            // NaN and inf give 1
}

/// The probability with which strategy St draws a segment's equiangular vertex under `opts`:
/// equiangular_probability for the three-way MIS with adaptive_equiangular, else 1.
template <PathStrategy St, class Sc>
float equiangular_selection(const EstimatorOptions& opts, const Sc& scene, const Ray& ray, const EquiangularSampler& eq,
                            const typename Sc::Spectral::Wavelengths& lambda) noexcept {
    if (!St::combines || !opts.adaptive_equiangular) return 1.f;
    return equiangular_probability<typename Sc::MediumType>(scene.majorant, ray, eq, lambda);
}

/// One density lookup (counted) at distance t on `ray` with the majorant there, treated as
/// free_flight treats its lookups: clamped under bound::Clamp; std::nullopt under bound::Reject
/// where mu_t exceeds mu_bar (the estimator reports Status::Rejected).
template <Medium M, MajorantPolicy<M> Maj, LookupCounter C>
std::optional<UntrackedVertex<M, Maj>> lookup_untracked(const M& medium, const Maj& majorant, const Ray& ray, float t,
                                                        const typename M::Spectral::Wavelengths& lambda, C& counter) {
    using B = bound_policy_t<Maj>;
    counter.lookup();
    UntrackedVertex<M, Maj> v{medium.coefficients(ray.at(t), lambda), majorant_value_at_point<M>(majorant, ray, t, lambda)};
    if constexpr (std::is_same_v<B, bound::Clamp>) {
        detail::clamp_to_majorant(v.k, v.mu);
    } else if constexpr (std::is_same_v<B, bound::Reject>) {
        if (detail::exceeds_majorant(v.k, v.mu)) return std::nullopt;
    }
    return v;
}

/// A point y of the emitting volume drawn for NEE from x (THEORY 5.7), with the shadow ray toward
/// it and its squared distance.
struct EmissionSample {
    VolumeSample y;  ///< the point and its volume pdf p_V(y) > 0
    Ray shadow;      ///< from x toward y (unit direction)
    float dist = 0.f, dist2 = 0.f;
};

/// Draws y from the medium's power grid with four random numbers; std::nullopt when nothing
/// emits, y = x, or the sphere light blocks the way.
template <EmissiveMedium M, SpectralMode S, UniformRng R>
std::optional<EmissionSample> sample_emission_from(const M& medium, const Lights<S>& lights, const Vec3& x, R& rng) {
    const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
    EmissionSample e;
    e.y = medium.sample_emission(u0, u1, u2, u3);
    if (!(e.y.pdf > 0.f)) return std::nullopt;
    const Vec3 dv = e.y.p - x;
    e.dist2 = glm::dot(dv, dv);
    if (!(e.dist2 > 0.f)) return std::nullopt;
    e.dist = std::sqrt(e.dist2);
    e.shadow = Ray{x, dv / e.dist};
    if (lights.sphere_blocks(e.shadow, e.dist)) return std::nullopt;
    return e;
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
        const float p_seg = p.segment / count;
        const float drawn = t == EmissionTechnique::Collision ? p.collision
                            : t == EmissionTechnique::Segment ? p_seg
                                                              : p.nee;
        detail::record_emission(counter, unweighted * drawn, p.collision, p_seg, p.nee, count, t);
    } else {
        (void)counter, (void)unweighted, (void)p, (void)opts, (void)t;
    }
}

/// The segment technique's density p_seg(y) = p_V(y) / W for an emission NEE sample from x: W along
/// the ray from x toward y, to the sphere light it would hit or out of the medium (the segment
/// tracking would take; sample_emission_from left y before that light), times the technique's
/// count. 0 where the technique does not run (`opts.emission_along_segments` off, or W = 0).
template <class Sc>
float emission_segment_pdf(const EstimatorOptions& opts, const Sc& scene, const EmissionSample& e) noexcept {
    if (!opts.emission_along_segments) return 0.f;
    const float along = scene.medium.emission_along(e.shadow, 0.f, scene.lights.intersect(e.shadow).t);
    return segment_density(opts, e.y.pdf, along);
}

}  // namespace nsp
