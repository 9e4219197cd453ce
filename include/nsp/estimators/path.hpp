// nsp/estimators/path.hpp: the grey path estimator (THEORY 4, 5.1, 5.2, 5.6): one pdf for every
// channel (event probabilities from the channel means under one grey majorant).
//
// One path loop serves all six strategies; they differ only where `if constexpr` on the
// strategy's traits says so:
// - Unidirectional: delta tracking, emission found by hitting lights;
// - NextEvent: light sampling with ratio-tracking transmittance at every real vertex;
// - DirectionalMis: both, weighted by the direction pdfs alone (Novak 2014, Kutz 2017);
// - NullScatteringMis: both, weighted by the full null-scattering path pdfs (THEORY 5.1);
// - EquiangularNextEvent: on every segment a real vertex drawn toward the point light
//   (equiangular, THEORY 5.4) with NEE from it;
// - EquiangularMis: tracking + NEE, tracking + hit and equiangular + NEE, by their path pdfs.
// An emissive medium (media/emissive.hpp) adds emission the same way: collected at every
// tentative collision where the strategy counts hits, sampled by NEE toward the volume where it
// samples lights, and, where it combines, also by the segment technique (a point drawn on each
// segment in proportion to the power grid along it, the nulls before it ratio-tracked), the three
// weighted by their analytic path pdfs (THEORY 5.7). A medium without emission compiles none of
// that code.
// Exact for Mono and grey media; on chromatic media the per-channel weights multiply along a
// path, which is what estimators/spectral.hpp is for.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../counts.hpp"
#include "../equiangular.hpp"
#include "../media/emissive.hpp"
#include "../mis.hpp"
#include "../pdf.hpp"
#include "../scene.hpp"
#include "../tracking.hpp"
#include "../surface_scene.hpp"
#include "../vertex.hpp"
#include "common.hpp"
#include "surface_path.hpp"

namespace nsp {

/// A path estimator: strategy St, MIS heuristic H (mis::None exactly for single-strategy
/// estimators) and absorption policy A for the delta-tracked segments.
template <PathStrategy St, mis::Heuristic H = mis::None, AbsorptionPolicy A = absorption::Weight>
class PathEstimator {
    static_assert(St::combines || !H::combines,
                  "nsp::PathEstimator: a single-strategy estimator (Unidirectional, NextEvent) "
                  "takes mis::None; a heuristic would weigh a strategy against nothing");
    static_assert(!St::combines || H::combines,
                  "nsp::PathEstimator: DirectionalMis and NullScatteringMis combine two strategies "
                  "and need a combining heuristic (mis::Balance or mis::Power), not mis::None");

public:
    using Strategy = St;
    using HeuristicType = H;
    using Absorption = A;

    /// Throws InvalidArgument on max_depth < 0, rr_start_depth < 1 or rr_max_survival outside (0, 1].
    explicit PathEstimator(EstimatorOptions opts = {}, H heuristic = H{})
        : kernels_(opts, heuristic) {}

    const EstimatorOptions& options() const noexcept { return kernels_.options(); }

    /// An estimate of the radiance arriving at `ray.o` from direction -ray.d, in a Scene (media
    /// in empty space) or a SurfaceScene (the host's surfaces, media and lights; the loop of
    /// estimators/surface_path.hpp). A camera ray that is not usable_ray (a non-finite origin, a
    /// direction that is not unit length) gives 0 and Status::InvalidInput. Never throws.
    template <class Sc, UniformRng R, LookupCounter C>
    RadianceSample<typename Sc::Spectral> radiance(const Sc& scene, const Ray& camera_ray,
                                                   const typename Sc::Spectral::Wavelengths& lambda,
                                                   R& rng, C& counter) const {
        static_assert(!is_per_channel_majorant_v<typename Sc::MajorantType, typename Sc::MediumType>,
                      "nsp::PathEstimator drives every channel with one pdf and needs a grey majorant "
                      "(GlobalMajorant or GridMajorant); per-channel majorants go with nsp::SpectralPathEstimator");
        if (!usable_ray(camera_ray)) return {Sc::Spectrum::Zero(), Status::InvalidInput};
        if constexpr (is_surface_scene_v<Sc>) return detail::surface_radiance(kernels_, scene, camera_ray, lambda, rng, counter);
        else return media_radiance(scene, camera_ray, lambda, rng, counter);
    }

private:
    /// One path through a Scene: one medium in empty space under Lights<S>.
    template <class Sc, UniformRng R, LookupCounter C>
    RadianceSample<typename Sc::Spectral> media_radiance(const Sc& scene, const Ray& camera_ray,
                                                         const typename Sc::Spectral::Wavelengths& lambda,
                                                         R& rng, C& counter) const {
        using Spectrum = typename Sc::Spectrum;
        constexpr bool kEmissive = EmissiveMedium<typename Sc::MediumType>;
        Spectrum L = Spectrum::Zero(), beta = Spectrum::Ones();
        Status status = Status::Ok;
        Ray ray = camera_ray;
        // The real vertex the current ray left from, for the MIS weight of a light it hits.
        Vec3 prev_x(0.f);
        float prev_phase_pdf = 0.f, prev_survival = 1.f;
        float prev_eq_ratio = 0.f;  // p_equiangular / p_tracking of that vertex (equiangular strategies)
        bool from_camera = true;
        std::optional<Vec3> target;
        if constexpr (St::equiangular) target = scene.lights.equiangular_target();

        for (int depth = 0;;) {
            const LightHit hit = scene.lights.intersect(ray);
            // Equiangular: a real vertex on this segment aimed at the light, and NEE from it.
            EquiangularSampler eq;
            float eq_select = 1.f;  // the probability of drawing this segment's equiangular vertex
            if constexpr (St::equiangular) {
                if (target) {
                    const Interval in = scene.medium.bounds().clip(ray, 0.f, hit.t);
                    eq = EquiangularSampler(ray, *target, in.t0, in.t1);
                    eq_select = equiangular_selection<St>(kernels_.options(), scene, ray, eq, lambda);
                    if (depth < kernels_.options().max_depth && draw_technique(eq_select, rng)) {
                        const Status es =
                            equiangular_vertex(scene, ray, eq, eq_select, depth + 1, beta, lambda, rng, counter, L);
                        if (es != Status::Ok) status = es;
                    }
                }
            }
            DeltaTrack<typename Sc::Spectral> seg;
            if constexpr (kEmissive) {
                // The segment technique: a point drawn on this segment in proportion to the power
                // grid along it (W: its normaliser; 0 where it does not run), with the expected
                // count EstimatorOptions::emission_segment_count (THEORY 5.9).
                float along = 0.f;
                if constexpr (St::combines) {
                    if (kernels_.options().emission_along_segments) {
                        along = scene.medium.emission_along(ray, 0.f, hit.t);
                        if (along > 0.f && draw_technique(kernels_.options().emission_segment_count, rng)) {
                            const double before = detail::recorder_work(counter);
                            const Status es = emission_segment(scene, ray, hit.t, along, !from_camera, prev_survival,
                                                               prev_phase_pdf, lambda, rng, counter, beta, L);
                            detail::record_segment_walk(counter, before);
                            if (es != Status::Ok) status = es;
                        }
                    }
                }
                if (from_camera || St::hits_lights) {
                    // The NEE alternative of emission exists from real vertices only (THEORY 5.7).
                    seg = track_delta_visiting<A>(scene.medium, scene.majorant, ray, hit.t, lambda, rng, counter,
                                                  EmissionCollector<Sc, C>{scene, ray, lambda, beta, L, kernels_.heuristic(),
                                                                           kernels_.options(), counter, !from_camera,
                                                                           prev_survival, prev_phase_pdf, along});
                } else {
                    seg = track_delta<A>(scene.medium, scene.majorant, ray, hit.t, lambda, rng, counter);
                }
            } else {
                seg = track_delta<A>(scene.medium, scene.majorant, ray, hit.t, lambda, rng, counter);
            }
            if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
                status = fs;
                break;
            }
            beta *= seg.weight;
            if (seg.end == SegmentEnd::Passed) {
                if (from_camera || St::hits_lights) {
                    float w = 1.f;
                    if constexpr (St::combines) {
                        if (!from_camera) {  // the shared prefix of the pdfs cancels
                            if constexpr (St::equiangular) {
                                // Relative to tracking + NEE: hitting is p_uni / p_light, equiangular
                                // + NEE is the vertex's p_eq / p_track (same light factor).
                                const float s = unidirectional_pdf<St>(prev_survival, prev_phase_pdf,
                                                                       seg.null_pdf_product) /
                                                scene.lights.pdf(prev_x, hit);
                                const float c = kernels_.nee_count();
                                w = equiangular_mis_weight(kernels_.heuristic(), VertexTechnique::TrackHit, c, s, prev_eq_ratio);
                                // Relative to tracking + hit: NEE 1 / s, equiangular + NEE eq_ratio / s.
                                if (s > 0.f)
                                    detail::record_light(counter, (beta * scene.lights.emitted(hit, lambda)).mean(), 1.f,
                                                         1.f / s, prev_eq_ratio / s, c, LightTechnique::Hit);
                            } else {
                                const float p_light = scene.lights.pdf(prev_x, hit);
                                w = kernels_.hit_weight(VertexPdf::scattered(prev_survival, prev_phase_pdf),
                                                        seg.null_pdf_product, p_light);
                                if constexpr (MisRecorder<C>) {
                                    const float p_uni =
                                        unidirectional_pdf<St>(prev_survival, prev_phase_pdf, seg.null_pdf_product);
                                    if (p_uni > 0.f && p_light > 0.f)
                                        detail::record_light(counter, (beta * scene.lights.emitted(hit, lambda)).mean(),
                                                             1.f, p_light / p_uni, 0.f, kernels_.nee_count(),
                                                             LightTechnique::Hit);
                                }
                            }
                        }
                    }
                    NSP_DEBUG_ASSERT(!(w < 0.f) && !(w > 1.f), "an MIS weight left [0, 1]");
                    L += w * beta * scene.lights.emitted(hit, lambda);
                }
                break;
            }
            if (seg.end != SegmentEnd::Scattered) break;  // absorbed
            if (++depth > kernels_.options().max_depth) break;

            const Vec3 x = ray.at(seg.t);
            // p_eq / p_track of this vertex: the nulls' P_n and mu_bar P_s against the equiangular
            // density (THEORY 5.4); inf if the tracking pdf underflowed.
            float eq_ratio = 0.f;
            if constexpr (St::equiangular)
                if (target)
                    eq_ratio = equiangular_over_tracking(eq_select * eq.pdf(seg.t), seg.null_pdf_product, seg.event_density);
            // Roulette survival is fixed before NEE: the continuing unidirectional path carries it.
            const float q = kernels_.survival(depth, beta);
            if constexpr (St::samples_lights) {
                // Equiangular + NEE alone leaves the lights to its own vertices when it has a target.
                // NEE at the expected count EstimatorOptions::nee_count (THEORY 5.9).
                if ((St::combines || !St::equiangular || !target) && kernels_.draw_nee(rng)) {
                    const Status ns = next_event(scene, x, ray.d, q, lambda, rng, counter, beta, L, 1.f, eq_ratio, false);
                    if (ns != Status::Ok) status = ns;
                }
                if constexpr (kEmissive) {
                    const Status es = emission_event(scene, x, ray.d, q, lambda, rng, counter, beta, L);
                    if (es != Status::Ok) status = es;
                }
            }
            if (q < 1.f) {
                if (!(rng.uniform() < q)) break;
                beta /= q;
            }
            const float u1 = rng.uniform(), u2 = rng.uniform();
            const PhaseSample ps = scene.phase.sample(ray.d, u1, u2);
            if (!(ps.pdf > 0.f)) break;
            beta *= ps.value / ps.pdf;
            prev_x = x;
            prev_phase_pdf = ps.pdf;
            prev_survival = q;
            prev_eq_ratio = eq_ratio;
            from_camera = false;
            ray = Ray{x, ps.wi};
        }
        if (!all_finite(L)) return {Spectrum::Zero(), Status::NonFinite};
        return {L, status};
    }

    /// Adds NEE's weighted contribution at real vertex x (arrived along wo, throughput beta) to L;
    /// returns Aborted or Rejected if its shadow flight was, else Ok. For the equiangular
    /// strategies, `track_ratio_` and `eq_ratio` are the tracking and equiangular pdfs of x over
    /// the pdf of the technique that drew x (`equiangular_drawn` says which one it was). NEE from
    /// a tracked vertex ran with the expected count nee_count (its estimate divides by it); from an
    /// equiangular vertex always (count 1: that vertex exists for it).
    template <class Sc, UniformRng R, LookupCounter C>
    Status next_event(const Sc& scene, const Vec3& x, const Vec3& wo, float survival,
                      const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                      const typename Sc::Spectrum& beta, typename Sc::Spectrum& L, float track_ratio_,
                      float eq_ratio, bool equiangular_drawn) const {
        const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
        const LightSample<typename Sc::Spectral> ls = scene.lights.sample(x, u0, u1, u2, lambda);
        if (!(ls.pdf > 0.f)) return Status::Ok;
        const Ray shadow{x, ls.wi};
        if (ls.occludable_by_sphere && scene.lights.sphere_blocks(shadow, ls.distance)) return Status::Ok;
        const double before = detail::recorder_work(counter);
        const auto tr = kernels_.shadow(scene.medium, scene.majorant, shadow, ls.distance, lambda, rng, counter);
        detail::record_shadow_walk(counter, before, !equiangular_drawn);
        if (tr.status != Status::Ok) return tr.status;
        if (!(tr.transmittance != 0.f).any()) return Status::Ok;
        const float count = equiangular_drawn ? 1.f : kernels_.nee_count();
        const typename Sc::Spectrum f = beta * tr.transmittance * ls.radiance * (scene.phase.eval(wo, ls.wi) / ls.pdf);
        float w = 1.f;
        if constexpr (St::combines) {
            const float c = kernels_.nee_count();
            if constexpr (St::equiangular) {
                // Three techniques, relative to the one that drew x followed by NEE (uncounted):
                // tracking + NEE (its count c), tracking + hit (not for a point light) and
                // equiangular + NEE.
                const float s = ls.delta ? 0.f
                                         : unidirectional_pdf<St>(survival, scene.phase.pdf(wo, ls.wi),
                                                                  tr.null_pdf_product) / ls.pdf;
                w = equiangular_mis_weight(kernels_.heuristic(),
                                           equiangular_drawn ? VertexTechnique::EquiangularNee : VertexTechnique::TrackNee,
                                           track_ratio_ * c, track_ratio_ * s, eq_ratio);
                detail::record_light(counter, f.mean(), track_ratio_ * s, track_ratio_, eq_ratio, c,
                                     equiangular_drawn ? LightTechnique::Other : LightTechnique::Nee);
            } else {  // a point light cannot be hit: NEE keeps weight 1
                const float p_dir = scene.phase.pdf(wo, ls.wi);
                w = kernels_.light_weight(survival, p_dir, tr.null_pdf_product, ls.pdf, ls.delta);
                if constexpr (MisRecorder<C>)
                    detail::record_light(counter, f.mean(),
                                         ls.delta ? 0.f : unidirectional_pdf<St>(survival, p_dir, tr.null_pdf_product) / ls.pdf,
                                         1.f, 0.f, c, LightTechnique::Nee);
            }
        }
        NSP_DEBUG_ASSERT(!(w < 0.f) && !(w > 1.f), "an MIS weight left [0, 1]");
        L += f * (w / count);
        return Status::Ok;
    }

    /// Equiangular + NEE on the segment `ray` (THEORY 5.4): draws t with `eq`, ratio-tracks the
    /// nulls on [0, t), makes t a real scattering vertex at path depth `depth` and does NEE from
    /// it. `beta` is the throughput of the prefix (up to the ray's origin); `select` the
    /// probability with which this segment draws an equiangular vertex at all (its density is
    /// select x eq's).
    template <class Sc, UniformRng R, LookupCounter C>
    Status equiangular_vertex(const Sc& scene, const Ray& ray, const EquiangularSampler& eq, float select, int depth,
                              const typename Sc::Spectrum& beta, const typename Sc::Spectral::Wavelengths& lambda,
                              R& rng, C& counter, typename Sc::Spectrum& L) const {
        DistanceSample ds = eq.sample(rng.uniform());
        ds.pdf *= select;
        if (!(ds.pdf > 0.f)) return Status::Ok;
        const auto tr = track_ratio<A, St::combines>(scene.medium, scene.majorant, ray, ds.t, lambda, rng, counter);
        if (tr.end == SegmentEnd::Aborted || tr.end == SegmentEnd::Rejected) return flight_status(tr.end);
        if (tr.end == SegmentEnd::Terminated) return Status::Ok;
        const Vec3 x = ray.at(ds.t);
        const auto v = lookup_untracked(scene.medium, scene.majorant, ray, ds.t, lambda, counter);
        if (!v) return Status::Rejected;
        const auto& c = v->k;
        const float mu_bar = v->mu;
        const typename Sc::Spectrum beta_eq = beta * tr.transmittance * c.sigma_s / ds.pdf;
        if (!(beta_eq != 0.f).any()) return Status::Ok;
        float track = 0.f, q = 1.f;  // p_track / p_eq of x; the roulette survival tracking would use at x
        if constexpr (St::combines) {
            track = tracking_over_equiangular<A>(ds.pdf, tr.null_pdf_product, c, mu_bar);
            // Roulette survival is a function of the path: the throughput tracking would carry at x
            // (null weights mu_n / (mu_bar P_n), real weight mu_s / (mu_bar P_s)), beta_eq p_eq / p_track.
            if (track > 0.f) q = kernels_.survival(depth, beta_eq / track);
        }
        return next_event(scene, x, ray.d, q, lambda, rng, counter, beta_eq, L, track, 1.f, true);
    }

    /// The collision estimator of volume emission (THEORY 5.7): at every tentative collision y of
    /// a delta-tracked segment, beta mu_a(y) L_e(y) / mu_bar(y), weighted against NEE toward the
    /// emission where the segment left a real vertex and against the segment technique where it
    /// can run (`along` > 0, its normaliser on this segment; its count in `opts`).
    template <class Sc, class C>
    struct EmissionCollector {
        static constexpr bool enabled = true;
        using S = typename Sc::Spectral;
        const Sc& scene;
        const Ray& ray;
        const typename S::Wavelengths& lambda;
        const typename S::Spectrum& beta;
        typename S::Spectrum& L;
        const H& heuristic;
        const EstimatorOptions& opts;
        C& counter;  ///< a MisRecorder records the contribution (counts.hpp)
        bool from_vertex;  ///< the segment left a real vertex (else the camera: no NEE alternative)
        float survival, phase_pdf;
        float along;

        void operator()(float t, const Coefficients<S>& c, float mu_bar, const typename S::Spectrum& w,
                        float null_pdf_product) const {
            if (!(c.sigma_a > 0.f).any()) return;
            const Vec3 y = ray.at(t);
            const typename S::Spectrum le = scene.medium.emission(y, lambda);
            if (!(le > 0.f).any()) return;
            float wt = 1.f;
            if constexpr (St::combines) {
                const float p_v = scene.medium.emission_pdf(y);
                const float p_seg = segment_density(opts, p_v, along);
                const EmissionPdfs p = from_vertex ? emission_pdfs<St>(survival, phase_pdf, null_pdf_product, mu_bar,
                                                                       p_seg, t * t, p_v)
                                                   : emission_pdfs<St>(1.f, 1.f, null_pdf_product, mu_bar, p_seg, 0.f, 0.f);
                wt = emission_weight(heuristic, EmissionTechnique::Collision, p);
                if constexpr (MisRecorder<C>)
                    record_emission_of(counter, (beta * w * c.sigma_a * le).mean() / mu_bar, p, opts,
                                       EmissionTechnique::Collision);
            }
            L += beta * w * c.sigma_a * le * (wt / mu_bar);
        }
    };

    /// The segment technique of volume emission on `ray` over [0, tmax) (THEORY 5.7): y drawn with
    /// the density p_seg = emission_pdf / `along` along the ray, the nulls before it ratio-tracked,
    /// beta Tbar-ratio mu_a(y) L_e(y) / p_seg(y), weighted against the collision estimator of the
    /// same segment and, from a real vertex (`from_vertex`, with roulette survival and phase pdf
    /// there), against NEE toward the volume. It ran with the expected count emission_segment_count:
    /// its estimate divides by it, its weight takes count x p_seg.
    template <class Sc, UniformRng R, LookupCounter C>
    Status emission_segment(const Sc& scene, const Ray& ray, float tmax, float along, bool from_vertex, float survival,
                            float phase_pdf, const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                            const typename Sc::Spectrum& beta, typename Sc::Spectrum& L) const {
        const DistanceSample ds = scene.medium.sample_emission_along(ray, 0.f, tmax, along, rng.uniform());
        if (!(ds.pdf > 0.f)) return Status::Ok;
        const auto tr = kernels_.shadow(scene.medium, scene.majorant, ray, ds.t, lambda, rng, counter);
        if (tr.status != Status::Ok) return tr.status;
        if (!(tr.transmittance != 0.f).any()) return Status::Ok;
        const auto v = lookup_untracked(scene.medium, scene.majorant, ray, ds.t, lambda, counter);
        if (!v) return Status::Rejected;
        if (!(v->k.sigma_a > 0.f).any()) return Status::Ok;
        const Vec3 y = ray.at(ds.t);
        const typename Sc::Spectrum le = scene.medium.emission(y, lambda);
        // The weight takes p_seg where every technique evaluates it: at the point's own cell.
        const float p_v = scene.medium.emission_pdf(y);
        const float count = kernels_.options().emission_segment_count;
        const float p_seg = segment_density(kernels_.options(), p_v, along);
        const EmissionPdfs p = from_vertex ? emission_pdfs<St>(survival, phase_pdf, tr.null_pdf_product, v->mu,
                                                               p_seg, ds.t * ds.t, p_v)
                                           : emission_pdfs<St>(1.f, 1.f, tr.null_pdf_product, v->mu, p_seg, 0.f, 0.f);
        const float w = emission_weight(kernels_.heuristic(), EmissionTechnique::Segment, p);
        if constexpr (MisRecorder<C>)
            record_emission_of(counter, (beta * tr.transmittance * v->k.sigma_a * le).mean() / ds.pdf, p,
                               kernels_.options(), EmissionTechnique::Segment);
        L += beta * tr.transmittance * v->k.sigma_a * le * (w / (count * ds.pdf));
        return Status::Ok;
    }

    /// NEE toward the emitting volume at real vertex x (THEORY 5.7): a point y drawn by the
    /// medium's emitted-power grid, the nulls to it ratio-tracked, weighted against the collision
    /// estimator and the segment technique (on the ray from x toward y, to the light it would hit).
    template <class Sc, UniformRng R, LookupCounter C>
    Status emission_event(const Sc& scene, const Vec3& x, const Vec3& wo, float survival,
                          const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                          const typename Sc::Spectrum& beta, typename Sc::Spectrum& L) const {
        const auto e = sample_emission_from(scene.medium, scene.lights, x, rng);
        if (!e) return Status::Ok;
        const auto tr = kernels_.shadow(scene.medium, scene.majorant, e->shadow, e->dist, lambda, rng, counter);
        if (tr.status != Status::Ok) return tr.status;
        if (!(tr.transmittance != 0.f).any()) return Status::Ok;
        const auto v = lookup_untracked(scene.medium, scene.majorant, e->shadow, e->dist, lambda, counter);
        if (!v) return Status::Rejected;
        const typename Sc::Spectrum le = scene.medium.emission(e->y.p, lambda);
        const Vec3& wi = e->shadow.d;
        float w = 1.f;
        if constexpr (St::combines) {
            const EmissionPdfs p =
                emission_pdfs<St>(survival, scene.phase.pdf(wo, wi), tr.null_pdf_product, v->mu,
                                  emission_segment_pdf(kernels_.options(), scene, *e), e->dist2, e->y.pdf);
            w = emission_weight(kernels_.heuristic(), EmissionTechnique::Nee, p);
            if constexpr (MisRecorder<C>)
                record_emission_of(counter,
                                   (beta * tr.transmittance * v->k.sigma_a * le).mean() * scene.phase.eval(wo, wi) /
                                       (e->dist2 * e->y.pdf),
                                   p, kernels_.options(), EmissionTechnique::Nee);
        }
        L += beta * tr.transmittance * v->k.sigma_a * le * (w * scene.phase.eval(wo, wi) / (e->dist2 * e->y.pdf));
        return Status::Ok;
    }

    /// The path-vertex kernels a host's own loop calls too (vertex.hpp), with the options and
    /// the heuristic.
    VertexKernels<St, H, A> kernels_;
};

}  // namespace nsp

