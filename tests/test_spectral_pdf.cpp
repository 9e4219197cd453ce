// tests/test_spectral_pdf.cpp: the per-channel path-pdf state (THEORY 5.3, 5.1). For random
// segments with nulls, every channel's pdf, contribution and NEE-alternative pdf that the channel
// trackers report equal an independent evaluation (pdf.hpp, in double); the spectral-MIS weights
// over channels x {uni, NEE} sum to 1 and equal the balance heuristic on the independent pdfs;
// ratios stay finite when channels differ by 1e6 or one has majorant 0; a state whose f / p leaves
// float's range ends Overflowed and zeroed, and the estimator reports the sample NonFinite.
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "majorants.hpp"
#include "spectral.hpp"

namespace {

using namespace nsp_test;

const Box kBox{Vec3(-1.f), Vec3(1.f)};

/// log of what a state entry reports relative to the sampling channel's pdf, or -inf for 0.
double log_or_ninf(double x) { return x > 0.0 ? std::log(x) : -std::numeric_limits<double>::infinity(); }

/// Checks log(reported) == expected within `tol`, treating -inf (a pdf of 0) exactly. `base` is
/// the log of the stored value the ratios are taken against (<= 0: the state keeps its largest
/// entry at 1): an entry below 1e-30 of the largest is a denormal or 0 in float, accurate in
/// absolute terms only, and is checked to stay that small.
void check_log(double reported, double expected, double tol, double base) {
    if (std::isinf(expected) && expected < 0.0) {
        CHECK(reported == -std::numeric_limits<double>::infinity());
    } else if (expected + base < std::log(1e-30)) {
        CHECK(reported + base < std::log(1e-29));
    } else {
        CAPTURE(reported);
        CAPTURE(expected);
        CHECK(std::abs(reported - expected) <= tol);
    }
}

/// The contribution f_c of a segment's vertices in double: prod_j mu_n,c(n_j) Tbar_c, then
/// mu_s,c Tbar_c at a scattering end (THEORY 3, channel c's own majorant).
template <Medium M, class Maj>
double channel_contribution(const M& medium, const Maj& maj, const Ray& ray, float tmax,
                            const typename M::Spectral::Wavelengths& lambda, int c,
                            std::span<const float> nulls, SegmentEnd end, float t_end) {
    double f = 1.0;
    float prev = 0.f;
    for (const float t : nulls) {
        const auto k = tracked_coefficients(medium, maj, ray, t, lambda);
        f *= (double(majorant_at<M>(maj, ray, t, lambda, c)) - double(k.sigma_a[c]) - double(k.sigma_s[c])) *
             std::exp(-majorant_optical_depth<M>(maj, ray, prev, t, lambda, c));
        prev = t;
    }
    if (end == SegmentEnd::Passed) return f * std::exp(-majorant_optical_depth<M>(maj, ray, prev, tmax, lambda, c));
    const auto k = tracked_coefficients(medium, maj, ray, t_end, lambda);
    return f * double(k.sigma_s[c]) * std::exp(-majorant_optical_depth<M>(maj, ray, prev, t_end, lambda, c));
}

/// A chromatic grid medium of mode S with one channel of zero extinction (Rgb green; Hero: a
/// band around 550 nm) and channels 6x apart, so per-channel majorants differ.
template <SpectralMode S>
DenseGridMedium<S> chromatic_grid(std::uint64_t seed) {
    return make_medium<DenseGridMedium<S>>(kBox, 1.f, chroma<S>(0.3f, 0.f, 1.f), chroma<S>(0.7f, 0.f, 5.f), seed);
}

/// One point of the pdf suites' product: mode, own-pdf channel policy, absorption, majorant.
template <SpectralMode S, ChannelPolicy CP, AbsorptionPolicy A, class K>
struct PdfCase {
    using Spectral = S;
    using Channels = CP;
    using Absorption = A;
    using Medium = DenseGridMedium<S>;
    using Kind = K;  ///< the majorant kind (tests/support/majorants.hpp)
};

template <SpectralMode S, ChannelPolicy CP>
using PdfCasesOf = std::tuple<PdfCase<S, CP, absorption::Event, ChannelKind>, PdfCase<S, CP, absorption::Weight, ChannelKind>,
                              PdfCase<S, CP, absorption::Event, GlobalKind>, PdfCase<S, CP, absorption::Weight, GlobalKind>,
                              PdfCase<S, CP, absorption::Weight, ChannelGridKind>,
                              PdfCase<S, CP, absorption::Event, SignedChannelGridKind>>;

using PdfCases = decltype(std::tuple_cat(PdfCasesOf<Rgb, channels::SpectralMis>{}, PdfCasesOf<Hero<4>, channels::SpectralMis>{},
                                         PdfCasesOf<Rgb, channels::Independent>{}, PdfCasesOf<Hero<4>, channels::Independent>{},
                                         std::tuple<PdfCase<Rgb, channels::SpectralMis, absorption::Weight, ChannelTreeKind>,
                                                    PdfCase<Hero<4>, channels::Independent, absorption::Event, ChannelTreeKind>>{}));

// Tolerance on log pdfs: float accumulation of a few dozen factors (relative ~1e-6 each) and of
// optical depths up to ~10; 1e-3 is far below any error in a factor or a missing term.
constexpr double kLogTol = 1e-3;

TEST_CASE_TEMPLATE_DEFINE("channel delta tracking reports every channel's pdf, contribution and NEE pdf", T, channel_delta_pdfs) {
    using S = typename T::Spectral;
    using M = typename T::Medium;
    using A = typename T::Absorption;
    using CP = typename T::Channels;
    const std::string name = std::string(S::name) + "/" + CP::name + "/" + A::name +
                             "/" + T::Kind::name;
    CAPTURE(name);
    const M medium = chromatic_grid<S>(3);
    const auto maj = T::Kind::make(medium);
    Pcg32 rng(11, 4);
    NoLookupCount none;
    int with_nulls = 0, scattered = 0;
    for (int i = 0; i < 400; ++i) {
        CAPTURE(i);
        const auto lambda = draw_wavelengths<S>(rng);
        const Ray ray{random_point(rng, kBox), random_direction(rng)};
        const float tmax = 0.3f + 2.5f * rng.uniform();
        const int c = std::min(int(rng.uniform() * S::channels), S::channels - 1);
        if (!channel_has_majorant<M>(maj, ray, tmax, lambda, c)) continue;
        ChannelPathState<S> st;
        st.nee.setOnes();
        SegmentRecord rec;
        const ChannelTrack tr = track_channels_delta<CP, A>(medium, maj, ray, tmax, lambda, c, st, true, rng, none, rec);
        if (tr.end == SegmentEnd::Absorbed) continue;  // the state is not updated for a path that ends
        REQUIRE((tr.end == SegmentEnd::Passed || tr.end == SegmentEnd::Scattered));
        std::vector<float> nulls = rec.t;
        if (tr.end != SegmentEnd::Passed) nulls.pop_back();
        with_nulls += !nulls.empty();
        scattered += tr.end == SegmentEnd::Scattered;
        const double lp_c = channel_delta_segment_log_pdf<A>(medium, maj, ray, tmax, lambda, c, nulls, tr.end, tr.t);
        // What the sampler says it sampled with equals the independent evaluation.
        CHECK(rec.log_pdf == doctest::Approx(lp_c).epsilon(1e-4).scale(1.0));
        for (int k = 0; k < S::channels; ++k) {
            CAPTURE(k);
            CAPTURE(c);
            const double lp_k = channel_delta_segment_log_pdf<A>(medium, maj, ray, tmax, lambda, k, nulls, tr.end, tr.t);
            const double base = std::log(double(st.uni[c]));
            check_log(log_or_ninf(st.uni[k]) - base, lp_k - lp_c, kLogTol, base);
            const double f_k = channel_contribution(medium, maj, ray, tmax, lambda, k, nulls, tr.end, tr.t);
            CHECK(double(st.f[k]) / double(st.uni[c]) ==
                  doctest::Approx(f_k / std::exp(lp_c)).epsilon(kLogTol).scale(1e-12));
            if (tr.end == SegmentEnd::Passed) {
                const double lr_k = channel_ratio_segment_log_pdf<M>(maj, ray, tmax, lambda, k, nulls);
                check_log(log_or_ninf(st.nee[k]) - base, lr_k - lp_c, kLogTol, base);
            }
        }
    }
    // Nulls were exercised (fewer under a majorant at half the bound, where most collisions are
    // real), and real collisions.
    CHECK(with_nulls > (T::Kind::name == std::string("channel-grid-signed-0.5") ? 20 : 50));
    CHECK(scattered > 20);
}

TEST_CASE_TEMPLATE_APPLY(channel_delta_pdfs, PdfCases);

TEST_CASE_TEMPLATE_DEFINE("channel ratio tracking reports every channel's NEE pdf, uni alternative and contribution; "
                          "spectral-MIS weights over channels x {uni, NEE} sum to 1", T, channel_ratio_pdfs) {
    using S = typename T::Spectral;
    using M = typename T::Medium;
    using A = typename T::Absorption;
    using CP = typename T::Channels;
    const std::string name = std::string(S::name) + "/" + CP::name + "/" + A::name + "/" + T::Kind::name;
    CAPTURE(name);
    const M medium = chromatic_grid<S>(5);
    const auto maj = T::Kind::make(medium);
    Pcg32 rng(12, 4);
    NoLookupCount none;
    int with_nulls = 0;
    for (int i = 0; i < 400; ++i) {
        CAPTURE(i);
        const auto lambda = draw_wavelengths<S>(rng);
        const Ray ray{random_point(rng, kBox), random_direction(rng)};
        const float tmax = 0.3f + 2.5f * rng.uniform();
        const int c = std::min(int(rng.uniform() * S::channels), S::channels - 1);
        if (!channel_has_majorant<M>(maj, ray, tmax, lambda, c)) continue;
        SegmentRecord rec;
        const auto sh = track_channels_ratio<CP, A>(medium, maj, ray, tmax, lambda, c, S::Spectrum::Ones().eval(), true,
                                                    rng, none, rec);
        if (sh.end != SegmentEnd::Passed) continue;
        const std::span<const float> nulls(rec.t);
        with_nulls += !nulls.empty();
        const double lr_c = channel_ratio_segment_log_pdf<M>(maj, ray, tmax, lambda, c, nulls);
        CHECK(rec.log_pdf == doctest::Approx(lr_c).epsilon(1e-4).scale(1.0));
        std::vector<double> lr(S::channels), lu(S::channels);
        for (int k = 0; k < S::channels; ++k) {
            CAPTURE(k);
            CAPTURE(c);
            lr[k] = channel_ratio_segment_log_pdf<M>(maj, ray, tmax, lambda, k, nulls);
            lu[k] = channel_delta_segment_log_pdf<A>(medium, maj, ray, tmax, lambda, k, nulls, SegmentEnd::Passed, tmax);
            const double base = std::log(double(sh.nee[c]));
            check_log(log_or_ninf(sh.nee[k]) - base, lr[k] - lr_c, kLogTol, base);
            check_log(log_or_ninf(sh.uni[k]) - base, lu[k] - lr_c, kLogTol, base);
            const double f_k = channel_contribution(medium, maj, ray, tmax, lambda, k, nulls, SegmentEnd::Passed, tmax);
            CHECK(double(sh.f[k]) / double(sh.nee[c]) == doctest::Approx(f_k / std::exp(lr_c)).epsilon(kLogTol).scale(1e-12));
        }
        // Spectral MIS + NEE (THEORY 5.3 with 5.1): a path through these nulls to a light has 2 x C
        // techniques, (channel k, uni) with pdf q_k p_w lu_k and (channel k, NEE) with pdf q_k p_l lr_k
        // (the shared prefix cancels). The estimator weighs technique (k, t) by q_k p_t,k / sum; from
        // the reported ratios and from the independent logs, with non-uniform q.
        const float p_w = 0.3f + rng.uniform(), p_l = 0.3f + rng.uniform();
        typename S::Spectrum w = S::Spectrum::Zero();
        for (int k = 0; k < S::channels; ++k) w[k] = 1.f + float(k) + rng.uniform();
        const ChannelSelection<S> q(w);
        const auto& qs = q.probabilities();
        const typename S::Spectrum pdf = p_l * sh.nee + p_w * sh.uni;  // as the estimator sums them
        const float denom = (qs * pdf).sum();
        double log_denom = -std::numeric_limits<double>::infinity();
        auto log_add = [](double a, double b) {
            if (std::isinf(a) && a < 0.0) return b;
            if (std::isinf(b) && b < 0.0) return a;
            const double m = std::max(a, b);
            return m + std::log(std::exp(a - m) + std::exp(b - m));
        };
        for (int k = 0; k < S::channels; ++k) {
            log_denom = log_add(log_denom, std::log(double(qs[k]) * p_w) + lu[k]);
            log_denom = log_add(log_denom, std::log(double(qs[k]) * p_l) + lr[k]);
        }
        double sum = 0.0;
        for (int k = 0; k < S::channels; ++k) {
            CAPTURE(k);
            const double w_uni = double(qs[k]) * p_w * double(sh.uni[k]) / denom;
            const double w_nee = double(qs[k]) * p_l * double(sh.nee[k]) / denom;
            sum += w_uni + w_nee;
            CHECK(w_uni == doctest::Approx(std::exp(std::log(double(qs[k]) * p_w) + lu[k] - log_denom)).epsilon(kLogTol).scale(1e-9));
            CHECK(w_nee == doctest::Approx(std::exp(std::log(double(qs[k]) * p_l) + lr[k] - log_denom)).epsilon(kLogTol).scale(1e-9));
        }
        CHECK(sum == doctest::Approx(1.0).epsilon(1e-5));
    }
    CHECK(with_nulls > 50);
}

using RatioCases = std::tuple<PdfCase<Rgb, channels::SpectralMis, absorption::Weight, ChannelKind>,
                              PdfCase<Rgb, channels::SpectralMis, absorption::Event, ChannelKind>,
                              PdfCase<Hero<4>, channels::SpectralMis, absorption::Weight, ChannelKind>,
                              PdfCase<Rgb, channels::SpectralMis, absorption::Weight, GlobalKind>,
                              PdfCase<Hero<4>, channels::SpectralMis, absorption::Event, GlobalKind>,
                              PdfCase<Rgb, channels::SpectralMis, absorption::Weight, ChannelGridKind>,
                              PdfCase<Hero<4>, channels::SpectralMis, absorption::Event, SignedChannelGridKind>,
                              PdfCase<Rgb, channels::SpectralMis, absorption::Weight, SignedGridKind>,
                              PdfCase<Rgb, channels::SpectralMis, absorption::Event, ChannelTreeKind>>;
TEST_CASE_TEMPLATE_APPLY(channel_ratio_pdfs, RatioCases);

/// Spectral tracking's pdf in double from the vertices: one grey majorant mu, event probabilities
/// from the channel maxima (THEORY 5.3, Kutz et al. 2017), absorption as a weight.
double spectral_tracking_max_log_pdf(const DenseGridMedium<Rgb>& medium, const GlobalMajorant<DenseGridMedium<Rgb>>& maj,
                                     const Ray& ray, float tmax, std::span<const float> nulls, SegmentEnd end,
                                     float t_end) {
    using M = DenseGridMedium<Rgb>;
    const float mu = maj.value();
    double lp = 0.0;
    float prev = 0.f;
    auto vertex = [&](float t, bool null) {
        const auto k = medium.coefficients(ray.at(t), {});
        double tmax_c = 0.0, nmax_c = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double tc = double(k.sigma_a[c]) + double(k.sigma_s[c]);
            tmax_c = std::max(tmax_c, tc);
            nmax_c = std::max(nmax_c, double(mu) - tc);
        }
        lp += std::log(double(mu) * (null ? nmax_c : tmax_c) / (tmax_c + nmax_c)) -
              majorant_optical_depth<M>(maj, ray, prev, t, {});
        prev = t;
    };
    for (const float t : nulls) vertex(t, true);
    if (end == SegmentEnd::Passed) return lp - majorant_optical_depth<M>(maj, ray, prev, tmax, {});
    vertex(t_end, false);
    return lp;
}

TEST_CASE("spectral tracking (max): one pdf for every channel, as an independent evaluation gives") {
    const auto medium = chromatic_grid<Rgb>(9);
    const GlobalMajorant<DenseGridMedium<Rgb>> maj(medium);
    Pcg32 rng(13, 4);
    NoLookupCount none;
    int with_nulls = 0;
    for (int i = 0; i < 400; ++i) {
        CAPTURE(i);
        const Ray ray{random_point(rng, kBox), random_direction(rng)};
        const float tmax = 0.3f + 2.5f * rng.uniform();
        ChannelPathState<Rgb> st;
        SegmentRecord rec;
        const auto tr = track_channels_delta<channels::SpectralTrackingMax, absorption::Weight>(
            medium, maj, ray, tmax, {}, 0, st, false, rng, none, rec);
        std::vector<float> nulls = rec.t;
        if (tr.end != SegmentEnd::Passed) nulls.pop_back();
        with_nulls += !nulls.empty();
        const double lp = spectral_tracking_max_log_pdf(medium, maj, ray, tmax, nulls, tr.end, tr.t);
        CHECK(rec.log_pdf == doctest::Approx(lp).epsilon(1e-4).scale(1.0));
        for (int k = 0; k < 3; ++k) {
            CHECK(st.uni[k] == st.uni[0]);  // a shared pdf: the same for every channel
            // f_k relative to the pdf: Tbar cancels (one majorant), the coefficients remain.
            double f = 1.0;
            for (const float t : nulls) {
                const auto co = medium.coefficients(ray.at(t), {});
                f *= double(maj.value()) - double(co.sigma_t()[k]);
            }
            if (tr.end == SegmentEnd::Scattered) f *= double(medium.coefficients(ray.at(tr.t), {}).sigma_s[k]);
            const double mu_tau = majorant_optical_depth<DenseGridMedium<Rgb>>(maj, ray, 0.f, tr.t, {});
            CHECK(double(st.f[k]) / double(st.uni[k]) == doctest::Approx(f * std::exp(-mu_tau - lp)).epsilon(kLogTol).scale(1e-12));
        }
    }
    CHECK(with_nulls > 50);
}

TEST_CASE("per-channel pdf ratios stay finite when majorants differ by 1e6 or one is 0") {
    // Channels with extinction 4e-6, 4 and 0 per unit density: majorants 1e6 apart and one 0.
    const auto medium = make_medium<DenseGridMedium<Rgb>>(kBox, 1.f, spec<Rgb>(1e-6f, 1.f, 0.f),
                                                          spec<Rgb>(3e-6f, 3.f, 0.f), 21);
    const ChannelMajorant<DenseGridMedium<Rgb>> maj(medium);
    const Scene<DenseGridMedium<Rgb>, ChannelMajorant<DenseGridMedium<Rgb>>, HenyeyGreensteinPhase> scene(
        medium, maj, HenyeyGreensteinPhase(0.3f), [] {
            Lights<Rgb> l;
            l.set(EnvironmentLight<Rgb>{grey<Rgb>(1.f)});
            l.set(SphereLight<Rgb>{Vec3(0.f, 3.f, 0.f), 0.5f, grey<Rgb>(4.f)});
            return l;
        }());
    Pcg32 rng(14, 4);
    NoLookupCount none;
    for (int i = 0; i < 3000; ++i) {
        const Ray ray{random_point(rng, kBox), random_direction(rng)};
        for (int c = 0; c < 2; ++c) {  // channel 2 has majorant 0: it is never sampled with
            ChannelPathState<Rgb> st;
            const auto tr = track_channels_delta<channels::SpectralMis, absorption::Weight>(
                medium, maj, ray, 3.f, {}, c, st, true, rng, none);
            REQUIRE(tr.end != SegmentEnd::Aborted);
            REQUIRE(all_finite(st.f));
            REQUIRE(all_finite(st.uni));
            REQUIRE(all_finite(st.nee));
            if (tr.end != SegmentEnd::Absorbed) {
                REQUIRE(st.uni[c] > 0.f);
                REQUIRE(st.uni.maxCoeff() == doctest::Approx(1.f));  // renormalised
            }
            if (tr.end == SegmentEnd::Scattered) REQUIRE(st.uni[2] == 0.f);  // majorant 0: no collision pdf
            const auto sh = track_channels_ratio<channels::SpectralMis, absorption::Weight>(
                medium, maj, ray, 3.f, {}, c, Rgb::Spectrum::Ones().eval(), true, rng, none);
            REQUIRE(all_finite(sh.f));
            REQUIRE(all_finite(sh.nee));
            REQUIRE(all_finite(sh.uni));
        }
    }
    const SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance> est;
    for (int i = 0; i < 3000; ++i) {
        const Ray ray{Vec3(0.f, 0.f, -3.f), glm::normalize(random_point(rng, kBox) - Vec3(0.f, 0.f, -3.f))};
        const auto r = est.radiance(scene, ray, {}, rng, none);
        REQUIRE(r.status == Status::Ok);
        REQUIRE(all_finite(r.value));
    }
}

TEST_CASE_TEMPLATE("a path state whose f / p leaves float's range ends Overflowed, zeroed, and the estimator says NonFinite",
                   CP, channels::SpectralMis, channels::Independent) {
    // Fuzzer finding 10. Extinction 1e30 under bound::Signed with a majorant 1e-25 of it (1e5):
    // P_n = |mu_n| / (mu_t + |mu_n|) = 1/2 to 1e-25, and one null multiplies f / p by
    // (mu_bar - mu_t) / (mu_bar P_n) = -2e25, a real collision (absorption weighted: pdf
    // mu_bar mu_t / (mu_t + |mu_n|), contribution mu_s) by mu_s / mu_t x 2e25 = 1.6e25. So a flight
    // whose first event is real scatters (f / p = 1.6e25, finite) and one whose first event is a
    // null overflows at its next event: each with probability 1/2.
    using M = DenseGridMedium<Rgb>;
    const M medium(kBox, {2, 2, 2}, std::vector<float>(8, 1e30f), grey<Rgb>(0.2f), grey<Rgb>(0.8f));
    const ChannelMajorant<M, bound::Signed> maj(medium, 1e-25f);
    Pcg32 rng(10, 10);
    NoLookupCount none;
    constexpr int kFlights = 2000;
    int scattered = 0, overflowed = 0;
    for (int i = 0; i < kFlights; ++i) {
        const Ray ray{Vec3(0.f, 0.f, -1.f), Vec3(0.f, 0.f, 1.f)};
        const int c = i % 3;
        ChannelPathState<Rgb> st;
        st.nee = st.uni;
        const auto tr = track_channels_delta<CP, absorption::Weight>(medium, maj, ray, 2.f, {}, c, st, true, rng, none);
        REQUIRE((tr.end == SegmentEnd::Scattered || tr.end == SegmentEnd::Overflowed));
        REQUIRE(all_finite(st.f));
        REQUIRE(all_finite(st.uni));
        REQUIRE(all_finite(st.nee));
        if (tr.end == SegmentEnd::Overflowed) {
            ++overflowed;
            REQUIRE((st.f == 0.f).all());
            REQUIRE((st.uni == 0.f).all());
            REQUIRE((st.nee == 0.f).all());
        } else {
            ++scattered;
            REQUIRE(st.uni[c] > 0.f);
            REQUIRE(st.f[c] / st.uni[c] == doctest::Approx(1.6e25f).epsilon(1e-4));
        }
    }
    // Binomial(2000, 1/2): sd 22.4; 5 sd either side.
    CHECK(std::abs(overflowed - kFlights / 2) <= 112);
    CHECK(scattered + overflowed == kFlights);

    // Ratio tracking over the same medium: f / nee = (mu_bar - mu_t) / mu_bar = -1e25 per null and
    // 1e5 expected nulls over the length 1: past FLT_MAX at the second, so every shadow overflows
    // (no null at all has probability e^-1e5).
    for (int i = 0; i < 200; ++i) {
        const Ray ray{Vec3(0.f, 0.f, -1.f), Vec3(0.f, 0.f, 1.f)};
        const auto sh = track_channels_ratio<CP, absorption::Weight>(medium, maj, ray, 1.f, {}, i % 3,
                                                                     Rgb::Spectrum::Ones().eval(), true, rng, none);
        REQUIRE(sh.end == SegmentEnd::Overflowed);
        REQUIRE((sh.f == 0.f).all());
        REQUIRE((sh.nee == 0.f).all());
    }

    // The estimator discards such a sample and says so; every value it returns is finite.
    const Scene<M, ChannelMajorant<M, bound::Signed>, HenyeyGreensteinPhase> scene(
        medium, maj, HenyeyGreensteinPhase(0.f), [] {
            Lights<Rgb> l;
            l.set(EnvironmentLight<Rgb>{grey<Rgb>(1.f)});
            return l;
        }());
    // With NEE, a sample whose shadow flight overflows is discarded whole, though the path may
    // have collected something before: NonFinite means a value of 0.
    auto run = [&](const auto& est) {
        int non_finite = 0;
        for (int i = 0; i < 500; ++i) {
            const auto r = est.radiance(scene, Ray{Vec3(0.f, 0.f, -3.f), Vec3(0.f, 0.f, 1.f)}, {}, rng, none);
            REQUIRE(all_finite(r.value));
            REQUIRE((r.status == Status::Ok || r.status == Status::NonFinite));
            if (r.status == Status::NonFinite) {
                ++non_finite;
                REQUIRE((r.value == 0.f).all());
            }
        }
        // At least every path whose first flight overflows (half of them; 5 sd of Binomial(500,
        // 1/2) below 250 is 194); later flights overflow too, so this is a lower bound.
        CHECK(non_finite >= 194);
    };
    run(SpectralPathEstimator<CP, strategy::Unidirectional, mis::None>{});
    run(SpectralPathEstimator<CP, strategy::NullScatteringMis, mis::Balance>{});
}

/// log of channel c's residual-ratio-tracking pdf of nulls at `nulls` on [0, tmax] under a
/// per-channel control (ChannelGridControl): prod_j R_c(n_j) exp(-int R_c), R_c = mu_bar_c -
/// mu_c,c, from the control's segments in double.
template <class M, class Ctl>
double channel_residual_ratio_log_pdf(const Ctl& control, const Ray& ray, float tmax,
                                      const typename M::Spectral::Wavelengths& lambda, int c,
                                      std::span<const float> nulls) {
    double lp = 0.0;
    for (const float t : nulls)
        lp += std::log(double(control.value_at(ray.at(t), lambda)[c]) -
                       double(control.control_value_at(ray.at(t), lambda)[c]));
    auto segments = control.iterate(ray, 0.f, tmax, lambda);
    while (auto seg = segments.next())
        lp -= (double(seg->sigma_maj[c]) - double(seg->sigma_ctl[c])) * (double(seg->t1) - double(seg->t0));
    return lp;
}

/// The relative error in channel k's product of null factors mu_bar - mu_t at `nulls` that float's
/// rounding of mu_t (the trackers sum mu_a + mu_s in float, as the majorants bound them) may give:
/// 4 ulps of mu_t over each factor. A lookup within 1e-4 of its majorant makes the factor's
/// relative rounding 1e-3 or more (seen on one ray of these suites).
template <class M, class Maj>
double null_rounding(const M& medium, const Maj& maj, const Ray& ray, const typename M::Spectral::Wavelengths& lambda,
                     int k, std::span<const float> nulls) {
    double e = 0.0;
    for (const float t : nulls) {
        const double mu_t = double(medium.coefficients(ray.at(t), lambda).sigma_t()[k]);
        const double n = std::abs(double(majorant_at<M>(maj, ray, t, lambda, k)) - mu_t);
        if (n > 0.0) e += 4.0 * std::ldexp(mu_t, -23) / n;
    }
    return e;
}

// A per-channel majorant's control (ChannelGridControl, THEORY 5.10 with 5.3): under a minorant
// every channel's decomposition-tracking pdf of a segment is its delta-tracking pdf under its own
// majorant (pdf.hpp's evaluation, which sees the control as a majorant), and its residual ratio
// tracking pdf prod R_c exp(-int R_c). The trackers must report exactly these, and the
// contributions of the medium (unchanged by the control), for each sampling channel.
template <AbsorptionPolicy A, class Ctl>
void check_channel_control_pdfs(const DenseGridMedium<Rgb>& medium, const Ctl& ctl) {
    using S = Rgb;
    using M = DenseGridMedium<S>;
    using CP = channels::SpectralMis;
    Pcg32 rng(17, 4);
    NoLookupCount none;
    int with_nulls = 0, scattered = 0, ratio_nulls = 0;
    for (int i = 0; i < 600; ++i) {
        CAPTURE(i);
        const auto lambda = draw_wavelengths<S>(rng);
        const Ray ray{random_point(rng, kBox), random_direction(rng)};
        const float tmax = 0.3f + 2.5f * rng.uniform();
        const int c = std::min(int(rng.uniform() * S::channels), S::channels - 1);
        if (!channel_has_majorant<M>(ctl, ray, tmax, lambda, c)) continue;
        {  // decomposition tracking
            ChannelPathState<S> st;
            st.nee.setOnes();
            SegmentRecord rec;
            const ChannelTrack tr = track_channels_delta<CP, A>(medium, ctl, ray, tmax, lambda, c, st, true, rng, none, rec);
            if (tr.end != SegmentEnd::Absorbed) {
                REQUIRE((tr.end == SegmentEnd::Passed || tr.end == SegmentEnd::Scattered));
                std::vector<float> nulls = rec.t;
                if (tr.end != SegmentEnd::Passed) nulls.pop_back();
                with_nulls += !nulls.empty();
                scattered += tr.end == SegmentEnd::Scattered;
                const double lp_c = channel_delta_segment_log_pdf<A>(medium, ctl, ray, tmax, lambda, c, nulls, tr.end, tr.t);
                CHECK(rec.log_pdf == doctest::Approx(lp_c).epsilon(1e-4).scale(1.0));
                const double base = std::log(double(st.uni[c]));
                for (int k = 0; k < S::channels; ++k) {
                    CAPTURE(k);
                    CAPTURE(c);
                    const double tol = kLogTol + null_rounding(medium, ctl, ray, lambda, k, nulls);
                    const double lp_k = channel_delta_segment_log_pdf<A>(medium, ctl, ray, tmax, lambda, k, nulls, tr.end, tr.t);
                    check_log(log_or_ninf(st.uni[k]) - base, lp_k - lp_c, tol, base);
                    const double f_k = channel_contribution(medium, ctl, ray, tmax, lambda, k, nulls, tr.end, tr.t);
                    CHECK(double(st.f[k]) / double(st.uni[c]) ==
                          doctest::Approx(f_k / std::exp(lp_c)).epsilon(tol).scale(1e-12));
                    if (tr.end == SegmentEnd::Passed) {
                        const double lr_k = channel_residual_ratio_log_pdf<M>(ctl, ray, tmax, lambda, k, nulls);
                        check_log(log_or_ninf(st.nee[k]) - base, lr_k - lp_c, kLogTol, base);
                    }
                }
            }
        }
        {  // residual ratio tracking
            SegmentRecord rec;
            const auto sh = track_channels_ratio<CP, A>(medium, ctl, ray, tmax, lambda, c, S::Spectrum::Ones().eval(), true,
                                                        rng, none, rec);
            if (sh.end != SegmentEnd::Passed) continue;
            const std::span<const float> nulls(rec.t);
            ratio_nulls += !nulls.empty();
            const double lr_c = channel_residual_ratio_log_pdf<M>(ctl, ray, tmax, lambda, c, nulls);
            CHECK(rec.log_pdf == doctest::Approx(lr_c).epsilon(1e-4).scale(1.0));
            const double base = std::log(double(sh.nee[c]));
            for (int k = 0; k < S::channels; ++k) {
                CAPTURE(k);
                CAPTURE(c);
                const double lr_k = channel_residual_ratio_log_pdf<M>(ctl, ray, tmax, lambda, k, nulls);
                const double lu_k =
                    channel_delta_segment_log_pdf<A>(medium, ctl, ray, tmax, lambda, k, nulls, SegmentEnd::Passed, tmax);
                const double tol = kLogTol + null_rounding(medium, ctl, ray, lambda, k, nulls);
                check_log(log_or_ninf(sh.nee[k]) - base, lr_k - lr_c, kLogTol, base);
                check_log(log_or_ninf(sh.uni[k]) - base, lu_k - lr_c, tol, base);
                const double f_k = channel_contribution(medium, ctl, ray, tmax, lambda, k, nulls, SegmentEnd::Passed, tmax);
                CHECK(double(sh.f[k]) / double(sh.nee[c]) == doctest::Approx(f_k / std::exp(lr_c)).epsilon(tol).scale(1e-12));
            }
        }
    }
    MESSAGE("per-channel control: " << with_nulls << " decomposition segments with nulls, " << scattered
                                    << " scattered, " << ratio_nulls << " residual ratio segments with nulls");
    CHECK(with_nulls > 50);
    CHECK(scattered > 20);
    CHECK(ratio_nulls > 50);
}

TEST_CASE_TEMPLATE("per-channel control: channel trackers report every channel's decomposition and residual ratio pdfs",
                   A, absorption::Event, absorption::Weight) {
    // Under the per-channel grid control and the per-channel tree control (the test trees' layout).
    const auto medium = chromatic_grid<Rgb>(3);
    check_channel_control_pdfs<A>(medium, ChannelGridControl<DenseGridMedium<Rgb>>(medium, kTestGridRes));
    check_channel_control_pdfs<A>(
        medium, ChannelTreeControl<DenseGridMedium<Rgb>>(medium, TreeLayout{medium.bounds(), kTestTreeCoarse, {2, 0, 0}, 0.f, 0.f}));
}

TEST_CASE("per-channel control on a homogeneous chromatic medium: no lookups, exact transmittance") {
    // A grid of one constant density: every cell's lower bound is its upper bound, every channel's
    // residual 0, so residual ratio tracking looks nothing up and returns exp(-mu_t,c L) per
    // channel, and the sampling channel's decomposition tracking draws only control collisions
    // (real, one lookup each).
    using S = Rgb;
    using M = DenseGridMedium<S>;
    const M medium(kBox, {2, 2, 2}, std::vector<float>(8, 1.f), spec<S>(0.3f, 0.05f, 1.2f), spec<S>(0.5f, 0.1f, 2.f));
    const ChannelGridControl<M> ctl(medium, 4);
    const Ray ray{Vec3(-3.f, 0.1f, 0.2f), glm::normalize(Vec3(1.f, 0.1f, -0.05f))};
    const Interval in = kBox.clip(ray, 0.f, kInf);
    const typename S::Spectrum tau = (spec<S>(0.3f, 0.05f, 1.2f) + spec<S>(0.5f, 0.1f, 2.f)) * (in.t1 - in.t0);
    // The control is the density's lower bound less rounding (a few ulps below mu_t,c): the
    // residual, a few ulps of mu_t,c, is tracked at a rate too small to draw a collision here.
    const typename S::Spectrum lo = ctl.control_value_at(Vec3(0.f), {});
    CHECK(((lo / ((spec<S>(0.3f, 0.05f, 1.2f) + spec<S>(0.5f, 0.1f, 2.f))) - 1.f).abs() < 1e-5f).all());
    const typename S::Spectrum tau_c = lo * (in.t1 - in.t0);
    Pcg32 rng(5, 1);
    for (int c = 0; c < 3; ++c) {
        LookupCount n;
        const auto sh = track_channels_ratio<channels::SpectralMis, absorption::Weight>(
            medium, ctl, ray, kInf, {}, c, S::Spectrum::Ones().eval(), true, rng, n);
        REQUIRE(sh.end == SegmentEnd::Passed);
        CHECK(n.n == 0);
        for (int k = 0; k < 3; ++k) {
            CAPTURE(k);
            // No nulls: f_k / nee_k = exp(-tau_c,k) (channel k's residual ratio estimate), within
            // 1e-4 of exp(-mu_t,k L); uni_k / nee_k the same (decomposition's exp(-mu_bar,k L) over
            // residual ratio tracking's exp(-R_k L)).
            CHECK(double(sh.f[k]) / double(sh.nee[k]) == doctest::Approx(std::exp(-double(tau_c[k]))).epsilon(1e-5));
            CHECK(double(sh.uni[k]) / double(sh.nee[k]) == doctest::Approx(std::exp(-double(tau_c[k]))).epsilon(1e-5));
            CHECK(double(sh.f[k]) / double(sh.nee[k]) == doctest::Approx(std::exp(-double(tau[k]))).epsilon(1e-4));
        }
        int real = 0, lookups = 0, flights = 2000;
        for (int i = 0; i < flights; ++i) {
            LookupCount m;
            ChannelPathState<S> st;
            const ChannelTrack tr = track_channels_delta<channels::SpectralMis, absorption::Weight>(
                medium, ctl, ray, kInf, {}, c, st, true, rng, m);
            real += tr.end == SegmentEnd::Scattered;
            lookups += int(m.n);
            CHECK(int(m.n) == (tr.end == SegmentEnd::Scattered ? 1 : 0));
        }
        // The sampling channel scatters with probability 1 - exp(-tau_c): 2000 flights, 5 sd.
        const double p = 1.0 - std::exp(-double(tau[c]));
        CHECK(std::abs(real - flights * p) <= 5.0 * std::sqrt(flights * p * (1.0 - p)) + 1.0);
        CHECK(lookups == real);
    }
}

TEST_CASE("ChannelSelection: probabilities, sampling frequencies (chi-square) and rejected weights") {
    const ChannelSelection<Rgb> uniform;
    CHECK(uniform.probabilities().isApprox(Rgb::Spectrum::Constant(1.f / 3.f)));
    const ChannelSelection<Rgb> q(spec<Rgb>(1.f, 6.f, 3.f));
    CHECK(q.probabilities().isApprox(spec<Rgb>(0.1f, 0.6f, 0.3f)));
    // n = 1e5 draws, 3 bins, dof 2: critical value 13.816 at p = 1e-3.
    std::vector<double> counts(3, 0.0);
    Pcg32 rng(15, 4);
    constexpr int n = 100000;
    for (int i = 0; i < n; ++i) counts[std::size_t(q.sample(rng.uniform()))] += 1.0;
    CHECK(chi_square(counts, {0.1, 0.6, 0.3}, n) < 13.816);
    CHECK(q.sample(0.f) == 0);
    CHECK(q.sample(std::nextafter(1.f, 0.f)) == 2);
    CHECK_THROWS_WITH_AS(ChannelSelection<Rgb>(spec<Rgb>(1.f, 0.f, 1.f)),
                         "nsp: ChannelSelection weight[1] = 0 is not allowed: every channel needs a finite weight > 0",
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelSelection<Rgb>(spec<Rgb>(1.f, 1.f, -2.f)), doctest::Contains("weight[2] = -2"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelSelection<Rgb>(spec<Rgb>(NAN, 1.f, 1.f)), doctest::Contains("weight[0] = nan"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelSelection<Rgb>(spec<Rgb>(1.f, INFINITY, 1.f)), doctest::Contains("weight[1] = inf"), InvalidArgument);
}

}  // namespace
