// tests/support/null_lobe_scenes.hpp: partly null BSDFs (nsp::PartlyNullBsdf: a lobe that passes
// straight through, taken with a probability) in scenes whose radiance has a closed form, for the
// path tracer's and BDPT's tests. A thin dielectric sheet (nsp::ThinDielectricBsdf) across a box
// whose upper half emits: R' seen from above, T' from below. A filter sheet that passes a weight
// other than its probability, over a Lambertian floor: L = rho w F, F the floor's form factor to
// the sheet, so that every shadow ray and every light hit crosses a null lobe. An alpha-masked
// Lambertian sheet (nsp::AlphaMasked) whose opacity is a uv checkerboard. And a white furnace: a
// medium of albedo 1 inside a thin-glass cube over an alpha-masked white floor under a uniform
// sky, L = 1.
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <nsp/nsp.hpp>

#include "grey_surface_scenes.hpp"
#include "host/shapes.hpp"
#include "surfaces.hpp"

namespace nsp_test::null_lobe_scenes {

using namespace nsp;
using nsp_host::Shapes;

/// Passes `weight` straight through with probability `p` and absorbs the rest: its real lobe is
/// black (no sample), so a path that does not take the null lobe ends there.
template <SpectralMode S>
struct FilterSheet {
    static constexpr bool passes_through = false;
    typename S::Coefficient weight = constant_coefficient<S>(0.45f);
    float p = 0.6f;

    NullLobe<S> null_lobe(const ShadingPoint&, const Vec3&, const typename S::Wavelengths& l = {}) const {
        return {S::sample(weight, l), p};
    }
    BsdfSample<S> sample(const Vec3&, const Vec3&, float, float, const typename S::Wavelengths& = {}) const { return {}; }
    typename S::Spectrum eval(const Vec3&, const Vec3&, const Vec3&, const typename S::Wavelengths& = {}) const {
        return S::Spectrum::Zero();
    }
    float pdf(const Vec3&, const Vec3&, const Vec3&) const { return 0.f; }
};

/// The sheet's opacity: a 2 x 2 checkerboard of 0.25 and 0.75 over uv in [0, 1]^2.
struct CheckerOpacity {
    float operator()(const ShadingPoint& sp) const {
        return (int(2.f * sp.uv.x) + int(2.f * sp.uv.y)) % 2 == 0 ? 0.25f : 0.75f;
    }
};

template <SpectralMode S>
using Masked = AlphaMasked<S, LambertianBsdf<S>, CheckerOpacity>;
static_assert(PartlyNullBsdf<FilterSheet<Mono>, Mono> && PartlyNullBsdf<Masked<Rgb>, Rgb> && ShadingBsdf<Masked<Mono>, Mono> &&
              PartlyNullBsdf<ThinDielectricBsdf<Mono>, Mono>);

template <SpectralMode S>
using Mats = Materials<S, ThinDielectricBsdf<S>, FilterSheet<S>, Masked<S>, LambertianBsdf<S>, RoughDielectricBsdf<S>>;
template <SpectralMode S>
using Ls = LightSampler<S, QuadLight<S>, EnvironmentLight<S>>;
/// The scenes over medium M (HomogeneousMedium<S>) and majorant Maj.
template <class M, class Maj = GlobalMajorant<M>>
using SceneOf = SurfaceScene<Shapes, M, Maj, HenyeyGreensteinPhase, Mats<typename M::Spectral>, Ls<typename M::Spectral>>;
using Sc = SceneOf<grey_scenes::M>;

// The materials, in the order Materials numbers them.
inline constexpr int kThin = 0, kFilter = 1, kMasked = 2, kWhiteMasked = 3, kBlack = 4, kFloor = 5, kRough = 6;
inline constexpr float kEta = 1.5f, kSheetAlbedo = 0.6f, kFloorAlbedo = 0.5f, kRoughAlpha = 0.3f;

/// The materials; the filter passes `filter` (0.45 in every channel by default) with probability
/// `filter_p`; the rough dielectric has index rough_eta and roughness rough_alpha.
template <SpectralMode S>
Mats<S> materials(typename S::Coefficient filter = constant_coefficient<S>(0.45f), float filter_p = 0.6f,
                  float rough_eta = kEta, float rough_alpha = kRoughAlpha) {
    auto lambert = [](float a) { return LambertianBsdf<S>(constant_coefficient<S>(a)); };
    return Mats<S>({ThinDielectricBsdf<S>(kEta)}, {FilterSheet<S>{filter, filter_p}},
                   {Masked<S>{lambert(kSheetAlbedo), {}}, Masked<S>{lambert(1.f), {}}}, {lambert(0.f), lambert(kFloorAlbedo)},
                   {RoughDielectricBsdf<S>(rough_eta, rough_alpha)});
}

/// The integral of BSDF b's value f |n . wi| (channel 0) over the directions wi with wi . axis > 0,
/// for a path arriving along wo at sp: the midpoint rule on 512 x 512 cells of equal solid angle in
/// (cos theta, phi) about axis, summed in double.
template <SpectralMode S, class B>
double hemisphere_integral(const B& b, const ShadingPoint& sp, const Vec3& wo, const Vec3& axis) {
    constexpr int kN = 512;
    Vec3 s, t;
    orthonormal_basis(axis, s, t);
    double sum = 0.0;
    for (int i = 0; i < kN; ++i) {
        const double c = (i + 0.5) / kN, r = std::sqrt(1.0 - c * c);
        for (int j = 0; j < kN; ++j) {
            const double phi = 2.0 * kPi * (j + 0.5) / kN;
            const Vec3 wi = float(r * std::cos(phi)) * s + float(r * std::sin(phi)) * t + float(c) * axis;
            sum += double(detail::eval_bsdf<S>(b, sp, wo, glm::normalize(wi), {})[0]);
        }
    }
    return sum * 2.0 * kPi / (double(kN) * kN);
}

/// A thin dielectric sheet's reflectance R' = 2R / (1 + R) at incidence cosine c, R the Fresnel
/// reflectance of index kEta, in double (independent of nsp's).
inline double thin_reflectance(double c) {
    const double eta = kEta, s2 = (1.0 - c * c) / (eta * eta), ct = std::sqrt(1.0 - s2);
    const double rs = (c - eta * ct) / (c + eta * ct), rp = (eta * c - ct) / (eta * c + ct);
    const double r = 0.5 * (rs * rs + rp * rp);
    return 2.0 * r / (1.0 + r);
}

/// The form factor from the centre of the floor y = -1 to the square [-1, 1]^2 at y = 0 above it:
/// four corner rectangles 1 x 1 at height 1, each (1 / 2 pi) 2 (1 / sqrt 2) atan(1 / sqrt 2).
inline double floor_to_sheet() { return 4.0 / (kPi * std::sqrt(2.0)) * std::atan(1.0 / std::sqrt(2.0)); }

/// The cube [-1, 1]^3 in vacuum cut at y = 0 by a sheet of material `sheet`: the walls of the
/// upper half emit 1 inward, those of the lower half are black, the floor (y = -1) is `floor`.
/// Scene Sc by default, or a SceneOf another mode's medium.
template <class Scene = Sc>
Scene half_lit_box(int sheet, int floor, Mats<typename Scene::Spectral> mats = materials<typename Scene::Spectral>()) {
    using S = typename Scene::Spectral;
    Shapes shapes;
    shapes.report_uv = true;
    std::vector<QuadLight<S>> lights;
    auto wall = [&](Vec3 corner, Vec3 eu, Vec3 ev, bool upper, int material) {  // normal cross(eu, ev) inward
        if (upper) {
            shapes.quads.push_back({corner, eu, ev, {-1, int(lights.size()), -1, -1}});
            lights.push_back({corner, eu, ev, constant_coefficient<S>(1.f)});
        } else {
            shapes.quads.push_back({corner, eu, ev, {material, -1, -1, -1}});
        }
    };
    for (const bool upper : {true, false}) {
        const float y0 = upper ? 0.f : -1.f;
        wall(Vec3(-1.f, y0, -1.f), Vec3(0.f, 1.f, 0.f), Vec3(0.f, 0.f, 2.f), upper, kBlack);  // x = -1
        wall(Vec3(1.f, y0, -1.f), Vec3(0.f, 0.f, 2.f), Vec3(0.f, 1.f, 0.f), upper, kBlack);   // x = +1
        wall(Vec3(-1.f, y0, -1.f), Vec3(2.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f), upper, kBlack);  // z = -1
        wall(Vec3(-1.f, y0, 1.f), Vec3(0.f, 1.f, 0.f), Vec3(2.f, 0.f, 0.f), upper, kBlack);   // z = +1
    }
    wall(Vec3(-1.f, 1.f, -1.f), Vec3(2.f, 0.f, 0.f), Vec3(0.f, 0.f, 2.f), true, -1);      // top
    wall(Vec3(-1.f, -1.f, -1.f), Vec3(0.f, 0.f, 2.f), Vec3(2.f, 0.f, 0.f), false, floor);  // floor
    // The sheet: u along z, v along x.
    shapes.quads.push_back({Vec3(-1.f, 0.f, -1.f), Vec3(0.f, 0.f, 2.f), Vec3(2.f, 0.f, 0.f), {sheet, -1, -1, -1}});
    return Scene(shapes, {}, std::move(mats), Ls<S>(LightSelection::Uniform, 3.f, std::move(lights), {}), -1);
}

/// A cube of medium `medium` (of albedo 1) whose boundary is a thin dielectric sheet, over an
/// alpha-masked white floor, under a uniform sky of radiance 1. Nothing absorbs: L = 1. Sc's
/// medium: sigma_s 2, g 0.5, majorant twice the extinction.
template <class Scene = Sc>
Scene glass_furnace(SceneMedium<typename Scene::MediumType, typename Scene::MajorantType, HenyeyGreensteinPhase> medium =
                        grey_scenes::medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.f, 2.f, 0.5f)) {
    using S = typename Scene::Spectral;
    Shapes shapes;
    shapes.report_uv = true;
    shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {kThin, -1, 0, -1}});
    shapes.quads.push_back({Vec3(-3.f, -1.2f, 3.f), Vec3(6.f, 0.f, 0.f), Vec3(0.f, 0.f, -6.f), {kWhiteMasked, -1, -1, -1}});
    const Ls<S> sky(LightSelection::Uniform, 4.f, {}, {EnvironmentLight<S>{constant_coefficient<S>(1.f)}});
    return Scene(shapes, {std::move(medium)}, materials<S>(), sky, 0);
}

/// What the camera at `o` sees of the rough dielectric sheet across half_lit_box looking toward
/// its centre: the integral of its value over the upper hemisphere, where the walls emit 1.
inline double rough_sheet_radiance(const Vec3& o) {
    ShadingPoint sp;
    sp.ng = sp.ns = Vec3(0.f, 1.f, 0.f);
    return hemisphere_integral<Mono>(RoughDielectricBsdf<Mono>(kEta, kRoughAlpha), sp, glm::normalize(-o), Vec3(0.f, 1.f, 0.f));
}

/// cube_over_floor's scene behind glass: its scattering cube (sigma_a 0.3, sigma_s 1.2, g 0.6)
/// bounded by material `boundary` (kThin: a thin dielectric, whose null lobe every path through
/// the cube's sides takes or not; kRough: a rough dielectric, which refracts into the medium, of
/// index 1.33 and alpha 0.5, whose wider cone of escape keeps rare the paths that no strategy
/// but one draws often) over
/// an alpha-masked floor (albedo 0.6 behind a uv checkerboard opacity of 0.25 and 0.75, black
/// below), under cube_over_floor's lamp, or with `lamp_inside` a smaller one inside the cube at
/// y = 0.6 (facing down, in the medium): each BDPT strategy alone and the pdf symmetry there.
inline Sc glass_cube_under_lamp(int boundary, bool lamp_inside = false) {
    using S = Mono;
    Shapes shapes;
    shapes.report_uv = true;
    shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {boundary, -1, 0, -1}});
    shapes.quads.push_back({Vec3(-3.f, -1.05f, 3.f), Vec3(6.f, 0.f, 0.f), Vec3(0.f, 0.f, -6.f), {kMasked, -1, -1, -1}});
    const QuadLight<S> lamp = lamp_inside ? QuadLight<S>{Vec3(-0.3f, 0.6f, -0.3f), Vec3(0.6f, 0.f, 0.f), Vec3(0.f, 0.f, 0.6f),
                                                         constant_coefficient<S>(12.f)}
                                          : QuadLight<S>{Vec3(-0.6f, 2.6f, -0.6f), Vec3(1.2f, 0.f, 0.f), Vec3(0.f, 0.f, 1.2f),
                                                         constant_coefficient<S>(12.f)};
    const int around = lamp_inside ? 0 : -1;  // the lamp's media: the cube's inside it
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, around, around}});
    return Sc(shapes, {grey_scenes::medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.3f, 1.2f, 0.6f)},
              materials<S>(constant_coefficient<S>(0.45f), 0.6f, 1.33f, 0.5f),
                 Ls<S>(LightSelection::Power, 4.f, {lamp}, {}), -1);
}

/// Runs the closed forms for every estimator `for_each` hands its check, n samples a case, within
/// k standard errors (the furnace: n_furnace samples):
/// - thin dielectric sheet, seen from above at incidence cosine c: R'(c); from below: T' = 1 - R'
///   (the upper walls emit 1, the lower half is black);
/// - the floor's centre under the filter (w = 0.45, P = 0.6): rho w F = 0.5 x 0.45 x 0.55413;
/// - the alpha-masked sheet from above over a black lower half: L = 0.6 alpha(uv), 0.15 and 0.45
///   on neighbouring squares;
/// - the glass furnace from inside its medium, in random directions: L = 1;
/// - the rough dielectric sheet (eta 1.5 below it, alpha 0.3) seen from above and from below: the
///   integral of its value over the upper hemisphere (the walls there emit 1, those below are
///   black), by quadrature of eval (itself checked against its samples in test_bsdf.cpp).
template <class ForEach>
void check_null_lobes(ForEach for_each, int n, int n_furnace, double k) {
    const Sc thin = half_lit_box(kThin, kBlack), filter = half_lit_box(kFilter, kFloor),
             masked = half_lit_box(kMasked, kBlack), furnace = glass_furnace(), rough = half_lit_box(kRough, kBlack);
    const double rough_above = rough_sheet_radiance(Vec3(0.1f, 0.6f, 0.2f)),
                 rough_below = rough_sheet_radiance(Vec3(0.1f, -0.6f, 0.2f));
    auto check = [&](const auto& est, const Sc& sc, double expected, int samples, std::uint64_t seed, auto make_ray) {
        const Stat s = grey_scenes::estimate(est, sc, samples, seed, make_ray);
        CAPTURE(expected);
        CAPTURE(s.mean);
        CAPTURE(s.se());
        CHECK(std::abs(s.mean - expected) <= k * s.se() + 1e-6);
    };
    auto toward = [](Vec3 o, Vec3 target) { return [=](Pcg32&) { return Ray{o, glm::normalize(target - o)}; }; };
    for_each([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        for (const float side : {1.f, -1.f}) {
            const Vec3 o(0.1f, 0.6f * side, 0.2f);
            const double c = 0.6 / double(glm::length(o)), r = thin_reflectance(c);
            check(est, thin, side > 0.f ? r : 1.0 - r, n, 51, toward(o, Vec3(0.f)));
            check(est, rough, side > 0.f ? rough_above : rough_below, n, 59, toward(o, Vec3(0.f)));
        }
        check(est, filter, kFloorAlbedo * 0.45 * floor_to_sheet(), n, 53,
              toward(Vec3(0.1f, -0.4f, 0.2f), Vec3(0.f, -1.f, 0.f)));
        for (const float x : {-0.5f, 0.5f}) {  // v = (x + 1) / 2: squares (0, 0) and (0, 1)
            const double alpha = x < 0.f ? 0.25 : 0.75;
            check(est, masked, kSheetAlbedo * alpha, n, 55, toward(Vec3(0.1f, 0.6f, 0.2f), Vec3(x, 0.f, -0.5f)));
        }
        check(est, furnace, 1.0, n_furnace, 57, [](Pcg32& rng) {
            return Ray{Vec3(0.2f, -0.5f, 0.1f), uniform_sphere(rng.uniform(), rng.uniform())};
        });
    });
}

/// A null lobe that breaks PartlyNullBsdf's rules (a probability that is NaN or outside [0, 1], a
/// weight that is not finite or is negative, a weight with probability 0) stops the path with
/// Status::InvalidInput and a finite value, never a NaN: where the camera's path meets it (the
/// filter seen from above), every sample; where a shadow ray crosses it (the floor under it, for
/// the estimators that sample lights), some.
template <class ForEach>
void check_bad_null_lobes(ForEach for_each) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<std::pair<float, float>> bad{{0.45f, nan}, {0.45f, 1.5f}, {0.45f, -0.1f}, {kInf, 0.6f},
                                                   {-0.2f, 0.6f}, {0.45f, 0.f}};
    for_each([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        for (const std::pair<float, float>& lobe : bad) {
            const float w = lobe.first, p = lobe.second;  // not a structured binding: CAPTURE's lambda takes them
            CAPTURE(w);
            CAPTURE(p);
            const Sc sc = half_lit_box(kFilter, kFloor, materials<Mono>(constant_coefficient<Mono>(w), p));
            Pcg32 rng(7, 7);
            LookupCount counter;
            int refused_above = 0, refused_below = 0;
            for (int i = 0; i < 64; ++i) {
                for (const float y : {0.6f, -0.4f}) {
                    const Vec3 o(0.1f, y, 0.2f);
                    const auto r = est.radiance(sc, Ray{o, glm::normalize(Vec3(0.f, -1.f, 0.f) - o)}, {}, rng, counter);
                    CHECK(std::isfinite(r.value[0]));
                    if (r.status == Status::InvalidInput) ++(y > 0.f ? refused_above : refused_below);
                    else CHECK(r.status == Status::Ok);
                }
            }
            CHECK(refused_above == 64);
            CHECK(refused_below > 0);
        }
    });
}

}  // namespace nsp_test::null_lobe_scenes
