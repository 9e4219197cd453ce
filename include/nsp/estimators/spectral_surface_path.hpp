// nsp/estimators/spectral_surface_path.hpp: the per-channel path loop of SpectralPathEstimator
// over a SurfaceScene (THEORY 5.3, 5.8): estimators/surface_path.hpp's walk (null interfaces
// switch media, surfaces with a BSDF are real vertices, shadow rays cross interfaces piece by
// piece, emitters are the light sampler's lights) with every channel's path pdfs in a
// ChannelPathState, as SpectralPathEstimator keeps them in media in empty space. One state runs
// through every medium a segment crosses: track_channels_delta multiplies each piece's null and
// Tbar factors into it, and a crossing adds none. A surface vertex multiplies f by the BSDF's
// value per channel and every channel's pdf by the same direction pdf; after a delta lobe the
// next segment has no NEE alternative.
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
#include "surface_walk.hpp"

namespace nsp::detail {

/// A shadow ray's per-channel factors through a SurfaceScene (see ChannelShadow), the pieces
/// between null interfaces multiplied; f = 0 where a surface blocks it. `end` Passed, or the
/// first failed piece's end (Aborted, Rejected, Overflowed), or InvalidInput for a bad hit.
template <ChannelPolicy CP, AbsorptionPolicy A, class Sc, UniformRng R, LookupCounter C>
ChannelShadow<typename Sc::Spectral> channel_shadow_through(const Sc& sc, Ray r, float distance, int medium,
                                                            const typename Sc::Spectral::Wavelengths& lambda, int c,
                                                            const typename Sc::Spectrum& weights, bool uni_alternative,
                                                            R& rng, C& counter) {
    using Sp = typename Sc::Spectral;
    ChannelShadow<Sp> out;
    auto blocked = [] {
        ChannelShadow<Sp> b;
        b.f.setZero();
        return b;
    };
    for (int crossing = 0; crossing <= kMaxInterfaceCrossings; ++crossing) {
        const SurfaceHit h = sc.geometry.intersect(r, distance);
        if (!usable_hit(sc, h)) {
            ChannelShadow<Sp> bad = blocked();
            bad.end = SegmentEnd::InvalidInput;
            return bad;
        }
        if (sc.has_medium(medium)) {
            const auto& m = sc.media[std::size_t(medium)];
            const auto s = track_channels_ratio<CP, A>(m.medium, m.majorant, r, h.found() ? h.t : distance, lambda, c,
                                                       typename Sc::Spectrum(weights * out.f), uni_alternative, rng,
                                                       counter);
            if (s.end == SegmentEnd::Terminated) return blocked();
            if (s.end != SegmentEnd::Passed) {
                ChannelShadow<Sp> failed = blocked();
                failed.end = s.end;
                return failed;
            }
            out.f *= s.f;
            out.nee *= s.nee;
            out.uni *= s.uni;
            // One common factor for the three keeps many pieces inside float's range; it cancels.
            const float k = std::max(out.nee.maxCoeff(), out.uni.maxCoeff());
            if (k > 0.f && std::isfinite(k)) {
                out.f /= k;
                out.nee /= k;
                out.uni /= k;
            }
        }
        if (!h.found()) return out;
        if (!crosses(sc, h)) return blocked();
        medium = h.medium_entered(r.d);
        r.o = h.p;
        distance -= h.t;
    }
    ChannelShadow<Sp> bad = blocked();
    bad.end = SegmentEnd::InvalidInput;
    return bad;
}

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
    static_assert(!St::equiangular,
                  "nsp::SpectralPathEstimator over a SurfaceScene: the equiangular strategies aim at the point or "
                  "sphere light of nsp::Scene and do not render scenes with surfaces yet");
    const Spectrum& q = selection.probabilities();
    const int c = selection.sample(rng.uniform());
    // An emissive medium's segment technique keeps its pdf in the state's second slot (eq.vertex).
    ChannelPathState<typename Sc::Spectral, kEmissive> st;
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
        if (sc.has_medium(medium)) {
            const auto& m = sc.media[std::size_t(medium)];
            ChannelTrack seg;
            if constexpr (kEmissive) {
                st.eq.vertex = st.uni;
                seg = track_emissive_piece_channels<CP, St, A>(opts, sc, medium, ray, hit.t,
                                                               St::hits_lights || camera_or_delta, nee_alternative,
                                                               walked, lambda, q, c, st, rng, counter, L, status);
                st.eq.vertex.setZero();  // used within the piece only
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
            } else if (seg.end != SegmentEnd::Passed) {
                break;  // absorbed, or no pdf left
            }
        }
        // An emitter reached: every channel's pdf of the path, tracking and (where it exists) NEE.
        auto add_emitter = [&](int light) {
            Spectrum pdf = st.uni;
            if (nee_alternative) pdf += sc.lights.pdf(light, prev, ray.d) * st.nee;
            L += channel_estimate<CP>(st.f, pdf, q, c) * sc.lights.emitted(light, ray.d, lambda);
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
            const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
            if (!(v.on_surface() && sc.materials.is_delta(material))) {
                const SampledLight<typename Sc::Spectral> ls = sc.lights.sample(x, u0, u1, u2, lambda);
                if (ls.sample.pdf > 0.f) {
                    const auto fv = eval_vertex(sc, v, ray.d, ls.sample.wi, lambda);
                    const Spectrum& fs = fv.value;
                    const float p = fv.pdf;
                    if ((fs != 0.f).any()) {
                        const bool uni_alternative = St::combines && !ls.sample.delta;
                        const auto sh = channel_shadow_through<CP, A>(
                            sc, Ray{x, fv.wi}, shadow_distance(ls.sample.distance),
                            v.on_surface() ? hit.medium_entered(fv.wi) : medium, lambda, c, st.f, uni_alternative, rng,
                            counter);
                        if (sh.end != SegmentEnd::Passed) {
                            status = shadow_status(sh.end);
                            if (status == Status::NonFinite) return {Spectrum::Zero(), status};
                        } else if ((sh.f != 0.f).any()) {
                            Spectrum seg_pdf = ls.sample.pdf * sh.nee;
                            if (uni_alternative) seg_pdf += (rr * p) * sh.uni;
                            L += channel_estimate<CP>(Spectrum(st.f * sh.f * fs), Spectrum(st.uni * seg_pdf), q, c) *
                                 ls.sample.radiance;
                        }
                    }
                }
                if constexpr (kEmissive) {
                    auto side = [&](const Vec3& wi) { return v.on_surface() ? hit.medium_entered(wi) : medium; };
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
        if (nee_alternative) st.nee = st.uni;
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
