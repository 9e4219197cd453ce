// nsp/light.hpp: the lights estimators know: a point light, a spherical area light and a
// constant environment, with light sampling for next-event estimation and the pdf of hitting
// them by unidirectional sampling (both in solid angle at the shading point).
#pragma once

#include <cmath>
#include <limits>
#include <optional>

#include "core/error.hpp"
#include "core/math.hpp"
#include "media/validate.hpp"
#include "spectrum.hpp"

namespace nsp {

/// An isotropic point light with radiant intensity `intensity` (W/sr). Reachable by NEE only.
template <SpectralMode S>
struct PointLight {
    Vec3 position;
    typename S::Coefficient intensity;
};

/// A sphere emitting radiance `radiance` from its surface, outward. Opaque: it blocks light.
template <SpectralMode S>
struct SphereLight {
    Vec3 center;
    float radius;
    typename S::Coefficient radiance;
};

/// Constant radiance arriving from every direction at infinity.
template <SpectralMode S>
struct EnvironmentLight {
    typename S::Coefficient radiance;
};

/// What a ray meets first among the lights.
struct LightHit {
    float t = kInf;       ///< distance to the sphere light, or kInf (the environment)
    bool sphere = false;  ///< true when the ray hits the sphere light
};

/// A light sample for next-event estimation from a point x.
template <SpectralMode S>
struct LightSample {
    Vec3 wi;                          ///< unit direction from x toward the light
    float distance = kInf;            ///< distance to the light's vertex (kInf: environment)
    typename S::Spectrum radiance;    ///< incident radiance (point light: intensity / d^2)
    float pdf = 0.f;                  ///< solid-angle pdf including light selection (delta: selection only)
    bool delta = false;               ///< a point light: no other strategy can sample it
    bool occludable_by_sphere = false;///< the sphere light may block this sample
};

/// The lights of a scene: at most one of each kind, selected uniformly for NEE.
template <SpectralMode S>
class Lights {
public:
    using Spectrum = typename S::Spectrum;

    /// Sets the point light; throws InvalidArgument on a non-finite position or bad intensity.
    Lights& set(const PointLight<S>& l) {
        for (int a = 0; a < 3; ++a) detail::require_finite(l.position[a], "PointLight position");
        detail::require_coefficient(l.intensity, "PointLight intensity");
        point_ = l;
        return *this;
    }
    /// Sets the sphere light; throws InvalidArgument on a non-finite centre, a radius that is not
    /// finite and > 0 (or whose square overflows), or a bad radiance.
    Lights& set(const SphereLight<S>& l) {
        for (int a = 0; a < 3; ++a) detail::require_finite(l.center[a], "SphereLight center");
        if (!std::isfinite(l.radius) || !(l.radius > 0.f))
            detail::fail("SphereLight radius = ", l.radius, " is not allowed: it must be finite and > 0");
        if (!std::isfinite(l.radius * l.radius))
            detail::fail("SphereLight radius = ", l.radius, " is not allowed: radius^2 must be finite (radius <= ",
                         std::sqrt(std::numeric_limits<float>::max()), ")");
        detail::require_coefficient(l.radiance, "SphereLight radiance");
        sphere_ = l;
        return *this;
    }
    /// Sets the environment; throws InvalidArgument on a bad radiance.
    Lights& set(const EnvironmentLight<S>& l) {
        detail::require_coefficient(l.radiance, "EnvironmentLight radiance");
        env_ = l;
        return *this;
    }

    const std::optional<PointLight<S>>& point() const noexcept { return point_; }
    const std::optional<SphereLight<S>>& sphere() const noexcept { return sphere_; }
    const std::optional<EnvironmentLight<S>>& environment() const noexcept { return env_; }

    /// Where equiangular sampling aims (THEORY 5.4): the point light, else the sphere light's
    /// centre, else nothing.
    std::optional<Vec3> equiangular_target() const noexcept {
        if (point_) return point_->position;
        if (sphere_) return sphere_->center;
        return std::nullopt;
    }

    /// Number of lights NEE chooses from.
    int count() const noexcept { return int(point_.has_value()) + int(sphere_.has_value()) + int(env_.has_value()); }

    /// The first light along the ray (the sphere, else the environment at infinity).
    LightHit intersect(const Ray& r) const noexcept {
        if (!sphere_) return {};
        const float t = intersect_sphere(r, sphere_->center, sphere_->radius);
        return {t, t < kInf};
    }

    /// Radiance a ray receives at `hit` at wavelengths l: the sphere's, the environment's, or zero.
    Spectrum emitted(const LightHit& hit, const typename S::Wavelengths& l = {}) const noexcept {
        if (hit.sphere) return S::sample(sphere_->radiance, l);
        if (env_) return S::sample(env_->radiance, l);
        return Spectrum::Zero();
    }

    /// Solid-angle pdf, at x, that `sample` picks direction wi to the light at `hit`.
    float pdf(const Vec3& x, const LightHit& hit) const noexcept {
        const int n = count();
        if (n == 0) return 0.f;
        if (hit.sphere) return cone_pdf(x) / float(n);
        return env_ ? kInv4Pi / float(n) : 0.f;
    }

    /// Chooses a light uniformly with u0 and samples a direction toward it with (u1, u2):
    /// uniform in the cone the sphere subtends, uniform on the sphere of directions for the
    /// environment; radiance at wavelengths l. Returns pdf 0 when there is no light.
    LightSample<S> sample(const Vec3& x, float u0, float u1, float u2,
                          const typename S::Wavelengths& l = {}) const noexcept {
        LightSample<S> s{Vec3(0.f, 0.f, 1.f), kInf, Spectrum::Zero(), 0.f, false, false};
        const int n = count();
        if (n == 0) return s;
        int pick = std::min(int(u0 * float(n)), n - 1);
        const float sel = 1.f / float(n);
        if (point_ && pick-- == 0) {
            const Vec3 d = point_->position - x;
            const float d2 = glm::dot(d, d);
            if (!(d2 > 0.f)) return s;
            s.distance = std::sqrt(d2);
            s.wi = d / s.distance;
            s.radiance = S::sample(point_->intensity, l) / d2;
            s.pdf = sel;
            s.delta = true;
            s.occludable_by_sphere = sphere_.has_value();
            return s;
        }
        if (sphere_ && pick-- == 0) {
            const Vec3 dc = sphere_->center - x;
            const float d = glm::length(dc);
            const float r = sphere_->radius;
            if (!(d > r)) return s;  // x inside the light: it cannot be sampled from here
            const float sin2 = (r * r) / (d * d);
            const float cos_max = std::sqrt(std::max(0.f, 1.f - sin2));
            const float one_minus_cos = sin2 / (1.f + cos_max);  // stable for small lights
            const float cos_theta = 1.f - u1 * one_minus_cos;
            s.wi = direction_around(dc / d, cos_theta, 2.f * kPi * u2);
            float t = intersect_sphere(Ray{x, s.wi}, sphere_->center, r);
            if (!(t < kInf))  // grazing: the tangent distance
                t = d * cos_theta - std::sqrt(std::max(0.f, r * r - d * d * (1.f - cos_theta * cos_theta)));
            s.distance = t;
            s.radiance = S::sample(sphere_->radiance, l);
            s.pdf = sel / (2.f * kPi * one_minus_cos);
            return s;
        }
        s.wi = uniform_sphere(u1, u2);
        s.radiance = S::sample(env_->radiance, l);
        s.pdf = sel * kInv4Pi;
        s.occludable_by_sphere = sphere_.has_value();
        return s;
    }

    /// True when the sphere light blocks the segment [0, tmax) of r.
    bool sphere_blocks(const Ray& r, float tmax) const noexcept {
        return sphere_ && intersect_sphere(r, sphere_->center, sphere_->radius) < tmax;
    }

private:
    float cone_pdf(const Vec3& x) const noexcept {
        const Vec3 dc = sphere_->center - x;
        const float d2 = glm::dot(dc, dc), r2 = sphere_->radius * sphere_->radius;
        if (!(d2 > r2)) return 0.f;
        const float sin2 = r2 / d2;
        const float one_minus_cos = sin2 / (1.f + std::sqrt(std::max(0.f, 1.f - sin2)));
        return 1.f / (2.f * kPi * one_minus_cos);
    }

    std::optional<PointLight<S>> point_;
    std::optional<SphereLight<S>> sphere_;
    std::optional<EnvironmentLight<S>> env_;
};

}  // namespace nsp
