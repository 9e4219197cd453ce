// tests/test_stability_flights.cpp: the stability suite (issue 8), second part:
// - the generic kernel cases of support/stability_cases.hpp for Hero<4> (every majorant kind x
//   bound policy; Mono and Rgb are in test_stability_tracking.cpp);
// - flights of hundreds of thousands of null collisions under a majorant 1e6 x the extinction,
//   which the README lists as a known limitation of float ratio tracking ("T = 0.99809 against
//   0.99800 exact"): these tests state the exact value and fail until the accumulation is fixed;
// - the collision limit: a flight past 2^24 tentative collisions is Aborted, contributes 0, and
//   a host's loop sees Status::Aborted; a scene refuses such a majorant up front;
// - ray origins 1e7 away from the medium, where float t has ulp 1.
#include <cmath>
#include <limits>

#include "stability_cases.hpp"

#define NSP_STAB_NAME(...)                                                                              \
    namespace doctest {                                                                                 \
    template <> inline String toString<__VA_ARGS__>() { return __VA_ARGS__::name().c_str(); }           \
    }
#define NSP_STAB_NAMES(K)                                                                       \
    NSP_STAB_NAME(nsp_test::stab::Track<nsp_test::stab::K, nsp::bound::Guaranteed, nsp::Hero<4>>) \
    NSP_STAB_NAME(nsp_test::stab::Track<nsp_test::stab::K, nsp::bound::Signed, nsp::Hero<4>>)     \
    NSP_STAB_NAME(nsp_test::stab::Track<nsp_test::stab::K, nsp::bound::Clamp, nsp::Hero<4>>)      \
    NSP_STAB_NAME(nsp_test::stab::Track<nsp_test::stab::K, nsp::bound::Reject, nsp::Hero<4>>)
NSP_STAB_NAMES(GlobalK)
NSP_STAB_NAMES(ChannelK)
NSP_STAB_NAMES(GridK)
NSP_STAB_NAMES(ChannelGridK)
#undef NSP_STAB_NAMES
#undef NSP_STAB_NAME
TYPE_TO_STRING_AS("hero", nsp::Hero<4>);

namespace {

using namespace nsp_test;
using namespace nsp_test::stab;

TEST_CASE_TEMPLATE_DEFINE("stability: densities 0, 1e-12, 1, 1e6 x majorants 0, equal, 1e3 above, below", Tr,
                          stab_density_hero) {
    density_and_majorant_sweep<Tr>();
}
TEST_CASE_TEMPLATE_DEFINE("stability: rays of length 0, 1e-7, 1e7; origins on faces; axis and denormal directions",
                          Tr, stab_rays_hero) {
    rays_and_origins<Tr>();
}
TEST_CASE_TEMPLATE_DEFINE("stability: densities 0, 1e-12, 1e3, 1e6 mixed in one grid", Tr, stab_mixed_hero) {
    mixed_grid<Tr>();
}
TEST_CASE_TEMPLATE_DEFINE("stability: channels whose coefficients differ by 1e8", Tr, stab_spread_hero) {
    channel_spread<Tr>();
}
TEST_CASE_TEMPLATE_APPLY(stab_density_hero, TracksHero);
TEST_CASE_TEMPLATE_APPLY(stab_rays_hero, TracksHero);
TEST_CASE_TEMPLATE_APPLY(stab_mixed_hero, TracksHero);
TEST_CASE_TEMPLATE_APPLY(stab_spread_hero, TracksHero);

// ---------------------------------------------------------------------------------------------
// Hundreds of thousands of null collisions (known limitation of float ratio tracking)

/// A homogeneous medium over [-1, 1]^3 with extinction mu_t per channel (albedo 0.8) and a ray
/// along +x through it (2.0 inside).
template <SpectralMode S>
HomogeneousMedium<S> slab(const typename S::Coefficient& mu_t) {
    return {Box{Vec3(-1.f), Vec3(1.f)}, scale(mu_t, 0.2f), scale(mu_t, 0.8f)};
}
const Ray kAlongX{Vec3(-2.f, 0.1f, -0.2f), Vec3(1.f, 0.f, 0.f)};

// KNOWN LIMITATION (README, "float ratio tracking"), being fixed in tracking.hpp and
// channel_tracking.hpp: this test shows it and must not be loosened.
//
// mu_t = 0.15 (tau = 0.3, T = exp(-0.3) = 0.740818) under a majorant 1e6 x mu_t: ~3e5 null
// collisions per flight, each null factor 1 - 1e-6.
// Float precision needed: a float factor 1 - 1e-6 is rounded by up to 2^-25 = 3e-8, 3% of its
// distance to 1, and the same way at every null of a homogeneous stretch, so float products are
// off by a few % of tau; the product must be formed and accumulated with the factor's deficit
// mu_t / mu_bar kept to ~1e-4 relative (e.g. in double, where the factor is exact to 1e-10 of it).
// Measured with the float products of f788fdb (this test's first commit): 0.73745 with the grey
// majorant (59 SE off at 32 flights) and 0.73115 with per-channel majorants (135 SE off).
// Delta tracking here is checked for finite weights only: its real-collision probability is
// ~1e-6, and u < p with Pcg32's 24-bit uniforms holds with probability ceil(p 2^24) / 2^24, up to
// 6% (on average ~3%) above p at p = 1e-6: the same few % of tau, from the random numbers, not
// the products. Seeing it would take ~1e5 flights of 3e5 collisions.
// Tolerance: kSigmas standard errors of 24 flights (SE ~8e-5: T-hat = prod (1 - eps), whose
// spread comes from the Poisson count of nulls, sd = T sqrt(N) eps ~ 4e-4) plus kRoundingFloor.
TEST_CASE_TEMPLATE("known limitation: ratio tracking through 3e5 nulls under a majorant 1e6 x the extinction is "
                   "unbiased",
                   S, Mono, Rgb, Hero<4>) {
    using H = HomogeneousMedium<S>;
    const H medium = slab<S>(constant_coefficient<S>(0.15f));
    const double exact = std::exp(-0.3);
    const int n = 24;
    auto check_mean = [&](const SpecStat<S>& st, const std::string& what) {
        for (int c = 0; c < S::channels; ++c) {
            const Stat& s = st.ch[std::size_t(c)];
            CAPTURE(what);
            CAPTURE(c);
            CAPTURE(s.mean);
            CAPTURE(exact);
            CAPTURE(s.se());
            CHECK(std::abs(s.mean - exact) <= kSigmas * s.se() + kRoundingFloor);
        }
    };
    {  // grey global majorant: track_ratio, and track_delta's nulls (finite, P_n product in (0, 1])
        const GlobalMajorant<H> maj(medium, 1e6f * medium.max_extinction());
        Pcg32 rng(2024, 1);
        LookupCount lookups;
        SpecStat<S> ratio;
        int bad = 0;
        for (int i = 0; i < n; ++i) {
            const auto l = draw_wavelengths<S>(rng);
            const auto r = track_ratio<absorption::Weight, true>(medium, maj, kAlongX, kInf, l, rng, lookups);
            bad += r.end != SegmentEnd::Passed || !all_finite(r.transmittance) || !(r.null_pdf_product > 0.f) ||
                   !(r.null_pdf_product <= 1.f);
            ratio.add(r.transmittance);
        }
        CHECK(bad == 0);
        CHECK(lookups.count() > std::uint64_t(n) * 250000);  // hundreds of thousands of nulls per flight
        check_mean(ratio, "ratio tracking, global majorant");
        int delta_bad = 0;
        for (int i = 0; i < 8; ++i) {
            const auto l = draw_wavelengths<S>(rng);
            const auto d = track_delta<absorption::Weight>(medium, maj, kAlongX, kInf, l, rng, lookups);
            delta_bad += !all_finite(d.weight) || !(d.null_pdf_product > 0.f) || d.end == SegmentEnd::Aborted;
        }
        CHECK(delta_bad == 0);
    }
    {  // per-channel majorant 1e6 x each channel's bound: track_channels_ratio, spectral MIS
        const ChannelMajorant<H> maj(medium, 1e6f);
        Pcg32 rng(2025, 1);
        NoLookupCount none;
        const ChannelSelection<S> q;
        SpecStat<S> st;
        int bad = 0;
        for (int i = 0; i < n; ++i) {
            const auto l = draw_wavelengths<S>(rng);
            const int c = q.sample(rng.uniform());
            const auto sh = track_channels_ratio<channels::SpectralMis, absorption::Weight>(
                medium, maj, kAlongX, kInf, l, c, S::Spectrum::Ones().eval(), true, rng, none);
            const auto t = channel_estimate<channels::SpectralMis>(sh.f, sh.nee, q.probabilities(), c);
            bad += sh.end != SegmentEnd::Passed || !all_finite(t);
            st.add(t);
        }
        CHECK(bad == 0);
        check_mean(st, "per-channel ratio tracking, per-channel majorant");
    }
}

// KNOWN LIMITATION (README, "float ratio tracking"), the same at its worst: channels 1e-4, 1 and
// 1e4 under one grey majorant (1e4). Red's null factor is 1 - 1e-8: in float it rounds to exactly
// 1, so red's T comes out 1 for exp(-2e-4) = 0.9998 (200 x kRoundingFloor off, with SE ~1e-6).
// Float precision needed: the factor's deficit 1e-8 must survive (double: exact to 1e-8 of it).
TEST_CASE_TEMPLATE("known limitation: ratio tracking resolves a channel 1e8 below the grey majorant", S, Rgb,
                   Hero<4>) {
    using H = HomogeneousMedium<S>;
    const H medium = slab<S>(chroma<S>(1e-4f, 1.f, 1e4f));
    const GlobalMajorant<H> maj(medium);
    Pcg32 rng(77, 1);
    NoLookupCount none;
    SpecStat<S> err;
    int bad = 0;
    for (int i = 0; i < 40; ++i) {
        const auto l = draw_wavelengths<S>(rng);
        const auto r = track_ratio<absorption::Weight, false>(medium, maj, kAlongX, kInf, l, rng, none);
        bad += !all_finite(r.transmittance) || r.end == SegmentEnd::Aborted;
        const auto mu_t = medium.extinction_bound(l);
        typename S::Spectrum e;
        for (int c = 0; c < S::channels; ++c) e[c] = float(double(r.transmittance[c]) - std::exp(-2.0 * double(mu_t[c])));
        err.add(e);
    }
    CHECK(bad == 0);
    for (int c = 0; c < S::channels; ++c) {
        const Stat& s = err.ch[std::size_t(c)];
        CAPTURE(c);
        CAPTURE(s.mean);
        CAPTURE(s.se());
        CHECK(std::abs(s.mean) <= kSigmas * s.se() + kRoundingFloor);
    }
}

// ---------------------------------------------------------------------------------------------
// The collision limit

// An empty medium (density 0) under a majorant of 1e7: 2e7 tentative collisions expected over
// the 2.0 inside, more than kDefaultMaxCollisions = 2^24 = 1.68e7 with probability 1 - 1e-300
// (Poisson sd 4.5e3). The docs promise: the flight is `aborted`, ratio and delta tracking end
// SegmentEnd::Aborted with weight 0 (a host's loop: Status::Aborted), and a Scene refuses the
// majorant before any render starts.
// float: t advances by ~1e-7 per step over [1, 3], where float resolves 1.2e-7 to 2.4e-7, so
// steps round but every one moves t forward by at least one ulp or stays (a stuck step still
// counts against the limit, so the limit is reached either way).
TEST_CASE("a flight past 2^24 tentative collisions is Aborted, contributes 0, and a scene refuses its majorant") {
    using H = HomogeneousMedium<Mono>;
    const H empty(Box{Vec3(-1.f), Vec3(1.f)}, grey<Mono>(0.f), grey<Mono>(0.f));
    const GlobalMajorant<H> maj(empty, 1e7f);
    Pcg32 rng(5, 5);
    LookupCount lookups;
    // An explicit small limit: the same flag, cheaply.
    const auto f = free_flight(empty, maj, kAlongX, 0.f, kInf, {}, rng, lookups,
                               [](float, const Coefficients<Mono>&, float, float) { return true; }, 1000u);
    CHECK(f.aborted);
    CHECK(!f.stopped);
    CHECK(!f.rejected);
    CHECK(f.t < 3.f);
    CHECK(lookups.count() == 1000);
    // The default limit.
    const auto r = track_ratio<absorption::Weight, true>(empty, maj, kAlongX, kInf, {}, rng, lookups);
    CHECK(r.end == SegmentEnd::Aborted);
    CHECK(r.transmittance[0] == 0.f);
    CHECK(lookups.count() >= 1000 + std::uint64_t(kDefaultMaxCollisions));

    // A host's own loop sees it as the status of the segment (VertexKernels::track, delta tracking).
    const VertexKernels<strategy::NullScatteringMis, mis::Balance> k;
    const auto seg = k.track(empty, maj, kAlongX, kInf, {}, rng, lookups);
    CHECK(seg.end == SegmentEnd::Aborted);
    CHECK(flight_status(seg.end) == Status::Aborted);
    CHECK(seg.weight[0] == 0.f);
    // A scene refuses this majorant up front (majorants/crossing.hpp: 2e7 null collisions along
    // +x, 3.5e7 along a diagonal, above kMaxFlightCollisions), so its render cannot run away; the
    // per-channel majorant of the same empty medium is 0 in every channel and is accepted.
    Lights<Mono> lights;
    lights.set(EnvironmentLight<Mono>{grey<Mono>(1.f)});
    CHECK_THROWS_AS((Scene<H, GlobalMajorant<H>, IsotropicPhase>(empty, maj, {}, lights)), InvalidArgument);

    using HR = HomogeneousMedium<Rgb>;
    const HR empty_rgb(Box{Vec3(-1.f), Vec3(1.f)}, grey<Rgb>(0.f), grey<Rgb>(0.f));
    Lights<Rgb> lights_rgb;
    lights_rgb.set(EnvironmentLight<Rgb>{grey<Rgb>(1.f)});
    const Scene<HR, ChannelMajorant<HR>, IsotropicPhase> scene_rgb(empty_rgb, ChannelMajorant<HR>(empty_rgb), {},
                                                                   lights_rgb);
    NoLookupCount none;
    // ChannelMajorant of an empty medium is 0 in every channel: nothing to abort, exactly the environment.
    const auto lr = SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>().radiance(
        scene_rgb, kAlongX, {}, rng, none);
    CHECK(lr.status == Status::Ok);
    CHECK((lr.value == 1.f).all());
    CHECK_THROWS_AS((Scene<HR, GlobalMajorant<HR>, IsotropicPhase>(empty_rgb, GlobalMajorant<HR>(empty_rgb, 1e7f), {},
                                                                   lights_rgb)),
                    InvalidArgument);
}

// ---------------------------------------------------------------------------------------------
// Origins 1e7 away from the medium

// float: at t ~ 1e7 float has ulp 1, and positions o + t d carry the same absolute error. A
// flight places collisions to within 0.5 of where they should be, which leaves a homogeneous
// medium's closed form intact as long as the majorant's mean free path is much longer than 1
// (here 25..50: each step's rounding is then at most 2% of it, unbiased to first order, and the
// optical depth is consumed exactly). Checked to kSigmas SE + kRoundingFloor.
//
// Where the mean free path is below ulp / 2 (0.5 here), t + dt rounds back to t and the
// flight cannot advance until a step of at least 0.5 is drawn: collisions pile up in place, so
// the number of nulls is no longer Poisson and ratio tracking is biased. Nothing in a
// free-flight kernel can fix that: the ray's own origin only resolves positions to 1 there. The
// requirement is on the host: start rays within D of the medium such that D * 6e-8 is much
// below the majorant's mean free path. That case is checked for finite estimates and valid
// statuses only.
TEST_CASE_TEMPLATE("stability: origins 1e7 away from the medium", S, Mono, Rgb) {
    using M = DenseGridMedium<S>;
    const Ray far{Vec3(-1e7f, 3.25f, -7.125f), Vec3(1.f, 0.f, 0.f)};
    // Box of size 200, density 0.01: tau = 1..2 per channel, majorant 2 x: mean free path 25..50.
    const M medium = uniform_grid<S>(Box{Vec3(-100.f), Vec3(100.f)}, 0.01f, base_sa<S>(), base_ss<S>());
    using G = Track<GlobalK, bound::Guaranteed, S>;
    using Gr = Track<GridK, bound::Guaranteed, S>;
    const Query q{"from -1e7 along +x", far, kInf};
    check_uniform<G>(medium, GlobalK::make<bound::Guaranteed>(medium, 2.f), q, 2000, 41, false, kRoundingFloor);
    check_uniform<Gr>(medium, GridK::make<bound::Guaranteed>(medium, 2.f), q, 2000, 42, false, kRoundingFloor);

    // Mean free path 0.5..1 against ulp 1: finite estimates and valid statuses only (see above).
    const M small = uniform_grid<S>(Box{Vec3(-1.f), Vec3(1.f)}, 1.f, base_sa<S>(), base_ss<S>());
    const auto maj = GlobalK::make<bound::Guaranteed>(small, 2.f);
    Pcg32 rng(43, 1);
    LookupCount lookups;
    int bad = 0;
    for (int i = 0; i < 500; ++i)
        for (const Est e : estimators_of<G>()) {
            const auto r = estimate<G>(e, small, maj, far, kInf, {}, rng, lookups);
            bad += !all_finite(r.value) || !status_allowed(e, r.end, false);
        }
    CHECK(bad == 0);
}

}  // namespace
