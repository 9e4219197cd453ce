// nsp/estimators/surface_path.hpp: the grey path loop of PathEstimator over a SurfaceScene
// (THEORY 3, 5.1, 5.6, 5.8): the loop vertex.hpp's header sketches for a host, written on the
// same VertexKernels. Each segment is delta-tracked through the medium the ray is in, up to the
// surface the host's geometry reports; a null interface (no BSDF, or one that passes through)
// switches the medium and carries the segment's null-pdf product on; a surface with a BSDF is a
// real vertex like a scattering one, with the BSDF's pdf where a medium vertex has the phase
// function's. Shadow rays cross interfaces the same way, one ratio-tracked piece per medium,
// their transmittances and null products multiplied. Emitters are the light sampler's lights:
// surfaces whose hit names one, and the lights at infinity for rays that leave the scene, and
// emissive media (surface_emission.hpp: collision estimator, segment technique and volume NEE per
// piece). The equiangular strategies draw a vertex on every piece in a medium, aimed at the light
// sampler's targets (surface_equiangular.hpp).
#pragma once

#include <cmath>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../geometry.hpp"
#include "../media/emissive.hpp"
#include "../surface_scene.hpp"
#include "../vertex.hpp"
#include "common.hpp"
#include "surface_emission.hpp"
#include "surface_equiangular.hpp"
#include "surface_walk.hpp"

namespace nsp::detail {

/// One path of PathEstimator<St, H, A> through a SurfaceScene, on the kernels `k`.
template <class K, class Sc, UniformRng R, LookupCounter C>
RadianceSample<typename Sc::Spectral> surface_radiance(const K& k, const Sc& sc, const Ray& camera_ray,
                                                       const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                       C& counter) {
    using St = typename K::Strategy;
    using Spectrum = typename Sc::Spectrum;
    constexpr bool kEmissive = EmissiveMedium<typename Sc::MediumType>;
    Spectrum L = Spectrum::Zero(), beta = Spectrum::Ones();
    Status status = Status::Ok;
    Ray ray = camera_ray;
    int medium = sc.camera_medium;
    VertexPdf from = VertexPdf::from_camera();  // the last real vertex, for the MIS weight of what the path hits
    float nulls = 1.f;                          // prod P_n of the segments since that vertex
    Vec3 prev = ray.o;
    float from_eq = 0.f;  // p_equiangular / p_tracking of that vertex (equiangular strategies; 0 on a surface)
    float walked = 0.f;  // the distance from that vertex to the current ray's origin (emission's MIS)
    int crossings = 0;
    // The MIS weight of a light the segments from `from` reach, sampled there with `light_pdf`:
    // against NEE, and with equiangular MIS also against equiangular + NEE (relative to tracking
    // + NEE: hitting is p_uni / p_light, equiangular + NEE the vertex's p_eq / p_track).
    // `le` is the light's emitted radiance, for a MisRecorder counter (counts.hpp).
    auto hit_weight = [&](float light_pdf, const Spectrum& le) {
        if constexpr (St::equiangular && St::combines) {
            if (from.camera || from.delta || !(light_pdf > 0.f)) return 1.f;
            const float s = unidirectional_pdf<St>(from.survival, from.direction_pdf, nulls) / light_pdf;
            // Relative to tracking + hit: NEE 1 / s, equiangular + NEE from_eq / s.
            if (s > 0.f) detail::record_light(counter, (beta * le).mean(), 1.f, 1.f / s, from_eq / s, k.nee_count(),
                                                 LightTechnique::Hit);
            return equiangular_mis_weight(k.heuristic(), VertexTechnique::TrackHit, k.nee_count(), s, from_eq);
        } else {
            if constexpr (St::combines && MisRecorder<C>) {
                const float p_uni = unidirectional_pdf<St>(from.survival, from.direction_pdf, nulls);
                if (!from.camera && !from.delta && p_uni > 0.f && light_pdf > 0.f)
                    detail::record_light(counter, (beta * le).mean(), 1.f, light_pdf / p_uni, 0.f, k.nee_count(),
                                         LightTechnique::Hit);
            } else {
                (void)le;
            }
            return k.hit_weight(from, nulls, light_pdf);
        }
    };
    for (int depth = 0;;) {
        const SurfaceHit hit = sc.geometry.intersect(ray, kInf);
        if (!usable_hit(sc, hit)) {
            status = Status::InvalidInput;
            break;
        }
        bool in_medium = false;
        float t_medium = 0.f;
        float eq_ratio = 0.f;    // p_equiangular / p_tracking of a medium vertex drawn on this piece
        bool eq_covers = false;  // the equiangular technique could have drawn it
        if (sc.has_medium(medium)) {
            const auto& m = sc.media[std::size_t(medium)];
            // Equiangular: a real vertex on this piece aimed at the lights, and NEE from it.
            [[maybe_unused]] PieceEquiangular<Sc> eq;
            [[maybe_unused]] float eq_select = 1.f;  // the probability of drawing this piece's equiangular vertex
            if constexpr (St::equiangular) {
                const Interval in = m.medium.bounds().clip(ray, 0.f, hit.t);
                eq = PieceEquiangular<Sc>(sc, ray, in.t0, in.t1);
                if (eq.valid()) {
                    eq_select = eq.template selection<St, typename Sc::MediumType>(k.options(), m.majorant, lambda);
                    if (depth < k.options().max_depth && draw_technique(eq_select, rng)) {
                        const Status es =
                            equiangular_event(k, sc, medium, ray, eq, eq_select, depth + 1, beta, lambda, rng, counter, L);
                        if (es != Status::Ok) status = es;
                    }
                }
            }
            DeltaTrack<typename Sc::Spectral> seg;
            if constexpr (kEmissive)
                seg = track_emissive_piece(k, sc, medium, ray, hit.t, PieceStart{from, nulls, walked}, lambda, rng,
                                           counter, beta, L, status);
            else
                seg = k.track(m.medium, m.majorant, ray, hit.t, lambda, rng, counter);
            if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
                status = fs;
                break;
            }
            beta *= seg.weight;
            nulls *= seg.null_pdf_product;
            if (seg.end == SegmentEnd::Scattered) {
                in_medium = true;
                t_medium = seg.t;
                if constexpr (St::equiangular) {
                    eq_covers = eq.valid();
                    // inf where the tracking pdf underflowed: equiangular then takes the weight
                    if (eq_covers)
                        eq_ratio = equiangular_over_tracking(eq_select * eq.density(seg.t), seg.null_pdf_product,
                                                             seg.event_density);
                }
            } else if (seg.end != SegmentEnd::Passed) {
                break;  // absorbed
            }
        }
        int material = -1;
        Vec3 x;
        if (in_medium) {
            x = ray.at(t_medium);
        } else {
            if (!hit.found()) {  // the ray leaves the scene: the lights at infinity
                if (k.counts_hit(from))
                    for (const int i : sc.lights.infinite()) {
                        const Spectrum le = sc.lights.emitted(i, ray.d, lambda);
                        L += beta * le * hit_weight(from.camera ? 0.f : sc.lights.pdf(i, prev, ray.d), le);
                    }
                break;
            }
            if (hit.light >= 0 && k.counts_hit(from)) {
                const Spectrum le = sc.lights.emitted(hit.light, ray.d, lambda);
                L += beta * le * hit_weight(from.camera ? 0.f : sc.lights.pdf(hit.light, prev, ray.d), le);
            }
            if (crosses(sc, hit)) {  // a null interface: no vertex, the segment goes on in the next medium
                if (++crossings > kMaxInterfaceCrossings) {
                    status = Status::InvalidInput;
                    break;
                }
                medium = hit.medium_entered(ray.d);
                ray.o = hit.p;
                walked += hit.t;
                continue;
            }
            if (hit.material < 0 || sc.materials.passes_through(hit.material))
                break;  // an emitter without a BSDF: what reaches it ends there
            material = hit.material;
            x = hit.p;
        }
        if (++depth > k.options().max_depth) break;
        // Roulette survival is fixed before NEE: the continuing unidirectional path carries it.
        const float q = k.survival(depth, beta);
        const SceneVertex v{material, medium, hit.ns};
        if constexpr (St::samples_lights) {
            auto side = [&](const Vec3& wi) { return v.on_surface() ? hit.medium_entered(wi) : medium; };
            // Equiangular + NEE alone leaves the lights of a vertex its own vertices cover to them.
            // NEE at the expected count EstimatorOptions::nee_count (THEORY 5.9).
            if ((St::combines || !St::equiangular || !eq_covers) && k.draw_nee(rng)) {
                const Status ns = light_event(k, sc, v, x, ray.d, q, side, 1.f, eq_ratio, false, lambda, rng, counter,
                                              beta, L);
                if (ns != Status::Ok) status = ns;
            }
            if constexpr (kEmissive) {
                if (!(v.on_surface() && sc.materials.is_delta(material))) {
                    const Status es = emission_event(k, sc, v, x, ray.d, q, side, lambda, rng, counter, beta, L);
                    if (es != Status::Ok) status = es;
                }
            }
        }
        if (q < 1.f) {
            if (!(rng.uniform() < q)) break;
            beta /= q;
        }
        const float v1 = rng.uniform(), v2 = rng.uniform();
        const auto next = sample_vertex(sc, v, ray.d, v1, v2, lambda);
        if (!(next.pdf > 0.f)) break;
        beta *= next.value / next.pdf;
        if (v.on_surface()) medium = hit.medium_entered(next.wi);
        if (!(beta != 0.f).any()) break;
        from = VertexPdf::scattered(q, next.pdf, next.delta);
        from_eq = eq_ratio;
        nulls = 1.f;
        prev = x;
        walked = 0.f;
        crossings = 0;
        ray = Ray{x, next.wi};
    }
    if (!all_finite(L)) return {Spectrum::Zero(), Status::NonFinite};
    return {L, status};
}

}  // namespace nsp::detail
