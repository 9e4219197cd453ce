// examples/combinations.hpp: every valid combination of nsp's policies that the example renderer
// can run, as compile-time lists.
//
// The policy lists below are multiplied out (spectral mode x channel policy x majorant x strategy
// x heuristic x absorption x medium) and the combinations the library rejects with a
// static_assert are filtered out before any of them is named as an estimator, so adding a policy
// to a list is all it takes to render it. The channel policy `Grey` stands for nsp::PathEstimator
// (one pdf for every channel, the grey-majorant baseline); the others select
// nsp::SpectralPathEstimator with that channel policy.
#pragma once

#include <string>
#include <type_traits>

#include <nsp/nsp.hpp>

#include "default_scene.hpp"
#include "type_list.hpp"

namespace nsp_examples {

/// Which of the two scenes of default_scene.hpp a render uses.
enum class SceneKind {
    Cloud,      ///< the grey cloud (set-ups A, B)
    Chromatic,  ///< the chromatic cloud, extinction 1 : 4 : 16 (set-ups C1, C2)
};

/// The medium of both scenes: the procedural cloud on a dense grid (grey or chromatic
/// coefficients; the type is the same, so the scene is a run-time choice).
struct DenseGridCloud {
    static constexpr const char* name = "dense-grid";
    template <nsp::SpectralMode S>
    using type = nsp::DenseGridMedium<S>;
    template <nsp::SpectralMode S>
    static type<S> make(SceneKind scene) {
        return scene == SceneKind::Cloud ? make_default_medium<S>() : make_chromatic_medium<S>();
    }
};

/// One constant grey majorant for the whole medium and every channel (the tightest the grid allows).
struct GlobalMajorantPolicy {
    static constexpr const char* name = "global";
    template <nsp::Medium M>
    using type = nsp::GlobalMajorant<M>;
    template <nsp::Medium M>
    static type<M> make(const M& medium) { return type<M>(medium); }
};

/// One constant majorant per channel, each channel's own extinction bound (THEORY 5.3).
struct ChannelMajorantPolicy {
    static constexpr const char* name = "per-channel";
    template <nsp::Medium M>
    using type = nsp::ChannelMajorant<M>;
    template <nsp::Medium M>
    static type<M> make(const M& medium) { return type<M>(medium); }
};

/// The channel policy of nsp::PathEstimator: one pdf driven by the channel means, grey majorant.
struct Grey {
    static constexpr const char* name = "grey";
};

/// Hero wavelengths, four per path.
using Hero4 = nsp::Hero<4>;

using SpectralModes = tl::list<nsp::Mono, nsp::Rgb, Hero4>;
using ChannelPolicies = tl::list<Grey, nsp::channels::Independent, nsp::channels::SpectralTrackingMax,
                                 nsp::channels::SpectralTrackingAverage, nsp::channels::SpectralMis>;
using Majorants = tl::list<GlobalMajorantPolicy, ChannelMajorantPolicy>;
using Strategies = tl::list<nsp::strategy::Unidirectional, nsp::strategy::NextEvent,
                            nsp::strategy::DirectionalMis, nsp::strategy::NullScatteringMis>;
using Heuristics = tl::list<nsp::mis::None, nsp::mis::Balance, nsp::mis::Power>;
using Absorptions = tl::list<nsp::absorption::Event, nsp::absorption::Weight>;
using MediumKinds = tl::list<DenseGridCloud>;

/// The library's static_asserts as a predicate on a point of the product, evaluated on the policy
/// tags alone (nothing is instantiated for an invalid point):
/// - PathEstimator (Grey): the grey majorant; MIS strategies take a combining heuristic, single
///   strategies mis::None;
/// - SpectralPathEstimator: a multi-channel mode; spectral tracking (one shared pdf) with the grey
///   majorant only (the library's static_assert); no DirectionalMis; mis::None for single
///   strategies, mis::Balance for NullScatteringMis.
/// and one choice of the examples, not the library's: independent tracking only with the
/// per-channel majorant (with the grey one it is spectral tracking's sampling without its
/// shared weights: every channel's free flight is the same, only the event probabilities differ,
/// and it is not a baseline anyone uses). Spectral MIS takes either majorant: per-channel (each
/// channel's own tight free-flight density; on the chromatic cloud, extinction 1 : 4 : 16, the
/// channels' pdfs barely overlap and MIS gains little over independent tracking) or global (one
/// shared free-flight density and per-channel event probabilities, so every channel's pdf is
/// large where the others' are and the balance heuristic actually combines them).
template <class Tuple>
struct is_valid;
template <class S, class CP, class Maj, class St, class H, class A, class Med>
struct is_valid<tl::list<S, CP, Maj, St, H, A, Med>> {
    static constexpr bool grey = std::is_same_v<CP, Grey>;
    static constexpr bool heuristic_fits =
        St::combines ? (grey ? H::combines : std::is_same_v<H, nsp::mis::Balance>) : !H::combines;
    static constexpr bool majorant_fits = [] {
        if constexpr (grey) return std::is_same_v<Maj, GlobalMajorantPolicy>;
        else if constexpr (!CP::own_pdfs) return std::is_same_v<Maj, GlobalMajorantPolicy>;
        else if constexpr (!CP::mis_over_channels) return std::is_same_v<Maj, ChannelMajorantPolicy>;
        else return true;
    }();
    static constexpr bool value = heuristic_fits && majorant_fits &&
                                  (grey || (S::channels > 1 && (St::null_pdfs || !St::combines)));
};

/// The estimator type of a combination (lazily, so that Grey is never passed to SpectralPathEstimator).
template <class CP, class St, class H, class A>
struct EstimatorFor {
    using type = nsp::SpectralPathEstimator<CP, St, H, A>;
};
template <class St, class H, class A>
struct EstimatorFor<Grey, St, H, A> {
    using type = nsp::PathEstimator<St, H, A>;
};

/// One valid point of the product: the types a render needs, and its names.
template <class Tuple>
struct Combination;
template <class S, class CP, class Maj, class St, class H, class A, class Med>
struct Combination<tl::list<S, CP, Maj, St, H, A, Med>> {
    using Spectral = S;
    using ChannelPolicy = CP;
    using MajorantKind = Maj;
    using Strategy = St;
    using Heuristic = H;
    using Absorption = A;
    using MediumKind = Med;
    using Medium = typename Med::template type<S>;
    using Majorant = typename Maj::template type<Medium>;
    using Scene = nsp::Scene<Medium, Majorant, nsp::HenyeyGreensteinPhase>;
    using Estimator = typename EstimatorFor<CP, St, H, A>::type;

    /// True for nsp::SpectralPathEstimator (it takes a ChannelSelection).
    static constexpr bool spectral = !std::is_same_v<CP, Grey>;
    /// True when the channel selection probabilities change the estimator (not for spectral
    /// tracking, whose one shared pdf makes the sampling channel irrelevant, nor for Grey).
    static constexpr bool uses_selection = [] {
        if constexpr (spectral) return CP::own_pdfs;
        else return false;
    }();

    /// Grey rows keep the names of the existing tables: "uni-nee-mis_balance_absorb-weight"
    /// ("unidirectional_absorb-event" for single strategies). Spectral rows add the channel
    /// policy and the majorant: "uni-nee-mis_spectral-mis_per-channel_balance_absorb-weight".
    static std::string name() {
        std::string n = St::name;
        if constexpr (spectral) n += std::string("_") + CP::name + "_" + Maj::name;
        if constexpr (H::combines) n += std::string("_") + H::name;
        return n + "_" + A::name;
    }
};

/// Every valid combination of spectral mode S, in the order of the policy lists.
template <class S>
using CombinationsOf = tl::transform<
    Combination, tl::filter<is_valid, tl::product<tl::list<S>, ChannelPolicies, Majorants, Strategies, Heuristics,
                                                  Absorptions, MediumKinds>>>;

// Grey: (Unidirectional, NextEvent with None; two MIS strategies with Balance and Power) x 2
// absorption policies, in every mode. Spectral: 5 (channel policy, majorant) pairs (independent
// per-channel, spectral tracking max and average global, spectral MIS per-channel and global) x
// (Unidirectional, NextEvent, NullScatteringMis with Balance) x 2 absorption policies, in Rgb and Hero.
static_assert(tl::size<CombinationsOf<nsp::Mono>> == (2 + 2 * 2) * 2);
static_assert(tl::size<CombinationsOf<nsp::Rgb>> == (2 + 2 * 2) * 2 + 5 * 3 * 2);
static_assert(tl::size<CombinationsOf<Hero4>> == (2 + 2 * 2) * 2 + 5 * 3 * 2);

}  // namespace nsp_examples
