// tests/test_spectral_surface_emission.cpp: chromatic emissive media in SpectralPathEstimator over
// a SurfaceScene (THEORY 5.7 with 5.3 and 5.8), every channel policy and strategy, against
// closed forms per channel: a Lambertian floor of chromatic albedo under an emitting absorbing
// sphere of chromatic absorption and emission (with a second emitting medium no path reaches,
// which takes part of volume NEE's samples), and white walls around two nested chromatic emitting
// media with the same L_e (L_c = L_e,c in either medium).
#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "host/shapes.hpp"
#include "spectral.hpp"
#include "surfaces.hpp"

namespace {

using namespace nsp_test;
using nsp_host::Shapes;
using S = Rgb;
using Spec = S::Spectrum;
using EM = Emissive<HomogeneousMedium<S>>;
using Mats = Materials<S, LambertianBsdf<S>, MirrorBsdf<S>>;
using Ls = LightSampler<S, QuadLight<S>, EnvironmentLight<S>>;
template <class E>
using SceneFor = SurfaceScene<Shapes, EM, MajorantFor<typename E::Channels, EM>, HenyeyGreensteinPhase, Mats, Ls>;

// k = 5 standard errors per channel, estimated from the samples, with fixed seeds: deterministic.
constexpr double kSigmas = 5.0;

/// The channel policies' strategies, and equiangular MIS beside the emission's techniques.
using Estimators = decltype(std::tuple_cat(
    SpectralEstimatorsWith<absorption::Weight>{},
    std::tuple<SpectralPathEstimator<channels::SpectralMis, strategy::EquiangularMis, mis::Balance>>{}));

/// A quad light of radiance 0 that no surface shows: an equiangular target.
QuadLight<S> dark_lamp() {
    return {Vec3(-0.3f, 0.2f, -0.3f), Vec3(0.6f, 0.f, 0.f), Vec3(0.f, 0.f, 0.6f), Spec::Zero()};
}

/// A homogeneous medium over `box` emitting le_c everywhere in it, under estimator E's majorant
/// kind: a grey one 1.5 times the largest extinction, or the per-channel extinction bound.
template <class E>
SceneMedium<EM, MajorantFor<typename E::Channels, EM>, HenyeyGreensteinPhase> emitting(Box box, S::Coefficient sigma_a,
                                                                                       S::Coefficient sigma_s,
                                                                                       S::Coefficient le, float g) {
    using Maj = MajorantFor<typename E::Channels, EM>;
    const HomogeneousMedium<S> base(box, sigma_a, sigma_s);
    const EM m(base, EmissionGrid(box, {2, 2, 2}, std::vector<float>(8, 1.f)), le, {4, 4, 4});
    if constexpr (std::is_same_v<Maj, GlobalMajorant<EM>>) return {m, Maj(m, 1.5f * m.max_extinction() + 0.2f), HenyeyGreensteinPhase(g)};
    else return {m, Maj(m), HenyeyGreensteinPhase(g)};
}

template <class E, class Sc, class Make>
void check_against(const E& est, const Sc& sc, int n, std::uint64_t seed, Make make_ray, const Spec& expected) {
    RadianceStats<S> out;
    Pcg32 rng(seed, 13);
    LookupCount counter;
    for (int i = 0; i < n; ++i) {
        const auto r = est.radiance(sc, make_ray(rng), {}, rng, counter);
        out.not_ok += r.status != Status::Ok;
        out.stat.add(Spec(r.value - expected));
    }
    CHECK(out.not_ok == 0);
    for (std::size_t ch = 0; ch < out.stat.ch.size(); ++ch) {
        const Stat& c = out.stat.ch[ch];
        CAPTURE(ch);
        CAPTURE(c.mean);
        CAPTURE(c.se());
        CHECK(std::abs(c.mean) <= kSigmas * c.se());
    }
}

TEST_CASE_TEMPLATE_DEFINE("spectral surface emission: a floor under an emitting sphere, closed form per channel", E,
                          spectral_floor_sphere) {
    // The grey test's scene (tests/test_surface_emission.cpp) per channel: floor albedo rho_c at
    // y = 0 under a sphere of radius R = 1 at height D = 2 (mu_a,c, no scattering, L_e,c), seen at
    // the floor point below its centre: L_c = 2 rho_c L_e,c / D^2 [R^2/2 - 1/k^2 + e^(-kR)(R/k + 1/k^2)],
    // k = 2 mu_a,c. Every NEE distance is >= 1: NEE alone has a finite variance too.
    CAPTURE(spectral_estimator_name<E>());
    const Spec rho(0.8f, 0.5f, 0.3f), le(2.f, 1.f, 0.5f), mu_a(1.5f, 0.6f, 3.f);
    Spec expected;
    for (int c = 0; c < 3; ++c) {
        const double k = 2.0 * mu_a[c];
        expected[c] = float(2.0 * rho[c] * le[c] / 4.0 * (0.5 - 1.0 / (k * k) + std::exp(-k) * (1.0 / k + 1.0 / (k * k))));
    }
    Shapes shapes;
    shapes.quads.push_back({Vec3(-50.f, 0.f, -50.f), Vec3(0.f, 0.f, 100.f), Vec3(100.f, 0.f, 0.f), {0, -1, -1, -1}});
    shapes.spheres.push_back({Vec3(0.f, 2.f, 0.f), 1.f, {-1, -1, 0, -1}});
    const Box below{Vec3(-2.f, -3.f, -2.f), Vec3(2.f, -1.f, 2.f)};
    shapes.boxes.push_back({below.lo, below.hi, {-1, -1, 1, -1}});
    const SceneFor<E> sc(shapes,
                         {emitting<E>(Box{Vec3(-1.f, 1.f, -1.f), Vec3(1.f, 3.f, 1.f)}, mu_a, Spec::Zero(), le, 0.f),
                          emitting<E>(below, Spec::Constant(1.f), Spec::Zero(), Spec::Constant(1.f), 0.f)},
                         Mats({LambertianBsdf<S>(rho)}, {}), Ls(LightSelection::Uniform, 1.f, {dark_lamp()}, {}), -1);
    const Vec3 eye(3.f, 0.5f, 0.f);
    check_against(E{}, sc, 12000, 51, [&](Pcg32&) { return Ray{eye, glm::normalize(-eye)}; }, expected);
}
TEST_CASE_TEMPLATE_APPLY(spectral_floor_sphere, Estimators);

TEST_CASE_TEMPLATE_DEFINE("spectral surface emission: white walls around two nested emitting media, L_c = L_e,c", E,
                          spectral_emissive_furnace) {
    // White Lambertian walls (and two mirrors of reflectance 1) close the box [-1, 1]^3 around
    // medium 0, which holds a sphere of radius 0.6 of medium 1 behind a null interface; both emit
    // L_e,c with their own chromatic coefficients, so L = L_e solves the transport equation. NEE
    // alone is left out: from vertices inside the emitter its volume NEE has an infinite variance
    // (tests/test_surface_emission.cpp), so its standard error says nothing.
    if constexpr (!std::is_same_v<typename E::Strategy, strategy::NextEvent>) {
        CAPTURE(spectral_estimator_name<E>());
        const Spec le(0.7f, 0.4f, 1.1f);
        Shapes shapes;
        for (const CubeFace& f : inward_cube_faces()) {
            const bool mirror = shapes.quads.size() == 0 || shapes.quads.size() == 3;
            shapes.quads.push_back({f.corner, f.u, f.v, {mirror ? 1 : 0, -1, -1, 0}});
        }
        shapes.spheres.push_back({Vec3(0.f), 0.6f, {-1, -1, 1, 0}});
        SceneFor<E> sc(shapes,
                       {emitting<E>(Box{Vec3(-1.f), Vec3(1.f)}, chroma<S>(1.f, 0.5f, 1.5f), chroma<S>(1.5f, 1.f, 0.8f), le, 0.3f),
                        emitting<E>(Box{Vec3(-0.6f), Vec3(0.6f)}, chroma<S>(0.8f, 1.2f, 0.6f), chroma<S>(0.7f, 0.4f, 1.f), le,
                                    -0.4f)},
                       Mats({LambertianBsdf<S>(Spec::Ones())}, {MirrorBsdf<S>(Spec::Ones())}),
                       Ls(LightSelection::Uniform, 2.f, {dark_lamp()}, {}), 0);
        check_against(E{}, sc, 8000, 61, [](Pcg32& rng) {
            return Ray{Vec3(0.1f, -0.2f, 0.8f), uniform_sphere(rng.uniform(), rng.uniform())};
        }, le);
        sc.camera_medium = 1;
        check_against(E{}, sc, 8000, 62, [](Pcg32& rng) {
            return Ray{Vec3(0.1f, 0.1f, -0.2f), uniform_sphere(rng.uniform(), rng.uniform())};
        }, le);
        if constexpr (E::Strategy::combines) {
            // Expected counts (THEORY 5.9): the segment technique on 30% of the pieces, NEE toward
            // the lights and the volume's light sampling at half the vertices.
            EstimatorOptions few;
            few.emission_segment_count = 0.3f;
            few.nee_count = 0.5f;
            check_against(E{few}, sc, 8000, 63, [](Pcg32& rng) {
                return Ray{Vec3(0.1f, 0.1f, -0.2f), uniform_sphere(rng.uniform(), rng.uniform())};
            }, le);
        }
    }
}
TEST_CASE_TEMPLATE_APPLY(spectral_emissive_furnace, Estimators);

}  // namespace
