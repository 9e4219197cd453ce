// nsp/phase.hpp: phase functions with sample, eval and pdf.
//
// Directions follow propagation: `wo` is the direction the path travelled to reach the vertex,
// `wi` the direction it leaves in, and cos_theta = dot(wo, wi) (forward scattering for g > 0).
#pragma once

#include <cmath>
#include <concepts>

#include "core/error.hpp"
#include "core/math.hpp"

namespace nsp {

/// A direction drawn from a phase function with its solid-angle pdf and value.
struct PhaseSample {
    Vec3 wi;
    float pdf = 0.f;   ///< solid-angle density of wi
    float value = 0.f; ///< f_p(wo, wi)
};

/// A phase function provides `eval(wo, wi)` (per steradian, integrating to 1), `pdf(wo, wi)`
/// of its own sampling, and `sample(wo, u1, u2)`.
template <class P>
concept PhaseFunction = requires(const P& p, const Vec3& w, float u) {
    { p.eval(w, w) } -> std::same_as<float>;
    { p.pdf(w, w) } -> std::same_as<float>;
    { p.sample(w, u, u) } -> std::same_as<PhaseSample>;
};

/// Uniform scattering: f_p = 1 / (4 pi).
struct IsotropicPhase {
    float eval(const Vec3&, const Vec3&) const noexcept { return kInv4Pi; }
    float pdf(const Vec3&, const Vec3&) const noexcept { return kInv4Pi; }
    PhaseSample sample(const Vec3&, float u1, float u2) const noexcept {
        return {uniform_sphere(u1, u2), kInv4Pi, kInv4Pi};
    }
};

/// Henyey-Greenstein: f_p = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^{3/2}), sampled exactly.
class HenyeyGreensteinPhase {
public:
    /// Throws InvalidArgument unless -1 < g < 1.
    explicit HenyeyGreensteinPhase(float g) : g_(g) {
        if (!(g > -1.f && g < 1.f))
            detail::fail("HenyeyGreensteinPhase g = ", g, " is not allowed: it must lie in (-1, 1)");
    }

    float g() const noexcept { return g_; }

    float eval(const Vec3& wo, const Vec3& wi) const noexcept { return value(glm::dot(wo, wi)); }
    float pdf(const Vec3& wo, const Vec3& wi) const noexcept { return eval(wo, wi); }

    /// Inverts the HG cdf in cos_theta (a closed form; isotropic below |g| = 1e-3).
    [[gnu::always_inline]] PhaseSample sample(const Vec3& wo, float u1, float u2) const noexcept {
        float cos_theta;
        if (std::abs(g_) < 1e-3f) {
            cos_theta = 1.f - 2.f * u1;
        } else {
            const float s = (1.f - g_ * g_) / (1.f - g_ + 2.f * g_ * u1);
            cos_theta = (1.f + g_ * g_ - s * s) / (2.f * g_);
        }
        cos_theta = std::clamp(cos_theta, -1.f, 1.f);
        const Vec3 wi = direction_around(wo, cos_theta, 2.f * kPi * u2);
        const float f = value(cos_theta);
        return {wi, f, f};
    }

private:
    float value(float cos_theta) const noexcept {
        const float denom = 1.f + g_ * g_ - 2.f * g_ * cos_theta;
        return kInv4Pi * (1.f - g_ * g_) / (denom * std::sqrt(denom));
    }
    float g_;
};

static_assert(PhaseFunction<IsotropicPhase> && PhaseFunction<HenyeyGreensteinPhase>);

}  // namespace nsp
