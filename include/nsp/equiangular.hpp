// nsp/equiangular.hpp: equiangular distance sampling toward a point (Kulla and Fajardo 2012,
// THEORY 5.4): the distance sampler and its pdf. The path estimators (estimators/path.hpp,
// strategy::EquiangularNextEvent and strategy::EquiangularMis) draw real vertices with it,
// ratio-track the nulls before them and weigh them against tracking with the analytic ratio.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/math.hpp"

namespace nsp {

/// A distance t on a ray and the density with which it was drawn (per unit length).
struct DistanceSample {
    float t = 0.f;
    float pdf = 0.f;  ///< > 0 for a sample; 0 when the stretch is empty
};

/// Equiangular sampling of t in [t0, t1] along a ray toward a point c: the density
/// p(t) = D / ((theta_1 - theta_0) (D^2 + (t - Delta)^2)), with Delta the ray distance of c's
/// foot point, D its distance from the ray and theta_i = atan((t_i - Delta) / D). It cancels the
/// 1 / distance^2 of a point light. A point on (or within `min_distance` of) the ray would make
/// the density a spike; D is floored at `min_distance` instead, which keeps sampler and pdf
/// consistent (an unbiased estimator with a bounded density) and every value finite. t1 may be
/// infinite. Never throws; a stretch with t1 <= t0 gives pdf 0.
class EquiangularSampler {
public:
    /// An empty sampler (pdf 0 everywhere).
    EquiangularSampler() = default;

    EquiangularSampler(const Ray& ray, const Vec3& c, float t0, float t1, float min_distance = 1e-4f) noexcept
        : t0_(t0), t1_(t1) {
        const Vec3 oc = c - ray.o;
        delta_ = glm::dot(oc, ray.d);
        const Vec3 perp = oc - delta_ * ray.d;
        // The floor keeps D^2 a normal float (1e-18^2 = 1e-36), so the density stays finite.
        d_ = std::max(glm::length(perp), std::max(min_distance, 1e-18f));
        theta0_ = std::atan2(t0 - delta_, d_);  // atan2 takes t1 = inf to pi/2
        theta1_ = std::atan2(t1 - delta_, d_);
        valid_ = t1 > t0 && theta1_ > theta0_;
    }

    /// t for a uniform u in [0, 1), with its density.
    DistanceSample sample(float u) const noexcept {
        if (!valid_) return {};
        const float theta = theta0_ + u * (theta1_ - theta0_);
        // tan stays finite below pi/2 (an infinite stretch has theta1 = pi/2); rounding may put t
        // a hair outside the stretch, so it is clamped back.
        const float t = std::clamp(delta_ + d_ * std::tan(std::min(theta, 1.5707962f)), t0_, t1_);
        return {t, density(t)};
    }

    /// The density of distance t (0 outside [t0, t1] or for an empty stretch).
    float pdf(float t) const noexcept { return valid_ && t >= t0_ && t <= t1_ ? density(t) : 0.f; }

    /// The distance in [t0, t1] where the density is largest: the foot point, clamped (0 for an
    /// empty stretch).
    float peak() const noexcept { return valid_ ? std::clamp(delta_, t0_, t1_) : 0.f; }

    float distance_to_ray() const noexcept { return d_; }  ///< D (floored)
    float foot() const noexcept { return delta_; }         ///< Delta

private:
    float density(float t) const noexcept {
        const float x = t - delta_;
        return d_ / ((theta1_ - theta0_) * (d_ * d_ + x * x));
    }

    float t0_ = 0.f, t1_ = 0.f;
    float delta_ = 0.f, d_ = 1.f, theta0_ = 0.f, theta1_ = 0.f;
    bool valid_ = false;
};

}  // namespace nsp
