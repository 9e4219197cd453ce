// bench/bench_spectral.cpp: the spectral path estimators (estimators/path.hpp with the per-channel path state), time per
// sample and density lookups per sample.
//
// Chromatic scene (examples/default_scene.hpp: the default cloud with extinction 1 : 4 : 16 in
// R : G : B, albedo 0.95), both set-ups (C1: white environment, C2: set-up A's small bright
// sphere), Rgb and Hero<4>: every channel policy (independent, spectral tracking max / average,
// spectral MIS) x every strategy (unidirectional, ratio NEE, uni + NEE MIS with the balance
// heuristic), absorb-weight, plus the grey-majorant baseline: the grey PathEstimator (uni + NEE
// MIS, balance) under one GlobalMajorant. Spectral tracking and the baseline run under the grey
// GlobalMajorant (the largest extinction over all channels); independent tracking and spectral
// MIS under the per-channel ChannelMajorant, as the library requires.
//
// Grey cloud (set-ups A and B): spectral MIS with ChannelMajorant in Rgb and Hero<4>, to compare
// with the grey estimators of bench_estimators.cpp in Mono (what spectral MIS costs on a medium
// that does not need it).
//
// Names: BM_Spectral/<channel policy>/<strategy[:heuristic]>/<mode>/<scene>, scene C1, C2, A, B;
// the baseline's channel policy is "grey-majorant". Camera rays are those of bench_estimators.cpp
// (they cross the cloud, whose density grid both scenes share). The sampling channel is chosen
// uniformly per sample (one random number), Hero wavelengths are drawn per sample from the
// benchmark's generator (one more).
#include <array>
#include <string>
#include <type_traits>
#include <utility>

#include <benchmark/benchmark.h>

#include "fixtures.hpp"

namespace {

using namespace nsp_bench;
using nsp_examples::ChromaticSetup;

/// The scenes of this file.
enum class SceneId { A, B, C1, C2 };

const char* name(SceneId id) {
    constexpr std::array<const char*, 4> names{"A", "B", "C1", "C2"};
    return names[std::size_t(id)];
}

/// The scene `id` in mode S under majorant policy GlobalMajorant (kPerChannel false) or
/// ChannelMajorant (true): the grey cloud in set-up A or B, or the chromatic cloud in set-up C1
/// or C2. Each of the four is built once per process, outside the timed loops.
template <nsp::SpectralMode S, bool kPerChannel>
const auto& scene(SceneId id) {
    using M = nsp::DenseGridMedium<S>;
    using Maj = std::conditional_t<kPerChannel, nsp::ChannelMajorant<M>, nsp::GlobalMajorant<M>>;
    using Sc = nsp::Scene<M, Maj, nsp::HenyeyGreensteinPhase>;
    auto make = [](SceneId s) {
        const bool grey = s == SceneId::A || s == SceneId::B;
        M medium = grey ? nsp_examples::make_default_medium<S>() : nsp_examples::make_chromatic_medium<S>();
        const Maj majorant(medium);  // holds values, not a reference: the medium may move
        nsp::Lights<S> lights =
            grey ? nsp_examples::default_lights<S>(s == SceneId::A ? LightSetup::A : LightSetup::B)
                 : nsp_examples::chromatic_lights<S>(s == SceneId::C1 ? ChromaticSetup::Env : ChromaticSetup::Small);
        return Sc(std::move(medium), majorant, nsp::HenyeyGreensteinPhase(nsp_examples::kPhaseG), std::move(lights));
    };
    static const std::array<Sc, 4> scenes{make(SceneId::A), make(SceneId::B), make(SceneId::C1), make(SceneId::C2)};
    return scenes[std::size_t(id)];
}

/// The heuristic a strategy takes in SpectralPathEstimator: balance to combine, none otherwise.
template <nsp::PathStrategy St>
using HeuristicFor = std::conditional_t<St::combines, nsp::mis::Balance, nsp::mis::None>;

/// A strategy's table name: "uni-nee-mis:balance" when it combines, else the strategy's name.
template <nsp::PathStrategy St>
std::string strategy_name() {
    using H = HeuristicFor<St>;
    return H::combines ? std::string(St::name) + ":" + H::name : std::string(St::name);
}

/// A benchmarked spectral estimator: channel policy CP, strategy St, absorb-weight, with the
/// majorant policy its channel policy needs.
template <nsp::ChannelPolicy CP, nsp::PathStrategy St>
struct SpectralEntry {
    using Estimator = nsp::SpectralPathEstimator<CP, St, HeuristicFor<St>, nsp::absorption::Weight>;
    static constexpr bool per_channel = CP::own_pdfs;
    static std::string name() { return std::string(CP::name) + "/" + strategy_name<St>(); }
};

/// The grey-majorant baseline: one pdf for all channels (the channel means drive the events).
struct GreyBaseline {
    using Estimator = nsp::PathEstimator<nsp::strategy::NullScatteringMis, nsp::mis::Balance, nsp::absorption::Weight>;
    static constexpr bool per_channel = false;
    static std::string name() { return "grey-majorant/" + strategy_name<nsp::strategy::NullScatteringMis>(); }
};

/// One radiance sample per iteration on the next camera ray; the generator runs on.
template <class E, nsp::SpectralMode S>
void BM_Spectral(benchmark::State& state, SceneId id) {
    const auto& sc = scene<S, E::per_channel>(id);
    const std::vector<nsp::Ray>& rays = camera_rays();
    const typename E::Estimator estimator;
    nsp::Pcg32 rng(8, 88);
    nsp::LookupCount counter;
    std::size_t i = 0;
    for (auto _ : state) {
        const auto lambda = draw_wavelengths<S>(rng);
        auto r = estimator.radiance(sc, rays[i], lambda, rng, counter);
        benchmark::DoNotOptimize(r);
        i = (i + 1) & kSetMask;
    }
    report_lookups(state, counter, "lookups/sample");
}

template <class... T>
struct List {};

using Policies = List<nsp::channels::Independent, nsp::channels::SpectralTrackingMax,
                      nsp::channels::SpectralTrackingAverage, nsp::channels::SpectralMis>;
using Strategies = List<nsp::strategy::Unidirectional, nsp::strategy::NextEvent, nsp::strategy::NullScatteringMis>;

template <class E, class S>
void register_one(std::initializer_list<SceneId> ids) {
    for (SceneId id : ids) {
        const std::string n = "BM_Spectral/" + E::name() + "/" + S::name + "/" + name(id);
        benchmark::RegisterBenchmark(n.c_str(), BM_Spectral<E, S>, id)->MinTime(kMinTime);
    }
}

/// Every entry on the chromatic scene, Rgb then Hero<4>.
template <class E>
void register_chromatic() {
    register_one<E, nsp::Rgb>({SceneId::C1, SceneId::C2});
    register_one<E, Hero4>({SceneId::C1, SceneId::C2});
}
template <class CP, class... Sts>
void register_strategies(List<Sts...>) { (register_chromatic<SpectralEntry<CP, Sts>>(), ...); }
template <class... CPs>
void register_policies(List<CPs...>) { (register_strategies<CPs>(Strategies{}), ...); }

const bool registered = [] {
    register_policies(Policies{});
    register_chromatic<GreyBaseline>();
    // Spectral MIS on the grey cloud: what per-channel bookkeeping costs where it is not needed.
    using GreySpectralMis = SpectralEntry<nsp::channels::SpectralMis, nsp::strategy::NullScatteringMis>;
    register_one<GreySpectralMis, nsp::Rgb>({SceneId::A, SceneId::B});
    register_one<GreySpectralMis, Hero4>({SceneId::A, SceneId::B});
    return true;
}();

}  // namespace
