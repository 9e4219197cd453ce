// tests/test_emission.cpp: emissive media (THEORY 5.7): the emission grid's lookup and bound, the
// Emissive<M> wrapper (bit-identical to its base medium, under every majorant), and the emission
// sampler: its points follow emission_pdf, which integrates to 1, matches the pdf it reports and
// is > 0 wherever mu_a L_e is; along a ray, emission_along integrates it and sample_emission_along
// draws distances from it.
#include <algorithm>
#include <cstring>
#include <limits>
#include <vector>

#include "spectral.hpp"

TYPE_TO_STRING_AS("hero", nsp::Hero<4>);

namespace {

using namespace nsp_test;
using doctest::Contains;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
const Box kUnitBox{Vec3(0.f), Vec3(1.f)};

/// n values uniform in [lo, hi) drawn with a fixed seed.
std::vector<float> random_values(std::size_t n, float lo, float hi, std::uint64_t seed) {
    Pcg32 rng(seed, 3);
    std::vector<float> v(n);
    for (float& x : v) x = lo + (hi - lo) * rng.uniform();
    return v;
}

/// A grid of resolution `res` that is zero except voxel (x, y, z), which is 1.
std::vector<float> one_voxel(std::array<int, 3> res, int x, int y, int z) {
    std::vector<float> v(std::size_t(res[0] * res[1] * res[2]), 0.f);
    v[std::size_t(x + res[0] * (y + res[1] * z))] = 1.f;
    return v;
}

/// The intersection of two boxes (the power grid's box), computed independently of Emissive.
Box overlap(const Box& a, const Box& b) {
    Box o;
    for (int i = 0; i < 3; ++i) {
        o.lo[i] = std::max(a.lo[i], b.lo[i]);
        o.hi[i] = std::min(a.hi[i], b.hi[i]);
    }
    return o;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

template <class Spec>
bool same_bits(const Spec& a, const Spec& b) {
    for (int c = 0; c < a.size(); ++c)
        if (!same_bits(a[c], b[c])) return false;
    return true;
}

/// The chromatic test scene: a random density grid and a random emission grid over boxes that
/// overlap in part, so the power grid is their intersection.
template <SpectralMode S>
Emissive<DenseGridMedium<S>> chromatic_flame(std::array<int, 3> power_resolution) {
    const Box mb{Vec3(-1.f, 0.f, 0.f), Vec3(1.f, 2.f, 1.5f)};
    const Box eb{Vec3(-0.5f, 0.5f, -0.2f), Vec3(1.5f, 2.5f, 1.2f)};
    DenseGridMedium<S> medium(mb, {5, 4, 6}, random_values(120, 0.2f, 1.2f, 11), chroma<S>(1.f, 0.5f, 0.25f),
                              chroma<S>(0.5f, 0.5f, 0.5f));
    EmissionGrid emission(eb, {6, 5, 4}, random_values(120, 0.1f, 1.f, 12));
    return {std::move(medium), std::move(emission), chroma<S>(2.f, 1.f, 0.5f), power_resolution};
}

// ---------------------------------------------------------------------------------------------
// Concepts

using RgbGrid = DenseGridMedium<Rgb>;
static_assert(EmissiveMedium<Emissive<RgbGrid>> && EmissiveMedium<Emissive<HomogeneousMedium<Mono>>> &&
              EmissiveMedium<Emissive<ExponentialMedium<Hero<4>>>>);
static_assert(!EmissiveMedium<RgbGrid> && !EmissiveMedium<HomogeneousMedium<Rgb>> &&
              !EmissiveMedium<ExponentialMedium<Mono>>);
// The wrapper has exactly the majorant support of its base.
static_assert(RegionBoundedMedium<Emissive<ExponentialMedium<Hero<4>>>> && RegionBoundedMedium<Emissive<RgbGrid>>);
static_assert(ChannelBoundedMedium<Emissive<HomogeneousMedium<Rgb>>> &&
              !RegionBoundedMedium<Emissive<HomogeneousMedium<Rgb>>>);
static_assert(MajorantPolicy<GridMajorant<Emissive<RgbGrid>, bound::Clamp>, Emissive<RgbGrid>> &&
              MajorantPolicy<ChannelGridMajorant<Emissive<DenseGridMedium<Hero<4>>>>, Emissive<DenseGridMedium<Hero<4>>>>);
static_assert(std::is_same_v<Emissive<RgbGrid>::Spectral, Rgb>);

// ---------------------------------------------------------------------------------------------
// Constructor messages (STYLE rule 6)

TEST_CASE("EmissionGrid rejects an empty or non-finite box, naming the axis") {
    const Box flat{Vec3(0.f), Vec3(1.f, 1.f, 0.f)};
    const Box infinite{Vec3(0.f, -kInf, 0.f), Vec3(1.f)};
    CHECK_THROWS_WITH_AS(EmissionGrid(flat, {1, 1, 1}, {1.f}),
                         Contains("EmissionGrid bounds is empty on axis 2: lo = 0 must be < hi = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(EmissionGrid(infinite, {1, 1, 1}, {1.f}),
                         Contains("EmissionGrid bounds has a non-finite corner on axis 1"), InvalidArgument);
}

TEST_CASE("EmissionGrid rejects a resolution below 1, naming the axis and value") {
    CHECK_THROWS_WITH_AS(EmissionGrid(kUnitBox, {1, 0, 1}, {1.f}),
                         Contains("EmissionGrid resolution[1] = 0 is not allowed: every axis needs at least 1 voxel"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(EmissionGrid(kUnitBox, {2, 2, -3}, {1.f}), Contains("resolution[2] = -3"), InvalidArgument);
}

TEST_CASE("EmissionGrid rejects an empty grid and a size mismatch") {
    CHECK_THROWS_WITH_AS(EmissionGrid(kUnitBox, {1, 1, 1}, {}), Contains("EmissionGrid: the value grid is empty"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(EmissionGrid(kUnitBox, {2, 2, 2}, std::vector<float>(5, 1.f)),
                         Contains("5 values given, but resolution 2x2x2 needs 8"), InvalidArgument);
}

TEST_CASE("EmissionGrid rejects a negative, NaN or infinite value, naming its index") {
    CHECK_THROWS_WITH_AS(EmissionGrid(kUnitBox, {3, 1, 1}, {1.f, -2.f, 1.f}),
                         Contains("value[1] = -2 is not allowed: emission values must be finite and >= 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(EmissionGrid(kUnitBox, {3, 1, 1}, {kNaN, 1.f, 1.f}), Contains("value[0] = nan"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(EmissionGrid(kUnitBox, {3, 1, 1}, {1.f, 1.f, kInf}), Contains("value[2] = inf"),
                         InvalidArgument);
}

TEST_CASE_TEMPLATE("Emissive rejects a negative or NaN radiance_scale, naming the channel", S, Mono, Rgb) {
    const auto ok = grey<S>(1.f);
    const EmissionGrid e(kUnitBox, {1, 1, 1}, {1.f});
    const HomogeneousMedium<S> m(kUnitBox, ok, ok);
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<S>>(m, e, grey<S>(-0.5f)),
                         Contains("Emissive radiance_scale[channel 0] = -0.5"), InvalidArgument);
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<S>>(m, e, grey<S>(kNaN)),
                         Contains("Emissive radiance_scale[channel 0] = nan"), InvalidArgument);
    if constexpr (S::channels == 3)
        CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<S>>(m, e, spec<S>(1.f, kInf, 1.f)),
                             Contains("radiance_scale[channel 1] = inf"), InvalidArgument);
}

TEST_CASE("Emissive rejects a power resolution outside [1, 256], naming the axis and value") {
    const EmissionGrid e(kUnitBox, {1, 1, 1}, {1.f});
    const HomogeneousMedium<Rgb> m(kUnitBox, grey<Rgb>(1.f), grey<Rgb>(1.f));
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<Rgb>>(m, e, grey<Rgb>(1.f), {4, 0, 4}),
                         Contains("Emissive power_resolution[1] = 0 is not allowed: it must lie in [1, 256]"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<Rgb>>(m, e, grey<Rgb>(1.f), {257, 4, 4}),
                         Contains("power_resolution[0] = 257"), InvalidArgument);
    CHECK_NOTHROW(Emissive<HomogeneousMedium<Rgb>>(m, e, grey<Rgb>(1.f), {1, 256, 1}));
}

TEST_CASE("Emissive rejects a power grid whose cells are too thin for float") {
    // 8 ulps wide on axis 0: 256 cells would need planes between consecutive floats.
    const float hi = 1.f + 8.f * std::numeric_limits<float>::epsilon();
    const Box thin{Vec3(1.f, 0.f, 0.f), Vec3(hi, 1.f, 1.f)};
    const EmissionGrid e(thin, {1, 1, 1}, {1.f});
    const HomogeneousMedium<Mono> m(thin, grey<Mono>(1.f), grey<Mono>(1.f));
    CHECK_THROWS_WITH_AS(Emissive<HomogeneousMedium<Mono>>(m, e, grey<Mono>(1.f), {256, 1, 1}),
                         Contains("cells too thin for float at power_resolution[0] = 256"), InvalidArgument);
    CHECK_NOTHROW(Emissive<HomogeneousMedium<Mono>>(m, e, grey<Mono>(1.f), {4, 1, 1}));
}

// ---------------------------------------------------------------------------------------------
// EmissionGrid lookup and bound

TEST_CASE("EmissionGrid::value is trilinear between voxel centres, clamped at faces, 0 outside") {
    // 3 x 2 x 4 voxels over [1, 4] x [0, 1] x [-2, 2]: voxel (i, j, k) is centred at
    // (1.5 + i, 0.25 + 0.5 j, -1.5 + k).
    const std::array<int, 3> res{3, 2, 4};
    const Box b{Vec3(1.f, 0.f, -2.f), Vec3(4.f, 1.f, 2.f)};
    const std::vector<float> v = random_values(24, 0.f, 5.f, 21);
    const EmissionGrid g(b, res, v);
    auto at = [&](int i, int j, int k) { return v[std::size_t(i + 3 * (j + 2 * k))]; };
    auto centre = [](int i, int j, int k) { return Vec3(1.5f + float(i), 0.25f + 0.5f * float(j), -1.5f + float(k)); };

    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 3; ++i) {
                CAPTURE(i);
                CAPTURE(j);
                CAPTURE(k);
                // At a voxel centre: the voxel's value.
                CHECK(g.value(centre(i, j, k)) == doctest::Approx(at(i, j, k)).epsilon(1e-6));
                // Midway between neighbours along x: their mean.
                if (i + 1 < 3)
                    CHECK(g.value(0.5f * (centre(i, j, k) + centre(i + 1, j, k))) ==
                          doctest::Approx(0.5 * (at(i, j, k) + at(i + 1, j, k))).epsilon(1e-6));
                // At the centre of 8 voxels: their mean.
                if (i + 1 < 3 && j + 1 < 2 && k + 1 < 4) {
                    double mean = 0.0;
                    for (int c = 0; c < 8; ++c) mean += at(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1)) / 8.0;
                    CHECK(g.value(0.5f * (centre(i, j, k) + centre(i + 1, j + 1, k + 1))) ==
                          doctest::Approx(mean).epsilon(1e-6));
                }
            }
    // Clamped at the faces: between a face and the first centres the value does not change.
    CHECK(g.value(b.lo) == doctest::Approx(at(0, 0, 0)).epsilon(1e-6));
    CHECK(g.value(b.hi) == doctest::Approx(at(2, 1, 3)).epsilon(1e-6));
    CHECK(g.value(Vec3(1.2f, 0.1f, 1.8f)) == doctest::Approx(at(0, 0, 3)).epsilon(1e-6));
    // Zero outside the box, even by one ulp.
    CHECK(g.value(Vec3(std::nextafter(1.f, 0.f), 0.5f, 0.f)) == 0.f);
    CHECK(g.value(Vec3(2.f, 0.5f, std::nextafter(2.f, 3.f))) == 0.f);
    CHECK(g.value(Vec3(-10.f)) == 0.f);
    CHECK(g.max_value() == *std::max_element(v.begin(), v.end()));
}

TEST_CASE("EmissionGrid::bound(region) bounds every lookup in the region and is 0 off the box") {
    const Box b{Vec3(-1.f, 0.f, 0.5f), Vec3(2.f, 1.f, 3.f)};
    const EmissionGrid g(b, {5, 4, 6}, random_values(120, 0.f, 1.f, 31));
    Pcg32 rng(32, 1);
    const Box wide{b.lo - 0.3f * (b.hi - b.lo), b.hi + 0.3f * (b.hi - b.lo)};
    int checked = 0;
    for (int r = 0; r < 2000; ++r) {
        // A random region, up to half the box on each axis, possibly sticking out of it.
        const Vec3 a = random_point(rng, wide);
        const Vec3 size = 0.5f * Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * (b.hi - b.lo);
        const Box region{a, a + size};
        const float bound = g.bound(region);
        CHECK(bound <= g.max_value());
        for (int i = 0; i < 50; ++i) {
            const Vec3 p = random_point(rng, region);
            const float v = g.value(p);
            if (v > bound) {
                CAPTURE(p.x);
                CAPTURE(p.y);
                CAPTURE(p.z);
                CHECK(v <= bound);
            }
            checked += v > 0.f;
        }
        // A region's corners are covered too.
        CHECK(g.value(region.lo) <= bound);
        CHECK(g.value(region.hi) <= bound);
    }
    CHECK(checked > 10000);
    CHECK(g.bound(Box{Vec3(5.f), Vec3(6.f)}) == 0.f);
    CHECK(g.bound(b) == g.max_value());
}

// ---------------------------------------------------------------------------------------------
// The wrapper: the base medium, unchanged

TEST_CASE("Emissive<DenseGridMedium<Rgb>> gives the base medium's coefficients and bounds, bit for bit") {
    const auto e = chromatic_flame<Rgb>({16, 16, 16});
    const RgbGrid& m = e.base();
    Pcg32 rng(41, 1);
    const Box b = m.bounds();
    const Box wide{b.lo - 0.2f * (b.hi - b.lo), b.hi + 0.2f * (b.hi - b.lo)};
    for (int i = 0; i < 100000; ++i) {
        const Vec3 p = random_point(rng, wide);
        const auto c0 = m.coefficients(p, {}), c1 = e.coefficients(p, {});
        REQUIRE(same_bits(c0.sigma_a, c1.sigma_a));
        REQUIRE(same_bits(c0.sigma_s, c1.sigma_s));
        if (i % 100 == 0) {
            const Box region{p, p + 0.3f * Vec3(rng.uniform(), rng.uniform(), rng.uniform())};
            REQUIRE(same_bits(m.density_bound(region), e.density_bound(region)));
        }
    }
    CHECK(e.bounds().lo == b.lo);
    CHECK(e.bounds().hi == b.hi);
    CHECK(same_bits(e.extinction_bound({}), m.extinction_bound({})));
    CHECK(same_bits(e.max_extinction(), m.max_extinction()));
    CHECK(same_bits(e.extinction_bound_coefficient(), m.extinction_bound_coefficient()));
    CHECK(same_bits(e.extinction_per_density(), m.extinction_per_density()));
}

TEST_CASE("every majorant takes Emissive<DenseGridMedium<Rgb>> and walks it as the base medium") {
    const auto e = chromatic_flame<Rgb>({8, 8, 8});
    const RgbGrid& m = e.base();
    CHECK(GlobalMajorant<Emissive<RgbGrid>>(e).value() == GlobalMajorant<RgbGrid>(m).value());
    CHECK(same_bits(ChannelMajorant<Emissive<RgbGrid>>(e).value({}), ChannelMajorant<RgbGrid>(m).value({})));

    const GridMajorant<Emissive<RgbGrid>> ge(e, {7, 5, 6});
    const GridMajorant<RgbGrid> gm(m, {7, 5, 6});
    const ChannelGridMajorant<Emissive<RgbGrid>> ce(e, 6);
    const ChannelGridMajorant<RgbGrid> cm(m, 6);
    for (int z = 0; z < 6; ++z)
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 7; ++x) REQUIRE(same_bits(ge.cell(x, y, z), gm.cell(x, y, z)));

    Pcg32 rng(42, 1);
    int segments = 0;
    for (int r = 0; r < 200; ++r) {
        // Through a random point of the medium, from outside it.
        const Vec3 d = random_direction(rng);
        const Ray ray{random_point(rng, m.bounds()) - 4.f * d, d};
        auto ie = ge.iterate(ray, 0.f, kInf, {});
        auto im = gm.iterate(ray, 0.f, kInf, {});
        for (;;) {
            const auto se = ie.next(), sm = im.next();
            REQUIRE(se.has_value() == sm.has_value());
            if (!se) break;
            REQUIRE(same_bits(se->t0, sm->t0));
            REQUIRE(same_bits(se->t1, sm->t1));
            REQUIRE(same_bits(se->sigma_maj, sm->sigma_maj));
            ++segments;
        }
        auto ke = ce.iterate(ray, 0.f, kInf, {});
        auto km = cm.iterate(ray, 0.f, kInf, {});
        for (;;) {
            const auto se = ke.next(), sm = km.next();
            REQUIRE(se.has_value() == sm.has_value());
            if (!se) break;
            REQUIRE(same_bits(se->sigma_maj, sm->sigma_maj));
        }
    }
    CHECK(segments > 1000);  // about 8 cells per ray
}

// ---------------------------------------------------------------------------------------------
// Emission values and the power estimate

TEST_CASE_TEMPLATE("Emissive::emission is the grid value times radiance_scale at the path's wavelengths", S, Mono,
                   Rgb, Hero<4>) {
    const auto e = chromatic_flame<S>({16, 16, 16});
    const auto scale = chroma<S>(2.f, 1.f, 0.5f);
    Pcg32 rng(51, 1);
    const Box eb = e.emission_grid().bounds();
    const Box wide{eb.lo - 0.2f * (eb.hi - eb.lo), eb.hi + 0.2f * (eb.hi - eb.lo)};
    int inside = 0;
    for (int i = 0; i < 20000; ++i) {
        const auto l = draw_wavelengths<S>(rng);
        const Vec3 p = random_point(rng, wide);
        const float v = e.emission_grid().value(p);
        const auto le = e.emission(p, l);
        const auto expected = typename S::Spectrum(S::sample(scale, l) * v);
        inside += v > 0.f;
        for (int c = 0; c < S::channels; ++c) {
            REQUIRE(std::isfinite(le[c]));
            REQUIRE(le[c] == doctest::Approx(expected[c]).epsilon(1e-6));
            if (!eb.contains(p)) REQUIRE(le[c] == 0.f);
        }
    }
    CHECK(inside > 5000);
    CHECK(e.total_power_estimate() > 0.f);
    CHECK(e.power_resolution() == std::array<int, 3>{16, 16, 16});
    // A probability and a CDF entry per cell (and one more CDF entry).
    CHECK(e.power_memory_bytes() == (2 * 16 * 16 * 16 + 1) * sizeof(float));
}

TEST_CASE_TEMPLATE("a constant mu_a L_e gives the closed-form total power and a uniform pdf", S, Mono, Rgb, Hero<4>) {
    // mu_a = 2 everywhere in the medium, L_e = 0.75 * 3 in the emission box: the overlap
    // [0, 1] x [0.5, 1] x [0, 1] (volume 0.5) emits mean_c mu_a L_e = 4.5, total 2.25; the pdf
    // is uniform, 1 / 0.5.
    const Box mb{Vec3(0.f), Vec3(1.f)}, eb{Vec3(-1.f, 0.5f, -1.f), Vec3(2.f, 2.f, 2.f)};
    const HomogeneousMedium<S> m(mb, constant_coefficient<S>(2.f), constant_coefficient<S>(1.f));
    const Emissive<HomogeneousMedium<S>> e(m, EmissionGrid(eb, {2, 3, 2}, std::vector<float>(12, 0.75f)),
                                           constant_coefficient<S>(3.f), {3, 4, 5});
    CHECK(e.total_power_estimate() == doctest::Approx(2.25).epsilon(1e-5));
    Pcg32 rng(52, 1);
    for (int i = 0; i < 1000; ++i) {
        const auto s = e.sample_emission(rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform());
        REQUIRE(s.pdf == doctest::Approx(2.0).epsilon(1e-5));
        REQUIRE(s.p.y >= 0.5f);
    }
    CHECK(e.emission_pdf(Vec3(0.5f, 0.25f, 0.5f)) == 0.f);  // in the medium, outside the emission grid
    CHECK(e.emission_pdf(Vec3(1.5f, 0.75f, 0.5f)) == 0.f);  // in the emission grid, outside the medium
}

// ---------------------------------------------------------------------------------------------
// The emission sampler

TEST_CASE_TEMPLATE("sample_emission's points follow emission_pdf (chi-square) and report it exactly", S, Mono, Rgb,
                   Hero<4>) {
    // 2 x 2 x 5 power cells, each split in two halves along one axis: 40 bins, 39 degrees of
    // freedom, rejected above the p = 1e-3 critical value (72.055). Splitting the cells checks
    // that points are uniform inside a cell as well as that cells are chosen in proportion.
    const std::array<int, 3> res{2, 2, 5};
    const auto e = chromatic_flame<S>(res);
    const Box pb = overlap(e.base().bounds(), e.emission_grid().bounds());
    const Vec3 w = (pb.hi - pb.lo) / Vec3(float(res[0]), float(res[1]), float(res[2]));
    const double vol = double(w.x) * double(w.y) * double(w.z);

    std::vector<double> cell_prob(20);
    double sum = 0.0;
    for (int z = 0; z < 5; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) {
                const Vec3 centre = pb.lo + (Vec3(float(x), float(y), float(z)) + 0.5f) * w;
                const double p = double(e.emission_pdf(centre)) * vol;
                REQUIRE(p > 0.0);
                cell_prob[std::size_t(x + 2 * (y + 2 * z))] = p;
                sum += p;
            }
    CHECK(sum == doctest::Approx(1.0).epsilon(1e-5));
    std::vector<double> prob(40);
    for (std::size_t i = 0; i < 40; ++i) prob[i] = cell_prob[i / 2] / sum / 2.0;

    constexpr int n = 200000;
    std::array<std::vector<double>, 3> counts;
    counts.fill(std::vector<double>(40, 0.0));
    Pcg32 rng(61, 5);
    for (int i = 0; i < n; ++i) {
        const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
        const VolumeSample s = e.sample_emission(u0, u1, u2, u3);
        REQUIRE(s.pdf > 0.f);
        REQUIRE(std::isfinite(s.pdf));
        REQUIRE(pb.contains(s.p));
        REQUIRE(s.pdf == e.emission_pdf(s.p));
        int c[3];
        float f[3];
        for (int a = 0; a < 3; ++a) {
            const float x = (s.p[a] - pb.lo[a]) / w[a];
            c[a] = std::clamp(int(std::floor(x)), 0, res[std::size_t(a)] - 1);
            f[a] = x - float(c[a]);
        }
        const std::size_t cell = std::size_t(c[0] + 2 * (c[1] + 2 * c[2]));
        for (int a = 0; a < 3; ++a) counts[std::size_t(a)][2 * cell + (f[a] >= 0.5f ? 1 : 0)] += 1.0;
    }
    for (int a = 0; a < 3; ++a) {
        CAPTURE(a);
        CHECK(chi_square(counts[std::size_t(a)], prob, n) < chi_square_critical_p001(39));
    }
}

TEST_CASE_TEMPLATE("emission_pdf integrates to 1 over the power grid (midpoint rule)", S, Mono, Rgb, Hero<4>) {
    // 4 midpoints per cell and axis: the pdf is constant per cell, so the rule is exact up to the
    // float rounding of the cell probabilities (about 1e-7 each); tolerance 1e-4.
    for (const std::array<int, 3> res : {std::array<int, 3>{16, 16, 16}, std::array<int, 3>{7, 3, 11}}) {
        const auto e = chromatic_flame<S>(res);
        const Box pb = overlap(e.base().bounds(), e.emission_grid().bounds());
        const int q[3] = {4 * res[0], 4 * res[1], 4 * res[2]};
        const Vec3 h = (pb.hi - pb.lo) / Vec3(float(q[0]), float(q[1]), float(q[2]));
        double integral = 0.0;
        for (int z = 0; z < q[2]; ++z)
            for (int y = 0; y < q[1]; ++y)
                for (int x = 0; x < q[0]; ++x)
                    integral += e.emission_pdf(pb.lo + (Vec3(float(x), float(y), float(z)) + 0.5f) * h);
        integral *= double(h.x) * double(h.y) * double(h.z);
        CAPTURE(res[0]);
        CHECK(integral == doctest::Approx(1.0).epsilon(1e-4));
        // Zero outside the overlap: in the medium only, in the emission grid only, in neither.
        CHECK(e.emission_pdf(Vec3(-0.9f, 1.f, 0.5f)) == 0.f);
        CHECK(e.emission_pdf(Vec3(1.4f, 2.4f, 0.5f)) == 0.f);
        CHECK(e.emission_pdf(Vec3(0.f, 1.f, 1.3f)) == 0.f);
        CHECK(e.emission_pdf(Vec3(50.f)) == 0.f);
    }
}

/// Checks emission_pdf > 0 at every probe where mu_a(p) L_e(p) > 0, over random points in `box`,
/// random points in `support` and points just off every power-cell corner; returns how many
/// probes had mu_a L_e > 0.
template <class E>
int check_support(const E& e, const Box& box, const Box& support, std::uint64_t seed) {
    using S = typename E::Spectral;
    Pcg32 rng(seed, 9);
    int positive = 0;
    auto probe = [&](const Vec3& p) {
        const auto l = draw_wavelengths<S>(rng);
        const auto source = typename S::Spectrum(e.coefficients(p, l).sigma_a * e.emission(p, l));
        if (source.maxCoeff() > 0.f) {
            ++positive;
            if (!(e.emission_pdf(p) > 0.f)) {
                CAPTURE(p.x);
                CAPTURE(p.y);
                CAPTURE(p.z);
                CHECK(e.emission_pdf(p) > 0.f);
            }
        }
    };
    for (int i = 0; i < 100000; ++i) probe(random_point(rng, box));
    for (int i = 0; i < 100000; ++i) probe(random_point(rng, support));
    const auto res = e.power_resolution();
    const Vec3 w = (box.hi - box.lo) / Vec3(float(res[0]), float(res[1]), float(res[2]));
    for (int z = 0; z <= res[2]; ++z)
        for (int y = 0; y <= res[1]; ++y)
            for (int x = 0; x <= res[0]; ++x)
                for (int c = 0; c < 8; ++c) {
                    const Vec3 off((c & 1) ? 1e-3f : -1e-3f, (c & 2) ? 1e-3f : -1e-3f, (c & 4) ? 1e-3f : -1e-3f);
                    probe(box.lo + (Vec3(float(x), float(y), float(z)) + off) * w);
                }
    return positive;
}

TEST_CASE_TEMPLATE("emission_pdf > 0 wherever mu_a L_e > 0, in cells whose sub-points all see zero", S, Mono, Rgb,
                   Hero<4>) {
    // Emission from the far corner voxel of a 7^3 grid over the unit cube is > 0 for x, y, z >
    // 1 - 1.5 / 7 = 0.7857. With 5 power cells per axis, cell 3 spans [0.6, 0.8] and its last
    // sub-point is at 0.775: the estimate of every cell with an index 3 is 0, and only the floor
    // keeps the pdf > 0 on the sliver (0.7857, 0.8].
    const std::vector<float> density = random_values(27, 0.5f, 1.f, 71);
    const DenseGridMedium<S> grid(kUnitBox, {3, 3, 3}, density, chroma<S>(1.f, 2.f, 0.5f), chroma<S>(1.f, 1.f, 1.f));
    const Emissive<DenseGridMedium<S>> flame(grid, EmissionGrid(kUnitBox, {7, 7, 7}, one_voxel({7, 7, 7}, 6, 6, 6)),
                                             chroma<S>(1.f, 1.f, 1.f), {5, 5, 5});
    const float edge = 1.f - 1.5f / 7.f;
    const Vec3 sliver(0.79f, 0.9f, 0.9f);
    Pcg32 rng(70, 1);
    REQUIRE(flame.emission(sliver, draw_wavelengths<S>(rng)).maxCoeff() > 0.f);
    CHECK(flame.emission_pdf(sliver) > 0.f);
    // The floor is small: below 1 % of the pdf in the corner cell, whose estimate is positive.
    CHECK(flame.emission_pdf(sliver) < 0.01f * flame.emission_pdf(Vec3(0.9f)));
    CHECK(check_support(flame, kUnitBox, Box{Vec3(edge), Vec3(1.f)}, 72) > 90000);

    // The density is > 0 only near the lo corner (x, y, z < 1.5 / 7 = 0.2143): with 5 power cells
    // per axis the sub-points of cell 1 (from 0.225) miss the sliver [0.2, 0.2143); the density
    // bound over the cell brings the floor.
    const DenseGridMedium<S> puff(kUnitBox, {7, 7, 7}, one_voxel({7, 7, 7}, 0, 0, 0), chroma<S>(1.f, 2.f, 0.5f),
                                  chroma<S>(1.f, 1.f, 1.f));
    const Emissive<DenseGridMedium<S>> glow(puff, EmissionGrid(kUnitBox, {2, 2, 2}, random_values(8, 0.5f, 1.f, 73)),
                                            chroma<S>(3.f, 2.f, 1.f), {5, 5, 5});
    CHECK(glow.emission_pdf(Vec3(0.21f, 0.1f, 0.1f)) > 0.f);
    CHECK(check_support(glow, kUnitBox, Box{Vec3(0.f), Vec3(1.5f / 7.f)}, 74) > 90000);

    // A medium without region bounds: max_extinction() > 0 stands in for the density bound. Its
    // box [0, 0.99]^3 clips the power grid, whose cell 3 per axis, [0.594, 0.792], again has a
    // sliver of emission its sub-points (up to 0.767) miss.
    const HomogeneousMedium<S> fog(Box{Vec3(0.f), Vec3(0.99f)}, chroma<S>(1.f, 2.f, 0.5f), chroma<S>(1.f, 1.f, 1.f));
    const Emissive<HomogeneousMedium<S>> lit(fog, EmissionGrid(kUnitBox, {7, 7, 7}, one_voxel({7, 7, 7}, 6, 6, 6)),
                                             chroma<S>(1.f, 1.f, 1.f), {5, 5, 5});
    CHECK(lit.emission_pdf(Vec3(0.79f, 0.9f, 0.9f)) > 0.f);
    CHECK(check_support(lit, Box{Vec3(0.f), Vec3(0.99f)}, Box{Vec3(edge), Vec3(0.99f)}, 75) > 90000);
}

TEST_CASE("sample_emission never leaves its cell or returns NaN, even for u at 1, NaN or cell boundaries") {
    // 256 cells on x: a cell is 1/256 of the box, so u near a cell edge stresses the rounding of
    // the point and of the cell lookup. Random emission, so neighbouring cells differ in pdf.
    const Box b{Vec3(-0.3f, 0.1f, 0.f), Vec3(1.7f, 0.4f, 3.f)};
    const HomogeneousMedium<Rgb> m(b, grey<Rgb>(1.f), grey<Rgb>(1.f));
    const Emissive<HomogeneousMedium<Rgb>> e(m, EmissionGrid(b, {64, 2, 3}, random_values(384, 0.f, 1.f, 81)),
                                             grey<Rgb>(1.f), {256, 1, 3});
    const float edge_u[] = {0.f, 0x1p-24f, 0.5f, 1.f - 0x1p-24f, 1.f, -0.f, -1.f, kNaN, kInf};
    Pcg32 rng(82, 1);
    auto check = [&](float u0, float u1, float u2, float u3) {
        const VolumeSample s = e.sample_emission(u0, u1, u2, u3);
        REQUIRE(std::isfinite(s.pdf));
        REQUIRE(s.pdf > 0.f);
        REQUIRE(b.contains(s.p));
        REQUIRE(s.pdf == e.emission_pdf(s.p));
    };
    for (float a : edge_u)
        for (float c : edge_u) check(a, c, c, c);
    for (int i = 0; i < 200000; ++i) {
        // u1 within a few ulps of k / 256, a cell boundary of the power grid on x.
        const float k = std::floor(rng.uniform() * 257.f) / 256.f;
        const float u1 = std::clamp(k + float(int(rng.next_u32() % 9) - 4) * 0x1p-24f, 0.f, 1.f);
        check(rng.uniform(), u1, rng.uniform(), rng.uniform());
    }
}

/// The stretches of `ray` over [t0, t1) between consecutive crossings of the power grid's planes
/// (computed from the grid's box and resolution, independently of GridWalk), with the pdf at each
/// stretch's midpoint: emission_pdf is constant on each.
template <class E>
std::vector<std::array<double, 3>> power_stretches(const E& e, const Ray& ray, double t0, double t1) {
    const Box pb = e.power_box();
    const auto res = e.power_resolution();
    std::vector<double> ts{t0, t1};
    for (int a = 0; a < 3; ++a) {
        if (ray.d[a] == 0.f) continue;
        for (int k = 0; k <= res[std::size_t(a)]; ++k) {
            const double plane = double(pb.lo[a]) + (double(pb.hi[a]) - double(pb.lo[a])) * k / res[std::size_t(a)];
            const double t = (plane - double(ray.o[a])) / double(ray.d[a]);
            if (t > t0 && t < t1) ts.push_back(t);
        }
    }
    std::sort(ts.begin(), ts.end());
    std::vector<std::array<double, 3>> out;
    for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
        const double a = ts[i], b = ts[i + 1];
        if (!(b > a)) continue;
        const double m = 0.5 * (a + b);
        const Vec3 p = ray.o + float(m) * ray.d;
        out.push_back({a, b, double(e.emission_pdf(p))});
    }
    return out;
}

TEST_CASE_TEMPLATE("emission_along integrates emission_pdf along a ray; sample_emission_along follows it (chi-square)",
                   S, Mono, Rgb) {
    // The segment technique's density along a ray is emission_pdf(ray.at(t)) / W. W against the
    // exact piecewise-constant integral over the stretches between the power grid's planes
    // (tolerance 1e-5 relative: float rounding of the plane crossings and of the sum); 200000
    // distances binned into 20 equal bins of the stretch the ray spends in the power box, against
    // the exact bin probabilities: 19 degrees of freedom, rejected above the p = 1e-3 critical
    // value (43.820).
    const auto e = chromatic_flame<S>({4, 3, 5});
    const Box pb = e.power_box();
    struct Case {
        Ray ray;
        float t0, t1;
    };
    const Case cases[] = {
        {Ray{Vec3(-2.f, 0.3f, -0.5f), glm::normalize(Vec3(1.f, 0.45f, 0.5f))}, 0.f, kInf},  // from outside, unbounded
        {Ray{Vec3(0.1f, 1.2f, 0.4f), glm::normalize(Vec3(-0.3f, 0.2f, 1.f))}, 0.f, 0.6f},   // from inside, ending inside
        {Ray{Vec3(-0.5f, 1.f, 0.5f), Vec3(1.f, 0.f, 0.f)}, 0.25f, 2.f},                   // along an axis, on a plane
    };
    int k = 0;
    for (const Case& c : cases) {
        CAPTURE(k++);
        const Interval in = pb.clip(c.ray, c.t0, c.t1);
        REQUIRE(in.t0 < in.t1);
        const auto stretches = power_stretches(e, c.ray, double(in.t0), double(in.t1));
        double exact = 0.0;
        for (const auto& s : stretches) exact += (s[1] - s[0]) * s[2];
        REQUIRE(exact > 0.0);
        const float w = e.emission_along(c.ray, c.t0, c.t1);
        CHECK(double(w) == doctest::Approx(exact).epsilon(1e-5));
        // Additive over a split of the stretch.
        const float mid = 0.5f * (in.t0 + in.t1);
        CHECK(double(e.emission_along(c.ray, c.t0, mid)) + double(e.emission_along(c.ray, mid, c.t1)) ==
              doctest::Approx(double(w)).epsilon(1e-5));

        constexpr int bins = 20, n = 200000;
        std::vector<double> prob(bins, 0.0), counts(bins, 0.0);
        const double len = double(in.t1) - double(in.t0);
        for (int b = 0; b < bins; ++b) {
            const double lo = double(in.t0) + len * b / bins, hi = double(in.t0) + len * (b + 1) / bins;
            for (const auto& s : stretches)
                prob[std::size_t(b)] += std::max(0.0, std::min(hi, s[1]) - std::max(lo, s[0])) * s[2] / exact;
        }
        double renorm = 0.0;
        for (double p : prob) renorm += p;
        for (double& p : prob) p /= renorm;  // the float-rounded planes leave the sum 1 within 1e-6
        Pcg32 rng(91, 7);
        int mismatched = 0;
        for (int i = 0; i < n; ++i) {
            const DistanceSample ds = e.sample_emission_along(c.ray, c.t0, c.t1, w, rng.uniform());
            REQUIRE(ds.pdf > 0.f);
            REQUIRE(std::isfinite(ds.pdf));
            REQUIRE(ds.t >= in.t0);
            REQUIRE(ds.t < in.t1);
            // The pdf is the density of the cell the walk put t in: emission_pdf there, but for t
            // within rounding of a cell face.
            if (ds.pdf != e.emission_pdf(c.ray.at(ds.t)) / w) ++mismatched;
            counts[std::size_t(std::clamp(int((double(ds.t) - double(in.t0)) / len * bins), 0, bins - 1))] += 1.0;
        }
        CHECK(mismatched <= n / 10000);
        CHECK(chi_square(counts, prob, n) < chi_square_critical_p001(19));
    }
}

TEST_CASE("sample_emission_along stays in [t0, t1) and finite for u at 0, 1, NaN and inf; W = 0 off the grid") {
    const auto e = chromatic_flame<Rgb>({7, 5, 3});
    const Ray ray{Vec3(-2.f, 0.9f, 0.3f), glm::normalize(Vec3(1.f, 0.2f, 0.1f))};
    const float w = e.emission_along(ray, 0.f, kInf);
    REQUIRE(w > 0.f);
    const Interval in = e.power_box().clip(ray, 0.f, kInf);
    for (const float u : {0.f, 0x1p-24f, 0.5f, 1.f - 0x1p-24f, 1.f, -0.f, -1.f, kNaN, kInf}) {
        CAPTURE(u);
        const DistanceSample ds = e.sample_emission_along(ray, 0.f, kInf, w, u);
        CHECK(ds.pdf > 0.f);
        CHECK(std::isfinite(ds.pdf));
        CHECK(ds.t >= in.t0);
        CHECK(ds.t < in.t1);
    }
    // A ray that misses the power box, an empty stretch and a total of 0 give no sample.
    const Ray miss{Vec3(-2.f, 5.f, 0.3f), Vec3(1.f, 0.f, 0.f)};
    CHECK(e.emission_along(miss, 0.f, kInf) == 0.f);
    CHECK(e.emission_along(ray, 1.f, 1.f) == 0.f);
    CHECK(e.sample_emission_along(miss, 0.f, kInf, 0.f, 0.5f).pdf == 0.f);
    CHECK(e.sample_emission_along(ray, 0.f, kInf, 0.f, 0.5f).pdf == 0.f);
    // Nothing emits: W = 0.
    const HomogeneousMedium<Rgb> m(kUnitBox, grey<Rgb>(1.f), grey<Rgb>(1.f));
    const Emissive<HomogeneousMedium<Rgb>> dark(m, EmissionGrid(kUnitBox, {2, 1, 1}, {0.f, 0.f}), grey<Rgb>(1.f));
    CHECK(dark.emission_along(Ray{Vec3(-1.f, 0.5f, 0.5f), Vec3(1.f, 0.f, 0.f)}, 0.f, kInf) == 0.f);
}

TEST_CASE("nothing emits: no overlap, a zero grid or a zero radiance scale give pdf 0") {
    const HomogeneousMedium<Rgb> m(kUnitBox, grey<Rgb>(1.f), grey<Rgb>(1.f));
    const Box far{Vec3(2.f), Vec3(3.f)};
    const Emissive<HomogeneousMedium<Rgb>> apart(m, EmissionGrid(far, {1, 1, 1}, {1.f}), grey<Rgb>(1.f));
    const Emissive<HomogeneousMedium<Rgb>> dark(m, EmissionGrid(kUnitBox, {2, 1, 1}, {0.f, 0.f}), grey<Rgb>(1.f));
    const Emissive<HomogeneousMedium<Rgb>> black(m, EmissionGrid(kUnitBox, {1, 1, 1}, {1.f}), grey<Rgb>(0.f));
    for (const auto* e : {&apart, &dark, &black}) {
        const VolumeSample s = e->sample_emission(0.3f, 0.5f, 0.5f, 0.5f);
        CHECK(s.pdf == 0.f);
        CHECK(e->emission_pdf(Vec3(0.5f)) == 0.f);
        CHECK(e->total_power_estimate() == 0.f);
    }
    CHECK(apart.power_memory_bytes() == 0);
    CHECK(dark.emission(Vec3(0.5f), {}).maxCoeff() == 0.f);
}

}  // namespace
