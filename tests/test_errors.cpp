// tests/test_errors.cpp: constructors reject bad input with nsp::InvalidArgument and a message
// that names the bad value (STYLE rule 6).
#include <limits>

#include "common.hpp"

namespace {

using namespace nsp_test;
using doctest::Contains;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
const Box kUnitBox{Vec3(0.f), Vec3(1.f)};

TEST_CASE_TEMPLATE("media reject negative and NaN coefficients", S, Mono, Rgb) {
    const auto ok = grey<S>(1.f);
    const auto neg = grey<S>(-0.5f);
    const auto nan = grey<S>(kNaN);

    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(kUnitBox, neg, ok), Contains("sigma_a[channel 0] = -0.5"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(kUnitBox, ok, nan), Contains("sigma_s[channel 0] = nan"),
                         InvalidArgument);
    if constexpr (S::channels == 3) {  // the message names the offending channel
        CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(kUnitBox, spec<S>(1.f, 1.f, -3.f), ok),
                             Contains("[channel 2] = -3"), InvalidArgument);
    }

    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {1, 1, 1}, {1.f}, neg, ok),
                         Contains("sigma_a_scale[channel 0] = -0.5"), InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {1, 1, 1}, {1.f}, ok, nan),
                         Contains("sigma_s_scale[channel 0] = nan"), InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {2, 1, 1}, {1.f, -2.f}, ok, ok),
                         Contains("density[1] = -2"), InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {2, 1, 1}, {kNaN, 1.f}, ok, ok),
                         Contains("density[0] = nan"), InvalidArgument);

    const Vec3 x(1.f, 0.f, 0.f);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, 1.f, 1.f, neg, ok),
                         Contains("sigma_a_scale[channel 0] = -0.5"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, 1.f, 1.f, ok, nan),
                         Contains("sigma_s_scale[channel 0] = nan"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, -1.f, 1.f, ok, ok), Contains("d0 = -1"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, kNaN, 1.f, ok, ok), Contains("d0 = nan"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, 1.f, kNaN, ok, ok), Contains("k = nan"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, Vec3(0.f), 1.f, 1.f, ok, ok),
                         Contains("axis has length 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, 1.f, 1000.f, ok, ok), Contains("k = 1000"),
                         InvalidArgument);
}

TEST_CASE_TEMPLATE("grids reject an empty grid, a size mismatch and a bad resolution", S, Mono, Rgb) {
    const auto ok = grey<S>(1.f);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {1, 1, 1}, {}, ok, ok), Contains("density grid is empty"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {2, 2, 2}, std::vector<float>(5, 1.f), ok, ok),
                         Contains("5 densities given, but resolution 2x2x2 needs 8"), InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {4, -3, 4}, std::vector<float>(16, 1.f), ok, ok),
                         Contains("resolution[1] = -3"), InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {0, 1, 1}, {1.f}, ok, ok), Contains("resolution[0] = 0"),
                         InvalidArgument);
}

TEST_CASE_TEMPLATE("media reject an empty or non-finite box", S, Mono, Rgb) {
    const auto ok = grey<S>(1.f);
    const Box flat{Vec3(0.f), Vec3(1.f, 0.f, 1.f)};
    const Box inverted{Vec3(0.f), Vec3(-1.f, 1.f, 1.f)};
    const Box infinite{Vec3(0.f), Vec3(1.f, 1.f, kInf)};
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(flat, ok, ok), Contains("empty on axis 1: lo = 0 must be < hi = 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(inverted, ok, ok), Contains("empty on axis 0: lo = 0 must be < hi = -1"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(infinite, ok, ok), Contains("non-finite corner on axis 2"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(flat, {1, 1, 1}, {1.f}, ok, ok), Contains("DenseGridMedium bounds"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(flat, Vec3(1.f, 0.f, 0.f), 1.f, 1.f, ok, ok),
                         Contains("ExponentialMedium bounds"), InvalidArgument);
}

TEST_CASE_TEMPLATE("GlobalMajorant rejects a value below the extinction bound", S, Mono, Rgb) {
    // Extinction (sigma_a + sigma_s) = 1 + 2 = 3 in every channel (channel 2 of Rgb: 1 + 4 = 5).
    const HomogeneousMedium<S> m(kUnitBox, grey<S>(1.f), spec<S>(2.f, 2.f, 4.f));
    CHECK_THROWS_WITH_AS(GlobalMajorant<HomogeneousMedium<S>>(m, 2.5f), Contains("value = 2.5 is below"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(GlobalMajorant<HomogeneousMedium<S>>(m, -1.f), Contains("value = -1"), InvalidArgument);
    CHECK_THROWS_WITH_AS(GlobalMajorant<HomogeneousMedium<S>>(m, kNaN), Contains("value = nan"), InvalidArgument);
    if constexpr (S::channels == 3) {
        CHECK_THROWS_WITH_AS(GlobalMajorant<HomogeneousMedium<S>>(m, 4.f), Contains("bound 5 in channel 2"),
                             InvalidArgument);
        CHECK(GlobalMajorant<HomogeneousMedium<S>>(m).value() == 5.f);
    } else {
        CHECK(GlobalMajorant<HomogeneousMedium<S>>(m).value() == 3.f);
    }
    CHECK_NOTHROW(GlobalMajorant<HomogeneousMedium<S>>(m, 100.f));
}

TEST_CASE("HenyeyGreensteinPhase rejects g outside (-1, 1)") {
    for (const float g : {-1.f, 1.f, 1.5f, -7.f}) {
        CAPTURE(g);
        CHECK_THROWS_AS(HenyeyGreensteinPhase{g}, InvalidArgument);
    }
    CHECK_THROWS_WITH_AS(HenyeyGreensteinPhase{1.f}, Contains("g = 1 is not allowed"), InvalidArgument);
    CHECK_THROWS_WITH_AS(HenyeyGreensteinPhase{kNaN}, Contains("g = nan"), InvalidArgument);
    CHECK_NOTHROW(HenyeyGreensteinPhase{0.999f});
    CHECK_NOTHROW(HenyeyGreensteinPhase{-0.999f});
}

TEST_CASE("mis::Power rejects a non-positive or non-finite exponent") {
    CHECK_THROWS_WITH_AS(mis::Power(0.f), Contains("exponent = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(mis::Power(-2.f), Contains("exponent = -2"), InvalidArgument);
    CHECK_THROWS_WITH_AS(mis::Power{kInf}, Contains("exponent = inf"), InvalidArgument);
    CHECK_THROWS_WITH_AS(mis::Power{kNaN}, Contains("exponent = nan"), InvalidArgument);
    CHECK(mis::Power(3.f).beta() == 3.f);
}

TEST_CASE_TEMPLATE("lights reject bad radius, radiance and position", S, Mono, Rgb) {
    Lights<S> lights;
    const auto one = grey<S>(1.f);
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(5.f), 0.f, one}), Contains("radius = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(5.f), -1.f, one}), Contains("radius = -1"), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(5.f), kNaN, one}), Contains("radius = nan"), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(5.f), 1.f, grey<S>(-2.f)}),
                         Contains("SphereLight radiance[channel 0] = -2"), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(kNaN), 1.f, one}), Contains("SphereLight center = nan"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(EnvironmentLight<S>{grey<S>(kNaN)}),
                         Contains("EnvironmentLight radiance[channel 0] = nan"), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(PointLight<S>{Vec3(0.f, kInf, 0.f), one}), Contains("PointLight position = inf"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(PointLight<S>{Vec3(0.f), grey<S>(-1.f)}),
                         Contains("PointLight intensity[channel 0] = -1"), InvalidArgument);
    CHECK(lights.count() == 0);  // nothing was set by a rejected call
}

TEST_CASE_TEMPLATE("Scene rejects a sphere light that overlaps the medium bounds", S, Mono, Rgb) {
    const HomogeneousMedium<S> m(kUnitBox, grey<S>(0.f), grey<S>(1.f));
    auto scene_with = [&](Vec3 c, float r) {
        Lights<S> l;
        l.set(SphereLight<S>{c, r, grey<S>(1.f)});
        return make_scene(m, IsotropicPhase{}, l);
    };
    // Centre inside the box.
    CHECK_THROWS_WITH_AS(scene_with(Vec3(0.5f), 0.1f), Contains("radius 0.1) overlaps the medium bounds"),
                         InvalidArgument);
    // Centre outside, but the sphere reaches into the box (distance 0.5 to the face x = 1).
    CHECK_THROWS_WITH_AS(scene_with(Vec3(1.5f, 0.5f, 0.5f), 0.6f), Contains("centre 1.5, 0.5, 0.5"),
                         InvalidArgument);
    // A sphere that contains the whole box.
    CHECK_THROWS_AS(scene_with(Vec3(0.5f), 10.f), InvalidArgument);
    // Just outside is fine.
    CHECK_NOTHROW(scene_with(Vec3(1.5f, 0.5f, 0.5f), 0.4f));
}

TEST_CASE("EstimatorOptions out of range are rejected by the estimator") {
    using E = PathEstimator<strategy::NullScatteringMis, mis::Balance>;
    auto opts = [](int depth, int rr_start, float q) {
        EstimatorOptions o;
        o.max_depth = depth;
        o.rr_start_depth = rr_start;
        o.rr_max_survival = q;
        return o;
    };
    CHECK_THROWS_WITH_AS(E(opts(-1, 3, 0.9f)), Contains("max_depth = -1"), InvalidArgument);
    CHECK_THROWS_WITH_AS(E(opts(10, 0, 0.9f)), Contains("rr_start_depth = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(E(opts(10, 3, 0.f)), Contains("rr_max_survival = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(E(opts(10, 3, 1.5f)), Contains("rr_max_survival = 1.5"), InvalidArgument);
    CHECK_THROWS_WITH_AS(E(opts(10, 3, kNaN)), Contains("rr_max_survival = nan"), InvalidArgument);
    CHECK_THROWS_WITH_AS((PathEstimator<strategy::Unidirectional>(opts(10, -4, 0.5f))),
                         Contains("rr_start_depth = -4"), InvalidArgument);
    CHECK_NOTHROW(E(opts(0, 1, 1.f)));
}

}  // namespace
