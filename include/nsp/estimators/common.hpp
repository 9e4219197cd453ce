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
#include "../counts.hpp"
#include "../equiangular.hpp"
#include "../light.hpp"
#include "../media/emissive.hpp"
#include "../pdf.hpp"
#include "../spectrum.hpp"
#include "../tracking.hpp"

namespace nsp {

namespace strategy {
/// Delta tracking; lights contribute when a path hits them.
struct Unidirectional {
    static constexpr const char* name = "unidirectional";
    static constexpr bool samples_lights = false, hits_lights = true, combines = false, null_pdfs = false;
    static constexpr bool equiangular = false;
};
/// Next-event estimation with ratio-tracking transmittance; hits count only for camera rays.
struct NextEvent {
    static constexpr const char* name = "ratio-nee";
    static constexpr bool samples_lights = true, hits_lights = false, combines = false, null_pdfs = false;
    static constexpr bool equiangular = false;
};
/// Unidirectional + NEE weighted by direction pdfs only (THEORY 5.2).
struct DirectionalMis {
    static constexpr const char* name = "directional-mis";
    static constexpr bool samples_lights = true, hits_lights = true, combines = true, null_pdfs = false;
    static constexpr bool equiangular = false;
};
/// Unidirectional + NEE weighted by null-scattering path pdfs (THEORY 5.1).
struct NullScatteringMis {
    static constexpr const char* name = "uni-nee-mis";
    static constexpr bool samples_lights = true, hits_lights = true, combines = true, null_pdfs = true;
    static constexpr bool equiangular = false;
};
/// Equiangular sampling + NEE (THEORY 5.4): on every segment of the path (the camera ray
/// included) a real vertex drawn with the equiangular pdf toward the point light (else the
/// sphere light's centre), the nulls before it ratio-tracked, and NEE from it; tracked vertices
/// only continue the path. Lights count when hit only on camera rays. Without a point or sphere
/// light there is nothing to aim at and it is NextEvent.
struct EquiangularNextEvent {
    static constexpr const char* name = "equiangular-nee";
    static constexpr bool samples_lights = true, hits_lights = false, combines = false, null_pdfs = false;
    static constexpr bool equiangular = true;
};
/// Unidirectional + NEE + equiangular: the last real vertex before a light drawn by tracking or
/// by equiangular sampling, the light reached by NEE or (from a tracked vertex) by hitting it;
/// the three techniques weighted by their null-scattering path pdfs (THEORY 5.1, 5.4).
struct EquiangularMis {
    static constexpr const char* name = "uni-nee-eq-mis";
    static constexpr bool samples_lights = true, hits_lights = true, combines = true, null_pdfs = true;
    static constexpr bool equiangular = true;
};
}  // namespace strategy

/// A path strategy: which techniques it runs (light sampling, light hits, equiangular vertices)
/// and whether it combines them with MIS, weighing by null-scattering path pdfs or not.
template <class T>
concept PathStrategy = requires {
    { T::name } -> std::convertible_to<const char*>;
    { T::samples_lights } -> std::convertible_to<bool>;
    { T::hits_lights } -> std::convertible_to<bool>;
    { T::combines } -> std::convertible_to<bool>;
    { T::null_pdfs } -> std::convertible_to<bool>;
    { T::equiangular } -> std::convertible_to<bool>;
};

/// Run-time settings of a path estimator.
struct EstimatorOptions {
    int max_depth = 1000;          ///< most real scattering vertices on a path (>= 0)
    bool russian_roulette = true;  ///< roulette at real vertices from `rr_start_depth` on
    int rr_start_depth = 3;        ///< first real vertex (1-based) at which roulette may stop a path
    float rr_max_survival = 0.95f; ///< survival q = min(rr_max_survival, max_c |throughput_c|), in (0, 1]
    /// strategy::EquiangularMis: draw the equiangular vertex of a segment with the probability of
    /// equiangular_probability (below) instead of on every segment. Off: on every segment.
    bool adaptive_equiangular = true;
    /// The combining strategies on an emissive medium: on every segment also draw one point in
    /// proportion to the emitted power along the segment (the segment technique of THEORY 5.7,
    /// the nulls before it ratio-tracked), combined with the collision estimator and NEE toward
    /// the volume by MIS. It is the only sampling technique for the emission a camera ray sees
    /// directly. Off: collisions and NEE only. No effect on other media or strategies.
    /// nsp::BdptEstimator<bdpt::NullScattering> (grey and per channel) draws it on every piece of
    /// a camera segment in an emitting medium, one more strategy among the (s, t) ones (THEORY 5.7
    /// in 5.5); directional MIS leaves it out.
    bool emission_along_segments = true;
    /// The expected count of the segment technique on each segment, in (0, 1] (THEORY 5.9,
    /// counts.hpp; with emission_along_segments on): it runs on a segment with this probability,
    /// its estimate divided by it, and every emission weight takes count x p_seg. 1: on every
    /// segment. Below 1 it saves the technique's flight and lookup where the collision estimator
    /// and NEE find the emission well; the power grid's walk along the segment stays (the other
    /// techniques' weights need W). nsp::PathEstimator and nsp::SpectralPathEstimator, media and
    /// surfaces, and nsp::BdptEstimator (on the camera segments' pieces; NeeCountLearner does
    /// not learn it there).
    float emission_segment_count = 1.f;
    /// The expected count of NEE toward the lights at each real vertex, in (0, 1] (THEORY 5.9,
    /// counts.hpp): NEE runs there with this probability, its estimate divided by it, and the MIS
    /// weights of both techniques take nee_count x the light pdf. 1: NEE at every vertex. Below 1
    /// it trades variance for the shadow rays' cost where tracking finds the light well (a large
    /// light, an environment); NeeCountLearner chooses it per pixel tile. nsp::PathEstimator and
    /// nsp::SpectralPathEstimator (every strategy that samples lights, NEE from equiangular
    /// vertices excepted: they exist for it); nsp::BdptEstimator (s = 1 toward the lights at each
    /// camera vertex; NEE toward an emitting volume keeps count 1).
    float nee_count = 1.f;
    /// nsp::BdptEstimator<bdpt::NullScattering> (grey and per channel): on every camera segment
    /// also draw one vertex by equiangular sampling toward the point lights on the part of the ray
    /// inside the media's bounding box, the nulls before it ratio-tracked, and connect it to the
    /// lights by NEE: one more strategy among the (s, t) ones, weighed with its analytic pdf
    /// (THEORY 5.4 in 5.5). Only where the scene has a point light (delta lights with a target;
    /// lights a path can hit have tracking's hits besides) and a medium. Directional MIS has no
    /// distance pdfs to weigh it by and leaves it out. The path estimators choose equiangular
    /// sampling by their strategy instead.
    bool bdpt_equiangular = true;
};

/// A radiance estimate and its status.
template <SpectralMode S>
struct RadianceSample {
    typename S::Spectrum value;
    Status status = Status::Ok;
};

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

/// Throws InvalidArgument on max_depth < 0, rr_start_depth < 1 or rr_max_survival outside (0, 1].
inline void validate(const EstimatorOptions& opts) {
    if (opts.max_depth < 0)
        detail::fail("EstimatorOptions max_depth = ", opts.max_depth, " is not allowed: it must be >= 0");
    if (opts.rr_start_depth < 1)
        detail::fail("EstimatorOptions rr_start_depth = ", opts.rr_start_depth, " is not allowed: it must be >= 1");
    if (!(opts.rr_max_survival > 0.f && opts.rr_max_survival <= 1.f))
        detail::fail("EstimatorOptions rr_max_survival = ", opts.rr_max_survival,
                     " is not allowed: it must lie in (0, 1]");
    validate_count("EstimatorOptions nee_count", opts.nee_count);
    validate_count("EstimatorOptions emission_segment_count", opts.emission_segment_count);
}

}  // namespace nsp
