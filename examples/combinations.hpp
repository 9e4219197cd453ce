// examples/combinations.hpp: every valid combination of nsp's policies that the example renderer
// can run, as compile-time lists.
//
// The policy lists below are multiplied out (spectral mode x channel policy x majorant x strategy
// x heuristic x absorption x medium) and the combinations the library rejects with a
// static_assert are filtered out before any of them is named as an estimator, so adding a policy
// to a list is all it takes to render it. The channel policy `Grey` stands for nsp::PathEstimator
// (one pdf for every channel, the grey-majorant baseline); the others select
// nsp::SpectralPathEstimator with that channel policy. The medium is an axis too: the dense grid
// of most scenes, or the same grid with an emission grid (the plume scene).
#pragma once

#include <array>
#include <string>
#include <type_traits>

#include <nsp/nsp.hpp>

#include "default_scene.hpp"
#include "scene_choice.hpp"
#include "type_list.hpp"

namespace nsp_examples {

/// The medium of every scene but the plume: a density on a dense grid (the cloud with grey or
/// chromatic coefficients, the sparse plume and puffs, or the fog; the type is the same, so the
/// scene is a run-time choice).
struct DenseGridCloud {
    static constexpr const char* name = "dense-grid";
    static constexpr bool emissive = false;
    template <nsp::SpectralMode S>
    using type = nsp::DenseGridMedium<S>;
    template <nsp::SpectralMode S>
    static type<S> make(const SceneChoice& scene) {
        switch (scene.kind) {
            case SceneKind::Chromatic: return make_chromatic_medium<S>();
            case SceneKind::Sparse: return make_sparse_medium<S>();
            case SceneKind::Fog: return make_fog_medium<S>(scene.fog);
            default: return make_default_medium<S>();
        }
    }
};

/// The plume scene's medium: the smoke of make_plume_medium with its flame, nsp::Emissive over a
/// dense grid (a different type: PathEstimator compiles its emission code for it alone).
struct EmissivePlume {
    static constexpr const char* name = "emissive";
    static constexpr bool emissive = true;
    template <nsp::SpectralMode S>
    using type = nsp::Emissive<nsp::DenseGridMedium<S>>;
    template <nsp::SpectralMode S>
    static type<S> make(const SceneChoice&) {
        return make_plume_medium<S>();
    }
};

/// One of four names by bound policy B (the row names of the non-bounding majorants).
template <nsp::BoundPolicy B>
constexpr const char* bound_name(const char* guaranteed, const char* signed_, const char* clamp, const char* reject) {
    if constexpr (std::is_same_v<B, nsp::bound::Signed>) return signed_;
    else if constexpr (std::is_same_v<B, nsp::bound::Clamp>) return clamp;
    else if constexpr (std::is_same_v<B, nsp::bound::Reject>) return reject;
    else return guaranteed;
}

// Every majorant policy states `per_channel` (segment values per channel: only the spectral
// estimators with their own pdfs take it) and `bounding` (bound::Guaranteed; the others are
// given a deliberately low majorant, MajorantSettings::scale times the bound).

/// One constant grey majorant for the whole medium and every channel: under bound::Guaranteed the
/// tightest the grid allows; under the other bound policies `scale` times it.
template <nsp::BoundPolicy B = nsp::bound::Guaranteed>
struct GlobalMajorantPolicy {
    static constexpr const char* name = bound_name<B>("global", "global-signed", "global-clamp", "global-reject");
    static constexpr bool per_channel = false;
    static constexpr bool bounding = !B::allows_below;
    template <nsp::Medium M>
    using type = nsp::GlobalMajorant<M, B>;
    template <nsp::Medium M>
    static type<M> make(const M& medium, const MajorantSettings& s) {
        if constexpr (bounding) return (void)s, type<M>(medium);
        else return type<M>(medium, s.scale * medium.max_extinction());
    }
};

/// One constant majorant per channel, each channel's own extinction bound (THEORY 5.3).
struct ChannelMajorantPolicy {
    static constexpr const char* name = "per-channel";
    static constexpr bool per_channel = true;
    static constexpr bool bounding = true;
    template <nsp::Medium M>
    using type = nsp::ChannelMajorant<M>;
    template <nsp::Medium M>
    static type<M> make(const M& medium, const MajorantSettings&) { return type<M>(medium); }
};

/// A grey voxel-grid majorant of MajorantSettings::grid_res^3 cells walked by a DDA: it follows the
/// medium, so empty space costs DDA steps instead of null collisions. Non-bounding policies get
/// `scale` times each cell's bound.
template <nsp::BoundPolicy B = nsp::bound::Guaranteed>
struct GridMajorantPolicy {
    static constexpr const char* name = bound_name<B>("grid", "grid-signed", "grid-clamp", "grid-reject");
    static constexpr bool per_channel = false;
    static constexpr bool bounding = !B::allows_below;
    template <nsp::Medium M>
    using type = nsp::GridMajorant<M, B>;
    template <nsp::Medium M>
    static type<M> make(const M& medium, const MajorantSettings& s) {
        return type<M>(medium, s.grid_res, bounding ? 1.f : s.scale);
    }
};

/// A per-channel voxel-grid majorant: the grid's density bound times each channel's extinction
/// per unit density (THEORY 5.3 with a grid).
struct ChannelGridMajorantPolicy {
    static constexpr const char* name = "channel-grid";
    static constexpr bool per_channel = true;
    static constexpr bool bounding = true;
    template <nsp::Medium M>
    using type = nsp::ChannelGridMajorant<M>;
    template <nsp::Medium M>
    static type<M> make(const M& medium, const MajorantSettings& s) { return type<M>(medium, s.grid_res); }
};

/// A grey voxel-grid majorant with a control beside it (nsp::GridControl, THEORY 5.10): per cell the
/// medium's density bounds from above and below. PathEstimator tracks its segments by decomposition
/// tracking and its shadow rays by residual ratio tracking, paying lookups only for the residual
/// above each cell's minorant.
struct GridControlPolicy {
    static constexpr const char* name = "grid-control";
    static constexpr bool per_channel = false;
    static constexpr bool bounding = true;
    template <nsp::Medium M>
    using type = nsp::GridControl<M>;
    template <nsp::Medium M>
    static type<M> make(const M& medium, const MajorantSettings& s) { return type<M>(medium, s.grid_res); }
};

/// A per-channel voxel-grid majorant with a control beside it (nsp::ChannelGridControl, THEORY 5.10
/// with 5.3): the grid control's cells with each channel's own majorant d_max u_c and control
/// d_min u_c. SpectralPathEstimator's own-pdf channel policies (spectral MIS, independent tracking)
/// track each channel's own residual.
struct ChannelGridControlPolicy {
    static constexpr const char* name = "channel-grid-control";
    static constexpr bool per_channel = true;
    static constexpr bool bounding = true;
    template <nsp::Medium M>
    using type = nsp::ChannelGridControl<M>;
    template <nsp::Medium M>
    static type<M> make(const M& medium, const MajorantSettings& s) { return type<M>(medium, s.grid_res); }
};

/// The channel policy of nsp::PathEstimator: one pdf driven by the channel means, grey majorant.
struct Grey {
    static constexpr const char* name = "grey";
};

using SpectralModes = tl::list<nsp::Mono, nsp::Rgb, Hero4>;
using ChannelPolicies = tl::list<Grey, nsp::channels::Independent, nsp::channels::SpectralTrackingMax,
                                 nsp::channels::SpectralTrackingAverage, nsp::channels::SpectralMis>;
using Majorants = tl::list<GlobalMajorantPolicy<>, ChannelMajorantPolicy, GridMajorantPolicy<>, ChannelGridMajorantPolicy,
                           GlobalMajorantPolicy<nsp::bound::Signed>, GlobalMajorantPolicy<nsp::bound::Clamp>,
                           GridMajorantPolicy<nsp::bound::Signed>, GridMajorantPolicy<nsp::bound::Clamp>,
                           GridControlPolicy, ChannelGridControlPolicy>;
using Strategies = tl::list<nsp::strategy::Unidirectional, nsp::strategy::NextEvent,
                            nsp::strategy::DirectionalMis, nsp::strategy::NullScatteringMis,
                            nsp::strategy::EquiangularNextEvent, nsp::strategy::EquiangularMis>;
using Heuristics = tl::list<nsp::mis::None, nsp::mis::Balance, nsp::mis::Power>;
using Absorptions = tl::list<nsp::absorption::Event, nsp::absorption::Weight>;
using MediumKinds = tl::list<DenseGridCloud, EmissivePlume>;

/// The library's static_asserts as a predicate on a point of the product, evaluated on the policy
/// tags alone (nothing is instantiated for an invalid point):
/// - PathEstimator (Grey): a grey majorant (global or grid); MIS strategies take a combining
///   heuristic, single strategies mis::None;
/// - SpectralPathEstimator: a multi-channel mode; spectral tracking (one shared pdf) with a grey
///   majorant only (the library's static_assert); no DirectionalMis; mis::None for single
///   strategies, mis::Balance for NullScatteringMis and EquiangularMis.
/// and choices of the examples, not the library's:
/// - independent tracking only with a per-channel majorant (per-channel or channel-grid; with a
///   grey one it is spectral tracking's sampling without its shared weights: every channel's free
///   flight is the same, only the event probabilities differ, and it is not a baseline anyone
///   uses). Spectral MIS takes every bounding majorant: per-channel ones (each channel's own tight
///   free-flight density; on the chromatic cloud, extinction 1 : 4 : 16, the channels' pdfs
///   barely overlap and MIS gains little over independent tracking) or grey ones (one shared
///   free-flight density and per-channel event probabilities, so every channel's pdf is large
///   where the others' are and the balance heuristic actually combines them).
/// - the build: every point costs nsp_render about 1.5 s of compile time (-O3), and the full
///   product of the eight majorants has 288 points against 96 with the first two. So the new
///   majorants (grid, channel-grid and the non-bounding ones) come with absorption::Weight only
///   (the absorb-event rows answer nothing about majorants that the absorb-weight ones do not),
///   and the non-bounding ones (bound::Signed, Clamp) with PathEstimator in Mono only (what a low
///   majorant costs in variance or bias is a question the grey medium answers).
/// - the equiangular strategies (EquiangularNextEvent, EquiangularMis) with PathEstimator in Mono
///   only: the fog that shows them is grey, PathEstimator's cost per mode is the benchmarks'
///   business, and SpectralPathEstimator's equiangular rows (15 channel-policy x majorant pairs x
///   2 strategies per mode) would add some 60 points for no table; the tests cover them. In Mono
///   they take both absorption policies with the grid majorant as well as the global one (every
///   strategy x heuristic x {global, grid} x absorption compiles), and the non-bounding majorants
///   with absorb-weight, as every grey strategy does.
/// - the emissive medium (the plume) with PathEstimator in Rgb only (a flame-coloured emission),
///   with the bounding grey majorants (global, grid), absorb-weight, and the four strategies
///   without equiangular sampling (the plume has no point or sphere light for it to aim at). The
///   smoke is grey, so SpectralPathEstimator's emission rows would repeat PathEstimator's at about
///   twice the cost per sample; the tests cover them.
/// - the grid control (GridControlPolicy) with PathEstimator in Mono and Rgb (the plume: Rgb, as
///   its other rows; the equiangular strategies: Mono, as under the other majorants), absorb-weight:
///   what PathEstimator takes under a control, without the Hero<4> points the grey axis does not need;
///   and with SpectralPathEstimator in Rgb on the cloud (spectral MIS and spectral tracking, which
///   take a grey majorant; no equiangular or emissive points, as under the other majorants). The
///   channel grid control (ChannelGridControlPolicy) likewise with spectral MIS and independent
///   tracking (the own-pdf policies it takes) in Rgb on the cloud, absorb-weight.
template <class Tuple>
struct is_valid;
template <class S, class CP, class Maj, class St, class H, class A, class Med>
struct is_valid<tl::list<S, CP, Maj, St, H, A, Med>> {
    static constexpr bool grey = std::is_same_v<CP, Grey>;
    static constexpr bool weight = std::is_same_v<A, nsp::absorption::Weight>;
    static constexpr bool heuristic_fits =
        St::combines ? (grey ? H::combines : std::is_same_v<H, nsp::mis::Balance>) : !H::combines;
    static constexpr bool majorant_fits = [] {
        constexpr bool first = std::is_same_v<Maj, GlobalMajorantPolicy<>> || std::is_same_v<Maj, ChannelMajorantPolicy>;
        constexpr bool both_absorptions = first || (St::equiangular && std::is_same_v<Maj, GridMajorantPolicy<>>);
        if constexpr (!both_absorptions && !weight) return false;
        else if constexpr (grey) return !Maj::per_channel && (Maj::bounding || S::channels == 1);
        else if constexpr (!Maj::bounding) return false;
        else if constexpr (!CP::own_pdfs) return !Maj::per_channel;
        else if constexpr (!CP::mis_over_channels) return Maj::per_channel;
        else return true;
    }();
    static constexpr bool estimator_fits = grey || (S::channels > 1 && (St::null_pdfs || !St::combines));
    static constexpr bool build_fits = [] {
        if constexpr (std::is_same_v<Maj, ChannelGridControlPolicy>)
            return !grey && weight && std::is_same_v<S, nsp::Rgb> && !Med::emissive && !St::equiangular;
        else if constexpr (std::is_same_v<Maj, GridControlPolicy>) {
            if constexpr (!grey)  // spectral MIS and spectral tracking on the cloud, in Rgb
                return weight && std::is_same_v<S, nsp::Rgb> && !Med::emissive && !St::equiangular;
            else
                return weight && S::channels <= 3 && !nsp::is_hero_v<S> &&
                       (St::equiangular ? std::is_same_v<S, nsp::Mono> && !Med::emissive
                                        : !Med::emissive || std::is_same_v<S, nsp::Rgb>);
        }
        else if constexpr (Med::emissive)
            return grey && std::is_same_v<S, nsp::Rgb> && Maj::bounding && weight && !St::equiangular;
        else if constexpr (St::equiangular) return grey && std::is_same_v<S, nsp::Mono>;
        else return true;
    }();
    static constexpr bool value = heuristic_fits && majorant_fits && estimator_fits && build_fits;
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

    /// True for rows that combine NEE with tracking under the balance heuristic (PathEstimator and
    /// SpectralPathEstimator): the rows whose NEE count nsp::NeeCountLearner can learn
    /// (render_job_impl.hpp, "_learned").
    static constexpr bool learns_nee_count =
        St::combines && St::samples_lights && std::is_same_v<H, nsp::mis::Balance>;

    /// True for the grey estimator with the plain global majorant (the rows of the first tables).
    static constexpr bool plain_global = !spectral && std::is_same_v<Maj, GlobalMajorantPolicy<>>;

    /// Grey rows with the global majorant keep the names of the existing tables:
    /// "uni-nee-mis_balance_absorb-weight" ("unidirectional_absorb-event" for single strategies);
    /// other grey rows add the majorant: "uni-nee-mis_grid_balance_absorb-weight". Spectral rows
    /// add the channel policy and the majorant:
    /// "uni-nee-mis_spectral-mis_per-channel_balance_absorb-weight".
    static std::string name() {
        std::string n = St::name;
        if constexpr (spectral) n += std::string("_") + CP::name + "_" + Maj::name;
        else if constexpr (!plain_global) n += std::string("_") + Maj::name;
        if constexpr (H::combines) n += std::string("_") + H::name;
        return n + "_" + A::name;
    }
};

/// Every valid combination of spectral mode S, in the order of the policy lists.
template <class S>
using CombinationsOf = tl::transform<
    Combination, tl::filtered_product<is_valid, tl::list<S>, ChannelPolicies, Majorants, Strategies, Heuristics,
                                      Absorptions, MediumKinds>>;

// Grey: Unidirectional, NextEvent with None; two MIS strategies with Balance and Power: 6 per
// absorption policy; with the global majorant both policies, with grid in every mode and the four
// non-bounding ones (global and grid, signed and clamp) in Mono absorb-weight only. In Mono the
// equiangular strategies add 3 (EquiangularNextEvent; EquiangularMis with Balance and Power) to
// each of these, and 3 more with grid and absorb-event. Spectral, in Rgb and Hero:
// (Unidirectional, NextEvent, NullScatteringMis with Balance) with 5 (channel policy, majorant)
// pairs of the first two majorants x 2 absorption policies (independent per-channel, spectral
// tracking max and average global, spectral MIS per-channel and global), and 5 pairs with the grid
// majorants x absorb-weight (independent channel-grid, spectral tracking max and average grid,
// spectral MIS grid and channel-grid). The emissive medium, in Rgb: the 6 grey rows with global and
// grid, absorb-weight. The grid control, absorb-weight: in Mono the 9 grey rows, in Rgb the 6
// without equiangular sampling, 6 more on the emissive medium, and 3 channel policies (spectral
// tracking max and average, spectral MIS) x the 3 spectral strategies. The channel grid control,
// absorb-weight, in Rgb: 2 channel policies (independent, spectral MIS) x the 3 spectral strategies.
static_assert(tl::size<CombinationsOf<nsp::Mono>> == 9 * 2 + (9 + 3) + 9 * 4 + 9);
static_assert(tl::size<CombinationsOf<nsp::Rgb>> == 6 * 2 + 6 + 5 * 3 * 2 + 5 * 3 + 6 * 3 + 6 + 3 * 3 + 2 * 3);
static_assert(tl::size<CombinationsOf<Hero4>> == 6 * 2 + 6 + 5 * 3 * 2 + 5 * 3);

/// What the driver knows of one combination at run time: its names and traits as plain data, so
/// that planning and --list loop over an array instead of instantiating code per combination
/// (which costs compile time for nothing).
struct CombinationInfo {
    const char* mode;
    const char* channels;
    const char* majorant;
    const char* strategy;
    const char* heuristic;
    const char* absorption;
    const char* medium;
    bool spectral;              ///< SpectralPathEstimator
    bool plain_global;          ///< PathEstimator with the plain global majorant (names without majorant)
    bool uses_selection;        ///< see Combination::uses_selection
    bool bounding;              ///< the majorant bounds the extinction (bound::Guaranteed)
    bool per_channel_majorant;  ///< per-channel or channel-grid
    bool emissive;              ///< the medium emits (the plume's): only the plume scene renders it
    bool learns_nee_count;      ///< see Combination::learns_nee_count
    std::string (*name)();      ///< Combination::name
};

namespace detail {
template <class L>
struct infos_of;
template <class... Cs>
struct infos_of<tl::list<Cs...>> {
    static constexpr std::array<CombinationInfo, sizeof...(Cs)> value{CombinationInfo{
        Cs::Spectral::name, Cs::ChannelPolicy::name, Cs::MajorantKind::name, Cs::Strategy::name, Cs::Heuristic::name,
        Cs::Absorption::name, Cs::MediumKind::name, Cs::spectral, Cs::plain_global, Cs::uses_selection,
        Cs::MajorantKind::bounding, Cs::MajorantKind::per_channel, Cs::MediumKind::emissive, Cs::learns_nee_count,
        &Cs::name}...};
};
}  // namespace detail

/// The run-time descriptions of CombinationsOf<S>, in order (element i is combination index i).
template <class S>
constexpr const auto& combination_infos() {
    return detail::infos_of<CombinationsOf<S>>::value;
}

}  // namespace nsp_examples
