// nsp/mis.hpp: MIS heuristics, evaluated on pdf ratios only (THEORY 5.1, STYLE rule 7).
//
// A heuristic weighs the strategy that produced a path against the other strategy from the
// ratio r = p_other / p_this of their pdfs for that path, so absolute path pdfs, which underflow
// on long paths, are never formed.
#pragma once

#include <cmath>
#include <concepts>
#include <limits>

#include "core/error.hpp"

namespace nsp::mis {

inline constexpr float kInfPower = std::numeric_limits<float>::infinity();

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
    /// The heuristic's power of a pdf ratio, r itself: weights are power(p_this) / sum power(p_i).
    float power(float r) const noexcept { return r; }
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
    /// r^beta: weights are power(p_this) / sum power(p_i).
    float power(float r) const noexcept { return std::pow(r, beta_); }

private:
    float beta_;
};

/// A heuristic that combines strategies: `weight(r)` in [0, 1], with weight(r) + weight(1/r) = 1,
/// and `power(r)` >= 0, multiplicative (power(a b) = power(a) power(b)), with which the weight of
/// one technique among several is power(p_this) / sum_i power(p_i) (see `weight_among`).
template <class H>
concept CombiningHeuristic = H::combines && requires(const H& h, float r) {
    { h.weight(r) } -> std::same_as<float>;
    { h.power(r) } -> std::same_as<float>;
};

/// The weight of one technique among several from the ratios of every technique's pdf to one
/// common reference pdf: `r_this` for the technique that sampled the path, `r_others` for the
/// rest (THEORY 5.4: tracking + NEE, tracking + hit, equiangular + NEE). The weights of all
/// techniques of one path, each computed with its own r_this, sum to 1. Infinite ratios take the
/// whole weight (shared between equal infinities), a zero r_this gets 0. The powers are taken of
/// the ratios over the largest one, numbers in [0, 1] of which one is 1, so they neither overflow
/// nor all underflow to 0 (with powers of the ratios themselves, three ratios of 1e-30 under
/// Power(2) gave every technique weight 0; found by the fuzzer, tests/fuzz). Never NaN for
/// ratios in [0, inf]; a NaN ratio gives NaN, which the estimator reports as Status::NonFinite.
template <class H, class... R>
float weight_among(const H& h, float r_this, R... r_others) noexcept {
    if (!(r_this > 0.f)) return 0.f;
    const float others[] = {float(r_others)...};
    int infinite = r_this == kInfPower ? 1 : 0;
    float largest = r_this;
    for (const float q : others) {
        infinite += q == kInfPower ? 1 : 0;
        largest = q > largest ? q : largest;
    }
    if (infinite > 0) return r_this == kInfPower ? 1.f / float(infinite) : 0.f;
    const float p = h.power(r_this / largest);
    double sum = p;  // at least power(1) = 1: never 0
    for (const float q : others) sum += double(h.power(q / largest));
    if (std::isnan(sum)) return std::numeric_limits<float>::quiet_NaN();
    return float(double(p) / sum);
}

/// Any heuristic policy, including None.
template <class H>
concept Heuristic = requires {
    { H::combines } -> std::convertible_to<bool>;
    { H::name } -> std::convertible_to<const char*>;
};

static_assert(CombiningHeuristic<Balance> && CombiningHeuristic<Power> && !CombiningHeuristic<None>);

}  // namespace nsp::mis
