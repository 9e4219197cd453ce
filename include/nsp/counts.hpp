// nsp/counts.hpp: expected sample counts of MIS techniques (THEORY 5.9) and a rule that learns
// them from a render's first samples.
//
// One mechanism serves every technique an estimator may skip: a technique with expected count
// n in (0, 1] runs with probability n, decided before it is sampled (draw_technique); where it
// runs its estimate divides by n, and every MIS weight takes n p in place of its pdf p. That keeps
// the estimator unbiased for any n in (0, 1] and lets a technique that does not pay for itself be
// drawn rarely. The adaptive equiangular probability (EstimatorOptions::adaptive_equiangular),
// BDPT's light_subpath_probability and PathEstimator's NEE count (EstimatorOptions::nee_count)
// are such counts.
//
// Choosing the NEE count (after Grittmann et al. 2022, "Efficiency-aware multiple importance
// sampling for bidirectional rendering algorithms", which picks counts from estimated variances
// and costs): with the balance heuristic every light contribution of a path, by whichever
// technique, is f / p_ref / (p_hit + n p_nee + p_other) on one reference density, so one pilot
// path traced at count 1, which has an NEE sample at every vertex, gives the path's estimate at
// any count n exactly, up to the Bernoulli draws that decide where NEE runs: their expectation
// A(n) (each contribution re-weighted, NEE's x(n) times n) and their variance B(n) = sum over the
// NEE samples of n (1 - n) x(n)^2, whose draws are independent of everything else. So
// Var[F(n)] = Var[A(n)] + E[B(n)] (total variance), estimated without bias from the pilot's own
// paths, covariances within a path included (the ones that matter where tracking alone is nearly
// noiseless, as in a furnace). NeeCountLearner keeps that for a ladder of candidate counts over a
// pixel tile and picks the count that minimises variance x cost, the cost being density lookups
// and DDA steps (deterministic, unlike time; a shadow walk's fixed work counted as one lookup) with
// the shadow walks' share scaled by n (THEORY 5.9).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "core/counter.hpp"
#include "core/error.hpp"
#include "core/rng.hpp"

namespace nsp {

/// Whether a technique with expected count `count` in (0, 1] runs this time: always at count >= 1
/// (no random number drawn, so a count of 1 leaves the random stream as without counts), else with
/// probability count (one number drawn).
template <UniformRng R>
bool draw_technique(float count, R& rng) {
    return count >= 1.f || rng.uniform() < count;
}

/// Throws InvalidArgument unless `count` lies in (0, 1]; `what` names the option.
inline void validate_count(const char* what, float count) {
    if (!(count > 0.f && count <= 1.f))
        detail::fail(what, " = ", count, " is not allowed: an expected sample count must lie in (0, 1]");
}

/// Which technique produced a light contribution a MisRecorder sees.
enum class LightTechnique : std::uint8_t {
    Hit,    ///< tracking hit the light (count 1)
    Nee,    ///< NEE from a tracked vertex or a surface, drawn with the NEE count
    Other,  ///< a technique whose count the learner does not change (NEE from an equiangular vertex)
};

/// A lookup counter that also records what NeeCountLearner needs: every light contribution that
/// both tracking and NEE can make and the work of every NEE shadow walk (whether the NEE count
/// scales it or not). The estimators call these only on such counters; with any other counter
/// they compile to nothing.
template <class C>
concept MisRecorder = LookupCounter<C> && requires(C& c, float f, LightTechnique t, double w, bool b) {
    { c.record_light(f, f, f, f, f, t) } noexcept;
    { c.record_shadow_walk(w, b) } noexcept;
    { c.work() } -> std::convertible_to<double>;
};

namespace detail {
/// Records a light contribution on a MisRecorder (else nothing). Every pdf is relative to one
/// reference density of the path (any one; the drawing technique's is simplest): `f_over_ref`
/// the contribution's channel mean f / p_ref (no MIS weight, no count), `p_hit` the density of
/// tracking that hits the light, `p_nee` NEE's without its count, `p_other` a further
/// technique's of fixed count (0 if none; equiangular + NEE), `count` the NEE count the path ran
/// with, `t` the technique that drew it.
template <class C>
void record_light(C& counter, float f_over_ref, float p_hit, float p_nee, float p_other, float count,
                  LightTechnique t) noexcept {
    if constexpr (MisRecorder<C>) counter.record_light(f_over_ref, p_hit, p_nee, p_other, count, t);
    else (void)counter, (void)f_over_ref, (void)p_hit, (void)p_nee, (void)p_other, (void)count, (void)t;
}
/// The work counted since `before` as one NEE shadow walk's, on a MisRecorder (else nothing):
/// `counted` when the walk ran with the NEE count (from a tracked vertex or a surface), false when
/// it runs whatever the count (from an equiangular vertex).
template <class C>
void record_shadow_walk(C& counter, double before, bool counted) noexcept {
    if constexpr (MisRecorder<C>) counter.record_shadow_walk(counter.work() - before, counted);
    else (void)counter, (void)before, (void)counted;
}
/// counter.work() on a MisRecorder, else 0 (what record_shadow_walk takes as `before`).
template <class C>
double recorder_work(const C& counter) noexcept {
    if constexpr (MisRecorder<C>) return counter.work();
    else return (void)counter, 0.0;
}
}  // namespace detail

/// Learns PathEstimator's NEE count (EstimatorOptions::nee_count) for a pixel tile from pilot
/// samples rendered at count 1 with the learner as their lookup counter (see the header), for the
/// balance heuristic. The host calls end_sample(estimate) after each sample and end_pixel() after
/// each pixel's samples; choose() then gives the count. Deterministic: the same samples in the
/// same order give the same count. Host-side and fixed-size (no heap); one per tile.
class NeeCountLearner {
public:
    static constexpr bool enabled = true;
    static constexpr int kCandidates = 7;  ///< counts 1, 1/2, ..., 1/64

    /// The j-th candidate count, 2^-j.
    static constexpr float candidate(int j) noexcept { return 1.f / float(1 << j); }

    /// A shadow walk's work besides its lookups and steps (the light sample, the phase or BSDF
    /// evaluation, the walk's set-up), in lookups: an assumption of the cost model, about what a
    /// lookup costs.
    static constexpr double kShadowRayCost = 1.0;

    void lookup() noexcept { ++lookups_; }
    void majorant_steps(std::uint64_t k) noexcept { steps_ += k; }
    std::uint64_t count() const noexcept { return lookups_; }
    std::uint64_t steps() const noexcept { return steps_; }  ///< grid-majorant DDA steps (as LookupCount's)
    /// The work so far in lookups: lookups + kDdaStepCost x DDA steps.
    double work() const noexcept { return double(lookups_) + double(kDdaStepCost) * double(steps_); }

    /// Called by the estimator for every light contribution both techniques can make (see
    /// detail::record_light). A pilot at a count other than 1 has no NEE sample at some vertices:
    /// the learner then reports invalid_pilot() and chooses 1.
    void record_light(float f_over_ref, float p_hit, float p_nee, float p_other, float count,
                      LightTechnique t) noexcept {
        if (count != 1.f) invalid_ = true;
        if (!(p_hit >= 0.f && p_nee >= 0.f && p_other >= 0.f) || !std::isfinite(f_over_ref) || f_over_ref == 0.f) return;
        const double u = f_over_ref, h = p_hit, n = p_nee, o = p_other;
        // With the balance heuristic the contribution is x = u / (h + c n + o) whichever technique
        // drew it, NEE's where it runs (its weight c n / D over its count c): B x with B a
        // Bernoulli draw of mean c, whose expectation c x and variance c (1 - c) x^2 go to A and B.
        const double d1 = h + n + o;
        if (!(d1 > 0.0) || !std::isfinite(d1)) return;
        const double v1 = u / d1;
        for (int j = 0; j < kCandidates; ++j) {
            const double c = candidate(j), d = h + c * n + o;
            const double x = d > 0.0 ? u / d : 0.0;
            if (t == LightTechnique::Nee) {
                path_delta_[std::size_t(j)] += c * x - v1;
                path_bernoulli_[std::size_t(j)] += c * (1.0 - c) * x * x;
            } else {
                path_delta_[std::size_t(j)] += x - v1;
            }
        }
    }
    /// Called by the estimator after each NEE shadow walk with the work (work()) it took;
    /// `counted`: the walk runs with the NEE count, so its share of the cost scales with it (the
    /// walks from equiangular vertices run at any count: their work stays in the base).
    void record_shadow_walk(double w, bool counted) noexcept {
        if (counted) nee_work_ += w + kShadowRayCost;
        fixed_work_ += kShadowRayCost;
    }

    /// The host, after each pilot sample: its estimate (the channel mean the render measures).
    void end_sample(double estimate) noexcept {
        for (int j = 0; j < kCandidates; ++j) {
            const double a = estimate + path_delta_[std::size_t(j)];
            if (pixel_n_ == 0) shift_[std::size_t(j)] = a;  // shifted sums: no cancellation
            const double d = a - shift_[std::size_t(j)];
            pixel_sum_[std::size_t(j)] += d;
            pixel_sum2_[std::size_t(j)] += d * d;
            bernoulli_[std::size_t(j)] += path_bernoulli_[std::size_t(j)];
            path_delta_[std::size_t(j)] = path_bernoulli_[std::size_t(j)] = 0.0;
        }
        ++pixel_n_;
        ++samples_;
    }
    /// The host, after each pixel's pilot samples: folds the pixel's sample variances in.
    void end_pixel() noexcept {
        if (pixel_n_ > 1) {
            const double n = double(pixel_n_);
            for (int j = 0; j < kCandidates; ++j) {
                const double s = pixel_sum_[std::size_t(j)], s2 = pixel_sum2_[std::size_t(j)];
                const double var = (s2 - s * s / n) / (n - 1.0);
                variance_sum_[std::size_t(j)] += (var > 0.0 ? var : 0.0) * n;
            }
            variance_samples_ += pixel_n_;
        }
        pixel_n_ = 0;
        pixel_sum_ = {};
        pixel_sum2_ = {};
    }

    /// Adds another learner's statistics (a tile learned in pieces; both after end_pixel).
    void merge(const NeeCountLearner& o) noexcept {
        lookups_ += o.lookups_;
        steps_ += o.steps_;
        nee_work_ += o.nee_work_;
        fixed_work_ += o.fixed_work_;
        samples_ += o.samples_;
        variance_samples_ += o.variance_samples_;
        invalid_ = invalid_ || o.invalid_;
        for (int j = 0; j < kCandidates; ++j) {
            variance_sum_[std::size_t(j)] += o.variance_sum_[std::size_t(j)];
            bernoulli_[std::size_t(j)] += o.bernoulli_[std::size_t(j)];
        }
    }

    /// The predicted variance of one sample at candidate j: the mean over pixels of the sample
    /// variance of A(c_j), plus the mean of B(c_j); 0 before any pixel ended.
    double predicted_variance(int j) const noexcept {
        const double a = variance_samples_ > 0 ? variance_sum_[std::size_t(j)] / double(variance_samples_) : 0.0;
        const double b = samples_ > 0 ? bernoulli_[std::size_t(j)] / double(samples_) : 0.0;
        return a + b;
    }
    /// Predicted work per sample at candidate j in lookups: lookups and DDA steps (work()), with
    /// NEE's share (its shadow walks' work and kShadowRayCost each) scaled by the count, +1 per
    /// sample for the camera ray (so that a tile whose paths never meet the medium has a cost).
    double predicted_cost(int j) const noexcept {
        if (samples_ == 0) return 1.0;
        const double base = work() + fixed_work_ - nee_work_;
        return (base + double(candidate(j)) * nee_work_) / double(samples_) + 1.0;
    }

    /// The candidate count with the smallest predicted variance x cost; 1 when there is nothing to
    /// learn from (no pixel with two samples, no variance at count 1) or the pilot did not run at
    /// count 1.
    float choose() const noexcept {
        if (invalid_ || variance_samples_ == 0 || !(predicted_variance(0) > 0.0)) return 1.f;
        int best = 0;
        double best_e = predicted_variance(0) * predicted_cost(0);
        for (int j = 1; j < kCandidates; ++j) {
            const double e = predicted_variance(j) * predicted_cost(j);
            if (e < best_e) best = j, best_e = e;
        }
        return candidate(best);
    }

    bool invalid_pilot() const noexcept { return invalid_; }
    std::uint64_t samples() const noexcept { return samples_; }
    double nee_work() const noexcept { return nee_work_; }  ///< NEE's work in lookups (see predicted_cost)

private:
    using PerCandidate = std::array<double, kCandidates>;
    std::uint64_t lookups_ = 0, steps_ = 0, samples_ = 0, variance_samples_ = 0;
    double nee_work_ = 0.0, fixed_work_ = 0.0;
    int pixel_n_ = 0;
    bool invalid_ = false;
    PerCandidate path_delta_{}, path_bernoulli_{};         // the current sample
    PerCandidate shift_{}, pixel_sum_{}, pixel_sum2_{};    // the current pixel
    PerCandidate variance_sum_{}, bernoulli_{};            // the tile
};

static_assert(MisRecorder<NeeCountLearner>);

}  // namespace nsp
