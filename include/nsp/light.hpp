// nsp/light.hpp: the lights estimators know: a point light, a spherical area light, a one-sided
// rectangle, a distant (directional) light and a constant environment, with light sampling for
// next-event estimation and the pdf of hitting them by unidirectional sampling (both in solid
// angle at the shading point).
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <limits>
#include <optional>

#include "core/error.hpp"
#include "core/math.hpp"
#include "geometry.hpp"
#include "media/validate.hpp"
#include "spectrum.hpp"

namespace nsp {

/// What a ray meets first among the lights.
struct LightHit {
    float t = kInf;       ///< distance to the sphere light, or kInf (the environment)
    bool sphere = false;  ///< true when the ray hits the sphere light
};

/// A light sample for next-event estimation from a point x.
template <SpectralMode S>
struct LightSample {
    Vec3 wi{0.f, 0.f, 1.f};           ///< unit direction from x toward the light
    float distance = kInf;            ///< distance to the light's vertex (kInf: environment)
    typename S::Spectrum radiance = S::Spectrum::Zero();  ///< incident radiance (point light: intensity / d^2)
    float pdf = 0.f;                  ///< solid-angle pdf including light selection (delta: selection only); 0: no sample
    bool delta = false;               ///< a point light: no other strategy can sample it
    bool occludable_by_sphere = false;///< Lights<S>: the sphere light may block this sample
    Vec2 uv{0.f};                     ///< where on the light it lies: the light's own surface parameters
    int user = -1;                    ///< and its own datum there (a primitive index; -1: none)
};

/// A point and direction of emission drawn from a light, for light subpaths (THEORY 5.5): the
/// point by `pdf_pos` (area measure; 1 for a point light's delta position), the direction leaving
/// it by `pdf_dir` (solid angle), the radiance (a point light: its intensity) sent along `w`, and
/// `cos` = |n . w| at the point (1 for a point light). pdf_pos 0: no sample.
/// From a light at infinity (`at_infinity`, LightSampler with a BoundingSphere) the path's first
/// vertex is the direction -w toward the light: pdf_pos is its solid-angle density, p the ray's
/// origin outside the scene and pdf_dir its density on a disk facing along w (area measure
/// perpendicular to w), n = w, cos = 1.
template <SpectralMode S>
struct LightEmission {
    Vec3 p{0.f}, n{0.f, 0.f, 1.f}, w{0.f, 0.f, 1.f};  ///< the point, its unit normal (a point light: w), the direction
    typename S::Spectrum radiance = S::Spectrum::Zero();
    float pdf_pos = 0.f, pdf_dir = 0.f, cos = 0.f;
    bool delta_position = false;  ///< a point light, or a DirectionalLight's one direction: no path can hit it
    bool at_infinity = false;     ///< a light at infinity (see above)
    Vec2 uv{0.f};                 ///< where on the light p lies (as LightSample::uv)
    int user = -1;                ///< the light's datum there (as LightSample::user)
};

/// The point `at` a light's densities get for one of its own samples (SurfacePdfLight): p, and
/// the uv and datum the sample reported; its normals and tangent unset.
inline ShadingPoint light_point(const Vec3& p, Vec2 uv, int user) noexcept {
    ShadingPoint at;
    at.p = p;
    at.uv = uv;
    at.user = user;
    return at;
}

/// The densities with which a light's `sample_emission` produces point p (on the light) and a
/// direction w leaving it, and |n . w| there (see LightEmission).
struct EmissionDensity {
    float pdf_pos = 0.f, pdf_dir = 0.f, cos = 0.f;
};

/// A light from which light subpaths start (BdptEstimator): `sample_emission(u1, u2, u3, u4,
/// lambda)` and `emission_pdf(p, w)` as above. Lights at infinity (`is_infinite`, and
/// DirectionalLight, `is_distant`) have none of their own: LightSampler starts their light
/// subpaths when it has a BoundingSphere (else bidirectional estimators reach them by hitting and
/// NEE alone, a DirectionalLight by NEE alone).
template <class L, class S>
concept EmittingLight = SpectralMode<S> &&
    requires(const L& l, const Vec3& v, float u, const typename S::Wavelengths& lambda) {
        { l.sample_emission(u, u, u, u, lambda) } -> std::same_as<LightEmission<S>>;
    } &&
    (requires(const L& l, const Vec3& v) {
        { l.emission_pdf(v, v) } -> std::same_as<EmissionDensity>;
    } || requires(const L& l, const ShadingPoint& at, const Vec3& v) {
        { l.emission_pdf(at, v) } -> std::same_as<EmissionDensity>;
    });

/// A light whose emitted radiance depends only on the direction of the ray that reaches it:
/// `emitted(w, lambda)`.
template <class L, class S>
concept DirectionEmitter = requires(const L& l, const Vec3& w, const typename S::Wavelengths& lambda) {
    { l.emitted(w, lambda) } -> std::same_as<typename S::Spectrum>;
};

/// A light on a host's surface that sees where a ray reaches it: `emitted(sp, w, lambda)`, sp the
/// hit on the light (its point, normals, uv and the host's datum, SurfaceHit::shading()), for a
/// textured or one-sided emitter. Its `sample` and `sample_emission` give the radiance at the
/// points they draw themselves.
template <class L, class S>
concept SurfaceEmitter = requires(const L& l, const ShadingPoint& sp, const Vec3& w, const typename S::Wavelengths& lambda) {
    { l.emitted(sp, w, lambda) } -> std::same_as<typename S::Spectrum>;
};

/// A surface light whose densities depend on where a direction or a ray lands on it (a textured
/// emitter sampled by its texture's brightness, a mesh light by its triangles):
/// `pdf(x, w, at, selection)` and, if it starts light subpaths, `emission_pdf(at, w)`. `at` is
/// the point on the light: at a hit SurfaceHit::shading(), for the light's own samples
/// light_point(p, uv, user) with the uv and datum its LightSample or LightEmission reported. nsp
/// passes `at` wherever it asks a surface light for a density, so such a light need not give the
/// position-only forms (where they are missing, LightSampler's position-only queries give 0).
template <class L, class S>
concept SurfacePdfLight = SurfaceEmitter<L, S> && requires(const L& l, const ShadingPoint& at, const Vec3& v, float u) {
    { l.pdf(v, v, at, u) } -> std::same_as<float>;
};

/// A light a host's loop samples for NEE and may hit (THEORY 5.8). `sample(x, u1, u2, lambda,
/// selection)` draws a direction from x toward it with its solid-angle pdf times `selection` (the
/// probability with which the caller picked this light); `pdf(x, w, selection)` is that density
/// for direction w (0 for a delta light, or where w misses it; a SurfacePdfLight may give
/// `pdf(x, w, at, selection)` instead); `emitted(w, lambda)` or
/// `emitted(sp, w, lambda)` (DirectionEmitter, SurfaceEmitter) what a ray travelling along w
/// receives when it reaches the light; `power(scene_radius)` a grey measure of its emitted power
/// for light selection by power. Models: PointLight, SphereLight, QuadLight, EnvironmentLight,
/// ImageEnvironmentLight (lights/image_environment.hpp); LightSampler chooses among any number of
/// them. A light at infinity (`is_infinite`) is reached by rays that leave the scene, where there
/// is no hit: it is a DirectionEmitter.
template <class L, class S>
concept Light = SpectralMode<S> && (DirectionEmitter<L, S> || SurfaceEmitter<L, S>) &&
    requires(const L& l, const Vec3& v, float u, const typename S::Wavelengths& lambda) {
        { l.sample(v, u, u, lambda, u) } -> std::same_as<LightSample<S>>;
        { l.power(u) } -> std::same_as<float>;
        { L::is_delta } -> std::convertible_to<bool>;
    } &&
    (SurfacePdfLight<L, S> || requires(const L& l, const Vec3& v, float u) {
        { l.pdf(v, v, u) } -> std::same_as<float>;
    });

/// An isotropic point light with radiant intensity `intensity` (W/sr). Reachable by NEE only.
template <SpectralMode S>
struct PointLight {
    static constexpr bool is_delta = true;
    Vec3 position;
    typename S::Coefficient intensity;

    LightSample<S> sample(const Vec3& x, float, float, const typename S::Wavelengths& l = {},
                          float selection = 1.f) const noexcept {
        LightSample<S> s;
        const Vec3 d = position - x;
        const float d2 = glm::dot(d, d);
        if (!(d2 > 0.f)) return s;
        s.distance = std::sqrt(d2);
        s.wi = d / s.distance;
        s.radiance = S::sample(intensity, l) / d2;
        s.pdf = selection;
        s.delta = true;
        return s;
    }
    float pdf(const Vec3&, const Vec3&, float = 1.f) const noexcept { return 0.f; }
    typename S::Spectrum emitted(const Vec3&, const typename S::Wavelengths& = {}) const noexcept {
        return S::Spectrum::Zero();  // a point is never hit
    }
    float power(float = 1.f) const noexcept { return 4.f * kPi * max_value(intensity); }

    /// Its position and a uniform direction: intensity along w, pdf_dir 1 / (4 pi).
    LightEmission<S> sample_emission(float u1, float u2, float, float, const typename S::Wavelengths& l = {}) const noexcept {
        const Vec3 w = uniform_sphere(u1, u2);
        return {position, w, w, S::sample(intensity, l), 1.f, kInv4Pi, 1.f, true};
    }
    EmissionDensity emission_pdf(const Vec3&, const Vec3&) const noexcept { return {1.f, kInv4Pi, 1.f}; }
};

/// A sphere emitting radiance `radiance` from its surface, outward. Opaque: it blocks light.
template <SpectralMode S>
struct SphereLight {
    static constexpr bool is_delta = false;
    Vec3 center;
    float radius;
    typename S::Coefficient radiance;

    /// Uniform in the cone the sphere subtends from x (nothing from inside it).
    LightSample<S> sample(const Vec3& x, float u1, float u2, const typename S::Wavelengths& l = {},
                          float selection = 1.f) const noexcept {
        LightSample<S> s;
        const Vec3 dc = center - x;
        const float d = glm::length(dc);
        const float r = radius;
        if (!(d > r)) return s;  // x inside the light: it cannot be sampled from here
        const float sin2 = (r * r) / (d * d);
        const float cos_max = std::sqrt(std::max(0.f, 1.f - sin2));
        const float one_minus_cos = sin2 / (1.f + cos_max);  // stable for small lights
        const float cos_theta = 1.f - u1 * one_minus_cos;
        s.wi = direction_around(dc / d, cos_theta, 2.f * kPi * u2);
        float t = intersect_sphere(Ray{x, s.wi}, center, r);
        if (!(t < kInf))  // grazing: the tangent distance
            t = d * cos_theta - std::sqrt(std::max(0.f, r * r - d * d * (1.f - cos_theta * cos_theta)));
        s.distance = t;
        s.radiance = S::sample(radiance, l);
        s.pdf = selection / (2.f * kPi * one_minus_cos);
        return s;
    }
    /// The solid-angle density of `sample` at x for any direction into the cone (0 from inside).
    float cone_pdf(const Vec3& x) const noexcept {
        const Vec3 dc = center - x;
        const float d2 = glm::dot(dc, dc), r2 = radius * radius;
        if (!(d2 > r2)) return 0.f;
        const float sin2 = r2 / d2;
        const float one_minus_cos = sin2 / (1.f + std::sqrt(std::max(0.f, 1.f - sin2)));
        return 1.f / (2.f * kPi * one_minus_cos);
    }
    float pdf(const Vec3& x, const Vec3& w, float selection = 1.f) const noexcept {
        return intersect(Ray{x, w}) < kInf ? selection * cone_pdf(x) : 0.f;
    }
    float intersect(const Ray& r) const noexcept { return intersect_sphere(r, center, radius); }
    typename S::Spectrum emitted(const Vec3&, const typename S::Wavelengths& l = {}) const noexcept {
        return S::sample(radiance, l);
    }
    /// pi L x area: what a Lambertian emitter of radiance L sends out.
    float power(float = 1.f) const noexcept { return kPi * max_value(radiance) * 4.f * kPi * radius * radius; }

    /// A uniform point on the sphere, a cosine-weighted direction around its outward normal.
    LightEmission<S> sample_emission(float u1, float u2, float u3, float u4,
                                     const typename S::Wavelengths& l = {}) const noexcept {
        const Vec3 n = uniform_sphere(u1, u2);
        const float c = std::sqrt(std::max(0.f, 1.f - u3));
        if (!(c > 0.f)) return {};
        return {center + radius * n, n, direction_around(n, c, 2.f * kPi * u4), S::sample(radiance, l),
                1.f / (4.f * kPi * radius * radius), c / kPi, c, false};
    }
    EmissionDensity emission_pdf(const Vec3& p, const Vec3& w) const noexcept {
        const float c = glm::dot(glm::normalize(p - center), w);
        return {1.f / (4.f * kPi * radius * radius), c > 0.f ? c / kPi : 0.f, std::max(c, 0.f)};
    }
};

/// A one-sided rectangle at `corner` spanned by `edge_u` and `edge_v`, emitting `radiance` toward
/// the side of cross(edge_u, edge_v). Sampled uniformly by area. A host's geometry holds it (it
/// blocks light where the host says so); `intersect` is there for hosts that have none.
template <SpectralMode S>
struct QuadLight {
    static constexpr bool is_delta = false;
    Vec3 corner, edge_u, edge_v;
    typename S::Coefficient radiance;

    Vec3 normal() const noexcept { return glm::normalize(glm::cross(edge_u, edge_v)); }
    float area() const noexcept { return glm::length(glm::cross(edge_u, edge_v)); }

    LightSample<S> sample(const Vec3& x, float u1, float u2, const typename S::Wavelengths& l = {},
                          float selection = 1.f) const noexcept {
        LightSample<S> s;
        const Vec3 y = corner + u1 * edge_u + u2 * edge_v;
        const Vec3 d = y - x;
        const float d2 = glm::dot(d, d);
        if (!(d2 > 0.f)) return s;
        const float dist = std::sqrt(d2);
        const Vec3 wi = d / dist;
        const float cos_y = -glm::dot(normal(), wi);  // > 0: x on the emitting side
        if (!(cos_y > 0.f)) return s;
        s.wi = wi;
        s.distance = dist;
        s.radiance = S::sample(radiance, l);
        s.pdf = selection * d2 / (cos_y * area());
        return s;
    }
    /// Distance along r to the rectangle (either side), or kInf.
    float intersect(const Ray& r) const noexcept {
        const Vec3 n = glm::cross(edge_u, edge_v);
        const float denom = glm::dot(n, r.d);
        if (denom == 0.f) return kInf;
        const float t = glm::dot(n, corner - r.o) / denom;
        if (!(t > 0.f)) return kInf;
        const Vec3 p = r.at(t) - corner;
        const float a = glm::dot(p, edge_u) / glm::dot(edge_u, edge_u), b = glm::dot(p, edge_v) / glm::dot(edge_v, edge_v);
        return a >= 0.f && a <= 1.f && b >= 0.f && b <= 1.f ? t : kInf;
    }
    float pdf(const Vec3& x, const Vec3& w, float selection = 1.f) const noexcept {
        const float t = intersect(Ray{x, w});
        const float cos_y = -glm::dot(normal(), w);
        if (!(t < kInf) || !(cos_y > 0.f)) return 0.f;
        return selection * t * t / (cos_y * area());
    }
    /// Its radiance for a ray travelling along w that reaches its emitting side, else 0.
    typename S::Spectrum emitted(const Vec3& w, const typename S::Wavelengths& l = {}) const noexcept {
        return glm::dot(normal(), w) < 0.f ? typename S::Spectrum(S::sample(radiance, l))
                                           : typename S::Spectrum(S::Spectrum::Zero());
    }
    float power(float = 1.f) const noexcept { return kPi * max_value(radiance) * area(); }

    /// A uniform point on the rectangle, a cosine-weighted direction on its emitting side.
    LightEmission<S> sample_emission(float u1, float u2, float u3, float u4,
                                     const typename S::Wavelengths& l = {}) const noexcept {
        const Vec3 n = normal();
        const float c = std::sqrt(std::max(0.f, 1.f - u3));
        if (!(c > 0.f)) return {};
        return {corner + u1 * edge_u + u2 * edge_v, n, direction_around(n, c, 2.f * kPi * u4), S::sample(radiance, l),
                1.f / area(), c / kPi, c, false};
    }
    EmissionDensity emission_pdf(const Vec3&, const Vec3& w) const noexcept {
        const float c = glm::dot(normal(), w);
        return {1.f / area(), c > 0.f ? c / kPi : 0.f, std::max(c, 0.f)};
    }
};

/// Constant radiance arriving from every direction at infinity, sampled uniformly.
template <SpectralMode S>
struct EnvironmentLight {
    static constexpr bool is_delta = false;
    static constexpr bool is_infinite = true;  ///< reached by every ray that leaves the scene
    typename S::Coefficient radiance;

    LightSample<S> sample(const Vec3&, float u1, float u2, const typename S::Wavelengths& l = {},
                          float selection = 1.f) const noexcept {
        LightSample<S> s;
        s.wi = uniform_sphere(u1, u2);
        s.radiance = S::sample(radiance, l);
        s.pdf = selection * kInv4Pi;
        return s;
    }
    float pdf(const Vec3&, const Vec3&, float selection = 1.f) const noexcept { return selection * kInv4Pi; }
    typename S::Spectrum emitted(const Vec3&, const typename S::Wavelengths& l = {}) const noexcept {
        return S::sample(radiance, l);
    }
    /// What it sends into a sphere of radius `scene_radius` around the scene: pi L x 4 pi R^2.
    float power(float scene_radius = 1.f) const noexcept {
        return kPi * max_value(radiance) * 4.f * kPi * scene_radius * scene_radius;
    }
};

/// A distant light (the sun): parallel light travelling along `direction` (need not be unit),
/// with irradiance `irradiance` (W/m^2) on a plane perpendicular to it. A delta light, reached
/// by NEE only, from infinitely far away: its shadow rays run to the end of the scene.
template <SpectralMode S>
struct DirectionalLight {
    static constexpr bool is_delta = true;
    /// A delta direction at infinity: with a BoundingSphere, LightSampler starts its light
    /// subpaths on the sphere's disk facing along `direction`, as it does for the lights at
    /// infinity (LightEmission::at_infinity and delta_position both set).
    static constexpr bool is_distant = true;
    Vec3 direction;
    typename S::Coefficient irradiance;

    LightSample<S> sample(const Vec3&, float, float, const typename S::Wavelengths& l = {},
                          float selection = 1.f) const noexcept {
        LightSample<S> s;
        const float len = glm::length(direction);
        if (!(len > 0.f)) return s;
        s.wi = -direction / len;
        s.radiance = S::sample(irradiance, l);
        s.pdf = selection;
        s.delta = true;
        return s;
    }
    float pdf(const Vec3&, const Vec3&, float = 1.f) const noexcept { return 0.f; }
    typename S::Spectrum emitted(const Vec3&, const typename S::Wavelengths& = {}) const noexcept {
        return S::Spectrum::Zero();  // a direction is never hit
    }
    /// What it sends through a disc of radius `scene_radius` across the scene: E pi R^2.
    float power(float scene_radius = 1.f) const noexcept { return kPi * scene_radius * scene_radius * max_value(irradiance); }
};

static_assert(Light<PointLight<Rgb>, Rgb> && Light<SphereLight<Rgb>, Rgb> && Light<QuadLight<Rgb>, Rgb> &&
              Light<EnvironmentLight<Hero<4>>, Hero<4>> && Light<DirectionalLight<Mono>, Mono>);

/// Checks a light model's values; throws InvalidArgument naming the bad one: a non-finite
/// position or edge, a radius that is not finite and > 0 (or whose square overflows), a
/// rectangle without a finite area > 0, a negative or non-finite radiance or intensity.
template <SpectralMode S>
void validate_light(const PointLight<S>& l) {
    for (int a = 0; a < 3; ++a) detail::require_finite(l.position[a], "PointLight position");
    detail::require_coefficient(l.intensity, "PointLight intensity");
}
template <SpectralMode S>
void validate_light(const SphereLight<S>& l) {
    for (int a = 0; a < 3; ++a) detail::require_finite(l.center[a], "SphereLight center");
    if (!std::isfinite(l.radius) || !(l.radius > 0.f))
        detail::fail("SphereLight radius = ", l.radius, " is not allowed: it must be finite and > 0");
    if (!std::isfinite(l.radius * l.radius))
        detail::fail("SphereLight radius = ", l.radius, " is not allowed: radius^2 must be finite (radius <= ",
                     std::sqrt(std::numeric_limits<float>::max()), ")");
    detail::require_coefficient(l.radiance, "SphereLight radiance");
}
template <SpectralMode S>
void validate_light(const QuadLight<S>& l) {
    for (int a = 0; a < 3; ++a) {
        detail::require_finite(l.corner[a], "QuadLight corner");
        detail::require_finite(l.edge_u[a], "QuadLight edge_u");
        detail::require_finite(l.edge_v[a], "QuadLight edge_v");
    }
    if (const float area = l.area(); !(area > 0.f) || !std::isfinite(area))
        detail::fail("QuadLight area = ", area, " is not allowed: edge_u and edge_v must span a finite area > 0");
    detail::require_coefficient(l.radiance, "QuadLight radiance");
}
template <SpectralMode S>
void validate_light(const EnvironmentLight<S>& l) {
    detail::require_coefficient(l.radiance, "EnvironmentLight radiance");
}
template <SpectralMode S>
void validate_light(const DirectionalLight<S>& l) {
    for (int a = 0; a < 3; ++a) detail::require_finite(l.direction[a], "DirectionalLight direction");
    if (!(glm::dot(l.direction, l.direction) > 0.f))
        detail::fail("DirectionalLight direction (", l.direction.x, ", ", l.direction.y, ", ", l.direction.z,
                     ") is not allowed: it must have a length > 0");
    detail::require_coefficient(l.irradiance, "DirectionalLight irradiance");
}

/// The lights of a scene: at most one of each kind, selected uniformly for NEE.
template <SpectralMode S>
class Lights {
public:
    using Spectrum = typename S::Spectrum;

    /// Sets the point light; throws InvalidArgument on a non-finite position or bad intensity.
    Lights& set(const PointLight<S>& l) {
        validate_light(l);
        point_ = l;
        return *this;
    }
    /// Sets the sphere light; throws InvalidArgument on a non-finite centre, a radius that is not
    /// finite and > 0 (or whose square overflows), or a bad radiance.
    Lights& set(const SphereLight<S>& l) {
        validate_light(l);
        sphere_ = l;
        return *this;
    }
    /// Sets the environment; throws InvalidArgument on a bad radiance.
    Lights& set(const EnvironmentLight<S>& l) {
        validate_light(l);
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
        if (hit.sphere) return sphere_->cone_pdf(x) / float(n);
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
            s = point_->sample(x, u1, u2, l, sel);
            if (s.pdf > 0.f) s.occludable_by_sphere = sphere_.has_value();
            return s;
        }
        if (sphere_ && pick-- == 0) return sphere_->sample(x, u1, u2, l, sel);
        s = env_->sample(x, u1, u2, l, sel);
        s.occludable_by_sphere = sphere_.has_value();
        return s;
    }

    /// True when the sphere light blocks the segment [0, tmax) of r.
    bool sphere_blocks(const Ray& r, float tmax) const noexcept {
        return sphere_ && intersect_sphere(r, sphere_->center, sphere_->radius) < tmax;
    }

private:
    std::optional<PointLight<S>> point_;
    std::optional<SphereLight<S>> sphere_;
    std::optional<EnvironmentLight<S>> env_;
};

}  // namespace nsp
