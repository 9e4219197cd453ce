// nsp/core/math.hpp: rays, boxes, spheres and direction frames shared by every kernel.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace nsp {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInv4Pi = 0.07957747154594767f;
inline constexpr float kInf = std::numeric_limits<float>::infinity();

/// A ray `o + t d`. Every kernel takes `d` of unit length, so that t is a distance (the optical
/// depth of a stretch is mu_bar times its t-length); nsp creates only such rays and rejects the
/// others (usable_ray).
struct Ray {
    Vec3 o;
    Vec3 d;
    /// The point at parameter t.
    Vec3 at(float t) const noexcept { return o + t * d; }
};

/// How far |d|^2 may lie from 1 for a direction nsp accepts as unit length: 1e-3, so that a
/// distance is off by at most 0.05%. A float normalisation is within a few 1e-7 of 1.
inline constexpr float kUnitTolerance = 1e-3f;

/// True when every component of v is finite.
inline bool finite(const Vec3& v) noexcept { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// True when v has unit length within kUnitTolerance (false for NaN and infinite components).
inline bool unit_length(const Vec3& v) noexcept { return std::abs(glm::dot(v, v) - 1.f) <= kUnitTolerance; }

/// Whether the kernels can track `r`: a finite origin and a unit direction (unit_length). Every
/// public kernel entry checks its rays with this and answers a ray that fails it with an
/// InvalidInput status and no estimate, never with a number computed from it.
inline bool usable_ray(const Ray& r) noexcept {
    // o - o is 0 for a finite coordinate and NaN otherwise: one branch for the whole test, which
    // runs at the start of every flight (a few flops against a flight's hundreds of instructions).
    const float finite_o = (r.o.x - r.o.x) + (r.o.y - r.o.y) + (r.o.z - r.o.z);
    return finite_o == 0.f && unit_length(r.d);
}

/// A parametric interval [t0, t1] along a ray.
struct Interval {
    float t0 = 0.f;
    float t1 = 0.f;
    bool empty() const noexcept { return !(t0 < t1); }
};

/// An axis-aligned box.
struct Box {
    Vec3 lo{0.f};
    Vec3 hi{1.f};

    /// True when p lies inside or on the boundary.
    bool contains(const Vec3& p) const noexcept {
        return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y &&
               p.z <= hi.z;
    }

    /// The part of [tmin, tmax] inside the box (empty interval on a miss). Axis-parallel rays
    /// and denormal direction components are handled without 0 * inf.
    Interval clip(const Ray& r, float tmin, float tmax) const noexcept {
        int axes[2];
        return slabs<false>(r, tmin, tmax, axes);
    }

    /// clip(), with the axes of the faces where the part starts and ends (-1 where tmin or tmax
    /// bounds it instead): a face's normal without guessing it from the point.
    Interval clip(const Ray& r, float tmin, float tmax, int& enter_axis, int& exit_axis) const noexcept {
        int axes[2] = {-1, -1};
        const Interval in = slabs<true>(r, tmin, tmax, axes);
        enter_axis = axes[0];
        exit_axis = axes[1];
        return in;
    }

private:
    /// The slab test of both clip()s; with kAxes it also notes which axis bounds each end (kept
    /// out of the plain clip, which tracking runs on every segment: min and max stay branch-free).
    template <bool kAxes>
    Interval slabs(const Ray& r, float tmin, float tmax, int (&axes)[2]) const noexcept {
        float t0 = tmin, t1 = tmax;
        for (int a = 0; a < 3; ++a) {
            if (r.d[a] == 0.f) {
                if (r.o[a] < lo[a] || r.o[a] > hi[a]) return {0.f, 0.f};
                continue;
            }
            // Divide, not multiply by 1 / d: for a denormal d, 1 / d is inf and an origin on
            // the face would give 0 * inf = NaN (found by the grid-majorant DDA tests).
            float tn = (lo[a] - r.o[a]) / r.d[a], tf = (hi[a] - r.o[a]) / r.d[a];
            if (tn > tf) std::swap(tn, tf);
            if constexpr (kAxes) {
                if (tn > t0) axes[0] = a;  // as std::max below: a NaN leaves the bound as it was
                if (tf < t1) axes[1] = a;
            }
            t0 = std::max(t0, tn);
            t1 = std::min(t1, tf);
        }
        return {t0, t1};
    }
};

/// Nearest t in (tmin, inf) where the ray meets the sphere, or kInf. Uses the numerically
/// stable quadratic form (no catastrophic cancellation for small spheres far away).
inline float intersect_sphere(const Ray& r, const Vec3& c, float radius, float tmin = 0.f) noexcept {
    const Vec3 oc = r.o - c;
    const float b = glm::dot(oc, r.d);
    const Vec3 perp = oc - b * r.d;  // offset of the closest approach
    const float disc = radius * radius - glm::dot(perp, perp);
    if (disc < 0.f) return kInf;
    const float c2 = glm::dot(oc, oc) - radius * radius;
    const float q = -b - std::copysign(std::sqrt(disc), b);
    float ta = q != 0.f ? c2 / q : 0.f, tb = q;
    if (ta > tb) std::swap(ta, tb);
    if (ta > tmin) return ta;
    if (tb > tmin) return tb;
    return kInf;
}

/// Two unit vectors that complete `n` to an orthonormal frame (Duff et al. 2017).
inline void orthonormal_basis(const Vec3& n, Vec3& s, Vec3& t) noexcept {
    const float sign = std::copysign(1.f, n.z);
    const float a = -1.f / (sign + n.z);
    const float b = n.x * n.y * a;
    s = Vec3(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    t = Vec3(b, sign + n.y * n.y * a, -n.y);
}

/// The direction with polar cosine `cos_theta` and azimuth `phi` around unit axis `n`.
inline Vec3 direction_around(const Vec3& n, float cos_theta, float phi) noexcept {
    Vec3 s, t;
    orthonormal_basis(n, s, t);
    const float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
    return sin_theta * std::cos(phi) * s + sin_theta * std::sin(phi) * t + cos_theta * n;
}

/// A uniformly distributed unit vector; its solid-angle density is 1 / (4 pi).
inline Vec3 uniform_sphere(float u1, float u2) noexcept {
    const float z = 1.f - 2.f * u1;
    const float r = std::sqrt(std::max(0.f, 1.f - z * z));
    const float phi = 2.f * kPi * u2;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace nsp
