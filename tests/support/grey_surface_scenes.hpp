// tests/support/grey_surface_scenes.hpp: the grey (Mono) surface scenes that the surface,
// emission and bidirectional estimator tests share: a homogeneous medium behind null interfaces
// (and its emitting variant) under a loose majorant, Lambertian and mirror materials, the furnace
// of six emitting walls, and the nested absorbing media with their closed-form transmittance.
#pragma once

#include <algorithm>
#include <vector>

#include <nsp/nsp.hpp>

#include "common.hpp"
#include "host/shapes.hpp"
#include "surfaces.hpp"

namespace nsp_test::grey_scenes {

using namespace nsp;
using S = Mono;
using Spectrum = S::Spectrum;
using nsp_host::Shapes;
using M = HomogeneousMedium<S>;
using EM = Emissive<HomogeneousMedium<S>>;
using Mats = Materials<S, LambertianBsdf<S>, MirrorBsdf<S>>;
using Ls = LightSampler<S, QuadLight<S>, EnvironmentLight<S>>;
using Sc = SurfaceScene<Shapes, M, GlobalMajorant<M>, HenyeyGreensteinPhase, Mats, Ls>;
using ESc = SurfaceScene<Shapes, EM, GlobalMajorant<EM>, HenyeyGreensteinPhase, Mats, Ls>;

inline Mats materials(float albedo = 0.5f) {
    return Mats({LambertianBsdf<S>(Spectrum::Constant(albedo))}, {MirrorBsdf<S>(Spectrum::Constant(albedo))});
}

/// A homogeneous medium over `box` with a majorant twice its extinction: every segment has
/// nulls, so their P_n enter the null-scattering MIS. `tight`: the majorant equals the
/// extinction instead, and no segment has a null.
inline SceneMedium<M, GlobalMajorant<M>, HenyeyGreensteinPhase> medium(Box box, float sigma_a, float sigma_s, float g = 0.3f,
                                                                      bool tight = false) {
    const M m(box, Spectrum::Constant(sigma_a), Spectrum::Constant(sigma_s));
    return {m, tight ? GlobalMajorant<M>(m) : GlobalMajorant<M>(m, 2.f * (sigma_a + sigma_s) + 0.5f), HenyeyGreensteinPhase(g)};
}

/// A homogeneous medium over `box` emitting L_e = `le` everywhere in it, majorant twice its
/// extinction.
inline SceneMedium<EM, GlobalMajorant<EM>, HenyeyGreensteinPhase> emitting(Box box, float sigma_a, float sigma_s, float le,
                                                                    float g = 0.3f) {
    const HomogeneousMedium<S> base(box, Spectrum::Constant(sigma_a), Spectrum::Constant(sigma_s));
    const EM m(base, EmissionGrid(box, {2, 2, 2}, std::vector<float>(8, 1.f)), Spectrum::Constant(le), {4, 4, 4});
    return {m, GlobalMajorant<EM>(m, 2.f * (sigma_a + sigma_s) + 0.5f), HenyeyGreensteinPhase(g)};
}

/// The six walls of [-1, 1]^3 as quad lights emitting `le` inward, and as shapes naming them
/// (normals inward; medium 0 on that side); the walls in `mirrors` are mirrors, the rest Lambertian.
inline void box_walls(float le, const std::vector<int>& mirrors, Shapes& shapes, std::vector<QuadLight<S>>& lights) {
    for (const CubeFace& f : inward_cube_faces()) {
        const int index = int(lights.size());
        const bool mirror = std::find(mirrors.begin(), mirrors.end(), index) != mirrors.end();
        lights.push_back({f.corner, f.u, f.v, Spectrum::Constant(le)});
        shapes.quads.push_back({f.corner, f.u, f.v, {mirror ? 1 : 0, index, -1, 0}});
    }
}

/// A box [-1, 1]^3 of absorbing medium 0 (sigma_a 0.5) behind null interfaces, holding a sphere of
/// radius 0.5 of medium 1 (sigma_a 1), and a quad light at z = 2 emitting 1 toward -z.
inline Sc nested_media() {
    Shapes shapes;
    shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {-1, -1, 0, -1}});
    shapes.spheres.push_back({Vec3(0.f), 0.5f, {-1, -1, 1, 0}});
    const QuadLight<S> lamp{Vec3(-2.f, -2.f, 2.f), Vec3(0.f, 4.f, 0.f), Vec3(4.f, 0.f, 0.f), Spectrum::Constant(1.f)};
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, -1, -1}});
    return Sc(shapes, {medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.5f, 0.f), medium(Box{Vec3(-0.5f), Vec3(0.5f)}, 1.f, 0.f)},
              materials(), Ls(LightSelection::Uniform, 3.f, {lamp}, {}), -1);
}

/// The nested media's box of absorbing medium 0 (sigma_a 0.5) with its sphere a null interface
/// that keeps the medium on both sides (kSameMedium): medium 0 throughout, so L = exp(-1) from
/// z = -3 toward the light and exp(-0.5) from the sphere's centre.
inline Sc sphere_keeping_medium() {
    Shapes shapes;
    shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {-1, -1, 0, -1}});
    shapes.spheres.push_back({Vec3(0.f), 0.5f, {-1, -1, kSameMedium, kSameMedium}});
    const QuadLight<S> lamp{Vec3(-2.f, -2.f, 2.f), Vec3(0.f, 4.f, 0.f), Vec3(4.f, 0.f, 0.f), Spectrum::Constant(1.f)};
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, -1, -1}});
    return Sc(shapes, {medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.5f, 0.f)}, materials(), Ls(LightSelection::Uniform, 3.f, {lamp}, {}),
              -1);
}

/// The scattering cube (albedo 0.8, HG 0.6, behind null interfaces) over a Lambertian floor,
/// under a quad lamp (`lamp_size` on a side, its power that of 1.2 at radiance 12) and (when
/// `sky`) a dim sky; the camera in front of it. `tight_majorant`: the cube's majorant is its
/// extinction (no nulls) instead of twice it.
inline Sc cube_over_floor(bool sky, float lamp_size = 1.2f, bool tight_majorant = false) {
    Shapes shapes;
    shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {-1, -1, 0, -1}});
    shapes.quads.push_back({Vec3(-3.f, -1.05f, 3.f), Vec3(6.f, 0.f, 0.f), Vec3(0.f, 0.f, -6.f), {0, -1, -1, -1}});
    const float l = lamp_size;
    const QuadLight<S> lamp{Vec3(-0.5f * l, 2.6f, -0.5f * l), Vec3(l, 0.f, 0.f), Vec3(0.f, 0.f, l),
                            Spectrum::Constant(12.f * (1.2f / l) * (1.2f / l))};
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, -1, -1}});
    std::vector<EnvironmentLight<S>> env;
    if (sky) env.push_back(EnvironmentLight<S>{Spectrum::Constant(0.05f)});
    return Sc(shapes, {medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.3f, 1.2f, 0.6f, tight_majorant)}, materials(0.6f),
              Ls(LightSelection::Power, 4.f, {lamp}, env), -1);
}

/// The scattering cube of cube_over_floor holding an opaque Lambertian ball of radius 0.4: its
/// media named (inside vacuum, outside the cube's medium 0) or, `keep`, kSameMedium on both
/// sides. Paths reach only its outside, so both describe one scene and sample the same paths.
inline Sc cube_with_ball(bool keep) {
    Sc base = cube_over_floor(true);
    Shapes shapes = base.geometry;
    shapes.spheres.push_back({Vec3(0.f), 0.4f, {0, -1, keep ? kSameMedium : -1, keep ? kSameMedium : 0}});
    return Sc(shapes, base.media, base.materials, base.lights, -1);
}

inline Ray cube_camera(Pcg32& rng) {
    const float u = rng.uniform(), v = rng.uniform();
    return Ray{Vec3(0.f, 0.3f, -4.5f), glm::normalize(Vec3(0.7f * (1.f - 2.f * u), 0.7f * (1.f - 2.f * v), 1.f))};
}

/// The cube's camera as a PinholeCamera: cube_camera(u, v) is its ray(u, 1 - v).
inline PinholeCamera cube_pinhole() {
    return PinholeCamera(Vec3(0.f, 0.3f, -4.5f), Vec3(0.f, 0.3f, 0.f), Vec3(0.f, 1.f, 0.f),
                         2.f * std::atan(0.7f) * 180.f / kPi, 1.f);
}

/// The statistics of n estimates of `est` over a SurfaceScene along rays from make_ray(rng) (Mono:
/// channel 0), every one of status Ok; one Pcg32 (seed, stream).
template <class E, class Scene, class Make>
Stat estimate(const E& est, const Scene& sc, int n, std::uint64_t seed, Make make_ray, std::uint64_t stream = 5) {
    Pcg32 rng(seed, stream);
    LookupCount counter;
    Stat s;
    for (int i = 0; i < n; ++i) {
        const auto r = est.radiance(sc, make_ray(rng), {}, rng, counter);
        REQUIRE(r.status == Status::Ok);
        s.add(r.value[0]);
    }
    return s;
}

}  // namespace nsp_test::grey_scenes
