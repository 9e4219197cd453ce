// tests/test_stability_tracking.cpp: the stability suite (issue 8) for the tracking and
// transmittance kernels, Mono and Rgb: every majorant kind (global, per-channel, grid,
// per-channel grid) x every bound policy (Guaranteed, Signed, Clamp, Reject) x mode, through
// free_flight, track_ratio, track_delta, track_channels_ratio and track_channels_delta.
// Hero<4> runs the same cases in test_stability_flights.cpp (a separate translation unit, so
// the two compile in parallel). The cases and what each checks are in
// support/stability_cases.hpp; the float precision each needs is stated there, case by case.
#include "stability_cases.hpp"

// Readable test names: "global/bounding/mono" ...
#define NSP_STAB_NAME(...) \
    namespace doctest { \
    template <> inline String toString<__VA_ARGS__>() { return __VA_ARGS__::name().c_str(); } \
    }
#define NSP_STAB_NAMES(K, S)                                                      \
    NSP_STAB_NAME(nsp_test::stab::Track<nsp_test::stab::K, nsp::bound::Guaranteed, nsp::S>) \
    NSP_STAB_NAME(nsp_test::stab::Track<nsp_test::stab::K, nsp::bound::Signed, nsp::S>)     \
    NSP_STAB_NAME(nsp_test::stab::Track<nsp_test::stab::K, nsp::bound::Clamp, nsp::S>)      \
    NSP_STAB_NAME(nsp_test::stab::Track<nsp_test::stab::K, nsp::bound::Reject, nsp::S>)
NSP_STAB_NAMES(GlobalK, Mono)
NSP_STAB_NAMES(ChannelK, Mono)
NSP_STAB_NAMES(GridK, Mono)
NSP_STAB_NAMES(ChannelGridK, Mono)
NSP_STAB_NAMES(GlobalK, Rgb)
NSP_STAB_NAMES(ChannelK, Rgb)
NSP_STAB_NAMES(GridK, Rgb)
NSP_STAB_NAMES(ChannelGridK, Rgb)
#undef NSP_STAB_NAMES
#undef NSP_STAB_NAME

namespace {

using namespace nsp_test;
using namespace nsp_test::stab;

TEST_CASE_TEMPLATE_DEFINE("stability: densities 0, 1e-12, 1, 1e6 x majorants 0, equal, 1e3 above, below", Tr,
                          stab_density_mono_rgb) {
    density_and_majorant_sweep<Tr>();
}
TEST_CASE_TEMPLATE_DEFINE("stability: rays of length 0, 1e-7, 1e7; origins on faces; axis and denormal directions",
                          Tr, stab_rays_mono_rgb) {
    rays_and_origins<Tr>();
}
TEST_CASE_TEMPLATE_DEFINE("stability: densities 0, 1e-12, 1e3, 1e6 mixed in one grid", Tr, stab_mixed_mono_rgb) {
    mixed_grid<Tr>();
}
TEST_CASE_TEMPLATE_DEFINE("stability: channels whose coefficients differ by 1e8", Tr, stab_spread_rgb) {
    channel_spread<Tr>();
}

using MonoRgb = decltype(std::tuple_cat(TracksMono{}, TracksRgb{}));
TEST_CASE_TEMPLATE_APPLY(stab_density_mono_rgb, MonoRgb);
TEST_CASE_TEMPLATE_APPLY(stab_rays_mono_rgb, MonoRgb);
TEST_CASE_TEMPLATE_APPLY(stab_mixed_mono_rgb, MonoRgb);
TEST_CASE_TEMPLATE_APPLY(stab_spread_rgb, TracksRgb);

}  // namespace


namespace {

using namespace nsp_test;

TEST_CASE_TEMPLATE("stability: controls of 0, equal to the extinction and above the density, at densities 0 to 1e6", S,
                   nsp::Mono, nsp::Rgb) {
    // A constant medium (two equal voxels) under GlobalControl 0 (the plain trackers), the
    // extinction itself (no residual: exact, no lookup for a shadow ray) and GridControl's and
    // TreeControl's minorants; a two-voxel ramp (d, d / 4) under a control above its thin end
    // (signed residuals) against the plain global majorant in the same run. Every estimate finite,
    // Ok, in [0, 1] under a minorant; means within 5 SE (+ 1e-6 for rounding) of exp(-tau) or of
    // each other.
    using M = DenseGridMedium<S>;
    using Spec = typename S::Spectrum;
    const Box box{Vec3(-1.f), Vec3(1.f)};
    const auto sa = spec<S>(0.2f, 0.1f, 0.4f), ss = spec<S>(0.6f, 0.3f, 1.2f);
    const Ray ray{Vec3(-3.f, 0.1f, -0.2f), Vec3(1.f, 0.f, 0.f)};
    constexpr int n = 2000;
    for (const float d : {0.f, 1e-12f, 1.f, 1e6f}) {
        CAPTURE(d);
        const M flat(box, {2, 1, 1}, std::vector<float>{d, d}, sa, ss);
        const Spec unit = (sa + ss);
        const Spec expected = (-unit * d * 2.f).exp();
        auto check = [&](const auto& control, const char* name, bool minorant) {
            CAPTURE(name);
            Pcg32 rng(3, 7);
            LookupCount lookups;
            SpecStat<S> ratio, delta;
            for (int i = 0; i < n; ++i) {
                const auto r = transmittance_ratio(flat, control, ray, kInf, {}, rng, lookups);
                const auto t = transmittance_delta(flat, control, ray, kInf, {}, rng, lookups);
                REQUIRE(r.status == Status::Ok);
                REQUIRE(t.status == Status::Ok);
                REQUIRE(all_finite(r.value));
                REQUIRE(all_finite(t.value));
                if (minorant) REQUIRE(((r.value >= 0.f) && (r.value <= 1.f)).all());
                ratio.add(r.value);
                delta.add(t.value);
            }
            for (int c = 0; c < S::channels; ++c) {
                CAPTURE(c);
                const Stat& a = ratio.ch[std::size_t(c)];
                const Stat& b = delta.ch[std::size_t(c)];
                CHECK(std::abs(a.mean - double(expected[c])) <= 5.0 * a.se() + 1e-6);
                CHECK(std::abs(b.mean - double(expected[c])) <= 5.0 * b.se() + 1e-6);
            }
            return lookups.count();
        };
        check(GlobalControl<M>(flat, spec<S>(0.f, 0.f, 0.f)), "control 0", true);
        check(GridControl<M>(flat, 2), "grid control", true);
        check(TreeControl<M>(flat, TreeLayout{box, {2, 1, 1}, {2, 0, 0}, 0.f, 0.f}), "tree control", true);
        const std::uint64_t exact = check(GlobalControl<M>(flat, scale(unit, d)), "control = extinction", true);
        if constexpr (S::channels == 1) CHECK(exact <= std::uint64_t(n));  // shadow rays none; flights one at a real collision
        // Above the density: control at half the dense end over a ramp whose thin end is a quarter.
        if (!(d > 0.f) || d > 1e3f) continue;  // 0: nothing above; 1e6: T = 0 for every estimator
        const M ramp(box, {2, 1, 1}, std::vector<float>{d, 0.25f * d}, sa, ss);
        Pcg32 rng(5, 7);
        LookupCount lookups;
        SpecStat<S> signed_ratio, plain;
        const GlobalControl<M> above(ramp, scale(unit, 0.5f * d));
        const GlobalMajorant<M> majorant(ramp);
        for (int i = 0; i < 20000; ++i) {
            const auto r = transmittance_ratio(ramp, above, ray, kInf, {}, rng, lookups);
            const auto p = transmittance_ratio(ramp, majorant, ray, kInf, {}, rng, lookups);
            REQUIRE(r.status == Status::Ok);
            REQUIRE(all_finite(r.value));
            signed_ratio.add(r.value);
            plain.add(p.value);
        }
        for (int c = 0; c < S::channels; ++c) {
            const Stat& a = signed_ratio.ch[std::size_t(c)];
            const Stat& b = plain.ch[std::size_t(c)];
            CAPTURE(c);
            CHECK(std::abs(a.mean - b.mean) <= 5.0 * std::sqrt(a.se() * a.se() + b.se() * b.se()) + 1e-6);
        }
    }
}

}  // namespace
