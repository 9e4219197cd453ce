// bench/work_count.cpp: a fixed amount of work per kernel, for the noise-free half of the
// before/after check (bench/run.sh, step 3; bench/instructions.sh alone). Fixed seeds and a fixed
// number of calls; under valgrind --tool=callgrind each kernel dumps its instruction count (client
// requests; without valgrind they do nothing). The kernels:
// - Mono, the default cloud (set-ups A and B): the trackers and every grey path estimator;
// - Rgb, the chromatic cloud: the per-channel trackers and SpectralPathEstimator (C1, C2);
// - the scenes with surfaces: the room (PathEstimator, Mono), the chromatic room
//   (SpectralPathEstimator), nsp_render's F2 and P1 as SurfaceScenes (equiangular and emission
//   MIS), the lantern (BdptEstimator, grey, with light tracing) and C1 as a SurfaceScene
//   (SpectralBdptEstimator with light tracing).
//
// The scripts compile this one file, with the same compiler command, against the current include/
// and examples/ and against the "before" commit's, so it uses only API both have. For each kernel
// it prints
//     <kernel> <calls> <density lookups> <checksum>
// If the two builds print the same lines they sampled the same paths and computed the same
// values; a difference in instructions is then the library's code alone (bench/report.py).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#else
#define CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_ZERO_STATS
#define CALLGRIND_DUMP_STATS_AT(name)
#endif

#include <default_scene.hpp>
#include <nsp/nsp.hpp>
#include <room_scene.hpp>
#include <combinations.hpp>
#include <scene_choice.hpp>

namespace {

using nsp::Mono;
using nsp_examples::LightSetup;

constexpr float kTmax = 100.f;
constexpr int kRays = 4096;          ///< rays in each set, cycled
constexpr int kTrackCalls = 20000;   ///< tracked rays per tracker kernel
constexpr int kSamples = 4000;       ///< radiance samples per estimator kernel

/// Rays through the cloud's box: origin on the sphere of radius 3, aimed at a point in the box
/// (the recipe of bench/fixtures.hpp tracking_rays()).
std::vector<nsp::Ray> tracking_rays(const nsp::Box& box) {
    nsp::Pcg32 rng(2, 22);
    std::vector<nsp::Ray> rays(kRays);
    for (auto& ray : rays) {
        const float u1 = rng.uniform(), u2 = rng.uniform();
        const nsp::Vec3 o = 3.f * nsp::uniform_sphere(u1, u2);
        const float x = rng.uniform(), y = rng.uniform(), z = rng.uniform();
        ray = {o, glm::normalize(box.lo + nsp::Vec3(x, y, z) * (box.hi - box.lo) - o)};
    }
    return rays;
}

/// Camera rays of the example renderer (square image) that cross the cloud: density 0.05 or more
/// somewhere along a 256-step march (the recipe of bench/fixtures.hpp camera_rays()).
template <class M>
std::vector<nsp::Ray> camera_rays(const M& medium) {
    nsp::Pcg32 rng(4, 44);
    std::vector<nsp::Ray> rays;
    while (int(rays.size()) < kRays) {
        const float u = rng.uniform(), v = rng.uniform();
        const nsp::Ray ray = nsp_examples::camera_ray(u, v, 1.f);
        const nsp::Interval in = medium.bounds().clip(ray, 0.f, kTmax);
        bool hits = false;
        for (int k = 0; k < 256 && !in.empty() && !hits; ++k)
            hits = medium.density(ray.at(in.t0 + (float(k) + 0.5f) / 256.f * (in.t1 - in.t0))) >= 0.05f;
        if (hits) rays.push_back(ray);
    }
    return rays;
}

/// Runs `body(i)` for i in [0, n) as one kernel: instructions counted from here to the dump.
template <class F>
void kernel(const char* name, int n, const nsp::LookupCount& counter, F&& body) {
    // NSP_WORK_ONLY=<prefix> runs only the kernels whose names start with it (a quicker look).
    if (const char* only = std::getenv("NSP_WORK_ONLY"); only && std::string(name).rfind(only, 0) != 0) return;
    const std::uint64_t before = counter.count();
    double checksum = 0.0;
    CALLGRIND_ZERO_STATS;
    for (int i = 0; i < n; ++i) checksum += body(i);
    CALLGRIND_DUMP_STATS_AT(name);
    std::printf("%s %d %llu %.9g\n", name, n, static_cast<unsigned long long>(counter.count() - before), checksum);
}

/// The medium and majorant of an nsp::Scene, as accessors (a Scene is a SurfaceScene) or as the
/// members of earlier versions: this file is built against both.
template <class Sc>
const auto& medium_of(const Sc& s) {
    if constexpr (requires { s.medium(); }) return s.medium();
    else return s.medium;
}
template <class Sc>
const auto& majorant_of(const Sc& s) {
    if constexpr (requires { s.majorant(); }) return s.majorant();
    else return s.majorant;
}

template <nsp::AbsorptionPolicy A>
void delta(const char* name, const auto& scene, const std::vector<nsp::Ray>& rays, nsp::LookupCount& counter) {
    nsp::Pcg32 rng(5, 55);
    kernel(name, kTrackCalls, counter, [&](int i) {
        const auto r = nsp::track_delta<A>(medium_of(scene), majorant_of(scene), rays[i % kRays], kTmax, {}, rng, counter);
        return double(r.t) + double(r.weight[0]) + double(r.null_pdf_product);
    });
}

template <nsp::AbsorptionPolicy A, bool kNullRatio>
void ratio(const char* name, const auto& scene, const std::vector<nsp::Ray>& rays, nsp::LookupCount& counter) {
    nsp::Pcg32 rng(5, 55);
    kernel(name, kTrackCalls, counter, [&](int i) {
        const auto r = nsp::track_ratio<A, kNullRatio>(medium_of(scene), majorant_of(scene), rays[i % kRays], kTmax, {},
                                                        rng, counter);
        return double(r.transmittance[0]) + double(r.null_pdf_product);
    });
}

template <class E>
void radiance(const std::string& name, const auto& scene, const std::vector<nsp::Ray>& rays,
              nsp::LookupCount& counter) {
    const E estimator;
    nsp::Pcg32 rng(6, 66);
    kernel(name.c_str(), kSamples, counter, [&](int i) {
        return double(estimator.radiance(scene, rays[i % kRays], {}, rng, counter).value[0]);
    });
}

template <class St, class H = nsp::mis::None>
void estimators(const char* kind, const auto& scene, const char* setup, const std::vector<nsp::Ray>& rays,
                nsp::LookupCount& counter) {
    const std::string base = std::string("radiance/") + kind + "/";
    radiance<nsp::PathEstimator<St, H, nsp::absorption::Event>>(base + "absorb-event/" + setup, scene, rays, counter);
    radiance<nsp::PathEstimator<St, H, nsp::absorption::Weight>>(base + "absorb-weight/" + setup, scene, rays, counter);
}


/// As radiance(), for an estimator over channels or one built from options.
template <class E, class Sc>
void radiance_with(const std::string& name, const E& estimator, const Sc& scene, const std::vector<nsp::Ray>& rays,
                   int n, nsp::LookupCount& counter) {
    nsp::Pcg32 rng(6, 66);
    kernel(name.c_str(), n, counter, [&](int i) {
        return double(estimator.radiance(scene, rays[i % kRays], {}, rng, counter).value.sum());
    });
}

/// BDPT with light tracing through `camera`: the sample's value and its splats.
template <class E, class Sc>
void bdpt_samples(const std::string& name, const E& estimator, const Sc& scene, const nsp::PinholeCamera& camera, int n,
                  nsp::LookupCount& counter) {
    nsp::Pcg32 rng(6, 66), uv(7, 77);
    kernel(name.c_str(), n, counter, [&](int) {
        double splats = 0.0;
        auto splat = [&](float, float, const auto& value) { splats += double(value.sum()); };
        const float u = uv.uniform(), v = uv.uniform();
        return double(estimator.sample(scene, camera, u, v, {}, rng, counter, splat).value.sum()) + splats;
    });
}

/// Camera rays of the room's image.
std::vector<nsp::Ray> room_rays() {
    nsp::Pcg32 rng(8, 88);
    std::vector<nsp::Ray> rays(kRays);
    for (auto& r : rays) r = nsp_examples::room_camera_ray(rng.uniform(), rng.uniform(), 1.f);
    return rays;
}

/// Camera rays of nsp_render's image (the pinhole of cloud_pinhole()).
std::vector<nsp::Ray> image_rays() {
    const nsp::PinholeCamera camera = nsp_examples::cloud_pinhole();
    nsp::Pcg32 rng(9, 99);
    std::vector<nsp::Ray> rays(kRays);
    for (auto& r : rays) r = camera.ray(rng.uniform(), rng.uniform());
    return rays;
}

/// The per-channel kernels on the chromatic cloud (Rgb, per-channel majorants).
void channel_kernels(nsp::LookupCount& counter) {
    using S = nsp::Rgb;
    using M = nsp::DenseGridMedium<S>;
    using Maj = nsp::ChannelMajorant<M>;
    namespace ch = nsp::channels;
    namespace st = nsp::strategy;
    const M medium = nsp_examples::make_chromatic_medium<S>();
    const Maj majorant(medium);
    const std::vector<nsp::Ray> track = tracking_rays(medium.bounds());
    {
        nsp::Pcg32 rng(5, 55);
        kernel("track/ChannelDelta:rgb", kTrackCalls / 4, counter, [&](int i) {
            nsp::ChannelPathState<S> st;
            const auto r = nsp::track_channels_delta<ch::SpectralMis, nsp::absorption::Weight>(
                medium, majorant, track[i % kRays], kTmax, {}, i % 3, st, true, rng, counter);
            return double(r.t) + double(st.f.sum()) + double(st.uni.sum()) + double(st.nee.sum());
        });
    }
    {
        nsp::Pcg32 rng(5, 55);
        kernel("track/ChannelRatio:rgb", kTrackCalls / 4, counter, [&](int i) {
            const auto r = nsp::track_channels_ratio<ch::SpectralMis, nsp::absorption::Weight>(
                medium, majorant, track[i % kRays], kTmax, {}, i % 3, S::Spectrum::Ones(), true, rng, counter);
            return double(r.f.sum()) + double(r.nee.sum()) + double(r.uni.sum());
        });
    }
    const std::vector<nsp::Ray> camera = camera_rays(medium);
    for (const auto setup : {nsp_examples::ChromaticSetup::Env, nsp_examples::ChromaticSetup::Small}) {
        const auto scene = nsp::Scene(medium, majorant, nsp::HenyeyGreensteinPhase(nsp_examples::kPhaseG),
                                      nsp_examples::chromatic_lights<S>(setup));
        const std::string tail = std::string(":rgb/") + nsp_examples::name(setup);
        radiance_with("radiance/spectral-mis:uni" + tail,
                      nsp::SpectralPathEstimator<ch::SpectralMis, st::Unidirectional>{}, scene, camera, kSamples / 4,
                      counter);
        radiance_with("radiance/spectral-mis:uni-nee-mis" + tail,
                      nsp::SpectralPathEstimator<ch::SpectralMis, st::NullScatteringMis, nsp::mis::Balance>{}, scene,
                      camera, kSamples / 4, counter);
    }
}

/// The estimators over SurfaceScenes: the room, the chromatic room, F2 and P1, the lantern and C1.
void surface_kernels(nsp::LookupCount& counter) {
    namespace st = nsp::strategy;
    namespace ch = nsp::channels;
    namespace ex = nsp_examples;
    const std::vector<nsp::Ray> room = room_rays(), image = image_rays();
    {
        const auto scene = ex::make_room_scene();
        radiance_with("surfaces/room:uni", nsp::PathEstimator<st::Unidirectional>{}, scene, room, kSamples / 4, counter);
        radiance_with("surfaces/room:uni-nee-mis", nsp::PathEstimator<st::NullScatteringMis, nsp::mis::Balance>{},
                      scene, room, kSamples / 4, counter);
    }
    {
        using CM = nsp::DenseGridMedium<nsp::Rgb>;
        const CM chroma = ex::make_chromatic_medium<nsp::Rgb>();
        const auto scene = ex::make_room_scene(chroma, nsp::ChannelMajorant<CM>(chroma));
        radiance_with("surfaces/chromatic-room:spectral-mis:uni-nee-mis",
                      nsp::SpectralPathEstimator<ch::SpectralMis, st::NullScatteringMis, nsp::mis::Balance>{}, scene,
                      room, kSamples / 8, counter);
    }
    {
        const ex::SceneChoice c{ex::SceneKind::Fog, {}, {}, ex::FogSetup::F2};
        const auto scene = ex::make_setup_surface_scene<nsp::Mono, ex::DenseGridCloud, ex::GridMajorantPolicy<>>(c);
        radiance_with("surfaces/F2:uni-nee-eq-mis", nsp::PathEstimator<st::EquiangularMis, nsp::mis::Balance>{}, scene,
                      image, kSamples / 4, counter);
    }
    {
        const ex::SceneChoice c{ex::SceneKind::Plume};
        const auto scene = ex::make_setup_surface_scene<nsp::Rgb, ex::EmissivePlume, ex::GridMajorantPolicy<>>(c);
        radiance_with("surfaces/P1:uni-nee-mis:rgb", nsp::PathEstimator<st::NullScatteringMis, nsp::mis::Balance>{},
                      scene, image, kSamples / 4, counter);
        radiance_with("surfaces/P1:spectral-mis:uni-nee-mis",
                      nsp::SpectralPathEstimator<ch::SpectralMis, st::NullScatteringMis, nsp::mis::Balance>{}, scene,
                      image, kSamples / 8, counter);
    }
    {
        using Cloud = nsp::DenseGridMedium<nsp::Mono>;
        const auto scene = ex::make_lantern_scene(ex::make_default_medium<nsp::Mono>(),
                                                  nsp::GlobalMajorant<Cloud>(ex::make_default_medium<nsp::Mono>()));
        bdpt_samples("bdpt/lantern:null-mis", nsp::BdptEstimator<nsp::bdpt::NullScattering>{}, scene, ex::room_pinhole(),
                     kSamples / 8, counter);
    }
    {
        const ex::SceneChoice c{ex::SceneKind::Chromatic, {}, ex::ChromaticSetup::Env};
        const auto scene = ex::make_setup_surface_scene<nsp::Rgb, ex::DenseGridCloud, ex::ChannelMajorantPolicy>(c);
        bdpt_samples("bdpt/C1:spectral-mis", nsp::SpectralBdptEstimator<nsp::mis::Balance>{}, scene, ex::cloud_pinhole(),
                     kSamples / 16, counter);
    }
}

}  // namespace

int main() {
    const auto a = nsp_examples::make_default_scene<Mono>(LightSetup::A);
    const auto b = nsp_examples::make_default_scene<Mono>(LightSetup::B);
    const std::vector<nsp::Ray> track = tracking_rays(medium_of(a).bounds());
    const std::vector<nsp::Ray> camera = camera_rays(medium_of(a));
    nsp::LookupCount counter;
    CALLGRIND_START_INSTRUMENTATION;

    delta<nsp::absorption::Event>("track/DeltaEvent", a, track, counter);
    delta<nsp::absorption::Weight>("track/DeltaWeight", a, track, counter);
    ratio<nsp::absorption::Event, false>("track/RatioPlain", a, track, counter);
    ratio<nsp::absorption::Event, true>("track/RatioNullEvent", a, track, counter);
    ratio<nsp::absorption::Weight, true>("track/RatioNullWeight", a, track, counter);

    namespace st = nsp::strategy;
    for (const auto* sc : {&a, &b}) {
        const char* setup = sc == &a ? "A" : "B";
        estimators<st::Unidirectional>("unidirectional", *sc, setup, camera, counter);
        estimators<st::NextEvent>("ratio-nee", *sc, setup, camera, counter);
        estimators<st::DirectionalMis, nsp::mis::Balance>("directional-mis:balance", *sc, setup, camera, counter);
        estimators<st::NullScatteringMis, nsp::mis::Balance>("uni-nee-mis:balance", *sc, setup, camera, counter);
        estimators<st::NullScatteringMis, nsp::mis::Power>("uni-nee-mis:power", *sc, setup, camera, counter);
    }
    channel_kernels(counter);
    surface_kernels(counter);
    return 0;
}
