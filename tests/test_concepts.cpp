// tests/test_concepts.cpp: every model satisfies its concept, at compile time (STYLE rule 1),
// policies are small trivially copyable values (rule 5), and counting nothing costs nothing.
#include <type_traits>

#include "common.hpp"

namespace {

using namespace nsp;

// Spectral modes and media.
static_assert(SpectralMode<Mono> && SpectralMode<Rgb>);
static_assert(!SpectralMode<int>);
static_assert(Medium<HomogeneousMedium<Mono>> && Medium<HomogeneousMedium<Rgb>>);
static_assert(Medium<DenseGridMedium<Mono>> && Medium<DenseGridMedium<Rgb>>);
static_assert(Medium<ExponentialMedium<Mono>> && Medium<ExponentialMedium<Rgb>>);
static_assert(!Medium<int> && !Medium<Box>);
static_assert(SpectralMode<Hero<4>> && SpectralMode<Hero<1>> && SpectralMode<Hero<8>>);
static_assert(Medium<HomogeneousMedium<Hero<4>>> && Medium<DenseGridMedium<Hero<4>>> &&
              Medium<ExponentialMedium<Hero<4>>>);
static_assert(is_hero_v<Hero<4>> && !is_hero_v<Rgb> && !is_hero_v<Mono>);
// Fixed-channel modes give coefficients as spectra: no conversion on a lookup.
static_assert(std::is_same_v<Mono::Coefficient, Mono::Spectrum> && std::is_same_v<Rgb::Coefficient, Rgb::Spectrum>);

// Majorants.
static_assert(MajorantIterator<SingleSegmentIterator<>> && MajorantIterator<SingleSegmentIterator<Rgb::Spectrum>>);
static_assert(MajorantPolicy<GlobalMajorant<HomogeneousMedium<Mono>>, HomogeneousMedium<Mono>>);
static_assert(MajorantPolicy<GlobalMajorant<HomogeneousMedium<Rgb>>, HomogeneousMedium<Rgb>>);
static_assert(MajorantPolicy<GlobalMajorant<DenseGridMedium<Mono>>, DenseGridMedium<Mono>>);
static_assert(MajorantPolicy<GlobalMajorant<DenseGridMedium<Rgb>>, DenseGridMedium<Rgb>>);
static_assert(MajorantPolicy<GlobalMajorant<ExponentialMedium<Mono>>, ExponentialMedium<Mono>>);
static_assert(MajorantPolicy<GlobalMajorant<ExponentialMedium<Rgb>>, ExponentialMedium<Rgb>>);
static_assert(std::is_same_v<bound_policy_t<GlobalMajorant<HomogeneousMedium<Mono>>>, bound::Guaranteed>);
static_assert(std::is_same_v<bound_policy_t<GlobalMajorant<HomogeneousMedium<Mono>, bound::Signed>>, bound::Signed>);
// Grid majorants: grid-like media only (a homogeneous medium has no DDA to walk), grey or per channel.
static_assert(RegionBoundedMedium<DenseGridMedium<Rgb>> && RegionBoundedMedium<ExponentialMedium<Hero<4>>>);
static_assert(!RegionBoundedMedium<HomogeneousMedium<Rgb>>);
static_assert(MajorantPolicy<GridMajorant<DenseGridMedium<Mono>>, DenseGridMedium<Mono>>);
static_assert(MajorantPolicy<GridMajorant<DenseGridMedium<Rgb>, bound::Clamp>, DenseGridMedium<Rgb>>);
static_assert(MajorantPolicy<ChannelGridMajorant<DenseGridMedium<Hero<4>>>, DenseGridMedium<Hero<4>>>);
static_assert(!is_per_channel_majorant_v<GridMajorant<DenseGridMedium<Rgb>>, DenseGridMedium<Rgb>>);
static_assert(is_per_channel_majorant_v<ChannelGridMajorant<DenseGridMedium<Rgb>>, DenseGridMedium<Rgb>>);
static_assert(MajorantPolicy<ChannelMajorant<DenseGridMedium<Rgb>>, DenseGridMedium<Rgb>>);
static_assert(MajorantPolicy<ChannelMajorant<DenseGridMedium<Hero<4>>>, DenseGridMedium<Hero<4>>>);
static_assert(MajorantPolicy<GlobalMajorant<DenseGridMedium<Hero<4>>>, DenseGridMedium<Hero<4>>>);
static_assert(is_per_channel_majorant_v<ChannelMajorant<DenseGridMedium<Rgb>>, DenseGridMedium<Rgb>>);
static_assert(!is_per_channel_majorant_v<GlobalMajorant<DenseGridMedium<Rgb>>, DenseGridMedium<Rgb>>);
static_assert(ChannelBoundedMedium<HomogeneousMedium<Rgb>> && ChannelBoundedMedium<ExponentialMedium<Hero<4>>>);

// Phase functions, RNG, counters, heuristics, policies.
static_assert(PhaseFunction<IsotropicPhase> && PhaseFunction<HenyeyGreensteinPhase>);
static_assert(!PhaseFunction<int>);
static_assert(UniformRng<Pcg32> && !UniformRng<int>);
static_assert(LookupCounter<NoLookupCount> && LookupCounter<LookupCount>);
static_assert(!LookupCounter<int>);
static_assert(mis::CombiningHeuristic<mis::Balance> && mis::CombiningHeuristic<mis::Power>);
static_assert(!mis::CombiningHeuristic<mis::None>);
static_assert(mis::Heuristic<mis::None> && mis::Heuristic<mis::Balance> && mis::Heuristic<mis::Power>);
static_assert(AbsorptionPolicy<absorption::Event> && AbsorptionPolicy<absorption::Weight>);
static_assert(PathStrategy<strategy::Unidirectional> && PathStrategy<strategy::NextEvent> &&
              PathStrategy<strategy::DirectionalMis> && PathStrategy<strategy::NullScatteringMis>);

// Channel policies.
static_assert(ChannelPolicy<channels::Independent> && ChannelPolicy<channels::SpectralMis> &&
              ChannelPolicy<channels::SpectralTrackingMax> && ChannelPolicy<channels::SpectralTrackingAverage>);
static_assert(!ChannelPolicy<int> && !ChannelPolicy<mis::Balance>);

// The tracking callbacks are collision callbacks.
static_assert(CollisionCallback<DeltaCollision<absorption::Event, Rgb, Pcg32, NoRecord>, Rgb>);
static_assert(CollisionCallback<RatioCollision<absorption::Weight, true, Mono, SegmentRecord>, Mono>);
static_assert(CollisionCallback<ChannelDeltaCollision<channels::SpectralMis, absorption::Weight, Rgb, Pcg32, NoRecord>,
                                Rgb, Rgb::Spectrum>);
static_assert(CollisionCallback<ChannelDeltaCollision<channels::SpectralTrackingMax, absorption::Event, Rgb, Pcg32, NoRecord>,
                                Rgb, float>);
static_assert(CollisionCallback<ChannelRatioCollision<channels::Independent, absorption::Weight, Hero<4>, NoRecord>,
                                Hero<4>, Hero<4>::Spectrum>);

// NoLookupCount is stateless: a kernel instantiated with it carries no counter at all.
static_assert(std::is_empty_v<NoLookupCount>);
static_assert(!NoLookupCount::enabled && LookupCount::enabled);
static_assert(std::is_empty_v<NoRecord> && !NoRecord::enabled);

// Policies are small, trivially copyable values (STYLE rule 5). (Media hold Eigen arrays,
// which are copyable but not trivially, so they are not listed.)
static_assert(std::is_trivially_copyable_v<GlobalMajorant<DenseGridMedium<Rgb>>>);
static_assert(std::is_trivially_copyable_v<TabulatedSpectrum> && std::is_trivially_copyable_v<Hero<4>::Wavelengths>);
static_assert(std::is_trivially_copyable_v<ChannelMajorant<DenseGridMedium<Hero<4>>>>);
static_assert(std::is_trivially_copyable_v<IsotropicPhase> &&
              std::is_trivially_copyable_v<HenyeyGreensteinPhase>);
static_assert(std::is_trivially_copyable_v<mis::Power> && std::is_empty_v<mis::Balance>);
static_assert(std::is_trivially_copyable_v<Pcg32>);
// A heuristic without state adds nothing to an estimator ([[no_unique_address]]).
static_assert(sizeof(PathEstimator<strategy::Unidirectional>) == sizeof(EstimatorOptions));

TEST_CASE("NoLookupCount records nothing, LookupCount counts each lookup") {
    NoLookupCount none;
    LookupCount some;
    for (int i = 0; i < 7; ++i) {
        none.lookup();
        some.lookup();
    }
    CHECK(none.count() == 0);
    CHECK(some.count() == 7);
}

TEST_CASE("Pcg32 gives floats in [0, 1), deterministic per seed, different per stream") {
    Pcg32 a(42, 1), b(42, 1), c(42, 2);
    bool differs = false;
    double sum = 0.0;
    constexpr int n = 100000;
    for (int i = 0; i < n; ++i) {
        const float x = a.uniform();
        REQUIRE(x >= 0.f);
        REQUIRE(x < 1.f);
        CHECK(x == b.uniform());
        differs |= x != c.uniform();
        sum += x;
    }
    CHECK(differs);
    // Mean of U[0,1) is 1/2 with SE sqrt(1/12/n) = 9.1e-4; tolerance 5 SE.
    CHECK(std::abs(sum / n - 0.5) < 5.0 * std::sqrt(1.0 / 12.0 / n));
}

#if !defined(NSP_DEBUG) && defined(NDEBUG)
// Release without NSP_DEBUG: debug checks compile to nothing (tests/debug/ covers them on).
static_assert(!nsp::kDebugChecks, "a release build must not run nsp's debug checks");

TEST_CASE("release: NSP_DEBUG_ASSERT compiles away and never evaluates its condition") {
    int evaluated = 0;
    NSP_DEBUG_ASSERT((++evaluated, false), "not evaluated in a release build");
    CHECK(evaluated == 0);
}
#endif

}  // namespace
