// examples/host/shapes.hpp: a host's own geometry for the example host renderer: spheres,
// axis-aligned boxes, parallelograms (quads) and a triangle list, each with the handles
// nsp::SurfaceHit carries (material, light, the media inside and outside), searched one by one
// (a real renderer would put a BVH here). Models nsp::Geometry. A quad's hits can also carry its
// parameters as uv, its first edge as the shading tangent and its index as the host's datum.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <nsp/geometry.hpp>

namespace nsp_host {

/// What every shape carries into its hits: the host's material and light handles, and the media
/// inside (behind the outward normal) and outside.
struct Handles {
    int material = -1, light = -1, inside = -1, outside = -1;
};

struct Sphere {
    nsp::Vec3 center;
    float radius;
    Handles h;
};
struct Box {
    nsp::Vec3 lo, hi;
    Handles h;
};
/// The parallelogram corner + a edge_u + b edge_v, a, b in [0, 1]; outward normal cross(edge_u, edge_v).
struct Quad {
    nsp::Vec3 corner, edge_u, edge_v;
    Handles h;
};
struct Triangle {
    nsp::Vec3 a, b, c;  ///< outward normal cross(b - a, c - a)
    Handles h;
};

/// The shapes of a scene.
class Shapes {
public:
    std::vector<Sphere> spheres;
    std::vector<Box> boxes;
    std::vector<Quad> quads;
    std::vector<Triangle> triangles;
    /// Whether a quad's hits carry its parameters (a, b) as uv, edge_u as the tangent and the
    /// quad's index as the host's datum (what a textured BSDF or light reads); off, no work is
    /// spent on them.
    bool report_uv = false;

    nsp::SurfaceHit intersect(const nsp::Ray& r, float t_max) const noexcept {
        nsp::SurfaceHit best;
        best.t = t_max;
        bool any = false;
        auto keep = [&](float t, const nsp::Vec3& outward, const Handles& h) {
            if (!(t > kEpsilon) || !(t < best.t)) return;
            any = true;
            best.t = t;
            best.ng = best.ns = glm::normalize(outward);
            best.material = h.material;
            best.light = h.light;
            best.medium_front = h.outside;
            best.medium_back = h.inside;
        };
        for (const Sphere& s : spheres)
            for (const float t : sphere_roots(r, s)) keep(t, r.at(t) - s.center, s.h);
        for (const Box& b : boxes)
            for (const float t : box_roots(r, b)) keep(t, box_normal(r.at(t), b), b.h);
        int quad = -1;  // the nearest quad so far, where uv is reported
        for (std::size_t i = 0; i < quads.size(); ++i) {
            const float t = best.t;
            keep(quad_root(r, quads[i]), glm::cross(quads[i].edge_u, quads[i].edge_v), quads[i].h);
            if (report_uv && best.t < t) quad = int(i);
        }
        const float after_quads = best.t;
        for (const Triangle& tr : triangles) keep(triangle_root(r, tr), glm::cross(tr.b - tr.a, tr.c - tr.a), tr.h);
        if (!any) return {};
        best.p = r.at(best.t);
        if (quad >= 0 && best.t == after_quads) {  // a quad, no triangle nearer
            const Quad& q = quads[std::size_t(quad)];
            const nsp::Vec3 d = best.p - q.corner;
            best.uv = {glm::dot(d, q.edge_u) / glm::dot(q.edge_u, q.edge_u), glm::dot(d, q.edge_v) / glm::dot(q.edge_v, q.edge_v)};
            best.dpdu = glm::normalize(q.edge_u);
            best.user = quad;
        }
        return best;
    }

    /// Whether a surface with a BSDF or a light lies on (0, t_max); media boundaries let it pass.
    bool occluded(const nsp::Ray& r, float t_max) const noexcept {
        nsp::Ray ray = r;
        float left = t_max;
        for (int crossings = 0; crossings < 64; ++crossings) {
            const nsp::SurfaceHit h = intersect(ray, left);
            if (!h.found()) return false;
            if (!h.passes_through()) return true;
            ray.o = h.p;  // go on past the boundary
            left -= h.t;
        }
        return true;  // more boundaries than any sane scene: call it blocked
    }

private:
    static constexpr float kEpsilon = 1e-4f;

    static std::array<float, 2> sphere_roots(const nsp::Ray& r, const Sphere& s) noexcept {
        const nsp::Vec3 oc = r.o - s.center;
        const float b = glm::dot(oc, r.d), c = glm::dot(oc, oc) - s.radius * s.radius;
        const float disc = b * b - c;
        if (disc < 0.f) return {nsp::kInf, nsp::kInf};
        const float sq = std::sqrt(disc);
        return {-b - sq, -b + sq};
    }
    static std::array<float, 2> box_roots(const nsp::Ray& r, const Box& b) noexcept {
        float t0 = -nsp::kInf, t1 = nsp::kInf;
        for (int a = 0; a < 3; ++a) {
            const float inv = 1.f / r.d[a];
            float ta = (b.lo[a] - r.o[a]) * inv, tb = (b.hi[a] - r.o[a]) * inv;
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta);
            t1 = std::min(t1, tb);
        }
        if (!(t0 <= t1)) return {nsp::kInf, nsp::kInf};
        return {t0, t1};
    }
    /// The outward normal of the face of b nearest to p.
    static nsp::Vec3 box_normal(const nsp::Vec3& p, const Box& b) noexcept {
        nsp::Vec3 n(0.f);
        float nearest = std::numeric_limits<float>::infinity();
        for (int a = 0; a < 3; ++a)
            for (const float side : {-1.f, 1.f}) {
                const float d = std::abs(p[a] - (side < 0.f ? b.lo[a] : b.hi[a]));
                if (d < nearest) nearest = d, n = nsp::Vec3(0.f), n[a] = side;
            }
        return n;
    }
    static float quad_root(const nsp::Ray& r, const Quad& q) noexcept {
        const nsp::Vec3 n = glm::cross(q.edge_u, q.edge_v);
        const float denom = glm::dot(n, r.d);
        if (denom == 0.f) return nsp::kInf;
        const float t = glm::dot(n, q.corner - r.o) / denom;
        const nsp::Vec3 p = r.at(t) - q.corner;
        const float a = glm::dot(p, q.edge_u) / glm::dot(q.edge_u, q.edge_u);
        const float b = glm::dot(p, q.edge_v) / glm::dot(q.edge_v, q.edge_v);
        return a >= 0.f && a <= 1.f && b >= 0.f && b <= 1.f ? t : nsp::kInf;
    }
    /// Moller-Trumbore.
    static float triangle_root(const nsp::Ray& r, const Triangle& tr) noexcept {
        const nsp::Vec3 e1 = tr.b - tr.a, e2 = tr.c - tr.a, pv = glm::cross(r.d, e2);
        const float det = glm::dot(e1, pv);
        if (det == 0.f) return nsp::kInf;
        const float inv = 1.f / det;
        const nsp::Vec3 tv = r.o - tr.a;
        const float u = glm::dot(tv, pv) * inv;
        if (u < 0.f || u > 1.f) return nsp::kInf;
        const nsp::Vec3 qv = glm::cross(tv, e1);
        const float v = glm::dot(r.d, qv) * inv;
        if (v < 0.f || u + v > 1.f) return nsp::kInf;
        return glm::dot(e2, qv) * inv;
    }
};

static_assert(nsp::Geometry<Shapes>);

}  // namespace nsp_host
