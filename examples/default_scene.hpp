// examples/default_scene.hpp: the scenes of the example renderer, shared with the tests.
//
// The default scene: a procedural, bunny-like cloud (a few soft blobs with deterministic noise)
// on a dense grid in the box [-1, 1]^3, with a forward-scattering Henyey-Greenstein phase
// function, lit in one of two set-ups modelled on the paper's bunny scene:
//   A: a small, bright sphere light above the cloud, out of view: NEE finds it, unidirectional
//      rarely hits it;
//   B: a large, dim sphere light behind the cloud: phase sampling finds it, light sampling wastes
//      samples where the forward-peaked phase function is small;
//   D: a bright uniform sky with A's light dimmed to 1/400: tracking alone finds nearly all
//      of the light, and NEE's shadow rays are mostly cost (the case for NEE count 0).
// The camera sees the cloud from the front; B's light shows as a bright disc around it.
// Further down: the chromatic cloud (C1, C2), the sparse medium (SA, SB), a fog bank lit by a
// lamp (F1-F3, equiangular sampling) and a flame inside the cloud (P1, an emissive medium).
// Nothing is downloaded; every grid is generated in milliseconds.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <nsp/nsp.hpp>

namespace nsp_examples {

/// The light set-ups of the default scene.
enum class LightSetup { A, B, D };

inline const char* name(LightSetup s) { return s == LightSetup::A ? "A" : s == LightSetup::B ? "B" : "D"; }

/// Set-up D's sky radiance and its small light's radiance (A's light at 1/400: about 3 % of the light).
inline constexpr float kSkyRadiance = 1.f, kDimLampRadiance = 20.f;

/// Camera placement shared by the renderer and the tests: at `eye`, looking at the origin.
inline constexpr float kEye[3] = {0.f, 0.f, -4.f};
inline constexpr float kFovY = 40.f;  ///< vertical field of view in degrees

/// Grid resolution of the default cloud along each axis.
inline constexpr int kGridRes = 64;

/// Deterministic value noise in [0, 1] (hash of the lattice point, trilinear, smoothstepped).
inline float value_noise(float x, float y, float z) {
    auto hash = [](int i, int j, int k) {
        std::uint32_t h = std::uint32_t(i) * 73856093u ^ std::uint32_t(j) * 19349663u ^ std::uint32_t(k) * 83492791u;
        h ^= h >> 13; h *= 0x5bd1e995u; h ^= h >> 15;
        return float(h & 0xffffffu) / float(0xffffff);
    };
    const int i = int(std::floor(x)), j = int(std::floor(y)), k = int(std::floor(z));
    auto s = [](float t) { return t * t * (3.f - 2.f * t); };
    const float fx = s(x - float(i)), fy = s(y - float(j)), fz = s(z - float(k));
    float v = 0.f;
    for (int c = 0; c < 8; ++c) {
        const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
        v += hash(i + dx, j + dy, k + dz) * (dx ? fx : 1.f - fx) * (dy ? fy : 1.f - fy) * (dz ? fz : 1.f - fz);
    }
    return v;
}

/// density(x, y, z) at every voxel centre of a kGridRes^3 grid over [-1, 1]^3 (x fastest).
template <class F>
std::vector<float> sample_voxel_centres(F&& density) {
    std::vector<float> d(std::size_t(kGridRes) * kGridRes * kGridRes);
    for (int z = 0; z < kGridRes; ++z)
        for (int y = 0; y < kGridRes; ++y)
            for (int x = 0; x < kGridRes; ++x) {
                const float px = -1.f + 2.f * (float(x) + 0.5f) / kGridRes;
                const float py = -1.f + 2.f * (float(y) + 0.5f) / kGridRes;
                const float pz = -1.f + 2.f * (float(z) + 0.5f) / kGridRes;
                d[std::size_t(x) + std::size_t(kGridRes) * (std::size_t(y) + std::size_t(kGridRes) * std::size_t(z))] =
                    density(px, py, pz);
            }
    return d;
}

/// The cloud's densities in [0, 1] on a kGridRes^3 grid over [-1, 1]^3 (x fastest).
inline std::vector<float> default_cloud_density() {
    struct Blob { float x, y, z, r; };
    // Body, head and two ears: a rough rabbit silhouette.
    constexpr std::array<Blob, 4> blobs{{{0.f, -0.3f, 0.f, 0.6f}, {0.15f, 0.25f, 0.f, 0.35f},
                                         {0.05f, 0.7f, 0.f, 0.14f}, {0.3f, 0.68f, 0.f, 0.14f}}};
    return sample_voxel_centres([&](float px, float py, float pz) {
        float shape = 0.f;
        for (const Blob& b : blobs) {
            const float r = std::sqrt((px - b.x) * (px - b.x) + (py - b.y) * (py - b.y) + (pz - b.z) * (pz - b.z));
            shape = std::max(shape, 1.f - r / b.r);
        }
        const float n = 0.6f * value_noise(4.f * px + 10.f, 4.f * py, 4.f * pz) +
                        0.4f * value_noise(9.f * px, 9.f * py + 5.f, 9.f * pz);
        // Squaring keeps a dense core but spreads the densities over [0, 1], so the global
        // majorant is loose over most of the cloud and tracking meets many null collisions.
        const float c = std::clamp(3.f * shape - 0.6f * n, 0.f, 1.f);
        return c * c;
    });
}

/// Default medium coefficients per unit density: extinction 20, albedo 0.9 (grey).
inline constexpr float kSigmaS = 18.f, kSigmaA = 2.f;
/// Henyey-Greenstein asymmetry of the default scene: strongly forward, as in clouds. It is what
/// makes light sampling lose in set-up B (the phase lobe is much narrower than the light's cone)
/// and what makes NEE's own variance in set-up A (a vertex whose path points at the light).
inline constexpr float kPhaseG = 0.9f;

/// The lights of set-up A, B or D.
template <nsp::SpectralMode S>
nsp::Lights<S> default_lights(LightSetup setup) {
    nsp::Lights<S> lights;
    if (setup == LightSetup::A)  // above and in front of the cloud, out of view; subtends ~0.005 sr
        lights.set(nsp::SphereLight<S>{nsp::Vec3(0.8f, 2.2f, -0.6f), 0.1f, nsp::constant_coefficient<S>(8000.f)});
    else if (setup == LightSetup::D)
        lights.set(nsp::SphereLight<S>{nsp::Vec3(0.8f, 2.2f, -0.6f), 0.1f, nsp::constant_coefficient<S>(kDimLampRadiance)})
            .set(nsp::EnvironmentLight<S>{nsp::constant_coefficient<S>(kSkyRadiance)});
    else  // behind the cloud, seen as a disc around it; a cone of half-angle ~44 deg at the cloud
        lights.set(nsp::SphereLight<S>{nsp::Vec3(0.f, 0.f, 4.f), 2.8f, nsp::constant_coefficient<S>(1.f)});
    return lights;
}

/// The default medium: the cloud on a kGridRes^3 grid over [-1, 1]^3 with kSigmaA and kSigmaS.
template <nsp::SpectralMode S>
nsp::DenseGridMedium<S> make_default_medium() {
    return {nsp::Box{nsp::Vec3(-1.f), nsp::Vec3(1.f)}, {kGridRes, kGridRes, kGridRes},
            default_cloud_density(), nsp::constant_coefficient<S>(kSigmaA), nsp::constant_coefficient<S>(kSigmaS)};
}

/// The default scene: the cloud with the tightest global majorant, HG phase, set-up lights.
template <nsp::SpectralMode S>
auto make_default_scene(LightSetup setup) {
    return nsp::make_scene(make_default_medium<S>(), nsp::HenyeyGreensteinPhase(kPhaseG), default_lights<S>(setup));
}

// ---------------------------------------------------------------------------------------------
// The chromatic scene (THEORY 7, the paper's chromatic smoke): the same cloud, extinction scales
// 1 : 4 : 16 (R : G : B) per unit density and albedo 0.95 in every channel.

/// The chromatic cloud's extinction per unit density in R, G and B: G equals the grey cloud's.
inline constexpr float kChromaticExtinction[3] = {5.f, 20.f, 80.f};
/// The chromatic cloud's single-scattering albedo (every channel).
inline constexpr float kChromaticAlbedo = 0.95f;

/// The two light set-ups of the chromatic scene, modelled on the paper's two smoke scenes.
enum class ChromaticSetup {
    Env,    ///< 1: a constant white environment; phase sampling finds it (unidirectional paths dominate)
    Small,  ///< 2: set-up A's small bright sphere light above the cloud; NEE matters
    SkyLamp,  ///< 3: set-up D's lights: a bright white sky and A's light dimmed; tracking alone is best
};

inline const char* name(ChromaticSetup s) {
    return s == ChromaticSetup::Env ? "C1" : s == ChromaticSetup::Small ? "C2" : "C3";
}

/// The chromatic extinction as a coefficient of mode S. In Hero mode a piecewise-linear spectrum
/// through the RGB values at 610 (R), 550 (G) and 465 nm (B), flat beyond.
template <nsp::SpectralMode S>
typename S::Coefficient chromatic_extinction() {
    const float* k = kChromaticExtinction;
    if constexpr (nsp::is_hero_v<S>) return nsp::TabulatedSpectrum::from_points({465.f, 550.f, 610.f}, {k[2], k[1], k[0]});
    else if constexpr (S::channels == 3) return typename S::Spectrum(k[0], k[1], k[2]);
    else return S::Spectrum::Constant(k[1]);  // Mono: the green channel
}

/// The chromatic cloud: the default density grid with the chromatic extinction and albedo.
template <nsp::SpectralMode S>
nsp::DenseGridMedium<S> make_chromatic_medium() {
    const auto ext = chromatic_extinction<S>();
    return {nsp::Box{nsp::Vec3(-1.f), nsp::Vec3(1.f)}, {kGridRes, kGridRes, kGridRes}, default_cloud_density(),
            nsp::scale(ext, 1.f - kChromaticAlbedo), nsp::scale(ext, kChromaticAlbedo)};
}

/// The lights of chromatic set-up 1 or 2 (white: every channel or wavelength the same).
template <nsp::SpectralMode S>
nsp::Lights<S> chromatic_lights(ChromaticSetup setup) {
    nsp::Lights<S> lights;
    if (setup == ChromaticSetup::Env)
        lights.set(nsp::EnvironmentLight<S>{nsp::constant_coefficient<S>(1.f)});
    else if (setup == ChromaticSetup::SkyLamp)
        return default_lights<S>(LightSetup::D);
    else
        lights.set(nsp::SphereLight<S>{nsp::Vec3(0.8f, 2.2f, -0.6f), 0.1f, nsp::constant_coefficient<S>(8000.f)});
    return lights;
}

// ---------------------------------------------------------------------------------------------
// The sparse scene (issue: majorants that fit the medium): a thin rising plume and a few small
// dense puffs filling about 3% of the same [-1, 1]^3 box, where one global majorant spends most
// of its lookups on empty space and a grid majorant skips it.

/// The sparse medium's extinction per unit density (grey, albedo kSigmaS / (kSigmaA + kSigmaS)).
inline constexpr float kSparseExtinction = 60.f;

/// The sparse medium's densities in [0, 1] on a kGridRes^3 grid over [-1, 1]^3 (x fastest): five
/// puffs of radius 0.12 to 0.22 and a plume of radius 0.06 winding up from the lowest puff.
inline std::vector<float> sparse_density() {
    struct Puff { float x, y, z, r; };
    constexpr std::array<Puff, 5> puffs{{{-0.55f, -0.6f, 0.1f, 0.22f}, {0.45f, -0.35f, -0.3f, 0.16f},
                                         {0.1f, 0.5f, 0.35f, 0.18f}, {-0.4f, 0.45f, -0.45f, 0.12f},
                                         {0.6f, 0.6f, 0.5f, 0.14f}}};
    return sample_voxel_centres([&](float px, float py, float pz) {
        float shape = 0.f;
        for (const Puff& p : puffs) {
            const float r = std::sqrt((px - p.x) * (px - p.x) + (py - p.y) * (py - p.y) + (pz - p.z) * (pz - p.z));
            shape = std::max(shape, 1.f - r / p.r);
        }
        // The plume: a tube of radius 0.06 around a curve rising from the first puff.
        const float cx = -0.55f + 0.35f * std::sin(2.f * (py + 0.6f)), cz = 0.1f + 0.2f * (py + 0.6f);
        const float rp = std::sqrt((px - cx) * (px - cx) + (pz - cz) * (pz - cz));
        if (py > -0.6f && py < 0.9f) shape = std::max(shape, 0.5f * (1.f - rp / 0.06f));
        const float n = value_noise(7.f * px + 3.f, 7.f * py, 7.f * pz - 2.f);
        return std::clamp(2.f * shape - 0.3f * n, 0.f, 1.f);
    });
}

/// The sparse medium: sparse_density() with extinction kSparseExtinction and the default albedo.
template <nsp::SpectralMode S>
nsp::DenseGridMedium<S> make_sparse_medium() {
    constexpr float albedo = kSigmaS / (kSigmaA + kSigmaS);
    return {nsp::Box{nsp::Vec3(-1.f), nsp::Vec3(1.f)}, {kGridRes, kGridRes, kGridRes}, sparse_density(),
            nsp::constant_coefficient<S>(kSparseExtinction * (1.f - albedo)),
            nsp::constant_coefficient<S>(kSparseExtinction * albedo)};
}

// ---------------------------------------------------------------------------------------------
// The fog scene (issue 7: equiangular sampling, THEORY 5.4): a bank of heterogeneous ground fog
// that fills the left four fifths of the view and thins out upward, lit by a lamp (an isotropic
// point light). Three set-ups:
//   F1: the lamp inside the thin fog (optical thickness 0.03-0.28 along camera rays): tracked
//       vertices are rare and land anywhere, equiangular vertices crowd around the lamp;
//   F2: the same fog, the lamp 0.4 beside its right face, in view;
//   F3: F2's lamp beside the same fog 40x denser (thickness ~3 on the median camera ray, up to
//       11): tracking puts vertices where the camera sees the lit fog, equiangular ones deep
//       inside where little light comes out.

/// The three set-ups of the fog scene.
enum class FogSetup { F1, F2, F3 };

inline const char* name(FogSetup s) { return s == FogSetup::F1 ? "F1" : s == FogSetup::F2 ? "F2" : "F3"; }

/// The fog's box: x in [-2.2, 0.8] (the right fifth of the view is empty), y in [-1.6, 1.6],
/// z in [-1.5, 2.5] (the camera at z = -4 stays outside).
inline constexpr float kFogLo[3] = {-2.2f, -1.6f, -1.5f}, kFogHi[3] = {0.8f, 1.6f, 2.5f};
/// Extinction per unit density of the thin fog (F1, F2) and of the dense one (F3, 40x).
inline constexpr float kFogExtinction = 0.12f, kDenseFogExtinction = 4.8f;
/// Single-scattering albedo and Henyey-Greenstein asymmetry of the fog (moderately forward, as
/// haze).
inline constexpr float kFogAlbedo = 0.9f, kFogPhaseG = 0.7f;
/// The lamp: intensity, and its position inside the fog (F1) or beside it (F2, F3).
inline constexpr float kLampIntensity = 5.f;
inline constexpr float kLampInside[3] = {-0.5f, 0.f, 0.4f}, kLampBeside[3] = {1.2f, 0.f, 0.4f};

/// The fog's densities in [0, 1] on a kGridRes^3 grid over its box (x fastest): three octaves of
/// value noise around a floor, times exp(-2 h) with h the normalised height (thinner upward).
inline std::vector<float> fog_density() {
    const int n = kGridRes;
    std::vector<float> d(std::size_t(n) * n * n);
    std::size_t i = 0;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x, ++i) {
                const float u = (float(x) + 0.5f) / float(n), h = (float(y) + 0.5f) / float(n);
                const float w = (float(z) + 0.5f) / float(n);
                const float f = 0.5f * value_noise(4.f * u, 4.f * h, 4.f * w) +
                                0.3f * value_noise(9.f * u + 3.f, 9.f * h, 9.f * w) +
                                0.2f * value_noise(19.f * u, 19.f * h + 7.f, 19.f * w);
                d[i] = std::clamp(0.2f + 0.8f * (2.f * f - 0.5f), 0.f, 1.f) * std::exp(-2.f * h);
            }
    return d;
}

/// The fog of set-up `setup`: fog_density() over the fog box, kFogExtinction (F1, F2) or
/// kDenseFogExtinction (F3) per unit density, albedo kFogAlbedo.
template <nsp::SpectralMode S>
nsp::DenseGridMedium<S> make_fog_medium(FogSetup setup) {
    const float ext = setup == FogSetup::F3 ? kDenseFogExtinction : kFogExtinction;
    return {nsp::Box{nsp::Vec3(kFogLo[0], kFogLo[1], kFogLo[2]), nsp::Vec3(kFogHi[0], kFogHi[1], kFogHi[2])},
            {kGridRes, kGridRes, kGridRes}, fog_density(), nsp::constant_coefficient<S>(ext * (1.f - kFogAlbedo)),
            nsp::constant_coefficient<S>(ext * kFogAlbedo)};
}

/// The lamp of set-up `setup`: inside the fog (F1) or beside it (F2, F3); no other light.
template <nsp::SpectralMode S>
nsp::Lights<S> fog_lights(FogSetup setup) {
    const float* p = setup == FogSetup::F1 ? kLampInside : kLampBeside;
    nsp::Lights<S> lights;
    lights.set(nsp::PointLight<S>{nsp::Vec3(p[0], p[1], p[2]), nsp::constant_coefficient<S>(kLampIntensity)});
    return lights;
}

// ---------------------------------------------------------------------------------------------
// The plume scene (issue 7: emissive media, THEORY 5.7): a flame inside the cloud. The medium is
// the default cloud's density with a quarter of its extinction (5 per unit density, albedo 0.9:
// about 6 optical depths through the body), isotropic scattering (smoke), and an emission grid
// that is non-zero only in a thin flickering flame in the back half of the body, behind its dense
// core as the camera sees it. No other light: the image is the flame seen through the smoke and
// the smoke's glow around it, which is light the flame sends to every scattering vertex.
// Set-up P1.

/// The plume medium's extinction per unit density (the grey cloud's is 20), albedo 0.9 as the
/// cloud's, and its phase asymmetry (isotropic).
inline constexpr float kPlumeExtinction = 5.f, kPlumePhaseG = 0.f;
/// The flame: base centre, tip height, base radius (the radius shrinks to 30% at the tip).
inline constexpr float kFlameBase[3] = {0.f, -0.6f, 0.3f};
inline constexpr float kFlameTip = -0.1f, kFlameRadius = 0.05f;
/// The emission grid's box (around the flame and its sideways flicker) and resolution.
inline constexpr float kFlameBoxLo[3] = {-0.145f, -0.62f, 0.155f}, kFlameBoxHi[3] = {0.145f, -0.08f, 0.445f};
inline constexpr std::array<int, 3> kFlameRes{24, 32, 24};
/// Emission strength at the hottest point of the flame (times kFlameColour per channel).
inline constexpr float kFlameStrength = 80.f;
/// The flame's colour, L_e per unit strength in R, G, B.
inline constexpr float kFlameColour[3] = {6.f, 2.f, 0.5f};

/// The flame's emission strength on kFlameRes voxels over the flame box (x fastest): a
/// temperature-like field, kFlameStrength x (1 - r / R(h))^2 x (1 - h) x noise in [0.6, 1.4],
/// with h in [0, 1] from base to tip, R(h) the radius (shrinking upward) and r the distance from
/// the flame's axis, which flickers sideways by up to 0.06; zero outside the flame.
inline std::vector<float> flame_strength() {
    const std::array<int, 3> n = kFlameRes;
    std::vector<float> v(static_cast<std::size_t>(n[0] * n[1] * n[2]), 0.f);
    std::size_t i = 0;
    for (int z = 0; z < n[2]; ++z)
        for (int y = 0; y < n[1]; ++y)
            for (int x = 0; x < n[0]; ++x, ++i) {
                const int c[3] = {x, y, z};
                float p[3];
                for (int a = 0; a < 3; ++a)
                    p[a] = kFlameBoxLo[a] + (float(c[a]) + 0.5f) / float(n[a]) * (kFlameBoxHi[a] - kFlameBoxLo[a]);
                const float h = (p[1] - kFlameBase[1]) / (kFlameTip - kFlameBase[1]);
                if (h < 0.f || h > 1.f) continue;
                const float flicker = 0.06f * std::sin(9.f * p[1] + 1.f);
                const float r = std::hypot(p[0] - kFlameBase[0] - flicker, p[2] - kFlameBase[2]) /
                                (kFlameRadius * (1.f - 0.7f * h));
                const float core = std::max(0.f, 1.f - r);
                const float noise = value_noise(8.f * p[0] + 2.f, 8.f * p[1], 8.f * p[2]);
                v[i] = kFlameStrength * core * core * (1.f - h) * (0.6f + 0.8f * noise);
            }
    return v;
}

/// kFlameColour as a coefficient of mode S: Rgb as it is; Mono the mean; Hero a piecewise-linear
/// spectrum through the RGB values at 610 (R), 550 (G) and 465 nm (B), flat beyond.
template <nsp::SpectralMode S>
typename S::Coefficient flame_colour() {
    const float* k = kFlameColour;
    if constexpr (nsp::is_hero_v<S>) return nsp::TabulatedSpectrum::from_points({465.f, 550.f, 610.f}, {k[2], k[1], k[0]});
    else if constexpr (S::channels == 3) return typename S::Spectrum(k[0], k[1], k[2]);
    else return S::Spectrum::Constant((k[0] + k[1] + k[2]) / 3.f);
}

/// The plume medium: the default cloud density with kPlumeExtinction per unit density and the
/// default albedo, emitting flame_strength() x flame_colour() (L_e; the source term is mu_a L_e).
template <nsp::SpectralMode S>
nsp::Emissive<nsp::DenseGridMedium<S>> make_plume_medium() {
    constexpr float albedo = kSigmaS / (kSigmaA + kSigmaS);
    nsp::DenseGridMedium<S> smoke{nsp::Box{nsp::Vec3(-1.f), nsp::Vec3(1.f)}, {kGridRes, kGridRes, kGridRes},
                                  default_cloud_density(), nsp::constant_coefficient<S>(kPlumeExtinction * (1.f - albedo)),
                                  nsp::constant_coefficient<S>(kPlumeExtinction * albedo)};
    const nsp::Box flame_box{nsp::Vec3(kFlameBoxLo[0], kFlameBoxLo[1], kFlameBoxLo[2]),
                             nsp::Vec3(kFlameBoxHi[0], kFlameBoxHi[1], kFlameBoxHi[2])};
    return {std::move(smoke), nsp::EmissionGrid(flame_box, kFlameRes, flame_strength()), flame_colour<S>()};
}

/// The camera ray through normalised image coordinates (u, v) in [0, 1]^2, v up, square pixels
/// for an image of aspect = width / height.
inline nsp::Ray camera_ray(float u, float v, float aspect) {
    const float tan_half = std::tan(0.5f * kFovY * nsp::kPi / 180.f);
    const nsp::Vec3 d((1.f - 2.f * u) * tan_half * aspect, (2.f * v - 1.f) * tan_half, 1.f);  // right-handed: u = 0 left (+x)
    return {nsp::Vec3(kEye[0], kEye[1], kEye[2]), glm::normalize(d)};
}

}  // namespace nsp_examples
