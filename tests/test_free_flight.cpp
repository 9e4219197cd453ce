// tests/test_free_flight.cpp: free-flight sampling follows its stated densities (THEORY 4.1-4.3):
// tentative collisions form a Poisson process of rate mu_bar, delta tracking's real collisions
// follow the true free-flight distribution, and the lookup counter counts every lookup.
#include <string>
#include <vector>

#include "common.hpp"

namespace {

using namespace nsp_test;

const Box kSlab{Vec3(0.f, -1.f, -1.f), Vec3(10.f, 1.f, 1.f)};

/// The media whose tentative collisions we test: the process depends only on the majorant.
template <class Fn>
void for_each_flight_medium(Fn&& fn) {
    fn(HomogeneousMedium<Mono>(kSlab, grey<Mono>(0.2f), grey<Mono>(0.5f)), "homogeneous");
    fn(make_medium<DenseGridMedium<Mono>>(kSlab, 0.6f, grey<Mono>(0.3f), grey<Mono>(0.7f), 5), "grid");
}

TEST_CASE("free_flight: the first tentative collision is Exp(mu_bar) (chi-square)") {
    for_each_flight_medium([](const auto& medium, const std::string& name) {
        using M = std::decay_t<decltype(medium)>;
        CAPTURE(name);
        // Majorant m = 2 (above either medium's bound), ray entering the slab at t0 = 1 and stopping
        // at tmax = t0 + L with m L = 3. Bins: 20 of equal probability (1 - e^-3) / 20 = 0.0475 over
        // [0, L) of s = t - t0, plus "passed tmax" with e^-3 = 0.0498. dof = 20, critical value 45.315
        // at p = 1e-3, n = 1e5 (expected counts >= 4750).
        const float m = 2.f, L = 1.5f, t0 = 1.f;
        const GlobalMajorant<M> maj(medium, m);
        const Ray ray{Vec3(-1.f, 0.2f, -0.3f), Vec3(1.f, 0.f, 0.f)};
        constexpr int n = 100000, bins = 20;
        const double p_pass = std::exp(-double(m) * L);
        std::vector<double> prob(bins, (1.0 - p_pass) / bins), counts(bins + 1, 0.0);
        prob.push_back(p_pass);
        Pcg32 rng(99, 1);
        NoLookupCount none;
        for (int i = 0; i < n; ++i) {
            const FlightEnd f = free_flight(medium, maj, ray, 0.f, t0 + L, Mono::Wavelengths{}, rng, none,
                                            [](float, const Coefficients<Mono>&, float, float) { return false; });
            REQUIRE(!f.aborted);
            if (!f.stopped) {
                counts[bins] += 1.0;
                continue;
            }
            const double s = double(f.t) - t0;
            REQUIRE(s >= 0.0);
            REQUIRE(s < L);
            // Bin index from the Exp(m) cdf: F(s) / (1 - e^{-mL}) in [0, 1).
            const double u = -std::expm1(-double(m) * s) / (1.0 - p_pass);
            counts[std::size_t(std::min(bins - 1, int(u * bins)))] += 1.0;
        }
        CHECK(chi_square(counts, prob, n) < chi_square_critical_p001(bins));
    });
}

TEST_CASE("free_flight: tentative collisions per ray are Poisson(mu_bar L); the counter counts each lookup") {
    for_each_flight_medium([](const auto& medium, const std::string& name) {
        using M = std::decay_t<decltype(medium)>;
        CAPTURE(name);
        // A Poisson process of rate m over a length L has Poisson(m L) points. m = 1.5, L = 2 (ray
        // starting inside the slab at x = 0.5): mean 3. Bins: counts 0..9 and >= 10 (P = 1.1e-3,
        // expected 110). dof = 10, critical value 29.588 at p = 1e-3, n = 1e5.
        const float m = 1.5f, L = 2.f;
        const GlobalMajorant<M> maj(medium, m);
        const Ray ray{Vec3(0.5f, 0.1f, 0.f), glm::normalize(Vec3(1.f, 0.1f, 0.05f))};
        constexpr int n = 100000, bins = 11;
        std::vector<double> prob(bins, 0.0), counts(bins, 0.0);
        double pk = std::exp(-double(m) * L), ptail = 1.0;
        for (int k = 0; k < bins - 1; ++k) {
            prob[std::size_t(k)] = pk;
            ptail -= pk;
            pk *= double(m) * L / (k + 1);
        }
        prob[bins - 1] = ptail;
        Pcg32 rng(7, 3);
        LookupCount lookups;
        std::uint64_t calls = 0, bad = 0;
        for (int i = 0; i < n; ++i) {
            int k = 0;
            const FlightEnd f = free_flight(medium, maj, ray, 0.f, L, Mono::Wavelengths{}, rng, lookups,
                                            [&](float t, const Coefficients<Mono>&, float mu_bar, float) {
                                                ++k;
                                                ++calls;
                                                bad += !(mu_bar == m && t >= 0.f && t < L);
                                                return true;
                                            });
            REQUIRE(!f.stopped);
            REQUIRE(!f.aborted);
            counts[std::size_t(std::min(k, bins - 1))] += 1.0;
        }
        CHECK(bad == 0);  // every collision inside [0, L) with the majorant's value
        CHECK(chi_square(counts, prob, n) < chi_square_critical_p001(bins - 1));
        // One density lookup per callback invocation, none otherwise.
        CHECK(lookups.count() == calls);
        CHECK(calls > std::uint64_t(n));
    });
}

TEST_CASE("lookup counts equal callback invocations when the callback stops early") {
    const auto medium = make_medium<DenseGridMedium<Rgb>>(kSlab, 1.f, spec<Rgb>(0.1f, 0.2f, 0.3f),
                                                          spec<Rgb>(0.5f, 0.5f, 0.9f), 3);
    const GlobalMajorant<DenseGridMedium<Rgb>> maj(medium, 4.f);
    Pcg32 rng(5, 5);
    for (int i = 0; i < 2000; ++i) {
        const Ray ray{random_point(rng, kSlab), random_direction(rng)};
        LookupCount lookups;
        std::uint64_t calls = 0;
        const float u_stop = rng.uniform();
        free_flight(medium, maj, ray, 0.f, kInf, Rgb::Wavelengths{}, rng, lookups,
                    [&](float, const Coefficients<Rgb>&, float, float) {
                        ++calls;
                        return calls < 1 + std::uint64_t(10.f * u_stop);
                    });
        REQUIRE(lookups.count() == calls);
    }
}

TEST_CASE("free_flight gives up after max_collisions and reports it") {
    const HomogeneousMedium<Mono> medium(kSlab, grey<Mono>(0.f), grey<Mono>(1.f));
    const GlobalMajorant<HomogeneousMedium<Mono>> maj(medium, 1000.f);
    Pcg32 rng(1, 1);
    LookupCount lookups;
    const Ray ray{Vec3(0.f), Vec3(1.f, 0.f, 0.f)};
    const FlightEnd f = free_flight(medium, maj, ray, 0.f, 10.f, Mono::Wavelengths{}, rng, lookups,
                                    [](float, const Coefficients<Mono>&, float, float) { return true; }, 100);
    CHECK(f.aborted);
    CHECK(!f.stopped);
    CHECK(lookups.count() == 100);
}

using ExponentialCombos = std::tuple<Combo<Mono, ExponentialMedium, absorption::Event>,
                                     Combo<Mono, ExponentialMedium, absorption::Weight>,
                                     Combo<Rgb, ExponentialMedium, absorption::Event>,
                                     Combo<Rgb, ExponentialMedium, absorption::Weight>>;

TEST_CASE_TEMPLATE_DEFINE("delta tracking's real collisions follow 1 - exp(-optical depth) (chi-square)", C,
                          delta_distance) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    // Exponential density d0 e^{k s}, s along an oblique axis, scales sigma_a = 0.3 c, sigma_s = 0.7 c
    // per channel (c = 1 on Mono; 1, 0.5, 2 on Rgb). The ray enters the box at t = 0.5 and we stop at
    // tmax = 2.2 (inside the box). Delta tracking drives one pdf for all channels by the channel mean
    // of mu_t, so its real-collision distance has cdf F(t) = 1 - exp(-mean_c tau_c(0, t)), tau_c the
    // closed-form optical depth (ExponentialMedium::optical_depth); P(pass tmax) = 1 - F(tmax).
    // Bins: 20 of equal width over [0.5, 2.2) plus "passed"; dof = 20, critical value 45.315 at
    // p = 1e-3, n = 1e5 (the smallest expected count is checked to be >= 5).
    const Box box{Vec3(0.f), Vec3(2.f)};
    const auto c = spec<S>(1.f, 0.5f, 2.f);
    const M medium(box, glm::normalize(Vec3(1.f, 1.f, 0.f)), 0.4f, 1.2f, 0.3f * c, 0.7f * c);
    const Ray ray{Vec3(-0.5f, 0.7f, 1.f), Vec3(1.f, 0.f, 0.f)};
    const float t_in = 0.5f, tmax = 2.2f;
    auto cdf = [&](float t) { return 1.0 - std::exp(-double(medium.optical_depth(ray, 0.f, t).mean())); };
    constexpr int n = 100000, bins = 20;
    std::vector<double> prob;
    for (int b = 0; b < bins; ++b) {
        const float lo = t_in + (tmax - t_in) * float(b) / bins, hi = t_in + (tmax - t_in) * float(b + 1) / bins;
        prob.push_back(cdf(hi) - cdf(lo));
    }
    prob.push_back(1.0 - cdf(tmax));

    const GlobalMajorant<M> tight(medium);
    for (const float looseness : {1.f, 2.f}) {
        CAPTURE(looseness);
        const GlobalMajorant<M> maj(medium, tight.value() * looseness);
        std::vector<double> counts(bins + 1, 0.0);
        double absorbed = 0.0, real = 0.0;
        Pcg32 rng(31, 17);
        NoLookupCount none;
        for (int i = 0; i < n; ++i) {
            const auto d = track_delta<A>(medium, maj, ray, tmax, typename S::Wavelengths{}, rng, none);
            REQUIRE(d.end != SegmentEnd::Aborted);
            if (d.end == SegmentEnd::Passed) {
                counts[bins] += 1.0;
                continue;
            }
            REQUIRE(d.t >= t_in);
            REQUIRE(d.t < tmax);
            counts[std::size_t(std::min(bins - 1, int((d.t - t_in) / (tmax - t_in) * bins)))] += 1.0;
            real += 1.0;
            absorbed += d.end == SegmentEnd::Absorbed;
        }
        CHECK(chi_square(counts, prob, n) < chi_square_critical_p001(bins));
        if constexpr (A::as_event) {
            // Absorbed / real = mean sigma_a / mean mu_t = 0.3 everywhere; binomial SE
            // sqrt(0.3 * 0.7 / real) ~ 2e-3, tolerance 5 SE.
            CHECK(std::abs(absorbed / real - 0.3) < 5.0 * std::sqrt(0.3 * 0.7 / real));
        } else {
            CHECK(absorbed == 0.0);
        }
    }
}

TEST_CASE_TEMPLATE_APPLY(delta_distance, ExponentialCombos);

}  // namespace
