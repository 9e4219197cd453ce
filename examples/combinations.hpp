// examples/combinations.hpp: every valid combination of nsp's policies that the example renderer
// can run, as one compile-time list.
//
// The policy lists below are multiplied out (spectral mode x strategy x heuristic x absorption x
// majorant x medium) and the combinations PathEstimator rejects with a static_assert are
// filtered out, so adding a policy to a list is all it takes to render it.
#pragma once

#include <string>

#include <nsp/nsp.hpp>

#include "default_scene.hpp"
#include "type_list.hpp"

namespace nsp_examples {

/// The medium of the default scene: the procedural cloud on a dense grid.
struct DenseGridCloud {
    static constexpr const char* name = "dense-grid";
    template <nsp::SpectralMode S>
    using type = nsp::DenseGridMedium<S>;
    template <nsp::SpectralMode S>
    static type<S> make() { return make_default_medium<S>(); }
};

/// One constant majorant for the whole medium (the tightest the grid allows).
struct GlobalMajorantPolicy {
    static constexpr const char* name = "global";
    template <nsp::Medium M>
    using type = nsp::GlobalMajorant<M>;
    template <nsp::Medium M>
    static type<M> make(const M& medium) { return type<M>(medium); }
};

using SpectralModes = tl::list<nsp::Mono, nsp::Rgb>;
using Strategies = tl::list<nsp::strategy::Unidirectional, nsp::strategy::NextEvent,
                            nsp::strategy::DirectionalMis, nsp::strategy::NullScatteringMis>;
using Heuristics = tl::list<nsp::mis::None, nsp::mis::Balance, nsp::mis::Power>;
using Absorptions = tl::list<nsp::absorption::Event, nsp::absorption::Weight>;
using Majorants = tl::list<GlobalMajorantPolicy>;
using MediumKinds = tl::list<DenseGridCloud>;

/// One point of the product: the types a render needs, and its names.
template <class Tuple>
struct Combination;
template <class S, class St, class H, class A, class Maj, class Med>
struct Combination<tl::list<S, St, H, A, Maj, Med>> {
    using Spectral = S;
    using Strategy = St;
    using Heuristic = H;
    using Absorption = A;
    using MajorantKind = Maj;
    using MediumKind = Med;
    using Medium = typename Med::template type<S>;
    using Majorant = typename Maj::template type<Medium>;
    using Scene = nsp::Scene<Medium, Majorant, nsp::HenyeyGreensteinPhase>;
    /// Naming the specialisation does not instantiate it; only valid combinations construct one.
    using Estimator = nsp::PathEstimator<St, H, A>;

    /// PathEstimator's static_asserts as a predicate: MIS strategies take a combining
    /// heuristic, single strategies take mis::None.
    static constexpr bool valid = St::combines == H::combines;

    /// "uni-nee-mis_balance_absorb-weight" ("unidirectional_absorb-event" for single strategies).
    static std::string name() {
        std::string n = St::name;
        if constexpr (H::combines) n += std::string("_") + H::name;
        return n + "_" + A::name;
    }
};

template <class C>
struct is_valid : std::bool_constant<C::valid> {};

/// Every valid combination, in the order of the policy lists.
using AllCombinations = tl::filter<
    is_valid, tl::transform<Combination, tl::product<SpectralModes, Strategies, Heuristics, Absorptions,
                                                    Majorants, MediumKinds>>>;

// 2 spectral modes x (Unidirectional, NextEvent with None; two MIS strategies with Balance and
// Power) x 2 absorption policies x 1 majorant x 1 medium.
static_assert(tl::size<AllCombinations> == 2 * (2 + 2 * 2) * 2);

}  // namespace nsp_examples
