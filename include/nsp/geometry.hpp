// nsp/geometry.hpp: a host's surfaces as nsp sees them (THEORY 5.8): the record of the surface a
// ray reaches first, and the concept a host's geometry models. nsp has no BVH or mesh format of
// its own; the host intersects, with whatever acceleration it has, and reports what it found as
// plain values: the distance, the normals, and small integer handles into its own tables (the
// BSDF there, the light emitting there, the media on either side). Handles rather than pointers
// keep the record trivially copyable and the same on a GPU.
#pragma once

#include <algorithm>
#include <concepts>

#include "core/math.hpp"

namespace nsp {

/// A SurfaceHit side's medium that the surface does not change: a ray crossing into that side
/// keeps the medium it is in, and a path leaving a vertex there into that side stays in the
/// medium it arrived in (an object inside a medium whose geometry does not name it, or a thin
/// surface in one). On both sides: the surface bounds no medium. The estimators replace it by
/// the ray's medium where the hit is found (SurfaceHit::keep_media).
inline constexpr int kSameMedium = -2;

/// What a BSDF sees of the surface point it scatters at: the point, its normals, the host's
/// shading tangent and surface parameters, and one datum of the host's own (a primitive or
/// texture index) that nsp carries without reading. A textured, anisotropic or position-dependent
/// BSDF reads what it needs; a simple one reads only `ns`.
struct ShadingPoint {
    Vec3 p{0.f};               ///< the point
    Vec3 ng{0.f, 0.f, 1.f};    ///< unit geometric normal
    Vec3 ns{0.f, 0.f, 1.f};    ///< unit shading normal
    Vec3 dpdu{0.f};            ///< the host's shading tangent along u (0: none given)
    Vec2 uv{0.f};              ///< surface parameters (texture coordinates)
    int user = -1;             ///< the host's own datum for this hit; nsp never reads it
};

/// What a ray reaches first among a host's surfaces.
struct SurfaceHit {
    float t = kInf;            ///< distance along the ray; kInf: nothing
    Vec3 p{0.f};               ///< the point
    Vec3 ng{0.f, 0.f, 1.f};    ///< unit geometric normal, the side medium_front lies on
    Vec3 ns{0.f, 0.f, 1.f};    ///< unit shading normal (what a BSDF is given)
    int material = -1;         ///< the host's BSDF at p; -1: none, an index-matched medium boundary
    int light = -1;            ///< the light emitting at p (e.g. a LightSampler index); -1: none
    int medium_front = -1;     ///< the medium on the side ng points to; -1: vacuum; kSameMedium
    int medium_back = -1;      ///< the medium on the other side; -1: vacuum; kSameMedium
    Vec2 uv{0.f};              ///< surface parameters at p, for the BSDF (ShadingPoint)
    Vec3 dpdu{0.f};            ///< shading tangent along u, for the BSDF (0: none given)
    int user = -1;             ///< the host's own datum, handed to the BSDF untouched

    bool found() const noexcept { return t < kInf; }
    /// A boundary a path crosses without a vertex: no BSDF and no light there.
    bool passes_through() const noexcept { return material < 0 && light < 0; }
    /// The medium a ray travelling along d is in after crossing p.
    int medium_entered(const Vec3& d) const noexcept { return glm::dot(d, ng) > 0.f ? medium_front : medium_back; }
    /// The medium a ray travelling along d was in before reaching p.
    int medium_left(const Vec3& d) const noexcept { return glm::dot(d, ng) > 0.f ? medium_back : medium_front; }
    /// What the BSDF at p is given.
    ShadingPoint shading() const noexcept { return {p, ng, ns, dpdu, uv, user}; }
    /// This hit's kSameMedium sides as `current`, the medium of the ray that found it.
    void keep_media(int current) noexcept {
        if (medium_front == kSameMedium) medium_front = current;
        if (medium_back == kSameMedium) medium_back = current;
    }
};

/// A host's geometry: `intersect(ray, t_max)` is the closest surface on (0, t_max) (t = kInf if
/// none), the only query nsp makes: paths and shadow rays alike walk from surface to surface,
/// crossing null interfaces (where the medium changes) and stopping at anything else. The ray
/// starts on the surface it leaves, unoffset: `intersect` must not report that surface again (an
/// epsilon, or the primitive's id), as every renderer's own does. A host's occlusion (any-hit)
/// query is its own business: nsp needs the closest hit, since a shadow ray is tracked through
/// every medium up to the blocker or the light.
template <class G>
concept Geometry = requires(const G& g, const Ray& r, float t) {
    { g.intersect(r, t) } -> std::same_as<SurfaceHit>;
};

/// A scene without surfaces: media in empty space. Every query is answered at no cost.
struct NoSurfaces {
    static constexpr bool is_empty_space = true;  ///< no surface bounds a medium: the camera's fills space
    SurfaceHit intersect(const Ray&, float) const noexcept { return {}; }
    /// The distance to the first surface before t_max (kInf: none), for shadow rays.
    float distance(const Ray&, float) const noexcept { return kInf; }
    /// Whether light `light` is this geometry's surface (never).
    bool ends_on(int) const noexcept { return false; }
};

/// Media in empty space with an optional sphere light (nsp::Scene's geometry): the sphere is the
/// only surface, reported with light handle `light` and no material (what reaches it ends there);
/// medium `medium` lies on both of its sides, as it fills space (tracking clips it to its box).
/// The sphere lies outside every medium's bounds (SurfaceScene refuses it otherwise), so a
/// segment from a point inside a medium leaves the medium's box before it can reach the sphere:
/// the path loop looks for the sphere only where such a segment passes its medium.
struct EmptySpace {
    static constexpr bool is_empty_space = true;
    bool has_sphere = false;
    Vec3 center{0.f};
    float radius = 0.f;
    int light = -1;
    int medium = 0;

    SurfaceHit intersect(const Ray& r, float t_max) const noexcept {
        SurfaceHit h;
        if (!has_sphere) return h;
        const float t = intersect_sphere(r, center, radius);
        if (!(t < t_max)) return h;
        h.t = t;
        h.p = r.at(t);
        const Vec3 n = glm::normalize(h.p - center);
        h.ng = h.ns = n;
        h.light = light;
        h.medium_front = h.medium_back = medium;
        return h;
    }
    /// The distance to the sphere light before t_max (kInf: none), for shadow rays.
    float distance(const Ray& r, float t_max) const noexcept {
        if (!has_sphere) return kInf;
        const float t = intersect_sphere(r, center, radius);
        return t < t_max ? t : kInf;
    }
    /// Whether light `light` is the sphere: a walk to a point sampled on its visible cap.
    bool ends_on(int l) const noexcept { return has_sphere && l >= 0 && l == light; }
    /// Whether the sphere (if any) lies apart from `box`: its centre farther from the box than
    /// its radius.
    bool apart_from(const Box& box) const noexcept {
        return !has_sphere || glm::length(glm::clamp(center, box.lo, box.hi) - center) > radius;
    }
};

/// True for a geometry with no surface that bounds a medium (NoSurfaces, EmptySpace).
template <class G>
inline constexpr bool is_empty_space_v = requires { requires bool(G::is_empty_space); };

static_assert(Geometry<NoSurfaces> && Geometry<EmptySpace>);

/// The faces of a medium's box as null interfaces (THEORY 5.8), for a host's `intersect` to
/// report beside its own surfaces: the medium `inside` fills `box`, `outside` surrounds it. Hits
/// closer than `epsilon` (in the scene's units) are the face a ray starts on and are not reported.
/// A host whose medium is bounded by its own meshes reports those instead.
///
///     SurfaceHit intersect(const Ray& r, float t_max) const {
///         return nsp::nearer(my_bvh.intersect(r, t_max), fog_box.intersect(r, t_max));
///     }
struct MediumBox {
    Box box;
    int inside = 0;        ///< the medium in the box (an index into the scene's media)
    int outside = -1;      ///< the medium around it (-1: vacuum)
    float epsilon = 1e-4f;

    /// The first face on (epsilon, t_max), a null interface (no material, no light), its outward
    /// normal as ng and ns; t = kInf if none.
    SurfaceHit intersect(const Ray& r, float t_max) const noexcept {
        int enter_axis, exit_axis;
        const Interval span = box.clip(r, -kInf, kInf, enter_axis, exit_axis);  // the whole line's stretch
        if (!(span.t0 <= span.t1)) return {};  // a miss (a ray grazing an edge hits it)
        const bool entering = span.t0 > epsilon;
        const float t = entering ? span.t0 : span.t1;
        const int axis = entering ? enter_axis : exit_axis;
        if (!(t > epsilon && t < t_max) || axis < 0) return {};
        SurfaceHit h;
        h.t = t;
        h.p = r.at(t);
        // The outward normal of the face the slab test found: against the ray where it enters,
        // along it where it leaves, so medium_entered() is right even at an edge, where the
        // point alone cannot tell the faces apart.
        Vec3 n(0.f);
        n[axis] = entering == (r.d[axis] > 0.f) ? -1.f : 1.f;
        h.ng = h.ns = n;
        h.medium_front = outside;
        h.medium_back = inside;
        return h;
    }
};

static_assert(Geometry<MediumBox>);

/// The nearer of two hits (a host's own and a MediumBox's, say).
inline SurfaceHit nearer(const SurfaceHit& a, const SurfaceHit& b) noexcept { return b.t < a.t ? b : a; }

}  // namespace nsp
