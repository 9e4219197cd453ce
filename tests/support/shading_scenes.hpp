// tests/support/shading_scenes.hpp: two shading BSDFs (nsp::ShadingBsdf: they see the hit and
// take a 3D sample) and the closed boxes of emitting walls in which their radiance has a closed
// form, for the path tracer's and BDPT's tests. A textured floor: a Lambertian checkerboard read
// from the hit's uv, black unless the hit's point, tangent and host datum reach it too. A diffuse
// sheet: Lambertian reflection r on the side the path arrives from and Lambertian transmission t
// through it, the lobe picked by the sample's third uniform. And a textured quad light
// (nsp::SurfaceEmitter: it sees where a ray reaches it; nsp::SurfacePdfLight: sampled by its
// texture) on the walls of a box over a floor.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <nsp/nsp.hpp>

#include "grey_surface_scenes.hpp"
#include "host/shapes.hpp"
#include "surfaces.hpp"

namespace nsp_test::shading_scenes {

using namespace nsp;
using S = Mono;
using Spectrum = S::Spectrum;
using nsp_host::Shapes;

/// The floor's checkerboard, 4 x 4 squares over uv in [0, 1]^2: 0.8 and 0.2.
inline float checker_albedo(Vec2 uv) { return (int(4.f * uv.x) + int(4.f * uv.y)) % 2 == 0 ? 0.8f : 0.2f; }

/// Lambertian reflection with the checkerboard's albedo at sp.uv; 0 unless sp.p lies on the plane
/// y = plane_y, sp.dpdu is `tangent` and sp.user is `user` (so a hit that lost them renders black).
struct CheckerBsdf {
    static constexpr bool passes_through = false;
    float plane_y = -1.f;
    Vec3 tangent{0.f, 0.f, 1.f};
    int user = -1;

    float albedo(const ShadingPoint& sp) const {
        const bool seen = std::abs(sp.p.y - plane_y) < 1e-4f && glm::length(sp.dpdu - tangent) < 1e-5f && sp.user == user;
        return seen ? checker_albedo(sp.uv) : 0.f;
    }
    BsdfSample<S> sample(const ShadingPoint& sp, const Vec3& wo, const Vec3& u, const S::Wavelengths& = {}) const {
        const float cos_theta = std::sqrt(1.f - u.x);
        BsdfSample<S> s;
        s.wi = direction_around(detail::facing(wo, sp.ns), cos_theta, 2.f * kPi * u.y);
        s.pdf = cos_theta / kPi;
        s.value = Spectrum::Constant(albedo(sp) * cos_theta / kPi);
        return s;
    }
    Spectrum eval(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi, const S::Wavelengths& = {}) const {
        const float c = glm::dot(wi, detail::facing(wo, sp.ns));
        return Spectrum::Constant(c > 0.f ? albedo(sp) * c / kPi : 0.f);
    }
    float pdf(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi) const {
        const float c = glm::dot(wi, detail::facing(wo, sp.ns));
        return c > 0.f ? c / kPi : 0.f;
    }
};

/// Lambertian reflection r back to the side the path arrives from and Lambertian transmission t
/// to the other, the lobe picked by u.z with probability r / (r + t) and t / (r + t).
struct DiffuseSheetBsdf {
    static constexpr bool passes_through = false;
    float r = 0.3f, t = 0.5f;

    BsdfSample<S> sample(const ShadingPoint& sp, const Vec3& wo, const Vec3& u, const S::Wavelengths& = {}) const {
        const float p_reflect = r / (r + t);
        const bool reflect = u.z < p_reflect;
        const Vec3 n = reflect ? detail::facing(wo, sp.ns) : -detail::facing(wo, sp.ns);
        const float cos_theta = std::sqrt(1.f - u.x);
        BsdfSample<S> s;
        s.wi = direction_around(n, cos_theta, 2.f * kPi * u.y);
        s.pdf = (reflect ? p_reflect : 1.f - p_reflect) * cos_theta / kPi;
        s.value = Spectrum::Constant((reflect ? r : t) * cos_theta / kPi);
        return s;
    }
    Spectrum eval(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi, const S::Wavelengths& = {}) const {
        const float c = glm::dot(wi, detail::facing(wo, sp.ns));
        return Spectrum::Constant((c > 0.f ? r : t) * std::abs(c) / kPi);
    }
    float pdf(const ShadingPoint& sp, const Vec3& wo, const Vec3& wi) const {
        const float c = glm::dot(wi, detail::facing(wo, sp.ns));
        return (c > 0.f ? r : t) / (r + t) * std::abs(c) / kPi;
    }
};

static_assert(ShadingBsdf<CheckerBsdf, S> && ShadingBsdf<DiffuseSheetBsdf, S> && !SimpleBsdf<CheckerBsdf, S> &&
              ShadingBsdf<OneSided<S, DiffuseSheetBsdf>, S>);

/// The walls' 2 x 2 checkerboard over uv in [0, 1]^2: 0.8 and 0.2.
inline float quadrant_albedo(Vec2 uv) { return (int(2.f * uv.x) + int(2.f * uv.y)) % 2 == 0 ? 0.8f : 0.2f; }

/// A QuadLight whose radiance is scaled by quadrant_albedo at the point it is reached or
/// sampled, uv its parameters along edge_u and edge_v (as Shapes reports a quad's hits): a textured
/// emitter (nsp::SurfaceEmitter). Sampled by its texture: a quadrant in proportion to its albedo
/// (0.8 : 0.2), uniformly inside it, so the density by area is 2 quadrant_albedo(uv) / area.
/// Its densities read uv from the point they get (nsp::SurfacePdfLight) and it has no
/// position-only ones: a density asked without the point, or with a point that lost its uv, would
/// weigh its MIS wrongly.
struct TexturedQuadLight {
    static constexpr bool is_delta = false;
    QuadLight<S> quad;

    /// (u1, u2) in [0, 1)^2 to uv: quadrants (0, 0), (1, 0), (0, 1), (1, 1) with probabilities
    /// 0.4, 0.1, 0.1, 0.4 (albedo / 2), uniformly inside.
    static Vec2 warp(float u1, float u2) {
        const float cdf[4] = {0.4f, 0.5f, 0.6f, 1.f};
        int k = 0;
        while (k < 3 && !(u1 < cdf[k])) ++k;
        const float lo = k == 0 ? 0.f : cdf[k - 1];
        const float r = std::min((u1 - lo) / (cdf[k] - lo), 0.99999994f);
        return {(float(k % 2) + r) * 0.5f, (float(k / 2) + u2) * 0.5f};
    }
    /// The uv density of warp() at uv, relative to uniform: 2 quadrant_albedo(uv).
    static float texture_density(Vec2 uv) { return 2.f * quadrant_albedo(uv); }

    LightSample<S> sample(const Vec3& x, float u1, float u2, const S::Wavelengths& l = {}, float selection = 1.f) const {
        const Vec2 uv = warp(u1, u2);
        LightSample<S> s = quad.sample(x, uv.x, uv.y, l, selection);
        s.pdf *= texture_density(uv);
        s.radiance *= quadrant_albedo(uv);
        s.uv = uv;
        return s;
    }
    float pdf(const Vec3& x, const Vec3& w, const ShadingPoint& at, float selection = 1.f) const {
        const Vec3 d = at.p - x;
        const float cos_y = -glm::dot(quad.normal(), w);
        if (!(cos_y > 0.f)) return 0.f;
        return selection * glm::dot(d, d) / (cos_y * quad.area()) * texture_density(at.uv);
    }
    Spectrum emitted(const ShadingPoint& sp, const Vec3& w, const S::Wavelengths& l = {}) const {
        return quad.emitted(w, l) * quadrant_albedo(sp.uv);
    }
    float power(float r = 1.f) const { return quad.power(r); }
    LightEmission<S> sample_emission(float u1, float u2, float u3, float u4, const S::Wavelengths& l = {}) const {
        const Vec2 uv = warp(u1, u2);
        LightEmission<S> e = quad.sample_emission(uv.x, uv.y, u3, u4, l);
        e.pdf_pos *= texture_density(uv);
        e.radiance *= quadrant_albedo(uv);
        e.uv = uv;
        return e;
    }
    EmissionDensity emission_pdf(const ShadingPoint& at, const Vec3& w) const {
        EmissionDensity d = quad.emission_pdf(at.p, w);
        d.pdf_pos *= texture_density(at.uv);
        return d;
    }
};

static_assert(Light<TexturedQuadLight, S> && SurfaceEmitter<TexturedQuadLight, S> && SurfacePdfLight<TexturedQuadLight, S> &&
              !DirectionEmitter<TexturedQuadLight, S> && EmittingLight<TexturedQuadLight, S>);

using Mats = Materials<S, CheckerBsdf, DiffuseSheetBsdf, LambertianBsdf<S>>;
using Ls = grey_scenes::Ls;
using M = grey_scenes::M;
using Sc = SurfaceScene<Shapes, M, GlobalMajorant<M>, HenyeyGreensteinPhase, Mats, Ls>;

/// The cube [-1, 1]^3 in vacuum: its floor (y = -1, quad 2, material 0) the checkerboard, the other five walls
/// quad lights emitting 1 inward. A point on the floor sees only emitting walls: L = its albedo.
inline Sc checker_box() {
    Shapes shapes;
    shapes.report_uv = true;
    std::vector<QuadLight<S>> lights;
    int face = 0;
    for (const CubeFace& f : inward_cube_faces()) {
        if (face++ == 2) {  // -y: u along z, v along x
            shapes.quads.push_back({f.corner, f.u, f.v, {0, -1, -1, -1}});
            continue;
        }
        shapes.quads.push_back({f.corner, f.u, f.v, {-1, int(lights.size()), -1, -1}});
        lights.push_back({f.corner, f.u, f.v, Spectrum::Constant(1.f)});
    }
    const CheckerBsdf checker{-1.f, Vec3(0.f, 0.f, 1.f), 2};
    return Sc(shapes, {}, Mats({checker}, {}, {LambertianBsdf<S>(Spectrum::Constant(0.f))}),
              Ls(LightSelection::Uniform, 3.f, std::move(lights), {}), -1);
}

/// The cube [-1, 1]^3 in vacuum cut at y = 0 by a diffuse sheet (r, t): the walls of the upper
/// half emit 1 inward, those of the lower half are black (material 1). From above the sheet
/// (material 0) is L = r, from below L = t.
inline Sc sheet_box(float r, float t) {
    Shapes shapes;
    shapes.report_uv = true;
    std::vector<QuadLight<S>> lights;
    const Spectrum one = Spectrum::Constant(1.f);
    auto wall = [&](Vec3 corner, Vec3 eu, Vec3 ev, bool upper) {  // normal cross(eu, ev) inward
        if (upper) {
            shapes.quads.push_back({corner, eu, ev, {-1, int(lights.size()), -1, -1}});
            lights.push_back({corner, eu, ev, one});
        } else {
            shapes.quads.push_back({corner, eu, ev, {1, -1, -1, -1}});
        }
    };
    for (const bool upper : {true, false}) {
        const float y0 = upper ? 0.f : -1.f;
        wall(Vec3(-1.f, y0, -1.f), Vec3(0.f, 1.f, 0.f), Vec3(0.f, 0.f, 2.f), upper);  // x = -1, normal +x
        wall(Vec3(1.f, y0, -1.f), Vec3(0.f, 0.f, 2.f), Vec3(0.f, 1.f, 0.f), upper);   // x = +1, normal -x
        wall(Vec3(-1.f, y0, -1.f), Vec3(2.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f), upper);  // z = -1, normal +z
        wall(Vec3(-1.f, y0, 1.f), Vec3(0.f, 1.f, 0.f), Vec3(2.f, 0.f, 0.f), upper);   // z = +1, normal -z
    }
    wall(Vec3(-1.f, 1.f, -1.f), Vec3(2.f, 0.f, 0.f), Vec3(0.f, 0.f, 2.f), true);    // top, normal -y
    wall(Vec3(-1.f, -1.f, -1.f), Vec3(0.f, 0.f, 2.f), Vec3(2.f, 0.f, 0.f), false);  // bottom, normal +y
    shapes.quads.push_back({Vec3(-1.f, 0.f, -1.f), Vec3(0.f, 0.f, 2.f), Vec3(2.f, 0.f, 0.f), {0, -1, -1, -1}});
    return Sc(shapes, {}, Mats({}, {DiffuseSheetBsdf{r, t}}, {LambertianBsdf<S>(Spectrum::Constant(0.f))}),
              Ls(LightSelection::Uniform, 3.f, std::move(lights), {}), -1);
}

using TexturedLs = LightSampler<S, TexturedQuadLight>;
using TexturedSc = SurfaceScene<Shapes, M, GlobalMajorant<M>, HenyeyGreensteinPhase, Mats, TexturedLs>;

/// The cube [-1, 1]^3 in vacuum: its floor (y = -1) Lambertian of albedo 0.5 (material 0), the
/// other five walls textured quad lights emitting quadrant_albedo(uv) inward. From the floor's
/// centre each wall's quadrants of 0.8 and 0.2 weigh alike in pairs (the mirror symmetries through
/// it), as if every wall emitted 0.5: L = 0.5 x 0.5 there.
inline TexturedSc textured_box() {
    Shapes shapes;
    shapes.report_uv = true;
    std::vector<TexturedQuadLight> lights;
    int face = 0;
    for (const CubeFace& f : inward_cube_faces()) {
        if (face++ == 2) {
            shapes.quads.push_back({f.corner, f.u, f.v, {0, -1, -1, -1}});
            continue;
        }
        shapes.quads.push_back({f.corner, f.u, f.v, {-1, int(lights.size()), -1, -1}});
        lights.push_back({QuadLight<S>{f.corner, f.u, f.v, Spectrum::Constant(1.f)}});
    }
    return TexturedSc(shapes, {}, Mats({}, {}, {LambertianBsdf<S>(Spectrum::Constant(0.5f))}),
                      TexturedLs(LightSelection::Uniform, 3.f, std::move(lights)), -1);
}

/// The camera ray from o toward `target`, for estimate().
inline auto toward(Vec3 o, Vec3 target) {
    return [=](Pcg32&) { return Ray{o, glm::normalize(target - o)}; };
}

/// Runs the closed forms of the shading BSDFs for every estimator `for_each` hands its check (as
/// the tests' for_each_strategy and for_each_bdpt do), n samples a case, within k standard
/// errors. The floor of a box of emitting walls sees only them: L = its albedo at the hit's uv,
/// 0.8 and 0.2 on neighbouring squares (0 if the hit's point, tangent or datum did not reach the
/// BSDF). A sheet across a box whose upper walls emit 1 and lower walls are black: L = r = 0.3
/// from above, t = 0.5 from below; a third uniform that did not pick the lobe would weigh r and t
/// wrongly.
template <class ForEach>
void check_shading_bsdfs(ForEach for_each, int n, double k) {
    const Sc checker = checker_box(), sheet = sheet_box(0.3f, 0.5f);
    for_each([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        for (const float x : {-0.1f, 0.1f}) {  // u along z, v along x: squares (1, 1) and (1, 2)
            const double expected = checker_albedo(Vec2(0.45f, 0.5f * (x + 1.f)));
            const Stat s = grey_scenes::estimate(est, checker, n, 41, toward(Vec3(0.f, 0.5f, 0.f), Vec3(x, -1.f, -0.1f)));
            CAPTURE(expected);
            CAPTURE(s.mean);
            CHECK(std::abs(s.mean - expected) <= k * s.se() + 1e-6);
        }
        for (const float side : {1.f, -1.f}) {
            const double expected = side > 0.f ? 0.3 : 0.5;
            const Stat s = grey_scenes::estimate(est, sheet, n, 43, toward(Vec3(0.1f, 0.6f * side, 0.2f), Vec3(0.f)));
            CAPTURE(expected);
            CAPTURE(s.mean);
            CHECK(std::abs(s.mean - expected) <= k * s.se() + 1e-6);
        }
    });
}

/// Runs the closed forms of the textured quad lights as check_shading_bsdfs does. Five walls
/// emit a 2 x 2 checkerboard of 0.8 and 0.2 read from the hit's (or sample's) uv and are sampled
/// by it: from the floor's centre every wall is as bright as a uniform 0.5, so L = 0.5 x 0.5 there
/// (0.4 if the hits' uv did not reach the light: its first quadrant everywhere; other values if a
/// density missed where it lands); seen directly, a wall is its square's value, exactly.
template <class ForEach>
void check_textured_lights(ForEach for_each, int n, double k) {
    const TexturedSc sc = textured_box();
    for_each([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        const Stat floor = grey_scenes::estimate(est, sc, n, 47, toward(Vec3(0.3f, 0.2f, 0.1f), Vec3(0.f, -1.f, 0.f)));
        CAPTURE(floor.mean);
        CHECK(std::abs(floor.mean - 0.25) <= k * floor.se() + 1e-6);
        for (const Vec3 target : {Vec3(-1.f, 0.5f, -0.5f), Vec3(-1.f, 0.5f, 0.5f)}) {  // x = -1: u along y, v along z
            const double expected = quadrant_albedo(Vec2(0.5f * (target.y + 1.f), 0.5f * (target.z + 1.f)));
            const Stat wall = grey_scenes::estimate(est, sc, 100, 49, toward(Vec3(0.f), target));
            CAPTURE(expected);
            CHECK(std::abs(wall.mean - expected) <= 1e-6);
        }
    });
}

}  // namespace nsp_test::shading_scenes
