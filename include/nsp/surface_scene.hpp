// nsp/surface_scene.hpp: what the path estimators render when a scene has surfaces (THEORY 3,
// 5.8): the host's geometry (an nsp::Geometry), a table of media with their majorants and phase
// functions, a table of BSDFs and a LightSampler over any number of lights. A SurfaceHit's
// handles index these tables: `material` the BSDFs, `light` the light sampler, `medium_front` /
// `medium_back` the media (-1 everywhere: none, vacuum).
//
//     using Mats = nsp::Materials<S, nsp::LambertianBsdf<S>, nsp::MirrorBsdf<S>>;
//     using Ls = nsp::LightSampler<S, nsp::QuadLight<S>, nsp::EnvironmentLight<S>>;
//     nsp::SurfaceScene<MyGeometry, M, nsp::GlobalMajorant<M>, nsp::HenyeyGreensteinPhase, Mats, Ls>
//         scene{geometry, {{medium, majorant, phase}}, Mats({floor}, {mirror}), lights, camera_medium};
//     estimator.radiance(scene, camera_ray, lambda, rng, counter);
//
// A medium's density is confined by the surfaces around it: a path is tracked through medium i
// only between the boundaries whose handles say it is inside i. The estimators start every ray
// at the previous hit point, unoffset: the host's intersect must not report the surface a ray
// starts on (an epsilon, or its primitive id), as every renderer's does.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "bsdf.hpp"
#include "core/error.hpp"
#include "geometry.hpp"
#include "light_sampler.hpp"
#include "majorant.hpp"
#include "majorants/crossing.hpp"
#include "medium.hpp"
#include "media/emissive.hpp"
#include "phase.hpp"

namespace nsp {

/// A table of BSDFs of the model types Bs..., one vector per type (no virtual calls). A
/// material is named by its index in the order the constructor got them, vector by vector.
template <SpectralMode S, class... Bs>
    requires(Bsdf<Bs, S> && ...)
class Materials {
public:
    using Spectral = S;
    /// Whether a BSDF here sees the hit (ShadingBsdf): only then are a hit's uv and tangent read.
    static constexpr bool sees_hits = (ShadingBsdf<Bs, S> || ...);
    /// Whether a BSDF here has a null lobe (PartlyNullBsdf): only then does a hit draw between it
    /// and a real vertex.
    static constexpr bool has_null_lobes = (PartlyNullBsdf<Bs, S> || ...);

    explicit Materials(std::vector<Bs>... bsdfs) : bsdfs_(std::move(bsdfs)...) {
        [&]<std::size_t... K>(std::index_sequence<K...>) {
            (([&] {
                 const auto& v = std::get<K>(bsdfs_);
                 for (std::size_t i = 0; i < v.size(); ++i) entries_.push_back({std::uint8_t(K), std::uint32_t(i)});
             }()),
             ...);
        }(std::index_sequence_for<Bs...>{});
    }

    int count() const noexcept { return int(entries_.size()); }
    bool contains(int material) const noexcept { return material >= 0 && material < count(); }

    /// Calls f(bsdf) with material `material` (which must be contained).
    template <class F>
    void visit(int material, F&& f) const noexcept {
        const Entry& e = entries_[std::size_t(material)];
        [&]<std::size_t... K>(std::index_sequence<K...>) {
            ((e.kind == K ? (f(std::get<K>(bsdfs_)[e.index]), 0) : 0), ...);
        }(std::index_sequence_for<Bs...>{});
    }

    /// Whether the material is a boundary a path crosses without a vertex (a null interface).
    bool passes_through(int material) const noexcept {
        bool p = false;
        visit(material, [&](const auto& b) { p = std::decay_t<decltype(b)>::passes_through; });
        return p;
    }
    /// The material's null lobe for a path arriving along wo (PartlyNullBsdf; none, probability 0,
    /// for the others).
    NullLobe<S> null_lobe(int material, const ShadingPoint& sp, const Vec3& wo,
                          const typename S::Wavelengths& lambda) const noexcept {
        NullLobe<S> out;
        if constexpr (has_null_lobes) {
            visit(material, [&](const auto& b) {
                if constexpr (PartlyNullBsdf<std::decay_t<decltype(b)>, S>) out = b.null_lobe(sp, wo, lambda);
            });
        } else {
            (void)material, (void)sp, (void)wo, (void)lambda;
        }
        return out;
    }
    /// Whether every lobe of the material is a delta lobe (light sampling cannot reach its paths).
    bool is_delta(int material) const noexcept {
        bool d = false;
        visit(material, [&](const auto& b) { d = detail::bsdf_delta_v<std::decay_t<decltype(b)>>; });
        return d;
    }

private:
    struct Entry {
        std::uint8_t kind;
        std::uint32_t index;
    };
    std::tuple<std::vector<Bs>...> bsdfs_;
    std::vector<Entry> entries_;
};

/// One medium of a SurfaceScene: its density, majorant and phase function.
template <Medium M, MajorantPolicy<M> Maj, PhaseFunction P>
struct SceneMedium {
    M medium;
    Maj majorant;
    P phase;
};

/// A scene with surfaces: geometry G (the host's), media of type M with majorants Maj and phase
/// functions P, the BSDF table Mats (a Materials) and the light sampler Ls (a LightSampler).
/// `camera_medium` is the medium camera rays start in (-1: vacuum).
template <Geometry G, Medium M, MajorantPolicy<M> Maj, PhaseFunction P, class Mats, class Ls>
struct SurfaceScene {
    static constexpr bool is_surface_scene = true;  ///< what the estimators render (nsp::Scene is one too)
    /// Whether a BSDF or light here reads a hit's uv and tangent (ShadingBsdf, SurfaceEmitter).
    static constexpr bool sees_hits = Mats::sees_hits || Ls::sees_hits;
    using GeometryType = G;
    using MediumType = M;
    using MajorantType = Maj;
    using PhaseType = P;
    using Spectral = typename M::Spectral;
    using Spectrum = typename Spectral::Spectrum;
    static_assert(std::is_same_v<typename Mats::Spectral, Spectral>,
                  "nsp::SurfaceScene: the materials' spectral mode must be the media's");

    G geometry;
    std::vector<SceneMedium<M, Maj, P>> media;
    Mats materials;
    Ls lights;
    int camera_medium = -1;

    /// Throws InvalidArgument if `camera_medium` is not -1 or an index into `media`, if a
    /// medium's single-valued majorant (GlobalMajorant) has a value its bound policy forbids, if a
    /// flight through a medium would take more than kMaxFlightCollisions tentative collisions under
    /// its majorant (majorants/crossing.hpp: a render that would run away), or
    /// if the lights have a BoundingSphere (light subpaths from infinity) that a medium's bounds
    /// do not lie inside (the geometry must lie inside it too; the host's is not checked).
    SurfaceScene(G g, std::vector<SceneMedium<M, Maj, P>> m, Mats mats, Ls l, int camera = -1)
        : geometry(std::move(g)), media(std::move(m)), materials(std::move(mats)), lights(std::move(l)),
          camera_medium(camera) {
        if (camera_medium < -1 || camera_medium >= int(media.size()))
            detail::fail("SurfaceScene camera_medium = ", camera_medium, " is not allowed: it must be -1 (vacuum) or "
                         "an index into the ", media.size(), " media");
        for (const auto& s : media) {
            if constexpr (requires(const Maj& j) { { j.value() } -> std::convertible_to<float>; })
                detail::require_majorant_value<bound_policy_t<Maj>>(s.majorant.value(), s.medium.max_extinction(),
                                                                    "SurfaceScene: a medium's majorant value",
                                                                    " of that medium");
            detail::require_trackable(s.medium, s.majorant, "SurfaceScene");
        }
        if constexpr (requires(const Ls& x) { x.bounding_sphere(); })
            if (lights.emits_from_infinity()) check_inside(lights.bounding_sphere());
        if constexpr (std::is_same_v<G, EmptySpace>) {
            for (const auto& s : media)
                if (!geometry.apart_from(s.medium.bounds()))
                    detail::fail("SphereLight (centre ", geometry.center.x, ", ", geometry.center.y, ", ",
                                 geometry.center.z, ", radius ", geometry.radius,
                                 ") overlaps the medium bounds; lights must lie outside the medium");
        }
        build_emission_selection();
    }

    bool has_medium(int i) const noexcept { return i >= 0 && i < int(media.size()); }

    /// Emissive media: the probability with which NEE toward volume emission picks medium i
    /// (THEORY 5.7), in proportion to its emitted power (total_power_estimate(), where the medium
    /// has one; else the same for every medium), floored at 1e-3 of the largest so that a medium
    /// whose estimate missed its emission is still sampled. 0 for an index outside the table.
    /// Fixed at construction: a scene whose `media` change afterwards must be built again.
    float emission_selection_pdf(int i) const noexcept {
        return has_medium(i) && i < int(emission_pdf_.size()) ? emission_pdf_[std::size_t(i)] : 0.f;
    }

    /// The medium NEE toward volume emission samples for a uniform u in [0, 1) (-1: none emits).
    int select_emission(float u) const noexcept {
        float run = 0.f;
        int last = -1;
        for (std::size_t i = 0; i < emission_pdf_.size(); ++i) {
            if (!(emission_pdf_[i] > 0.f)) continue;
            run += emission_pdf_[i];
            last = int(i);
            if (u < run) return last;
        }
        return last;  // u rounded past the sum
    }

private:
    /// Light subpaths from infinity start outside the sphere: every medium must lie inside it.
    void check_inside(const BoundingSphere& b) const {
        for (std::size_t i = 0; i < media.size(); ++i) {
            const Box box = media[i].medium.bounds();
            for (int c = 0; c < 8; ++c) {
                const Vec3 corner((c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y,
                                  (c & 4) ? box.hi.z : box.lo.z);
                const float d = glm::length(corner - b.center);
                if (!(d <= b.radius))
                    detail::fail("SurfaceScene: medium ", i, "'s bounds [", box.lo.x, ", ", box.lo.y, ", ", box.lo.z,
                                 "] .. [", box.hi.x, ", ", box.hi.y, ", ", box.hi.z,
                                 "] are not allowed: they must lie inside the lights' BoundingSphere (centre ", b.center.x,
                                 ", ", b.center.y, ", ", b.center.z, ", radius ", b.radius, "; a corner lies ", d,
                                 " from its centre), where light subpaths from infinity start");
            }
        }
    }

    void build_emission_selection() {
        if constexpr (EmissiveMedium<M>) {
            std::vector<double> w(media.size(), 1.0);
            if constexpr (requires(const M& m) { { m.total_power_estimate() } -> std::convertible_to<double>; })
                for (std::size_t i = 0; i < media.size(); ++i) {
                    const double p = double(media[i].medium.total_power_estimate());
                    w[i] = std::isfinite(p) && p > 0.0 ? p : 0.0;
                }
            const double largest = w.empty() ? 0.0 : *std::max_element(w.begin(), w.end());
            double sum = 0.0;
            for (double& x : w) {
                x = largest > 0.0 ? std::max(x, 1e-3 * largest) : 1.0;
                sum += x;
            }
            emission_pdf_.resize(media.size());
            for (std::size_t i = 0; i < media.size(); ++i) emission_pdf_[i] = float(w[i] / sum);
        }
    }

    std::vector<float> emission_pdf_;  ///< emissive media: emission_selection_pdf by medium
};

/// True for a SurfaceScene and the types built on one (nsp::Scene).
template <class Sc>
inline constexpr bool is_surface_scene_v = requires { requires bool(Sc::is_surface_scene); };

}  // namespace nsp
