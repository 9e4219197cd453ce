// nsp/estimators/surface_walk.hpp: what the path loops over a SurfaceScene share (THEORY 5.8):
// which host hits they can use, which surfaces a path crosses without a vertex (null interfaces),
// a real vertex's direction value, pdf and sample (BSDF or phase function), and a shadow ray's
// walk across the media between interfaces. Used by surface_path.hpp (grey),
// surface_emission.hpp and spectral_surface_path.hpp (per channel).
#pragma once

#include <cmath>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../geometry.hpp"
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
    if (!finite(h.p) || !unit_length(h.ng) || !unit_length(h.ns)) return false;
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

/// The part of a shadow ray's length near its end where shadow_through does not look for
/// blockers: 1e-4 of it, so that the surface or light the ray ends on does not block it (0 for
/// lights at infinity). The media are tracked over the whole length all the same.
inline float shadow_margin(float distance) noexcept { return std::isfinite(distance) ? distance * 1e-4f : 0.f; }

/// The transmittance of a shadow ray from r.o, which lies in medium `medium`, to the point at
/// `distance` (kInf: a light at infinity) through the scene: one VertexKernels::shadow per medium
/// between the null interfaces it crosses, transmittances and null-pdf products multiplied, the
/// last medium tracked up to the end point itself; 0 where a surface that is not a null interface
/// blocks it before shadow_margin of the end. Status InvalidInput on a hit the estimator cannot
/// use. `end_medium`, if given, receives the medium the ray ends in (where it passes).
template <class K, class Sc, UniformRng R, LookupCounter C>
ShadowTransmittance<typename Sc::Spectral> shadow_through(const K& k, const Sc& sc, Ray r, float distance, int medium,
                                                          const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                          C& counter, int* end_medium = nullptr) {
    using Sp = typename Sc::Spectral;
    ShadowTransmittance<Sp> out;
    out.transmittance = Sp::Spectrum::Ones();
    const ShadowTransmittance<Sp> blocked;
    const float margin = shadow_margin(distance);
    for (int crossing = 0; crossing <= kMaxInterfaceCrossings; ++crossing) {
        const SurfaceHit h = sc.geometry.intersect(r, distance - margin);
        if (!usable_hit(sc, h)) return {Sp::Spectrum::Zero(), 1.f, Status::InvalidInput};
        if (sc.has_medium(medium)) {
            const auto& m = sc.media[std::size_t(medium)];
            const auto s = k.shadow(m.medium, m.majorant, r, h.found() ? h.t : distance, lambda, rng, counter);
            if (s.status != Status::Ok) return {Sp::Spectrum::Zero(), 1.f, s.status};
            out.transmittance *= s.transmittance;
            out.null_pdf_product *= s.null_pdf_product;
            if (!(out.transmittance != 0.f).any()) return blocked;
        }
        if (!h.found()) {
            if (end_medium) *end_medium = medium;
            return out;
        }
        if (!crosses(sc, h)) return blocked;
        medium = h.medium_entered(r.d);
        r.o = h.p;
        distance -= h.t;
    }
    return {Sp::Spectrum::Zero(), 1.f, Status::InvalidInput};
}


}  // namespace nsp::detail
