// nsp/estimators/surface_path.hpp: the grey path loop of PathEstimator over a SurfaceScene
// (THEORY 3, 5.1, 5.6, 5.8): the loop vertex.hpp's header sketches for a host, written on the
// same VertexKernels. Each segment is delta-tracked through the medium the ray is in, up to the
// surface the host's geometry reports; a null interface (no BSDF, or one that passes through)
// switches the medium and carries the segment's null-pdf product on; a surface with a BSDF is a
// real vertex like a scattering one, with the BSDF's pdf where a medium vertex has the phase
// function's. Shadow rays cross interfaces the same way, one ratio-tracked piece per medium,
// their transmittances and null products multiplied. Emitters are the light sampler's lights:
// surfaces whose hit names one, and the lights at infinity for rays that leave the scene.
#pragma once

#include <cmath>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../geometry.hpp"
#include "../media/emissive.hpp"
#include "../surface_scene.hpp"
#include "../vertex.hpp"
#include "common.hpp"

namespace nsp::detail {

/// More null interfaces on one segment than this (a host's geometry that reports the same
/// boundary again and again) stops the path with Status::InvalidInput.
inline constexpr int kMaxInterfaceCrossings = 256;

/// Whether a hit from the host's geometry is one the estimator can use: a distance that is not
/// NaN or negative, and where something was found a finite point, unit normals and handles
/// inside the scene's tables.
template <class Sc>
bool usable_hit(const Sc& sc, const SurfaceHit& h) noexcept {
    if (std::isnan(h.t) || h.t < 0.f) return false;
    if (!h.found()) return true;
    auto finite = [](const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    auto unit = [](const Vec3& v) { return std::abs(glm::dot(v, v) - 1.f) < 1e-3f; };
    if (!finite(h.p) || !unit(h.ng) || !unit(h.ns)) return false;
    if (h.material != -1 && !sc.materials.contains(h.material)) return false;
    if (h.light != -1 && !(h.light >= 0 && h.light < sc.lights.count())) return false;
    auto medium_ok = [&](int m) { return m == -1 || sc.has_medium(m); };
    return medium_ok(h.medium_front) && medium_ok(h.medium_back);
}

/// Whether a path crosses the surface of `h` without a vertex: no light there, and no BSDF or
/// one that passes through (a null interface).
template <class Sc>
bool crosses(const Sc& sc, const SurfaceHit& h) noexcept {
    return h.light < 0 && (h.material < 0 || sc.materials.passes_through(h.material));
}

/// A real vertex of a path through a SurfaceScene: on a surface (material >= 0, the hit's shading
/// normal ns) or in medium `medium` (material -1). What both path loops ask of it: the value and
/// pdf of a direction (NEE), and a sampled direction (the path's continuation).
struct SceneVertex {
    int material = -1;
    int medium = -1;
    Vec3 ns{0.f, 0.f, 1.f};
    bool on_surface() const noexcept { return material >= 0; }
};

/// A direction's throughput factor at a vertex (BSDF f_s |n . wi| or phase f_p) and its pdf.
template <SpectralMode S>
struct VertexDirection {
    Vec3 wi{0.f, 0.f, 1.f};
    typename S::Spectrum value = S::Spectrum::Zero();
    float pdf = 0.f;
    bool delta = false;
};

/// The value and pdf of direction wi at vertex v for a path that arrived along wo.
template <class Sc>
VertexDirection<typename Sc::Spectral> eval_vertex(const Sc& sc, const SceneVertex& v, const Vec3& wo, const Vec3& wi,
                                                   const typename Sc::Spectral::Wavelengths& lambda) noexcept {
    VertexDirection<typename Sc::Spectral> out;
    out.wi = wi;
    if (v.on_surface()) {
        sc.materials.visit(v.material, [&](const auto& b) {
            out.value = b.eval(wo, wi, v.ns, lambda);
            out.pdf = b.pdf(wo, wi, v.ns);
        });
    } else {
        const auto& phase = sc.media[std::size_t(v.medium)].phase;
        out.value = Sc::Spectrum::Constant(phase.eval(wo, wi));
        out.pdf = phase.pdf(wo, wi);
    }
    return out;
}

/// The next direction at vertex v from (u1, u2): the BSDF's or the phase function's sample; pdf
/// 0 when there is none.
template <class Sc>
VertexDirection<typename Sc::Spectral> sample_vertex(const Sc& sc, const SceneVertex& v, const Vec3& wo, float u1,
                                                     float u2, const typename Sc::Spectral::Wavelengths& lambda) noexcept {
    VertexDirection<typename Sc::Spectral> out;
    if (v.on_surface()) {
        sc.materials.visit(v.material, [&](const auto& b) {
            const BsdfSample<typename Sc::Spectral> bs = b.sample(wo, v.ns, u1, u2, lambda);
            out = {bs.wi, bs.value, bs.pdf, bs.delta};
        });
    } else {
        const PhaseSample ps = sc.media[std::size_t(v.medium)].phase.sample(wo, u1, u2);
        out = {ps.wi, Sc::Spectrum::Constant(ps.value), ps.pdf, false};
    }
    return out;
}

/// How far a shadow ray toward a light sample at `light_distance` runs: short of the light's own
/// surface, which it must not count as a blocker (kInf for lights at infinity).
inline float shadow_distance(float light_distance) noexcept {
    return std::isfinite(light_distance) ? light_distance * (1.f - 1e-4f) : kInf;
}

/// The transmittance of a shadow ray from r.o, which lies in medium `medium`, over `distance`
/// through the scene: one VertexKernels::shadow per medium between the null interfaces it
/// crosses, transmittances and null-pdf products multiplied; 0 where a surface that is not a
/// null interface blocks it. Status InvalidInput on a hit the estimator cannot use.
template <class K, class Sc, UniformRng R, LookupCounter C>
ShadowTransmittance<typename Sc::Spectral> shadow_through(const K& k, const Sc& sc, Ray r, float distance, int medium,
                                                          const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                          C& counter) {
    using Sp = typename Sc::Spectral;
    ShadowTransmittance<Sp> out;
    out.transmittance = Sp::Spectrum::Ones();
    const ShadowTransmittance<Sp> blocked;
    for (int crossing = 0; crossing <= kMaxInterfaceCrossings; ++crossing) {
        const SurfaceHit h = sc.geometry.intersect(r, distance);
        if (!usable_hit(sc, h)) return {Sp::Spectrum::Zero(), 1.f, Status::InvalidInput};
        if (sc.has_medium(medium)) {
            const auto& m = sc.media[std::size_t(medium)];
            const auto s = k.shadow(m.medium, m.majorant, r, h.found() ? h.t : distance, lambda, rng, counter);
            if (s.status != Status::Ok) return {Sp::Spectrum::Zero(), 1.f, s.status};
            out.transmittance *= s.transmittance;
            out.null_pdf_product *= s.null_pdf_product;
            if (!(out.transmittance != 0.f).any()) return blocked;
        }
        if (!h.found()) return out;
        if (!crosses(sc, h)) return blocked;
        medium = h.medium_entered(r.d);
        r.o = h.p;
        distance -= h.t;
    }
    return {Sp::Spectrum::Zero(), 1.f, Status::InvalidInput};
}

/// One path of PathEstimator<St, H, A> through a SurfaceScene, on the kernels `k`.
template <class K, class Sc, UniformRng R, LookupCounter C>
RadianceSample<typename Sc::Spectral> surface_radiance(const K& k, const Sc& sc, const Ray& camera_ray,
                                                       const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                       C& counter) {
    using St = typename K::Strategy;
    using Spectrum = typename Sc::Spectrum;
    static_assert(!St::equiangular,
                  "nsp::PathEstimator over a SurfaceScene: the equiangular strategies aim at the point or sphere light "
                  "of nsp::Scene and do not render scenes with surfaces yet");
    static_assert(!EmissiveMedium<typename Sc::MediumType>,
                  "nsp::PathEstimator over a SurfaceScene: emissive media render in nsp::Scene only so far");
    Spectrum L = Spectrum::Zero(), beta = Spectrum::Ones();
    Status status = Status::Ok;
    Ray ray = camera_ray;
    int medium = sc.camera_medium;
    VertexPdf from = VertexPdf::from_camera();  // the last real vertex, for the MIS weight of what the path hits
    float nulls = 1.f;                          // prod P_n of the segments since that vertex
    Vec3 prev = ray.o;
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
            const auto seg = k.track(m.medium, m.majorant, ray, hit.t, lambda, rng, counter);
            if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
                status = fs;
                break;
            }
            beta *= seg.weight;
            nulls *= seg.null_pdf_product;
            if (seg.end == SegmentEnd::Scattered) {
                in_medium = true;
                t_medium = seg.t;
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
                    for (const int i : sc.lights.infinite())
                        L += beta * sc.lights.emitted(i, ray.d, lambda) *
                             k.hit_weight(from, nulls, from.camera ? 0.f : sc.lights.pdf(i, prev, ray.d));
                break;
            }
            if (hit.light >= 0 && k.counts_hit(from))
                L += beta * sc.lights.emitted(hit.light, ray.d, lambda) *
                     k.hit_weight(from, nulls, from.camera ? 0.f : sc.lights.pdf(hit.light, prev, ray.d));
            if (crosses(sc, hit)) {  // a null interface: no vertex, the segment goes on in the next medium
                if (++crossings > kMaxInterfaceCrossings) {
                    status = Status::InvalidInput;
                    break;
                }
                medium = hit.medium_entered(ray.d);
                ray.o = hit.p;
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
            const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
            if (!(v.on_surface() && sc.materials.is_delta(material))) {
                const SampledLight<typename Sc::Spectral> ls = sc.lights.sample(x, u0, u1, u2, lambda);
                if (ls.sample.pdf > 0.f) {
                    const auto f = eval_vertex(sc, v, ray.d, ls.sample.wi, lambda);
                    if ((f.value != 0.f).any()) {
                        const auto sh = shadow_through(k, sc, Ray{x, f.wi}, shadow_distance(ls.sample.distance),
                                                       v.on_surface() ? hit.medium_entered(f.wi) : medium, lambda, rng,
                                                       counter);
                        if (sh.status != Status::Ok) {
                            status = sh.status;
                        } else if ((sh.transmittance != 0.f).any()) {
                            const float w =
                                k.light_weight(q, f.pdf, sh.null_pdf_product, ls.sample.pdf, ls.sample.delta);
                            L += beta * sh.transmittance * ls.sample.radiance * f.value * (w / ls.sample.pdf);
                        }
                    }
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
        nulls = 1.f;
        prev = x;
        crossings = 0;
        ray = Ray{x, next.wi};
    }
    if (!all_finite(L)) return {Spectrum::Zero(), Status::NonFinite};
    return {L, status};
}

}  // namespace nsp::detail
