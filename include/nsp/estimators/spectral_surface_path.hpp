// nsp/estimators/spectral_surface_path.hpp: the per-channel path loop of SpectralPathEstimator
// over a SurfaceScene (THEORY 5.3, 5.8): estimators/surface_path.hpp's walk (null interfaces
// switch media, surfaces with a BSDF are real vertices, shadow rays cross interfaces piece by
// piece, emitters are the light sampler's lights) with every channel's path pdfs in a
// ChannelPathState, as SpectralPathEstimator keeps them in media in empty space. One state runs
// through every medium a segment crosses: track_channels_delta multiplies each piece's null and
// Tbar factors into it, and a crossing adds none. A surface vertex multiplies f by the BSDF's
// value per channel and every channel's pdf by the same direction pdf; after a delta lobe the
// next segment has no NEE alternative. Emissive media (spectral_surface_emission.hpp) and the
// equiangular strategies (spectral_surface_equiangular.hpp) work per piece, as in the grey loop.
#pragma once

#include <cmath>

#include "../channel_tracking.hpp"
#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../media/emissive.hpp"
#include "../path_pdf.hpp"
#include "../surface_scene.hpp"
#include "common.hpp"
#include "spectral_surface_emission.hpp"
#include "spectral_surface_equiangular.hpp"
#include "surface_walk.hpp"

namespace nsp::detail {

/// One path of SpectralPathEstimator<CP, St, H, A> through a SurfaceScene: sampling channel c
/// drawn with probabilities q (selection), every channel's pdfs in the one-sample balance
/// heuristic over channels and techniques (THEORY 5.3).
template <ChannelPolicy CP, PathStrategy St, AbsorptionPolicy A, class Sc, UniformRng R, LookupCounter C>
RadianceSample<typename Sc::Spectral> spectral_surface_radiance(const EstimatorOptions& opts, const Sc& sc,
                                                                const Ray& camera_ray,
                                                                const typename Sc::Spectral::Wavelengths& lambda,
                                                                const ChannelSelection<typename Sc::Spectral>& selection,
                                                                R& rng, C& counter) {
    using Spectrum = typename Sc::Spectrum;
    constexpr bool kEmissive = EmissiveMedium<typename Sc::MediumType>;
    const Spectrum& q = selection.probabilities();
    const int c = selection.sample(rng.uniform());
    // The equiangular strategies and an emissive medium's segment technique keep their pdfs in
    // the state's second slot (eq: the pdf of a piece's prefix with its nulls ratio-tracked).
    constexpr bool kEq = St::equiangular || kEmissive;
    ChannelPathState<typename Sc::Spectral, kEq> st;
    Spectrum L = Spectrum::Zero();
    Status status = Status::Ok;
    Ray ray = camera_ray;
    int medium = sc.camera_medium;
    Vec3 prev = ray.o;               // the last real vertex
    bool camera_or_delta = true;     // no real vertex yet, or the last one drew a delta lobe: NEE cannot reach what follows
    bool nee_alternative = false;    // combining, and light sampling from that vertex could have produced what the path reaches
    float walked = 0.f;              // the distance from that vertex to the current ray's origin (emission's MIS)
    int crossings = 0;
    for (int depth = 0;;) {
        const SurfaceHit hit = sc.geometry.intersect(ray, kInf);
        if (!usable_hit(sc, hit)) {
            status = Status::InvalidInput;
            break;
        }
        bool in_medium = false;
        float t_medium = 0.f;
        Spectrum eq_pdf = Spectrum::Zero();  // every channel's equiangular pdf of a medium vertex drawn on this piece
        bool eq_covers = false;              // the equiangular technique could have drawn it
        if (sc.has_medium(medium)) {
            const auto& m = sc.media[std::size_t(medium)];
            if constexpr (kEq) st.eq.vertex = st.uni;
            // Equiangular: a real vertex on this piece aimed at the lights, and NEE from it.
            [[maybe_unused]] PieceEquiangular<Sc> eq;
            [[maybe_unused]] float eq_select = 1.f;
            if constexpr (St::equiangular) {
                const Interval in = m.medium.bounds().clip(ray, 0.f, hit.t);
                eq = PieceEquiangular<Sc>(sc, ray, in.t0, in.t1);
                if (eq.valid()) {
                    eq_select = eq.template selection<St, typename Sc::MediumType>(opts, m.majorant, lambda);
                    if (depth < opts.max_depth && draw_technique(eq_select, rng)) {
                        const Status es = channel_equiangular_event<CP, St, A>(opts, sc, medium, ray, eq, eq_select,
                                                                               depth + 1, lambda, q, c, st, rng, counter, L);
                        if (es == Status::NonFinite) return {Spectrum::Zero(), es};  // an overflowed flight
                        if (es != Status::Ok) status = es;
                    }
                }
            }
            ChannelTrack seg;
            if constexpr (kEmissive) {
                seg = track_emissive_piece_channels<CP, St, A>(opts, sc, medium, ray, hit.t,
                                                               St::hits_lights || camera_or_delta, nee_alternative,
                                                               walked, lambda, q, c, st, rng, counter, L, status);
            } else {
                seg = track_channels_delta<CP, A>(m.medium, m.majorant, ray, hit.t, lambda, c, st, nee_alternative, rng,
                                                  counter);
            }
            if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
                status = fs;
                break;
            }
            if (seg.end == SegmentEnd::Scattered) {
                in_medium = true;
                t_medium = seg.t;
                if constexpr (St::equiangular) {
                    eq_covers = eq.valid();
                    if (eq_covers) eq_pdf = st.eq.vertex * (eq_select * eq.density(seg.t));
                }
            } else if (seg.end != SegmentEnd::Passed) {
                break;  // absorbed, or no pdf left
            }
            if constexpr (kEq) st.eq.vertex.setZero();  // the piece's alone
        }
        // An emitter reached: every channel's pdf of the path, tracking and (where it exists) NEE.
        // NEE's pdf carries its expected count (THEORY 5.9; equiangular + NEE has count 1).
        auto add_emitter = [&](int light) {
            Spectrum pdf = st.uni;
            const Spectrum le = sc.lights.emitted(light, ray.d, lambda);
            if (nee_alternative) {
                const float p_light = sc.lights.pdf(light, prev, ray.d);
                Spectrum other = Spectrum::Zero();
                if constexpr (St::equiangular) other = p_light * st.eq.nee;
                pdf += opts.nee_count * p_light * st.nee + other;
                record_channels<CP>(counter, Spectrum(st.f * le), st.uni, Spectrum(p_light * st.nee), other, q, c,
                                    opts.nee_count, LightTechnique::Hit);
            }
            L += channel_estimate<CP>(st.f, pdf, q, c) * le;
        };
        int material = -1;
        Vec3 x;
        if (in_medium) {
            x = ray.at(t_medium);
        } else {
            if (!hit.found()) {
                if (St::hits_lights || camera_or_delta)
                    for (const int i : sc.lights.infinite()) add_emitter(i);
                break;
            }
            if (hit.light >= 0 && (St::hits_lights || camera_or_delta)) add_emitter(hit.light);
            if (crosses(sc, hit)) {
                if (++crossings > kMaxInterfaceCrossings) {
                    status = Status::InvalidInput;
                    break;
                }
                medium = hit.medium_entered(ray.d);
                ray.o = hit.p;
                walked += hit.t;
                continue;
            }
            if (hit.material < 0 || sc.materials.passes_through(hit.material)) break;  // an emitter without a BSDF
            material = hit.material;
            x = hit.p;
        }
        if (++depth > opts.max_depth) break;
        const SceneVertex v{material, medium, hit.ns};
        // Roulette survival is fixed before NEE, from the largest channel estimate (as in media).
        float rr = 1.f;
        if (opts.russian_roulette && depth >= opts.rr_start_depth)
            rr = std::min(opts.rr_max_survival, channel_estimate<CP>(st.f, st.uni, q, c).abs().maxCoeff());
        if constexpr (St::samples_lights) {
            auto side = [&](const Vec3& wi) { return v.on_surface() ? hit.medium_entered(wi) : medium; };
            // Equiangular + NEE alone leaves the lights of a vertex its own vertices cover to them.
            // NEE at the expected count EstimatorOptions::nee_count (THEORY 5.9).
            if ((St::combines || !St::equiangular || !eq_covers) && draw_technique(opts.nee_count, rng)) {
                const Status ns = channel_light_event<CP, St, A>(sc, v, x, ray.d, rr, side, lambda, q, c, st.f, st.uni,
                                                                 eq_pdf, opts.nee_count, false, rng, counter, L);
                if (ns == Status::NonFinite) return {Spectrum::Zero(), ns};  // an overflowed flight
                if (ns != Status::Ok) status = ns;
            }
            if constexpr (kEmissive) {
                if (!(v.on_surface() && sc.materials.is_delta(material))) {
                    const Status es = channel_emission_event<CP, St, A>(opts, sc, v, x, ray.d, rr, side, lambda, q, c,
                                                                        st, rng, counter, L);
                    if (es == Status::NonFinite) return {Spectrum::Zero(), es};  // an overflowed flight
                    if (es != Status::Ok) status = es;
                }
            }
        }
        if (rr < 1.f && !(rng.uniform() < rr)) break;
        const float v1 = rng.uniform(), v2 = rng.uniform();
        const auto next = sample_vertex(sc, v, ray.d, v1, v2, lambda);
        if (!(next.pdf > 0.f)) break;
        if (v.on_surface()) medium = hit.medium_entered(next.wi);
        // The NEE alternative of the next segment starts from the prefix, without roulette; a
        // delta lobe has none.
        camera_or_delta = next.delta;
        nee_alternative = St::combines && !next.delta;
        if (nee_alternative) {
            st.nee = st.uni;
            if constexpr (St::equiangular) st.eq.nee = eq_pdf;  // kept apart: emission NEE is from tracked vertices only
        }
        st.f *= next.value;
        st.uni *= rr * next.pdf;
        if (const StateScale r = st.template renormalize<CP>(c); r != StateScale::Ok) {
            if (r == StateScale::Overflowed) status = Status::NonFinite;
            break;
        }
        prev = x;
        walked = 0.f;
        crossings = 0;
        ray = Ray{x, next.wi};
    }
    if (status == Status::NonFinite || !all_finite(L)) return {Spectrum::Zero(), Status::NonFinite};
    return {L, status};
}

}  // namespace nsp::detail
