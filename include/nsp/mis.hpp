// nsp/mis.hpp: MIS heuristics, evaluated on pdf ratios only (THEORY 5.1, STYLE rule 7).
//
// A heuristic weighs the strategy that produced a path against the other strategy from the
// ratio r = p_other / p_this of their pdfs for that path, so absolute path pdfs, which underflow
// on long paths, are never formed.
#pragma once

#include <cmath>
#include <concepts>

#include "core/error.hpp"

namespace nsp::mis {

/// No MIS: the estimator uses one strategy alone. Only single-strategy estimators accept it.
struct None {
    static constexpr bool combines = false;
    static constexpr const char* name = "none";
};

/// The balance heuristic (Veach 1997): w = p_this / (p_this + p_other) = 1 / (1 + r).
struct Balance {
    static constexpr bool combines = true;
    static constexpr const char* name = "balance";
    /// Weight of the sampling strategy given r = p_other / p_this >= 0 (r = inf gives 0).
    float weight(float r) const noexcept { return r < kHuge ? 1.f / (1.f + r) : 0.f; }
    static constexpr float kHuge = 1e30f;
};

/// The power heuristic with exponent beta: w = 1 / (1 + r^beta).
class Power {
public:
    static constexpr bool combines = true;
    static constexpr const char* name = "power";

    /// Throws InvalidArgument unless beta is finite and > 0 (beta = 1 is the balance heuristic).
    explicit Power(float beta = 2.f) : beta_(beta) {
        if (!std::isfinite(beta) || !(beta > 0.f))
            detail::fail("mis::Power exponent = ", beta, " is not allowed: it must be finite and > 0");
    }
    float beta() const noexcept { return beta_; }

    /// Weight of the sampling strategy given r = p_other / p_this >= 0 (r = inf gives 0).
    float weight(float r) const noexcept {
        const float rb = std::pow(r, beta_);
        return rb < Balance::kHuge ? 1.f / (1.f + rb) : 0.f;
    }

private:
    float beta_;
};

/// A heuristic that combines strategies: `weight(r)` in [0, 1], with weight(r) + weight(1/r) = 1.
template <class H>
concept CombiningHeuristic = H::combines && requires(const H& h, float r) {
    { h.weight(r) } -> std::same_as<float>;
};

/// Any heuristic policy, including None.
template <class H>
concept Heuristic = requires {
    { H::combines } -> std::convertible_to<bool>;
    { H::name } -> std::convertible_to<const char*>;
};

static_assert(CombiningHeuristic<Balance> && CombiningHeuristic<Power> && !CombiningHeuristic<None>);

}  // namespace nsp::mis
