// tests/test_validation.cpp: the input checks of issue 8 that test_errors.cpp does not cover:
// values that overflow float (extinction bounds, emission, sphere radius, selection weights), box
// extents, voxel counts, tabulated coefficients made invalid after they were built, every bound
// policy's allowed majorant values and scales, and the checks majorants make of host media nsp
// does not validate. Each check matches the message from the bad value through what is allowed.
#include <limits>
#include <sstream>
#include <string>

#include "common.hpp"

namespace {

using namespace nsp_test;
using doctest::Contains;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kDenormMin = std::numeric_limits<float>::denorm_min();  // prints as 1.4013e-45
const Box kUnitBox{Vec3(0.f), Vec3(1.f)};

/// A coefficient of mode S equal to v everywhere (Hero: a tabulated spectrum scaled by v, so
/// values TabulatedSpectrum::constant would reject still reach the constructor under test).
template <SpectralMode S>
typename S::Coefficient coef(float v) {
    if constexpr (is_hero_v<S>) return TabulatedSpectrum::constant(1.f).scaled(v);
    else return S::Spectrum::Constant(v);
}

/// doctest::Contains of a message part built as a std::string.
Contains has(const std::string& s) { return Contains(s.c_str()); }

// ---------------------------------------------------------------------------------------------
// Media

TEST_CASE_TEMPLATE("media reject an extinction bound that overflows float", S, Mono, Rgb, Hero<4>) {
    const std::string allowed = " = inf is not allowed: it must be finite (at most 3.40282e+38); scale the "
                                "coefficients or densities down";
    // 3e38 + 3e38 overflows; each is a valid coefficient on its own.
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(kUnitBox, coef<S>(3e38f), coef<S>(3e38f)),
                         has("HomogeneousMedium extinction bound max(sigma_a + sigma_s)" + allowed), InvalidArgument);
    // 1e30 density x (1e10 + 1e10) per unit density overflows.
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {1, 1, 1}, {1e30f}, coef<S>(1e10f), coef<S>(1e10f)),
                         has("DenseGridMedium extinction bound max(sigma_a_scale + sigma_s_scale) x max density" + allowed),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(kUnitBox, Vec3(0.f, 0.f, 1.f), 1e30f, 0.f, coef<S>(1e10f), coef<S>(0.f)),
                         has("ExponentialMedium extinction bound max(sigma_a_scale + sigma_s_scale) x max density" + allowed),
                         InvalidArgument);
    CHECK_NOTHROW(HomogeneousMedium<S>(kUnitBox, coef<S>(1e38f), coef<S>(1e38f)));
}

TEST_CASE_TEMPLATE("media reject a box whose extent or 1 / extent overflows", S, Mono, Rgb, Hero<4>) {
    const auto ok = coef<S>(1.f);
    const Box huge{Vec3(-3e38f, 0.f, 0.f), Vec3(3e38f, 1.f, 1.f)};  // finite corners, extent inf
    const Box tiny{Vec3(0.f), Vec3(1.f, 1e-39f, 1.f)};              // extent > 0, 1 / extent inf
    const std::string allowed = "; it is not allowed: the extent and 1 / extent must be finite";
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(huge, ok, ok),
                         has("HomogeneousMedium bounds has extent hi - lo = inf on axis 0 ([-3e+38, 3e+38])" + allowed),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(tiny, {1, 1, 1}, {1.f}, ok, ok),
                         has("DenseGridMedium bounds has extent hi - lo = 1e-39 on axis 1 ([0, 1e-39])" + allowed),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ExponentialMedium<S>(huge, Vec3(1.f, 0.f, 0.f), 1.f, 0.f, ok, ok),
                         has("ExponentialMedium bounds has extent hi - lo = inf on axis 0 ([-3e+38, 3e+38])" + allowed), InvalidArgument);
    CHECK_THROWS_WITH_AS(EmissionGrid(tiny, {1, 1, 1}, {1.f}),
                         has("EmissionGrid bounds has extent hi - lo = 1e-39 on axis 1 ([0, 1e-39])" + allowed),
                         InvalidArgument);
    CHECK_NOTHROW(HomogeneousMedium<S>(Box{Vec3(-1e38f), Vec3(1e38f)}, ok, ok));
}

TEST_CASE("voxel grids reject a resolution whose voxel count a vector cannot hold") {
    // 2^21 per axis: 2^63 voxels, which wrapped around in size_t before it was checked.
    const std::array<int, 3> res{1 << 21, 1 << 21, 1 << 21};
    CHECK_THROWS_WITH_AS(DenseGridMedium<Mono>(kUnitBox, res, {1.f}, coef<Mono>(1.f), coef<Mono>(1.f)),
                         Contains("DenseGridMedium resolution 2097152x2097152x2097152 has 9.22337e+18 voxels; at most "),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(EmissionGrid(kUnitBox, res, {1.f}),
                         Contains("EmissionGrid resolution 2097152x2097152x2097152 has 9.22337e+18 voxels; at most "),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(EmissionGrid(kUnitBox, {2, 1, 1}, {}),
                         Contains("EmissionGrid: the value grid is empty; resolution 2x1x1 needs 2 values"), InvalidArgument);
}

TEST_CASE("Hero coefficients made negative or infinite after they were built are rejected, naming the wavelength") {
    using S = Hero<4>;
    const auto ok = coef<S>(1.f);
    // A bump at 500 nm (table entry 14), 0 elsewhere, negated: only that entry is < 0 (-0 is allowed).
    const TabulatedSpectrum bump = TabulatedSpectrum::from_points({490.f, 500.f, 510.f}, {0.f, 1.f, 0.f});
    CHECK_THROWS_WITH_AS(HomogeneousMedium<S>(kUnitBox, ok, bump.scaled(-1.f)),
                         Contains("HomogeneousMedium sigma_s[500 nm] = -1 is not allowed: coefficients must be finite and >= 0"),
                         InvalidArgument);
    // The sum of two valid spectra can overflow.
    const TabulatedSpectrum big = TabulatedSpectrum::constant(3e38f);
    CHECK_THROWS_WITH_AS(Lights<S>().set(EnvironmentLight<S>{big + big}),
                         Contains("EnvironmentLight radiance[360 nm] = inf is not allowed: coefficients must be finite and >= 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(DenseGridMedium<S>(kUnitBox, {1, 1, 1}, {1.f}, bump.scaled(kNaN), ok),
                         Contains("DenseGridMedium sigma_a_scale[360 nm] = nan is not allowed"), InvalidArgument);
    CHECK_NOTHROW(HomogeneousMedium<S>(kUnitBox, ok, bump));
}

TEST_CASE("TabulatedSpectrum rejects non-finite wavelengths and values, empty input and repeated wavelengths") {
    CHECK_THROWS_WITH_AS(TabulatedSpectrum::from_points({400.f, kNaN}, {1.f, 1.f}),
                         Contains("TabulatedSpectrum wavelength = nan is not allowed: it must be finite"), InvalidArgument);
    CHECK_THROWS_WITH_AS(TabulatedSpectrum::from_points({400.f, 500.f}, {1.f, kInf}),
                         Contains("TabulatedSpectrum value = inf is not allowed: it must be finite and >= 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(TabulatedSpectrum::constant(-2.f),
                         Contains("TabulatedSpectrum value = -2 is not allowed: it must be finite and >= 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(TabulatedSpectrum::from_points({}, {}),
                         Contains("TabulatedSpectrum: 0 wavelengths and 0 values given; both must be non-empty and of "
                                  "equal size"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(TabulatedSpectrum::from_points({400.f, 400.f}, {1.f, 2.f}),
                         Contains("TabulatedSpectrum: wavelength[1] = 400 is not above wavelength[0] = 400; wavelengths "
                                  "must increase"),
                         InvalidArgument);
}

// ---------------------------------------------------------------------------------------------
// Emission

TEST_CASE_TEMPLATE("Emissive rejects a bad radiance_scale and an emission that overflows", S, Mono, Rgb, Hero<4>) {
    const HomogeneousMedium<S> m(kUnitBox, coef<S>(1.f), coef<S>(1.f));
    const EmissionGrid e(kUnitBox, {1, 1, 1}, {1.f});
    const std::string first = is_hero_v<S> ? "[360 nm]" : "[channel 0]";
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<S>>(m, e, coef<S>(-0.5f)),
                         has("Emissive radiance_scale" + first +
                             " = -0.5 is not allowed: coefficients must be finite and >= 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<S>>(m, e, coef<S>(kInf)),
                         has("Emissive radiance_scale" + first + " = inf is not allowed"), InvalidArgument);
    // 1e30 x 1e10 overflows although each factor is finite.
    const EmissionGrid bright(kUnitBox, {1, 1, 1}, {1e30f});
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<S>>(m, bright, coef<S>(1e10f)),
                         Contains("Emissive: the largest emission L_e = emission grid max 1e+30 x radiance_scale max 1e+10 "
                                  "= inf is not allowed: it must be finite (at most 3.40282e+38)"),
                         InvalidArgument);
    CHECK_NOTHROW(Emissive<HomogeneousMedium<S>>(m, bright, coef<S>(1e8f)));
}

TEST_CASE("Emissive rejects power-grid cells too thin or too small for float") {
    // Cells of 1e-15 per axis: volume 1e-45 (a denormal), whose reciprocal overflows.
    const Box speck{Vec3(0.f), Vec3(1e-15f)};
    const HomogeneousMedium<Mono> m(speck, coef<Mono>(1.f), coef<Mono>(1.f));
    const EmissionGrid e(speck, {1, 1, 1}, {1.f});
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<Mono>>(m, e, coef<Mono>(1.f), {1, 1, 1}),
                         Contains("Emissive: the power grid's cells have volume 1.4013e-45, too small for a float pdf: "
                                  "1 / volume must be finite; choose a lower power_resolution or a larger box"),
                         InvalidArgument);
    // 8 ulps wide on axis 2: 16 cells would need planes between consecutive floats.
    const float hi = 1.f + 8.f * std::numeric_limits<float>::epsilon();
    const Box thin{Vec3(0.f, 0.f, 1.f), Vec3(1.f, 1.f, hi)};
    const HomogeneousMedium<Mono> mt(thin, coef<Mono>(1.f), coef<Mono>(1.f));
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<Mono>>(mt, EmissionGrid(thin, {1, 1, 1}, {1.f}), coef<Mono>(1.f),
                                                            {1, 1, 16}),
                         Contains("on axis 2 has cells too thin for float at power_resolution[2] = 16; choose a lower "
                                  "resolution"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<Mono>>(mt, EmissionGrid(thin, {1, 1, 1}, {1.f}), coef<Mono>(1.f),
                                                            {1, -2, 1}),
                         Contains("Emissive power_resolution[1] = -2 is not allowed: it must lie in [1, 256]"),
                         InvalidArgument);
}

// ---------------------------------------------------------------------------------------------
// Majorants and bound policies

using Grid = DenseGridMedium<Rgb>;

/// A grid of one voxel of density 1 with sigma_a = 1, sigma_s = 2: extinction bound 3.
Grid three() { return Grid(kUnitBox, {1, 1, 1}, {1.f}, grey<Rgb>(1.f), grey<Rgb>(2.f)); }

TEST_CASE_TEMPLATE("each bound policy rejects the majorant values and scales it forbids", B, bound::Guaranteed,
                   bound::Signed, bound::Clamp, bound::Reject) {
    const Grid m = three();
    const Grid empty(kUnitBox, {1, 1, 1}, {0.f}, grey<Rgb>(1.f), grey<Rgb>(2.f));
    CAPTURE(B::name);

    // Values: never negative, NaN or infinite; never 0 for a medium that is not empty.
    const std::string value_allowed = " is not allowed: it must be finite and >= 0";
    CHECK_THROWS_WITH_AS((GlobalMajorant<Grid, B>(m, -1.f)), has("GlobalMajorant value = -1" + value_allowed),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS((GlobalMajorant<Grid, B>(m, kNaN)), has("GlobalMajorant value = nan" + value_allowed),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS((GlobalMajorant<Grid, B>(m, kInf)), has("GlobalMajorant value = inf" + value_allowed),
                         InvalidArgument);
    const std::string guaranteed = "; bound::Guaranteed requires mu_bar >= mu_t everywhere (bound::Signed, Clamp or "
                                   "Reject allow a lower majorant)";
    if constexpr (B::allows_below) {
        CHECK_THROWS_WITH_AS((GlobalMajorant<Grid, B>(m, 0.f)),
                             Contains("GlobalMajorant value = 0 is not allowed for a medium with extinction bound 3 over "
                                      "every channel: no collision would ever be sampled; it must be > 0"),
                             InvalidArgument);
        CHECK_NOTHROW(GlobalMajorant<Grid, B>(m, 1.5f));  // below the bound: allowed
    } else {
        CHECK_THROWS_WITH_AS((GlobalMajorant<Grid, B>(m, 0.f)),
                             has("GlobalMajorant value = 0 is below the medium's extinction bound 3 in channel 0" + guaranteed),
                             InvalidArgument);
        CHECK_THROWS_WITH_AS((GlobalMajorant<Grid, B>(m, 1.5f)),
                             has("GlobalMajorant value = 1.5 is below the medium's extinction bound 3 in channel 0" + guaranteed),
                             InvalidArgument);
    }
    CHECK_NOTHROW(GlobalMajorant<Grid, B>(empty, 0.f));  // an empty medium may have majorant 0
    CHECK_NOTHROW(GlobalMajorant<Grid, B>(m, 3.f));

    // Scales: finite and > 0 under every policy, >= 1 under bound::Guaranteed.
    const std::string scale_allowed = " is not allowed: it must be finite and > 0";
    for (const float s : {0.f, -1.f, kNaN, kInf}) {
        CAPTURE(s);
        std::ostringstream v;
        v << s;
        CHECK_THROWS_WITH_AS((GridMajorant<Grid, B>(m, 2, s)), has("GridMajorant scale = " + v.str() + scale_allowed),
                             InvalidArgument);
        CHECK_THROWS_WITH_AS((ChannelGridMajorant<Grid, B>(m, 2, s)),
                             has("ChannelGridMajorant scale = " + v.str() + scale_allowed), InvalidArgument);
        CHECK_THROWS_WITH_AS((ChannelMajorant<Grid, B>(m, s)), has("ChannelMajorant scale = " + v.str() + scale_allowed),
                             InvalidArgument);
    }
    const std::string below_one = " is below 1: bound::Guaranteed requires mu_bar >= mu_t everywhere (bound::Signed, "
                                  "Clamp or Reject allow a scale below 1)";
    if constexpr (B::allows_below) {
        CHECK_NOTHROW(GridMajorant<Grid, B>(m, 2, 0.5f));
        CHECK_NOTHROW(ChannelGridMajorant<Grid, B>(m, 2, 0.5f));
        CHECK_NOTHROW(ChannelMajorant<Grid, B>(m, 0.5f));
        // A scale so small that the cell majorant rounds to 0 where mu_t = 0.003 is forbidden too.
        const Grid faint(kUnitBox, {1, 1, 1}, {1e-3f}, grey<Rgb>(1.f), grey<Rgb>(2.f));
        CHECK_THROWS_WITH_AS((GridMajorant<Grid, B>(faint, 1, kDenormMin)),
                             Contains("GridMajorant cell (0, 0, 0) majorant = density bound 0.001 x scale 1.4013e-45 x "
                                      "extinction per density 3 rounds to 0 where the extinction may be 0.003; it must "
                                      "be > 0 there (no collision would be sampled)"),
                             InvalidArgument);
    } else {
        CHECK_THROWS_WITH_AS((GridMajorant<Grid, B>(m, 2, 0.5f)), has("GridMajorant scale = 0.5" + below_one),
                             InvalidArgument);
        CHECK_THROWS_WITH_AS((ChannelGridMajorant<Grid, B>(m, 2, 0.99f)),
                             has("ChannelGridMajorant scale = 0.99" + below_one), InvalidArgument);
        CHECK_THROWS_WITH_AS((ChannelMajorant<Grid, B>(m, 0.5f)), has("ChannelMajorant scale = 0.5" + below_one),
                             InvalidArgument);
    }
}

TEST_CASE("GlobalMajorant in Hero mode names the bound over every wavelength") {
    using M = HomogeneousMedium<Hero<4>>;
    const M m(kUnitBox, TabulatedSpectrum::constant(1.f), TabulatedSpectrum::constant(2.f));
    CHECK_THROWS_WITH_AS(GlobalMajorant<M>(m, 2.5f),
                         Contains("GlobalMajorant value = 2.5 is below the medium's extinction bound 3 over every "
                                  "channel; bound::Guaranteed requires mu_bar >= mu_t everywhere"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS((GlobalMajorant<M, bound::Reject>(m, 0.f)),
                         Contains("GlobalMajorant value = 0 is not allowed for a medium with extinction bound 3"),
                         InvalidArgument);
    CHECK_NOTHROW(GlobalMajorant<M, bound::Reject>(m, 1.f));
}

TEST_CASE("grid majorants reject resolutions outside [1, 4096] and more than 2^28 cells") {
    const Grid m = three();
    CHECK_THROWS_WITH_AS(GridMajorant<Grid>(m, {4, 4, 4097}),
                         Contains("GridMajorant resolution[2] = 4097 is not allowed: it must lie in [1, 4096]"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelGridMajorant<Grid>(m, 0),
                         Contains("ChannelGridMajorant resolution[0] = 0 is not allowed: it must lie in [1, 4096]"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelGridMajorant<Grid>(m, {4096, 32, 4096}),
                         Contains("ChannelGridMajorant resolution 4096x32x4096 has 536870912 cells; at most 2^28 are "
                                  "allowed"),
                         InvalidArgument);
}

TEST_CASE("majorants reject a bound or cell value that overflows float") {
    // Extinction bound 2e38 is finite; twice it is not.
    const Grid dense(kUnitBox, {1, 1, 1}, {1e38f}, grey<Rgb>(1.f), grey<Rgb>(1.f));
    CHECK_THROWS_WITH_AS(ChannelMajorant<Grid>(dense, 2.f),
                         Contains("ChannelMajorant: the medium's extinction bound x scale[channel 0] = inf is not allowed: "
                                  "coefficients must be finite and >= 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(GridMajorant<Grid>(dense, 1, 2.f),
                         Contains("GridMajorant cell (0, 0, 0) majorant = density bound 1e+38 x scale 2 x extinction per "
                                  "density 2 = inf is not allowed: it must be finite"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelGridMajorant<Grid>(dense, 1, 2.f), Contains("ChannelGridMajorant cell (0, 0, 0) majorant"),
                         InvalidArgument);
    CHECK_NOTHROW(GridMajorant<Grid>(dense, 1));
    CHECK_NOTHROW(ChannelMajorant<Grid>{dense});
}

/// A host medium nsp does not validate: a RegionBoundedMedium with whatever bounds, extinction per
/// unit density and density bound the test sets, to reach the checks majorants make of their medium.
struct HostMedium {
    using Spectral = Mono;
    Box box{Vec3(0.f), Vec3(1.f)};
    float per_density = 1.f;  ///< extinction per unit density
    float density = 1.f;      ///< the density bound of every region

    Box bounds() const noexcept { return box; }
    Coefficients<Mono> coefficients(const Vec3&, const Mono::Wavelengths&) const noexcept {
        return {Mono::Spectrum::Zero(), Mono::Spectrum::Constant(per_density * density)};
    }
    Mono::Spectrum extinction_bound(const Mono::Wavelengths&) const noexcept {
        return Mono::Spectrum::Constant(max_extinction());
    }
    float max_extinction() const noexcept { return per_density * density; }
    Mono::Coefficient extinction_bound_coefficient() const { return Mono::Spectrum::Constant(max_extinction()); }
    float density_bound(const Box&) const noexcept { return density; }
    Mono::Coefficient extinction_per_density() const { return Mono::Spectrum::Constant(per_density); }
};
static_assert(RegionBoundedMedium<HostMedium>);

TEST_CASE("majorants reject a host medium's non-finite bounds, extinction or density bound") {
    HostMedium inf_extinction;
    inf_extinction.density = kInf;
    CHECK_THROWS_WITH_AS(GlobalMajorant<HostMedium>{inf_extinction},
                         Contains("GlobalMajorant: the medium's extinction bound = inf is not allowed: it must be finite "
                                  "and >= 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(GridMajorant<HostMedium>(inf_extinction, 2),
                         Contains("GridMajorant cell (0, 0, 0): the medium's density bound = inf is not allowed: it must "
                                  "be finite and >= 0"),
                         InvalidArgument);

    HostMedium open;
    open.box.hi.y = kInf;
    CHECK_THROWS_WITH_AS(GridMajorant<HostMedium>(open, 2),
                         Contains("GridMajorant: the medium's bounds on axis 1 are [0, inf]; they must be finite with lo < hi"),
                         InvalidArgument);
    HostMedium wide;
    wide.box = Box{Vec3(-3e38f, 0.f, 0.f), Vec3(3e38f, 1.f, 1.f)};
    CHECK_THROWS_WITH_AS(ChannelGridMajorant<HostMedium>(wide, 4),
                         Contains("ChannelGridMajorant cell size on axis 0 = inf (bounds [-3e+38, 3e+38] over "
                                  "resolution[0] = 4) is not allowed: it must be finite and > 0"),
                         InvalidArgument);
    HostMedium speck;
    speck.box.hi.z = kDenormMin;
    CHECK_THROWS_WITH_AS(GridMajorant<HostMedium>(speck, 2),
                         Contains("GridMajorant cell size on axis 2 = 0 (bounds [0, 1.4013e-45] over resolution[2] = 2) "
                                  "is not allowed: it must be finite and > 0"),
                         InvalidArgument);
    HostMedium nan_coefficient;
    nan_coefficient.per_density = kNaN;
    CHECK_THROWS_WITH_AS(GridMajorant<HostMedium>(nan_coefficient, 2),
                         Contains("GridMajorant: the medium's extinction per unit density[channel 0] = nan is not allowed: "
                                  "coefficients must be finite and >= 0"),
                         InvalidArgument);
    CHECK_NOTHROW(GridMajorant<HostMedium>(HostMedium{}, 2));
}

TEST_CASE_TEMPLATE("Scene rejects a global majorant its bound policy forbids for the scene's medium", B,
                   bound::Guaranteed, bound::Signed, bound::Clamp, bound::Reject) {
    // A majorant built for a thinner medium (bound 1.5) paired with one of bound 3.
    using H = HomogeneousMedium<Rgb>;
    const H thin(kUnitBox, grey<Rgb>(0.5f), grey<Rgb>(1.f)), dense(kUnitBox, grey<Rgb>(1.f), grey<Rgb>(2.f));
    const H empty(kUnitBox, grey<Rgb>(0.f), grey<Rgb>(0.f));
    using Sc = Scene<H, GlobalMajorant<H, B>, IsotropicPhase>;
    CAPTURE(B::name);
    if constexpr (B::allows_below) {
        CHECK_NOTHROW(Sc(dense, GlobalMajorant<H, B>(thin), IsotropicPhase{}, Lights<Rgb>{}));
        CHECK_THROWS_WITH_AS(Sc(dense, GlobalMajorant<H, B>(empty, 0.f), IsotropicPhase{}, Lights<Rgb>{}),
                             Contains("Scene: the majorant value = 0 is not allowed for a medium with extinction bound 3 "
                                      "of the scene's medium: no collision would ever be sampled; it must be > 0"),
                             InvalidArgument);
    } else {
        CHECK_THROWS_WITH_AS(Sc(dense, GlobalMajorant<H, B>(thin), IsotropicPhase{}, Lights<Rgb>{}),
                             Contains("Scene: the majorant value = 1.5 is below the medium's extinction bound 3 of the "
                                      "scene's medium; bound::Guaranteed requires mu_bar >= mu_t everywhere"),
                             InvalidArgument);
    }
    CHECK_NOTHROW(Sc(dense, GlobalMajorant<H, B>(dense), IsotropicPhase{}, Lights<Rgb>{}));
    CHECK_NOTHROW(Sc(thin, GlobalMajorant<H, B>(dense), IsotropicPhase{}, Lights<Rgb>{}));
}

// ---------------------------------------------------------------------------------------------
// Lights and channel selection

TEST_CASE_TEMPLATE("SphereLight rejects a radius whose square overflows", S, Mono, Rgb, Hero<4>) {
    Lights<S> lights;
    CHECK_THROWS_WITH_AS(lights.set(SphereLight<S>{Vec3(0.f), 1e20f, coef<S>(1.f)}),
                         Contains("SphereLight radius = 1e+20 is not allowed: radius^2 must be finite (radius <= "
                                  "1.84467e+19)"),
                         InvalidArgument);
    CHECK_NOTHROW(lights.set(SphereLight<S>{Vec3(0.f), 1e18f, coef<S>(1.f)}));
}

TEST_CASE("ChannelSelection rejects weights whose sum overflows or whose probability rounds to 0") {
    CHECK_THROWS_WITH_AS(ChannelSelection<Rgb>(spec<Rgb>(3e38f, 3e38f, 1.f)),
                         Contains("ChannelSelection weights sum to inf, which is not allowed: the sum must be finite"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelSelection<Rgb>(spec<Rgb>(1e38f, 1e-38f, 1.f)),
                         Contains("ChannelSelection weight[1] = 1e-38 is not allowed: its probability 1e-38 / 1e+38 "
                                  "rounds to 0; every channel needs a probability > 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelSelection<Rgb>(spec<Rgb>(1.f, 1.f, -2.f)),
                         Contains("ChannelSelection weight[2] = -2 is not allowed: every channel needs a finite weight > 0"),
                         InvalidArgument);
    CHECK_NOTHROW(ChannelSelection<Rgb>(spec<Rgb>(1e30f, 1.f, 1.f)));
}

}  // namespace
