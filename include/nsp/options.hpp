// nsp/options.hpp: what every estimator and path-vertex kernel shares and nothing more: the path
// strategies (which techniques run and how they combine), the run-time options, the result type,
// the techniques' names, and the expected-count draw (THEORY 5.9). Below vertex.hpp and the
// estimators, so that a header needing them pulls in no estimator.
#pragma once

#include <concepts>
#include <cstdint>

#include "core/error.hpp"
#include "core/rng.hpp"
#include "core/status.hpp"
#include "spectrum.hpp"

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

/// Settings of unbiased ray marching (transmittance_ray_marching, nsp/transmittance.hpp).
struct RayMarchingOptions {
    /// Lookups of one comb per unit of the majorant's optical depth along the ray (the comb has
    /// ceil(this x tau_bar) lookups, at least min_lookups and at most max_lookups).
    float lookups_per_depth = 1.f;
    int min_lookups = 2;
    int max_lookups = 1 << 16;
    /// The roulette that ends the series: after the k-th term (weighted by the inverse of the
    /// probabilities so far), the next is taken with probability min(1, |term| / term_scale)
    /// (largest channel); a term of 0 ends it.
    float term_scale = 0.01f;
    /// The highest order: the roulette practically never gets there (a term's size falls as 1/k!),
    /// and the estimate ends with Status::Aborted (value 0) if it does.
    int max_order = 64;
};

/// Throws InvalidArgument on RayMarchingOptions outside their ranges: lookups_per_depth finite and
/// > 0, 1 <= min_lookups <= max_lookups <= 2^24, term_scale finite and > 0, max_order in [1, 1024].
inline void validate(const RayMarchingOptions& o) {
    if (!(o.lookups_per_depth > 0.f) || !(o.lookups_per_depth <= 3.4e38f))
        detail::fail("RayMarchingOptions lookups_per_depth = ", o.lookups_per_depth,
                     " is not allowed: it must be finite and > 0");
    if (o.min_lookups < 1 || o.max_lookups < o.min_lookups || o.max_lookups > (1 << 24))
        detail::fail("RayMarchingOptions min_lookups = ", o.min_lookups, ", max_lookups = ", o.max_lookups,
                     " is not allowed: they must satisfy 1 <= min_lookups <= max_lookups <= 2^24");
    if (!(o.term_scale > 0.f) || !(o.term_scale <= 3.4e38f))
        detail::fail("RayMarchingOptions term_scale = ", o.term_scale, " is not allowed: it must be finite and > 0");
    if (o.max_order < 1 || o.max_order > 1024)
        detail::fail("RayMarchingOptions max_order = ", o.max_order, " is not allowed: it must lie in [1, 1024]");
}

/// How a path estimator estimates a shadow ray's transmittance (EstimatorOptions::shadow_estimator).
enum class ShadowEstimator : std::uint8_t {
    RatioTracking,  ///< ratio tracking under the scene's majorant: every strategy (its null pdfs are what null-scattering MIS weighs)
    RayMarching,    ///< unbiased ray marching under the scene's grey majorant (THEORY 5.10): strategies without null-scattering pdfs
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
    /// The expected count of the equiangular vertex on each piece of a segment, in [0, 1] (THEORY
    /// 5.9, counts.hpp), for the strategies with equiangular sampling: the piece draws it with
    /// probability equiangular_count (x equiangular_probability where adaptive_equiangular applies),
    /// its estimate divided by that, and every weight takes the product x its density. 1: as
    /// without counts. 0: strategy::EquiangularMis never draws it and it is absent from every
    /// weight, so the estimator is exactly uni + NEE MIS (tracking and NEE from tracked vertices
    /// reach every light it reaches); strategy::EquiangularNextEvent reaches the lights from its
    /// equiangular vertices alone and refuses 0 at construction. nsp::PathEstimator and
    /// nsp::SpectralPathEstimator; nsp::BdptEstimator's equiangular strategy is on or off
    /// (bdpt_equiangular).
    float equiangular_count = 1.f;
    /// The combining strategies on an emissive medium: on every segment also draw one point in
    /// proportion to the emitted power along the segment (the segment technique of THEORY 5.7,
    /// the nulls before it ratio-tracked), combined with the collision estimator and NEE toward
    /// the volume by MIS. It is the only sampling technique for the emission a camera ray sees
    /// directly. Off: collisions and NEE only. No effect on other media or strategies.
    /// nsp::BdptEstimator<bdpt::NullScattering> (grey and per channel) draws it on every piece of
    /// a camera segment in an emitting medium, one more strategy among the (s, t) ones (THEORY 5.7
    /// in 5.5); directional MIS leaves it out.
    bool emission_along_segments = true;
    /// The expected count of the segment technique on each segment, in [0, 1] (THEORY 5.9,
    /// counts.hpp; with emission_along_segments on): it runs on a segment with this probability,
    /// its estimate divided by it, and every emission weight takes count x p_seg. 1: on every
    /// segment. Below 1 it saves the technique's flight and lookup where the collision estimator
    /// and NEE find the emission well; the power grid's walk along the segment stays (the other
    /// techniques' weights need W). 0: it never runs and is absent from every weight (the
    /// collision estimator reaches all emission, so nothing is lost). nsp::PathEstimator and
    /// nsp::SpectralPathEstimator, media and surfaces, and nsp::BdptEstimator (on the camera
    /// segments' pieces; NeeCountLearner does not learn it there).
    float emission_segment_count = 1.f;
    /// The expected count of NEE toward the lights at each real vertex, in [0, 1] (THEORY 5.9,
    /// counts.hpp): NEE runs there with this probability, its estimate divided by it, and the MIS
    /// weights of both techniques take nee_count x the light pdf. 1: NEE at every vertex. Below 1
    /// it trades variance for the shadow rays' cost where tracking finds the light well (a large
    /// light, an environment); NeeCountLearner chooses it per pixel tile. 0: NEE never runs and
    /// is absent from every weight, so a combining strategy is exactly tracking + hits; allowed
    /// only where every light can be hit: a strategy that reaches lights by NEE alone (ratio-nee,
    /// equiangular-nee) refuses it at construction, and a scene with a delta light (a point or
    /// directional light) gives Status::InvalidInput and 0 (LightSampler::has_delta_lights()). A
    /// light the host's geometry never reports as hit is the host's to leave out.
    /// nsp::PathEstimator and nsp::SpectralPathEstimator (every strategy that samples lights, NEE
    /// from equiangular vertices excepted: they exist for it); nsp::BdptEstimator (s = 1 toward
    /// the lights at each camera vertex; NEE toward an emitting volume keeps count 1).
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
    /// How shadow rays (NEE, and the nulls before an equiangular vertex) estimate their
    /// transmittance. RayMarching: unbiased ray marching (nsp/transmittance.hpp, THEORY 5.10;
    /// fewer lookups x variance than ratio tracking on every example medium, worse where a
    /// medium's detail is finer than its comb) with `ray_marching`'s settings; it has no path pdf,
    /// so only nsp::PathEstimator with strategy::NextEvent, DirectionalMis or EquiangularNextEvent
    /// takes it (and VertexKernels::shadow for a host's own loop with them); the others refuse it
    /// at construction. Its estimate is unbiased but may leave [0, 1].
    ShadowEstimator shadow_estimator = ShadowEstimator::RatioTracking;
    RayMarchingOptions ray_marching{};
};

/// A radiance estimate and its status.
template <SpectralMode S>
struct RadianceSample {
    typename S::Spectrum value;
    Status status = Status::Ok;
};

/// Whether a technique with expected count `count` in [0, 1] runs this time: always at count >= 1
/// (no random number drawn, so a count of 1 leaves the random stream as without counts), else
/// with probability count (one number drawn; at count 0 never). Testing for 0 before the draw
/// made the grey path tracers' loops 2% longer in instructions at count 1, so 0 draws too.
template <UniformRng R>
bool draw_technique(float count, R& rng) {
    return count >= 1.f || rng.uniform() < count;
}

/// Throws InvalidArgument unless `count` lies in (0, 1], or in [0, 1] where `zero_allowed` (a
/// technique that other techniques cover, THEORY 5.9); `what` names the option.
inline void validate_count(const char* what, float count, bool zero_allowed = false) {
    if (zero_allowed) {
        if (!(count >= 0.f && count <= 1.f))
            detail::fail(what, " = ", count,
                         " is not allowed: an expected sample count must lie in [0, 1] (0: the technique never runs)");
    } else if (!(count > 0.f && count <= 1.f)) {
        detail::fail(what, " = ", count, " is not allowed: an expected sample count must lie in (0, 1]");
    }
}

/// Which technique produced a light contribution a MisRecorder sees.
enum class LightTechnique : std::uint8_t {
    Hit,    ///< tracking hit the light (count 1)
    Nee,    ///< NEE from a tracked vertex or a surface, drawn with the NEE count
    Other,  ///< a technique whose count the learner does not change (NEE from an equiangular vertex)
};

/// The three techniques that can produce volume emission at a point y of a segment (THEORY 5.7).
enum class EmissionTechnique : std::uint8_t {
    Collision,  ///< y a tentative collision of the delta-tracked segment (the collision estimator)
    Segment,    ///< y drawn on the segment in proportion to the power grid along it, nulls ratio-tracked
                ///< (drawn with EstimatorOptions::emission_segment_count)
    Nee,        ///< y drawn in the volume by the power grid from the segment's real vertex x, nulls ratio-tracked
};

/// Which group of BDPT's strategies drew a contribution a BdptRecorder sees (the groups whose
/// counts the learner changes together).
enum class BdptTechnique : std::uint8_t {
    Fixed,  ///< s = 0 (the camera subpath reaches the emitter), NEE toward an emitting volume: count 1
    Nee,    ///< s = 1 toward a light, drawn with EstimatorOptions::nee_count at each camera vertex
    Light,  ///< s >= 2 and t = 1: a light subpath's, drawn with the light subpath probability (one draw a sample)
};

/// The three techniques that can produce a path's last real vertex x and its light vertex y
/// when equiangular sampling is on (THEORY 5.4).
enum class VertexTechnique : std::uint8_t {
    TrackNee,        ///< x by tracking, y by NEE
    TrackHit,        ///< x by tracking, y by tracking from x (hitting the light)
    EquiangularNee,  ///< x by equiangular sampling (nulls before it ratio-tracked), y by NEE
};

/// Throws InvalidArgument on max_depth < 0, rr_start_depth < 1 or rr_max_survival outside (0, 1].
inline void validate(const EstimatorOptions& opts) {
    if (opts.max_depth < 0)
        detail::fail("EstimatorOptions max_depth = ", opts.max_depth, " is not allowed: it must be >= 0");
    if (opts.rr_start_depth < 1)
        detail::fail("EstimatorOptions rr_start_depth = ", opts.rr_start_depth, " is not allowed: it must be >= 1");
    if (!(opts.rr_max_survival > 0.f && opts.rr_max_survival <= 1.f))
        detail::fail("EstimatorOptions rr_max_survival = ", opts.rr_max_survival,
                     " is not allowed: it must lie in (0, 1]");
    validate_count("EstimatorOptions nee_count", opts.nee_count, true);
    validate_count("EstimatorOptions emission_segment_count", opts.emission_segment_count, true);
    validate_count("EstimatorOptions equiangular_count", opts.equiangular_count, true);
    validate(opts.ray_marching);
}

}  // namespace nsp
