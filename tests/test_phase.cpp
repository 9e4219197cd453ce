// tests/test_phase.cpp: phase functions integrate to 1 over the sphere, pdf equals eval, and
// sampled directions follow the pdf (chi-square on histograms of cos(theta) and azimuth).
#include <algorithm>
#include <string>
#include <vector>

#include "common.hpp"

namespace {

using namespace nsp_test;

/// Closed-form CDF of cos(theta) = dot(wo, wi) under HG with asymmetry g (isotropic at g = 0):
/// P(cos <= x) = (1 - g^2) / (2g) * [(1 + g^2 - 2 g x)^{-1/2} - 1 / (1 + g)], from integrating
/// 2 pi f_p over the cap. Evaluated in double, independently of the sampler's inversion.
double hg_cos_cdf(double g, double x) {
    if (g == 0.0) return 0.5 * (x + 1.0);
    return (1.0 - g * g) / (2.0 * g) * (1.0 / std::sqrt(1.0 + g * g - 2.0 * g * x) - 1.0 / (1.0 + g));
}

/// Edges of `bins` equal-probability bins of cos(theta), by bisection on the CDF.
std::vector<double> equal_probability_edges(double g, int bins) {
    std::vector<double> edges{-1.0};
    for (int i = 1; i < bins; ++i) {
        const double target = double(i) / bins;
        double lo = -1.0, hi = 1.0;
        for (int it = 0; it < 100; ++it) {
            const double mid = 0.5 * (lo + hi);
            (hg_cos_cdf(g, mid) < target ? lo : hi) = mid;
        }
        edges.push_back(0.5 * (lo + hi));
    }
    edges.push_back(1.0);
    return edges;
}

/// The phase functions under test with the g they have (isotropic counts as g = 0).
template <class Fn>
void for_each_phase(Fn&& fn) {
    fn(IsotropicPhase{}, 0.0, "isotropic");
    for (const float g : {-0.9f, 0.f, 0.3f, 0.9f}) fn(HenyeyGreensteinPhase(g), double(g), "hg");
}

const Vec3 kWo = glm::normalize(Vec3(0.3f, -0.5f, 0.8f));

TEST_CASE("phase functions integrate to 1 over the sphere") {
    for_each_phase([](const auto& phase, double g, const std::string& name) {
        CAPTURE(name);
        CAPTURE(g);
        // (a) 1D: int f dw = 2 pi int_{-1}^{1} f(cos) dcos, midpoint rule with 2e5 intervals in cos
        // around wo. Quadrature error for g = 0.9 is ~1e-7; expected 1 within 1e-4.
        {
            constexpr int n = 200000;
            double sum = 0.0;
            for (int i = 0; i < n; ++i) {
                const float c = float(-1.0 + (i + 0.5) * 2.0 / n);
                sum += phase.eval(kWo, direction_around(kWo, c, 0.7f));
            }
            CHECK(2.0 * double(kPi) * sum * (2.0 / n) == doctest::Approx(1.0).epsilon(1e-4));
        }
        // (b) 2D over the whole sphere in a fixed frame (z up) with wo tilted, so the integrand
        // really depends on both angles: midpoint in (z, phi), 1500 x 3000 cells. Its error for the
        // g = 0.9 peak (width ~0.1 rad) is below 1e-4; expected 1 within 1e-3.
        {
            constexpr int nz = 1500, nphi = 3000;
            double sum = 0.0;
            for (int i = 0; i < nz; ++i) {
                const float z = float(-1.0 + (i + 0.5) * 2.0 / nz);
                const float r = std::sqrt(std::max(0.f, 1.f - z * z));
                for (int j = 0; j < nphi; ++j) {
                    const float phi = float((j + 0.5) * 2.0 * double(kPi) / nphi);
                    sum += phase.eval(kWo, Vec3(r * std::cos(phi), r * std::sin(phi), z));
                }
            }
            CHECK(sum * (2.0 / nz) * (2.0 * double(kPi) / nphi) == doctest::Approx(1.0).epsilon(1e-3));
        }
    });
}

TEST_CASE("phase functions: pdf equals eval, and samples report their own pdf and value") {
    for_each_phase([](const auto& phase, double g, const std::string& name) {
        CAPTURE(name);
        CAPTURE(g);
        Pcg32 rng(3, 4);
        for (int i = 0; i < 2000; ++i) {
            const Vec3 wo = random_direction(rng), wi = random_direction(rng);
            REQUIRE(phase.pdf(wo, wi) == phase.eval(wo, wi));
            const float u1 = rng.uniform(), u2 = rng.uniform();
            const PhaseSample s = phase.sample(wo, u1, u2);
            REQUIRE(glm::length(s.wi) == doctest::Approx(1.0).epsilon(1e-5));
            REQUIRE(s.pdf > 0.f);
            REQUIRE(s.pdf == doctest::Approx(phase.pdf(wo, s.wi)).epsilon(1e-3));
            REQUIRE(s.value == doctest::Approx(phase.eval(wo, s.wi)).epsilon(1e-3));
        }
    });
}

TEST_CASE("phase function sampling follows the pdf (chi-square)") {
    for_each_phase([](const auto& phase, double g, const std::string& name) {
        CAPTURE(name);
        CAPTURE(g);
        // 20 equal-probability bins of cos(theta) (expected count n/20 = 10000 each), dof = 19,
        // critical value 43.82 at p = 1e-3; 16 azimuth bins (uniform), dof = 15, critical 37.697.
        constexpr int n = 200000, bins = 20, phi_bins = 16;
        const auto edges = equal_probability_edges(g, bins);
        std::vector<double> counts(bins, 0.0), phi_counts(phi_bins, 0.0);
        Vec3 s_axis, t_axis;  // our own frame around wo, to measure azimuth
        const Vec3 helper = std::abs(kWo.x) < 0.9f ? Vec3(1.f, 0.f, 0.f) : Vec3(0.f, 1.f, 0.f);
        s_axis = glm::normalize(glm::cross(kWo, helper));
        t_axis = glm::cross(kWo, s_axis);
        Pcg32 rng(11, 12);
        for (int i = 0; i < n; ++i) {
            const float u1 = rng.uniform(), u2 = rng.uniform();
            const PhaseSample s = phase.sample(kWo, u1, u2);
            const double c = std::clamp(double(glm::dot(kWo, s.wi)), -1.0, 1.0);
            const auto bin = std::upper_bound(edges.begin() + 1, edges.end() - 1, c) - (edges.begin() + 1);
            counts[std::size_t(bin)] += 1.0;
            const double phi = std::atan2(double(glm::dot(s.wi, t_axis)), double(glm::dot(s.wi, s_axis))) + double(kPi);
            phi_counts[std::size_t(std::min(phi_bins - 1, int(phi / (2.0 * double(kPi)) * phi_bins)))] += 1.0;
        }
        const double chi2 = chi_square(counts, std::vector<double>(bins, 1.0 / bins), n);
        CHECK(chi2 < chi_square_critical_p001(bins - 1));
        const double chi2_phi = chi_square(phi_counts, std::vector<double>(phi_bins, 1.0 / phi_bins), n);
        CHECK(chi2_phi < chi_square_critical_p001(phi_bins - 1));
    });
}

}  // namespace
