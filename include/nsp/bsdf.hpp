// nsp/bsdf.hpp: surface scattering for path vertices on a host's surfaces (THEORY 5.8): the
// concept a host's BSDF models, and its models: Lambertian reflection, a perfect mirror (a delta
// lobe), a null interface (the index-matched boundary of a medium, which a path crosses without a
// real vertex), and two partly null BSDFs, whose lobe that passes straight through a path takes
// with a probability: a thin dielectric sheet and any BSDF behind an opacity mask; and a rough
// dielectric interface (GGX microfacets).
//
// A BSDF comes in one of two forms. A shading BSDF sees the hit (a ShadingPoint: position, uv,
// shading frame, the host's datum) and samples from three uniforms, enough for a rough lobe
// chosen among several; a simple BSDF sees only the shading normal and samples from two. The
// estimators take either (detail::sample_bsdf and its siblings) and draw the third uniform only
// for a shading BSDF.
//
// Directions follow propagation, as for phase functions (phase.hpp): `wo` is the direction the
// path travelled to reach the surface (the ray's direction), `wi` the direction it leaves in. `n`
// (ShadingPoint::ns) is the unit shading normal, of either orientation: a one-sided model decides
// the side from `wo` (a normal that is NaN or not of unit length gives no sample: pdf 0).
// A BSDF's `value` is f_s(wo, wi) |n . wi|, the cosine of the outgoing direction included, so
// that a path's throughput is multiplied by value / pdf at a surface vertex exactly as by
// f_p / pdf at a medium vertex, and NEE adds value / light_pdf at either.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <type_traits>

#include "core/error.hpp"
#include "core/math.hpp"
#include "core/rng.hpp"
#include "geometry.hpp"
#include "media/validate.hpp"
#include "spectrum.hpp"

namespace nsp {

/// A direction drawn from a BSDF: the throughput factor value = f_s |n . wi| and its pdf. For a
/// delta lobe `pdf` is the discrete probability of the lobe (1 for a single lobe), value / pdf
/// the lobe's weight, and no other technique can produce wi (`delta`).
template <SpectralMode S>
struct BsdfSample {
    Vec3 wi{0.f, 0.f, 1.f};
    float pdf = 0.f;                        ///< solid-angle density of wi (0: no sample)
    typename S::Spectrum value = S::Spectrum::Zero();  ///< f_s(wo, wi) |n . wi|
    bool delta = false;                     ///< a delta lobe: light sampling cannot produce wi
};

/// A simple BSDF provides `sample(wo, n, u1, u2, lambda)`, `eval(wo, wi, n, lambda)` (f_s |n . wi|;
/// 0 for the directions of a delta lobe, which no other technique reaches) and `pdf(wo, wi, n)` of
/// its own sampling (0 for delta lobes). `passes_through` is true for a null interface: the path
/// crosses it as it would cross empty space, with no real vertex (its MIS state carries on).
/// Optional: `static constexpr bool is_delta = true` on a model all of whose lobes are delta
/// lobes (MirrorBsdf), so that an estimator skips light sampling there.
template <class B, class S>
concept SimpleBsdf = SpectralMode<S> && requires(const B& b, const Vec3& w, float u, const typename S::Wavelengths& l) {
    { b.sample(w, w, u, u, l) } -> std::same_as<BsdfSample<S>>;
    { b.eval(w, w, w, l) } -> std::same_as<typename S::Spectrum>;
    { b.pdf(w, w, w) } -> std::same_as<float>;
    { B::passes_through } -> std::convertible_to<bool>;
};

/// A shading BSDF sees the hit: `sample(sp, wo, u, lambda)` with u a 3D sample in [0, 1)^3 (two
/// for the direction, one to pick a lobe, or however the model spends them), `eval(sp, wo, wi,
/// lambda)` and `pdf(sp, wo, wi)`, with the same meaning as a simple BSDF's, `passes_through` and
/// the optional `is_delta` likewise. A texture reads sp.uv (or sp.user), an anisotropic lobe
/// sp.dpdu.
template <class B, class S>
concept ShadingBsdf = SpectralMode<S> &&
    requires(const B& b, const ShadingPoint& sp, const Vec3& w, const typename S::Wavelengths& l) {
        { b.sample(sp, w, w, l) } -> std::same_as<BsdfSample<S>>;
        { b.eval(sp, w, w, l) } -> std::same_as<typename S::Spectrum>;
        { b.pdf(sp, w, w) } -> std::same_as<float>;
        { B::passes_through } -> std::convertible_to<bool>;
    };

/// A BSDF of either form.
template <class B, class S>
concept Bsdf = ShadingBsdf<B, S> || SimpleBsdf<B, S>;

/// The lobe of a partly null BSDF that passes straight through (wi = wo): `weight`, per channel,
/// the fraction of light that crosses unchanged, and `probability`, with which a path arriving
/// along wo takes it.
template <SpectralMode S>
struct NullLobe {
    typename S::Spectrum weight = S::Spectrum::Zero();
    float probability = 0.f;
};

/// A partly null BSDF (a thin dielectric, an alpha-masked surface) also has a lobe that passes
/// straight through: `null_lobe(sp, wo, lambda)` gives it, and its sample, eval and pdf describe
/// the other lobes alone (their values unscaled: f_s of the real part). A path that reaches it
/// takes the null lobe with `probability`: it crosses as at a null interface (no vertex, no depth,
/// throughput x weight / probability, and probability joins the segment's null product as a null
/// collision's P_n does; THEORY 5.8, docs/theory.md). Otherwise it makes a real vertex, its
/// throughput divided by 1 - probability. A shadow ray crosses it with factor `weight` (and the
/// probability in its unidirectional pdf). Requirements: probability in [0, 1], above 0 wherever
/// weight is not 0 and below 1 wherever the other lobes are not black (a lobe never taken would
/// be missing from the estimate), and the same from either side (for wo and -wo: BDPT's reverse
/// densities reuse it). Kernels stop a path whose null lobe is outside [0, 1], has a weight that
/// is not finite and >= 0, or a weight with probability 0, with Status::InvalidInput.
template <class B, class S>
concept PartlyNullBsdf = Bsdf<B, S> &&
    requires(const B& b, const ShadingPoint& sp, const Vec3& w, const typename S::Wavelengths& l) {
        { b.null_lobe(sp, w, l) } -> std::same_as<NullLobe<S>>;
    };

namespace detail {
/// Whether BSDF model B says every lobe is a delta lobe (its optional `is_delta`).
template <class B>
inline constexpr bool bsdf_delta_v = [] {
    if constexpr (requires { B::is_delta; }) return bool(B::is_delta);
    else return false;
}();

/// BSDF b's sample at sp from (u1, u2), and from a third uniform drawn from rng if b is a
/// shading BSDF (a simple one draws none: its paths keep their random streams).
template <SpectralMode S, class B, UniformRng R>
    requires Bsdf<B, S>
[[gnu::always_inline]] inline BsdfSample<S> sample_bsdf(const B& b, const ShadingPoint& sp, const Vec3& wo, float u1,
                                                         float u2, R& rng, const typename S::Wavelengths& lambda) noexcept {
    if constexpr (ShadingBsdf<B, S>) return b.sample(sp, wo, Vec3(u1, u2, rng.uniform()), lambda);
    else return b.sample(wo, sp.ns, u1, u2, lambda);
}
/// BSDF b's value f_s |n . wi| at sp.
template <SpectralMode S, class B>
    requires Bsdf<B, S>
[[gnu::always_inline]] inline typename S::Spectrum eval_bsdf(const B& b, const ShadingPoint& sp, const Vec3& wo,
                                                              const Vec3& wi, const typename S::Wavelengths& lambda) noexcept {
    if constexpr (ShadingBsdf<B, S>) return b.eval(sp, wo, wi, lambda);
    else return b.eval(wo, wi, sp.ns, lambda);
}
/// BSDF b's sampling pdf of wi at sp.
template <SpectralMode S, class B>
    requires Bsdf<B, S>
[[gnu::always_inline]] inline float bsdf_pdf(const B& b, const ShadingPoint& sp, const Vec3& wo, const Vec3& wi) noexcept {
    if constexpr (ShadingBsdf<B, S>) return b.pdf(sp, wo, wi);
    else return b.pdf(wo, wi, sp.ns);
}

/// The unit normal on the side of the surface the path arrived from (opposite to wo).
inline Vec3 facing(const Vec3& wo, const Vec3& n) noexcept { return glm::dot(wo, n) > 0.f ? -n : n; }

/// A perfect mirror's delta lobe at normal n with weight `value`: wo reflected about n, pdf 1 (no
/// sample for a normal that is NaN or not of unit length).
template <SpectralMode S>
BsdfSample<S> mirror_sample(const Vec3& wo, const Vec3& n, const typename S::Spectrum& value) noexcept {
    BsdfSample<S> s;
    if (!unit_length(n)) return s;
    s.wi = wo - 2.f * glm::dot(wo, n) * n;
    s.pdf = 1.f;
    s.value = value;
    s.delta = true;
    return s;
}
}  // namespace detail

/// Lambertian reflection f_s = albedo / pi on the side the path arrived from, sampled by the
/// cosine: pdf = |n . wi| / pi. Transmits nothing.
template <SpectralMode S>
class LambertianBsdf {
public:
    static constexpr bool passes_through = false;

    /// Throws InvalidArgument unless every channel of `albedo` is finite and in [0, 1].
    explicit LambertianBsdf(typename S::Coefficient albedo) : albedo_(albedo) {
        detail::require_coefficient(albedo_, "LambertianBsdf albedo");
        if (const float m = max_value(albedo_); !(m <= 1.f))
            detail::fail("LambertianBsdf albedo = ", m, " (its largest channel) is not allowed: every channel must lie in [0, 1]");
    }

    BsdfSample<S> sample(const Vec3& wo, const Vec3& n, float u1, float u2,
                         const typename S::Wavelengths& lambda = {}) const noexcept {
        const Vec3 up = detail::facing(wo, n);
        if (!unit_length(up)) return BsdfSample<S>{};  // a NaN or non-unit normal: no sample
        const float cos_theta = std::sqrt(std::max(0.f, 1.f - u1));  // p(cos) = 2 cos: cosine-weighted
        BsdfSample<S> s;
        s.wi = direction_around(up, cos_theta, 2.f * kPi * u2);
        s.pdf = cos_theta / kPi;
        if (!(s.pdf > 0.f)) return BsdfSample<S>{};
        s.value = S::sample(albedo_, lambda) * (cos_theta / kPi);
        return s;
    }
    typename S::Spectrum eval(const Vec3& wo, const Vec3& wi, const Vec3& n,
                              const typename S::Wavelengths& lambda = {}) const noexcept {
        const float c = glm::dot(wi, detail::facing(wo, n));
        return c > 0.f ? typename S::Spectrum(S::sample(albedo_, lambda) * (c / kPi)) : typename S::Spectrum(S::Spectrum::Zero());
    }
    float pdf(const Vec3& wo, const Vec3& wi, const Vec3& n) const noexcept {
        const float c = glm::dot(wi, detail::facing(wo, n));
        return c > 0.f ? c / kPi : 0.f;
    }

private:
    typename S::Coefficient albedo_;
};

/// A perfect mirror with per-channel reflectance: one delta lobe, wi = wo reflected about n.
template <SpectralMode S>
class MirrorBsdf {
public:
    static constexpr bool passes_through = false;
    static constexpr bool is_delta = true;  ///< its only lobe is a delta: NEE is skipped there

    /// Throws InvalidArgument unless every channel of `reflectance` is finite and >= 0.
    explicit MirrorBsdf(typename S::Coefficient reflectance) : reflectance_(reflectance) {
        detail::require_coefficient(reflectance_, "MirrorBsdf reflectance");
    }

    BsdfSample<S> sample(const Vec3& wo, const Vec3& n, float, float,
                         const typename S::Wavelengths& lambda = {}) const noexcept {
        return detail::mirror_sample<S>(wo, n, S::sample(reflectance_, lambda));
    }
    typename S::Spectrum eval(const Vec3&, const Vec3&, const Vec3&, const typename S::Wavelengths& = {}) const noexcept {
        return S::Spectrum::Zero();
    }
    float pdf(const Vec3&, const Vec3&, const Vec3&) const noexcept { return 0.f; }

private:
    typename S::Coefficient reflectance_;
};

/// Any BSDF made one-sided: it scatters only paths that arrive on the side the normal points to
/// (wo . n < 0, wo the direction the path travelled) and is black from behind (eval and pdf 0, no
/// sample), as Mitsuba's diffuse and conductor models are by default. nsp's models are two-sided
/// (they scatter on whichever side the path arrives); a host matching a one-sided renderer wraps
/// them, `nsp::OneSided<S, nsp::LambertianBsdf<S>>{nsp::LambertianBsdf<S>(albedo)}`, and reports
/// the shading normal on the front side of each surface.
template <SpectralMode S, class B>
    requires Bsdf<B, S>
struct OneSided {
    static constexpr bool passes_through = B::passes_through;
    static constexpr bool is_delta = detail::bsdf_delta_v<B>;
    B bsdf;

    // B's form: a simple BSDF's three functions.
    BsdfSample<S> sample(const Vec3& wo, const Vec3& n, float u1, float u2,
                         const typename S::Wavelengths& lambda = {}) const noexcept
        requires(!ShadingBsdf<B, S>)
    {
        return glm::dot(wo, n) < 0.f ? bsdf.sample(wo, n, u1, u2, lambda) : BsdfSample<S>{};
    }
    typename S::Spectrum eval(const Vec3& wo, const Vec3& wi, const Vec3& n,
                              const typename S::Wavelengths& lambda = {}) const noexcept
        requires(!ShadingBsdf<B, S>)
    {
        return glm::dot(wo, n) < 0.f ? bsdf.eval(wo, wi, n, lambda) : typename S::Spectrum(S::Spectrum::Zero());
    }
    float pdf(const Vec3& wo, const Vec3& wi, const Vec3& n) const noexcept
        requires(!ShadingBsdf<B, S>)
    {
        return glm::dot(wo, n) < 0.f ? bsdf.pdf(wo, wi, n) : 0.f;
    }

    // Or a shading BSDF's, the side read from sp.ns.
    BsdfSample<S> sample(const ShadingPoint& sp, const Vec3& wo, const Vec3& u,
                         const typename S::Wavelengths& lambda = {}) const noexcept
        requires ShadingBsdf<B, S>
    {
        return glm::dot(wo, sp.ns) < 0.f ? bsdf.sample(sp, wo, u, lambda) : BsdfSample<S>{};
    }
    typename S::Spectrum eval(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi,
                              const typename S::Wavelengths& lambda = {}) const noexcept
        requires ShadingBsdf<B, S>
    {
        return glm::dot(wo, sp.ns) < 0.f ? bsdf.eval(sp, wo, wi, lambda) : typename S::Spectrum(S::Spectrum::Zero());
    }
    float pdf(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi) const noexcept
        requires ShadingBsdf<B, S>
    {
        return glm::dot(wo, sp.ns) < 0.f ? bsdf.pdf(sp, wo, wi) : 0.f;
    }
};

/// The boundary of a medium between index-matched sides: the path goes straight on (wi = wo,
/// weight 1). A host crosses it without a real vertex: it changes the current medium and keeps
/// tracking, and the null-pdf products of the segments on both sides multiply (THEORY 5.8).
template <SpectralMode S>
struct NullInterface {
    static constexpr bool passes_through = true;

    BsdfSample<S> sample(const Vec3& wo, const Vec3&, float, float, const typename S::Wavelengths& = {}) const noexcept {
        return {wo, 1.f, S::Spectrum::Ones(), true};
    }
    typename S::Spectrum eval(const Vec3&, const Vec3&, const Vec3&, const typename S::Wavelengths& = {}) const noexcept {
        return S::Spectrum::Zero();
    }
    float pdf(const Vec3&, const Vec3&, const Vec3&) const noexcept { return 0.f; }
};

namespace detail {
/// The reflectance of a smooth dielectric interface of relative index eta (the far side's over
/// the near side's) at incidence cosine cos_i (unpolarised; 1 under total internal reflection).
inline float fresnel_dielectric(float cos_i, float eta) noexcept {
    cos_i = std::min(1.f, std::abs(cos_i));
    const float sin2_t = (1.f - cos_i * cos_i) / (eta * eta);
    if (!(sin2_t < 1.f)) return 1.f;
    const float cos_t = std::sqrt(1.f - sin2_t);
    const float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    const float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5f * (rs * rs + rp * rp);
}
}  // namespace detail

/// A thin dielectric sheet of index eta in a medium of index 1, its two faces parallel and so close
/// that the light between them stays at the point it entered: it reflects R' = 2R / (1 + R) (R the
/// faces' Fresnel reflectance at the incidence angle; every order of reflection between them
/// summed) and passes the rest, T' = 1 - R', straight through. A partly null BSDF: the reflection
/// is its one delta lobe, the passage its null lobe, taken with probability T' (so either way the
/// throughput keeps its value).
template <SpectralMode S>
class ThinDielectricBsdf {
public:
    static constexpr bool passes_through = false;
    static constexpr bool is_delta = true;  ///< its real lobe is a mirror's: NEE is skipped there

    /// Throws InvalidArgument unless eta is finite and > 0.
    explicit ThinDielectricBsdf(float eta) : eta_(eta) {
        if (!(std::isfinite(eta) && eta > 0.f))
            detail::fail("ThinDielectricBsdf eta = ", eta, " is not allowed: it must be finite and > 0");
    }

    /// The sheet's reflectance R' at incidence cosine cos_i.
    float reflectance(float cos_i) const noexcept {
        const float r = detail::fresnel_dielectric(cos_i, eta_);
        return r < 1.f ? 2.f * r / (1.f + r) : 1.f;
    }

    NullLobe<S> null_lobe(const ShadingPoint& sp, const Vec3& wo, const typename S::Wavelengths& = {}) const noexcept {
        if (!unit_length(sp.ns)) return {};
        const float t = 1.f - reflectance(glm::dot(wo, sp.ns));
        return {S::Spectrum::Constant(t), t};
    }
    BsdfSample<S> sample(const Vec3& wo, const Vec3& n, float, float,
                         const typename S::Wavelengths& = {}) const noexcept {
        return detail::mirror_sample<S>(wo, n, S::Spectrum::Constant(reflectance(glm::dot(wo, n))));
    }
    typename S::Spectrum eval(const Vec3&, const Vec3&, const Vec3&, const typename S::Wavelengths& = {}) const noexcept {
        return S::Spectrum::Zero();
    }
    float pdf(const Vec3&, const Vec3&, const Vec3&) const noexcept { return 0.f; }

private:
    float eta_;
};

/// A rough dielectric interface (Walter et al. 2007): GGX microfacets of roughness alpha (isotropic;
/// Smith's separable shadowing G = G1(wo) G1(wi), as in Mitsuba 3), each a smooth interface that
/// reflects the Fresnel fraction F and refracts the rest. `eta` is the index on the side opposite
/// the geometric normal sp.ng over the index on the side ng points to (glass in air, ng outward:
/// 1.5); the medium a refracted path enters is the hit's, as for any surface. Sampled from the
/// visible normals (Heitz 2018): two uniforms draw the microfacet, the third picks reflection with
/// probability F, so reflection's weight is G1(wi) and refraction's G1(wi) / eta_rel.
///
/// nsp's estimators use one BSDF for paths from the camera and from lights (BDPT), so its
/// refraction lobe is the symmetric f_t n_i / n_o = f_t / eta_rel (f_t Walter's radiance form):
/// along a path the factors n_i / n_o telescope, and every estimate is the radiance exactly when
/// the camera and the lights lie in media of one index (all in air, say). A light inside glass of
/// index n seen from a camera in air must report its radiance times 1 / n (docs/integration.md).
template <SpectralMode S>
class RoughDielectricBsdf {
public:
    static constexpr bool passes_through = false;

    /// Throws InvalidArgument unless eta is finite, > 0 and not 1 (an index-matched boundary is a
    /// NullInterface), and alpha is finite and in [1e-3, 2].
    RoughDielectricBsdf(float eta, float alpha) : eta_(eta), alpha_(alpha) {
        if (!(std::isfinite(eta) && eta > 0.f) || eta == 1.f)
            detail::fail("RoughDielectricBsdf eta = ", eta,
                         " is not allowed: it must be finite, > 0 and not 1 (an index-matched boundary is a NullInterface)");
        if (!(alpha >= 1e-3f && alpha <= 2.f))
            detail::fail("RoughDielectricBsdf alpha = ", alpha, " is not allowed: it must lie in [0.001, 2]");
    }

    BsdfSample<S> sample(const ShadingPoint& sp, const Vec3& wo, const Vec3& u,
                         const typename S::Wavelengths& = {}) const noexcept {
        Frame f;
        if (!frame(sp, wo, f)) return {};
        const Vec3 o = -wo;
        const float cos_o = glm::dot(o, f.n);
        // The visible normal in the local frame (z = f.n), then in the world.
        const Vec3 ol(glm::dot(o, f.s), glm::dot(o, f.t), cos_o);
        const Vec3 hl = sample_visible_normal(ol, u.x, u.y);
        const Vec3 h = hl.x * f.s + hl.y * f.t + hl.z * f.n;
        const float cos_oh = glm::dot(o, h);
        if (!(cos_oh > 0.f)) return {};
        const float fr = detail::fresnel_dielectric(cos_oh, f.eta);
        BsdfSample<S> s;
        const bool reflect = u.z < fr;
        if (reflect) {
            s.wi = 2.f * cos_oh * h - o;
        } else {
            const float sin2_t = (1.f - cos_oh * cos_oh) / (f.eta * f.eta);
            const float cos_t = std::sqrt(std::max(0.f, 1.f - sin2_t));
            s.wi = (cos_oh / f.eta - cos_t) * h - o / f.eta;
        }
        // A microfacet can send the path to the wrong side of the macro surface: no sample (the
        // pdf of the other lobe there is not this draw's).
        if ((glm::dot(s.wi, f.n) > 0.f) != reflect) return {};
        const Lobe l = lobe(f, o, s.wi);
        if (!(l.pdf > 0.f) || !std::isfinite(l.value)) return {};
        s.pdf = l.pdf;
        s.value = S::Spectrum::Constant(l.value);
        return s;
    }
    typename S::Spectrum eval(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi,
                              const typename S::Wavelengths& = {}) const noexcept {
        Frame f;
        if (!frame(sp, wo, f)) return S::Spectrum::Zero();
        const float v = lobe(f, -wo, wi).value;
        return S::Spectrum::Constant(std::isfinite(v) ? v : 0.f);
    }
    float pdf(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi) const noexcept {
        Frame f;
        if (!frame(sp, wo, f)) return 0.f;
        const float p = lobe(f, -wo, wi).pdf;
        return std::isfinite(p) ? p : 0.f;
    }

    float eta() const noexcept { return eta_; }
    float alpha() const noexcept { return alpha_; }

private:
    /// The shading normal on the side the path arrived from, a tangent frame around it, and the
    /// relative index of the far side over the near side.
    struct Frame {
        Vec3 n, s, t;
        float eta;
    };
    struct Lobe {
        float value = 0.f;  ///< f |n . wi|
        float pdf = 0.f;
    };

    bool frame(const ShadingPoint& sp, const Vec3& wo, Frame& f) const noexcept {
        if (!unit_length(sp.ns) || !unit_length(sp.ng) || !unit_length(wo)) return false;
        const Vec3 ns = glm::dot(sp.ns, sp.ng) < 0.f ? -sp.ns : sp.ns;  // on ng's side
        const bool front = glm::dot(wo, sp.ng) < 0.f;                   // arrived on ng's side
        f.n = front ? ns : -ns;
        f.eta = front ? eta_ : 1.f / eta_;
        if (!(glm::dot(wo, f.n) < 0.f)) return false;  // grazing, or behind the shading normal
        orthonormal_basis(f.n, f.s, f.t);
        return true;
    }

    /// GGX's density of microfacet normals with cosine c to the macro normal.
    float ggx(float c) const noexcept {
        if (!(c > 0.f)) return 0.f;
        const float a2 = alpha_ * alpha_;
        const float d = c * c * (a2 - 1.f) + 1.f;
        return a2 / (kPi * d * d);
    }
    /// Smith's G1 for direction v (pointing away from the surface) and microfacet h about n.
    float smith_g1(const Vec3& v, const Vec3& h, const Vec3& n) const noexcept {
        const float cv = glm::dot(v, n);
        if (!(glm::dot(v, h) * cv > 0.f)) return 0.f;
        const float c2 = cv * cv;
        const float tan2 = std::max(0.f, 1.f - c2) / c2;
        return 2.f / (1.f + std::sqrt(1.f + alpha_ * alpha_ * tan2));
    }
    /// A microfacet normal drawn with density G1(o) max(0, o . h) D(h) / (o . n) (local frame,
    /// o.z > 0): Heitz's sampling of the visible normals of the stretched hemisphere.
    Vec3 sample_visible_normal(const Vec3& o, float u1, float u2) const noexcept {
        const Vec3 v = glm::normalize(Vec3(alpha_ * o.x, alpha_ * o.y, o.z));
        const float len2 = v.x * v.x + v.y * v.y;
        const Vec3 t1 = len2 > 0.f ? Vec3(-v.y, v.x, 0.f) / std::sqrt(len2) : Vec3(1.f, 0.f, 0.f);
        const Vec3 t2 = glm::cross(v, t1);
        const float r = std::sqrt(u1), phi = 2.f * kPi * u2;
        const float p1 = r * std::cos(phi);
        const float s = 0.5f * (1.f + v.z);
        const float p2 = (1.f - s) * std::sqrt(std::max(0.f, 1.f - p1 * p1)) + s * r * std::sin(phi);
        const Vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.f, 1.f - p1 * p1 - p2 * p2)) * v;
        return glm::normalize(Vec3(alpha_ * nh.x, alpha_ * nh.y, std::max(1e-6f, nh.z)));
    }

    /// The value f |n . wi| and the sampling pdf of wi for a path leaving along o (= -wo).
    Lobe lobe(const Frame& f, const Vec3& o, const Vec3& wi) const noexcept {
        const float cos_o = glm::dot(o, f.n), cos_i = glm::dot(wi, f.n);
        Lobe l;
        if (!(cos_o > 0.f) || cos_i == 0.f || !unit_length(wi)) return l;
        const bool reflect = cos_i > 0.f;
        // The (generalised) half vector, on the near side.
        Vec3 h = reflect ? o + wi : o + f.eta * wi;
        const float len = glm::length(h);
        if (!(len > 1e-6f)) return l;
        h /= len;
        if (glm::dot(h, f.n) < 0.f) h = -h;
        const float cos_oh = glm::dot(o, h), cos_ih = glm::dot(wi, h);
        if (!(cos_oh > 0.f) || (reflect ? !(cos_ih > 0.f) : !(cos_ih < 0.f))) return l;
        const float d = ggx(glm::dot(h, f.n));
        const float g1o = smith_g1(o, h, f.n);
        const float g = g1o * smith_g1(wi, h, f.n);
        const float fr = detail::fresnel_dielectric(cos_oh, f.eta);
        const float visible = g1o * cos_oh * d / cos_o;  // density of h among the visible normals
        if (reflect) {
            l.value = fr * d * g / (4.f * cos_o);
            l.pdf = fr * visible / (4.f * cos_oh);
        } else {
            const float denom = cos_oh + f.eta * cos_ih;
            const float jac = std::abs(cos_ih) / (denom * denom);  // dh / dwi over eta^2
            l.value = (1.f - fr) * d * g * cos_oh * f.eta * jac / cos_o;
            l.pdf = (1.f - fr) * visible * f.eta * f.eta * jac;
        }
        return l;
    }

    float eta_, alpha_;
};

/// Any BSDF behind an opacity mask: where `opacity(sp)` is alpha (in [0, 1]; a texture read from
/// sp.uv, say) the surface scatters alpha x B and lets 1 - alpha pass straight through, a partly
/// null BSDF whose null lobe is taken with probability 1 - alpha. A shading BSDF whichever form B
/// has (the mask sees the hit). Opacity must be the same seen from either side (it is a property
/// of the point).
template <SpectralMode S, class B, class Opacity>
    requires Bsdf<B, S> && std::is_invocable_r_v<float, const Opacity&, const ShadingPoint&>
struct AlphaMasked {
    static constexpr bool passes_through = false;
    static constexpr bool is_delta = detail::bsdf_delta_v<B>;
    B bsdf;
    Opacity opacity;

    NullLobe<S> null_lobe(const ShadingPoint& sp, const Vec3&, const typename S::Wavelengths& = {}) const noexcept {
        const float pass = 1.f - opacity(sp);
        return {S::Spectrum::Constant(pass), pass};
    }
    BsdfSample<S> sample(const ShadingPoint& sp, const Vec3& wo, const Vec3& u,
                         const typename S::Wavelengths& lambda = {}) const noexcept {
        BsdfSample<S> s;
        if constexpr (ShadingBsdf<B, S>) s = bsdf.sample(sp, wo, u, lambda);
        else s = bsdf.sample(wo, sp.ns, u.x, u.y, lambda);
        s.value *= opacity(sp);
        return s;
    }
    typename S::Spectrum eval(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi,
                              const typename S::Wavelengths& lambda = {}) const noexcept {
        return detail::eval_bsdf<S>(bsdf, sp, wo, wi, lambda) * opacity(sp);
    }
    float pdf(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi) const noexcept {
        return detail::bsdf_pdf<S>(bsdf, sp, wo, wi);
    }
};

static_assert(SimpleBsdf<LambertianBsdf<Mono>, Mono> && !ShadingBsdf<LambertianBsdf<Mono>, Mono> &&
              Bsdf<LambertianBsdf<Mono>, Mono> && Bsdf<MirrorBsdf<Rgb>, Rgb> && Bsdf<NullInterface<Mono>, Mono> &&
              Bsdf<OneSided<Rgb, LambertianBsdf<Rgb>>, Rgb> && Bsdf<OneSided<Mono, MirrorBsdf<Mono>>, Mono> &&
              PartlyNullBsdf<ThinDielectricBsdf<Rgb>, Rgb> && ShadingBsdf<RoughDielectricBsdf<Rgb>, Rgb> &&
              !PartlyNullBsdf<LambertianBsdf<Mono>, Mono>);

}  // namespace nsp
