// nsp/recorder.hpp: the recording hooks of the estimators (THEORY 5.9): a lookup counter that also
// records every contribution with its techniques' pdfs (MisRecorder, BdptRecorder; NeeCountLearner
// in counts.hpp is one) gets them; any other counter compiles them to nothing. One policy, called
// at the same points by every estimator.
#pragma once

#include <concepts>

#include "core/counter.hpp"
#include "options.hpp"

namespace nsp {

/// A lookup counter that also records what NeeCountLearner needs: every light contribution that
/// both tracking and NEE can make and every emission contribution, the work of every NEE shadow
/// walk (whether the NEE count scales it or not) and of every run of the emission segment
/// technique. The estimators call these only on such counters; with any other counter they
/// compile to nothing.
template <class C>
concept MisRecorder = LookupCounter<C> &&
    requires(C& c, float f, LightTechnique t, EmissionTechnique e, double w, bool b) {
        { c.record_light(f, f, f, f, f, t) } noexcept;
        { c.record_emission(f, f, f, f, f, e) } noexcept;
        { c.record_shadow_walk(w, b) } noexcept;
        { c.record_segment_walk(w) } noexcept;
        { c.work() } -> std::convertible_to<double>;
    };

namespace detail {
/// Records a light contribution on a MisRecorder (else nothing). Every pdf is relative to one
/// reference density of the path (any one; the drawing technique's is simplest): `f_over_ref`
/// the contribution's channel mean f / p_ref (no MIS weight, no count), `p_hit` the density of
/// tracking that hits the light, `p_nee` NEE's without its count, `p_other` a further
/// technique's of fixed count (0 if none; equiangular + NEE), `count` the NEE count the path ran
/// with, `t` the technique that drew it.
template <class C>
void record_light(C& counter, float f_over_ref, float p_hit, float p_nee, float p_other, float count,
                  LightTechnique t) noexcept {
    if constexpr (MisRecorder<C>) counter.record_light(f_over_ref, p_hit, p_nee, p_other, count, t);
    else (void)counter, (void)f_over_ref, (void)p_hit, (void)p_nee, (void)p_other, (void)count, (void)t;
}
/// Records a volume emission contribution on a MisRecorder (else nothing), as record_light: the
/// pdfs of the collision estimator, the segment technique (without its count) and NEE toward the
/// volume relative to one reference density, `count` the segment count the path ran with.
template <class C>
void record_emission(C& counter, float f_over_ref, float p_collision, float p_segment, float p_nee, float count,
                     EmissionTechnique t) noexcept {
    if constexpr (MisRecorder<C>) counter.record_emission(f_over_ref, p_collision, p_segment, p_nee, count, t);
    else (void)counter, (void)f_over_ref, (void)p_collision, (void)p_segment, (void)p_nee, (void)count, (void)t;
}
/// The work counted since `before` as one NEE shadow walk's, on a MisRecorder (else nothing):
/// `counted` when the walk ran with the NEE count (from a tracked vertex or a surface), false when
/// it runs whatever the count (from an equiangular vertex).
template <class C>
void record_shadow_walk(C& counter, double before, bool counted) noexcept {
    if constexpr (MisRecorder<C>) counter.record_shadow_walk(counter.work() - before, counted);
    else (void)counter, (void)before, (void)counted;
}
/// The work counted since `before` as one run of the emission segment technique's, on a
/// MisRecorder (else nothing).
template <class C>
void record_segment_walk(C& counter, double before) noexcept {
    if constexpr (MisRecorder<C>) counter.record_segment_walk(counter.work() - before);
    else (void)counter, (void)before;
}
/// Tells a recorder that learns counts (NeeCountLearner::nee_count_may_be_0) whether the scene
/// allows NEE count 0; nothing on any other counter.
template <class C>
void record_nee_count_may_be_0(C& counter, bool allowed) noexcept {
    if constexpr (requires { counter.nee_count_may_be_0(allowed); }) counter.nee_count_may_be_0(allowed);
    else (void)counter, (void)allowed;
}
/// counter.work() on a MisRecorder, else 0 (what record_shadow_walk takes as `before`).
template <class C>
double recorder_work(const C& counter) noexcept {
    if constexpr (MisRecorder<C>) return counter.work();
    else return (void)counter, 0.0;
}
}  // namespace detail

/// A MisRecorder that also records BdptEstimator's contributions (every strategy's, balance
/// heuristic) and the work of its light subpaths; BdptEstimator calls these only on such counters.
template <class C>
concept BdptRecorder = MisRecorder<C> && requires(C& c, float f, BdptTechnique t, double w, bool b) {
    { c.record_bdpt(f, f, f, f, f, f, t, b) } noexcept;
    { c.record_light_walk(w) } noexcept;
};

namespace detail {
/// Records a BDPT contribution on a BdptRecorder (else nothing), as record_light: `f_over_ref`
/// the unweighted contribution times its strategy's pdf relative to one reference density of the
/// path, the summed pdfs of the path's strategies by group (`p_fixed` the count-1 strategies',
/// `p_nee` light NEE's without its count, `p_light` the light subpath's strategies' without its
/// probability), the counts the path ran with, the group that drew it and whether it was splatted
/// onto the image elsewhere (t = 1) instead of returned for the sample's own pixel.
template <class C>
void record_bdpt(C& counter, float f_over_ref, float p_fixed, float p_nee, float p_light, float nee_count,
                 float light_count, BdptTechnique t, bool splat) noexcept {
    if constexpr (BdptRecorder<C>) counter.record_bdpt(f_over_ref, p_fixed, p_nee, p_light, nee_count, light_count, t, splat);
    else (void)counter, (void)f_over_ref, (void)p_fixed, (void)p_nee, (void)p_light, (void)nee_count, (void)light_count, (void)t, (void)splat;
}
/// The work counted since `before` as a light subpath's (its walk, or one of its connections'
/// shadow walks), on a BdptRecorder (else nothing).
template <class C>
void record_light_walk(C& counter, double before) noexcept {
    if constexpr (BdptRecorder<C>) counter.record_light_walk(counter.work() - before);
    else (void)counter, (void)before;
}
}  // namespace detail

}  // namespace nsp
