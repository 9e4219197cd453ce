// tests/test_decomposition.cpp: the free-flight loop under a control (THEORY 5.10): delta tracking
// becomes decomposition tracking and ratio tracking residual ratio tracking, and the two form the
// MIS pair of 5.10. Checked here: a control of 0 gives today's trackers draw for draw; a control
// equal to a homogeneous medium's extinction pays one lookup per real collision and none for the
// shadow ray, which is exact; transmittance and collision probabilities against closed forms on
// exponential media (grid control, global control below and above the density; Mono and Rgb on
// the grey axis); the recorded pdfs against an independent evaluation of p_uni and p_nee, whose
// ratio is the null product exp(-tau_c) prod P_n,r, and the MIS weights built from it sum to 1.
#include <cmath>
#include <string>
#include <vector>

#include "references.hpp"

namespace {

using namespace nsp_test;

// k = 5 standard errors of the mean (estimated from the samples); fixed seeds: deterministic.
constexpr double kSigmas = 5.0;
constexpr int kSamples = 20000;

template <SpectralMode S>
void check_mean(const SpecStat<S>& stat, const typename S::Spectrum& expected, const std::string& label) {
    check_channel_means(stat, expected, label, kSigmas);
}

/// A control of `f` times the medium's density lower bound over its box, per channel.
template <class M>
typename M::Spectral::Coefficient box_control(const M& medium, float f) {
    return scale(medium.extinction_per_density(), f * medium.density_lower_bound(medium.bounds()));
}

TEST_CASE("decomposition tracking: a homogeneous medium under its own extinction as control") {
    // mu_t = 1.2 everywhere and control 1.2: the residual majorant is 0, so no null is ever drawn.
    // Residual ratio tracking is exp(-1.2 L) exactly with no lookup; decomposition tracking looks the
    // medium up only at its real collision (for the albedo), so lookups = collided flights, and its
    // passing probability is exp(-1.2 L) within 5 SE.
    const Box box{Vec3(-1.f), Vec3(1.f)};
    const HomogeneousMedium<Mono> medium(box, grey<Mono>(0.3f), grey<Mono>(0.9f));
    const GlobalControl<HomogeneousMedium<Mono>> control(medium, grey<Mono>(1.2f));
    const Ray ray{Vec3(-3.f, 0.1f, 0.2f), Vec3(1.f, 0.f, 0.f)};
    const double expected = std::exp(-1.2 * 2.0);
    Pcg32 rng(7, 1);
    LookupCount n;
    const auto r = transmittance_ratio(medium, control, ray, kInf, {}, rng, n);
    CHECK(r.status == Status::Ok);
    CHECK(double(r.value[0]) == doctest::Approx(expected).epsilon(1e-6));
    CHECK(n.count() == 0);
    Stat pass;
    int collided = 0;
    for (int i = 0; i < kSamples; ++i) {
        const auto d = track_delta<absorption::Event>(medium, control, ray, kInf, {}, rng, n);
        REQUIRE(flight_status(d.end) == Status::Ok);
        const bool passed = d.end == SegmentEnd::Passed;
        collided += !passed;
        if (!passed) REQUIRE((d.t >= 2.f && d.t <= 4.f));  // inside the box
        pass.add(passed ? double(d.weight[0]) : 0.0);
        REQUIRE((passed ? d.weight[0] == 1.f : true));
    }
    MESSAGE("passing " << pass.mean << " (SE " << pass.se() << "), closed form " << expected);
    CHECK(std::abs(pass.mean - expected) <= kSigmas * pass.se());
    CHECK(n.count() == std::uint64_t(collided));
}

TEST_CASE("a control of 0: decomposition and residual ratio tracking are delta and ratio tracking, draw for draw") {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    using M = DenseGridMedium<Rgb>;
    const auto medium = make_medium<M>(box, 1.5f, spec<Rgb>(0.2f, 0.1f, 0.4f), spec<Rgb>(0.6f, 0.3f, 1.2f));
    const GlobalControl<M> zero(medium, spec<Rgb>(0.f, 0.f, 0.f));
    const GlobalMajorant<M> plain(medium);
    Pcg32 rays(5, 5);
    int differ = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 o(-3.f, 1.6f * rays.uniform() - 0.8f, 1.6f * rays.uniform() - 0.8f);
        const Ray ray{o, glm::normalize(Vec3(1.f, 0.3f * rays.uniform() - 0.15f, 0.3f * rays.uniform() - 0.15f))};
        Pcg32 a(i, 1), b(i, 1);
        LookupCount na, nb;
        const auto da = track_delta<absorption::Event>(medium, zero, ray, kInf, {}, a, na);
        const auto db = track_delta<absorption::Event>(medium, plain, ray, kInf, {}, b, nb);
        const auto ra = track_ratio<absorption::Weight, true>(medium, zero, ray, kInf, {}, a, na);
        const auto rb = track_ratio<absorption::Weight, true>(medium, plain, ray, kInf, {}, b, nb);
        const bool same = da.end == db.end && da.t == db.t && (da.weight == db.weight).all() &&
                          da.null_pdf_product == db.null_pdf_product && da.event_density == db.event_density &&
                          ra.end == rb.end && (ra.transmittance == rb.transmittance).all() &&
                          ra.null_pdf_product == rb.null_pdf_product && na.count() == nb.count() &&
                          a.uniform() == b.uniform();
        differ += !same;
    }
    CHECK(differ == 0);
}

/// Closed-form checks of the loop's trackers under a control on an exponential medium: delta
/// tracking's passing weight and ratio tracking's estimate are unbiased for T = exp(-tau) through
/// the box and to a point inside it, per channel on the grey axis.
template <SpectralMode S, class Ctl>
void check_closed_forms(const ExponentialMedium<S>& medium, const Ctl& control, const std::string& name,
                        std::uint64_t seed, std::uint64_t* lookups = nullptr) {
    using Spec = typename S::Spectrum;
    struct Case {
        const char* what;
        Ray ray;
        float tmax;
    };
    const Case cases[] = {
        {"through the box", Ray{Vec3(-3.f, 0.1f, -0.2f), glm::normalize(Vec3(1.f, 0.05f, 0.1f))}, kInf},
        {"to a point inside", Ray{Vec3(-0.6f, -0.5f, 0.3f), glm::normalize(Vec3(0.6f, 0.7f, -0.3f))}, 1.1f},
    };
    for (const Case& c : cases) {
        const Spec expected = (-medium.optical_depth(c.ray, 0.f, c.tmax)).exp();
        SpecStat<S> delta, ratio;
        Pcg32 rng(seed, 9);
        LookupCount n;
        for (int i = 0; i < kSamples; ++i) {
            const auto d = transmittance_delta(medium, control, c.ray, c.tmax, {}, rng, n);
            const auto r = transmittance_ratio(medium, control, c.ray, c.tmax, {}, rng, n);
            REQUIRE(d.status == Status::Ok);
            REQUIRE(r.status == Status::Ok);
            REQUIRE(all_finite(d.value));
            REQUIRE(all_finite(r.value));
            delta.add(d.value);
            ratio.add(r.value);
        }
        check_mean(delta, expected, name + ", " + c.what + ", delta tracking (decomposition under a control)");
        check_mean(ratio, expected, name + ", " + c.what + ", ratio tracking (residual under a control)");
        if (lookups) *lookups += n.count();
    }
}

TEST_CASE_TEMPLATE("decomposition and residual ratio tracking are unbiased on exponential media", S, Mono, Rgb) {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    using M = ExponentialMedium<S>;
    const auto medium = make_medium<M>(box, 1.2f, spec<S>(0.2f, 0.1f, 0.4f), spec<S>(0.6f, 0.3f, 1.2f));
    std::uint64_t with_control = 0, without = 0;
    check_closed_forms<S>(medium, GridControl<M>(medium, 8), "grid control (8^3)", 21, &with_control);
    check_closed_forms<S>(medium, GridMajorant<M>(medium, 8), "grid majorant (8^3), no control", 21, &without);
    check_closed_forms<S>(medium, GlobalControl<M>(medium, box_control(medium, 0.9f)), "global control below", 22);
    // The tree's cells (the adaptive layout: 16^3 coarse, split 4^3 twice where that pays), each with its minorant.
    check_closed_forms<S>(medium, TreeControl<M>(medium), "tree control (adaptive layout)", 24);
    // A control above the density over part of the box: negative residuals there, signed null
    // weights (delta) and null factors above 1 (ratio), still unbiased.
    const float above = 0.5f * (medium.density_lower_bound(box) + medium.density_bound(box));
    check_closed_forms<S>(medium, GlobalControl<M>(medium, scale(medium.extinction_per_density(), above)),
                          "global control above the density in places", 23);
    MESSAGE(std::string(S::name) << ": lookups, grid control " << with_control << ", grid majorant " << without);
    CHECK(with_control < without);
}

/// The nulls a SegmentRecord holds, with the independent log pdfs of THEORY 5.10 for a Mono
/// medium under a global control c and majorant mu_bar, over `len` inside the box: NEE's
/// (residual ratio tracking) prod (mu_bar - c) exp(-(mu_bar - c) len) and decomposition tracking's
/// passing prod (mu_bar - mu_t(n_j)) exp(-mu_bar len) (its residual null density (mu_bar - c) P_n,r
/// is mu_bar - mu_t, and it passes the control with exp(-c len)).
struct IndependentPdfs {
    double log_nee = 0.0, log_uni = 0.0;
};
template <class M>
IndependentPdfs independent_pdfs(const M& medium, const Ray& ray, const std::vector<float>& nulls, float mu_bar,
                                 float c, float len) {
    IndependentPdfs p;
    for (const float t : nulls) {
        const double mu_t = medium.coefficients(ray.at(t), {}).sigma_t()[0];
        p.log_nee += std::log(double(mu_bar) - double(c));
        p.log_uni += std::log(double(mu_bar) - mu_t);
    }
    p.log_nee -= (double(mu_bar) - double(c)) * len;
    p.log_uni -= double(mu_bar) * len;
    return p;
}

TEST_CASE("the MIS pair under a control: independent pdfs, the null product and weights that sum to 1") {
    const Box box{Vec3(-1.f), Vec3(1.f)};
    using M = ExponentialMedium<Mono>;
    const auto medium = make_medium<M>(box, 1.5f, grey<Mono>(0.3f), grey<Mono>(0.7f));
    const float c = 0.8f * medium.density_lower_bound(box) * medium.extinction_per_density()[0];
    REQUIRE(c > 0.1f);
    const GlobalControl<M> control(medium, grey<Mono>(c));
    const float mu_bar = medium.max_extinction();
    const Ray ray{Vec3(-3.f, 0.2f, -0.1f), glm::normalize(Vec3(1.f, -0.1f, 0.05f))};
    const Interval in = box.clip(ray, 0.f, kInf);
    const float len = in.t1 - in.t0;
    const VertexKernels<strategy::NullScatteringMis, mis::Balance> k;
    const VertexPdf from = VertexPdf::scattered(0.9f, 0.3f);
    Pcg32 rng(31, 2);
    LookupCount n;
    int checked_nee = 0, checked_uni = 0, with_nulls = 0;
    double worst_pdf = 0.0, worst_ratio = 0.0, worst_sum = 0.0;
    for (int i = 0; i < 4000; ++i) {
        SegmentRecord rec;
        const auto r = track_ratio<absorption::Weight, true>(medium, control, ray, kInf, {}, rng, n, rec);
        REQUIRE(r.end == SegmentEnd::Passed);
        const IndependentPdfs p = independent_pdfs(medium, ray, rec.t, mu_bar, c, len);
        worst_pdf = std::max(worst_pdf, std::abs(rec.log_pdf - p.log_nee));
        worst_ratio = std::max(worst_ratio, std::abs(std::log(double(r.null_pdf_product)) - (p.log_uni - p.log_nee)));
        // The grey residual ratio estimate is the null product itself (THEORY 5.10).
        REQUIRE(r.transmittance[0] == doctest::Approx(r.null_pdf_product).epsilon(1e-5));
        // The hit's weight with the independent product and the light's with the tracker's sum to 1.
        const float light_pdf = 0.7f;
        const float w = k.hit_weight(from, float(std::exp(p.log_uni - p.log_nee)), light_pdf) +
                        k.light_weight(from.survival, from.direction_pdf, r.null_pdf_product, light_pdf, false);
        worst_sum = std::max(worst_sum, std::abs(double(w) - 1.0));
        ++checked_nee;
        with_nulls += !rec.t.empty();
    }
    for (int i = 0; i < 16000; ++i) {
        SegmentRecord rec;
        const auto d = track_delta<absorption::Weight>(medium, control, ray, kInf, {}, rng, n, rec);
        if (d.end != SegmentEnd::Passed) continue;
        const IndependentPdfs p = independent_pdfs(medium, ray, rec.t, mu_bar, c, len);
        worst_pdf = std::max(worst_pdf, std::abs(rec.log_pdf - p.log_uni));
        worst_ratio = std::max(worst_ratio, std::abs(std::log(double(d.null_pdf_product)) - (p.log_uni - p.log_nee)));
        REQUIRE(d.weight[0] == doctest::Approx(1.0).epsilon(1e-5));  // grey, bounding: nulls weigh 1
        ++checked_uni;
    }
    MESSAGE("flights checked: " << checked_nee << " residual ratio (" << with_nulls << " with nulls), " << checked_uni
                                << " passing decomposition; largest log-pdf error " << worst_pdf
                                << ", null-product error " << worst_ratio << ", weight-sum error " << worst_sum);
    CHECK(with_nulls > 1000);
    CHECK(checked_uni > 500);
    // Float sums of a few optical depths of order 1: 1e-4 in the log is 10x their rounding.
    CHECK(worst_pdf < 1e-4);
    CHECK(worst_ratio < 1e-4);
    CHECK(worst_sum < 1e-5);
}

}  // namespace
