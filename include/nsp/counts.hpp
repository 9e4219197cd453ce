// nsp/counts.hpp: expected sample counts of MIS techniques (THEORY 5.9) and a rule that learns
// them from a render's first samples.
//
// One mechanism serves every technique an estimator may skip: a technique with expected count
// n in [0, 1] runs with probability n, decided before it is sampled (draw_technique); where it
// runs its estimate divides by n, and every MIS weight takes n p in place of its pdf p. That keeps
// the estimator unbiased for any n in (0, 1] and lets a technique that does not pay for itself be
// drawn rarely; n = 0 removes the technique from every weight, unbiased where the others cover
// what it samples (EstimatorOptions says where nsp allows it). The equiangular vertex's count
// (EstimatorOptions::equiangular_count, times the adaptive probability of adaptive_equiangular),
// BDPT's light_subpath_probability, the NEE count (EstimatorOptions::nee_count) and the emission
// segment technique's count (EstimatorOptions::emission_segment_count) are such counts.
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
// pixel tile (1, 1/2, ..., 1/64 and 0) and picks the count that minimises variance x cost, the
// cost being the host's CostModel of density lookups, DDA steps and technique runs (by default in
// lookups: deterministic, unlike time) with the shadow walks' share scaled by n (THEORY 5.9).
// Count 0 is a candidate only where no pilot contribution needs the technique (its balance
// denominator without it is 0, as for a point light) and the scene allows it (no delta lights).
// A pilot may also run below count 1 (NeeCountLearner::pilot_counts). Volume emission is the
// same with the collision estimator in tracking's place and the segment technique in NEE's (NEE
// toward the volume at a fixed count): the learner keeps both ladders and picks the pair. Under
// BdptEstimator the pair is NEE's count and the light subpath probability: every strategy's
// contribution is u / (p_fixed + n p_nee + c p_light) at counts (n, c), the NEE draws independent
// per camera vertex, the light subpath one draw for all of its connections and splats.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "core/counter.hpp"
#include "core/error.hpp"
#include "core/rng.hpp"
#include "options.hpp"
#include "recorder.hpp"

namespace nsp {

/// The expected counts a NeeCountLearner chooses (EstimatorOptions::nee_count,
/// EstimatorOptions::emission_segment_count, BdptEstimator's light_subpath_probability).
struct TechniqueCounts {
    float nee = 1.f;
    float emission_segment = 1.f;
    float light_subpath = 1.f;
    bool operator==(const TechniqueCounts&) const = default;
};

/// What a host's work costs the learner's prediction, in the host's own unit (seconds, lookups,
/// anything proportional): a sample costs per_sample plus per_lookup per density lookup and
/// per_dda_step per grid-majorant DDA step, plus per_shadow_walk per NEE shadow walk (the light
/// sample, the phase or BSDF evaluation, the host's own ray casts: what it costs besides its
/// lookups), per_segment_walk per run of the emission segment technique and per_light_walk per
/// light subpath walk or connection. The default is nsp's own model in lookups. A host that times
/// its parts passes them here; only the ratios matter.
struct CostModel {
    double per_sample = 1.0;
    double per_lookup = 1.0;
    double per_dda_step = double(kDdaStepCost);
    double per_shadow_walk = 1.0;
    double per_segment_walk = 1.0;
    double per_light_walk = 1.0;
    bool operator==(const CostModel&) const = default;
};

/// Learns a tile's expected counts from pilot samples rendered at counts 1 with the learner as
/// their lookup counter (see the header), for the balance heuristic: under PathEstimator and
/// SpectralPathEstimator the NEE count (EstimatorOptions::nee_count) and, in emissive media, the
/// emission segment count (EstimatorOptions::emission_segment_count); under BdptEstimator the NEE
/// count and the light subpath probability. Two counts jointly, over every pair of candidates (a
/// path's contributions share its variance): the second is the segment technique's or the light
/// subpaths', whichever the pilot recorded. The host calls end_sample(estimate) after each sample
/// and end_pixel() after each pixel's samples; choose_counts() then gives the counts (choose() the
/// NEE count alone). Where the second technique never ran its count stays 1 and the NEE count is
/// what it would be without it. Deterministic: the same samples in the same order give the same
/// counts. Host-side and fixed-size (no heap, about 40 KiB); one per tile.
///
/// Count 0 drops a technique from every weight. The learner offers it only where the pilot saw no
/// contribution that the other techniques cannot make (a pair of counts at which some recorded
/// contribution's balance denominator is 0 is never chosen) and, for NEE, where the scene has no
/// delta light (the estimators tell the learner through nee_count_may_be_0; a host that drives
/// the kernels itself calls it with false for such a scene, as those refuse NEE count 0).
///
/// BDPT's light subpath is one draw per sample for all of its strategies, so its Bernoulli
/// variance is that of the sum of its contributions to the sample's own pixel; its splats (t = 1)
/// land on other pixels, whose variance they add to by their second moment (their means there,
/// spread over the image, are left out). At light subpath count 0 the prediction takes the
/// diagonal correction (see add_contribution) over every contribution, splats included: exact
/// over the image, approximate per tile (a path one tile's light subpath splats may be drawn by
/// another tile's camera subpaths). BDPT's NEE count is not offered 0: with light tracing a
/// splatted path's camera-side strategies are drawn on other pixels, and the variance at NEE
/// count 0 of what NEE alone drew here is not predicted well per pixel.
class NeeCountLearner {
public:
    static constexpr bool enabled = true;
    static constexpr int kCandidates = 8;  ///< counts 1, 1/2, ..., 1/64 and 0 (for each technique)
    static constexpr int kZero = kCandidates - 1;  ///< the index of count 0

    /// The j-th candidate count: 2^-j, and 0 for j = kZero.
    static constexpr float candidate(int j) noexcept { return j == kZero ? 0.f : 1.f / float(1 << j); }
    /// The index j of a candidate count (the inverse of candidate()), e.g. of a chosen one.
    static int candidate_index(float count) noexcept {
        return count == 0.f ? kZero : int(std::lround(-std::log2(count)));
    }

    /// A learner whose cost prediction uses `costs` (see CostModel), for a pilot rendered at
    /// counts `pilot` (see pilot_counts()). Throws InvalidArgument naming a cost that is negative
    /// or not finite, per_sample not > 0, or a pilot count outside (0, 1] (the light subpath's
    /// must be 1).
    explicit NeeCountLearner(const CostModel& costs = {}, const TechniqueCounts& pilot = {})
        : costs_(costs), pilot_(pilot) {
        const auto check_count = [](const char* what, float v) {
            if (!(v > 0.f && v <= 1.f))
                throw InvalidArgument(std::string("nsp::NeeCountLearner: the pilot's ") + what + " count is " +
                                      std::to_string(v) + "; it must be in (0, 1]");
        };
        check_count("NEE", pilot.nee);
        check_count("emission segment", pilot.emission_segment);
        if (pilot.light_subpath != 1.f)
            throw InvalidArgument("nsp::NeeCountLearner: the pilot's light subpath probability is " +
                                  std::to_string(pilot.light_subpath) + "; a BDPT pilot runs at 1");
        const auto check = [](const char* what, double v, bool positive) {
            if (!std::isfinite(v) || v < 0.0 || (positive && v == 0.0))
                throw InvalidArgument(std::string("nsp::NeeCountLearner: CostModel::") + what + " is " +
                                      std::to_string(v) + "; it must be finite and " + (positive ? "> 0" : ">= 0"));
        };
        check("per_sample", costs.per_sample, true);
        check("per_lookup", costs.per_lookup, false);
        check("per_dda_step", costs.per_dda_step, false);
        check("per_shadow_walk", costs.per_shadow_walk, false);
        check("per_segment_walk", costs.per_segment_walk, false);
        check("per_light_walk", costs.per_light_walk, false);
    }
    const CostModel& costs() const noexcept { return costs_; }
    /// The counts the pilot runs at (EstimatorOptions::nee_count, emission_segment_count): 1 by
    /// default. A pilot at NEE count c has NEE samples at a fraction c of its vertices; the
    /// learner re-weights them by 1 / c (and takes the pilot's own Bernoulli variance out), so it
    /// predicts every candidate without bias from a pilot that costs less. BdptEstimator's pilot
    /// runs at counts 1. A contribution recorded at other counts makes the pilot invalid.
    const TechniqueCounts& pilot_counts() const noexcept { return pilot_; }

    /// Whether the scene allows NEE count 0 (no delta lights); false rules count 0 out for NEE.
    /// The estimators call it on every sample.
    void nee_count_may_be_0(bool allowed) noexcept { nee_zero_refused_ = nee_zero_refused_ || !allowed; }

    void lookup() noexcept { ++lookups_; }
    void majorant_steps(std::uint64_t k) noexcept { steps_ += k; }
    std::uint64_t count() const noexcept { return lookups_; }
    std::uint64_t steps() const noexcept { return steps_; }  ///< grid-majorant DDA steps (as LookupCount's)
    /// The work so far in the CostModel's unit: per_lookup x lookups + per_dda_step x DDA steps.
    double work() const noexcept {
        return costs_.per_lookup * double(lookups_) + costs_.per_dda_step * double(steps_);
    }

    /// Called by the estimator for every light contribution both techniques can make (see
    /// detail::record_light). A contribution at a count other than the pilot's makes the learner
    /// report invalid_pilot() and choose 1.
    void record_light(float f_over_ref, float p_hit, float p_nee, float p_other, float count,
                      LightTechnique t) noexcept {
        add_contribution(Axis::Nee, f_over_ref, p_hit, p_nee, p_other, count, pilot_.nee, t == LightTechnique::Nee);
    }
    /// Called by the estimator for every volume emission contribution of a combining strategy
    /// (see detail::record_emission); at a segment count other than the pilot's it is invalid as above.
    void record_emission(float f_over_ref, float p_collision, float p_segment, float p_nee, float count,
                         EmissionTechnique t) noexcept {
        set_second(Second::Segment);
        add_contribution(Axis::Second, f_over_ref, p_collision, p_segment, p_nee, count, pilot_.emission_segment,
                         t == EmissionTechnique::Segment);
    }
    /// Called by BdptEstimator for every strategy's contribution (see detail::record_bdpt): at
    /// NEE count c_n and light subpath count c_l it is x = u / (p_fixed + c_n p_nee + c_l p_light),
    /// times the Bernoulli draw of the group that drew it (none for the fixed group).
    void record_bdpt(float f_over_ref, float p_fixed, float p_nee, float p_light, float nee_count, float light_count,
                     BdptTechnique t, bool splat) noexcept {
        set_second(Second::LightSubpath);
        nee_zero_refused_ = true;  // BDPT's NEE count stays above 0 (see the class comment)
        if (nee_count != 1.f || light_count != 1.f) invalid_ = true;
        if (pilot_.nee != 1.f || pilot_.emission_segment != 1.f) invalid_ = true;
        double v1 = 0.0, d1 = 0.0;
        if (!at_pilot(f_over_ref, p_fixed, p_nee, p_light, 1.0, v1, d1)) return;
        const double u = f_over_ref, h = p_fixed, n = p_nee, l = p_light;
        for (int jn = 0; jn < kCandidates; ++jn)
            for (int jl = 0; jl < kCandidates; ++jl) {
                const std::size_t k = pair(jn, jl);
                const double cn = candidate(jn), cl = candidate(jl), d = h + cn * n + cl * l;
                if (!(d > 0.0)) lost_ |= std::uint64_t(1) << k;  // only the counted groups draw it
                const double x = d > 0.0 ? u / d : 0.0;
                // At light subpath count 0 the diagonal correction of add_contribution, splats
                // included: over the image every path's draws by every strategy are recorded by
                // some sample, so the sum estimates the image's second moment there (a splat lands
                // on another pixel: a tile's share is approximate). It carries the variance of
                // what only the light subpaths drew in the pilot; at counts above 0 their
                // Bernoulli terms do, and the prediction is exact per pixel without it.
                if (jl == kZero) {
                    const double c = t == BdptTechnique::Fixed ? 1.0 : t == BdptTechnique::Nee ? cn : cl;
                    path_diagonal_[k] += (d > 0.0 ? u * u / (d1 * d) : 0.0) - c * x * x;
                }
                switch (t) {
                    case BdptTechnique::Fixed: path_delta_[k] += x - v1; break;
                    case BdptTechnique::Nee:
                        path_delta_[k] += cn * x - v1;
                        path_bernoulli_[k] += cn * (1.0 - cn) * x * x;
                        break;
                    case BdptTechnique::Light:
                        if (splat) {
                            path_bernoulli_[k] += cl * x * x;  // E[(B x)^2] on another pixel
                        } else {
                            path_delta_[k] += cl * x - v1;
                            light_sum_[k] += x;  // one draw for all: its variance at end_sample
                        }
                        break;
                }
            }
    }
    /// Called by the estimator after each NEE shadow walk with the work (work()) it took;
    /// `counted`: the walk runs with the NEE count, so its share of the cost scales with it (the
    /// walks from equiangular vertices run at any count: their work stays in the base). The
    /// counted walks' work, measured at the pilot's count, scales by candidate / pilot count.
    void record_shadow_walk(double w, bool counted) noexcept {
        if (counted) nee_work_ += w + costs_.per_shadow_walk;
        fixed_work_ += costs_.per_shadow_walk;
    }
    /// Called by the estimator after each run of the emission segment technique with its work.
    void record_segment_walk(double w) noexcept {
        set_second(Second::Segment);
        add_second_work(w, costs_.per_segment_walk);
    }
    /// Called by BdptEstimator after a light subpath's walk and after each of its connections'
    /// shadow walks with the work it took: all of it scales with the light subpath count.
    void record_light_walk(double w) noexcept {
        set_second(Second::LightSubpath);
        add_second_work(w, costs_.per_light_walk);
    }

    /// The host, after each pilot sample: its estimate for its own pixel (the channel mean the
    /// render measures; BDPT's splats are not part of it).
    void end_sample(double estimate) noexcept {
        for (int jn = 0; jn < kCandidates; ++jn)
            for (int js = 0; js < kCandidates; ++js) {
                const std::size_t k = pair(jn, js);
                const double c = candidate(js);
                path_bernoulli_[k] += c * (1.0 - c) * light_sum_[k] * light_sum_[k];
                const double a = estimate + path_delta_[k];
                if (pixel_n_ == 0) shift_[k] = a;  // shifted sums: no cancellation
                const double d = a - shift_[k];
                pixel_sum_[k] += d;
                pixel_sum2_[k] += d * d;
                bernoulli_[k] += path_bernoulli_[k] + path_diagonal_[k];
            }
        SampleRecord& rec = group_[std::size_t(group_n_++)];
        rec.estimate = estimate;
        rec.delta = path_delta_;
        for (std::size_t k = 0; k < kPairs; ++k) rec.bernoulli[k] = path_bernoulli_[k] + path_diagonal_[k];
        if (group_n_ == kGroupSize) flush_group();
        path_delta_ = {};
        path_bernoulli_ = {};
        path_diagonal_ = {};
        light_sum_ = {};
        ++pixel_n_;
        ++samples_;
    }
    /// The host, after each pixel's pilot samples: folds the pixel's sample variances in.
    void end_pixel() noexcept {
        if (pixel_n_ > 1) {
            const double n = double(pixel_n_);
            for (std::size_t k = 0; k < kPairs; ++k) {
                const double var = (pixel_sum2_[k] - pixel_sum_[k] * pixel_sum_[k] / n) / (n - 1.0);
                variance_sum_[k] += (var > 0.0 ? var : 0.0) * n;
            }
            variance_samples_ += pixel_n_;
        }
        flush_group();
        pixel_n_ = 0;
        pixel_sum_ = {};
        pixel_sum2_ = {};
    }

    /// Adds another learner's statistics (a tile learned in pieces; both after end_pixel). Both
    /// must have the same pilot counts and costs, else the result is invalid_pilot().
    void merge(const NeeCountLearner& o) noexcept {
        // Pilots at different counts or in different cost units do not pool.
        if (o.samples_ > 0 && (!(o.pilot_ == pilot_) || !(o.costs_ == costs_))) invalid_ = true;
        lookups_ += o.lookups_;
        steps_ += o.steps_;
        fixed_work_ += o.fixed_work_;
        nee_work_ += o.nee_work_;
        second_work_ += o.second_work_;
        samples_ += o.samples_;
        variance_samples_ += o.variance_samples_;
        z_n_ += o.z_n_;
        z_dof_ += o.z_dof_;
        invalid_ = invalid_ || o.invalid_;
        nee_zero_refused_ = nee_zero_refused_ || o.nee_zero_refused_;
        lost_ |= o.lost_;
        if (o.second_ != Second::None) set_second(o.second_);
        for (std::size_t k = 0; k < kPairs; ++k) {
            variance_sum_[k] += o.variance_sum_[k];
            bernoulli_[k] += o.bernoulli_[k];
            z_[k] += o.z_[k];
            z2_[k] += o.z2_[k];
            z_at_1_[k] += o.z_at_1_[k];
            z_nee_at_1_[k] += o.z_nee_at_1_[k];
            z_segment_at_1_[k] += o.z_segment_at_1_[k];
        }
    }

    /// The predicted variance of one sample at NEE candidate j and candidate js of the second
    /// technique (the segment technique's or the light subpaths'): the mean over pixels of the
    /// sample variance of A, plus the mean of the Bernoulli variances, the splats' second moments
    /// and the contributions' diagonal correction (see add_contribution); 0 before any pixel ended.
    double predicted_variance(int j, int js = 0) const noexcept {
        const std::size_t k = pair(j, js);
        const double a = variance_samples_ > 0 ? variance_sum_[k] / double(variance_samples_) : 0.0;
        const double b = samples_ > 0 ? bernoulli_[k] / double(samples_) : 0.0;
        return std::max(a + b, 0.0);  // below 0 only by noise, with a pilot at a count below 1
    }
    /// Predicted work per sample at NEE candidate j and second candidate js, in lookups: lookups
    /// and DDA steps (work()), with each counted technique's share (its walks' work and its
    /// per-run cost each) scaled by its count, + per_sample (so that a tile whose paths never meet
    /// the medium has a cost), all in the CostModel's unit.
    double predicted_cost(int j, int js = 0) const noexcept {
        if (samples_ == 0) return 1.0;
        const double base = work() + fixed_work_ - nee_work_ - second_work_;
        const double second_pilot = second_ == Second::Segment ? double(pilot_.emission_segment) : 1.0;
        return (base + double(candidate(j)) / double(pilot_.nee) * nee_work_ +
                double(candidate(js)) / second_pilot * second_work_) /
                   double(samples_) +
               costs_.per_sample;
    }

    /// A count below 1 must pay for itself beyond the pilot's noise: a pair is taken only where its
    /// predicted variance x cost is below that of the same pair with each reduced count put back
    /// to 1 by at least kSignificance standard errors of the difference (paired: one pilot). The
    /// predicted variance is a mean over the pilot's samples of z = n / (n - 1) (a - mean a)^2 + B
    /// (a a sample's re-weighted estimate, the mean over its pixel, B its Bernoulli variance and
    /// diagonal correction), so
    /// the standard error follows from the spread of the samples' z differences: large exactly
    /// where a few samples carry the prediction. A pilot's variance at a low count
    /// rests on its largest re-weighted contributions, which are rare where the skipped technique
    /// is the one that finds them: in the plume (examples) three pilots of one tile predicted the
    /// variance at segment count 1/64 as 0.05, 0.0007 and 0.013 (measured: 0.007, against 0.002 at
    /// count 1), and taking the lowest prediction's count tripled the image's variance. Count 1
    /// (plain MIS) is the safe side.
    static constexpr double kSignificance = 2.0;

    /// The candidate pair with the smallest predicted variance x cost among the allowed ones
    /// (allowed()) that pass the significance test above (ties to the larger counts); counts 1 when there is nothing to
    /// learn from (fewer than two samples in pixels with two or more, no variance at counts 1) or the pilot
    /// did not run at counts 1.
    TechniqueCounts choose_counts() const noexcept {
        if (invalid_ || z_dof_ < 2 || !(predicted_variance(0, 0) > 0.0)) return {};
        int best_n = 0, best_s = 0;
        double best_e = predicted_variance(0, 0) * predicted_cost(0, 0);
        for (int jn = 0; jn < kCandidates; ++jn)
            for (int js = 0; js < kCandidates; ++js) {
                if ((jn == 0 && js == 0) || !allowed(jn, js)) continue;
                const double e = predicted_variance(jn, js) * predicted_cost(jn, js);
                if (!(e < best_e)) continue;
                // Better than every pair with one or both of its reduced counts at 1, significantly.
                const bool pays = significantly_better(jn, js, 0, 0, z_at_1_) &&
                                  (jn == 0 || js == 0 ||
                                   (significantly_better(jn, js, 0, js, z_nee_at_1_) &&
                                    significantly_better(jn, js, jn, 0, z_segment_at_1_)));
                if (pays) best_n = jn, best_s = js, best_e = e;
            }
        TechniqueCounts out;
        out.nee = candidate(best_n);
        (second_ == Second::LightSubpath ? out.light_subpath : out.emission_segment) = candidate(best_s);
        return out;
    }
    /// What choose_counts(fallback) needs of a tile once its pilot is done, about 270 bytes (the
    /// learner itself is about 40 KiB): a host keeps one per tile until every tile's pilot has run
    /// and their learners are merged into the image's.
    struct Summary {
        TechniqueCounts own;        ///< choose_counts()
        bool open = false;          ///< `own` is counts 1 for want of a significant gain, not of data
        bool light_subpath = false; ///< the second count is the light subpath probability
        /// Per pair (NEE candidate x second candidate, row-major): predicted variance x cost
        /// over that at counts 1; infinite at pairs not allowed().
        std::array<float, std::size_t(kCandidates) * std::size_t(kCandidates)> efficiency{};
    };
    Summary summary() const noexcept {
        Summary out;
        out.own = choose_counts();
        out.light_subpath = second_ == Second::LightSubpath;
        const float own_second = out.light_subpath ? out.own.light_subpath : out.own.emission_segment;
        const double e1 = predicted_variance(0, 0) * predicted_cost(0, 0);
        out.open = out.own.nee == 1.f && own_second == 1.f && !invalid_ && z_dof_ >= 2 && e1 > 0.0;
        for (int jn = 0; jn < kCandidates; ++jn)
            for (int js = 0; js < kCandidates; ++js)
                out.efficiency[pair(jn, js)] =
                    !allowed(jn, js) ? std::numeric_limits<float>::infinity()
                    : out.open       ? float(predicted_variance(jn, js) * predicted_cost(jn, js) / e1)
                                     : 1.f;
        return out;
    }

    /// A tile's counts with a fallback for a pilot too small to show a gain on its own: typically
    /// the image's counts, choose_counts() of every tile's learner merged (merge()), whose pooled
    /// pilot is many times larger. The tile's own choice where it passes the significance test or
    /// where it had nothing to learn from; otherwise `fallback` where the tile's predicted variance
    /// x cost at it is no larger than at counts 1 (and it is allowed there), else counts 1: a tile
    /// whose pilot shows that NEE pays (a small bright light in it alone) keeps count 1 whatever
    /// the image chose. Counts in `fallback` that are not candidates count as 1.
    static TechniqueCounts choose_counts(const Summary& tile, const TechniqueCounts& fallback) noexcept {
        if (!tile.open) return tile.own;
        const int fn = candidate_or_1(fallback.nee);
        const int fs = candidate_or_1(tile.light_subpath ? fallback.light_subpath : fallback.emission_segment);
        if ((fn == 0 && fs == 0) || !(tile.efficiency[pair(fn, fs)] <= 1.f)) return tile.own;
        TechniqueCounts out;
        out.nee = candidate(fn);
        (tile.light_subpath ? out.light_subpath : out.emission_segment) = candidate(fs);
        return out;
    }
    /// choose_counts(summary(), fallback).
    TechniqueCounts choose_counts(const TechniqueCounts& fallback) const noexcept {
        return choose_counts(summary(), fallback);
    }
    /// The NEE count of choose_counts().
    float choose() const noexcept { return choose_counts().nee; }

    bool invalid_pilot() const noexcept { return invalid_; }
    /// Whether the pair of candidates (jn, js) may be chosen: no recorded contribution has a
    /// balance denominator of 0 there (only a technique at count 0 could draw it), and NEE count
    /// 0 only where nee_count_may_be_0 was never told false.
    bool allowed(int jn, int js = 0) const noexcept {
        return !((lost_ >> pair(jn, js)) & 1u) && !(nee_zero_refused_ && jn == kZero);
    }
    std::uint64_t samples() const noexcept { return samples_; }
    double nee_work() const noexcept { return nee_work_; }  ///< NEE's work in lookups (see predicted_cost)
    /// The segment technique's work (0 under BDPT).
    double segment_work() const noexcept { return second_ == Second::Segment ? second_work_ : 0.0; }
    /// The light subpaths' work (0 under the path estimators).
    double light_subpath_work() const noexcept { return second_ == Second::LightSubpath ? second_work_ : 0.0; }

private:
    static constexpr std::size_t kPairs = std::size_t(kCandidates) * std::size_t(kCandidates);
    /// The candidate index of `count`, 0 (count 1) where it is not a candidate.
    static int candidate_or_1(float count) noexcept {
        if (count == 0.f) return kZero;
        if (!(count > 0.f && count <= 1.f)) return 0;
        const int j = candidate_index(count);
        return j >= 0 && j < kCandidates && candidate(j) == count ? j : 0;
    }
    static_assert(kPairs <= 64, "lost_ holds a bit per pair");
    using PerPair = std::array<double, kPairs>;
    static constexpr std::size_t pair(int jn, int js) noexcept { return std::size_t(jn * kCandidates + js); }

    /// Which count the second axis of the pairs is: none recorded yet, the emission segment
    /// technique's (path estimators) or the light subpath probability (BDPT). A pilot that records
    /// both is invalid.
    enum class Second : std::uint8_t { None, Segment, LightSubpath };
    void set_second(Second s) noexcept {
        if (second_ != Second::None && second_ != s) invalid_ = true;
        second_ = s;
    }
    void add_second_work(double w, double per_run) noexcept {
        second_work_ += w + per_run;
        fixed_work_ += per_run;
    }

    /// One pilot sample as the significance test needs it: its estimate and, per candidate pair,
    /// the change of its re-weighted estimate and its Bernoulli variance plus diagonal correction.
    struct SampleRecord {
        double estimate = 0.0;
        PerPair delta{}, bernoulli{};
    };
    /// Samples of one pixel per group (a pixel with more forms several groups: the test's z only).
    static constexpr int kGroupSize = 32;

    /// Folds the current group's samples into the z sums (see kSignificance): z per sample at
    /// every pair, its square and its products with z at the reference pairs.
    void flush_group() noexcept {
        const int n = group_n_;
        group_n_ = 0;
        if (n < 2) return;
        PerPair mean{};
        for (int i = 0; i < n; ++i)
            for (std::size_t k = 0; k < kPairs; ++k) mean[k] += value(group_[std::size_t(i)], k);
        for (double& m : mean) m /= double(n);
        const double c = double(n) / double(n - 1);
        // Sums within the group, then folded in about the group's own means: the standard error
        // is that of the tile's pixels as they are (their spread within), not of a random draw
        // of pixels (their differences between them are no noise of the prediction).
        PerPair z{}, sum{}, sum2{}, at_1{}, nee_at_1{}, segment_at_1{};
        for (int i = 0; i < n; ++i) {
            const SampleRecord& r = group_[std::size_t(i)];
            for (std::size_t k = 0; k < kPairs; ++k) {
                const double d = value(r, k) - mean[k];
                z[k] = c * d * d + r.bernoulli[k];
            }
            for (int jn = 0; jn < kCandidates; ++jn)
                for (int js = 0; js < kCandidates; ++js) {
                    const std::size_t p = pair(jn, js);
                    sum[p] += z[p];
                    sum2[p] += z[p] * z[p];
                    at_1[p] += z[p] * z[0];
                    nee_at_1[p] += z[p] * z[pair(0, js)];
                    segment_at_1[p] += z[p] * z[pair(jn, 0)];
                }
        }
        const double inv = 1.0 / double(n);
        for (int jn = 0; jn < kCandidates; ++jn)
            for (int js = 0; js < kCandidates; ++js) {
                const std::size_t p = pair(jn, js);
                z_[p] += sum[p];
                z2_[p] += sum2[p] - sum[p] * sum[p] * inv;
                z_at_1_[p] += at_1[p] - sum[p] * sum[0] * inv;
                z_nee_at_1_[p] += nee_at_1[p] - sum[p] * sum[pair(0, js)] * inv;
                z_segment_at_1_[p] += segment_at_1[p] - sum[p] * sum[pair(jn, 0)] * inv;
            }
        z_n_ += std::uint64_t(n);
        z_dof_ += std::uint64_t(n - 1);
    }
    static double value(const SampleRecord& r, std::size_t k) noexcept { return r.estimate + r.delta[k]; }

    /// Whether pair (jn, js) has a smaller predicted variance x cost than pair (rn, rs) by more
    /// than kSignificance standard errors: over the pilot's samples, the mean and spread of
    /// d = z(jn, js) C(jn, js) - z(rn, rs) C(rn, rs) within the groups (`cross`: the sums of
    /// z(jn, js) z(rn, rs) about the groups' means), C the tile's predicted cost.
    bool significantly_better(int jn, int js, int rn, int rs, const PerPair& cross) const noexcept {
        const std::size_t k = pair(jn, js), r = pair(rn, rs);
        const double m = double(z_n_), dof = double(z_dof_), c = predicted_cost(jn, js), cr = predicted_cost(rn, rs);
        const double mean = (z_[k] * c - z_[r] * cr) / m;
        const double var_k = z2_[k] / dof, var_r = z2_[r] / dof, cov = cross[k] / dof;
        const double var_d = c * c * var_k + cr * cr * var_r - 2.0 * c * cr * cov;
        const double se = std::sqrt(std::max(var_d, 0.0) / m);
        return mean + kSignificance * se < 0.0;
    }

    /// A recorded contribution u at the pilot's count `cp` of the technique of pdf b: its balance
    /// denominator dp = a + cp b + c and its value in the pilot's estimate vp = u / dp; false
    /// where it cannot enter the prediction (a negative or NaN pdf, u zero or not finite, no or an
    /// infinite denominator).
    static bool at_pilot(float u, float a, float b, float c, double cp, double& vp, double& dp) noexcept {
        if (!(a >= 0.f && b >= 0.f && c >= 0.f) || !std::isfinite(u) || u == 0.f) return false;
        dp = double(a) + cp * double(b) + double(c);
        if (!(dp > 0.0) || !std::isfinite(dp)) return false;
        vp = double(u) / dp;
        return true;
    }

    /// Which count a path estimator's contribution depends on: NEE's (the first of a pair) or the
    /// segment technique's (the second).
    enum class Axis : std::uint8_t { Nee, Second };

    /// A contribution x = u / (h + c n + o) under the balance heuristic whichever of the three
    /// techniques drew it (h: count 1; n: the counted one, at count c; o: a fixed count), the
    /// counted technique's where it runs (its weight c n / D over its count c): B x with B a
    /// Bernoulli draw of mean c, whose expectation c x and variance c (1 - c) x^2 go to A and B.
    /// It depends on one axis's count: every pair with that candidate gets the same terms.
    ///
    /// A pilot at count cp < 1 has the counted technique's draw with probability cp: each term
    /// of such a draw is divided by cp (unbiased over the pilot's draws), and the variance
    /// the pilot's own draw adds to the re-weighted estimate, c^2 (1 - cp) / cp x^2 in
    /// expectation, is taken out of B by its unbiased estimate c^2 (1 - cp) / cp^2 x^2.
    void add_contribution(Axis axis, float f_over_ref, float p_fixed, float p_counted, float p_other, float count,
                          float pilot_count, bool drawn_by_counted) noexcept {
        if (count != pilot_count) invalid_ = true;
        const double cp = pilot_count;
        double v1 = 0.0, d1 = 0.0;  // at the pilot's count
        if (!at_pilot(f_over_ref, p_fixed, p_counted, p_other, cp, v1, d1)) return;
        const double u = f_over_ref, h = p_fixed, n = p_counted, o = p_other;
        for (int j = 0; j < kCandidates; ++j) {
            const double c = candidate(j), d = h + c * n + o;
            if (!(d > 0.0))  // only the counted technique draws it: count 0 would lose it
                for (int i = 0; i < kCandidates; ++i)
                    lost_ |= std::uint64_t(1) << (axis == Axis::Nee ? pair(j, i) : pair(i, j));
            const double x = d > 0.0 ? u / d : 0.0;
            // The contribution's own second moment at count c, E[(its estimate)^2]: x^2 drawn by a
            // technique of fixed count, c x^2 by the counted one (the sum of its A and B parts).
            // Its expectation over the techniques is int f^2 / D(c), which u^2 / (D(1) D(c)) from
            // any technique's draw estimates too, with far less noise where the drawing technique
            // is the rare one; the difference goes into `diagonal` (expectation 0).
            const double own = drawn_by_counted ? c / cp * x * x : x * x;
            const double diagonal = (d > 0.0 ? u * u / (d1 * d) : 0.0) - own;
            const double delta = drawn_by_counted ? c / cp * x - v1 : x - v1;
            const double bernoulli =
                drawn_by_counted ? (c * (1.0 - c) / cp - c * c * (1.0 - cp) / (cp * cp)) * x * x : 0.0;
            for (int i = 0; i < kCandidates; ++i) {
                const std::size_t k = axis == Axis::Nee ? pair(j, i) : pair(i, j);
                path_diagonal_[k] += diagonal;
                path_delta_[k] += delta;
                path_bernoulli_[k] += bernoulli;
            }
        }
    }

    std::uint64_t lookups_ = 0, steps_ = 0, samples_ = 0, variance_samples_ = 0, z_n_ = 0, z_dof_ = 0;
    double fixed_work_ = 0.0, nee_work_ = 0.0, second_work_ = 0.0;
    int pixel_n_ = 0;
    bool invalid_ = false, nee_zero_refused_ = false;
    std::uint64_t lost_ = 0;  // a bit per pair: a recorded contribution's denominator is 0 there
    CostModel costs_;
    TechniqueCounts pilot_;
    Second second_ = Second::None;
    // The current sample, per pair: the change of its estimate from count 1, its Bernoulli
    // variance (and splats' second moments), its diagonal correction, its light subpath's
    // contributions to its own pixel.
    PerPair path_delta_{}, path_bernoulli_{}, path_diagonal_{}, light_sum_{};
    PerPair shift_{}, pixel_sum_{}, pixel_sum2_{};  // the current pixel
    PerPair variance_sum_{}, bernoulli_{};          // the tile
    // Over the pilot's samples (in groups of two or more), of z at each pair: its sum, and about
    // each group's mean its sum of squares and its products with z at counts 1 (both), with z at
    // the pair's second count and NEE count 1, and at its NEE count and second count 1; the
    // samples and the degrees of freedom (samples less groups).
    PerPair z_{}, z2_{}, z_at_1_{}, z_nee_at_1_{}, z_segment_at_1_{};
    std::array<SampleRecord, std::size_t(kGroupSize)> group_{};  // the current pixel's samples
    int group_n_ = 0;
};

static_assert(MisRecorder<NeeCountLearner>);
static_assert(BdptRecorder<NeeCountLearner>);

}  // namespace nsp
