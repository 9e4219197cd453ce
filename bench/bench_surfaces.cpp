// bench/bench_surfaces.cpp: the path estimators over an nsp::SurfaceScene (THEORY 5.8).
// - BM_Room/<strategy>: one radiance sample of the room (examples/room_scene.hpp: the cloud behind
//   null interfaces over a floor with walls, a quad light and a sky), Mono, per grey strategy, on
//   camera rays through the image (cycled).
// - BM_CloudUnderSky/<scene>/<strategy>: what the general loop costs where there are no surfaces:
//   the default cloud under a white sky as an nsp::Scene and as a SurfaceScene over
//   nsp::NoSurfaces (the camera in the cloud's medium, a LightSampler of the one environment
//   light): the same estimator, so the ratio of the two times is the price of the surface walk
//   (its geometry queries and handle checks, the light sampler) for a host that uses it anyway.
// - BM_Lantern/<estimator>: one radiance sample of the lantern (room_scene.hpp: the lamp boxed
//   above the cloud, the BDPT scene), the path tracers against BdptEstimator; for BDPT the
//   strategy families' counts per sample (hits s = 0, NEE s = 1, connections s >= 2, each one
//   evaluated path; splats t = 1 with light tracing) and the stack its subpaths take (bytes,
//   MaxDepth = 32).
// - BM_FogLamp/<estimator>: one sample of nsp_render's F2 (a point lamp beside thin fog) as a
//   SurfaceScene through its camera: uni + NEE + equiangular MIS against BDPT with light tracing,
//   with its equiangular strategy and without; for BDPT the equiangular strategy's contributions
//   per sample.
// - BM_FlameSmoke/<estimator>: the same for nsp_render's P1 (a flame in smoke, no other light;
//   Rgb): uni + NEE MIS (with the emission segment technique) against BDPT with light tracing,
//   with its segment technique and without; for BDPT the segment technique's contributions per
//   sample.
// - BM_ChromaticSky/<estimator>: one sample of nsp_render's C1 (the chromatic cloud under a white
//   sky; Rgb, per-channel majorants) as a SurfaceScene through its camera, where tracking alone is
//   the best technique: the spectral MIS path tracer against per-channel BDPT with light tracing
//   at the counts its learner chooses there (NEE and light subpaths on 1/64 of the samples), so
//   that the ratio is BDPT's bookkeeping along the camera subpath.
// - BM_ChromaticRoom/<estimator>: one sample of the room around the chromatic cloud (Rgb,
//   extinction 5, 20 and 80 per unit density: nsp_room's second table), spectral MIS + NEE and
//   per-channel BDPT under per-channel majorants, grey BDPT under the grey one; the BDPT rows with
//   light tracing through the room's pinhole camera, with their subpaths' stack (bytes).
#include <array>
#include <string>
#include <type_traits>
#include <vector>

#include <benchmark/benchmark.h>

#include "fixtures.hpp"
#include "combinations.hpp"
#include "room_scene.hpp"
#include "scene_choice.hpp"

namespace {

using namespace nsp_bench;

/// Camera rays through the room's image, a fixed set.
const std::vector<nsp::Ray>& room_rays() {
    static const std::vector<nsp::Ray> rays = [] {
        nsp::Pcg32 rng(8, 88);
        std::vector<nsp::Ray> r;
        r.reserve(kSetSize);
        for (std::size_t i = 0; i < kSetSize; ++i) r.push_back(nsp_examples::room_camera_ray(rng.uniform(), rng.uniform(), 1.f));
        return r;
    }();
    return rays;
}

template <class E, class Sc>
void run(benchmark::State& state, const Sc& scene, const std::vector<nsp::Ray>& rays) {
    const E estimator;
    nsp::Pcg32 rng(6, 66);
    nsp::LookupCount counter;
    std::size_t i = 0;
    for (auto _ : state) {
        auto r = estimator.radiance(scene, rays[i], {}, rng, counter);
        benchmark::DoNotOptimize(r);
        i = (i + 1) & kSetMask;
    }
    report_lookups(state, counter, "lookups/sample");
}

template <class E>
void BM_Room(benchmark::State& state) {
    static const auto scene = nsp_examples::make_room_scene();
    run<E>(state, scene, room_rays());
}

using Cloud = nsp::DenseGridMedium<nsp::Mono>;
using Sky = nsp::LightSampler<nsp::Mono, nsp::EnvironmentLight<nsp::Mono>>;
using CloudOnly = nsp::SurfaceScene<nsp::NoSurfaces, Cloud, nsp::GlobalMajorant<Cloud>, nsp::HenyeyGreensteinPhase,
                                    nsp::Materials<nsp::Mono, nsp::LambertianBsdf<nsp::Mono>>, Sky>;

template <class E>
void BM_CloudUnderSky_Scene(benchmark::State& state) {
    static const auto scene = [] {
        nsp::Lights<nsp::Mono> sky;
        sky.set(nsp::EnvironmentLight<nsp::Mono>{nsp::constant_coefficient<nsp::Mono>(1.f)});
        return nsp::make_scene(nsp_examples::make_default_medium<nsp::Mono>(),
                               nsp::HenyeyGreensteinPhase(nsp_examples::kPhaseG), sky);
    }();
    run<E>(state, scene, camera_rays());
}

template <class E>
void BM_CloudUnderSky_NoSurfaces(benchmark::State& state) {
    static const CloudOnly scene = [] {
        Cloud cloud = nsp_examples::make_default_medium<nsp::Mono>();
        nsp::GlobalMajorant<Cloud> majorant(cloud);
        return CloudOnly({}, {{std::move(cloud), majorant, nsp::HenyeyGreensteinPhase(nsp_examples::kPhaseG)}},
                         nsp::Materials<nsp::Mono, nsp::LambertianBsdf<nsp::Mono>>({}),
                         Sky(nsp::LightSelection::Uniform, 2.f, {nsp::EnvironmentLight<nsp::Mono>{nsp::constant_coefficient<nsp::Mono>(1.f)}}),
                         0);
    }();
    run<E>(state, scene, camera_rays());
}

/// Uniform image points, kSetSize of them (fixed seed).
const std::vector<std::array<float, 2>>& image_points() {
    static const std::vector<std::array<float, 2>> uv = [] {
        nsp::Pcg32 g(8, 88);
        std::vector<std::array<float, 2>> p(kSetSize);
        for (auto& x : p) x = {g.uniform(), g.uniform()};
        return p;
    }();
    return uv;
}

/// With light tracing: BdptEstimator::sample through the room's pinhole camera at the same image
/// points, the splats summed into a sink.
template <class E, bool kLightTracing = false>
void BM_Lantern(benchmark::State& state) {
    static const auto scene = nsp_examples::make_lantern_scene(
        nsp_examples::make_default_medium<nsp::Mono>(),
        nsp::GlobalMajorant<Cloud>(nsp_examples::make_default_medium<nsp::Mono>()));
    const E estimator;
    nsp::Pcg32 rng(6, 66);
    nsp::LookupCount counter;
    double hits = 0, nee = 0, connections = 0, splats = 0;
    auto count = [&](int s, int t, const auto&, float, const auto&, const auto&) {
        (t == 1 ? splats : s == 0 ? hits : s == 1 ? nee : connections) += 1.0;
    };
    std::size_t i = 0;
    for (auto _ : state) {
        if constexpr (kLightTracing) {
            static const nsp::PinholeCamera camera = nsp_examples::room_pinhole();
            const auto& uv = image_points();
            double sink = 0.0;
            auto splat = [&](float, float, const auto& value) { sink += double(value[0]); };
            auto r = estimator.sample_observed(scene, camera, uv[i][0], uv[i][1], {}, rng, counter, splat, count);
            benchmark::DoNotOptimize(r);
            benchmark::DoNotOptimize(sink);
        } else if constexpr (requires { E::kMaxPath; }) {
            auto r = estimator.radiance_observed(scene, room_rays()[i], {}, rng, counter, count);
            benchmark::DoNotOptimize(r);
        } else {
            auto r = estimator.radiance(scene, room_rays()[i], {}, rng, counter);
            benchmark::DoNotOptimize(r);
        }
        i = (i + 1) & kSetMask;
    }
    report_lookups(state, counter, "lookups/sample");
    if constexpr (requires { E::kMaxPath; }) {
        const double n = double(state.iterations());
        state.counters["hits/sample"] = hits / n;
        state.counters["nee/sample"] = nee / n;
        state.counters["connections/sample"] = connections / n;
        state.counters["splats/sample"] = splats / n;
        state.counters["subpath_bytes"] =
            double(sizeof(typename E::template VertexFor<nsp::Mono>) * (2 * E::kMaxDepth + 3) + sizeof(typename E::Pdfs));
    }
}

/// The chromatic room under per-channel majorants (kPerChannel) or the grey one; one sample per
/// iteration: BDPT through the room's pinhole camera with light tracing, the path tracer on the
/// camera rays.
template <class E, bool kPerChannelMajorant>
void BM_ChromaticRoom(benchmark::State& state) {
    using CM = nsp::DenseGridMedium<nsp::Rgb>;
    using Maj = std::conditional_t<kPerChannelMajorant, nsp::ChannelMajorant<CM>, nsp::GlobalMajorant<CM>>;
    static const auto scene = [] {
        const CM chroma = nsp_examples::make_chromatic_medium<nsp::Rgb>();
        return nsp_examples::make_room_scene(chroma, Maj(chroma));
    }();
    const E estimator;
    nsp::Pcg32 rng(6, 66);
    nsp::LookupCount counter;
    std::size_t i = 0;
    const nsp::PinholeCamera camera = nsp_examples::room_pinhole();
    for (auto _ : state) {
        if constexpr (requires { E::kMaxPath; }) {
            const nsp::Ray& ray = room_rays()[i];
            float u = 0.f, v = 0.f;
            camera.raster(ray.d, u, v);
            double sink = 0.0;
            auto splat = [&](float, float, const auto& value) { sink += double(value[0]); };
            auto r = estimator.sample(scene, camera, u, v, {}, rng, counter, splat);
            benchmark::DoNotOptimize(r);
            benchmark::DoNotOptimize(sink);
        } else {
            auto r = estimator.radiance(scene, room_rays()[i], {}, rng, counter);
            benchmark::DoNotOptimize(r);
        }
        i = (i + 1) & kSetMask;
    }
    report_lookups(state, counter, "lookups/sample");
    if constexpr (requires { E::kMaxPath; })
        state.counters["subpath_bytes"] =
            double(sizeof(typename E::template VertexFor<nsp::Rgb>) * (2 * E::kMaxDepth + 3) +
                   sizeof(typename E::template PdfsFor<nsp::Rgb>));
}

using SpectralNsmis = nsp::SpectralPathEstimator<nsp::channels::SpectralMis, nsp::strategy::NullScatteringMis, nsp::mis::Balance>;
BENCHMARK_TEMPLATE(BM_ChromaticRoom, SpectralNsmis, true)->Name("BM_ChromaticRoom/spectral-mis+nee:per-channel-majorant");
BENCHMARK_TEMPLATE(BM_ChromaticRoom, nsp::BdptEstimator<>, false)->Name("BM_ChromaticRoom/bdpt-null-mis:grey+light-tracing");
BENCHMARK_TEMPLATE(BM_ChromaticRoom, nsp::SpectralBdptEstimator<>, true)
    ->Name("BM_ChromaticRoom/bdpt-spectral-mis:per-channel-majorant+light-tracing");

using Uni = nsp::PathEstimator<nsp::strategy::Unidirectional>;
using Nee = nsp::PathEstimator<nsp::strategy::NextEvent>;
using Dmis = nsp::PathEstimator<nsp::strategy::DirectionalMis, nsp::mis::Balance>;
using Nsmis = nsp::PathEstimator<nsp::strategy::NullScatteringMis, nsp::mis::Balance>;

BENCHMARK_TEMPLATE(BM_Room, Uni)->Name("BM_Room/unidirectional");
BENCHMARK_TEMPLATE(BM_Room, Nee)->Name("BM_Room/ratio-nee");
BENCHMARK_TEMPLATE(BM_Room, Dmis)->Name("BM_Room/directional-mis:balance");
BENCHMARK_TEMPLATE(BM_Room, Nsmis)->Name("BM_Room/uni-nee-mis:balance");
BENCHMARK_TEMPLATE(BM_Lantern, Uni)->Name("BM_Lantern/unidirectional");
BENCHMARK_TEMPLATE(BM_Lantern, Nsmis)->Name("BM_Lantern/uni-nee-mis:balance");
BENCHMARK_TEMPLATE(BM_Lantern, nsp::BdptEstimator<nsp::bdpt::Directional>)->Name("BM_Lantern/bdpt-directional-mis:balance");
BENCHMARK_TEMPLATE(BM_Lantern, nsp::BdptEstimator<nsp::bdpt::NullScattering>)->Name("BM_Lantern/bdpt-null-mis:balance");
BENCHMARK_TEMPLATE(BM_Lantern, nsp::BdptEstimator<nsp::bdpt::NullScattering>, true)
    ->Name("BM_Lantern/bdpt-null-mis:balance+light-tracing");

/// One sample per iteration of `scene` at image_points() through nsp_render's camera: BDPT's with
/// light tracing (its splats summed), a path tracer's camera ray; BDPT's contributions of the
/// strategy `strategy(pdfs)` names are reported per sample as `name`.
template <class E, class Scene, class Strategy>
void pinhole_samples(benchmark::State& state, const Scene& scene, const E& estimator, Strategy strategy,
                     const char* name) {
    static const nsp::PinholeCamera camera = nsp_examples::cloud_pinhole();
    nsp::Pcg32 rng(6, 66);
    nsp::LookupCount counter;
    double counted = 0;
    std::size_t i = 0;
    const auto& uv = image_points();
    for (auto _ : state) {
        if constexpr (requires { E::kMaxPath; }) {
            auto count = [&](int s, int, const auto&, float, const auto& pdfs, const auto&) {
                if (s == strategy(pdfs)) counted += 1.0;
            };
            double sink = 0.0;
            auto splat = [&](float, float, const auto& value) { sink += double(value[0]); };
            auto r = estimator.sample_observed(scene, camera, uv[i][0], uv[i][1], {}, rng, counter, splat, count);
            benchmark::DoNotOptimize(r);
            benchmark::DoNotOptimize(sink);
        } else {
            auto r = estimator.radiance(scene, camera.ray(uv[i][0], uv[i][1]), {}, rng, counter);
            benchmark::DoNotOptimize(r);
        }
        i = (i + 1) & kSetMask;
    }
    report_lookups(state, counter, "lookups/sample");
    if constexpr (requires { E::kMaxPath; }) state.counters[name] = counted / double(state.iterations());
}

/// Every row's options: BDPT's 32 real vertices, as nsp_room's; `set` changes them for BDPT.
template <class E, class Set>
E with_bdpt_depth(Set set) {
    nsp::EstimatorOptions o = nsp::BdptEstimator<>::default_options();
    if constexpr (requires { E::kMaxPath; }) set(o);
    return E(o);
}

/// nsp_render's F2 as a SurfaceScene (see the header); BDPT with its equiangular strategy when
/// kEquiangular.
template <class E, bool kEquiangular = true>
void BM_FogLamp(benchmark::State& state) {
    static const auto scene = [] {
        const nsp_examples::SceneChoice c{nsp_examples::SceneKind::Fog, {}, {}, nsp_examples::FogSetup::F2};
        return nsp_examples::make_setup_surface_scene<nsp::Mono, nsp_examples::DenseGridCloud,
                                                      nsp_examples::GridMajorantPolicy<>>(c);
    }();
    const E estimator = with_bdpt_depth<E>([](nsp::EstimatorOptions& o) { o.bdpt_equiangular = kEquiangular; });
    pinhole_samples(state, scene, estimator, [](const auto& pdfs) { return pdfs.kEquiangular; }, "equiangular/sample");
}

/// nsp_render's P1 (the flame in the smoke, no other light; Rgb, 16^3 grid majorant) as a
/// SurfaceScene, as nsp_room renders it; BDPT with its segment technique when kSegment.
template <class E, bool kSegment = true>
void BM_FlameSmoke(benchmark::State& state) {
    static const auto scene = [] {
        const nsp_examples::SceneChoice c{nsp_examples::SceneKind::Plume};
        return nsp_examples::make_setup_surface_scene<nsp::Rgb, nsp_examples::EmissivePlume,
                                                      nsp_examples::GridMajorantPolicy<>>(c);
    }();
    const E estimator = with_bdpt_depth<E>([](nsp::EstimatorOptions& o) { o.emission_along_segments = kSegment; });
    pinhole_samples(state, scene, estimator, [](const auto& pdfs) { return pdfs.kSegment; }, "segment/sample");
}

/// nsp_render's C1 (the chromatic cloud under a white sky; Rgb, per-channel 16^3 grid majorants) as
/// a SurfaceScene, as nsp_room renders it; BDPT at the counts its learner chooses there (NEE and
/// light subpaths on 1/64 of the samples), where tracking alone is the best technique.
template <class E>
void BM_ChromaticSky(benchmark::State& state) {
    static const auto scene = [] {
        const nsp_examples::SceneChoice c{nsp_examples::SceneKind::Chromatic, {}, nsp_examples::ChromaticSetup::Env};
        return nsp_examples::make_setup_surface_scene<nsp::Rgb, nsp_examples::DenseGridCloud,
                                                      nsp_examples::ChannelMajorantPolicy>(c);
    }();
    static const E estimator = [] {
        nsp::EstimatorOptions o = nsp::BdptEstimator<>::default_options();
        if constexpr (requires { E::kMaxPath; }) {
            o.nee_count = 1.f / 64.f;
            return E(o, {}, 1.f / 64.f);
        } else {
            return E(o);
        }
    }();
    pinhole_samples(state, scene, estimator, [](const auto&) { return 1; }, "nee/sample");
}

BENCHMARK_TEMPLATE(BM_ChromaticSky, nsp::SpectralPathEstimator<nsp::channels::SpectralMis, nsp::strategy::Unidirectional>)
    ->Name("BM_ChromaticSky/unidirectional:spectral-mis");
BENCHMARK_TEMPLATE(BM_ChromaticSky, nsp::SpectralBdptEstimator<nsp::mis::Balance>)
    ->Name("BM_ChromaticSky/bdpt-null-mis:spectral-mis+light-tracing:counts-1/64");
BENCHMARK_TEMPLATE(BM_FogLamp, nsp::PathEstimator<nsp::strategy::EquiangularMis, nsp::mis::Balance>)
    ->Name("BM_FogLamp/uni-nee-eq-mis:balance");
BENCHMARK_TEMPLATE(BM_FogLamp, nsp::BdptEstimator<nsp::bdpt::NullScattering>, false)
    ->Name("BM_FogLamp/bdpt-null-mis:balance+light-tracing");
BENCHMARK_TEMPLATE(BM_FogLamp, nsp::BdptEstimator<nsp::bdpt::NullScattering>, true)
    ->Name("BM_FogLamp/bdpt-null-mis:balance+light-tracing+equiangular");
BENCHMARK_TEMPLATE(BM_FlameSmoke, Nsmis)->Name("BM_FlameSmoke/uni-nee-mis:balance");
BENCHMARK_TEMPLATE(BM_FlameSmoke, nsp::BdptEstimator<nsp::bdpt::NullScattering>, false)
    ->Name("BM_FlameSmoke/bdpt-null-mis:balance+light-tracing");
BENCHMARK_TEMPLATE(BM_FlameSmoke, nsp::BdptEstimator<nsp::bdpt::NullScattering>, true)
    ->Name("BM_FlameSmoke/bdpt-null-mis:balance+light-tracing+segment");
BENCHMARK_TEMPLATE(BM_CloudUnderSky_Scene, Uni)->Name("BM_CloudUnderSky/Scene/unidirectional");
BENCHMARK_TEMPLATE(BM_CloudUnderSky_NoSurfaces, Uni)->Name("BM_CloudUnderSky/NoSurfaces/unidirectional");
BENCHMARK_TEMPLATE(BM_CloudUnderSky_Scene, Nsmis)->Name("BM_CloudUnderSky/Scene/uni-nee-mis:balance");
BENCHMARK_TEMPLATE(BM_CloudUnderSky_NoSurfaces, Nsmis)->Name("BM_CloudUnderSky/NoSurfaces/uni-nee-mis:balance");

}  // namespace
