// nsp/estimators/bdpt_vertex.hpp: a BDPT subpath's vertices (THEORY 5.5): what each stores (its
// densities from both sides, the null and event factors of the segment it was drawn along), the
// measure conversions between them, and the medium a light subpath starts in.
#pragma once

#include <cmath>
#include <cstdint>

#include "../geometry.hpp"
#include "../spectrum.hpp"
#include "../surface_scene.hpp"
#include "bdpt_pdfs.hpp"
#include "scene_walk.hpp"

namespace nsp::bdpt {

/// What one vertex of a subpath is.
enum class VertexKind : std::uint8_t { Camera, Light, Surface, Medium };

/// A real vertex of a camera or light subpath; P the type of its densities (PdfType).
template <SpectralMode S, class P = float>
struct Vertex {
    Vec3 p{0.f};
    Vec3 ng{0.f, 0.f, 1.f}, ns{0.f, 0.f, 1.f};  ///< normals (surfaces; a light vertex: its emitting normal)
    Vec3 dpdu{0.f};                              ///< a surface's shading tangent (SurfaceHit::dpdu)
    Vec2 uv{0.f};                                ///< a surface's parameters (SurfaceHit::uv)
    int user = -1;                               ///< the host's datum at a surface (SurfaceHit::user)
    Vec3 wo{0.f, 0.f, 1.f};                      ///< the subpath's direction of travel arriving at p
    typename S::Spectrum beta = S::Spectrum::Zero();  ///< the subpath's throughput up to p
    P pdf_fwd = broadcast<P>(0.f);   ///< density of p drawn by its own subpath (area / volume measure, with N and E)
    P pdf_rev = broadcast<P>(0.f);   ///< density of p drawn from the other side, from the next vertex of its subpath
    P nulls_in = broadcast<P>(1.f);  ///< N: prod P_n of the segment arriving at p (1 under Directional)
    P event = broadcast<P>(1.f);     ///< E: mu_bar P_s at a medium vertex (1 on surfaces and under Directional)
    /// The equiangular strategy's density of p (a medium vertex; 0 elsewhere and when it is off),
    /// drawn from the camera side's vertex before it: a camera subpath's previous vertex, a light
    /// subpath's next one (kept for y_1 alone, the only light vertex that can be x_1).
    P eq = broadcast<P>(0.f);
    /// Per channel: every channel's factor that all strategies share (Tbar_c, the nulls' mu_bar_c)
    /// over the subpath up to p, relative to the largest.
    [[no_unique_address]] GammaOf<P> gamma = unit_gamma<P>();
    int material = -1, medium = -1, medium_front = -1, medium_back = -1, light = -1;
    VertexKind kind = VertexKind::Camera;
    bool delta = false;           ///< a delta lobe was sampled here: no connection may end at p
    bool delta_position = false;  ///< a point light or a directional light's direction: no path hits it
    bool at_infinity = false;     ///< a light at infinity: x_0 is a direction (solid angle), p its ray's origin

    /// The vertex as the BSDF or phase function there sees it.
    SceneVertex scene_vertex() const noexcept { return {material, medium, {p, ng, ns, dpdu, uv, user}}; }
    /// The medium a ray leaving p along w travels in.
    int medium_toward(const Vec3& w) const noexcept {
        if (kind != VertexKind::Surface) return medium;
        return glm::dot(w, ng) > 0.f ? medium_front : medium_back;
    }
};

/// The vertices of one strategy's path, for an observer (BdptEstimator::radiance_observed): the
/// light subpath's first s vertices (s >= 2), the camera subpath's first t (z_0 the camera; for
/// s = 0 the emitter hit is not among them), and x_0's position (the light point; for a light at
/// infinity, `x0_at_infinity`, the light subpath's ray origin outside the scene or else the last
/// camera vertex's).
template <SpectralMode S, class P = float>
struct PathVertices {
    const Vertex<S, P>* light = nullptr;
    int s = 0;
    const Vertex<S, P>* camera = nullptr;
    int t = 0;
    Vec3 x0{0.f};
    bool x0_at_infinity = false;
};

/// Converts a solid-angle density at `from` toward vertex `to` into `to`'s measure: |n . w| / d^2
/// on a surface or light, 1 / d^2 in a medium; 0 for a point light and the camera. A light at
/// infinity is a direction: its measure is the solid angle, pdf_dir unchanged (0 for a directional
/// light's one direction).
template <SpectralMode S, class P>
float to_vertex_measure(float pdf_dir, const Vec3& from, const Vertex<S, P>& to) noexcept {
    if (to.at_infinity) return to.delta_position ? 0.f : pdf_dir;
    const Vec3 d = to.p - from;
    const float d2 = glm::dot(d, d);
    if (!(d2 > 0.f)) return 0.f;
    switch (to.kind) {
        case VertexKind::Medium: return pdf_dir / d2;
        case VertexKind::Surface: return pdf_dir * std::abs(glm::dot(to.ng, d)) / (d2 * std::sqrt(d2));
        case VertexKind::Light:
            return to.delta_position ? 0.f : pdf_dir * std::abs(glm::dot(to.ng, d)) / (d2 * std::sqrt(d2));
        default: return 0.f;
    }
}

/// Converts the density of a ray from a light at infinity, per area perpendicular to its direction
/// w, into the measure of the vertex `to` it reaches: x |ng . w| on a surface, x 1 in a medium
/// (the ray's length is the tracking's own measure); 0 for a light and the camera.
template <SpectralMode S, class P>
float from_infinity_measure(float pdf_perpendicular, const Vec3& w, const Vertex<S, P>& to) noexcept {
    switch (to.kind) {
        case VertexKind::Medium: return pdf_perpendicular;
        case VertexKind::Surface: return pdf_perpendicular * std::abs(glm::dot(to.ng, w));
        default: return 0.f;
    }
}

/// The medium a light subpath starting at p along w is in (-3 where the host's hits cannot be
/// used): the side facing p of the first surface ahead that names it (across surfaces that bound
/// no medium, kSameMedium on both sides), else likewise behind p, else the scene's unbounded
/// region: the camera's medium when the geometry has no surface that bounds a medium
/// (nsp::NoSurfaces, nsp::EmptySpace: media in empty space fill it), vacuum otherwise. A surface
/// whose side facing p keeps the medium (kSameMedium) and whose other side names one says nothing
/// of p's medium. The camera side's walks see the same media, so both sides of every connection
/// agree.
template <class Sc>
int light_start_medium(const Sc& sc, const Vec3& p, const Vec3& w) noexcept {
    constexpr int kUnknown = -4;
    auto facing = [&](const Vec3& d) {
        Ray r{p, d};
        for (int crossing = 0; crossing <= detail::kMaxInterfaceCrossings; ++crossing) {
            const SurfaceHit h = sc.geometry.intersect(r, kInf);
            if (!detail::usable_hit(sc, h)) return -3;
            if (!h.found()) return kUnknown;
            if (const int left = h.medium_left(d); left != kSameMedium) return left;
            if (h.medium_entered(d) != kSameMedium) return kUnknown;
            r.o = h.p;  // a surface that bounds no medium: p's medium goes on beyond it
        }
        return -3;  // the host reports the same surface again and again
    };
    if (const int m = facing(w); m != kUnknown) return m;
    if (const int m = facing(-w); m != kUnknown) return m;
    if constexpr (is_empty_space_v<typename Sc::GeometryType>) return sc.camera_medium;
    else return -1;
}

}  // namespace nsp::bdpt
