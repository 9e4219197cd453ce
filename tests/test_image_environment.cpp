// tests/test_image_environment.cpp: ImageEnvironmentLight (lights/image_environment.hpp): each
// sample's pdf and radiance equal pdf() and emitted() for its direction; the pdf integrates to 1
// over the sphere; radiance / pdf estimates the integral of the image over the sphere (exact from
// the pixels), with zero variance where radiance is proportional to luminance; pixels are drawn
// with the probabilities luminance x solid angle (chi-square); bad images are rejected by name;
// PathEstimator renders the sky through vacuum exactly and through a medium without bias.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "common.hpp"
#include "grey_surface_scenes.hpp"

namespace {

using namespace nsp_test;

// k = 5 standard errors, estimated from the samples, with fixed seeds: deterministic.
constexpr double kSigmas = 5.0;

/// A W x H test image: smooth chromatic values, a bright "sun" pixel, a black pixel and (when
/// `black_row`) a black row, so that the tables meet rows and pixels of weight 0.
std::vector<float> test_image(int w, int h, bool black_row = true) {
    std::vector<float> rgb(std::size_t(3 * w * h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y * w + x);
            const float a = float(x) / float(w), b = float(y) / float(h);
            rgb[3 * p] = 0.2f + a;
            rgb[3 * p + 1] = 0.1f + 0.5f * b * b;
            rgb[3 * p + 2] = 0.05f + 0.4f * std::abs(std::sin(6.f * a + b));
        }
    auto set = [&](int x, int y, float r, float g, float b) {
        const std::size_t p = std::size_t(y * w + x);
        rgb[3 * p] = r;
        rgb[3 * p + 1] = g;
        rgb[3 * p + 2] = b;
    };
    set(w / 3, h / 4, 40.f, 35.f, 30.f);  // the sun
    set(w / 2, h / 2, 0.f, 0.f, 0.f);
    if (black_row)
        for (int x = 0; x < w; ++x) set(x, h - 2, 0.f, 0.f, 0.f);
    return rgb;
}

/// The solid angle of a pixel of row y: (2 pi / W)(cos theta_top - cos theta_bottom).
double pixel_solid_angle(int w, int h, int y) {
    const double pi = 3.14159265358979323846;
    return 2.0 * pi / w * (std::cos(pi * y / h) - std::cos(pi * (y + 1) / h));
}

/// The pixel a unit direction points at, by the header's mapping, computed here in double.
int pixel_of(const Vec3& d, int w, int h) {
    const double pi = 3.14159265358979323846;
    const double theta = std::acos(std::clamp(double(d.y), -1.0, 1.0));
    double phi = std::atan2(double(d.x), -double(d.z));
    if (phi < 0.0) phi += 2.0 * pi;
    const int x = std::min(int(phi / (2.0 * pi) * w), w - 1), y = std::min(int(theta / pi * h), h - 1);
    return y * w + x;
}

double luminance(const std::vector<float>& rgb, std::size_t p) {
    return 0.2126 * rgb[3 * p] + 0.7152 * rgb[3 * p + 1] + 0.0722 * rgb[3 * p + 2];
}

TEST_CASE_TEMPLATE("image environment: each sample's pdf and radiance equal pdf() and emitted() for its direction", S, Mono,
                   Rgb) {
    const int w = 64, h = 32;
    const std::vector<float> rgb = test_image(w, h);
    const ImageEnvironmentLight<S> light(w, h, rgb, 2.f);
    Pcg32 rng(3, 1);
    int zero = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 x(rng.uniform(), rng.uniform(), rng.uniform());  // a light at infinity: x does not matter
        const float sel = 0.25f + 0.75f * rng.uniform();
        const auto s = light.sample(x, rng.uniform(), rng.uniform(), {}, sel);
        if (!(s.pdf > 0.f)) {  // only where rounding moves a direction into a black pixel
            ++zero;
            continue;
        }
        CHECK(std::isinf(s.distance));
        CHECK_FALSE(s.delta);
        CHECK(glm::length(s.wi) == doctest::Approx(1.f).epsilon(1e-5));
        CHECK(light.pdf(x, s.wi, sel) == doctest::Approx(s.pdf).epsilon(1e-4));
        CHECK((light.emitted(s.wi) == s.radiance).all());
        // Against the test's own mapping: the pixel's radiance, and pdf = P(pixel) / Omega(pixel).
        const int p = pixel_of(s.wi, w, h);
        CHECK(luminance(rgb, std::size_t(p)) > 0.0);
        if constexpr (S::channels == 3) CHECK(s.radiance[0] == doctest::Approx(2.f * rgb[3 * std::size_t(p)]));
        else CHECK(s.radiance[0] == doctest::Approx(2.0 * luminance(rgb, std::size_t(p))));
    }
    CHECK(zero <= 2);
    // Directions into a black pixel, at the poles and non-finite ones: pdf 0 or finite, never NaN.
    const float pole_pdf = light.pdf(Vec3(0.f), Vec3(0.f, 1.f, 0.f));
    CHECK((std::isfinite(pole_pdf) && pole_pdf > 0.f));
    CHECK(std::isfinite(light.pdf(Vec3(0.f), Vec3(0.f, -1.f, 0.f))));
    CHECK(light.pdf(Vec3(0.f), Vec3(std::numeric_limits<float>::quiet_NaN(), 0.f, 1.f)) == 0.f);
    CHECK(light.emitted(Vec3(std::numeric_limits<float>::quiet_NaN(), 0.f, 1.f))[0] == 0.f);
    // The centre of the black pixel (w / 2, h / 2): theta = pi (h/2 + 1/2) / h, phi = 2 pi (w/2 + 1/2) / w.
    const float theta = kPi * (float(h / 2) + 0.5f) / float(h), phi = 2.f * kPi * (float(w / 2) + 0.5f) / float(w);
    const Vec3 black(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
    CHECK(light.pdf(Vec3(0.f), black) == 0.f);
    CHECK(light.emitted(black)[0] == 0.f);
}

TEST_CASE("image environment: the pdf integrates to 1 over the sphere") {
    // Midpoint rule on 1024 x 512 cells uniform in (phi, cos theta). The pdf is constant on each
    // pixel; the columns of cells line up with the 64 pixel columns, but a cell that straddles one
    // of the 31 row edges (cos theta = cos(pi j / 32)) takes the pdf of one side for all of its
    // area. The quadrature's error is at most the sum, over those cells, of the cell's area times
    // the pdf's jump across the edge: that sum is the tolerance, computed below (plus 1e-5 for
    // float accumulation).
    const int w = 64, h = 32, nphi = 1024, nz = 512;
    const ImageEnvironmentLight<Rgb> light(w, h, test_image(w, h));
    const double cell = (2.0 * 3.14159265358979323846 / nphi) * (2.0 / nz);
    double integral = 0.0, bound = 0.0;
    for (int k = 0; k < nz; ++k) {
        const double z0 = 1.0 - 2.0 * k / nz, z1 = 1.0 - 2.0 * (k + 1) / nz;
        const float z = float(1.0 - 2.0 * (k + 0.5) / nz), r = std::sqrt(1.f - z * z);
        const int row0 = pixel_of(Vec3(0.f, float(z0), 0.f), 1, h), row1 = pixel_of(Vec3(0.f, float(z1), 0.f), 1, h);
        for (int i = 0; i < nphi; ++i) {
            const float phi = 2.f * kPi * (float(i) + 0.5f) / float(nphi);
            integral += double(light.pdf(Vec3(0.f), Vec3(r * std::sin(phi), z, -r * std::cos(phi)))) * cell;
            if (row0 != row1) {  // straddles a row edge: the jump between the two pixels
                auto at = [&](double zz) {
                    const float rr = float(std::sqrt(std::max(0.0, 1.0 - zz * zz)));
                    return double(light.pdf(Vec3(0.f), Vec3(rr * std::sin(phi), float(zz), -rr * std::cos(phi))));
                };
                bound += cell * std::abs(at(z0 - 1e-6) - at(z1 + 1e-6));
            }
        }
    }
    CAPTURE(bound);
    CHECK(bound < 0.05);  // the check below means something
    CHECK(std::abs(integral - 1.0) <= bound + 1e-5);
}

TEST_CASE_TEMPLATE("image environment: radiance / pdf estimates the image's integral over the sphere", S, Mono, Rgb) {
    // The integral of the radiance over the sphere, exactly from the pixels:
    // sum over pixels of scale x value x (2 pi / W)(cos theta_top - cos theta_bottom).
    const int w = 40, h = 20;
    const float scale = 0.5f;
    const std::vector<float> rgb = test_image(w, h);
    const ImageEnvironmentLight<S> light(w, h, rgb, scale);
    std::array<double, 3> exact{};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t p = std::size_t(y * w + x);
            const double omega = pixel_solid_angle(w, h, y);
            if constexpr (S::channels == 1) exact[0] += scale * luminance(rgb, p) * omega;
            else
                for (std::size_t c = 0; c < 3; ++c) exact[c] += scale * double(rgb[3 * p + c]) * omega;
        }
    Pcg32 rng(11, 3);
    SpecStat<S> est;
    for (int i = 0; i < 40000; ++i) {
        const auto s = light.sample(Vec3(0.f), rng.uniform(), rng.uniform());
        est.add(s.pdf > 0.f ? typename S::Spectrum(s.radiance / s.pdf) : typename S::Spectrum(S::Spectrum::Zero()));
    }
    for (int c = 0; c < S::channels; ++c) {
        const Stat& st = est.ch[std::size_t(c)];
        CAPTURE(c);
        CAPTURE(st.mean);
        CAPTURE(st.se());
        CAPTURE(exact[std::size_t(c)]);
        CHECK(std::abs(st.mean - exact[std::size_t(c)]) <= kSigmas * st.se() + kRoundingFloor * exact[std::size_t(c)]);
    }
    // Mono radiance is the luminance the pixels are drawn by, and the pdf is constant over each
    // pixel: every sample is the integral itself (float rounding: 1e-5 relative).
    if constexpr (S::channels == 1) {
        CHECK(est.ch[0].se() <= 1e-5 * exact[0]);
        CHECK(est.ch[0].mean == doctest::Approx(exact[0]).epsilon(1e-5));
    }
}

TEST_CASE("image environment: pixels are drawn with probability luminance x solid angle (chi-square)") {
    // An 8 x 4 image with two black pixels (test_image's (4, 2) and (5, 0)): 30 bins of expected probability
    // luminance x Omega(pixel) / sum, 2e5 samples, Pearson's chi-square below its 0.1% point for
    // 29 degrees of freedom (58.301); the black pixels are never drawn.
    const int w = 8, h = 4, n = 200000;
    const std::vector<float> rgb = test_image(w, h, false);
    std::vector<float> with_black = rgb;
    for (std::size_t c = 0; c < 3; ++c) with_black[3 * 5 + c] = 0.f;
    const ImageEnvironmentLight<Rgb> light(w, h, with_black);
    std::vector<double> weight(std::size_t(w * h));
    double total = 0.0;
    for (int p = 0; p < w * h; ++p) {
        weight[std::size_t(p)] = luminance(with_black, std::size_t(p)) * pixel_solid_angle(w, h, p / w);
        total += weight[std::size_t(p)];
    }
    std::vector<double> hits(std::size_t(w * h), 0.0);
    Pcg32 rng(7, 2);
    for (int i = 0; i < n; ++i) hits[std::size_t(pixel_of(light.sample(Vec3(0.f), rng.uniform(), rng.uniform()).wi, w, h))] += 1.0;
    std::vector<double> counts, prob;
    for (int p = 0; p < w * h; ++p) {
        if (weight[std::size_t(p)] > 0.0) {
            counts.push_back(hits[std::size_t(p)]);
            prob.push_back(weight[std::size_t(p)] / total);
        } else {
            CHECK(hits[std::size_t(p)] == 0.0);
        }
    }
    REQUIRE(counts.size() == 30);
    const double chi2 = chi_square(counts, prob, n);
    CAPTURE(chi2);
    CHECK(chi2 < chi_square_critical_p001(29));
}

TEST_CASE("image environment: a constant image is EnvironmentLight, in a LightSampler too") {
    // One grey pixel, or any image of one value: pdf 1 / (4 pi) everywhere (the pixel solid
    // angles cancel), the same radiance and power as EnvironmentLight; a LightSampler lists it
    // among its lights at infinity and starts light subpaths from it on a BoundingSphere's disk.
    using M = Mono;
    const ImageEnvironmentLight<M> image(6, 3, std::vector<float>(54, 0.7f));
    const EnvironmentLight<M> constant{M::Spectrum::Constant(0.7f)};
    CHECK(image.power(2.f) == doctest::Approx(constant.power(2.f)).epsilon(1e-5));
    const BoundingSphere sphere{Vec3(0.f, 1.f, 0.f), 2.f};
    const LightSampler<M, QuadLight<M>, ImageEnvironmentLight<M>> sampler(
        LightSelection::Power, sphere, {QuadLight<M>{Vec3(-1.f, 3.f, -1.f), Vec3(2.f, 0.f, 0.f), Vec3(0.f, 0.f, 2.f), M::Spectrum::Ones()}},
        {image});
    REQUIRE(sampler.infinite() == std::vector<int>{1});
    CHECK(LightSampler<M, ImageEnvironmentLight<M>>::bidirectional_ready());
    const float sel = sampler.selection_pdf(1);
    CHECK(sel == doctest::Approx(constant.power(2.f) / (constant.power(2.f) + kPi * 4.f)).epsilon(1e-5));
    Pcg32 rng(5, 9);
    int emitted = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 w = uniform_sphere(rng.uniform(), rng.uniform());
        CHECK(image.pdf(Vec3(0.f), w) == doctest::Approx(kInv4Pi).epsilon(1e-4));
        CHECK(sampler.pdf(1, Vec3(0.f), w) == doctest::Approx(sel * kInv4Pi).epsilon(1e-4));
        CHECK(sampler.emitted(1, w)[0] == doctest::Approx(0.7f));
        const auto e = sampler.sample_emission(rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform());
        if (e.light != 1) continue;
        ++emitted;
        REQUIRE(e.emission.pdf_pos > 0.f);
        CHECK(e.emission.at_infinity);
        // emission_pdf at a point the ray reaches inside the sphere (the disk itself is its edge).
        const EmissionDensity d = sampler.emission_pdf(1, e.emission.p + sphere.radius * e.emission.w, e.emission.w);
        CHECK(d.pdf_pos == doctest::Approx(e.emission.pdf_pos).epsilon(1e-4));
        CHECK(d.pdf_dir == doctest::Approx(e.emission.pdf_dir).epsilon(1e-4));
        CHECK(e.emission.radiance[0] == doctest::Approx(0.7f));
    }
    CHECK(emitted > 1000);  // selection by power: the sky sends far more than the lamp
}

TEST_CASE("image environment: bad images are rejected with the bad value") {
    using L = ImageEnvironmentLight<Rgb>;
    const std::vector<float> ok = test_image(4, 2, false);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH_AS(L(0, 2, ok), doctest::Contains("ImageEnvironmentLight width = 0 is not allowed: it must be > 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(L(4, -1, ok), doctest::Contains("ImageEnvironmentLight height = -1 is not allowed: it must be > 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(L(4, 3, ok), doctest::Contains("rgb size = 24 is not allowed: it must be width x height x 3 = 4 x 3 x 3 = 36"),
                         InvalidArgument);
    auto with = [&](std::size_t i, float v) {
        std::vector<float> bad = ok;
        bad[i] = v;
        return bad;
    };
    CHECK_THROWS_WITH_AS(L(4, 2, with(3 * 6 + 1, nan)),
                         doctest::Contains("pixel (x 2, y 1) channel 1 = nan is not allowed: every value must be finite and >= 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(L(4, 2, with(2, -0.5f)), doctest::Contains("pixel (x 0, y 0) channel 2 = -0.5 is not allowed"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(L(4, 2, with(0, std::numeric_limits<float>::infinity())),
                         doctest::Contains("channel 0 = inf is not allowed"), InvalidArgument);
    CHECK_THROWS_WITH_AS(L(4, 2, ok, -1.f), doctest::Contains("ImageEnvironmentLight scale = -1 is not allowed: it must be finite and >= 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(L(4, 2, ok, nan), doctest::Contains("ImageEnvironmentLight scale = nan is not allowed"), InvalidArgument);
    CHECK_THROWS_WITH_AS(L(4, 2, std::vector<float>(24, 0.f)),
                         doctest::Contains("all 8 pixels have luminance 0, which is not allowed"), InvalidArgument);
    CHECK_NOTHROW(L(1, 1, {0.f, 0.f, 1.f}));  // one pixel: a constant sky, blue only
    // Scale 0 is a dark sky, not an error: it is still sampled by the image's luminance.
    const L dark(4, 2, ok, 0.f);
    const auto s = dark.sample(Vec3(0.f), 0.3f, 0.6f);
    CHECK(s.pdf > 0.f);
    CHECK(s.radiance.isZero());
    CHECK(dark.power(1.f) == 0.f);
}

TEST_CASE("image environment: PathEstimator renders the sky through vacuum exactly, through a medium without bias") {
    using namespace nsp_test::grey_scenes;
    using ILs = LightSampler<S, ImageEnvironmentLight<S>>;
    using ISc = SurfaceScene<NoSurfaces, M, GlobalMajorant<M>, HenyeyGreensteinPhase, Mats, ILs>;
    const int w = 32, h = 16;
    const ImageEnvironmentLight<S> sky(w, h, test_image(w, h));
    const PathEstimator<strategy::NullScatteringMis, mis::Balance> nee_mis;
    const PathEstimator<strategy::Unidirectional> uni;
    LookupCount counter;

    // Vacuum: a camera ray reaches the sky unchanged, whatever the strategy.
    const ISc vacuum(NoSurfaces{}, {}, materials(), ILs(LightSelection::Uniform, 3.f, {sky}), -1);
    Pcg32 rng(21, 1);
    for (int i = 0; i < 200; ++i) {
        const Ray r{Vec3(0.f), uniform_sphere(rng.uniform(), rng.uniform())};
        const auto a = nee_mis.radiance(vacuum, r, {}, rng, counter);
        const auto b = uni.radiance(vacuum, r, {}, rng, counter);
        REQUIRE(a.status == Status::Ok);
        REQUIRE(b.status == Status::Ok);
        CHECK(a.value[0] == sky.emitted(r.d)[0]);
        CHECK(b.value[0] == sky.emitted(r.d)[0]);
    }

    // A box of scattering medium (optical radius 1, albedo 0.8, HG 0.3) around the camera, the
    // image the only light: hitting the sky alone and NEE + hitting with the balance heuristic
    // are both unbiased; their means agree within 5 combined standard errors (independent seeds).
    const ISc fog(NoSurfaces{}, {medium(Box{Vec3(-1.f), Vec3(1.f)}, 0.2f, 0.8f)}, materials(),
                  ILs(LightSelection::Uniform, 3.f, {sky}), 0);
    auto ray = [](Pcg32& r) { return Ray{Vec3(0.1f, -0.2f, 0.f), uniform_sphere(r.uniform(), r.uniform())}; };
    const Stat a = estimate(nee_mis, fog, 40000, 41, ray);
    const Stat b = estimate(uni, fog, 40000, 42, ray);
    CAPTURE(a.mean);
    CAPTURE(a.se());
    CAPTURE(b.mean);
    CAPTURE(b.se());
    CHECK(a.mean > 0.0);
    CHECK(std::abs(a.mean - b.mean) <= kSigmas * std::sqrt(a.se() * a.se() + b.se() * b.se()));
}

}  // namespace
