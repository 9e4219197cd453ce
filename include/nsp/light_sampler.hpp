// nsp/light_sampler.hpp: next-event estimation over any number of lights of any models of
// nsp::Light (light.hpp), for a host's own loop (THEORY 5.8): one light chosen uniformly or in
// proportion to its power, then a direction toward it, with the solid-angle pdf of both; the pdf
// of a direction toward a given light, for the MIS weight of a path that hit it.
//
// The lights live in one vector per model type (no virtual calls): `LightSampler<S, QuadLight<S>,
// SphereLight<S>>`. A light is named by its index in the order the constructor got them, vector
// by vector. Everything is built and checked in the constructor; sample / pdf allocate nothing.
//
// Light subpaths (BdptEstimator) start at the lights with a point to emit from (EmittingLight
// models) and, when the sampler is given a BoundingSphere around the scene, at the lights at
// infinity and the directional lights too: a direction toward the light by its own sample(), then
// the ray's origin uniform on a disk of the sphere's radius that faces the scene from outside it
// (THEORY 5.5).
#pragma once

#include <algorithm>
#include <concepts>
#include <cstdint>
#include <optional>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "light.hpp"
#include "media/validate.hpp"

namespace nsp {

/// A light subpath's first vertex and the light it came from (LightSampler::sample_emission).
template <SpectralMode S>
struct EmittedLight {
    LightEmission<S> emission;  ///< pdf_pos includes the selection probability; 0: no sample
    int light = -1;             ///< the light's index, or -1
};

/// A sphere that holds everything of a scene (its surfaces and its media's bounds): what light
/// subpaths from the lights at infinity start outside of (LightSampler, BdptEstimator).
struct BoundingSphere {
    Vec3 center{0.f};
    float radius = 0.f;
};

/// How LightSampler chooses a light.
enum class LightSelection : std::uint8_t {
    Uniform,  ///< every light with probability 1 / count
    Power,    ///< in proportion to Light::power(scene_radius)
};

/// A light sample and the light it came from.
template <SpectralMode S>
struct SampledLight {
    LightSample<S> sample;  ///< pdf includes the selection probability; 0: no sample
    int light = -1;         ///< the light's index, or -1
};

template <SpectralMode S, class... Ls>
    requires(Light<Ls, S> && ...)
class LightSampler {
public:
    /// Whether a light here sees where a ray reaches it (SurfaceEmitter).
    static constexpr bool sees_hits = (SurfaceEmitter<Ls, S> || ...);

    /// Throws InvalidArgument on a light with a non-finite position, a radius or area that is not
    /// finite and > 0, a bad radiance, or (Power) when no light has positive power. No lights is
    /// allowed: sample() then returns pdf 0.
    /// Lights at infinity and directional lights start no light subpaths (emits_from_infinity()
    /// false).
    explicit LightSampler(LightSelection selection, float scene_radius, std::vector<Ls>... lights)
        : LightSampler(Checked{}, selection, checked_radius(scene_radius), BoundingSphere{}, std::move(lights)...) {}

    /// As above with `sphere.radius` as the scene radius, and light subpaths from the lights at
    /// infinity (sample_emission): their rays start on a disk of radius `sphere.radius` outside
    /// `sphere`, which must hold all of the scene (SurfaceScene checks its media's bounds; the host
    /// keeps its surfaces inside). Throws InvalidArgument on a non-finite centre or a radius that
    /// is not finite and > 0.
    explicit LightSampler(LightSelection selection, BoundingSphere sphere, std::vector<Ls>... lights)
        : LightSampler(Checked{}, selection, checked_radius(sphere.radius), checked(sphere), std::move(lights)...) {}

private:
    struct Checked {};
    static float checked_radius(float r) {
        if (!(r > 0.f) || !std::isfinite(r) || !std::isfinite(r * r))
            detail::fail("LightSampler scene_radius = ", r,
                         " is not allowed: it must be finite and > 0, its square finite (a BoundingSphere's radius too)");
        return r;
    }
    static BoundingSphere checked(const BoundingSphere& b) {
        for (int a = 0; a < 3; ++a) detail::require_finite(b.center[a], "LightSampler BoundingSphere center");
        return b;
    }
    LightSampler(Checked, LightSelection selection, float scene_radius, BoundingSphere sphere, std::vector<Ls>... lights)
        : lights_(std::move(lights)...), sphere_(sphere), uniform_(selection == LightSelection::Uniform) {
        static_assert(((!is_infinite<Ls>() || DirectionEmitter<Ls, S>) && ...),
                      "nsp::LightSampler: a light at infinity (is_infinite) is reached where there is no hit; it "
                      "must give emitted(w, lambda) (DirectionEmitter)");
        double total = 0.0;
        for_each_light([&](const auto& l, int kind, int index) {
            validate(l);
            const double w = selection == LightSelection::Power ? double(l.power(scene_radius)) : 1.0;
            if (is_infinite<std::decay_t<decltype(l)>>()) infinite_.push_back(int(entries_.size()));
            if (std::decay_t<decltype(l)>::is_delta) delta_ = true;
            entries_.push_back({std::uint8_t(kind), std::uint32_t(index), float(w), 0.f});
            total += w;
        });
        if (!entries_.empty() && !(total > 0.0))
            detail::fail("LightSampler: selection by power needs a light whose power is > 0; all ", entries_.size(),
                         " have power 0");
        double cdf = 0.0;
        for (Entry& e : entries_) {
            cdf += double(e.pmf);
            e.pmf = float(double(e.pmf) / total);
            e.cdf = float(cdf / total);
        }
        if (!entries_.empty()) entries_.back().cdf = 1.f;
        // The equiangular strategies' targets: the lights with a point to aim at, by the same
        // selection probabilities renormalised over them.
        double aim_total = 0.0;
        std::size_t entry = 0;
        for_each_light([&](const auto& l, int, int) {
            if (const auto p = aim_point(l)) {
                using L = std::decay_t<decltype(l)>;
                bool delta = false;
                if constexpr (requires { L::is_delta; }) delta = bool(L::is_delta);
                targets_.push_back({*p, entries_[entry].pmf, 0.f, delta});
                aim_total += double(entries_[entry].pmf);
            }
            ++entry;
        });
        double aim_cdf = 0.0;
        for (Target& t : targets_) {
            aim_cdf += double(t.pmf);
            t.pmf = aim_total > 0.0 ? float(double(t.pmf) / aim_total) : 0.f;
            t.cdf = aim_total > 0.0 ? float(aim_cdf / aim_total) : 0.f;
        }
        if (!targets_.empty()) targets_.back().cdf = 1.f;
        // The lights light subpaths start from (EmittingLight models), by the same selection
        // probabilities renormalised over them.
        double emit_total = 0.0;
        for (std::size_t i = 0; i < entries_.size(); ++i)
            if (emits(entries_[i])) emit_total += double(entries_[i].pmf);
        emit_pmf_.assign(entries_.size(), 0.f);
        double emit_cdf = 0.0;
        for (std::size_t i = 0; i < entries_.size(); ++i)
            if (emits(entries_[i]) && emit_total > 0.0) {
                emit_cdf += double(entries_[i].pmf);
                emit_pmf_[i] = float(double(entries_[i].pmf) / emit_total);
                emitters_.push_back({int(i), float(emit_cdf / emit_total)});
            }
        if (!emitters_.empty()) emitters_.back().cdf = 1.f;
    }

public:
    /// Whether every light model can start light subpaths, or is reached from infinity (hit or
    /// NEE only): what a bidirectional estimator needs of its lights.
    static constexpr bool bidirectional_ready() noexcept {
        return ((EmittingLight<Ls, S> || is_infinite<Ls>() || bool(Ls::is_delta)) && ...);
    }

    /// Whether any light is a delta light (a point light, a directional light): one no path can
    /// hit, which NEE alone reaches (so NEE's count may not be 0; EstimatorOptions::nee_count).
    bool has_delta_lights() const noexcept { return delta_; }

    /// Whether any light can start a light subpath (an EmittingLight with a positive probability).
    bool has_emitters() const noexcept { return !emitters_.empty(); }

    /// Whether the lights at infinity start light subpaths (the sampler was given a BoundingSphere).
    bool emits_from_infinity() const noexcept { return sphere_.radius > 0.f; }
    /// The sphere given to the constructor (radius 0: none).
    const BoundingSphere& bounding_sphere() const noexcept { return sphere_; }

    /// The probability with which sample_emission() starts at light `light` (0 for lights at
    /// infinity and directional lights without a BoundingSphere, and for indices outside the
    /// table).
    float emission_selection_pdf(int light) const noexcept {
        return light >= 0 && light < count() ? emit_pmf_[std::size_t(light)] : 0.f;
    }

    /// Chooses a light that emits (an EmittingLight, or with a BoundingSphere a light at infinity
    /// or a directional light) with u0, and a point on it and a direction leaving it with (u1, u2)
    /// and (u3, u4). pdf_pos 0 when there is none. From a light at infinity
    /// (LightEmission::at_infinity): the direction toward it by (u1, u2) and its sample()
    /// (pdf_pos, solid angle; a directional light's one direction: pdf_pos 1 and delta_position),
    /// the ray's origin p uniform by (u3, u4) on the disk of the sphere's radius centred at
    /// center + radius x (-w), facing along w (pdf_dir = 1 / (pi radius^2), area on the disk),
    /// cos = 1.
    EmittedLight<S> sample_emission(float u0, float u1, float u2, float u3, float u4,
                                    const typename S::Wavelengths& lambda = {}) const noexcept {
        if (emitters_.empty()) return {};
        const auto it = std::upper_bound(emitters_.begin(), emitters_.end(), u0,
                                         [](float u, const Emitter& e) { return u < e.cdf; });
        const int light = std::min(it, emitters_.end() - 1)->light;
        EmittedLight<S> out{{}, light};
        visit(entries_[std::size_t(light)], [&](const auto& l) {
            using L = std::decay_t<decltype(l)>;
            if constexpr (EmittingLight<L, S>) out.emission = l.sample_emission(u1, u2, u3, u4, lambda);
            else if constexpr (from_infinity<L>()) out.emission = emission_from_infinity(l, u1, u2, u3, u4, lambda);
        });
        out.emission.pdf_pos *= emit_pmf_[std::size_t(light)];
        return out;
    }

    /// The densities with which sample_emission() starts at point p of light `light` (selection
    /// included in pdf_pos) and leaves along w; all 0 for a light it never starts from. For a
    /// light at infinity p is any point the ray reaches: pdf_pos the density of the direction -w
    /// toward the light, pdf_dir that of a ray through p (0 where no ray from the disk passes
    /// through p: outside the sphere's cylinder along w, or beyond the disk); for a directional
    /// light pdf_pos is 1 (its delta), w taken to be its direction.
    EmissionDensity emission_pdf(int light, const Vec3& p, const Vec3& w) const noexcept {
        EmissionDensity d;
        if (!(emission_selection_pdf(light) > 0.f)) return d;
        visit(entries_[std::size_t(light)], [&](const auto& l) {
            using L = std::decay_t<decltype(l)>;
            if constexpr (requires { l.emission_pdf(p, w); }) d = l.emission_pdf(p, w);
            else if constexpr (from_infinity<L>()) d = emission_pdf_from_infinity(l, p, w);
        });
        d.pdf_pos *= emit_pmf_[std::size_t(light)];
        return d;
    }
    /// The same at the point `at` on a surface light (a hit's SurfaceHit::shading(), or
    /// light_point() of the light's own sample): a SurfacePdfLight reads it, any other light at.p.
    EmissionDensity emission_pdf(int light, const ShadingPoint& at, const Vec3& w) const noexcept {
        EmissionDensity d;
        if (!(emission_selection_pdf(light) > 0.f)) return d;
        bool read = false;
        visit(entries_[std::size_t(light)], [&](const auto& l) {
            if constexpr (requires { l.emission_pdf(at, w); }) d = l.emission_pdf(at, w), read = true;
        });
        if (!read) return emission_pdf(light, at.p, w);
        d.pdf_pos *= emit_pmf_[std::size_t(light)];
        return d;
    }

    /// The equiangular strategies' targets (THEORY 5.4): one per light with a point to aim at
    /// (a PointLight's position, a SphereLight's centre, a QuadLight's centre, or a host model's
    /// `equiangular_point()`), in light order; lights at infinity and DirectionalLight have none.
    int equiangular_count() const noexcept { return int(targets_.size()); }
    /// Target k's point.
    const Vec3& equiangular_point(int k) const noexcept { return targets_[std::size_t(k)].point; }
    /// The probability with which an equiangular vertex aims at target k: its light's selection
    /// probability, renormalised over the targets.
    float equiangular_pmf(int k) const noexcept { return targets_[std::size_t(k)].pmf; }
    /// Whether target k's light is a delta light (a point light): no path hits it.
    bool equiangular_is_delta(int k) const noexcept { return targets_[std::size_t(k)].delta; }
    /// The target for a uniform u in [0, 1) (-1: there is none).
    int pick_equiangular(float u) const noexcept {
        if (targets_.empty()) return -1;
        const auto it = std::upper_bound(targets_.begin(), targets_.end(), u,
                                         [](float x, const Target& t) { return x < t.cdf; });
        return int(std::min(std::size_t(it - targets_.begin()), targets_.size() - 1));
    }

    int count() const noexcept { return int(entries_.size()); }

    /// The indices of the lights at infinity (models with `is_infinite`, e.g. EnvironmentLight):
    /// what a ray that leaves the scene reaches.
    const std::vector<int>& infinite() const noexcept { return infinite_; }

    /// The probability with which sample() chooses light `light`.
    float selection_pdf(int light) const noexcept {
        return light >= 0 && light < count() ? entries_[std::size_t(light)].pmf : 0.f;
    }

    /// Chooses a light with u0 and a direction toward it from x with (u1, u2).
    SampledLight<S> sample(const Vec3& x, float u0, float u1, float u2, const typename S::Wavelengths& lambda = {}) const
        noexcept {
        if (entries_.empty()) return {};
        std::size_t i;
        if (uniform_) {  // every pmf 1/n: the index without a search
            i = std::min(std::size_t(u0 * float(entries_.size())), entries_.size() - 1);
        } else {
            const auto it = std::upper_bound(entries_.begin(), entries_.end(), u0,
                                             [](float u, const Entry& e) { return u < e.cdf; });
            i = std::min(std::size_t(it - entries_.begin()), entries_.size() - 1);
        }
        SampledLight<S> out{{}, int(i)};
        const Entry& e = entries_[i];
        visit(e, [&](const auto& l) { out.sample = l.sample(x, u1, u2, lambda, e.pmf); });
        return out;
    }

    /// The solid-angle pdf with which sample() from x produces direction w toward light `light`
    /// (selection included): what the MIS weight of a path that hit that light needs.
    float pdf(int light, const Vec3& x, const Vec3& w) const noexcept {
        if (light < 0 || light >= count()) return 0.f;
        const Entry& e = entries_[std::size_t(light)];
        float p = 0.f;
        visit(e, [&](const auto& l) {
            if constexpr (requires { l.pdf(x, w, e.pmf); }) p = l.pdf(x, w, e.pmf);
        });
        return p;
    }
    /// The same for a direction that reaches the light at `at` (a hit's SurfaceHit::shading(), or
    /// light_point() of the light's own sample): a SurfacePdfLight reads it, any other light not.
    float pdf(int light, const Vec3& x, const Vec3& w, const ShadingPoint& at) const noexcept {
        if (light < 0 || light >= count()) return 0.f;
        const Entry& e = entries_[std::size_t(light)];
        float p = 0.f;
        visit(e, [&](const auto& l) {
            if constexpr (SurfacePdfLight<std::decay_t<decltype(l)>, S>) p = l.pdf(x, w, at, e.pmf);
            else p = l.pdf(x, w, e.pmf);
        });
        return p;
    }

    /// What a ray travelling along w receives when it reaches light `light` with no hit: a light at
    /// infinity (a SurfaceEmitter, which needs its hit, gives 0 here).
    typename S::Spectrum emitted(int light, const Vec3& w, const typename S::Wavelengths& lambda = {}) const noexcept {
        typename S::Spectrum v = S::Spectrum::Zero();
        if (light >= 0 && light < count())
            visit(entries_[std::size_t(light)], [&](const auto& l) {
                if constexpr (DirectionEmitter<std::decay_t<decltype(l)>, S>) v = l.emitted(w, lambda);
            });
        return v;
    }
    /// What a ray travelling along w receives where it reaches light `light` at the hit sp
    /// (SurfaceHit::shading()): a SurfaceEmitter sees sp, any other light only w.
    typename S::Spectrum emitted(int light, const ShadingPoint& sp, const Vec3& w,
                                 const typename S::Wavelengths& lambda = {}) const noexcept {
        typename S::Spectrum v = S::Spectrum::Zero();
        if (light >= 0 && light < count())
            visit(entries_[std::size_t(light)], [&](const auto& l) {
                if constexpr (SurfaceEmitter<std::decay_t<decltype(l)>, S>) v = l.emitted(sp, w, lambda);
                else v = l.emitted(w, lambda);
            });
        return v;
    }

    /// The lights of model type L, in the order given.
    template <class L>
    const std::vector<L>& lights() const noexcept {
        return std::get<std::vector<L>>(lights_);
    }

private:
    struct Entry {
        std::uint8_t kind;
        std::uint32_t index;
        float pmf, cdf;
    };

    bool emits(const Entry& e) const noexcept {
        bool r = false;
        visit(e, [&](const auto& l) {
            using L = std::decay_t<decltype(l)>;
            r = EmittingLight<L, S> || (from_infinity<L>() && emits_from_infinity());
        });
        return r;
    }

    /// A light subpath's start from light l at infinity (see sample_emission), selection left out.
    template <class L>
    LightEmission<S> emission_from_infinity(const L& l, float u1, float u2, float u3, float u4,
                                            const typename S::Wavelengths& lambda) const noexcept {
        LightEmission<S> e;
        const LightSample<S> s = l.sample(sphere_.center, u1, u2, lambda, 1.f);
        if (!(s.pdf > 0.f) || !std::isinf(s.distance)) return e;
        const Vec3 toward = s.wi;
        Vec3 a, b;
        orthonormal_basis(toward, a, b);
        const float r = sphere_.radius * std::sqrt(u3), phi = 2.f * kPi * u4;
        e.p = sphere_.center + sphere_.radius * toward + r * (std::cos(phi) * a + std::sin(phi) * b);
        e.w = e.n = -toward;
        e.radiance = s.radiance;
        e.pdf_pos = s.pdf;
        e.pdf_dir = 1.f / (kPi * sphere_.radius * sphere_.radius);
        e.cos = 1.f;
        e.at_infinity = true;
        e.delta_position = s.delta;
        return e;
    }

    template <class L>
    EmissionDensity emission_pdf_from_infinity(const L& l, const Vec3& p, const Vec3& w) const noexcept {
        EmissionDensity d;
        const Vec3 toward = -w, q = p - sphere_.center;
        const float along = glm::dot(q, toward), r2 = sphere_.radius * sphere_.radius;
        if constexpr (L::is_delta) d.pdf_pos = 1.f;
        else d.pdf_pos = l.pdf(sphere_.center, toward, 1.f);
        d.pdf_dir = along < sphere_.radius && glm::dot(q, q) - along * along < r2 ? 1.f / (kPi * r2) : 0.f;
        d.cos = 1.f;
        return d;
    }

    template <class F>
    void for_each_light(F&& f) const {
        [&]<std::size_t... K>(std::index_sequence<K...>) {
            (([&] {
                 const auto& v = std::get<K>(lights_);
                 for (std::size_t i = 0; i < v.size(); ++i) f(v[i], int(K), int(i));
             }()),
             ...);
        }(std::index_sequence_for<Ls...>{});
    }

    template <class F>
    void visit(const Entry& e, F&& f) const noexcept {
        [&]<std::size_t... K>(std::index_sequence<K...>) {
            ((e.kind == K ? (f(std::get<K>(lights_)[e.index]), 0) : 0), ...);
        }(std::index_sequence_for<Ls...>{});
    }

    /// nsp's light models check their values (validate_light); a host's own model checks itself.
    template <class L>
    static void validate(const L& l) {
        if constexpr (requires { validate_light(l); }) validate_light(l);
    }

    /// The point an equiangular vertex aims at for light l, if it has one.
    template <class L>
    static std::optional<Vec3> aim_point(const L& l) noexcept {
        if constexpr (requires { { l.equiangular_point() } -> std::convertible_to<Vec3>; }) return l.equiangular_point();
        else if constexpr (requires { { l.position } -> std::convertible_to<Vec3>; }) return l.position;
        else if constexpr (requires { { l.center } -> std::convertible_to<Vec3>; }) return l.center;
        else if constexpr (requires { l.corner + 0.5f * (l.edge_u + l.edge_v); })
            return Vec3(l.corner + 0.5f * (l.edge_u + l.edge_v));
        else return std::nullopt;
    }

    template <class L>
    static constexpr bool is_infinite() noexcept {
        if constexpr (requires { L::is_infinite; }) return bool(L::is_infinite);
        else return false;
    }
    /// A light at infinity or a delta direction at infinity (`is_distant`, DirectionalLight): its
    /// light subpaths start on the BoundingSphere's disk.
    template <class L>
    static constexpr bool from_infinity() noexcept {
        if constexpr (requires { L::is_distant; }) return is_infinite<L>() || bool(L::is_distant);
        else return is_infinite<L>();
    }

    std::tuple<std::vector<Ls>...> lights_;
    std::vector<Entry> entries_;
    std::vector<int> infinite_;
    bool delta_ = false;
    struct Target {
        Vec3 point;
        float pmf, cdf;
        bool delta;
    };
    std::vector<Target> targets_;
    struct Emitter {
        int light;
        float cdf;
    };
    std::vector<Emitter> emitters_;  ///< the EmittingLight entries, with their cdf for sample_emission
    std::vector<float> emit_pmf_;    ///< by light index: sample_emission's probability of it
    BoundingSphere sphere_;          ///< radius 0: the lights at infinity start no light subpaths
    bool uniform_;                   ///< LightSelection::Uniform: sample() picks by index
};

}  // namespace nsp
