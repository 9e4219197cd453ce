// bench/work_count.cpp: a fixed amount of Mono work, for the noise-free half of the before/after
// Mono check (bench/run.sh, step 3). The trackers and the grey path estimators run on the default
// cloud with fixed seeds and a fixed number of calls; under valgrind --tool=callgrind each kernel
// dumps its instruction count (client requests; without valgrind they do nothing).
//
// run.sh compiles this one file, with the same compiler command, against the current include/
// and against the "before" commit's, so it uses only API both have. For each kernel it prints
//     <kernel> <calls> <density lookups> <checksum>
// If the two builds print the same lines they sampled the same paths and computed the same
// values; a difference in instructions is then the library's code alone (bench/report.py).
#include <cstdint>
#include <cstdio>
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
    const std::uint64_t before = counter.count();
    double checksum = 0.0;
    CALLGRIND_ZERO_STATS;
    for (int i = 0; i < n; ++i) checksum += body(i);
    CALLGRIND_DUMP_STATS_AT(name);
    std::printf("%s %d %llu %.9g\n", name, n, static_cast<unsigned long long>(counter.count() - before), checksum);
}

template <nsp::AbsorptionPolicy A>
void delta(const char* name, const auto& scene, const std::vector<nsp::Ray>& rays, nsp::LookupCount& counter) {
    nsp::Pcg32 rng(5, 55);
    kernel(name, kTrackCalls, counter, [&](int i) {
        const auto r = nsp::track_delta<A>(scene.medium, scene.majorant, rays[i % kRays], kTmax, {}, rng, counter);
        return double(r.t) + double(r.weight[0]) + double(r.null_pdf_product);
    });
}

template <nsp::AbsorptionPolicy A, bool kNullRatio>
void ratio(const char* name, const auto& scene, const std::vector<nsp::Ray>& rays, nsp::LookupCount& counter) {
    nsp::Pcg32 rng(5, 55);
    kernel(name, kTrackCalls, counter, [&](int i) {
        const auto r = nsp::track_ratio<A, kNullRatio>(scene.medium, scene.majorant, rays[i % kRays], kTmax, {},
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

}  // namespace

int main() {
    const auto a = nsp_examples::make_default_scene<Mono>(LightSetup::A);
    const auto b = nsp_examples::make_default_scene<Mono>(LightSetup::B);
    const std::vector<nsp::Ray> track = tracking_rays(a.medium.bounds());
    const std::vector<nsp::Ray> camera = camera_rays(a.medium);
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
    return 0;
}
