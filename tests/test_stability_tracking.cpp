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

