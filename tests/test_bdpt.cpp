// tests/test_bdpt.cpp: nsp::BdptEstimator (THEORY 5.5): the strategy weights of one path sum to 1
// and equal the brute-force balance and power heuristics of the strategies' path pdfs (light
// tracing, t = 1, included); the strategies' pdfs are their true densities (a symmetry that any
// misplaced null-chain factor breaks, and that directional MIS's pseudo-pdfs do break); each
// (s, t) strategy alone, t = 1 too, is unbiased; the combined estimator against closed forms (the
// furnace of six emitting walls, with and without light tracing, nested absorbing media behind
// null interfaces, a mirror behind an absorbing slab) and against PathEstimator (a scattering
// cube over a floor under a lamp and a sky, and with light tracing pixel by pixel); finite output
// at extreme densities and light sizes; PinholeCamera's rays, image coordinates and density; and
// under a control (THEORY 5.10), the furnaces and the per-strategy checks on a heterogeneous medium.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"
#include "control_scenes.hpp"
#include "grey_surface_scenes.hpp"
#include "null_lobe_scenes.hpp"
#include "shading_scenes.hpp"

namespace {

using namespace nsp_test;
using namespace nsp_test::grey_scenes;

// k = 5 standard errors, estimated from the samples, with fixed seeds: deterministic.
constexpr double kSigmas = 5.0;

/// The image's average over uniform (u, v) through `camera` with light tracing: each sample's
/// return plus the splats of its light subpath (wherever they land), n samples.
template <class E, class Scene>
Stat image_average(const E& est, const Scene& sc, const PinholeCamera& camera, int n, std::uint64_t seed) {
    Pcg32 rng(seed, 2);
    LookupCount counter;
    Stat s;
    for (int i = 0; i < n; ++i) {
        double x = 0.0;
        auto splat = [&](float, float, const Spectrum& value) { x += double(value[0]); };
        const auto r = est.sample(sc, camera, rng.uniform(), rng.uniform(), {}, rng, counter, splat);
        REQUIRE(r.status == Status::Ok);
        s.add(x + double(r.value[0]));
    }
    return s;
}

/// Runs `check(estimator, name)` for both MIS policies under the balance and power heuristics.
template <int D = 32, class F>
void for_each_bdpt(F check, EstimatorOptions opts = BdptEstimator<>::default_options()) {
    check(BdptEstimator<bdpt::NullScattering, mis::Balance, absorption::Weight, D>(opts), "null-mis balance");
    check(BdptEstimator<bdpt::NullScattering, mis::Power, absorption::Event, D>(opts), "null-mis power event");
    check(BdptEstimator<bdpt::Directional, mis::Balance, absorption::Weight, D>(opts), "directional balance");
}

using Pdfs = bdpt::PathPdfs<16>;

/// Strategy s's pdf of the path, as a plain product (THEORY 5.5): x_0..x_{s-1} from the light
/// (x_0 by NEE when s = 1, by emission when s >= 2), x_s..x_{k-1} from the camera; 0 where a
/// connection would end at a delta vertex.
double brute_pdf(const Pdfs& p, int s) {
    if (s == Pdfs::kEquiangular) {  // x_0 by NEE from x_1, x_1 by equiangular sampling from x_2
        if (p.k < 2 || !p.connectible[1]) return 0.0;
        double v = double(p.eq_nee) * double(p.eq);
        for (int i = 2; i < p.k; ++i) v *= p.from_camera[i];
        return v;
    }
    if (s == Pdfs::kSegment) {  // x_0 by the segment technique from x_1, x_1.. from the camera
        double v = double(p.seg);
        for (int i = 1; i < p.k; ++i) v *= p.from_camera[i];
        return v;
    }
    if (s == p.k) {  // t = 1: x_0..x_{k-1} from the light, x_{k-1} connected to the camera
        if (!p.light_tracing || p.k < 2 || !p.connectible[p.k - 1]) return 0.0;
    } else {
        if (s == 1 && !p.connectible[1]) return 0.0;
        if (s >= 2 && !(p.connectible[s - 1] && p.connectible[s])) return 0.0;
    }
    double v = s == 0 ? p.from_camera[0] : s == 1 ? p.nee : p.emit;
    for (int i = 1; i < s; ++i) v *= p.from_light[i];
    for (int i = std::max(s, 1); i < p.k; ++i) v *= p.from_camera[i];
    return v;
}

TEST_CASE("bdpt: the strategy weights of a path are the heuristics of its strategies' pdfs and sum to 1") {
    // Random densities over 12 orders of magnitude, delta vertices and zero densities (a point
    // light: from_camera[0] = 0; a light at infinity: emit = 0), paths of 2 to 15 vertices, with
    // and without light tracing (t = 1), with and without the equiangular strategy.
    Pcg32 rng(17, 3);
    const mis::Balance balance;
    const mis::Power power(2.f);
    for (int trial = 0; trial < 4000; ++trial) {
        Pdfs p;
        p.k = 1 + int(rng.uniform() * 14.f);
        auto density = [&] { return std::pow(10.f, 12.f * rng.uniform() - 6.f); };
        for (int i = 0; i < p.k; ++i) {
            p.from_light[i] = density();
            p.from_camera[i] = density();
            p.connectible[i] = rng.uniform() > 0.15f;
        }
        p.connectible[0] = true;
        p.light_tracing = rng.uniform() < 0.5f;
        if (!p.light_tracing) p.from_camera[p.k - 1] = 1.f;
        p.nee = density();
        p.emit = rng.uniform() < 0.2f ? 0.f : density();
        if (rng.uniform() < 0.2f) p.from_camera[0] = 0.f;
        p.eq = rng.uniform() < 0.3f ? 0.f : density();
        p.eq_nee = rng.uniform() < 0.2f ? 0.f : density();
        p.seg = rng.uniform() < 0.3f ? 0.f : density();
        const int count = p.light_tracing && p.k >= 2 ? p.k + 1 : p.k;
        CHECK(bdpt::strategy_count(p) == count);
        std::vector<int> strategies;
        for (int s = 0; s < count; ++s) strategies.push_back(s);
        strategies.push_back(Pdfs::kEquiangular);
        strategies.push_back(Pdfs::kSegment);
        double total = 0.0, total2 = 0.0;
        for (const int s : strategies) {
            total += brute_pdf(p, s);
            total2 += brute_pdf(p, s) * brute_pdf(p, s);
        }
        float sum_b = 0.f, sum_p = 0.f;
        for (const int s : strategies) {
            const float wb = bdpt::strategy_weight(balance, p, s), wp = bdpt::strategy_weight(power, p, s);
            CAPTURE(trial);
            CAPTURE(s);
            CHECK(wb == doctest::Approx(total > 0.0 ? brute_pdf(p, s) / total : 0.0).epsilon(1e-4));
            CHECK(wp == doctest::Approx(total2 > 0.0 ? brute_pdf(p, s) * brute_pdf(p, s) / total2 : 0.0).epsilon(1e-4));
            sum_b += wb;
            sum_p += wp;
        }
        if (total > 0.0) {
            CHECK(sum_b == doctest::Approx(1.f).epsilon(1e-5));
            CHECK(sum_p == doctest::Approx(1.f).epsilon(1e-5));
        }
    }
}

TEST_CASE("bdpt: an overflowed (infinite) density takes the weight; NaN gives NaN") {
    // Path x_0..x_3 (k = 3), strategies s = 0, 1, 2: from_light[1] = inf, so the strategy that
    // draws x_1 from the light side (s = 2) takes the whole weight; both sides of x_1 infinite: a
    // tie among all; a NaN density: NaN, which the estimator reports as Status::NonFinite.
    const mis::Balance h;
    Pdfs p;
    p.k = 3;
    for (int i = 0; i < 3; ++i) {
        p.from_light[i] = 1.f;
        p.from_camera[i] = 1.f;
        p.connectible[i] = true;
    }
    p.nee = p.emit = 1.f;
    p.from_light[1] = kInf;
    CHECK(bdpt::strategy_weight(h, p, 2) == 1.f);
    CHECK(bdpt::strategy_weight(h, p, 0) == 0.f);
    CHECK(bdpt::strategy_weight(h, p, 1) == 0.f);
    p.from_camera[1] = kInf;  // both infinite: a tie between the two sides of x_1
    const float w0 = bdpt::strategy_weight(h, p, 0), w1 = bdpt::strategy_weight(h, p, 1), w2 = bdpt::strategy_weight(h, p, 2);
    CHECK(w0 + w1 + w2 == doctest::Approx(1.f));
    CHECK(w2 > 0.f);
    p.from_camera[1] = std::numeric_limits<float>::quiet_NaN();
    CHECK(std::isnan(bdpt::strategy_weight(h, p, 0)));
}

TEST_CASE("bdpt: the furnace of six emitting walls around a medium of albedo 1 (L = 2), camera inside" * doctest::test_suite("converge")) {
    // As the surface estimators' furnace: L = Le / (1 - 0.5) = 2 whatever the phase function,
    // the density and which walls are mirrors. Subpaths of up to 64 vertices: the walls halve the
    // throughput about every third vertex, so the paths cut off carry ~1e-6 of L.
    for (const auto& mirrors : {std::vector<int>{}, std::vector<int>{1, 4}}) {
        Shapes shapes;
        std::vector<QuadLight<S>> walls;
        box_walls(1.f, mirrors, shapes, walls);
        const Sc sc(shapes, {medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.f, 1.5f)}, materials(),
                    Ls(LightSelection::Uniform, 2.f, walls, {}), 0);
        EstimatorOptions opts;
        opts.max_depth = 64;
        for_each_bdpt<64>(
            [&](const auto& est, const char* name) {
                CAPTURE(std::string(name));
                CAPTURE(mirrors.size());
                const Stat s = estimate(est, sc, 6000, 11 + mirrors.size(), [](Pcg32& rng) {
                    return Ray{Vec3(0.1f, -0.2f, 0.3f), uniform_sphere(rng.uniform(), rng.uniform())};
                });
                CAPTURE(s.mean);
                CAPTURE(s.se());
                CHECK(std::abs(s.mean - 2.0) <= kSigmas * s.se());
            },
            opts);
    }
}

TEST_CASE("bdpt: an unusable camera ray (not unit length, NaN, infinite) gives InvalidInput and no estimate") {
    const Sc sc = cube_over_floor(true);
    const PinholeCamera camera = cube_pinhole();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<std::pair<const char*, Ray>> bad{
        {"|d| = 2", Ray{Vec3(0.f, 0.3f, -4.5f), Vec3(0.f, 0.f, 2.f)}},
        {"zero direction", Ray{Vec3(0.f, 0.3f, -4.5f), Vec3(0.f)}},
        {"NaN origin", Ray{Vec3(nan, 0.3f, -4.5f), Vec3(0.f, 0.f, 1.f)}},
        {"infinite direction", Ray{Vec3(0.f, 0.3f, -4.5f), Vec3(0.f, kInf, 0.f)}}};
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        Pcg32 rng(21, 1);
        LookupCount lookups;
        for (const auto& entry : bad) {  // no structured binding: clang cannot capture one in CAPTURE's lambda
            CAPTURE(std::string(entry.first));
            const auto r = est.radiance(sc, entry.second, {}, rng, lookups);
            CHECK(r.status == Status::InvalidInput);
            CHECK(r.value[0] == 0.f);
        }
        // sample() at image coordinates whose ray is NaN: nothing splatted either.
        int splats = 0;
        const auto r = est.sample(sc, camera, nan, 0.5f, {}, rng, lookups, [&](float, float, const auto&) { ++splats; });
        CHECK(r.status == Status::InvalidInput);
        CHECK(r.value[0] == 0.f);
        CHECK(splats == 0);
        CHECK(lookups.count() == 0);
    });
}

TEST_CASE("bdpt: nested media behind null interfaces, the camera outside and inside") {
    // L = exp(-0.5 - 1) from z = -3 toward the light; exp(-0.75) from the sphere's centre.
    Sc sc = nested_media();
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        const Stat outside = estimate(est, sc, 4000, 3, [](Pcg32&) { return Ray{Vec3(0.f, 0.f, -3.f), Vec3(0.f, 0.f, 1.f)}; });
        CAPTURE(outside.mean);
        CHECK(std::abs(outside.mean - std::exp(-1.5)) <= kSigmas * outside.se() + 1e-6);
        sc.camera_medium = 1;
        const Stat inside = estimate(est, sc, 4000, 4, [](Pcg32&) { return Ray{Vec3(0.f), Vec3(0.f, 0.f, 1.f)}; });
        sc.camera_medium = -1;
        CAPTURE(inside.mean);
        CHECK(std::abs(inside.mean - std::exp(-0.75)) <= kSigmas * inside.se() + 1e-6);
    });
}

TEST_CASE("bdpt: a surface that keeps the medium (kSameMedium), a null interface and an opaque ball") {
    // As the path tracer's test: exp(-1) from z = -3, exp(-0.5) from the sphere's centre.
    Sc sc = sphere_keeping_medium();
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        const Stat outside = estimate(est, sc, 4000, 3, [](Pcg32&) { return Ray{Vec3(0.f, 0.f, -3.f), Vec3(0.f, 0.f, 1.f)}; });
        CAPTURE(outside.mean);
        CHECK(std::abs(outside.mean - std::exp(-1.0)) <= kSigmas * outside.se() + 1e-6);
        sc.camera_medium = 0;
        const Stat inside = estimate(est, sc, 4000, 4, [](Pcg32&) { return Ray{Vec3(0.f), Vec3(0.f, 0.f, 1.f)}; });
        sc.camera_medium = -1;
        CAPTURE(inside.mean);
        CHECK(std::abs(inside.mean - std::exp(-0.5)) <= kSigmas * inside.se() + 1e-6);
    });
    // The opaque ball named or kept: the same paths, the same estimate to the last bit.
    const Sc named = cube_with_ball(false), kept = cube_with_ball(true);
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        const Stat a = estimate(est, named, 1000, 23, cube_camera);
        const Stat b = estimate(est, kept, 1000, 23, cube_camera);
        CHECK(a.mean > 0.0);
        CHECK(a.mean == b.mean);
        CHECK(a.se() == b.se());
    });
    // A light subpath's first medium: inside the kept sphere, medium 0 beyond it; outside a sphere
    // that keeps its outside and holds medium 0 inside, the box's medium 0 behind the point; with
    // nothing but kept surfaces on the line, vacuum.
    CHECK(bdpt::light_start_medium(sc, Vec3(0.f), Vec3(0.f, 0.f, 1.f)) == 0);
    Shapes shapes;
    shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {-1, -1, 0, -1}});
    shapes.spheres.push_back({Vec3(0.f), 0.5f, {-1, -1, 0, kSameMedium}});
    const Sc holder(shapes, {medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.5f, 0.f)}, materials(),
                    Ls(LightSelection::Uniform, 3.f, {}, {EnvironmentLight<S>{Spectrum::Constant(1.f)}}), -1);
    CHECK(bdpt::light_start_medium(holder, Vec3(0.f, 0.f, -0.75f), Vec3(0.f, 0.f, 1.f)) == 0);
    Shapes loose;
    loose.spheres.push_back({Vec3(0.f), 0.5f, {-1, -1, kSameMedium, kSameMedium}});
    const Sc open(loose, {}, materials(), Ls(LightSelection::Uniform, 3.f, {}, {EnvironmentLight<S>{Spectrum::Constant(1.f)}}),
                  -1);
    CHECK(bdpt::light_start_medium(open, Vec3(0.f), Vec3(1.f, 0.f, 0.f)) == -1);
}

TEST_CASE("bdpt: a BSDF that sees the hit (a uv checkerboard), one that takes a 3D sample (a diffuse sheet)") {
    // The path tracer's closed forms (shading_scenes.hpp), every strategy's connections
    // evaluating the BSDFs at the stored vertices' hits.
    shading_scenes::check_shading_bsdfs([](auto check) { for_each_bdpt(check); }, 2000, kSigmas);
}

TEST_CASE("bdpt: partly null BSDFs (thin dielectric, filter, alpha mask, a glass furnace)") {
    // The path tracer's closed forms (null_lobe_scenes.hpp): subpaths from both sides cross the
    // null lobes, connections cross them with their weights.
    null_lobe_scenes::check_null_lobes([](auto check) { for_each_bdpt(check); }, 2000, 6000, kSigmas);
}

TEST_CASE("bdpt: a null lobe that breaks its rules gives Status::InvalidInput, never a NaN") {
    null_lobe_scenes::check_bad_null_lobes([](auto check) { for_each_bdpt(check); });
}

TEST_CASE("bdpt: a light that sees its hit (textured quad lights around a Lambertian floor)") {
    // Light subpaths start with the texture at the points they draw; s = 0 sees the hit.
    shading_scenes::check_textured_lights([](auto check) { for_each_bdpt(check); }, 2000, kSigmas);
}

TEST_CASE("bdpt: lights sampled by their texture: with light tracing, the image agrees with PathEstimator") {
    // shading_scenes::textured_box's walls are sampled by their texture, and their densities
    // read where they are asked (SurfacePdfLight): at a hit, at NEE's point, at a light subpath's
    // start. Light tracing and the light subpaths' strategies weigh against NEE and hits with
    // them, so a density that lost its uv unbalances the weights. No closed form for an image:
    // the average through a camera looking down at the floor, against null-scattering uni + NEE
    // MIS, within 5 combined standard errors (0.4M and 0.2M samples, about 3 s: 5 SE is 1% of
    // the image). A hit's density that lost its uv fails the closed forms above; a light
    // subpath's or NEE point's density read at uv (0, 0) moves this image only 0.3% (the
    // strategies that read it carry little weight here), which this test does not separate.
    const auto sc = shading_scenes::textured_box();
    const PinholeCamera camera(Vec3(0.3f, 0.2f, 0.1f), Vec3(0.3f, -1.f, 0.1f), Vec3(0.f, 0.f, 1.f), 100.f, 1.f);
    const Stat ref = estimate(PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, sc, 400000, 61,
                              [&](Pcg32& rng) { return camera.ray(rng.uniform(), rng.uniform()); });
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        const Stat s = image_average(est, sc, camera, 200000, 62);
        CAPTURE(s.mean);
        CAPTURE(s.se());
        CAPTURE(ref.mean);
        CAPTURE(ref.se());
        CHECK(std::abs(s.mean - ref.mean) <= kSigmas * std::sqrt(s.se() * s.se() + ref.se() * ref.se()));
    });
}

TEST_CASE("bdpt: a mirror behind an absorbing slab reflects the light behind the camera") {
    // L = 0.5 exp(-0.4 x 2) Le: a delta vertex, reached by the camera subpath alone.
    Shapes shapes;
    shapes.boxes.push_back({Vec3(-5.f, -5.f, 0.5f), Vec3(5.f, 5.f, 1.5f), {-1, -1, 0, -1}});
    shapes.quads.push_back({Vec3(-5.f, -5.f, 2.f), Vec3(0.f, 10.f, 0.f), Vec3(10.f, 0.f, 0.f), {1, -1, -1, -1}});
    const QuadLight<S> lamp{Vec3(-5.f, -5.f, -2.f), Vec3(10.f, 0.f, 0.f), Vec3(0.f, 10.f, 0.f), Spectrum::Constant(2.f)};
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, -1, -1}});
    const Sc sc(shapes, {medium(Box{Vec3(-5.f, -5.f, 0.5f), Vec3(5.f, 5.f, 1.5f)}, 0.4f, 0.f)}, materials(),
                Ls(LightSelection::Uniform, 8.f, {lamp}, {}), -1);
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        const Stat s = estimate(est, sc, 4000, 7, [](Pcg32&) { return Ray{Vec3(0.f, 0.f, -1.f), Vec3(0.f, 0.f, 1.f)}; });
        CAPTURE(s.mean);
        CHECK(std::abs(s.mean - 0.5 * 2.0 * std::exp(-0.8)) <= kSigmas * s.se() + 1e-6);
    });
}

/// Every BDPT variant's estimate through cube_camera (10000 samples, seed + 1) against null-
/// scattering uni + NEE MIS's (40000, seed), within 5 combined standard errors (independent).
template <class Scene>
void check_agrees_with_path_estimator(const Scene& sc, std::uint64_t seed) {
    const Stat ref = estimate(PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, sc, 40000, seed, cube_camera);
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        const Stat s = estimate(est, sc, 10000, seed + 1, cube_camera);
        CAPTURE(s.mean);
        CAPTURE(ref.mean);
        CHECK(std::abs(s.mean - ref.mean) <= kSigmas * std::sqrt(s.se() * s.se() + ref.se() * ref.se()));
    });
}

TEST_CASE("bdpt: agrees with PathEstimator on a scattering cube over a floor, a quad light and a sky") {
    // No closed form: against null-scattering uni + NEE MIS, within 5 combined standard errors
    // (independent estimates). The sky's paths are weighted among s = 0 and s = 1 alone.
    check_agrees_with_path_estimator(cube_over_floor(true), 21);
}

/// What one run of the estimator on the cube over the floor measured per strategy, over the paths
/// whose consecutive real vertices lie at least 0.3 apart (see below): for each strategy (s, t),
/// the unweighted contribution of every sample (0 where the strategy drew no such path), the same
/// over the paths whose x_1 is a medium vertex and x_0 a light's (outside the cube [-1, 1]^3 the
/// tests' media fill), and for each other strategy o of the same path
/// length, p_o / sum_r p_r of the path s drew (0 likewise), and the unweighted contributions of
/// the paths whose x_0 lies inside the cube (an emitting cube's volume sources). The equiangular
/// strategy is (eq, t), t its camera-side vertices as s = 1's; the segment technique (seg, t),
/// as s = 0's.
struct StrategyRecord {
    int eq = 0;   ///< the equiangular strategy's index (PathPdfs::kEquiangular)
    int seg = 0;  ///< the segment technique's (PathPdfs::kSegment)
    std::map<std::pair<int, int>, Stat> alone;
    std::map<std::pair<int, int>, Stat> alone_medium;
    std::map<std::pair<int, int>, Stat> alone_volume;
    std::map<std::pair<int, int>, std::map<int, Stat>> share;

    /// The strategies of the paths of n interior vertices: (s, n + 2 - s), s = 0..n+1, (eq, n + 1)
    /// and (seg, n + 2).
    std::vector<std::pair<int, int>> strategies(int n) const {
        std::vector<std::pair<int, int>> out;
        for (int s = 0; s <= n + 1; ++s) out.emplace_back(s, n + 2 - s);
        out.emplace_back(eq, n + 1);
        out.emplace_back(seg, n + 2);
        return out;
    }
};

/// Samples of the cube's image at uniform (u, v) over the whole image, light tracing included.
template <class E, class Scene>
StrategyRecord record_strategies(const E& est, const Scene& sc, int n_samples, int longest) {
    StrategyRecord rec;
    rec.eq = E::Pdfs::kEquiangular;
    rec.seg = E::Pdfs::kSegment;
    Pcg32 rng(41, 7);
    LookupCount counter;
    const PinholeCamera camera = cube_pinhole();
    std::map<std::pair<int, int>, double> value, value_medium, value_volume;
    std::map<std::pair<int, int>, std::map<int, double>> shares;
    auto far_apart = [](const auto& v) {
        std::vector<Vec3> x{v.x0};
        for (int i = 1; i < v.s; ++i) x.push_back(v.light[i].p);
        for (int j = v.t - 1; j >= 1; --j) x.push_back(v.camera[j].p);
        // x_0 at infinity is a direction: no distance to x_1.
        for (std::size_t i = v.x0_at_infinity ? 2 : 1; i < x.size(); ++i)
            if (glm::length(x[i] - x[i - 1]) < 0.3f) return false;
        return true;
    };
    for (int i = 0; i < n_samples; ++i) {
        value.clear();
        value_medium.clear();
        value_volume.clear();
        shares.clear();
        auto observe = [&](int s, int t, const Spectrum& f, float, const auto& pdfs, const auto& vertices) {
            if (!far_apart(vertices)) return;
            value[{s, t}] += double(f[0]);
            const auto& x1 = vertices.s >= 2 ? vertices.light[1] : vertices.camera[vertices.t - 1];
            const bool x0_on_light = vertices.x0_at_infinity || !Box{Vec3(-1.f), Vec3(1.f)}.contains(vertices.x0);
            if (x1.kind == bdpt::VertexKind::Medium && x0_on_light) value_medium[{s, t}] += double(f[0]);
            if (!x0_on_light) value_volume[{s, t}] += double(f[0]);
            double q[E::Pdfs::kSlots];
            REQUIRE(bdpt::strategy_pdfs(pdfs, q));
            std::vector<int> all;
            for (int o = 0; o < bdpt::strategy_count(pdfs); ++o) all.push_back(o);
            all.push_back(rec.eq);
            all.push_back(rec.seg);
            double sum = 0.0;
            for (const int o : all) sum += q[o];
            // Summed: a strategy may draw several paths in one sample (the collision estimator's
            // every tentative collision; NEE toward the lights and toward the volume), each a sample
            // of its density, so E_s[sum of the shares] is still the integral of p_s p_o / sum p.
            for (const int o : all) shares[{s, t}][o] += q[o] / sum;
        };
        auto splat = [](float, float, const Spectrum&) {};
        const float u = rng.uniform(), v = rng.uniform();
        const auto r = est.sample_observed(sc, camera, u, v, {}, rng, counter, splat, observe);
        REQUIRE(r.status == Status::Ok);
        for (int n = 0; n <= longest; ++n) {
            const auto keys = rec.strategies(n);
            for (const auto& key : keys) {
                rec.alone[key].add(value.count(key) ? value[key] : 0.0);
                rec.alone_medium[key].add(value_medium.count(key) ? value_medium[key] : 0.0);
                rec.alone_volume[key].add(value_volume.count(key) ? value_volume[key] : 0.0);
                const auto it = shares.find(key);
                for (const auto& other : keys) {
                    const int o = other.first;
                    rec.share[key][o].add(it == shares.end() || !it->second.count(o) ? 0.0 : it->second.at(o));
                }
            }
        }
    }
    return rec;
}

/// The largest |E_s[p_o / sum p] - E_o[p_s / sum p]| over pairs of strategies of one path length
/// (n = 0 too: the camera sees x_0), in combined standard errors.
double worst_share_asymmetry(StrategyRecord& rec, int longest) {
    double worst = 0.0;
    for (int n = 0; n <= longest; ++n) {
        const auto keys = rec.strategies(n);
        for (std::size_t i = 0; i < keys.size(); ++i)
            for (std::size_t j = i + 1; j < keys.size(); ++j) {
                const Stat& a = rec.share[keys[i]][keys[j].first];
                const Stat& b = rec.share[keys[j]][keys[i].first];
                const double se = std::sqrt(a.se() * a.se() + b.se() * b.se());
                if (!(se > 0.0)) {  // neither draws the other's paths: both shares are 0
                    CHECK(a.mean == b.mean);
                    continue;
                }
                if (getenv("BDPT_DEBUG"))
                    printf("n=%d s=%d o=%d  E_s[p_o/sum] %.5f  E_o[p_s/sum] %.5f  (%.1f SE)\n", n, keys[i].first,
                           keys[j].first, a.mean, b.mean, std::abs(a.mean - b.mean) / se);
                worst = std::max(worst, std::abs(a.mean - b.mean) / se);
            }
    }
    return worst;
}

/// What the per-strategy tests render with: no roulette (its survival is left out of the weights)
/// and paths of at most 3 interior vertices, the lengths the tests check.
EstimatorOptions strategy_test_options() {
    EstimatorOptions opts;
    opts.russian_roulette = false;
    opts.max_depth = 3;
    return opts;
}

/// The estimate of a strategy alone against `reference`'s over the same paths (kSigmas combined
/// SE) where the strategy draws them (`draws`), else exactly nothing.
void check_alone(const Stat& alone, const Stat& reference, bool draws) {
    CAPTURE(alone.mean);
    CAPTURE(reference.mean);
    if (!draws) {
        CHECK(alone.mean == 0.0);
        return;
    }
    CHECK(alone.mean > 0.0);
    CHECK(std::abs(alone.mean - reference.mean) <= kSigmas * std::hypot(alone.se(), reference.se()));
}

/// The two checks on a record of paths of 0..3 interior vertices (see the test below): every
/// (s, t) alone against NEE's estimate of the same path length, and the pdf symmetry over every
/// pair of strategies, both within 5 combined SE. `hittable`: the lights can be hit (s = 0 draws
/// paths); else s = 0 must contribute exactly nothing. `equiangular`, `segment`: the scene has a
/// point light, an emitting medium, where these strategies draw paths.
void check_strategies_alone_and_symmetric(StrategyRecord& rec, bool hittable = true, bool equiangular = false,
                                          bool segment = false) {
    for (int n = 1; n <= 3; ++n) {
        const Stat& nee = rec.alone[{1, n + 1}];
        for (int s = 0; s <= n + 1; ++s) {
            CAPTURE(n);
            CAPTURE(s);
            check_alone(rec.alone[{s, n + 2 - s}], nee, s != 0 || hittable);
        }
        // The equiangular strategy draws the paths whose x_1 is a medium vertex and x_0 a light's,
        // all of them: its estimate alone against NEE's over those paths (5 combined SE); where it
        // is off (no light with a target), nothing.
        const Stat& eq = rec.alone[{rec.eq, n + 1}];
        CAPTURE(n);
        check_alone(eq, rec.alone_medium[{1, n + 1}], equiangular);
        if (equiangular) CHECK(rec.alone_medium[{rec.eq, n + 1}].mean == eq.mean);
    }
    // The segment technique draws every path whose x_0 lies in an emitting medium: its estimate
    // alone against NEE's over those paths (NEE toward the volume), 5 combined SE; seen from the
    // camera (no interior vertex, n = 0), against the collision estimator's; without emission,
    // nothing.
    for (int n = 0; n <= 3; ++n) {
        const Stat& seg = rec.alone[{rec.seg, n + 2}];
        CAPTURE(n);
        check_alone(seg, n == 0 ? rec.alone_volume[{0, 2}] : rec.alone_volume[{1, n + 1}], segment);
        if (segment) CHECK(rec.alone_volume[{rec.seg, n + 2}].mean == seg.mean);
    }
    CHECK(worst_share_asymmetry(rec, 3) <= kSigmas);
}

TEST_CASE("bdpt: each strategy alone is unbiased, and the strategies' pdfs are the true densities" * doctest::test_suite("converge")) {
    // The cube over the floor under the lamp alone (no sky, no roulette, no delta vertices), paths
    // of n = 1, 2, 3 interior vertices, the image's average over uniform (u, v), light tracing on:
    // every (s, t) with s + t - 2 = n (t = 1 too) draws every such path, so each alone (weight 1)
    // estimates the same radiance: against NEE's (s = 1), 5 combined SE.
    // The pdfs: for any two strategies s, o and true path densities p,
    //     E_s[p_o / sum_r p_r] = integral of p_s p_o / sum_r p_r = E_o[p_s / sum_r p_r],
    // a symmetry that breaks where a strategy's reported pdf is off by a factor that depends on
    // the path (e.g. a null chain's P_n or a medium vertex's mu_bar P_s left out or misplaced);
    // the shares are bounded, so their standard errors mean something: 5 combined SE. Both over
    // the paths whose consecutive real vertices lie at least 0.3 apart, a region of path space that
    // is the same for every strategy: near d = 0 a connection's 1 / d^2 gives a strategy alone
    // infinite variance. Deterministic: fixed seeds.
    const Sc sc = cube_over_floor(false);
    const EstimatorOptions opts = strategy_test_options();
    StrategyRecord rec = record_strategies(BdptEstimator<bdpt::NullScattering, mis::Balance>(opts), sc, 200000, 3);
    check_strategies_alone_and_symmetric(rec);
}

TEST_CASE("bdpt: behind thin or rough glass over an alpha-masked floor: each strategy alone unbiased, the pdfs true densities" *
          doctest::test_suite("converge")) {
    // The test above on the cube behind glass (null_lobe_scenes::glass_cube_under_lamp). Thin
    // glass and the floor's mask are partly null: a path takes their null lobe or makes a vertex,
    // and their probabilities enter every strategy's pdf as null factors; were one left out or
    // misplaced, the strategies alone would disagree and the shares lose their symmetry. Rough
    // glass refracts into the medium. With the lamp inside the cube every path to the camera
    // refracts out of the glass, at a vertex that light tracing (t = 1) reaches from the light's
    // side and s = 0 and NEE from the camera's: the strategies alone agree only if its one BSDF
    // serves both directions (its refraction lobe is symmetric; the radiance form's is not).
    struct Case {
        int boundary;
        bool lamp_inside;
        int samples;
    };
    // Rough glass reflects 2% at normal incidence: under the lamp outside, the camera's paths
    // that reflect off it onto the floor and then hit the lamp (s = 0, n = 2) are 1 in 10^5,
    // hence 8x the samples.
    for (const Case c : {Case{null_lobe_scenes::kThin, false, 200000}, Case{null_lobe_scenes::kRough, false, 1600000},
                         Case{null_lobe_scenes::kRough, true, 400000}}) {
        CAPTURE(c.boundary);
        CAPTURE(c.lamp_inside);
        const null_lobe_scenes::Sc sc = null_lobe_scenes::glass_cube_under_lamp(c.boundary, c.lamp_inside);
        StrategyRecord rec = record_strategies(BdptEstimator<bdpt::NullScattering, mis::Balance>(strategy_test_options()), sc,
                                               c.samples, 3);
        check_strategies_alone_and_symmetric(rec);
    }
}

/// The cube over the floor under a sky alone (no lamp), whose light sampler has a BoundingSphere of
/// radius 4.5 around the origin (the floor's corners lie 4.37 from it): light subpaths start from
/// the sky, on a disk outside the sphere.
Sc cube_under_sky(float radius = 4.5f) {
    Shapes shapes;
    shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {-1, -1, 0, -1}});
    shapes.quads.push_back({Vec3(-3.f, -1.05f, 3.f), Vec3(6.f, 0.f, 0.f), Vec3(0.f, 0.f, -6.f), {0, -1, -1, -1}});
    return Sc(shapes, {medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.3f, 1.2f, 0.6f)}, materials(0.6f),
              Ls(LightSelection::Uniform, BoundingSphere{Vec3(0.f), radius}, {}, {EnvironmentLight<S>{Spectrum::Constant(0.5f)}}),
              -1);
}

TEST_CASE("bdpt: light subpaths from the sky: each strategy alone is unbiased, the pdfs true densities" * doctest::test_suite("converge")) {
    // As the test above, with the sky as the only light and light subpaths starting from it
    // (x_0 a direction, x_1 reached from a disk outside the scene's sphere): every (s, t) of
    // n = 1..3 alone against NEE (5 combined SE), and the pdf symmetry over every pair (5 SE).
    // Without light subpaths from the sky the strategies s >= 2 would estimate 0 and fail.
    // 1e6 samples, not 2e5: connections from the sky's wide disk are rare and skewed, and at 2e5
    // the (s, t) = (2, 3) estimate (SE 12x NEE's) still came out 5.3 of its SE low; at 1e6 it
    // lies within the tolerance, and at 2e6 with another seed within 1 SE. 4 s in Release.
    const Sc sc = cube_under_sky();
    REQUIRE(sc.lights.emits_from_infinity());
    const EstimatorOptions opts = strategy_test_options();
    StrategyRecord rec = record_strategies(BdptEstimator<bdpt::NullScattering, mis::Balance>(opts), sc, 1000000, 3);
    check_strategies_alone_and_symmetric(rec);
}

TEST_CASE("bdpt: with light subpaths from the sky, agrees with PathEstimator under the lamp and the sky") {
    // The cube over the floor under the lamp and the sky, the sampler given a BoundingSphere:
    // BDPT's estimate against null-scattering uni + NEE MIS's on the same scene, 5 combined SE.
    Sc base = cube_over_floor(true);
    const QuadLight<S> lamp = base.lights.lights<QuadLight<S>>()[0];
    const Sc sc(base.geometry, base.media, base.materials,
                Ls(LightSelection::Power, BoundingSphere{Vec3(0.f), 4.5f}, {lamp}, {EnvironmentLight<S>{Spectrum::Constant(0.05f)}}),
                -1);
    check_agrees_with_path_estimator(sc, 23);
}

using SunLs = LightSampler<S, QuadLight<S>, DirectionalLight<S>>;
using SunSc = SurfaceScene<Shapes, M, GlobalMajorant<M>, HenyeyGreensteinPhase, Mats, SunLs>;

/// The cube over the floor under a sun (irradiance 2, from above and the side) and, with `lamp`,
/// the quad lamp; with `sphere` the sampler has the BoundingSphere of cube_under_sky, so light
/// subpaths start from the sun too.
SunSc cube_under_sun(bool lamp, bool sphere) {
    const Sc base = cube_over_floor(false);
    std::vector<QuadLight<S>> lamps;
    if (lamp) lamps = base.lights.lights<QuadLight<S>>();
    const DirectionalLight<S> sun{Vec3(0.4f, -1.f, 0.3f), Spectrum::Constant(2.f)};
    return SunSc(base.geometry, base.media, base.materials,
                 sphere ? SunLs(LightSelection::Power, BoundingSphere{Vec3(0.f), 4.5f}, lamps, {sun})
                        : SunLs(LightSelection::Power, 4.5f, lamps, {sun}),
                 -1);
}

TEST_CASE("bdpt: light subpaths from a directional light: each strategy alone is unbiased, the pdfs true densities" * doctest::test_suite("converge")) {
    // As the sky's test above, under a sun alone: x_0 is the sun's one direction, x_1 reached
    // from a disk outside the scene's sphere. No path hits the sun, so s = 0 contributes nothing;
    // every other (s, t) of n = 1..3 alone against NEE (5 combined SE), and the pdf symmetry over
    // every pair (5 SE). Without light subpaths from the sun the strategies s >= 2 would estimate 0.
    const SunSc sc = cube_under_sun(false, true);
    REQUIRE(sc.lights.emits_from_infinity());
    REQUIRE(sc.lights.emission_selection_pdf(0) == 1.f);
    const EstimatorOptions opts = strategy_test_options();
    StrategyRecord rec = record_strategies(BdptEstimator<bdpt::NullScattering, mis::Balance>(opts), sc, 400000, 3);
    check_strategies_alone_and_symmetric(rec, false);
}

TEST_CASE("bdpt: with light subpaths from a directional light, agrees with PathEstimator under the lamp and the sun") {
    // BDPT's estimate against null-scattering uni + NEE MIS's on the same scene, 5 combined SE,
    // with the sun's light subpaths and without (no BoundingSphere: the sun is NEE's alone).
    check_agrees_with_path_estimator(cube_under_sun(true, true), 25);
    check_agrees_with_path_estimator(cube_under_sun(true, false), 27);
}

using PointLs = LightSampler<S, QuadLight<S>, PointLight<S>>;
using PointSc = SurfaceScene<Shapes, M, GlobalMajorant<M>, HenyeyGreensteinPhase, Mats, PointLs>;

/// The cube over the floor under a point lamp 0.5 above its top face (and with `quad`, the quad
/// lamp too): the point light is what BDPT's equiangular strategy aims at.
PointSc cube_under_point_lamp(bool quad) {
    const Sc base = cube_over_floor(false);
    std::vector<QuadLight<S>> lamps;
    if (quad) lamps = base.lights.lights<QuadLight<S>>();
    Shapes shapes = base.geometry;
    if (!quad) shapes.quads.pop_back();  // the quad lamp's shape
    const PointLight<S> point{Vec3(0.4f, 1.5f, -0.3f), Spectrum::Constant(3.f)};
    return PointSc(shapes, base.media, base.materials, PointLs(LightSelection::Power, 4.f, lamps, {point}), -1);
}

TEST_CASE("bdpt: under a point lamp the equiangular strategy alone is unbiased, its pdf the true density" * doctest::test_suite("converge")) {
    // The cube over the floor under a point lamp alone: no path hits it (s = 0 contributes
    // nothing); every other (s, t) of n = 1..3 alone against NEE, the equiangular strategy alone
    // against NEE over the paths it draws (x_1 in the cube), and the pdf symmetry over every pair
    // with it, 5 combined SE. The walls of the cube's box are null interfaces its vertices cross.
    const PointSc sc = cube_under_point_lamp(false);
    REQUIRE(sc.lights.equiangular_count() == 1);
    REQUIRE(sc.lights.equiangular_is_delta(0));
    const EstimatorOptions opts = strategy_test_options();
    StrategyRecord rec = record_strategies(BdptEstimator<bdpt::NullScattering, mis::Balance>(opts), sc, 200000, 3);
    check_strategies_alone_and_symmetric(rec, false, true);
    // Off: nothing drawn.
    EstimatorOptions off = opts;
    off.bdpt_equiangular = false;
    StrategyRecord none = record_strategies(BdptEstimator<bdpt::NullScattering, mis::Balance>(off), sc, 20000, 3);
    check_strategies_alone_and_symmetric(none, false, false);
}

TEST_CASE("bdpt: agrees with PathEstimator under a point lamp and a quad lamp, the equiangular strategy on") {
    // BDPT (every variant; the null-scattering ones with the equiangular strategy toward the point
    // lamp) against null-scattering uni + NEE MIS, 5 combined SE.
    check_agrees_with_path_estimator(cube_under_point_lamp(true), 29);
}

TEST_CASE("bdpt: a sun through an absorbing slab onto a diffuse floor, light tracing included (closed form)") {
    // A Lambertian floor (albedo 0.6) at y = 0 under an absorbing slab (sigma_a 0.7, y in [2, 3]),
    // a sun of irradiance E = 2 at 30 degrees from the vertical, the camera at y = 1 below the
    // slab looking straight down at the floor (+-1 of it in view, every sun ray to it through the
    // slab's top): every pixel sees
    //     L = 0.6 / pi E cos 30 exp(-0.7 / cos 30) = 0.14741.
    // One real vertex (max_depth 1): NEE (s = 1) and light tracing from the sun's disk (s = 2,
    // t = 1; through the slab's nulls) draw these paths. The image's average with the splats for
    // each variant, and each strategy alone (weight 1), within 5 SE. Light tracing alone is rare
    // (9 % of the disk's rays reach the floor in view): 160000 samples put its SE at 1.4 % of L,
    // so a factor such as cos 30 left out (13 %) is 9 SE off.
    Shapes shapes;
    shapes.quads.push_back({Vec3(-1.5f, 0.f, 1.5f), Vec3(3.f, 0.f, 0.f), Vec3(0.f, 0.f, -3.f), {0, -1, -1, -1}});
    const Box slab{Vec3(-3.f, 2.f, -1.5f), Vec3(3.f, 3.f, 1.5f)};
    shapes.boxes.push_back({slab.lo, slab.hi, {-1, -1, 0, -1}});
    const float theta = 30.f * kPi / 180.f;
    const DirectionalLight<S> sun{Vec3(std::sin(theta), -std::cos(theta), 0.f), Spectrum::Constant(2.f)};
    const SunSc sc(shapes, {medium(slab, 0.7f, 0.f)}, materials(0.6f),
                   SunLs(LightSelection::Uniform, BoundingSphere{Vec3(0.f, 1.5f, 0.f), 3.8f}, {}, {sun}), -1);
    const double expected = 0.6 / kPi * 2.0 * std::cos(double(theta)) * std::exp(-0.7 / std::cos(double(theta)));
    const PinholeCamera camera(Vec3(0.f, 1.f, 0.f), Vec3(0.f, 0.f, 0.f), Vec3(0.f, 0.f, 1.f), 90.f, 1.f);
    EstimatorOptions opts = BdptEstimator<>::default_options();
    opts.max_depth = 1;
    for_each_bdpt(
        [&](const auto& est, const char* name) {
            CAPTURE(std::string(name));
            const Stat s = image_average(est, sc, camera, 20000, 31);
            CAPTURE(s.mean);
            CAPTURE(expected);
            CHECK(std::abs(s.mean - expected) <= kSigmas * s.se());
        },
        opts);
    std::map<int, Stat> alone;
    Pcg32 rng(33, 5);
    LookupCount counter;
    const BdptEstimator<bdpt::NullScattering, mis::Balance> est(opts);
    for (int i = 0; i < 160000; ++i) {
        std::map<int, double> x;
        auto observe = [&](int s, int, const Spectrum& f, float, const auto&, const auto&) { x[s] += double(f[0]); };
        auto splat = [](float, float, const Spectrum&) {};
        REQUIRE(est.sample_observed(sc, camera, rng.uniform(), rng.uniform(), {}, rng, counter, splat, observe).status ==
                Status::Ok);
        for (int s = 0; s <= 2; ++s) alone[s].add(x.count(s) ? x[s] : 0.0);
    }
    CHECK(alone[0].mean == 0.0);  // no path hits the sun
    for (int s = 1; s <= 2; ++s) {
        CAPTURE(s);
        CAPTURE(alone[s].mean);
        CHECK(alone[s].mean > 0.0);
        CHECK(std::abs(alone[s].mean - expected) <= kSigmas * alone[s].se());
    }
}

TEST_CASE("bdpt: a medium outside the lights' BoundingSphere is rejected with its bounds") {
    // The cube's corners lie sqrt(3) = 1.73 from the centre: a sphere of radius 1.5 cannot hold it.
    CHECK_THROWS_WITH_AS(cube_under_sky(1.5f), doctest::Contains("BoundingSphere"), InvalidArgument);
    CHECK_NOTHROW(cube_under_sky(1.8f));
}

TEST_CASE("bdpt: the pdf symmetry test sees directional MIS's pdfs are not densities" * doctest::test_suite("converge")) {
    // The same measurement with bdpt::Directional, whose weights leave out the distance pdfs
    // (unbiased, but its "pdfs" are not the strategies' densities): the symmetry must break, by
    // far more than 5 SE. Shows that the test above can fail.
    const Sc sc = cube_over_floor(false);
    const EstimatorOptions opts = strategy_test_options();
    StrategyRecord rec = record_strategies(BdptEstimator<bdpt::Directional, mis::Balance>(opts), sc, 200000, 3);
    CHECK(worst_share_asymmetry(rec, 3) > 4.0 * kSigmas);
}

TEST_CASE("bdpt: without nulls, null-scattering MIS weighs every path as directional MIS does") {
    // THEORY 5.5: a strategy's pdf of a path differs from directional MIS's pseudo-pdf by the
    // nulls' prod P_n of every segment it tracks and the end factor mu_bar P_s at every medium
    // vertex. Each medium vertex is the end of a tracked segment in every strategy, so its end
    // factor is common to all of them and cancels; what is left is prod P_n of the one segment a
    // strategy connects instead of tracking. With the cube's majorant equal to its extinction no
    // segment has a null: both estimators (the same random draws; the weights draw none) must
    // return the same value and the same splats for every sample, to float rounding (1e-4
    // relative). With the majorant twice the extinction the weights must differ (some sample by
    // more than 1 %): the comparison can fail. The equiangular strategy, which directional MIS
    // does not have, is off.
    const PinholeCamera camera = cube_pinhole();
    EstimatorOptions no_eq = BdptEstimator<>::default_options();
    no_eq.bdpt_equiangular = false;
    for (const bool tight : {true, false}) {
        CAPTURE(tight);
        const Sc sc = cube_over_floor(true, 1.2f, tight);
        const BdptEstimator<bdpt::NullScattering, mis::Balance> null_mis(no_eq);
        const BdptEstimator<bdpt::Directional, mis::Balance> directional;
        LookupCount counter;
        double worst = 0.0;
        int compared = 0;
        for (int i = 0; i < 20000; ++i) {
            double a[2] = {0.0, 0.0};
            int splats[2] = {0, 0};
            for (int k = 0; k < 2; ++k) {
                Pcg32 rng(91, std::uint64_t(i));
                const float u = rng.uniform(), v = rng.uniform();
                auto splat = [&](float, float, const Spectrum& value) {
                    a[k] += double(value[0]);
                    ++splats[k];
                };
                const auto r = k == 0 ? null_mis.sample(sc, camera, u, v, {}, rng, counter, splat)
                                      : directional.sample(sc, camera, u, v, {}, rng, counter, splat);
                REQUIRE(r.status == Status::Ok);
                a[k] += double(r.value[0]);
            }
            REQUIRE(splats[0] == splats[1]);  // the same paths
            if (a[0] == 0.0 && a[1] == 0.0) continue;
            ++compared;
            worst = std::max(worst, std::abs(a[0] - a[1]) / std::max(std::abs(a[0]), std::abs(a[1])));
        }
        CAPTURE(compared);
        CAPTURE(worst);
        CHECK(compared > 5000);
        if (tight)
            CHECK(worst <= 1e-4);
        else
            CHECK(worst > 1e-2);
    }
}

TEST_CASE("bdpt: with light tracing, the image agrees with PathEstimator pixel by pixel" * doctest::test_suite("converge")) {
    // The cube over the floor under the lamp and the sky, 4 x 4 pixels through cube_pinhole(),
    // BdptEstimator::sample with splats: each pixel = (its samples' returns + the splats it
    // received) / its sample count. Against PathEstimator's pixel means, 5 combined SE; the BDPT
    // pixel's SE from 10 independent batches (splats land in other pixels than their sample's, so
    // a pixel's samples alone do not give its variance).
    const Sc sc = cube_over_floor(true);
    const PinholeCamera camera = cube_pinhole();
    constexpr int kRes = 4, kBatches = 10, kPerBatch = 1500;  // samples per pixel per batch
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        std::vector<Stat> bdpt_pixel(kRes * kRes), path_pixel(kRes * kRes);
        Pcg32 rng(77, 1);
        LookupCount counter;
        const PathEstimator<strategy::NullScatteringMis, mis::Balance> path;
        for (int b = 0; b < kBatches; ++b) {
            std::vector<double> sum(kRes * kRes, 0.0);
            auto splat = [&](float u, float v, const Spectrum& value) {
                const int px = std::min(kRes - 1, int(u * kRes)), py = std::min(kRes - 1, int(v * kRes));
                sum[std::size_t(py * kRes + px)] += double(value[0]);
            };
            for (int p = 0; p < kRes * kRes; ++p)
                for (int i = 0; i < kPerBatch; ++i) {
                    const float u = (float(p % kRes) + rng.uniform()) / kRes, v = (float(p / kRes) + rng.uniform()) / kRes;
                    const auto r = est.sample(sc, camera, u, v, {}, rng, counter, splat);
                    REQUIRE(r.status == Status::Ok);
                    sum[std::size_t(p)] += double(r.value[0]);
                    const auto q = path.radiance(sc, camera.ray(u, v), {}, rng, counter);
                    REQUIRE(q.status == Status::Ok);
                    path_pixel[std::size_t(p)].add(double(q.value[0]));
                }
            for (int p = 0; p < kRes * kRes; ++p) bdpt_pixel[std::size_t(p)].add(sum[std::size_t(p)] / kPerBatch);
        }
        for (int p = 0; p < kRes * kRes; ++p) {
            const Stat& a = bdpt_pixel[std::size_t(p)];
            const Stat& b = path_pixel[std::size_t(p)];
            CAPTURE(p);
            CAPTURE(a.mean);
            CAPTURE(b.mean);
            CHECK(std::abs(a.mean - b.mean) <= kSigmas * std::sqrt(a.se() * a.se() + b.se() * b.se()) + 1e-6);
        }
    });
}

TEST_CASE("bdpt: with light tracing, the furnace of six emitting walls is still L = 2 everywhere") {
    // The camera inside the closed box: every pixel sees L = 2, so the image's average over
    // uniform (u, v), each sample's return plus its light subpath's splats, is 2 (5 SE).
    Shapes shapes;
    std::vector<QuadLight<S>> walls;
    box_walls(1.f, {1, 4}, shapes, walls);
    const Sc sc(shapes, {medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.f, 1.5f)}, materials(),
                Ls(LightSelection::Uniform, 2.f, walls, {}), 0);
    const PinholeCamera camera(Vec3(0.1f, -0.2f, 0.3f), Vec3(0.5f, 0.f, -1.f), Vec3(0.f, 1.f, 0.f), 70.f, 1.3f);
    EstimatorOptions opts;
    opts.max_depth = 64;
    for_each_bdpt<64>(
        [&](const auto& est, const char* name) {
            CAPTURE(std::string(name));
            const Stat s = image_average(est, sc, camera, 6000, 19);
            CAPTURE(s.mean);
            CAPTURE(s.se());
            CHECK(std::abs(s.mean - 2.0) <= kSigmas * s.se());
        },
        opts);
}

TEST_CASE("bdpt: PinholeCamera's rays, image coordinates and direction density agree") {
    // raster inverts ray; pdf_dir integrates to 1 over the image (Monte Carlo over the sphere of
    // directions, 5 SE); bad parameters are rejected by name.
    const PinholeCamera cam(Vec3(1.f, 2.f, 3.f), Vec3(0.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f), 50.f, 1.5f);
    Pcg32 rng(3, 3);
    for (int i = 0; i < 1000; ++i) {
        const float u = rng.uniform(), v = rng.uniform();
        float uu = -1.f, vv = -1.f;
        REQUIRE(cam.raster(cam.ray(u, v).d, uu, vv));
        CHECK(uu == doctest::Approx(u).epsilon(1e-3));
        CHECK(vv == doctest::Approx(v).epsilon(1e-3));
    }
    Stat s;
    for (int i = 0; i < 200000; ++i) s.add(double(cam.pdf_dir(uniform_sphere(rng.uniform(), rng.uniform()))) * 4.0 * kPi);
    CHECK(std::abs(s.mean - 1.0) <= kSigmas * s.se());
    CHECK_THROWS_WITH_AS(PinholeCamera(Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec3(0.f, 1.f, 0.f), 180.f),
                         doctest::Contains("vfov_degrees = 180 is not allowed"), InvalidArgument);
    CHECK_THROWS_WITH_AS(PinholeCamera(Vec3(0.f), Vec3(0.f, 1.f, 0.f), Vec3(0.f, 1.f, 0.f), 40.f),
                         doctest::Contains("up is parallel"), InvalidArgument);
}

TEST_CASE("bdpt: finite estimates and splats at the extremes of density and light size") {
    // Densities 0, 1e-6 and 1e6 (optical depth 2e6 across the cube), a lamp of 1e-3 x 1e-3 and one
    // of 100 x 100, the camera inside the cube: every return and splat is finite, every status Ok.
    for (const float sigma : {0.f, 1e-6f, 1e6f})
        for (const float size : {1e-3f, 100.f}) {
            Shapes shapes;
            shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {-1, -1, 0, -1}});
            shapes.quads.push_back({Vec3(-3.f, -1.05f, 3.f), Vec3(6.f, 0.f, 0.f), Vec3(0.f, 0.f, -6.f), {0, -1, -1, -1}});
            const QuadLight<S> lamp{Vec3(-0.5f * size, 2.6f, -0.5f * size), Vec3(size, 0.f, 0.f), Vec3(0.f, 0.f, size),
                                    Spectrum::Constant(12.f)};
            shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, -1, -1}});
            const Sc sc(shapes, {medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.5f * sigma, 0.5f * sigma)}, materials(0.6f),
                        Ls(LightSelection::Power, 4.f, {lamp}, {EnvironmentLight<S>{Spectrum::Constant(0.05f)}}), 0);
            const PinholeCamera camera(Vec3(0.f, 0.2f, 0.f), Vec3(0.f, 0.f, 1.f), Vec3(0.f, 1.f, 0.f), 60.f);
            for_each_bdpt([&](const auto& est, const char* name) {
                CAPTURE(std::string(name));
                CAPTURE(sigma);
                CAPTURE(size);
                Pcg32 rng(5, 5);
                LookupCount counter;
                bool finite = true;
                auto splat = [&](float, float, const Spectrum& v) { finite = finite && std::isfinite(v[0]); };
                for (int i = 0; i < 300; ++i) {
                    const auto a = est.radiance(sc, camera.ray(rng.uniform(), rng.uniform()), {}, rng, counter);
                    const auto b = est.sample(sc, camera, rng.uniform(), rng.uniform(), {}, rng, counter, splat);
                    CHECK(a.status == Status::Ok);
                    CHECK(b.status == Status::Ok);
                    CHECK(std::isfinite(a.value[0]));
                    CHECK(std::isfinite(b.value[0]));
                }
                CHECK(finite);
            });
        }
}


TEST_CASE("bdpt: an emitting medium in the furnace: L = L_e everywhere, light subpaths from the volume and the walls") {
    // Walls of albedo 0.5 emitting (1 - 0.5) L_e around a medium that absorbs (sigma_a 0.6),
    // scatters (1.0) and emits L_e = 2: the radiance L_e is the equilibrium (the walls give
    // Le_w + 0.5 L_e = L_e, the medium dL/ds = mu_a (L_e - L) = 0), so L = 2 in every direction.
    // Light subpaths start in the volume or at a wall (one half each), NEE goes to both, the
    // camera subpath collects the volume's emission at every tentative collision; with and without
    // light tracing, both MIS policies (5 SE).
    Shapes shapes;
    std::vector<QuadLight<S>> walls;
    box_walls(1.f, {}, shapes, walls);
    const ESc sc(shapes, {emitting(Box{Vec3(-1.f), Vec3(1.f)}, 0.6f, 1.f, 2.f)}, materials(),
                 Ls(LightSelection::Uniform, 2.f, walls, {}), 0);
    const PinholeCamera camera(Vec3(0.1f, -0.2f, 0.3f), Vec3(0.5f, 0.f, -1.f), Vec3(0.f, 1.f, 0.f), 70.f, 1.3f);
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        const Stat a = estimate(est, sc, 6000, 13, [](Pcg32& rng) {
            return Ray{Vec3(0.1f, -0.2f, 0.3f), uniform_sphere(rng.uniform(), rng.uniform())};
        });
        CAPTURE(a.mean);
        CHECK(std::abs(a.mean - 2.0) <= kSigmas * a.se());
        const Stat b = image_average(est, sc, camera, 6000, 23);
        CAPTURE(b.mean);
        CHECK(std::abs(b.mean - 2.0) <= kSigmas * b.se());
    });
}

/// The cube over the floor (cube_over_floor) with the cube also emitting L_e = 0.8.
ESc emitting_cube_over_floor() {
    Shapes shapes;
    shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {-1, -1, 0, -1}});
    shapes.quads.push_back({Vec3(-3.f, -1.05f, 3.f), Vec3(6.f, 0.f, 0.f), Vec3(0.f, 0.f, -6.f), {0, -1, -1, -1}});
    const QuadLight<S> lamp{Vec3(-0.6f, 2.6f, -0.6f), Vec3(1.2f, 0.f, 0.f), Vec3(0.f, 0.f, 1.2f), Spectrum::Constant(12.f)};
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, -1, -1}});
    return ESc(shapes, {emitting(Box{Vec3(-1.f), Vec3(1.f)}, 0.3f, 1.2f, 0.8f, 0.6f)}, materials(0.6f),
               Ls(LightSelection::Power, 4.f, {lamp}, {}), -1);
}

TEST_CASE("bdpt: an emitting cube: each strategy alone unbiased, the pdfs true densities, volume sources included" * doctest::test_suite("converge")) {
    // The symmetry and each-strategy-alone tests of the plain cube, with the cube emitting: paths
    // now start at the lamp or anywhere in the volume, every strategy samples both (5 SE).
    const ESc sc = emitting_cube_over_floor();
    const EstimatorOptions opts = strategy_test_options();
    StrategyRecord rec = record_strategies(BdptEstimator<bdpt::NullScattering, mis::Balance>(opts), sc, 200000, 3);
    check_strategies_alone_and_symmetric(rec, true, false, true);
}

/// emitting_cube_over_floor with a core [-0.5, 0.5]^3 of a denser, brighter emitting medium 1
/// behind null interfaces inside the cube (medium 0 around it): a segment reaches the core's piece
/// after tracking the shell's, whose nulls' P_n the segment technique's density carries.
ESc nested_emitting_cubes() {
    Shapes shapes;
    shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {-1, -1, 0, -1}});
    shapes.boxes.push_back({Vec3(-0.5f), Vec3(0.5f), {-1, -1, 1, 0}});
    shapes.quads.push_back({Vec3(-3.f, -1.05f, 3.f), Vec3(6.f, 0.f, 0.f), Vec3(0.f, 0.f, -6.f), {0, -1, -1, -1}});
    const QuadLight<S> lamp{Vec3(-0.6f, 2.6f, -0.6f), Vec3(1.2f, 0.f, 0.f), Vec3(0.f, 0.f, 1.2f), Spectrum::Constant(12.f)};
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, -1, -1}});
    return ESc(shapes,
               {emitting(Box{Vec3(-1.f), Vec3(1.f)}, 0.3f, 1.2f, 0.4f, 0.6f),
                emitting(Box{Vec3(-0.5f), Vec3(0.5f)}, 1.f, 2.f, 3.f, 0.2f)},
               materials(0.6f), Ls(LightSelection::Power, 4.f, {lamp}, {}), -1);
}

TEST_CASE("bdpt: nested emitting media: each strategy alone unbiased, the pdfs true densities" * doctest::test_suite("converge")) {
    // The emitting cube's checks with an emitting core behind null interfaces inside it: the
    // segment technique's points in the core come after the shell's tracked piece (its nulls'
    // P_n in the technique's density, on the camera side, in NEE toward the volume and in light
    // subpaths from the core, whose first segment crosses the shell), 5 SE.
    const ESc sc = nested_emitting_cubes();
    const EstimatorOptions opts = strategy_test_options();
    StrategyRecord rec = record_strategies(BdptEstimator<bdpt::NullScattering, mis::Balance>(opts), sc, 200000, 3);
    check_strategies_alone_and_symmetric(rec, true, false, true);
}

TEST_CASE("bdpt: agrees with PathEstimator on an emitting cube over a floor under a lamp") {
    // Image averages over uniform (u, v): BDPT with and without light tracing against
    // PathEstimator's three-way emission MIS, 5 combined SE.
    const ESc sc = emitting_cube_over_floor();
    const PinholeCamera camera = cube_pinhole();
    auto ray = [&](Pcg32& rng) { return camera.ray(rng.uniform(), rng.uniform()); };
    const Stat ref = estimate(PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, sc, 40000, 31, ray);
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        const Stat a = estimate(est, sc, 10000, 32, ray);
        CAPTURE(a.mean);
        CAPTURE(ref.mean);
        CHECK(std::abs(a.mean - ref.mean) <= kSigmas * std::sqrt(a.se() * a.se() + ref.se() * ref.se()));
        const Stat b = image_average(est, sc, camera, 10000, 33);
        CAPTURE(b.mean);
        CHECK(std::abs(b.mean - ref.mean) <= kSigmas * std::sqrt(b.se() * b.se() + ref.se() * ref.se()));
    });
}

TEST_CASE("bdpt: light subpaths and NEE on a fraction of the samples (expected counts < 1, or 0) stay unbiased" * doctest::test_suite("converge")) {
    // THEORY 5.9: with light_subpath_probability c the connections and light tracing run on a
    // fraction c of the samples and weigh with c times their densities; with nee_count n, NEE
    // toward the lights (s = 1) runs at a camera vertex with probability n, divides by it, and
    // every path's NEE density carries n. The emitting furnace (L = 2, with and without light
    // tracing) at c = 0.3, n = 0.3 (NEE toward the volume keeps count 1), and the cube's pdf
    // symmetry and each strategy alone at c = 0.4, n = 0.5 (the densities now include both), 5 SE.
    Shapes shapes;
    std::vector<QuadLight<S>> walls;
    box_walls(1.f, {}, shapes, walls);
    const ESc sc(shapes, {emitting(Box{Vec3(-1.f), Vec3(1.f)}, 0.6f, 1.f, 2.f)}, materials(),
                 Ls(LightSelection::Uniform, 2.f, walls, {}), 0);
    const PinholeCamera camera(Vec3(0.1f, -0.2f, 0.3f), Vec3(0.5f, 0.f, -1.f), Vec3(0.f, 1.f, 0.f), 70.f, 1.3f);
    EstimatorOptions furnace_opts = BdptEstimator<>::default_options();
    furnace_opts.nee_count = 0.3f;
    const BdptEstimator<bdpt::NullScattering, mis::Balance> est(furnace_opts, {}, 0.3f);
    CHECK(est.light_subpath_probability() == 0.3f);
    const Stat a = estimate(est, sc, 6000, 43, [](Pcg32& rng) {
        return Ray{Vec3(0.1f, -0.2f, 0.3f), uniform_sphere(rng.uniform(), rng.uniform())};
    });
    CAPTURE(a.mean);
    CHECK(std::abs(a.mean - 2.0) <= kSigmas * a.se());
    const Stat b = image_average(est, sc, camera, 6000, 44);
    CAPTURE(b.mean);
    CHECK(std::abs(b.mean - 2.0) <= kSigmas * b.se());
    // Counts 0 (THEORY 5.9: the technique is absent from the sum): no NEE toward the lights, no
    // light subpaths, or neither (s = 0, the collision estimator's emission, NEE toward the
    // volume and the segment technique are left; the walls can be hit): still L = 2.
    for (const auto& [n, c] : {std::pair{0.f, 0.4f}, std::pair{0.5f, 0.f}, std::pair{0.f, 0.f}}) {
        EstimatorOptions o = BdptEstimator<>::default_options();
        o.nee_count = n;
        const float light = c;  // not a structured binding: CAPTURE's lambda takes it
        const float nee = n;
        CAPTURE(nee);
        CAPTURE(light);
        const BdptEstimator<bdpt::NullScattering, mis::Balance> zero(o, {}, light);
        const Stat z = image_average(zero, sc, camera, 6000, 45);
        CAPTURE(z.mean);
        CHECK(std::abs(z.mean - 2.0) <= kSigmas * z.se());
    }

    EstimatorOptions opts = strategy_test_options();
    opts.nee_count = 0.5f;
    StrategyRecord rec =
        record_strategies(BdptEstimator<bdpt::NullScattering, mis::Balance>(opts, {}, 0.4f), cube_over_floor(false), 200000, 3);
    check_strategies_alone_and_symmetric(rec);
    CHECK_THROWS_WITH_AS((BdptEstimator<>(BdptEstimator<>::default_options(), {}, -0.1f)),
                         doctest::Contains("light_subpath_probability = -0.1 is not allowed"), InvalidArgument);
    CHECK_THROWS_WITH_AS((BdptEstimator<>(BdptEstimator<>::default_options(), {}, 1.5f)),
                         doctest::Contains("light_subpath_probability = 1.5 is not allowed"), InvalidArgument);
}

TEST_CASE("bdpt: media in empty space (NoSurfaces): light subpaths start in the camera's medium") {
    // A fog box without any surface (a SurfaceScene over nsp::NoSurfaces, the camera in medium 0),
    // lit by a point light 0.6 above it (outside, so that no vertex comes near it: NEE's 1/d^2 has
    // finite variance): the light subpaths find no surface to tell their medium and start in the
    // medium that fills the scene, as the camera side sees it. Against PathEstimator on the same
    // scene, image averages with and without light tracing, 5 combined SE. (Started in vacuum, as
    // before this test, the light subpaths never scatter and the estimate was 35-42% low.)
    using NSc = SurfaceScene<NoSurfaces, M, GlobalMajorant<M>, HenyeyGreensteinPhase, Mats,
                             LightSampler<S, PointLight<S>>>;
    const NSc sc(NoSurfaces{}, {medium(Box{Vec3(-2.f), Vec3(2.f)}, 0.2f, 0.8f, 0.4f)}, materials(),
                 LightSampler<S, PointLight<S>>(LightSelection::Uniform, 3.f, {PointLight<S>{Vec3(0.3f, 2.6f, 0.2f),
                                                                                             Spectrum::Constant(3.f)}}),
                 0);
    const PinholeCamera camera(Vec3(0.f, 0.f, -1.5f), Vec3(0.f, 0.f, 1.f), Vec3(0.f, 1.f, 0.f), 60.f);
    auto ray = [&](Pcg32& rng) { return camera.ray(rng.uniform(), rng.uniform()); };
    const Stat ref = estimate(PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, sc, 40000, 51, ray);
    for_each_bdpt([&](const auto& est, const char* name) {
        CAPTURE(std::string(name));
        const Stat a = estimate(est, sc, 10000, 52, ray);
        const Stat b = image_average(est, sc, camera, 10000, 53);
        CAPTURE(a.mean);
        CAPTURE(b.mean);
        CAPTURE(ref.mean);
        if (getenv("BDPT_DEBUG")) printf("%s: %.5f +- %.5f, %.5f +- %.5f, ref %.5f +- %.5f\n", name, a.mean, a.se(), b.mean, b.se(), ref.mean, ref.se());
        CHECK(std::abs(a.mean - ref.mean) <= kSigmas * std::sqrt(a.se() * a.se() + ref.se() * ref.se()));
        CHECK(std::abs(b.mean - ref.mean) <= kSigmas * std::sqrt(b.se() * b.se() + ref.se() * ref.se()));
    });
    // The point light is a delta light: only NEE reaches it, so NEE's count 0 is refused there
    // (Status::InvalidInput, no estimate), light subpaths or not.
    EstimatorOptions none = BdptEstimator<>::default_options();
    none.nee_count = 0.f;
    for (const float c : {1.f, 0.f}) {
        const BdptEstimator<bdpt::NullScattering, mis::Balance> est(none, {}, c);
        Pcg32 rng(3, 3);
        LookupCount counter;
        const auto r = est.radiance(sc, camera.ray(0.5f, 0.5f), {}, rng, counter);
        CHECK(r.status == Status::InvalidInput);
        CHECK(r.value[0] == 0.f);
    }
}

TEST_CASE("bdpt: rejects a max_depth beyond its vertex arrays") {
    EstimatorOptions opts;
    opts.max_depth = 40;
    CHECK_THROWS_WITH_AS((BdptEstimator<bdpt::NullScattering, mis::Balance, absorption::Weight, 32>(opts)),
                         doctest::Contains("max_depth = 40 is not allowed: it must be <= 32"), InvalidArgument);
}

// ---- Under a control (THEORY 5.10) ---------------------------------------------------------------
// Grey BDPT tracks its subpaths by decomposition tracking and its connections by residual ratio
// tracking where a medium's majorant carries a control: every null factor is the pair's exp(-tau_c)
// prod P_n,r and every medium vertex's event density the sum of its control and residual routes.
// The checks of the plain scenes run again on a heterogeneous medium under two controls.

using Exp = ExponentialMedium<S>;
using EExp = Emissive<ExponentialMedium<S>>;

/// An exponential medium over `box` with extinction sigma_a + sigma_s at its centre, varying by e^2
/// across it along an oblique axis (tests/support/common.hpp's MediumKind).
Exp ramp(const Box& box, float sigma_a, float sigma_s) {
    return make_medium<Exp>(box, 1.f, Spectrum::Constant(sigma_a), Spectrum::Constant(sigma_s));
}

/// The same ramp emitting L_e = `le` everywhere in it.
EExp emitting_ramp(const Box& box, float sigma_a, float sigma_s, float le) {
    return EExp(ramp(box, sigma_a, sigma_s), EmissionGrid(box, {2, 2, 2}, std::vector<float>(8, 1.f)),
                Spectrum::Constant(le), {4, 4, 4});
}

TEST_CASE("bdpt under a control: the furnace of six emitting walls around a medium of albedo 1 (L = 2)" *
          doctest::test_suite("converge")) {
    // The furnace above with the medium an albedo-1 ramp (extinction 0.37 to 2.7 across the box)
    // under each control: L = 2 whatever the density, for every variant (5 SE).
    Shapes shapes;
    std::vector<QuadLight<S>> walls;
    box_walls(1.f, {1, 4}, shapes, walls);
    const Sc base(shapes, {medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.f, 1.5f)}, materials(),
                  Ls(LightSelection::Uniform, 2.f, walls, {}), 0);
    EstimatorOptions opts;
    opts.max_depth = 64;
    for_each_control(base, ramp(Box{Vec3(-1.f), Vec3(1.f)}, 0.f, 1.5f), 0.3f, [&](const auto& sc, const char* control) {
        for_each_bdpt<64>(
            [&](const auto& est, const char* name) {
                CAPTURE(std::string(control));
                CAPTURE(std::string(name));
                const Stat s = estimate(est, sc, 6000, 71, [](Pcg32& rng) {
                    return Ray{Vec3(0.1f, -0.2f, 0.3f), uniform_sphere(rng.uniform(), rng.uniform())};
                });
                CAPTURE(s.mean);
                CAPTURE(s.se());
                CHECK(std::abs(s.mean - 2.0) <= kSigmas * s.se());
            },
            opts);
    });
}

TEST_CASE("bdpt under a control: each strategy alone unbiased, the pdfs true densities (cube, point lamp, emitting cube)" *
          doctest::test_suite("converge")) {
    // The symmetry and each-strategy-alone checks of the plain scenes (see above), on the cube of
    // a ramp (albedo 0.8, extinction 0.56 to 4.1) under each control: over the floor under the quad
    // lamp; under the point lamp, where the equiangular strategy's vertex weighs against the sum
    // of decomposition tracking's two routes; and emitting (the collision estimator at control and
    // residual collisions, the segment technique, NEE toward the volume and light subpaths from
    // it). A null factor or event density that were the full majorant's would break the symmetry.
    const Box cube{Vec3(-1.f), Vec3(1.f)};
    const EstimatorOptions opts = strategy_test_options();
    const BdptEstimator<bdpt::NullScattering, mis::Balance> est(opts);
    for_each_control(cube_over_floor(false), ramp(cube, 0.3f, 1.2f), 0.6f, [&](const auto& sc, const char* control) {
        CAPTURE(std::string(control));
        StrategyRecord rec = record_strategies(est, sc, 200000, 3);
        check_strategies_alone_and_symmetric(rec);
    });
    for_each_control(cube_under_point_lamp(false), ramp(cube, 0.3f, 1.2f), 0.6f, [&](const auto& sc, const char* control) {
        CAPTURE(std::string(control));
        StrategyRecord rec = record_strategies(est, sc, 200000, 3);
        check_strategies_alone_and_symmetric(rec, false, true);
    });
    for_each_control(emitting_cube_over_floor(), emitting_ramp(cube, 0.3f, 1.2f, 0.8f), 0.6f,
                     [&](const auto& sc, const char* control) {
                         CAPTURE(std::string(control));
                         StrategyRecord rec = record_strategies(est, sc, 200000, 3);
                         check_strategies_alone_and_symmetric(rec, true, false, true);
                     });
}

TEST_CASE("bdpt under a control: an emitting medium in the furnace gives L = L_e") {
    // The emitting furnace above with the medium an emitting ramp (mu_a 0.6, mu_s 1 at the centre,
    // L_e = 2) under each control: L = 2 in every direction, with and without light tracing,
    // every variant (5 SE).
    Shapes shapes;
    std::vector<QuadLight<S>> walls;
    box_walls(1.f, {}, shapes, walls);
    const ESc base(shapes, {emitting(Box{Vec3(-1.f), Vec3(1.f)}, 0.6f, 1.f, 2.f)}, materials(),
                   Ls(LightSelection::Uniform, 2.f, walls, {}), 0);
    const PinholeCamera camera(Vec3(0.1f, -0.2f, 0.3f), Vec3(0.5f, 0.f, -1.f), Vec3(0.f, 1.f, 0.f), 70.f, 1.3f);
    for_each_control(base, emitting_ramp(Box{Vec3(-1.f), Vec3(1.f)}, 0.6f, 1.f, 2.f), 0.3f,
                     [&](const auto& sc, const char* control) {
                         for_each_bdpt([&](const auto& e, const char* name) {
                             CAPTURE(std::string(control));
                             CAPTURE(std::string(name));
                             const Stat a = estimate(e, sc, 6000, 73, [](Pcg32& rng) {
                                 return Ray{Vec3(0.1f, -0.2f, 0.3f), uniform_sphere(rng.uniform(), rng.uniform())};
                             });
                             CAPTURE(a.mean);
                             CHECK(std::abs(a.mean - 2.0) <= kSigmas * a.se());
                             const Stat b = image_average(e, sc, camera, 6000, 74);
                             CAPTURE(b.mean);
                             CHECK(std::abs(b.mean - 2.0) <= kSigmas * b.se());
                         });
                     });
}

}  // namespace
