// tests/test_mis_weights.cpp: for one path, the MIS weights of unidirectional sampling and NEE
// sum to 1 and equal the heuristic applied to independently evaluated path pdfs; the null
// products the two samplers report equal the independent evaluation (THEORY 5.1, 5.2, 5.6).
#include <span>
#include <string>
#include <vector>

#include "majorants.hpp"

namespace {

using namespace nsp_test;

/// w = p_this^beta / (p_this^beta + p_other^beta) from log pdfs (beta = 1: balance).
double heuristic_from_logs(double beta, double log_this, double log_other) {
    return 1.0 / (1.0 + std::exp(beta * (log_other - log_this)));
}

/// Checks, for strategy St and heuristic h with exponent beta, that the two weights of one path
/// sum to 1 and match the heuristic on independent pdfs. `p_delta_nulls` is the product the
/// delta tracker reported, `p_ratio_nulls` the one ratio tracking reports for the same nulls;
/// `log_track` / `log_ratio` are pdf.hpp's log pdfs of the nulls under delta / ratio tracking.
template <class St, class H>
void check_weights(const H& h, double beta, float q, float p_w, float p_l, float p_delta_nulls,
                   float p_ratio_nulls, double log_track, double log_ratio) {
    const std::string strategy_name = St::name;
    CAPTURE(strategy_name);
    CAPTURE(beta);
    CAPTURE(q);
    const float w_uni = unidirectional_weight<St>(h, q, p_w, p_delta_nulls, p_l);
    const float w_nee = next_event_weight<St>(h, q, p_w, p_ratio_nulls, p_l);
    CHECK(double(w_uni) + double(w_nee) == doctest::Approx(1.0).epsilon(1e-5));
    // Absolute pdfs of the path's last segment (the shared prefix cancels). Unidirectional:
    // roulette survival q, phase pdf and (null-scattering MIS only) the delta-tracking pdf of the
    // nulls; NEE: light pdf and (null-scattering MIS only) the ratio-tracking pdf of the nulls.
    // Directional MIS compares direction pdfs only (THEORY 5.2).
    double log_uni = std::log(double(q) * p_w), log_nee = std::log(double(p_l));
    if constexpr (St::null_pdfs) {
        log_uni += log_track;
        log_nee += log_ratio;
    }
    CHECK(double(w_uni) == doctest::Approx(heuristic_from_logs(beta, log_uni, log_nee)).epsilon(1e-4));
}

TEST_CASE_TEMPLATE_DEFINE("MIS weights of unidirectional and NEE sum to 1 for one path", C, mis_weights) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    const typename S::Wavelengths lambda{};
    const Box box{Vec3(-1.f), Vec3(1.f)};
    Lights<S> lights;
    lights.set(SphereLight<S>{Vec3(2.5f, 0.5f, -0.2f), 0.6f, grey<S>(5.f)});
    const HenyeyGreensteinPhase phase(0.4f);
    int passed_with_nulls = 0;
    Pcg32 rng(8, 8);
    for (int seed = 0; seed < 3; ++seed) {
        const M medium = make_medium<M>(box, 0.8f + 0.7f * float(seed), spec<S>(0.3f, 0.1f, 0.6f),
                                        spec<S>(0.7f, 1.2f, 0.4f), std::uint64_t(seed + 10));
        // The majorant axis: the global majorant, tight and 2.x loose, and every other grey
        // model and bound policy that applies to M (grid; Signed and Clamp below the extinction).
        auto run = [&](const auto& maj, const std::string& maj_name) {
            for (int i = 0; i < 200; ++i) {
                CAPTURE(seed);
                CAPTURE(maj_name);
                CAPTURE(i);
                // A real vertex x reached along wo; NEE's light sample fixes the direction and the
                // light vertex; the unidirectional segment along it is drawn by delta tracking.
                const Vec3 x = random_point(rng, box), wo = random_direction(rng);
                const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
                const LightSample<S> ls = lights.sample(x, u0, u1, u2);
                REQUIRE(ls.pdf > 0.f);
                const Ray ray{x, ls.wi};
                // The light sample's direction hits the light where NEE says, with the pdf a
                // unidirectional hit would be weighted with.
                const LightHit hit = lights.intersect(ray);
                REQUIRE(hit.sphere);
                REQUIRE(hit.t == doctest::Approx(ls.distance).epsilon(1e-4));
                REQUIRE(lights.pdf(x, hit) == doctest::Approx(ls.pdf).epsilon(1e-4));

                SegmentRecord rec;
                NoLookupCount none;
                const auto d = track_delta<A>(medium, maj, ray, ls.distance, lambda, rng, none, rec);
                if (d.end != SegmentEnd::Passed) continue;  // only paths that reach the light
                const std::span<const float> nulls(rec.t);
                passed_with_nulls += !nulls.empty();

                // Independent evaluation of both pdfs of these nulls (pdf.hpp).
                const double log_track = delta_segment_log_pdf<A>(medium, maj, ray, ls.distance, lambda, nulls,
                                                                  SegmentEnd::Passed, ls.distance);
                const double log_ratio = ratio_segment_log_pdf(medium, maj, ray, ls.distance, lambda, nulls);
                const double p_nulls = std::exp(log_track - log_ratio);
                REQUIRE(double(d.null_pdf_product) == doctest::Approx(p_nulls).epsilon(1e-4));

                // What NEE's ratio tracker reports for the same nulls: replay them through its
                // collision callback with the coefficients and majorant depth there.
                NoRecord no_record;
                RatioCollision<A, true, S, NoRecord> nee{no_record};
                float prev = 0.f;
                for (const float t : nulls) {
                    const float tau = float(majorant_optical_depth<M>(maj, ray, prev, t, lambda));
                    REQUIRE(nee(t, tracked_coefficients(medium, maj, ray, t, lambda), majorant_at<M>(maj, ray, t, lambda), tau));
                    prev = t;
                }
                REQUIRE(double(nee.finish().null_pdf_product) == doctest::Approx(p_nulls).epsilon(1e-4));

                const float p_w = phase.pdf(wo, ls.wi);
                for (const float q : {1.f, 0.5f}) {
                    check_weights<strategy::DirectionalMis>(mis::Balance{}, 1.0, q, p_w, ls.pdf, d.null_pdf_product,
                                                            nee.finish().null_pdf_product, log_track, log_ratio);
                    check_weights<strategy::DirectionalMis>(mis::Power{2.f}, 2.0, q, p_w, ls.pdf,
                                                            d.null_pdf_product, nee.finish().null_pdf_product,
                                                            log_track, log_ratio);
                    check_weights<strategy::NullScatteringMis>(mis::Balance{}, 1.0, q, p_w, ls.pdf,
                                                               d.null_pdf_product, nee.finish().null_pdf_product,
                                                               log_track, log_ratio);
                    check_weights<strategy::NullScatteringMis>(mis::Power{2.f}, 2.0, q, p_w, ls.pdf,
                                                               d.null_pdf_product, nee.finish().null_pdf_product,
                                                               log_track, log_ratio);
                    check_weights<strategy::NullScatteringMis>(mis::Power{3.f}, 3.0, q, p_w, ls.pdf,
                                                               d.null_pdf_product, nee.finish().null_pdf_product,
                                                               log_track, log_ratio);
                }
            }
        };
        const GlobalMajorant<M> tight(medium);
        run(tight, "global");
        run(GlobalMajorant<M>(medium, tight.value() * 2.f), "global-loose");
        for_each_kind<PdfGreyKinds, M>([&](auto kind) { run(decltype(kind)::make(medium), decltype(kind)::name); });
    }
    CHECK(passed_with_nulls > 20);  // the non-trivial case (prod P_n != 1) was exercised
}

TEST_CASE_TEMPLATE_APPLY(mis_weights, AllCombos);

TEST_CASE_TEMPLATE_DEFINE("three-technique weights (tracking + NEE, tracking + hit, equiangular + NEE) sum to 1",
                          C, eq_weights) {
    // One path: a real vertex x at distance t on a segment with nulls before it, then a light
    // vertex. Tracking's side reports p_eq / p_track from the delta tracker's own products, the
    // equiangular side p_track / p_eq from ratio tracking's products for the same nulls; both must
    // equal the independent log pdfs of pdf.hpp, and the three weights, each computed from its
    // own side, must sum to 1 for every heuristic and roulette survival (THEORY 5.4, 5.6).
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    const typename S::Wavelengths lambda{};
    const Box box{Vec3(-1.f), Vec3(1.f)};
    int with_nulls = 0;
    Pcg32 rng(18, 8);
    const M medium = make_medium<M>(box, 1.1f, spec<S>(0.3f, 0.1f, 0.6f), spec<S>(0.7f, 1.2f, 0.4f), 21);
    auto run = [&](const auto& maj, const std::string& maj_name) {
        for (int i = 0; i < 300; ++i) {
            CAPTURE(maj_name);
            CAPTURE(i);
            const Vec3 o = random_point(rng, box), target = random_point(rng, box);
            const Ray ray{o, random_direction(rng)};
            const Interval in = box.clip(ray, 0.f, kInf);
            const EquiangularSampler eq(ray, target, in.t0, in.t1);
            SegmentRecord rec;
            NoLookupCount none;
            const auto d = track_delta<A>(medium, maj, ray, kInf, lambda, rng, none, rec);
            if (d.end != SegmentEnd::Scattered) continue;
            std::vector<float> nulls(rec.t.begin(), rec.t.end() - 1);  // the last vertex is x
            with_nulls += !nulls.empty();
            // Independent pdfs: tracking's nulls and real vertex; equiangular's density times the
            // ratio-tracking pdf of the same nulls up to t.
            const double log_track = delta_segment_log_pdf<A>(medium, maj, ray, kInf, lambda, nulls,
                                                              SegmentEnd::Scattered, d.t);
            const double log_eq = std::log(double(eq.pdf(d.t))) + ratio_segment_log_pdf(medium, maj, ray, d.t, lambda, nulls);
            const float eq_over_track = equiangular_over_tracking(eq.pdf(d.t), d.null_pdf_product, d.event_density);
            REQUIRE(double(eq_over_track) == doctest::Approx(std::exp(log_eq - log_track)).epsilon(2e-4));
            // The equiangular side: ratio tracking's callback over the same nulls.
            NoRecord no_record;
            RatioCollision<A, true, S, NoRecord> rt{no_record};
            float prev = 0.f;
            for (const float t : nulls) {
                const float tau = float(majorant_optical_depth<M>(maj, ray, prev, t, lambda));
                REQUIRE(rt(t, tracked_coefficients(medium, maj, ray, t, lambda), majorant_at<M>(maj, ray, t, lambda), tau));
                prev = t;
            }
            const float mu_x = majorant_value_at_point<M>(maj, ray, d.t, lambda);
            const float track_over_eq = tracking_over_equiangular<A>(
                eq.pdf(d.t), rt.finish().null_pdf_product, tracked_coefficients(medium, maj, ray, d.t, lambda), mu_x);
            REQUIRE(double(track_over_eq) == doctest::Approx(std::exp(log_track - log_eq)).epsilon(2e-4));
            // The light segment: hitting over NEE, s = q p_w prod P_n / p_l (any positive value
            // the two sides share; the uni/NEE suite above checks how it is formed).
            for (const float s : {0.f, 0.03f, 1.f, 40.f}) {
                auto sum = [&](const auto& h) {
                    // Tracking's side (reference p_track,NEE = 1) and equiangular's (p_eq,NEE = 1).
                    const double tn = equiangular_mis_weight(h, VertexTechnique::TrackNee, 1.f, s, eq_over_track);
                    const double th = equiangular_mis_weight(h, VertexTechnique::TrackHit, 1.f, s, eq_over_track);
                    const double en = equiangular_mis_weight(h, VertexTechnique::EquiangularNee, track_over_eq,
                                                             track_over_eq * s, 1.f);
                    return tn + th + en;
                };
                CAPTURE(s);
                CHECK(sum(mis::Balance{}) == doctest::Approx(1.0).epsilon(1e-3));
                CHECK(sum(mis::Power{2.f}) == doctest::Approx(1.0).epsilon(1e-3));
            }
        }
    };
    const GlobalMajorant<M> tight(medium);
    run(tight, "global");
    run(GlobalMajorant<M>(medium, tight.value() * 2.f), "global-loose");  // nulls in homogeneous media too
    for_each_kind<PdfGreyKinds, M>([&](auto kind) { run(decltype(kind)::make(medium), decltype(kind)::name); });
    CHECK(with_nulls > 20);
}

TEST_CASE_TEMPLATE_APPLY(eq_weights, AllCombos);

TEST_CASE("weight_among: weights of one path sum to 1, limits without NaN") {
    const mis::Balance b;
    const mis::Power p2(2.f);
    for (const float a : {0.f, 1e-30f, 0.2f, 1.f, 7.f, 1e30f, kInf})
        for (const float c : {0.f, 1e-20f, 0.5f, 3.f, 1e35f, kInf}) {
            CAPTURE(a);
            CAPTURE(c);
            for (const float one : {1.f}) {
                const double sb = double(mis::weight_among(b, one, a, c)) + mis::weight_among(b, a, one, c) +
                                  mis::weight_among(b, c, one, a);
                const double sp = double(mis::weight_among(p2, one, a, c)) + mis::weight_among(p2, a, one, c) +
                                  mis::weight_among(p2, c, one, a);
                CHECK(sb == doctest::Approx(1.0).epsilon(1e-6));
                CHECK(sp == doctest::Approx(1.0).epsilon(1e-6));
            }
        }
    CHECK(mis::weight_among(b, 1.f, 3.f) == doctest::Approx(b.weight(3.f)));
    CHECK(mis::weight_among(p2, 2.f, 3.f) == doctest::Approx(p2.weight(1.5f)));
    CHECK(mis::weight_among(b, 0.f, 0.f) == 0.f);
    CHECK(mis::weight_among(b, kInf, kInf, 1.f) == 0.5f);
}

TEST_CASE("heuristics: w(r) + w(1/r) = 1, w(0) = 1, w(inf) = 0") {
    const mis::Balance b;
    const mis::Power p2(2.f), p3(3.f);
    for (const float r : {1e-20f, 1e-3f, 0.3f, 1.f, 2.f, 1e3f, 1e20f}) {
        CAPTURE(r);
        CHECK(double(b.weight(r)) + double(b.weight(1.f / r)) == doctest::Approx(1.0).epsilon(1e-6));
        CHECK(double(p2.weight(r)) + double(p2.weight(1.f / r)) == doctest::Approx(1.0).epsilon(1e-6));
        CHECK(double(p3.weight(r)) + double(p3.weight(1.f / r)) == doctest::Approx(1.0).epsilon(1e-6));
        CHECK(b.weight(r) == doctest::Approx(1.0 / (1.0 + r)).epsilon(1e-6));
        CHECK(p2.weight(r) == doctest::Approx(1.0 / (1.0 + double(r) * r)).epsilon(1e-6));
    }
    CHECK(b.weight(0.f) == 1.f);
    CHECK(p2.weight(0.f) == 1.f);
    CHECK(b.weight(kInf) == 0.f);
    CHECK(p2.weight(kInf) == 0.f);
    CHECK(mis::Power(1.f).weight(0.25f) == doctest::Approx(b.weight(0.25f)));
}

}  // namespace
