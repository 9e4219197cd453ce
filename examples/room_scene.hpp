// examples/room_scene.hpp: the surface-and-smoke scene of the main job (nsp_room): the default
// cloud (default_scene.hpp), grey or chromatic, resting over a diffuse floor in an open room (a
// floor, a back wall and a left wall), lit by a small rectangular light above and to the right of
// it and a dim sky, as an nsp::SurfaceScene over the example shapes (host/shapes.hpp); the
// lantern (a lamp in a box above the cloud); and the glass (the cloud in a thin glass cube on a
// checkered floor, a lamp in the smoke, under a sky image).
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <nsp/nsp.hpp>

#include "default_scene.hpp"
#include "scene_choice.hpp"
#include "host/shapes.hpp"

namespace nsp_examples {

template <nsp::SpectralMode S>
using RoomMaterials = nsp::Materials<S, nsp::LambertianBsdf<S>>;
template <nsp::SpectralMode S>
using RoomLights = nsp::LightSampler<S, nsp::QuadLight<S>, nsp::EnvironmentLight<S>>;
/// The room with medium M under majorant Maj (the default: the grey cloud, Mono, one global majorant).
template <nsp::Medium M = nsp::DenseGridMedium<nsp::Mono>, class Maj = nsp::GlobalMajorant<M>>
using RoomScene = nsp::SurfaceScene<nsp_host::Shapes, M, Maj, nsp::HenyeyGreensteinPhase,
                                    RoomMaterials<typename M::Spectral>, RoomLights<typename M::Spectral>>;

/// The lamp: 0.7 x 0.7 at height 2.2 above (1.1, 0.3), facing down, radiance 40 (white).
template <nsp::SpectralMode S = nsp::Mono>
nsp::QuadLight<S> room_lamp() {
    return {nsp::Vec3(0.75f, 2.2f, -0.05f), nsp::Vec3(0.7f, 0.f, 0.f), nsp::Vec3(0.f, 0.f, 0.7f),
            nsp::constant_coefficient<S>(40.f)};
}
inline constexpr float kRoomSky = 0.08f;  ///< the environment's radiance (white)
inline constexpr float kRoomFloorY = -1.05f;

/// The medium's box (null interfaces, medium 0 inside), the floor (material 0) and the back and
/// left walls (material 1) of the room and of the lantern.
inline void add_room_shell(nsp_host::Shapes& shapes) {
    shapes.boxes.push_back({nsp::Vec3(-1.f), nsp::Vec3(1.f), {-1, -1, 0, -1}});
    const float y0 = kRoomFloorY, y1 = 2.95f;
    shapes.quads.push_back({nsp::Vec3(-3.f, y0, 3.f), nsp::Vec3(6.f, 0.f, 0.f), nsp::Vec3(0.f, 0.f, -6.f), {0, -1, -1, -1}});
    shapes.quads.push_back({nsp::Vec3(-3.f, y0, 3.f), nsp::Vec3(0.f, y1 - y0, 0.f), nsp::Vec3(6.f, 0.f, 0.f), {1, -1, -1, -1}});
    shapes.quads.push_back({nsp::Vec3(-3.f, y0, -3.f), nsp::Vec3(0.f, 0.f, 6.f), nsp::Vec3(0.f, y1 - y0, 0.f), {1, -1, -1, -1}});
}

/// The room around `medium` (in [-1, 1]^3, behind null interfaces: medium 0) with `majorant`:
/// the floor (material 0, albedo 0.7), the back and left walls (material 1, albedo 0.5), the lamp
/// (light 0) and the sky (light 1), light selection by power. Grey surfaces and lights.
/// `sky_subpaths`: the light sampler gets a BoundingSphere around the room (centre (0, 0.95, 0),
/// radius 4.8; the shell's corners lie 4.69 from it), so BDPT's light subpaths start from the sky
/// too; its power is then measured over that radius instead of 4, which changes the selection.
template <nsp::Medium M, class Maj>
RoomScene<M, Maj> make_room_scene(M medium, Maj majorant, bool sky_subpaths = false) {
    using S = typename M::Spectral;
    nsp_host::Shapes shapes;
    add_room_shell(shapes);
    const nsp::QuadLight<S> lamp = room_lamp<S>();
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, -1, -1}});
    return RoomScene<M, Maj>(std::move(shapes), {{std::move(medium), std::move(majorant), nsp::HenyeyGreensteinPhase(kPhaseG)}},
                             RoomMaterials<S>({nsp::LambertianBsdf<S>(nsp::constant_coefficient<S>(0.7f)),
                                               nsp::LambertianBsdf<S>(nsp::constant_coefficient<S>(0.5f))}),
                             sky_subpaths
                                 ? RoomLights<S>(nsp::LightSelection::Power, nsp::BoundingSphere{nsp::Vec3(0.f, 0.95f, 0.f), 4.8f},
                                                 {lamp}, {nsp::EnvironmentLight<S>{nsp::constant_coefficient<S>(kRoomSky)}})
                                 : RoomLights<S>(nsp::LightSelection::Power, 4.f, {lamp},
                                                 {nsp::EnvironmentLight<S>{nsp::constant_coefficient<S>(kRoomSky)}}),
                             -1);
}

/// The grey room of the main job's first table: the default cloud, Mono, one global majorant.
inline RoomScene<> make_room_scene(bool sky_subpaths = false) {
    auto cloud = make_default_medium<nsp::Mono>();
    nsp::GlobalMajorant<nsp::DenseGridMedium<nsp::Mono>> majorant(cloud);
    return make_room_scene(std::move(cloud), majorant, sky_subpaths);
}

/// The lantern: the room's floor and walls around the cloud, no sky, lit only by a lamp inside a
/// closed box above the cloud whose one opening, its floor, faces down into the smoke (after
/// the paper's BDPT scene): light reaches what the camera sees only by
/// scattering in the cloud (or straight through its thin parts), the camera cannot see the lamp
/// (only a sliver of the box's lit inner wall),
/// and NEE toward the lamp from the floor and the walls is always blocked: only the points in the
/// beam below the opening see the lamp. The box, 0.3 x 0.8 x 0.3 over (0, 1.55, 0) with dark
/// Lambertian walls (albedo 0.2, material 2), holds the lamp 0.26 x 0.26 at its ceiling facing
/// down, radiance 300; its opening is 0.15 above the cloud's bounds.
template <nsp::Medium M, class Maj>
RoomScene<M, Maj> make_lantern_scene(M medium, Maj majorant) {
    using S = typename M::Spectral;
    nsp_host::Shapes shapes;
    add_room_shell(shapes);
    // The lantern's four sides and its ceiling (material 2); open at y = 1.15.
    const float lo = 1.15f, hi = 1.95f, h = 0.15f;
    const nsp::Vec3 up(0.f, hi - lo, 0.f);
    shapes.quads.push_back({nsp::Vec3(-h, lo, -h), nsp::Vec3(2.f * h, 0.f, 0.f), up, {2, -1, -1, -1}});
    shapes.quads.push_back({nsp::Vec3(-h, lo, h), up, nsp::Vec3(2.f * h, 0.f, 0.f), {2, -1, -1, -1}});
    shapes.quads.push_back({nsp::Vec3(-h, lo, -h), up, nsp::Vec3(0.f, 0.f, 2.f * h), {2, -1, -1, -1}});
    shapes.quads.push_back({nsp::Vec3(h, lo, -h), nsp::Vec3(0.f, 0.f, 2.f * h), up, {2, -1, -1, -1}});
    shapes.quads.push_back({nsp::Vec3(-h, hi, -h), nsp::Vec3(0.f, 0.f, 2.f * h), nsp::Vec3(2.f * h, 0.f, 0.f), {2, -1, -1, -1}});
    const nsp::QuadLight<S> lamp{nsp::Vec3(-0.13f, hi - 0.02f, -0.13f), nsp::Vec3(0.26f, 0.f, 0.f), nsp::Vec3(0.f, 0.f, 0.26f),
                                 nsp::constant_coefficient<S>(300.f)};
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, -1, -1}});
    return RoomScene<M, Maj>(std::move(shapes), {{std::move(medium), std::move(majorant), nsp::HenyeyGreensteinPhase(kPhaseG)}},
                             RoomMaterials<S>({nsp::LambertianBsdf<S>(nsp::constant_coefficient<S>(0.7f)),
                                               nsp::LambertianBsdf<S>(nsp::constant_coefficient<S>(0.5f)),
                                               nsp::LambertianBsdf<S>(nsp::constant_coefficient<S>(0.2f))}),
                             RoomLights<S>(nsp::LightSelection::Power, 4.f, {lamp}, {}), -1);
}

// ---------------------------------------------------------------------------------------------
// The glass: the cloud inside a thin glass cube on a checkered floor, a lamp inside the smoke,
// under an environment map. What a host brings: a BSDF that reads the hit's uv, a partly null
// BSDF around a medium, an emitter inside a medium and an image light.

/// The glass scene's floor: Lambertian with a checkerboard albedo, 0.75 and 0.25 on 8 x 8 squares
/// over the quad's uv; a host's textured BSDF (nsp::ShadingBsdf).
template <nsp::SpectralMode S>
struct CheckerFloorBsdf {
    static constexpr bool passes_through = false;

    static float albedo(const nsp::ShadingPoint& sp) {
        return (int(8.f * sp.uv.x) + int(8.f * sp.uv.y)) % 2 == 0 ? 0.75f : 0.25f;
    }
    nsp::BsdfSample<S> sample(const nsp::ShadingPoint& sp, const nsp::Vec3& wo, const nsp::Vec3& u,
                              const typename S::Wavelengths& = {}) const noexcept {
        const float cos_theta = std::sqrt(std::max(0.f, 1.f - u.x));
        nsp::BsdfSample<S> s;
        if (!(cos_theta > 0.f)) return s;
        s.wi = nsp::direction_around(nsp::detail::facing(wo, sp.ns), cos_theta, 2.f * nsp::kPi * u.y);
        s.pdf = cos_theta / nsp::kPi;
        s.value = S::Spectrum::Constant(albedo(sp) * cos_theta / nsp::kPi);
        return s;
    }
    typename S::Spectrum eval(const nsp::ShadingPoint& sp, const nsp::Vec3& wo, const nsp::Vec3& wi,
                              const typename S::Wavelengths& = {}) const noexcept {
        const float c = glm::dot(wi, nsp::detail::facing(wo, sp.ns));
        return S::Spectrum::Constant(c > 0.f ? albedo(sp) * c / nsp::kPi : 0.f);
    }
    float pdf(const nsp::ShadingPoint& sp, const nsp::Vec3& wo, const nsp::Vec3& wi) const noexcept {
        const float c = glm::dot(wi, nsp::detail::facing(wo, sp.ns));
        return c > 0.f ? c / nsp::kPi : 0.f;
    }
};

template <nsp::SpectralMode S>
using GlassMaterials =
    nsp::Materials<S, CheckerFloorBsdf<S>, nsp::ThinDielectricBsdf<S>, nsp::LambertianBsdf<S>, nsp::RoughDielectricBsdf<S>>;
template <nsp::SpectralMode S>
using GlassLights = nsp::LightSampler<S, nsp::QuadLight<S>, nsp::ImageEnvironmentLight<S>>;
template <nsp::Medium M = nsp::DenseGridMedium<nsp::Mono>, class Maj = nsp::GlobalMajorant<M>>
using GlassScene = nsp::SurfaceScene<nsp_host::Shapes, M, Maj, nsp::HenyeyGreensteinPhase,
                                     GlassMaterials<typename M::Spectral>, GlassLights<typename M::Spectral>>;

/// The glass scene's sky, 64 x 32 in latitude-longitude: a gradient from a pale horizon (0.35) to
/// a blue zenith and a sun 6 degrees across, 30 degrees up toward -x, +z (radiance 400), dark below
/// the horizon (0.05).
inline std::vector<float> glass_sky_image(int w = 64, int h = 32) {
    std::vector<float> rgb(std::size_t(w) * std::size_t(h) * 3);
    const nsp::Vec3 sun = glm::normalize(nsp::Vec3(-0.6f, std::tan(30.f * nsp::kPi / 180.f), 0.8f));
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const float theta = nsp::kPi * (float(y) + 0.5f) / float(h), phi = 2.f * nsp::kPi * (float(x) + 0.5f) / float(w);
            const nsp::Vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
            float r = 0.05f, g = 0.05f, b = 0.05f;
            if (d.y > 0.f) {
                r = 0.35f - 0.25f * d.y;
                g = 0.35f - 0.15f * d.y;
                b = 0.35f + 0.1f * d.y;
            }
            if (glm::dot(d, sun) > std::cos(5.f * nsp::kPi / 180.f)) r = g = b = 144.f;
            float* px = &rgb[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 3];
            px[0] = r, px[1] = g, px[2] = b;
        }
    }
    return rgb;
}

/// The glass: `medium` (in [-1, 1]^3) inside a thin glass cube of index 1.5 (material 1, medium 0
/// inside), standing on the room's floor as a checkerboard (material 0, uv over its 6 x 6) before
/// the back and left walls (material 2, albedo 0.5); a lamp 0.3 x 0.3 inside the smoke at height
/// 0.6, facing down, radiance 25 (light 0, medium 0 on both sides); a ball of rough glass (index
/// 1.5, alpha 0.2; material 3) of radius 0.45 on the floor in front of it, to the left; the sky
/// image (light 1).
template <nsp::Medium M, class Maj>
GlassScene<M, Maj> make_glass_scene(M medium, Maj majorant) {
    using S = typename M::Spectral;
    nsp_host::Shapes shapes;
    shapes.report_uv = true;
    add_room_shell(shapes);
    shapes.boxes[0].h.material = 1;
    shapes.quads[1].h.material = shapes.quads[2].h.material = 2;
    const nsp::QuadLight<S> lamp{nsp::Vec3(-0.15f, 0.6f, -0.15f), nsp::Vec3(0.f, 0.f, 0.3f), nsp::Vec3(0.3f, 0.f, 0.f),
                                 nsp::constant_coefficient<S>(25.f)};
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, 0, 0}});
    shapes.spheres.push_back({nsp::Vec3(1.f, kRoomFloorY + 0.45f, -2.f), 0.45f, {3, -1, -1, -1}});
    return GlassScene<M, Maj>(
        std::move(shapes), {{std::move(medium), std::move(majorant), nsp::HenyeyGreensteinPhase(kPhaseG)}},
        GlassMaterials<S>({CheckerFloorBsdf<S>{}}, {nsp::ThinDielectricBsdf<S>(1.5f)},
                          {nsp::LambertianBsdf<S>(nsp::constant_coefficient<S>(0.5f))}, {nsp::RoughDielectricBsdf<S>(1.5f, 0.35f)}),
        GlassLights<S>(nsp::LightSelection::Power, 4.f, {lamp}, {nsp::ImageEnvironmentLight<S>(64, 32, glass_sky_image())}),
        -1);
}

/// The glass of the main job's table: the default cloud, Mono, one global majorant.
inline GlassScene<> make_glass_scene() {
    auto cloud = make_default_medium<nsp::Mono>();
    nsp::GlobalMajorant<nsp::DenseGridMedium<nsp::Mono>> majorant(cloud);
    return make_glass_scene(std::move(cloud), majorant);
}

/// The room's camera: from (0, 0.6, -5.6) toward (0, -0.15, 0), 42 degrees vertical field of
/// view; (u, v) in [0, 1)^2 with v = 0 at the bottom.
inline nsp::Ray room_camera_ray(float u, float v, float aspect) {
    const nsp::Vec3 eye(0.f, 0.6f, -5.6f), target(0.f, -0.15f, 0.f);
    const nsp::Vec3 f = glm::normalize(target - eye);
    const nsp::Vec3 r = glm::normalize(glm::cross(f, nsp::Vec3(0.f, 1.f, 0.f)));  // right-handed, as nsp::PinholeCamera
    const nsp::Vec3 up = glm::cross(r, f);
    const float tan_half = std::tan(0.5f * 42.f * nsp::kPi / 180.f);
    return {eye, glm::normalize(f + (2.f * u - 1.f) * tan_half * aspect * r + (2.f * v - 1.f) * tan_half * up)};
}

/// The lights of the main job's scenes in empty space as one LightSampler type (a model's list
/// is empty where a scene has none of it).
template <nsp::SpectralMode S>
using EmptySpaceLights = nsp::LightSampler<S, nsp::SphereLight<S>, nsp::PointLight<S>, nsp::EnvironmentLight<S>>;
template <nsp::Medium M, class Maj>
using EmptySpaceScene = nsp::SurfaceScene<nsp_host::Shapes, M, Maj, nsp::HenyeyGreensteinPhase,
                                          RoomMaterials<typename M::Spectral>, EmptySpaceLights<typename M::Spectral>>;

/// A scene of the main job's nsp_render (a medium in empty space under its nsp::Lights; the
/// phase asymmetry g) as a SurfaceScene, so that the bidirectional estimator, which needs a
/// geometry that reports the lights it may hit, renders it: the medium's box behind null
/// interfaces (medium 0), a sphere light as a sphere shape naming light 0, no other surface;
/// lights selected uniformly, scene radius 4 (nsp_render's). What PathEstimator renders from it
/// equals the nsp::Scene's image (the same medium, phase function, lights and camera).
template <nsp::Medium M, class Maj>
EmptySpaceScene<M, Maj> make_empty_space_scene(M medium, Maj majorant, float g, const nsp::Lights<typename M::Spectral>& lights) {
    using S = typename M::Spectral;
    nsp_host::Shapes shapes;
    const nsp::Box box = medium.bounds();
    shapes.boxes.push_back({box.lo, box.hi, {-1, -1, 0, -1}});
    std::vector<nsp::SphereLight<S>> spheres;
    std::vector<nsp::PointLight<S>> points;
    std::vector<nsp::EnvironmentLight<S>> environments;
    if (lights.sphere()) {
        spheres.push_back(*lights.sphere());
        shapes.spheres.push_back({spheres[0].center, spheres[0].radius, {-1, 0, -1, -1}});  // light 0: the first model's first
    }
    if (lights.point()) points.push_back(*lights.point());
    if (lights.environment()) environments.push_back(*lights.environment());
    return EmptySpaceScene<M, Maj>(std::move(shapes), {{std::move(medium), std::move(majorant), nsp::HenyeyGreensteinPhase(g)}},
                                   RoomMaterials<S>({}),
                                   EmptySpaceLights<S>(nsp::LightSelection::Uniform, 4.f, std::move(spheres), std::move(points),
                                                       std::move(environments)),
                                   -1);
}

/// nsp_render's set-up `c` as a SurfaceScene (make_empty_space_scene) in spectral mode S: its
/// medium made by `Medium` (a medium of combinations.hpp: DenseGridCloud, EmissivePlume), its
/// majorant by the policy `Majorant` at nsp_render's default MajorantSettings, its phase and
/// lights.
template <nsp::SpectralMode S, class Medium, class Majorant>
auto make_setup_surface_scene(const SceneChoice& c) {
    auto medium = Medium::template make<S>(c);
    const auto majorant = Majorant::make(medium, MajorantSettings{});
    return make_empty_space_scene(std::move(medium), majorant, phase_g(c.kind), scene_lights<S>(c));
}

/// The main job's cloud scene (default_scene.hpp, set-up A or B) as a SurfaceScene
/// (make_empty_space_scene): the grey cloud under its one global majorant.
inline auto make_cloud_surface_scene(LightSetup setup) {
    auto cloud = make_default_medium<nsp::Mono>();
    nsp::GlobalMajorant<nsp::DenseGridMedium<nsp::Mono>> majorant(cloud);
    return make_empty_space_scene(std::move(cloud), majorant, kPhaseG, default_lights<nsp::Mono>(setup));
}

/// The main job's camera (default_scene.hpp's camera_ray) as an nsp::PinholeCamera, square image.
inline nsp::PinholeCamera cloud_pinhole() {
    const nsp::Vec3 eye(kEye[0], kEye[1], kEye[2]);
    return nsp::PinholeCamera(eye, eye + nsp::Vec3(0.f, 0.f, 1.f), nsp::Vec3(0.f, 1.f, 0.f), kFovY, 1.f);
}

/// The same camera as an nsp::PinholeCamera (light tracing needs where points appear on the image):
/// its ray(u, v) is room_camera_ray(u, v, 1).
inline nsp::PinholeCamera room_pinhole() {
    return nsp::PinholeCamera(nsp::Vec3(0.f, 0.6f, -5.6f), nsp::Vec3(0.f, -0.15f, 0.f), nsp::Vec3(0.f, 1.f, 0.f), 42.f, 1.f);
}

}  // namespace nsp_examples
