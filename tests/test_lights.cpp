// tests/test_lights.cpp: the light models of the Light concept (light.hpp) and LightSampler
// (light_sampler.hpp): each sample's pdf equals an independent evaluation of pdf() for its
// direction; NEE estimates of irradiance from a sphere and from rectangles match their closed
// forms; selection by power follows the powers; bad lights are rejected by name.
#include <array>
#include <cmath>
#include <vector>

#include "common.hpp"

namespace {

using namespace nsp_test;
using S = Rgb;

// k = 5 standard errors, estimated from the samples, with fixed seeds: deterministic.
constexpr double kSigmas = 5.0;

/// Irradiance at x (normal n) from a rectangle of radiance 1 with corners c[0..3], in closed form
/// (Lambert's formula for polygons): E = 1/2 sum_i theta_i n . normalize(v_i x v_{i+1}), v_i the
/// unit vectors toward the corners, theta_i the angle between consecutive ones.
double polygon_irradiance(const Vec3& x, const Vec3& n, const std::array<Vec3, 4>& c) {
    double e = 0.0;
    for (int i = 0; i < 4; ++i) {
        const glm::dvec3 a = glm::normalize(glm::dvec3(c[std::size_t(i)] - x));
        const glm::dvec3 b = glm::normalize(glm::dvec3(c[std::size_t((i + 1) % 4)] - x));
        const double theta = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
        e += theta * glm::dot(glm::dvec3(n), glm::normalize(glm::cross(a, b)));
    }
    return std::abs(0.5 * e);
}

/// NEE's estimate of the irradiance at x (normal n) from `sampler`'s lights, channel 0.
template <class Sampler>
Stat irradiance(const Sampler& sampler, const Vec3& x, const Vec3& n, std::uint64_t seed) {
    Pcg32 rng(seed, 5);
    Stat s;
    for (int i = 0; i < 40000; ++i) {
        const auto l = sampler.sample(x, rng.uniform(), rng.uniform(), rng.uniform());
        const float c = glm::dot(n, l.sample.wi);
        s.add(l.sample.pdf > 0.f && c > 0.f ? double(l.sample.radiance[0]) * c / l.sample.pdf : 0.0);
    }
    return s;
}

TEST_CASE("lights: every model's sample pdf equals its pdf() for the sampled direction") {
    const SphereLight<S> sphere{Vec3(0.f, 2.f, 0.f), 0.5f, S::Spectrum(1.f, 2.f, 3.f)};
    const QuadLight<S> quad{Vec3(-1.f, 3.f, -1.f), Vec3(2.f, 0.f, 0.f), Vec3(0.f, 0.f, 2.f), S::Spectrum::Ones()};
    const EnvironmentLight<S> env{S::Spectrum::Constant(0.5f)};
    const PointLight<S> point{Vec3(1.f, 1.f, 1.f), S::Spectrum::Constant(4.f)};
    CHECK(quad.normal().y == doctest::Approx(-1.f));  // emits downward, toward the origin
    Pcg32 rng(1, 1);
    for (int i = 0; i < 2000; ++i) {
        const Vec3 x(2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f);
        const float u1 = rng.uniform(), u2 = rng.uniform(), sel = 0.25f + 0.75f * rng.uniform();
        const auto ls = sphere.sample(x, u1, u2, {}, sel);
        REQUIRE(ls.pdf > 0.f);  // x lies outside the sphere
        CHECK(sphere.pdf(x, ls.wi, sel) == doctest::Approx(ls.pdf).epsilon(1e-4));
        CHECK(ls.distance == doctest::Approx(sphere.intersect(Ray{x, ls.wi})).epsilon(1e-3));
        const auto lq = quad.sample(x, u1, u2, {}, sel);
        REQUIRE(lq.pdf > 0.f);  // x lies below the quad, on its emitting side
        CHECK(quad.pdf(x, lq.wi, sel) == doctest::Approx(lq.pdf).epsilon(1e-3));
        CHECK(lq.distance == doctest::Approx(quad.intersect(Ray{x, lq.wi})).epsilon(1e-4));
        CHECK(quad.emitted(lq.wi, {})[0] == 1.f);
        CHECK(quad.emitted(-lq.wi, {})[0] == 0.f);  // one-sided
        const auto le = env.sample(x, u1, u2, {}, sel);
        CHECK(env.pdf(x, le.wi, sel) == doctest::Approx(le.pdf));
        const auto lp = point.sample(x, u1, u2, {}, sel);
        CHECK(lp.delta);
        CHECK(point.pdf(x, lp.wi, sel) == 0.f);  // no direction reaches a point by chance
        CHECK(lp.radiance[0] == doctest::Approx(4.f / (lp.distance * lp.distance)));
    }
    // Behind the quad nothing is emitted toward x: no sample, pdf 0.
    CHECK(quad.sample(Vec3(0.f, 4.f, 0.f), 0.5f, 0.5f).pdf == 0.f);
    CHECK(quad.pdf(Vec3(0.f, 4.f, 0.f), Vec3(0.f, -1.f, 0.f)) == 0.f);
}

TEST_CASE("lights: NEE irradiance from a sphere and from rectangles matches the closed forms") {
    const Vec3 x(0.f), n(0.f, 1.f, 0.f);
    // A sphere of radiance 1 and radius r at distance d above x: E = pi (r / d)^2.
    const LightSampler<S, SphereLight<S>> one_sphere(LightSelection::Uniform, 10.f,
                                                     {{Vec3(0.f, 3.f, 0.f), 0.5f, S::Spectrum::Ones()}});
    const Stat es = irradiance(one_sphere, x, n, 1);
    CAPTURE(es.mean);
    CHECK(std::abs(es.mean - kPi * (0.5 / 3.0) * (0.5 / 3.0)) <= kSigmas * es.se());
    // Two rectangles, one tilted, chosen uniformly or by power (radiances 1 and 3): the sum of
    // their closed forms either way (radiance scales the formula).
    const QuadLight<S> a{Vec3(-1.f, 2.f, -1.f), Vec3(2.f, 0.f, 0.f), Vec3(0.f, 0.f, 2.f), S::Spectrum::Ones()};
    const QuadLight<S> b{Vec3(1.f, 1.f, -0.5f), Vec3(0.f, 0.f, 1.f), Vec3(0.5f, 0.8f, 0.f), S::Spectrum::Constant(3.f)};
    REQUIRE(glm::dot(b.normal(), x - b.corner) > 0.f);  // b faces x
    const double exact = polygon_irradiance(x, n, {a.corner, a.corner + a.edge_u, a.corner + a.edge_u + a.edge_v, a.corner + a.edge_v}) +
                         3.0 * polygon_irradiance(x, n, {b.corner, b.corner + b.edge_u, b.corner + b.edge_u + b.edge_v, b.corner + b.edge_v});
    for (const LightSelection sel : {LightSelection::Uniform, LightSelection::Power}) {
        const LightSampler<S, QuadLight<S>> quads(sel, 10.f, {a, b});
        const Stat eq = irradiance(quads, x, n, 2 + std::uint64_t(sel));
        CAPTURE(int(sel));
        CAPTURE(eq.mean);
        CAPTURE(exact);
        CHECK(std::abs(eq.mean - exact) <= kSigmas * eq.se());
    }
}

TEST_CASE("lights: LightSampler selects by power, and its pdf matches its samples") {
    const std::vector<QuadLight<S>> quads{{Vec3(-1.f, 2.f, -1.f), Vec3(2.f, 0.f, 0.f), Vec3(0.f, 0.f, 2.f), S::Spectrum::Ones()}};
    const std::vector<SphereLight<S>> spheres{{Vec3(0.f, 3.f, 0.f), 0.5f, S::Spectrum::Constant(2.f)},
                                              {Vec3(3.f, 0.f, 0.f), 0.25f, S::Spectrum::Constant(1.f)}};
    const std::vector<PointLight<S>> points{{Vec3(0.f, -2.f, 0.f), S::Spectrum::Constant(1.f)}};
    const LightSampler<S, QuadLight<S>, SphereLight<S>, PointLight<S>> power(LightSelection::Power, 1.f, quads, spheres, points);
    const LightSampler<S, QuadLight<S>, SphereLight<S>, PointLight<S>> uniform(LightSelection::Uniform, 1.f, quads, spheres, points);
    REQUIRE(power.count() == 4);
    const double p[4] = {kPi * 4.0, kPi * 2.0 * 4.0 * kPi * 0.25, kPi * 4.0 * kPi * 0.0625, 4.0 * kPi};
    const double total = p[0] + p[1] + p[2] + p[3];
    for (int i = 0; i < 4; ++i) {
        CHECK(power.selection_pdf(i) == doctest::Approx(p[i] / total).epsilon(1e-5));
        CHECK(uniform.selection_pdf(i) == doctest::Approx(0.25));
    }
    // How often each light is chosen: Binomial(n, pmf), within 5 standard deviations.
    Pcg32 rng(4, 4);
    const int n = 40000;
    std::array<int, 4> counts{};
    const Vec3 x(0.1f, 0.2f, -0.3f);
    for (int k = 0; k < n; ++k) {
        const auto l = power.sample(x, rng.uniform(), rng.uniform(), rng.uniform());
        REQUIRE(l.light >= 0);
        ++counts[std::size_t(l.light)];
        if (l.sample.pdf > 0.f && !l.sample.delta)
            CHECK(power.pdf(l.light, x, l.sample.wi) == doctest::Approx(l.sample.pdf).epsilon(1e-3));
    }
    for (int i = 0; i < 4; ++i) {
        const double q = power.selection_pdf(i);
        CHECK(std::abs(counts[std::size_t(i)] - n * q) <= 5.0 * std::sqrt(n * q * (1.0 - q)));
    }
    CHECK(power.emitted(1, Vec3(0.f, 1.f, 0.f))[0] == 2.f);
    // No lights: a valid sampler whose samples have pdf 0.
    const LightSampler<S, QuadLight<S>> none(LightSelection::Power, 1.f, {});
    CHECK(none.count() == 0);
    CHECK(none.sample(x, 0.5f, 0.5f, 0.5f).sample.pdf == 0.f);
    CHECK(none.pdf(0, x, Vec3(0.f, 1.f, 0.f)) == 0.f);
}

TEST_CASE("lights: LightSampler rejects bad lights with their value") {
    using QS = LightSampler<S, QuadLight<S>>;
    CHECK_THROWS_WITH_AS(QS(LightSelection::Uniform, 1.f, {{Vec3(0.f), Vec3(1.f, 0.f, 0.f), Vec3(2.f, 0.f, 0.f), S::Spectrum::Ones()}}),
                         doctest::Contains("QuadLight area = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(QS(LightSelection::Uniform, 1.f, {{Vec3(0.f), Vec3(1.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f), S::Spectrum(1.f, -1.f, 1.f)}}),
                         doctest::Contains("QuadLight radiance"), InvalidArgument);
    CHECK_THROWS_WITH_AS(QS(LightSelection::Power, 1.f, {{Vec3(0.f), Vec3(1.f, 0.f, 0.f), Vec3(0.f, 1.f, 0.f), S::Spectrum::Zero()}}),
                         doctest::Contains("power is > 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS((LightSampler<S, SphereLight<S>>(LightSelection::Uniform, 1.f, {{Vec3(0.f), 0.f, S::Spectrum::Ones()}})),
                         doctest::Contains("SphereLight radius = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(QS(LightSelection::Uniform, -1.f, {}), doctest::Contains("scene_radius = -1"), InvalidArgument);
    using DS = LightSampler<S, DirectionalLight<S>>;
    CHECK_THROWS_WITH_AS(DS(LightSelection::Uniform, 1.f, {{Vec3(0.f), S::Spectrum::Ones()}}),
                         doctest::Contains("DirectionalLight direction (0, 0, 0)"), InvalidArgument);
    CHECK_THROWS_WITH_AS(DS(LightSelection::Uniform, 1.f, {{Vec3(0.f, 0.f, -1.f), S::Spectrum::Constant(kInf)}}),
                         doctest::Contains("DirectionalLight irradiance"), InvalidArgument);
}

TEST_CASE("lights: a directional light is a delta light from one direction, never hit") {
    const DirectionalLight<S> sun{Vec3(0.f, 0.f, -2.f), S::Spectrum::Constant(3.f)};  // travelling down
    const auto ls = sun.sample(Vec3(1.f, 2.f, 3.f), 0.3f, 0.7f, {}, 0.25f);
    CHECK(ls.wi == Vec3(0.f, 0.f, 1.f));  // toward the light: up
    CHECK(ls.distance == kInf);
    CHECK(ls.delta);
    CHECK(ls.pdf == 0.25f);  // the selection probability alone
    CHECK(ls.radiance[0] == 3.f);
    CHECK(sun.pdf(Vec3(0.f), Vec3(0.f, 0.f, 1.f)) == 0.f);
    CHECK(sun.emitted(Vec3(0.f, 0.f, -1.f))[0] == 0.f);
    CHECK(sun.power(2.f) == doctest::Approx(kPi * 4.f * 3.f));
}

}  // namespace


namespace {

TEST_CASE("lights: emission sampling (light subpaths) matches emission_pdf and emits the light's power") {
    // For every EmittingLight model: the densities a sample reports equal emission_pdf() of its
    // point and direction (and the sampler's, selection included), the direction leaves the
    // emitting side, and E[radiance cos / (pdf_pos pdf_dir)] is the emitted power in closed form:
    // pi L A for a quad, pi L 4 pi r^2 for a sphere, 4 pi I for a point light (5 SE, fixed seed).
    using M = Mono;
    const QuadLight<M> quad{Vec3(-1.f, 2.f, 0.f), Vec3(2.f, 0.f, 0.f), Vec3(0.f, 0.f, 0.5f), M::Spectrum::Constant(3.f)};
    const SphereLight<M> sphere{Vec3(0.f, 1.f, 2.f), 0.4f, M::Spectrum::Constant(2.f)};
    const PointLight<M> point{Vec3(1.f, 1.f, 1.f), M::Spectrum::Constant(5.f)};
    const LightSampler<M, QuadLight<M>, SphereLight<M>, PointLight<M>, EnvironmentLight<M>> sampler(
        LightSelection::Uniform, 10.f, {quad}, {sphere}, {point}, {EnvironmentLight<M>{M::Spectrum::Constant(1.f)}});
    const double powers[3] = {kPi * 3.0 * 1.0, kPi * 2.0 * 4.0 * kPi * 0.16, 4.0 * kPi * 5.0};
    CHECK(sampler.emission_selection_pdf(0) == doctest::Approx(1.f / 3.f));
    CHECK(sampler.emission_selection_pdf(3) == 0.f);  // the environment starts no light subpaths
    Pcg32 rng(5, 9);
    auto check_model = [&](const auto& light, double power, int index) {
        Stat s;
        for (int i = 0; i < 20000; ++i) {
            const float u[4] = {rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()};
            const LightEmission<M> e = light.sample_emission(u[0], u[1], u[2], u[3]);
            REQUIRE(e.pdf_pos > 0.f);
            REQUIRE(e.pdf_dir > 0.f);
            const EmissionDensity d = light.emission_pdf(e.p, e.w);
            CHECK(d.pdf_pos == doctest::Approx(e.pdf_pos).epsilon(1e-4));
            CHECK(d.pdf_dir == doctest::Approx(e.pdf_dir).epsilon(1e-3));
            CHECK(d.cos == doctest::Approx(e.cos).epsilon(1e-3));
            CHECK(glm::dot(e.n, e.w) > 0.f);
            const EmissionDensity ds = sampler.emission_pdf(index, e.p, e.w);
            CHECK(ds.pdf_pos == doctest::Approx(e.pdf_pos / 3.f).epsilon(1e-4));
            s.add(double(e.radiance[0]) * e.cos / (double(e.pdf_pos) * e.pdf_dir));
        }
        CAPTURE(index);
        CAPTURE(s.mean);
        CHECK(std::abs(s.mean - power) <= kSigmas * s.se() + 1e-5 * power);
    };
    check_model(quad, powers[0], 0);
    check_model(sphere, powers[1], 1);
    check_model(point, powers[2], 2);
    // The sampler picks each emitter with its probability and reports it.
    int picked[4] = {0, 0, 0, 0};
    for (int i = 0; i < 3000; ++i) {
        const EmittedLight<M> e = sampler.sample_emission(rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform());
        REQUIRE(e.light >= 0);
        ++picked[e.light];
    }
    CHECK(picked[3] == 0);
    for (int i = 0; i < 3; ++i) CHECK(std::abs(picked[i] - 1000) < 5 * std::sqrt(3000 * (1.0 / 3) * (2.0 / 3)));
}

TEST_CASE("lights: with a BoundingSphere, lights at infinity and directional lights start light subpaths from a disk outside it") {
    // The environment's direction uniform (1 / 4 pi, selection 1/2 included in pdf_pos), the ray's
    // origin uniform on a disk of radius R facing the scene: E[L / (pdf_pos pdf_dir)] over all
    // samples (0 for the quad's) is the environment's power in closed form, L 4 pi x pi R^2
    // (5 SE, fixed seed). emission_pdf agrees with every sample at points on its ray inside the
    // sphere, and is 0 off the disk's cylinder and beyond the disk.
    using M = Mono;
    const BoundingSphere sphere{Vec3(1.f, -2.f, 0.5f), 3.f};
    const QuadLight<M> quad{Vec3(-1.f, 2.f, 0.f), Vec3(2.f, 0.f, 0.f), Vec3(0.f, 0.f, 0.5f), M::Spectrum::Constant(3.f)};
    const LightSampler<M, QuadLight<M>, EnvironmentLight<M>> sampler(LightSelection::Uniform, sphere, {quad},
                                                                     {EnvironmentLight<M>{M::Spectrum::Constant(0.7f)}});
    CHECK(sampler.emits_from_infinity());
    CHECK(sampler.emission_selection_pdf(1) == doctest::Approx(0.5f));
    const double R = 3.0, power = 0.7 * 4.0 * kPi * kPi * R * R;
    Pcg32 rng(17, 3);
    Stat s;
    int env = 0;
    const int n = 40000;
    for (int i = 0; i < n; ++i) {
        const EmittedLight<M> e = sampler.sample_emission(rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform(),
                                                          rng.uniform());
        REQUIRE(e.emission.pdf_pos > 0.f);
        if (e.light != 1) {
            CHECK_FALSE(e.emission.at_infinity);
            s.add(0.0);
            continue;
        }
        ++env;
        const LightEmission<M>& x = e.emission;
        CHECK(x.at_infinity);
        CHECK(x.pdf_pos == doctest::Approx(0.5f * kInv4Pi));
        CHECK(x.pdf_dir == doctest::Approx(1.0 / (kPi * R * R)));
        // The origin lies on the disk: R from the centre along -w, within R across.
        const Vec3 q = x.p - sphere.center;
        const float along = glm::dot(q, -x.w);
        CHECK(along == doctest::Approx(R).epsilon(1e-4));
        CHECK(glm::dot(q, q) - along * along <= float(R * R) * 1.0001f);
        for (const float t : {1.f, 3.f, 5.f}) {  // points on the ray inside the sphere
            const EmissionDensity d = sampler.emission_pdf(1, x.p + t * x.w, x.w);
            CHECK(d.pdf_pos == doctest::Approx(x.pdf_pos));
            CHECK(d.pdf_dir == doctest::Approx(x.pdf_dir));
        }
        s.add(double(x.radiance[0]) * x.cos / (double(x.pdf_pos) * x.pdf_dir));
    }
    CAPTURE(s.mean);
    CHECK(std::abs(s.mean - power) <= kSigmas * s.se());
    CHECK(std::abs(env - n / 2) < 5 * std::sqrt(n * 0.25));
    // Off the cylinder, and beyond the disk (behind where every ray starts): no ray passes there.
    const Vec3 w(0.f, 0.f, 1.f);
    CHECK(sampler.emission_pdf(1, sphere.center + Vec3(3.1f, 0.f, 0.f), w).pdf_dir == 0.f);
    CHECK(sampler.emission_pdf(1, sphere.center + Vec3(0.f, 0.f, -3.1f), w).pdf_dir == 0.f);
    CHECK(sampler.emission_pdf(1, sphere.center + Vec3(2.9f, 0.f, 2.9f), w).pdf_dir > 0.f);
    // Without a sphere the environment starts none, as before.
    const LightSampler<M, QuadLight<M>, EnvironmentLight<M>> plain(LightSelection::Uniform, 3.f, {quad},
                                                                   {EnvironmentLight<M>{M::Spectrum::Constant(0.7f)}});
    CHECK_FALSE(plain.emits_from_infinity());
    CHECK(plain.emission_selection_pdf(1) == 0.f);
    CHECK(plain.emission_pdf(1, Vec3(0.f), w).pdf_pos == 0.f);
    // A directional light, given the sphere, starts them from the same disk: its one direction
    // (pdf_pos its selection probability, delta_position), E[E cos / (pdf_pos pdf_dir)] its power
    // through the disk, E pi R^2 (exactly: every sample has the same value); without the sphere none.
    const DirectionalLight<M> sun{Vec3(0.3f, -2.f, 0.4f), M::Spectrum::Constant(1.5f)};
    const LightSampler<M, QuadLight<M>, DirectionalLight<M>> sunny(LightSelection::Uniform, sphere, {quad}, {sun});
    CHECK(sunny.emission_selection_pdf(1) == doctest::Approx(0.5f));
    int suns = 0;
    for (int i = 0; i < 1000; ++i) {
        const EmittedLight<M> e = sunny.sample_emission(rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform(),
                                                        rng.uniform());
        if (e.light != 1) continue;
        ++suns;
        const LightEmission<M>& x = e.emission;
        CHECK(x.at_infinity);
        CHECK(x.delta_position);
        CHECK(x.pdf_pos == doctest::Approx(0.5f));
        CHECK(glm::length(x.w - glm::normalize(sun.direction)) < 1e-6f);
        const Vec3 q = x.p - sphere.center;
        CHECK(glm::dot(q, -x.w) == doctest::Approx(R).epsilon(1e-4));
        CHECK(double(x.radiance[0]) * x.cos / (double(x.pdf_pos) * x.pdf_dir) ==
              doctest::Approx(2.0 * 1.5 * kPi * R * R).epsilon(1e-5));  // power E pi R^2 over selection 1/2
        const EmissionDensity d = sunny.emission_pdf(1, x.p + 2.f * x.w, x.w);
        CHECK(d.pdf_pos == doctest::Approx(x.pdf_pos));
        CHECK(d.pdf_dir == doctest::Approx(x.pdf_dir));
    }
    CHECK(suns > 400);
    const LightSampler<M, QuadLight<M>, DirectionalLight<M>> no_sphere(LightSelection::Uniform, 3.f, {quad}, {sun});
    CHECK(no_sphere.emission_selection_pdf(1) == 0.f);
    // Bad spheres are rejected with their value.
    CHECK_THROWS_WITH_AS((LightSampler<M, QuadLight<M>>(LightSelection::Uniform, BoundingSphere{Vec3(0.f), -1.f}, {quad})),
                         doctest::Contains("scene_radius = -1"), InvalidArgument);
    CHECK_THROWS_WITH_AS(
        (LightSampler<M, QuadLight<M>>(LightSelection::Uniform, BoundingSphere{Vec3(kInf, 0.f, 0.f), 1.f}, {quad})),
        doctest::Contains("BoundingSphere center"), InvalidArgument);
}

}  // namespace
