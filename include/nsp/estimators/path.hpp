// nsp/estimators/path.hpp: the grey path estimator (THEORY 4, 5.1, 5.2, 5.6): one pdf for every
// channel (event probabilities from the channel means under one grey majorant).
//
// One path loop serves all four strategies; they differ only where `if constexpr` on the
// strategy's traits says so:
// - Unidirectional: delta tracking, emission found by hitting lights;
// - NextEvent: light sampling with ratio-tracking transmittance at every real vertex;
// - DirectionalMis: both, weighted by the direction pdfs alone (Novak 2014, Kutz 2017);
// - NullScatteringMis: both, weighted by the full null-scattering path pdfs (THEORY 5.1).
// Exact for Mono and grey media; on chromatic media the per-channel weights multiply along a
// path, which is what estimators/spectral.hpp is for.
#pragma once

#include <algorithm>
#include <cstdint>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../mis.hpp"
#include "../scene.hpp"
#include "../tracking.hpp"
#include "common.hpp"

namespace nsp {

/// The unidirectional strategy's pdf of a light path segment relative to the shared prefix:
/// q p_w, times prod_j P_n(n_j) when the strategy uses null-scattering pdfs (THEORY 5.1, 5.6).
/// Both weights below use it, so the two sides of one path cannot disagree.
template <PathStrategy St>
float unidirectional_pdf(float survival, float phase_pdf, float null_pdf_product) noexcept {
    if constexpr (St::null_pdfs) return survival * phase_pdf * null_pdf_product;
    else return survival * phase_pdf;
}

/// MIS weight of the unidirectional technique for a path whose last segment, tracked from a real
/// vertex with roulette survival `survival` and phase pdf `phase_pdf`, hit a light that NEE
/// samples with solid-angle pdf `light_pdf`. `null_pdf_product` is prod_j P_n(n_j) of the
/// segment's nulls (used by NullScatteringMis only). THEORY 5.1, 5.2, 5.6.
template <PathStrategy St, mis::CombiningHeuristic H>
float unidirectional_weight(const H& h, float survival, float phase_pdf, float null_pdf_product,
                            float light_pdf) noexcept {
    const float p_uni = unidirectional_pdf<St>(survival, phase_pdf, null_pdf_product);
    return p_uni > 0.f ? h.weight(light_pdf / p_uni) : 0.f;
}

/// MIS weight of NEE for the same kind of path, sampled by the light (pdf `light_pdf` > 0) with
/// ratio tracking, whose nulls have delta-tracking product `null_pdf_product`. For one path,
/// unidirectional_weight + next_event_weight = 1.
template <PathStrategy St, mis::CombiningHeuristic H>
float next_event_weight(const H& h, float survival, float phase_pdf, float null_pdf_product,
                        float light_pdf) noexcept {
    return h.weight(unidirectional_pdf<St>(survival, phase_pdf, null_pdf_product) / light_pdf);
}
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
    explicit PathEstimator(EstimatorOptions opts = {}, H heuristic = H{}) : opts_(opts), heuristic_(heuristic) {
        validate(opts);
    }

    const EstimatorOptions& options() const noexcept { return opts_; }

    /// An estimate of the radiance arriving at `ray.o` from direction -ray.d. Never throws.
    template <class Sc, UniformRng R, LookupCounter C>
    RadianceSample<typename Sc::Spectral> radiance(const Sc& scene, const Ray& camera_ray,
                                                   const typename Sc::Spectral::Wavelengths& lambda,
                                                   R& rng, C& counter) const {
        static_assert(!is_per_channel_majorant_v<typename Sc::MajorantType, typename Sc::MediumType>,
                      "nsp::PathEstimator drives every channel with one pdf and needs a grey majorant "
                      "(GlobalMajorant or GridMajorant); per-channel majorants go with nsp::SpectralPathEstimator");
        using Spectrum = typename Sc::Spectrum;
        Spectrum L = Spectrum::Zero(), beta = Spectrum::Ones();
        Status status = Status::Ok;
        Ray ray = camera_ray;
        // The real vertex the current ray left from, for the MIS weight of a light it hits.
        Vec3 prev_x(0.f);
        float prev_phase_pdf = 0.f, prev_survival = 1.f;
        bool from_camera = true;

        for (int depth = 0;;) {
            const LightHit hit = scene.lights.intersect(ray);
            const auto seg = track_delta<A>(scene.medium, scene.majorant, ray, hit.t, lambda, rng, counter);
            if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
                status = fs;
                break;
            }
            beta *= seg.weight;
            if (seg.end == SegmentEnd::Passed) {
                if (from_camera || St::hits_lights) {
                    float w = 1.f;
                    if constexpr (St::combines) {
                        if (!from_camera)  // the shared prefix of the two pdfs cancels
                            w = unidirectional_weight<St>(heuristic_, prev_survival, prev_phase_pdf,
                                                          seg.null_pdf_product,
                                                          scene.lights.pdf(prev_x, hit));
                    }
                    L += w * beta * scene.lights.emitted(hit, lambda);
                }
                break;
            }
            if (seg.end != SegmentEnd::Scattered) break;  // absorbed
            if (++depth > opts_.max_depth) break;

            const Vec3 x = ray.at(seg.t);
            // Roulette survival is fixed before NEE: the continuing unidirectional path carries it.
            float q = 1.f;
            if (opts_.russian_roulette && depth >= opts_.rr_start_depth)
                q = std::min(opts_.rr_max_survival, beta.abs().maxCoeff());
            if constexpr (St::samples_lights) {
                const Status ns = next_event(scene, x, ray.d, q, lambda, rng, counter, beta, L);
                if (ns != Status::Ok) status = ns;
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
            from_camera = false;
            ray = Ray{x, ps.wi};
        }
        if (!all_finite(L)) return {Spectrum::Zero(), Status::NonFinite};
        return {L, status};
    }

private:
    /// Adds NEE's weighted contribution at real vertex x (arrived along wo) to L; returns true if
    /// its shadow flight was aborted.
    template <class Sc, UniformRng R, LookupCounter C>
    Status next_event(const Sc& scene, const Vec3& x, const Vec3& wo, float survival,
                    const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                    const typename Sc::Spectrum& beta, typename Sc::Spectrum& L) const {
        const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
        const LightSample<typename Sc::Spectral> ls = scene.lights.sample(x, u0, u1, u2, lambda);
        if (!(ls.pdf > 0.f)) return Status::Ok;
        const Ray shadow{x, ls.wi};
        if (ls.occludable_by_sphere && scene.lights.sphere_blocks(shadow, ls.distance)) return Status::Ok;
        const auto tr = track_ratio<A, St::null_pdfs>(scene.medium, scene.majorant, shadow,
                                                      ls.distance, lambda, rng, counter);
        if (tr.end == SegmentEnd::Aborted || tr.end == SegmentEnd::Rejected) return flight_status(tr.end);
        if (tr.end == SegmentEnd::Terminated) return Status::Ok;
        float w = 1.f;
        if constexpr (St::combines) {
            if (!ls.delta)  // a point light cannot be hit: NEE keeps weight 1
                w = next_event_weight<St>(heuristic_, survival, scene.phase.pdf(wo, ls.wi),
                                          tr.null_pdf_product, ls.pdf);
        }
        L += beta * tr.transmittance * ls.radiance * (w * scene.phase.eval(wo, ls.wi) / ls.pdf);
        return Status::Ok;
    }

    EstimatorOptions opts_;
    [[no_unique_address]] H heuristic_;
};

}  // namespace nsp

