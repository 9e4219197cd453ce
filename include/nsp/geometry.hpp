// nsp/geometry.hpp: a host's surfaces as nsp sees them (THEORY 5.8): the record of the surface a
// ray reaches first, and the concept a host's geometry models. nsp has no BVH or mesh format of
// its own; the host intersects, with whatever acceleration it has, and reports what it found as
// plain values: the distance, the normals, and small integer handles into its own tables (the
// BSDF there, the light emitting there, the media on either side). Handles rather than pointers
// keep the record trivially copyable and the same on a GPU.
#pragma once

#include <concepts>

#include "core/math.hpp"

namespace nsp {

/// What a ray reaches first among a host's surfaces.
struct SurfaceHit {
    float t = kInf;            ///< distance along the ray; kInf: nothing
    Vec3 p{0.f};               ///< the point
    Vec3 ng{0.f, 0.f, 1.f};    ///< unit geometric normal, the side medium_front lies on
    Vec3 ns{0.f, 0.f, 1.f};    ///< unit shading normal (what a BSDF is given)
    int material = -1;         ///< the host's BSDF at p; -1: none, an index-matched medium boundary
    int light = -1;            ///< the light emitting at p (e.g. a LightSampler index); -1: none
    int medium_front = -1;     ///< the medium on the side ng points to; -1: vacuum
    int medium_back = -1;      ///< the medium on the other side; -1: vacuum

    bool found() const noexcept { return t < kInf; }
    /// A boundary a path crosses without a vertex: no BSDF and no light there.
    bool passes_through() const noexcept { return material < 0 && light < 0; }
    /// The medium a ray travelling along d is in after crossing p.
    int medium_entered(const Vec3& d) const noexcept { return glm::dot(d, ng) > 0.f ? medium_front : medium_back; }
    /// The medium a ray travelling along d was in before reaching p.
    int medium_left(const Vec3& d) const noexcept { return glm::dot(d, ng) > 0.f ? medium_back : medium_front; }
};

/// A host's geometry: `intersect(ray, t_max)` is the closest surface on (0, t_max) (t = kInf if
/// none), `occluded(ray, t_max)` whether a surface that is not a pass-through boundary lies on
/// (0, t_max): what a shadow ray asks (index-matched boundaries do not block it; the media on its
/// way are the host's to track, one VertexKernels::shadow per medium).
template <class G>
concept Geometry = requires(const G& g, const Ray& r, float t) {
    { g.intersect(r, t) } -> std::same_as<SurfaceHit>;
    { g.occluded(r, t) } -> std::same_as<bool>;
};

/// A scene without surfaces: media in empty space. Every query is answered at no cost.
struct NoSurfaces {
    SurfaceHit intersect(const Ray&, float) const noexcept { return {}; }
    bool occluded(const Ray&, float) const noexcept { return false; }
};

static_assert(Geometry<NoSurfaces>);

}  // namespace nsp
