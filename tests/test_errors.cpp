// tests/test_errors.cpp: constructors reject bad input with nsp::InvalidArgument and a message
// that names the bad value and what is allowed (STYLE rule 6). Each check matches the message
// from the value through the allowed range. The checks added for issue 8 (overflow, host media,
// grid-majorant cells, Hero tabulated coefficients) are in test_validation.cpp.
#include <limits>
#include <string>

#include "common.hpp"

namespace {

using namespace nsp_test;
using doctest::Contains;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
const Box kUnitBox{Vec3(0.f), Vec3(1.f)};

/// A coefficient of mode S equal to v at every channel or wavelength. In Hero mode it is a
/// tabulated spectrum scaled by v, so a negative, NaN or infinite v reaches the constructor
/// (TabulatedSpectrum::constant would reject it itself).
template <SpectralMode S>
typename S::Coefficient coef(float v) {
    if constexpr (is_hero_v<S>) return TabulatedSpectrum::constant(1.f).scaled(v);
    else return S::Spectrum::Constant(v);
}

/// How a message names the first channel of a coefficient: "[channel 0]", or in Hero mode the
/// first table entry's wavelength, "[360 nm]".
template <SpectralMode S>
std::string first_channel() {
    return is_hero_v<S> ? "[360 nm]" : "[channel 0]";
}

/// doctest::Contains of `what` + the first channel's name + `rest`.
template <SpectralMode S>
Contains at_first(const std::string& what, const std::string& rest) {
    return Contains((what + first_channel<S>() + rest).c_str());
}

const std::string kCoefficientAllowed = " is not allowed: coefficients must be finite and >= 0";

TEST_CASE_TEMPLATE("media reject negative, NaN and infinite coefficients, naming the channel", S, Mono, Rgb, Hero<4>) {
    const auto ok = coef<S>(1.f);
    const auto neg = coef<S>(-0.5f);
    const auto nan = coef<S>(kNaN);
    const auto inf = coef<S>(kInf);

    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(kUnitBox, neg, ok),
                         at_first<S>("HomogeneousMedium sigma_a", " = -0.5" + kCoefficientAllowed), InvalidArgument);
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(kUnitBox, ok, nan),
                         at_first<S>("HomogeneousMedium sigma_s", " = nan" + kCoefficientAllowed), InvalidArgument);
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(kUnitBox, inf, ok),
                         at_first<S>("HomogeneousMedium sigma_a", " = inf" + kCoefficientAllowed), InvalidArgument);
    if constexpr (S::channels == 3) {  // the message names the offending channel
        CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(kUnitBox, spec<S>(1.f, 1.f, -3.f), ok),
                             Contains(("sigma_a[channel 2] = -3" + kCoefficientAllowed).c_str()), InvalidArgument);
    }

    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {1, 1, 1}, {1.f}, neg, ok),
                         at_first<S>("DenseGridMedium sigma_a_scale", " = -0.5" + kCoefficientAllowed), InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {1, 1, 1}, {1.f}, ok, nan),
                         at_first<S>("DenseGridMedium sigma_s_scale", " = nan" + kCoefficientAllowed), InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {2, 1, 1}, {1.f, -2.f}, ok, ok),
                         Contains("DenseGridMedium: density[1] = -2 is not allowed: densities must be finite and >= 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {2, 1, 1}, {kNaN, 1.f}, ok, ok),
                         Contains("density[0] = nan is not allowed: densities must be finite and >= 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {2, 1, 1}, {1.f, kInf}, ok, ok),
                         Contains("density[1] = inf is not allowed: densities must be finite and >= 0"), InvalidArgument);

    const Vec3 x(1.f, 0.f, 0.f);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, 1.f, 1.f, neg, ok),
                         at_first<S>("ExponentialMedium sigma_a_scale", " = -0.5" + kCoefficientAllowed), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, 1.f, 1.f, ok, inf),
                         at_first<S>("ExponentialMedium sigma_s_scale", " = inf" + kCoefficientAllowed), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, -1.f, 1.f, ok, ok),
                         Contains("ExponentialMedium d0 = -1 is not allowed: it must be finite and >= 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, kNaN, 1.f, ok, ok),
                         Contains("ExponentialMedium d0 = nan is not allowed: it must be finite and >= 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, 1.f, kNaN, ok, ok),
                         Contains("ExponentialMedium k = nan is not allowed: it must be finite"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, 1.f, -kInf, ok, ok),
                         Contains("ExponentialMedium k = -inf is not allowed: it must be finite"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, Vec3(0.f), 1.f, 1.f, ok, ok),
                         Contains("ExponentialMedium axis has length 0: it must be finite and > 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, Vec3(1.f, kNaN, 0.f), 1.f, 1.f, ok, ok),
                         Contains("ExponentialMedium axis has length nan: it must be finite and > 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, x, 1.f, 1000.f, ok, ok),
                         Contains("the largest density d0 * exp(k * s) in the box (d0 = 1, k = 1000) overflows float; "
                                  "it must be finite"),
                         InvalidArgument);
    CHECK_NOTHROW(ExponentialMedium<S>(kUnitBox, x, 0.f, -50.f, ok, ok));
}

TEST_CASE_TEMPLATE("grids reject an empty grid, a size mismatch and a bad resolution", S, Mono, Rgb, Hero<4>) {
    const auto ok = coef<S>(1.f);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {1, 1, 1}, {}, ok, ok),
                         Contains("DenseGridMedium: the density grid is empty; resolution 1x1x1 needs 1 densities"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {2, 2, 2}, std::vector<float>(5, 1.f), ok, ok),
                         Contains("DenseGridMedium: 5 densities given, but resolution 2x2x2 needs 8"), InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {4, -3, 4}, std::vector<float>(16, 1.f), ok, ok),
                         Contains("DenseGridMedium resolution[1] = -3 is not allowed: every axis needs at least 1 voxel"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {0, 1, 1}, {1.f}, ok, ok),
                         Contains("resolution[0] = 0 is not allowed: every axis needs at least 1 voxel"), InvalidArgument);
}

TEST_CASE_TEMPLATE("media reject an empty or non-finite box", S, Mono, Rgb, Hero<4>) {
    const auto ok = coef<S>(1.f);
    const Box flat{Vec3(0.f), Vec3(1.f, 0.f, 1.f)};
    const Box inverted{Vec3(0.f), Vec3(-1.f, 1.f, 1.f)};
    const Box infinite{Vec3(0.f), Vec3(1.f, 1.f, kInf)};
    const Box nan_corner{Vec3(kNaN, 0.f, 0.f), Vec3(1.f)};
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(flat, ok, ok),
                         Contains("HomogeneousMedium bounds is empty on axis 1: lo = 0 must be < hi = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(inverted, ok, ok), Contains("empty on axis 0: lo = 0 must be < hi = -1"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(infinite, ok, ok),
                         Contains("HomogeneousMedium bounds has a non-finite corner on axis 2: [0, inf]; corners must be finite"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(nan_corner, ok, ok),
                         Contains("non-finite corner on axis 0: [nan, 1]; corners must be finite"), InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(flat, {1, 1, 1}, {1.f}, ok, ok),
                         Contains("DenseGridMedium bounds is empty on axis 1: lo = 0 must be < hi = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(flat, Vec3(1.f, 0.f, 0.f), 1.f, 1.f, ok, ok),
                         Contains("ExponentialMedium bounds is empty on axis 1: lo = 0 must be < hi = 0"), InvalidArgument);
}

TEST_CASE_TEMPLATE("GlobalMajorant rejects a value below the extinction bound", S, Mono, Rgb) {
    // Extinction (sigma_a + sigma_s) = 1 + 2 = 3 in every channel (channel 2 of Rgb: 1 + 4 = 5).
    const HomogeneousMedium<S> m(kUnitBox, grey<S>(1.f), spec<S>(2.f, 2.f, 4.f));
    const std::string guaranteed = "; bound::Guaranteed requires mu_bar >= mu_t everywhere (bound::Signed, Clamp or "
                                   "Reject allow a lower majorant)";
    CHECK_THROWS_WITH_AS(GlobalMajorant<HomogeneousMedium<S>>(m, 2.5f),
                         Contains(("GlobalMajorant value = 2.5 is below the medium's extinction bound 3 in channel 0" +
                                   guaranteed).c_str()),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(GlobalMajorant<HomogeneousMedium<S>>(m, -1.f),
                         Contains("GlobalMajorant value = -1 is not allowed: it must be finite and >= 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(GlobalMajorant<HomogeneousMedium<S>>(m, kNaN),
                         Contains("GlobalMajorant value = nan is not allowed: it must be finite and >= 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(GlobalMajorant<HomogeneousMedium<S>>(m, kInf),
                         Contains("GlobalMajorant value = inf is not allowed: it must be finite and >= 0"), InvalidArgument);
    if constexpr (S::channels == 3) {
        CHECK_THROWS_WITH_AS(GlobalMajorant<HomogeneousMedium<S>>(m, 4.f),
                             Contains(("value = 4 is below the medium's extinction bound 5 in channel 2" + guaranteed).c_str()),
                             InvalidArgument);
        CHECK(GlobalMajorant<HomogeneousMedium<S>>(m).value() == 5.f);
    } else {
        CHECK(GlobalMajorant<HomogeneousMedium<S>>(m).value() == 3.f);
    }
    CHECK_NOTHROW(GlobalMajorant<HomogeneousMedium<S>>(m, 100.f));
}

TEST_CASE("HenyeyGreensteinPhase rejects g outside (-1, 1)") {
    for (const float g : {-1.f, 1.f, 1.5f, -7.f, kInf}) {
        CAPTURE(g);
        CHECK_THROWS_AS(HenyeyGreensteinPhase{g}, InvalidArgument);
    }
    CHECK_THROWS_WITH_AS(HenyeyGreensteinPhase{1.f},
                         Contains("HenyeyGreensteinPhase g = 1 is not allowed: it must lie in (-1, 1)"), InvalidArgument);
    CHECK_THROWS_WITH_AS(HenyeyGreensteinPhase{kNaN}, Contains("g = nan is not allowed: it must lie in (-1, 1)"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(HenyeyGreensteinPhase{-kInf}, Contains("g = -inf is not allowed: it must lie in (-1, 1)"),
                         InvalidArgument);
    CHECK_NOTHROW(HenyeyGreensteinPhase{0.999f});
    CHECK_NOTHROW(HenyeyGreensteinPhase{-0.999f});
}

TEST_CASE("mis::Power rejects a non-positive or non-finite exponent") {
    const std::string allowed = " is not allowed: it must be finite and > 0";
    CHECK_THROWS_WITH_AS(mis::Power(0.f), Contains(("mis::Power exponent = 0" + allowed).c_str()), InvalidArgument);
    CHECK_THROWS_WITH_AS(mis::Power(-2.f), Contains(("mis::Power exponent = -2" + allowed).c_str()), InvalidArgument);
    CHECK_THROWS_WITH_AS(mis::Power{kInf}, Contains(("mis::Power exponent = inf" + allowed).c_str()), InvalidArgument);
    CHECK_THROWS_WITH_AS(mis::Power{kNaN}, Contains(("mis::Power exponent = nan" + allowed).c_str()), InvalidArgument);
    CHECK(mis::Power(3.f).beta() == 3.f);
}

TEST_CASE_TEMPLATE("lights reject bad radius, radiance and position", S, Mono, Rgb, Hero<4>) {
    Lights<S> lights;
    const auto one = coef<S>(1.f);
    const std::string radius_allowed = " is not allowed: it must be finite and > 0";
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(5.f), 0.f, one}),
                         Contains(("SphereLight radius = 0" + radius_allowed).c_str()), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(5.f), -1.f, one}),
                         Contains(("SphereLight radius = -1" + radius_allowed).c_str()), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(5.f), kNaN, one}),
                         Contains(("SphereLight radius = nan" + radius_allowed).c_str()), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(5.f), kInf, one}),
                         Contains(("SphereLight radius = inf" + radius_allowed).c_str()), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(5.f), 1.f, coef<S>(-2.f)}),
                         at_first<S>("SphereLight radiance", " = -2" + kCoefficientAllowed), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(kNaN), 1.f, one}),
                         Contains("SphereLight center = nan is not allowed: it must be finite"), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(EnvironmentLight<S>{coef<S>(kNaN)}),
                         at_first<S>("EnvironmentLight radiance", " = nan" + kCoefficientAllowed), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(PointLight<S>{Vec3(0.f, kInf, 0.f), one}),
                         Contains("PointLight position = inf is not allowed: it must be finite"), InvalidArgument);
    CHECK_THROWS_WITH_AS(lights.set(PointLight<S>{Vec3(0.f), coef<S>(-1.f)}),
                         at_first<S>("PointLight intensity", " = -1" + kCoefficientAllowed), InvalidArgument);
    CHECK(lights.count() == 0);  // nothing was set by a rejected call
}

TEST_CASE_TEMPLATE("Scene rejects a sphere light that overlaps the medium bounds", S, Mono, Rgb, Hero<4>) {
    const HomogeneousMedium<S> m(kUnitBox, coef<S>(0.f), coef<S>(1.f));
    auto scene_with = [&](Vec3 c, float r) {
        Lights<S> l;
        l.set(SphereLight<S>{c, r, coef<S>(1.f)});
        return make_scene(m, IsotropicPhase{}, l);
    };
    const char* allowed = "overlaps the medium bounds; lights must lie outside the medium";
    // Centre inside the box.
    CHECK_THROWS_WITH_AS(scene_with(Vec3(0.5f), 0.1f),
                         Contains((std::string("SphereLight (centre 0.5, 0.5, 0.5, radius 0.1) ") + allowed).c_str()),
                         InvalidArgument);
    // Centre outside, but the sphere reaches into the box (distance 0.5 to the face x = 1).
    CHECK_THROWS_WITH_AS(scene_with(Vec3(1.5f, 0.5f, 0.5f), 0.6f),
                         Contains((std::string("(centre 1.5, 0.5, 0.5, radius 0.6) ") + allowed).c_str()), InvalidArgument);
    // A sphere that contains the whole box.
    CHECK_THROWS_WITH_AS(scene_with(Vec3(0.5f), 10.f), Contains(allowed), InvalidArgument);
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
    const char* survival = " is not allowed: it must lie in (0, 1]";
    CHECK_THROWS_WITH_AS(E(opts(-1, 3, 0.9f)),
                         Contains("EstimatorOptions max_depth = -1 is not allowed: it must be >= 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(E(opts(10, 0, 0.9f)),
                         Contains("EstimatorOptions rr_start_depth = 0 is not allowed: it must be >= 1"), InvalidArgument);
    CHECK_THROWS_WITH_AS(E(opts(10, 3, 0.f)),
                         Contains((std::string("EstimatorOptions rr_max_survival = 0") + survival).c_str()), InvalidArgument);
    CHECK_THROWS_WITH_AS(E(opts(10, 3, 1.5f)), Contains((std::string("rr_max_survival = 1.5") + survival).c_str()),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(E(opts(10, 3, kNaN)), Contains((std::string("rr_max_survival = nan") + survival).c_str()),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(E(opts(10, 3, -kInf)), Contains((std::string("rr_max_survival = -inf") + survival).c_str()),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS((PathEstimator<strategy::Unidirectional>(opts(10, -4, 0.5f))),
                         Contains("rr_start_depth = -4 is not allowed: it must be >= 1"), InvalidArgument);
    // The spectral estimator validates the same options.
    CHECK_THROWS_WITH_AS((SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>(opts(-2, 3, 0.9f))),
                         Contains("EstimatorOptions max_depth = -2 is not allowed: it must be >= 0"), InvalidArgument);
    CHECK_NOTHROW(E(opts(0, 1, 1.f)));
}

}  // namespace
