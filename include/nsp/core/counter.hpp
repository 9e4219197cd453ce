// nsp/core/counter.hpp: density-lookup counters, the currency of efficiency (THEORY 7).
//
// Kernels call `counter.lookup()` once per evaluation of a medium's coefficients. With
// NoLookupCount the call is an empty inline function and compiles to nothing.
#pragma once

#include <concepts>
#include <cstdint>

namespace nsp {

/// A lookup counter: `lookup()` records one density lookup.
template <class C>
concept LookupCounter = requires(C& c) {
    { c.lookup() } noexcept;
    { C::enabled } -> std::convertible_to<bool>;
};

/// A grid majorant's DDA step's cost in density lookups, for the cost models that weigh both
/// (majorants/choose.hpp, counts.hpp): a step about 20 ns, a tracked trilinear lookup about 60 ns
/// on the 2-core CI machine (docs/majorants.md).
inline constexpr float kDdaStepCost = 0.3f;

/// Counts nothing and costs nothing.
struct NoLookupCount {
    static constexpr bool enabled = false;
    void lookup() noexcept {}
    std::uint64_t count() const noexcept { return 0; }
};

/// Counts lookups in a plain integer (one per thread; sum them afterwards), and the DDA steps of
/// grid majorants (free_flight reports them to any counter with `majorant_steps`).
struct LookupCount {
    static constexpr bool enabled = true;
    std::uint64_t n = 0;
    std::uint64_t steps = 0;  ///< grid-majorant cells crossed (DDA steps), skipped empty ones included
    void lookup() noexcept { ++n; }
    void majorant_steps(std::uint64_t k) noexcept { steps += k; }
    std::uint64_t count() const noexcept { return n; }
};

static_assert(LookupCounter<NoLookupCount> && LookupCounter<LookupCount>);

}  // namespace nsp
