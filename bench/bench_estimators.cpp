// bench/bench_estimators.cpp: one benchmark per path estimator x absorption policy x spectral
// mode x light set-up on the default (grey) scene: time per radiance() call (one sample) and
// density lookups per sample. Camera rays are pre-generated (fixtures.hpp) and cycled; Hero<4>
// draws each sample's wavelengths from the benchmark's generator.
//
// The 84 combinations are the Cartesian product of four type lists, registered by a fold at
// start-up (the BENCHMARK_TEMPLATE idea without 84 hand-written lines); names come from the
// policies' own `name`s: BM_Radiance/<strategy[:heuristic]>/<absorption>/<mode>/<set-up>.
// The timed loop counts with LookupCount (one integer increment per lookup); the BM_CountCost
// pair shows that this costs nothing measurable.
#include <string>

#include <benchmark/benchmark.h>

#include "fixtures.hpp"

namespace {

using namespace nsp_bench;

/// A path estimator's strategy and heuristic, as one type.
template <nsp::PathStrategy St, nsp::mis::Heuristic H = nsp::mis::None>
struct Kind {
    using Strategy = St;
    using Heuristic = H;
    static std::string name() {
        return H::combines ? std::string(St::name) + ":" + H::name : std::string(St::name);
    }
};

template <class... T>
struct List {};

using Kinds = List<Kind<nsp::strategy::Unidirectional>, Kind<nsp::strategy::NextEvent>,
                   Kind<nsp::strategy::DirectionalMis, nsp::mis::Balance>,
                   Kind<nsp::strategy::NullScatteringMis, nsp::mis::Balance>,
                   Kind<nsp::strategy::NullScatteringMis, nsp::mis::Power>,
                   Kind<nsp::strategy::EquiangularNextEvent>, Kind<nsp::strategy::EquiangularMis, nsp::mis::Balance>>;
using Absorptions = List<nsp::absorption::Event, nsp::absorption::Weight>;
using Modes = List<nsp::Mono, nsp::Rgb, Hero4>;

/// One radiance sample per iteration on the next camera ray; the generator runs on. In Mono and
/// Rgb the wavelength context is empty and no random number is drawn for it.
template <class K, nsp::AbsorptionPolicy A, nsp::SpectralMode S, nsp::LookupCounter C>
void BM_Radiance(benchmark::State& state, LightSetup setup) {
    const auto& scene = default_scene<S>(setup);
    const std::vector<nsp::Ray>& rays = camera_rays();
    const nsp::PathEstimator<typename K::Strategy, typename K::Heuristic, A> estimator;
    nsp::Pcg32 rng(6, 66);
    C counter;
    std::size_t i = 0;
    for (auto _ : state) {
        const auto lambda = draw_wavelengths<S>(rng);
        auto r = estimator.radiance(scene, rays[i], lambda, rng, counter);
        benchmark::DoNotOptimize(r);
        i = (i + 1) & kSetMask;
    }
    report_lookups(state, counter, "lookups/sample");
}

template <class K, class A, class S, class C = nsp::LookupCount>
void register_radiance(const std::string& prefix, const std::string& suffix = "") {
    for (LightSetup setup : {LightSetup::A, LightSetup::B}) {
        const std::string name = prefix + "/" + K::name() + "/" + A::name + "/" + S::name + "/" +
                                 nsp_examples::name(setup) + suffix;
        benchmark::RegisterBenchmark(name.c_str(), BM_Radiance<K, A, S, C>, setup)->MinTime(kMinTime);
    }
}

template <class K, class A, class... Ss>
void register_modes(List<Ss...>) { (register_radiance<K, A, Ss>("BM_Radiance"), ...); }
template <class K, class... As>
void register_absorptions(List<As...>) { (register_modes<K, As>(Modes{}), ...); }
template <class... Ks>
void register_kinds(List<Ks...>) { (register_absorptions<Ks>(Absorptions{}), ...); }

const bool registered = [] {
    register_kinds(Kinds{});
    // The cost of counting: one configuration without and with a counter.
    using NsMis = Kind<nsp::strategy::NullScatteringMis, nsp::mis::Balance>;
    register_radiance<NsMis, nsp::absorption::Weight, nsp::Rgb, nsp::NoLookupCount>("BM_CountCost", "/no-count");
    register_radiance<NsMis, nsp::absorption::Weight, nsp::Rgb, nsp::LookupCount>("BM_CountCost", "/count");
    return true;
}();

}  // namespace
