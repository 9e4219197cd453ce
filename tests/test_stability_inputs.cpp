// tests/test_stability_inputs.cpp: the stability suite, third part: what the kernels do with input
// they cannot use, and with a scene that would run away.
// - Every public kernel entry (free_flight, the grey and per-channel trackers, the transmittance
//   estimates, VertexKernels, the independent pdf evaluation, both path estimators over a Scene
//   and over a SurfaceScene) given a ray whose direction is not unit length (0.5, 2, |d|^2 =
//   1.0201, zero), has a NaN or infinite direction or origin, or a NaN distance, answers
//   InvalidInput (or pdf 0) with no estimate and no lookup, never a number computed from it
//   (core/math.hpp, usable_ray). A direction within kUnitTolerance is accepted.
// - A scene whose majorant would make a flight through a medium take more than
//   kMaxFlightCollisions tentative collisions is refused at construction with a message naming
//   the count and the limit (majorants/crossing.hpp); a dense medium under a twice-loose majorant
//   (a flight ends within a few hundred collisions, however thick it is) is not; flight_collisions
//   is the closed form on homogeneous media.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "grey_surface_scenes.hpp"
#include "stability.hpp"

namespace {

using namespace nsp_test;
using namespace nsp_test::stab;

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

struct BadInput {
    std::string what;
    Ray ray;
    float tmax;
};

/// The unusable inputs, from a good ray along +z into [-1, 1]^3 (the last keeps the ray and has a
/// NaN distance).
std::vector<BadInput> bad_inputs() {
    const Ray good{Vec3(0.1f, 0.2f, -3.f), Vec3(0.f, 0.f, 1.f)};
    auto with_d = [&](const char* w, Vec3 d) { return BadInput{w, Ray{good.o, d}, 10.f}; };
    auto with_o = [&](const char* w, Vec3 o) { return BadInput{w, Ray{o, good.d}, 10.f}; };
    return {with_d("|d| = 0.5", Vec3(0.f, 0.f, 0.5f)),
            with_d("|d| = 2", Vec3(0.f, 0.f, 2.f)),
            with_d("|d|^2 = 1.0201", Vec3(0.f, 0.f, 1.01f)),
            with_d("zero direction", Vec3(0.f)),
            with_d("NaN direction", Vec3(0.f, kNan, 1.f)),
            with_d("infinite direction", Vec3(kInf, 0.f, 0.f)),
            with_o("NaN origin", Vec3(kNan, 0.f, -3.f)),
            with_o("infinite origin", Vec3(0.f, -kInf, -3.f)),
            BadInput{"NaN distance", good, kNan}};
}

/// Every tracking entry on medium m under majorant maj (grey or per channel) with one input.
template <SpectralMode S, class M, class Maj>
void check_tracking_entries(const M& m, const Maj& maj, const BadInput& in) {
    using Spec = typename S::Spectrum;
    const Ray& r = in.ray;
    Pcg32 rng(11, 1);
    LookupCount lookups;
    int visited = 0;
    auto never = [&](float, const auto&, const auto&, const auto&) { return ++visited, true; };
    const auto f = free_flight(m, maj, r, 0.f, in.tmax, {}, rng, lookups, never);
    CHECK(f.invalid);
    CHECK(f.aborted);
    CHECK(!f.stopped);
    if constexpr (!is_per_channel_majorant_v<Maj, M>) {
        const auto d = track_delta<absorption::Weight>(m, maj, r, in.tmax, {}, rng, lookups);
        CHECK(d.end == SegmentEnd::InvalidInput);
        CHECK((d.weight == 0.f).all());
        const auto t = track_ratio<absorption::Event, true>(m, maj, r, in.tmax, {}, rng, lookups);
        CHECK(t.end == SegmentEnd::InvalidInput);
        CHECK((t.transmittance == 0.f).all());
        for (const auto& sample : {transmittance_ratio(m, maj, r, in.tmax, {}, rng, lookups),
                                   transmittance_delta(m, maj, r, in.tmax, {}, rng, lookups)}) {
            CHECK(sample.status == Status::InvalidInput);
            CHECK((sample.value == 0.f).all());
        }
        const VertexKernels<strategy::NullScatteringMis, mis::Balance> k;
        CHECK(k.track(m, maj, r, in.tmax, {}, rng, lookups).end == SegmentEnd::InvalidInput);
        CHECK(k.shadow(m, maj, r, in.tmax, {}, rng, lookups).status == Status::InvalidInput);
        const std::vector<float> nulls{0.5f};
        CHECK(delta_segment_log_pdf<absorption::Weight>(m, maj, r, in.tmax, {}, nulls, SegmentEnd::Passed, 0.f) ==
              -std::numeric_limits<double>::infinity());
        CHECK(ratio_segment_log_pdf(m, maj, r, in.tmax, {}, nulls) == -std::numeric_limits<double>::infinity());
    }
    ChannelPathState<S> st;
    const auto cd = track_channels_delta<channels::SpectralMis, absorption::Weight>(m, maj, r, in.tmax, {}, 0, st, true,
                                                                                   rng, lookups);
    CHECK(cd.end == SegmentEnd::InvalidInput);
    const auto cr = track_channels_ratio<channels::Independent, absorption::Event>(m, maj, r, in.tmax, {}, 0,
                                                                                  Spec::Ones(), true, rng, lookups);
    CHECK(cr.end == SegmentEnd::InvalidInput);
    CHECK((cr.f == 0.f).all());
    CHECK(visited == 0);
    CHECK(lookups.count() == 0);
}

TEST_CASE_TEMPLATE("stability: every kernel entry answers an unusable ray with InvalidInput and no estimate", S, Mono,
                   Rgb) {
    using M = DenseGridMedium<S>;
    const M medium = uniform_grid<S>(Box{Vec3(-1.f), Vec3(1.f)}, 1.f, base_sa<S>(), base_ss<S>());
    const GlobalMajorant<M> grey_majorant(medium, 2.f * medium.max_extinction());
    const ChannelMajorant<M> channel_majorant(medium, 2.f);
    Lights<S> lights;
    lights.set(EnvironmentLight<S>{constant_coefficient<S>(1.f)});
    lights.set(PointLight<S>{Vec3(0.f, 3.f, 0.f), constant_coefficient<S>(5.f)});
    const Scene<M, GlobalMajorant<M>, HenyeyGreensteinPhase> scene(medium, grey_majorant, HenyeyGreensteinPhase(0.3f),
                                                                   lights);
    const Scene<M, ChannelMajorant<M>, HenyeyGreensteinPhase> channel_scene(medium, channel_majorant,
                                                                            HenyeyGreensteinPhase(0.3f), lights);
    for (const BadInput& in : bad_inputs()) {
        CAPTURE(in.what);
        check_tracking_entries<S>(medium, grey_majorant, in);
        check_tracking_entries<S>(medium, channel_majorant, in);
        if (std::isnan(in.tmax)) continue;  // the estimators take a camera ray alone
        Pcg32 rng(12, 1);
        LookupCount lookups;
        auto check = [&](const RadianceSample<S>& s) {
            CHECK(s.status == Status::InvalidInput);
            CHECK((s.value == 0.f).all());
        };
        check(PathEstimator<strategy::NullScatteringMis, mis::Balance>{}.radiance(scene, in.ray, {}, rng, lookups));
        check(PathEstimator<strategy::EquiangularMis, mis::Balance>{}.radiance(scene, in.ray, {}, rng, lookups));
        check(SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>{}.radiance(
            channel_scene, in.ray, {}, rng, lookups));
        CHECK(lookups.count() == 0);
    }
}

TEST_CASE("stability: the estimators over a SurfaceScene answer an unusable camera ray with InvalidInput") {
    using namespace nsp_test::grey_scenes;
    const Sc scene = cube_over_floor(true);
    for (const BadInput& in : bad_inputs()) {
        if (std::isnan(in.tmax)) continue;
        CAPTURE(in.what);
        Pcg32 rng(13, 1);
        LookupCount lookups;
        for (const auto& s : {PathEstimator<strategy::NullScatteringMis, mis::Balance>{}.radiance(scene, in.ray, {}, rng,
                                                                                                 lookups),
                              SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>{}
                                  .radiance(scene, in.ray, {}, rng, lookups)}) {
            CHECK(s.status == Status::InvalidInput);
            CHECK(s.value[0] == 0.f);
        }
        CHECK(lookups.count() == 0);
    }
}

TEST_CASE("stability: a direction within kUnitTolerance of unit length is tracked as usual") {
    using M = HomogeneousMedium<Mono>;
    const M medium(Box{Vec3(-1.f), Vec3(1.f)}, grey<Mono>(0.5f), grey<Mono>(0.5f));
    const GlobalMajorant<M> maj(medium, 2.f);
    // |d|^2 = 1 + 8e-4, inside the tolerance: a host's own normalisation in float is far closer.
    const Ray r{Vec3(0.f, 0.f, -3.f), Vec3(0.f, 0.f, std::sqrt(1.f + 8e-4f))};
    REQUIRE(usable_ray(r));
    Pcg32 rng(14, 1);
    NoLookupCount none;
    Stat s;
    for (int i = 0; i < 20000; ++i) {
        const auto t = transmittance_ratio(medium, maj, r, kInf, {}, rng, none);
        REQUIRE(t.status == Status::Ok);
        s.add(t.value[0]);
    }
    // exp(-2 / |d|) = exp(-1.9992): the t-length of the crossing is 2 / |d|. Ratio tracking's
    // per-sample variance here is below 0.1, so the SE is below 0.0023; 5 SE.
    CHECK(std::abs(s.mean - std::exp(-2.0 / std::sqrt(1.0 + 8e-4))) < kSigmas * s.se());
}

// ---------------------------------------------------------------------------------------------
// Runaway scenes

TEST_CASE("stability: flight_collisions counts a flight's tentative collisions until it must have ended") {
    using M = HomogeneousMedium<Mono>;
    const M medium(Box{Vec3(-1.f), Vec3(1.f)}, grey<Mono>(25.f), grey<Mono>(75.f));  // mu_t = 100
    const GlobalMajorant<M> maj(medium, 300.f);
    const double diagonal = 2.0 * std::sqrt(3.0);
    // Below the threshold no lookup is made: the majorant's depth along the longest probe (a
    // diagonal) is the bound.
    const FlightCollisions cheap = flight_collisions(medium, maj, {});
    CHECK(cheap.majorant_depth == doctest::Approx(300.0 * diagonal).epsilon(1e-6));
    CHECK(cheap.collisions == doctest::Approx(300.0 * diagonal).epsilon(1e-6));
    CHECK(cheap.length == doctest::Approx(diagonal).epsilon(1e-6));
    // Threshold 0 looks the medium up: every probe reaches the real optical depth kFlightDepth = 88
    // after 0.88 of its length (mu_t = 100), where 300 x 0.88 = 264 collisions were made.
    const FlightCollisions looked = flight_collisions(medium, maj, {}, 0.0);
    CHECK(looked.collisions == doctest::Approx(300.0 * kFlightDepth / 100.0).epsilon(1e-5));
    // A thin medium the flights cross whole: every tentative collision of the longest probe.
    const M thin(Box{Vec3(-1.f), Vec3(1.f)}, grey<Mono>(0.25f), grey<Mono>(0.75f));  // mu_t = 1
    CHECK(flight_collisions(thin, GlobalMajorant<M>(thin, 3.f), {}, 0.0).collisions ==
          doctest::Approx(3.0 * diagonal).epsilon(1e-5));
}

TEST_CASE("stability: a scene whose majorant would run away is refused up front; a dense tight one is not") {
    using M = HomogeneousMedium<Mono>;
    const M empty(Box{Vec3(-1.f), Vec3(1.f)}, grey<Mono>(0.f), grey<Mono>(0.f));
    Lights<Mono> lights;
    lights.set(EnvironmentLight<Mono>{grey<Mono>(1.f)});
    // 1e7 over an empty box: 3.5e7 collisions along a diagonal. The message names the count, the
    // probe and the limit.
    const GlobalMajorant<M> loose(empty, 1e7f);
    CHECK_THROWS_WITH_AS((Scene<M, GlobalMajorant<M>, IsotropicPhase>(empty, loose, {}, lights)),
                         doctest::Contains("Scene: a flight through the medium takes 3.4641e+07 tentative collisions"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS((Scene<M, GlobalMajorant<M>, IsotropicPhase>(empty, loose, {}, lights)),
                         doctest::Contains("at most kMaxFlightCollisions = 2^20 = 1048576 are allowed"), InvalidArgument);
    // 2e5 over it (6.9e5 collisions): allowed.
    CHECK_NOTHROW((Scene<M, GlobalMajorant<M>, IsotropicPhase>(empty, GlobalMajorant<M>(empty, 2e5f), {}, lights)));
    // Density 1e6 under a majorant twice that: optical thickness 3.5e6 along a diagonal, but every
    // flight has ended after 176 collisions: allowed, and it renders.
    const M dense(Box{Vec3(-1.f), Vec3(1.f)}, grey<Mono>(1e6f), grey<Mono>(0.f));
    const Scene<M, GlobalMajorant<M>, IsotropicPhase> absorber(dense, GlobalMajorant<M>(dense, 2e6f), {}, lights);
    Pcg32 rng(15, 1);
    NoLookupCount none;
    const auto l = PathEstimator<strategy::NullScatteringMis, mis::Balance>{}.radiance(
        absorber, Ray{Vec3(0.f, 0.f, -3.f), Vec3(0.f, 0.f, 1.f)}, {}, rng, none);
    CHECK(l.status == Status::Ok);
    CHECK(l.value[0] == 0.f);
    // A SurfaceScene checks each of its media the same way.
    using namespace nsp_test::grey_scenes;
    const Ls sky(LightSelection::Uniform, 4.f, {}, {EnvironmentLight<Mono>{Spectrum::Constant(1.f)}});
    Shapes shapes;
    shapes.boxes.push_back({Vec3(-1.f), Vec3(1.f), {-1, -1, 0, -1}});
    CHECK_THROWS_WITH_AS(Sc(shapes, {{empty, loose, HenyeyGreensteinPhase(0.f)}}, materials(), sky, -1),
                         doctest::Contains("SurfaceScene: a flight through the medium takes"), InvalidArgument);
}

}  // namespace
