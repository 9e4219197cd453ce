// tests/test_pdf.cpp: the pdf a tracker reports for the vertices it drew equals an independent
// evaluation of the same vertices (pdf.hpp), and the null-probability products that
// null-scattering MIS uses equal the ratio of the two segment pdfs (THEORY 4, 5.1, 6).
#include <span>
#include <string>
#include <type_traits>

#include "majorants.hpp"

namespace {

using namespace nsp_test;

// Log pdfs are sums of O(10) float-rounded terms; 1e-4 relative (doctest Approx: |a - b| <
// 1e-4 (1 + max(|a|, |b|))) is far above rounding and far below any missing factor.
constexpr double kLogPdfEps = 1e-4;

TEST_CASE_TEMPLATE_DEFINE("tracking reports the log pdf of its vertices; null products match pdf.hpp", C,
                          pdf_consistency) {
    using S = typename C::Spectral;
    using M = typename C::Medium;
    using A = typename C::Absorption;
    const typename S::Wavelengths lambda{};
    const Box box{Vec3(-1.f, -0.5f, -1.f), Vec3(1.f, 1.5f, 0.5f)};
    const Box around{box.lo - Vec3(1.f), box.hi + Vec3(1.f)};  // ray origins inside and outside

    int delta_passed_with_nulls = 0, delta_real = 0, delta_absorbed = 0;
    int ratio_passed_with_nulls = 0, ratio_terminated = 0;
    Pcg32 rng(2024, 7);
    for (int seed = 0; seed < 4; ++seed) {
        const M medium = make_medium<M>(box, 0.5f + float(seed), spec<S>(0.3f, 0.1f, 0.6f),
                                        spec<S>(0.7f, 1.2f, 0.4f), std::uint64_t(seed + 1));
        // The majorant axis: the global majorant, tight and 2.5x loose, and every other grey
        // model and bound policy that applies to M (grid; Signed and Clamp below the extinction).
        auto run = [&](const auto& maj, const std::string& maj_name) {
            for (int i = 0; i < 250; ++i) {
                CAPTURE(seed);
                CAPTURE(maj_name);
                CAPTURE(i);
                const Ray ray{random_point(rng, around), random_direction(rng)};
                const float tmax = i % 3 == 0 ? kInf : 4.f * rng.uniform();

                // Delta tracking.
                SegmentRecord rec;
                LookupCount lookups;
                const auto d = track_delta<A>(medium, maj, ray, tmax, lambda, rng, lookups, rec);
                REQUIRE(d.end != SegmentEnd::Aborted);
                REQUIRE(lookups.count() == rec.t.size());  // one lookup per vertex created
                std::span<const float> nulls(rec.t);
                if (d.end != SegmentEnd::Passed) {
                    REQUIRE(!rec.t.empty());
                    REQUIRE(rec.t.back() == d.t);
                    nulls = nulls.first(nulls.size() - 1);
                    ++delta_real;
                    delta_absorbed += d.end == SegmentEnd::Absorbed;
                }
                const double lp = delta_segment_log_pdf<A>(medium, maj, ray, tmax, lambda, nulls, d.end, d.t);
                REQUIRE(rec.log_pdf == doctest::Approx(lp).epsilon(kLogPdfEps));
                if (d.end == SegmentEnd::Passed) {
                    // prod_j P_n(n_j) = p_delta(nulls, passed) / p_ratio(nulls) (THEORY 5.1).
                    const double lr = ratio_segment_log_pdf(medium, maj, ray, tmax, lambda, nulls);
                    REQUIRE(double(d.null_pdf_product) == doctest::Approx(std::exp(lp - lr)).epsilon(kLogPdfEps));
                    delta_passed_with_nulls += !nulls.empty();
                }

                // Ratio tracking with the null-probability product of delta tracking (policy A).
                SegmentRecord rrec;
                LookupCount rlookups;
                const auto r = track_ratio<A, true>(medium, maj, ray, tmax, lambda, rng, rlookups, rrec);
                REQUIRE(rlookups.count() == rrec.t.size());
                const std::span<const float> rnulls(rrec.t);
                if (r.end == SegmentEnd::Passed) {
                    const double lr = ratio_segment_log_pdf(medium, maj, ray, tmax, lambda, rnulls);
                    REQUIRE(rrec.log_pdf == doctest::Approx(lr).epsilon(kLogPdfEps));
                    const double ld = delta_segment_log_pdf<A>(medium, maj, ray, tmax, lambda, rnulls,
                                                               SegmentEnd::Passed, tmax);
                    REQUIRE(double(r.null_pdf_product) == doctest::Approx(std::exp(ld - lr)).epsilon(kLogPdfEps));
                    ratio_passed_with_nulls += !rnulls.empty();
                } else {
                    // Terminated at its last null: the pdf of those nulls, with no tail term.
                    REQUIRE(r.end == SegmentEnd::Terminated);
                    REQUIRE(!rrec.t.empty());
                    const double lr = ratio_segment_log_pdf(medium, maj, ray, rrec.t.back(), lambda, rnulls);
                    REQUIRE(rrec.log_pdf == doctest::Approx(lr).epsilon(kLogPdfEps));
                    ++ratio_terminated;
                }
            }
        };
        const GlobalMajorant<M> tight(medium);
        run(tight, "global");
        run(GlobalMajorant<M>(medium, tight.value() * 2.5f), "global-loose");
        for_each_kind<PdfGreyKinds, M>([&](auto kind) { run(decltype(kind)::make(medium), decltype(kind)::name); });
    }
    // The test must have exercised every branch it checks.
    CHECK(delta_passed_with_nulls > 20);
    CHECK(delta_real > 50);
    CHECK(ratio_passed_with_nulls > 50);
    // Ratio tracking terminates (every channel's weight exactly 0) only where mu_t = mu_bar
    // exactly in every channel, i.e. on grey homogeneous media with the tight majorant.
    if constexpr (std::is_same_v<M, HomogeneousMedium<Mono>>) CHECK(ratio_terminated > 0);
    if constexpr (A::as_event) CHECK(delta_absorbed > 10);
    else CHECK(delta_absorbed == 0);
}

TEST_CASE_TEMPLATE_APPLY(pdf_consistency, AllCombos);

}  // namespace
