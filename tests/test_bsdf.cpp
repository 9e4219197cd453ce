// tests/test_bsdf.cpp: the rough dielectric (nsp::RoughDielectricBsdf, bsdf.hpp) against
// independent evaluation: each sample's value and pdf equal eval() and pdf() for its direction;
// the samples' histogram over the sphere equals pdf() integrated over each bin by quadrature; the
// samples' mean weight equals the quadrature of eval(); eval is symmetric (what BDPT's light
// subpaths rely on); at alpha = 0.001 it is a smooth interface (Fresnel's R, Snell's law, the
// weight 1 / eta of the symmetric refraction lobe); bad input is refused by name, and unusable
// directions give nothing, never a NaN.
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "common.hpp"

namespace {

using namespace nsp_test;
using doctest::Contains;
using nsp::RoughDielectricBsdf;
using S = Mono;

// k = 5 standard errors with fixed seeds: deterministic.
constexpr double kSigmas = 5.0;

/// A hit on the plane z = 0, both normals +z (the side of index 1; eta is the side below's).
ShadingPoint plane_hit() {
    ShadingPoint sp;
    sp.ng = sp.ns = Vec3(0.f, 0.f, 1.f);
    return sp;
}

/// The direction with polar cosine c about +z and azimuth phi.
Vec3 polar(double c, double phi) {
    const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
    return Vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c));
}

/// A path arriving from above (side +1) or below (-1) at polar angle theta from the normal.
Vec3 arriving(double theta, float side) {
    return -polar(double(side) * std::cos(theta), 0.3);
}

/// Fresnel's reflectance of a smooth interface, relative index eta, incidence cosine c, in double.
double fresnel(double c, double eta) {
    const double s2 = (1.0 - c * c) / (eta * eta);
    if (s2 >= 1.0) return 1.0;
    const double ct = std::sqrt(1.0 - s2);
    const double rs = (c - eta * ct) / (c + eta * ct), rp = (eta * c - ct) / (eta * c + ct);
    return 0.5 * (rs * rs + rp * rp);
}

struct Case {
    float eta, alpha;
    double theta;  ///< incidence angle
    float side;    ///< +1: arriving from above (index 1), -1: from below (index eta)
};
const std::vector<Case> kCases{{1.5f, 0.15f, 0.9, 1.f},  {1.5f, 0.5f, 0.3, 1.f},  {1.5f, 0.3f, 0.4, -1.f},
                               {1.5f, 0.3f, 1.0, -1.f},  {1.33f, 0.8f, 1.3, 1.f}, {0.7f, 0.2f, 0.6, 1.f}};

TEST_CASE("rough dielectric: each sample's value and pdf are eval() and pdf() of its direction; eval is symmetric") {
    Pcg32 rng(3, 9);
    const ShadingPoint sp = plane_hit();
    int samples = 0, refracted = 0;
    for (const float eta : {1.5f, 1.f / 1.5f, 2.4f})
        for (const float alpha : {0.002f, 0.05f, 0.3f, 1.f, 2.f}) {
            const RoughDielectricBsdf<S> b(eta, alpha);
            for (int i = 0; i < 2000; ++i) {
                const Vec3 wo = -uniform_sphere(rng.uniform(), rng.uniform());
                const BsdfSample<S> s = b.sample(sp, wo, Vec3(rng.uniform(), rng.uniform(), rng.uniform()));
                CAPTURE(eta);
                CAPTURE(alpha);
                CHECK(std::isfinite(s.pdf));
                CHECK(std::isfinite(s.value[0]));
                if (!(s.pdf > 0.f)) continue;
                ++samples;
                CHECK_FALSE(s.delta);
                CHECK(std::abs(glm::length(s.wi) - 1.f) < 1e-4f);
                const float p = b.pdf(sp, wo, s.wi), v = b.eval(sp, wo, s.wi)[0];
                CHECK(p == doctest::Approx(s.pdf).epsilon(1e-3));
                CHECK(v == doctest::Approx(s.value[0]).epsilon(1e-3));
                // Symmetry f(wo -> wi) = f(-wi -> -wo): value / |n . wi| both ways.
                const float ci = std::abs(s.wi.z), co = std::abs(wo.z);
                if (ci < 1e-3f || co < 1e-3f || alpha < 0.01f) continue;  // float's cancellation near the peak
                if (s.wi.z * wo.z > 0.f) ++refracted;
                const float back = b.eval(sp, -s.wi, -wo)[0];
                CHECK(back / co == doctest::Approx(v / ci).epsilon(2e-3));
            }
        }
    CHECK(samples > 25000);
    CHECK(refracted > 5000);
}

/// The integral of f over the cell [c0, c1] x [p0, p1] of (cos theta, phi), by the midpoint rule on
/// m x m sub-cells.
template <class F>
double cell_integral(F f, double c0, double c1, double p0, double p1, int m) {
    const double dc = (c1 - c0) / m, dp = (p1 - p0) / m;
    double sum = 0.0;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) sum += f(polar(c0 + (i + 0.5) * dc, p0 + (j + 0.5) * dp));
    return sum * dc * dp;
}

TEST_CASE("rough dielectric: the samples' histogram is pdf() integrated over its bins; their mean weight the integral of eval()") {
    // 16 x 12 bins of equal solid angle over the whole sphere (cos theta about the normal, phi);
    // each bin's expected share is the integral of pdf() over it, by the midpoint rule on 24 x 24
    // sub-cells; the same with 12 x 12 bounds that rule's error. A bin's count must lie within 5
    // binomial standard errors plus twice that bound. The mean of value / pdf over 600000 samples
    // (failed draws count 0) is the integral of eval() over the sphere (5 SE plus the rule's
    // error): together, sample() draws from pdf() and weighs by eval() / pdf().
    constexpr int kC = 16, kP = 12, kN = 600000;
    const ShadingPoint sp = plane_hit();
    for (const Case& k : kCases) {
        CAPTURE(k.eta);
        CAPTURE(k.alpha);
        CAPTURE(k.theta);
        CAPTURE(k.side);
        const RoughDielectricBsdf<S> b(k.eta, k.alpha);
        const Vec3 wo = arriving(k.theta, k.side);
        std::vector<int> count(kC * kP, 0);
        Pcg32 rng(11, 4);
        Stat weight;
        for (int i = 0; i < kN; ++i) {
            const BsdfSample<S> s = b.sample(sp, wo, Vec3(rng.uniform(), rng.uniform(), rng.uniform()));
            if (!(s.pdf > 0.f)) {
                weight.add(0.0);
                continue;
            }
            weight.add(double(s.value[0]) / double(s.pdf));
            const int ci = std::min(kC - 1, int((double(s.wi.z) + 1.0) * 0.5 * kC));
            double phi = std::atan2(double(s.wi.y), double(s.wi.x));
            if (phi < 0.0) phi += 2.0 * kPi;
            const int pi = std::min(kP - 1, int(phi / (2.0 * kPi) * kP));
            ++count[std::size_t(ci * kP + pi)];
        }
        auto pdf = [&](const Vec3& wi) { return double(b.pdf(sp, wo, wi)); };
        auto value = [&](const Vec3& wi) { return double(b.eval(sp, wo, wi)[0]); };
        double total_value = 0.0, value_error = 0.0;
        int worst_bin = -1;
        double worst = 0.0;
        for (int ci = 0; ci < kC; ++ci)
            for (int pi = 0; pi < kP; ++pi) {
                const double c0 = -1.0 + 2.0 * ci / kC, c1 = -1.0 + 2.0 * (ci + 1) / kC;
                const double p0 = 2.0 * kPi * pi / kP, p1 = 2.0 * kPi * (pi + 1) / kP;
                const double fine = cell_integral(pdf, c0, c1, p0, p1, 24);
                const double rule = std::abs(fine - cell_integral(pdf, c0, c1, p0, p1, 12));
                const double share = double(count[std::size_t(ci * kP + pi)]) / kN;
                const double se = std::sqrt(std::max(fine, 1.0 / kN) * (1.0 - fine) / kN);
                const double excess = std::abs(share - fine) / (kSigmas * se + 2.0 * rule);
                if (excess > worst) worst = excess, worst_bin = ci * kP + pi;
                const double v = cell_integral(value, c0, c1, p0, p1, 24);
                total_value += v;
                value_error += std::abs(v - cell_integral(value, c0, c1, p0, p1, 12));
            }
        CAPTURE(worst_bin);
        CHECK(worst <= 1.0);
        CAPTURE(total_value);
        CAPTURE(weight.mean);
        CHECK(std::abs(weight.mean - total_value) <= kSigmas * weight.se() + 2.0 * value_error);
    }
}

TEST_CASE("rough dielectric: at alpha = 0.001 it is a smooth interface: Fresnel's R, Snell's law, weights 1 and 1 / eta") {
    // From either side at three angles (one beyond the critical angle from inside): the share of
    // samples reflected is Fresnel's R in closed form (5 binomial SE plus 0.002, R's change over
    // the microfacets' spread); reflected samples go within 0.01 of the mirror direction, refracted
    // ones within 0.01 of Snell's (all but GGX's tail, below), with weights value / pdf within 1% of 1 (reflection) and of
    // 1 / eta_rel (the symmetric refraction lobe: eta_rel the far side's index over the near's).
    const ShadingPoint sp = plane_hit();
    const float eta = 1.5f;
    const RoughDielectricBsdf<S> b(eta, 1e-3f);
    Pcg32 rng(5, 5);
    for (const float side : {1.f, -1.f})
        for (const double theta : {0.2, 0.5, 1.2}) {
            CAPTURE(side);
            CAPTURE(theta);
            const Vec3 wo = arriving(theta, side);
            const double rel = side > 0.f ? eta : 1.0 / eta, c = std::cos(theta), r = fresnel(c, rel);
            const Vec3 mirror(wo.x, wo.y, -wo.z);
            const double st = std::sin(theta) / rel;
            Vec3 snell(0.f);
            if (st < 1.0) {
                const Vec3 t = glm::normalize(Vec3(wo.x, wo.y, 0.f));
                snell = float(st) * t + float(-double(side) * std::sqrt(1.0 - st * st)) * Vec3(0.f, 0.f, 1.f);
            }
            constexpr int n = 40000;
            int reflected = 0, astray = 0;
            for (int i = 0; i < n; ++i) {
                const BsdfSample<S> s = b.sample(sp, wo, Vec3(rng.uniform(), rng.uniform(), rng.uniform()));
                REQUIRE(s.pdf > 0.f);
                const float w = s.value[0] / s.pdf;
                if (s.wi.z * wo.z < 0.f) {
                    ++reflected;
                    astray += glm::length(s.wi - mirror) > 0.01f;
                    CHECK(w == doctest::Approx(1.0).epsilon(0.01));
                } else {
                    astray += glm::length(s.wi - snell) > 0.01f;
                    CHECK(w == doctest::Approx(1.0 / rel).epsilon(0.01));
                }
            }
            const double share = double(reflected) / n;
            // GGX's tail puts a share alpha^2 / (alpha^2 + t^2) = 3.8% of the microfacet normals
            // beyond t = 5 alpha = 0.005 rad, the least tilt that turns a direction by 0.01 here.
            CHECK(astray <= 0.04 * n);
            CAPTURE(r);
            CAPTURE(share);
            CHECK(std::abs(share - r) <= kSigmas * std::sqrt(r * (1.0 - r) / n) + 0.002);
        }
}

TEST_CASE("rough dielectric: bad parameters are refused by name; unusable directions give nothing, never a NaN") {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH_AS(RoughDielectricBsdf<S>(1.f, 0.3f),
                         Contains("RoughDielectricBsdf eta = 1 is not allowed: it must be finite, > 0 and not 1"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(RoughDielectricBsdf<S>(nan, 0.3f), Contains("RoughDielectricBsdf eta = nan"), InvalidArgument);
    CHECK_THROWS_WITH_AS(RoughDielectricBsdf<S>(-1.5f, 0.3f), Contains("RoughDielectricBsdf eta = -1.5"), InvalidArgument);
    CHECK_THROWS_WITH_AS(RoughDielectricBsdf<S>(1.5f, 0.f),
                         Contains("RoughDielectricBsdf alpha = 0 is not allowed: it must lie in [0.001, 2]"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(RoughDielectricBsdf<S>(1.5f, kInf), Contains("RoughDielectricBsdf alpha = inf"), InvalidArgument);
    const RoughDielectricBsdf<S> b(1.5f, 0.3f);
    ShadingPoint bad = plane_hit();
    const Vec3 wo = glm::normalize(Vec3(0.3f, 0.f, -1.f)), wi = glm::normalize(Vec3(0.2f, 0.1f, 1.f));
    const std::array<Vec3, 4> unusable{Vec3(nan), Vec3(0.f), Vec3(0.f, 0.f, 2.f), Vec3(kInf, 0.f, 0.f)};
    for (const Vec3& v : unusable) {
        bad.ns = v;
        CHECK(b.sample(bad, wo, Vec3(0.5f)).pdf == 0.f);
        CHECK(b.eval(bad, wo, wi)[0] == 0.f);
        CHECK(b.pdf(bad, wo, wi) == 0.f);
        CHECK(b.sample(plane_hit(), v, Vec3(0.5f)).pdf == 0.f);
        CHECK(b.eval(plane_hit(), v, wi)[0] == 0.f);
        CHECK(b.eval(plane_hit(), wo, v)[0] == 0.f);
        CHECK(b.pdf(plane_hit(), wo, v) == 0.f);
    }
    // Grazing: in the plane, no sample and no value.
    CHECK(b.sample(plane_hit(), Vec3(1.f, 0.f, 0.f), Vec3(0.5f)).pdf == 0.f);
    CHECK(b.eval(plane_hit(), wo, Vec3(0.f, 1.f, 0.f))[0] == 0.f);
}

}  // namespace
