// examples/stats.hpp: the statistics of nsp_render's tables: a rendered row and its runs, the
// variance each table reports, effective variances against a reference image (--reference-spp)
// and how far apart two rows' image means are.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plan.hpp"
#include "render_job.hpp"

namespace nsp_examples {

/// The median of `v` (the mean of the two middle values for an even count; NaN when empty).
double median_of(std::vector<double> v);

/// A rendered row: its runs.
struct Row {
    Candidate c;
    std::vector<RenderStats> runs;
    /// With --reference-spp, per run: the effective variance per sample (see effective_variance).
    std::vector<double> effective;
    /// With --reference-spp, per run: the same from the error of the image mean (effective_image_variance).
    std::vector<double> effective_image;

    /// The median over runs of metric f.
    template <class F>
    double median(F f) const {
        std::vector<double> v;
        for (const RenderStats& r : runs) v.push_back(f(r));
        return median_of(std::move(v));
    }
    /// The smallest and largest value over runs of metric f.
    template <class F>
    std::pair<double, double> range(F f) const {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const RenderStats& r : runs) {
            lo = std::min(lo, f(r));
            hi = std::max(hi, f(r));
        }
        return {lo, hi};
    }
    /// Channel c's image mean over the runs, and its standard error (from the per-pixel variances).
    double mean(int ch) const;
    double standard_error(int ch) const;
    /// Nonzero samples over all runs.
    std::uint64_t nonzero() const;
};

/// The statistics of one table: which variance it reports (see the footers).
struct Metrics {
    bool per_channel = false;  ///< per-channel variance (chromatic) or variance of the channel mean (cloud)

    double variance(const RenderStats& r) const { return per_channel ? r.variance_per_channel() : r.variance_of_mean; }
    double ltuv(const RenderStats& r) const { return r.lookups_per_sample() * variance(r); }
    double time_variance(const RenderStats& r) const { return r.cpu_seconds_per_sample() * variance(r); }

    double var(const Row& row) const { return row.median([&](const RenderStats& r) { return variance(r); }); }
    double ltuv(const Row& row) const { return row.median([&](const RenderStats& r) { return ltuv(r); }); }

    /// With --reference-spp: the median over runs of the effective variance per sample, of the
    /// same from the image mean, and the effective LTUV (lookups/spl x effective variance of the
    /// same run); NaN without a reference.
    static double eff(const Row& row) { return median_of(row.effective); }
    static double eff_image(const Row& row) { return median_of(row.effective_image); }
    static double eff_ltuv(const Row& row);
};

/// Time x variance of a row: the median over its runs of thread CPU seconds per sample x var/spl,
/// or x eff var/spl of the same run when the table has a reference (--reference-spp).
double time_variance(const Row& r, const Metrics& m);

/// The reference image of --reference-spp for one table, and what it cost.
struct Reference {
    std::string estimator;  ///< the row name of the estimator that rendered it
    int spp = 0;
    std::uint64_t seed = 0;
    RenderStats stats;  ///< with pixel_mean and pixel_variance
    /// spp_row x the mean over pixels and channels of var_ref / spp_ref: what the reference's own
    /// noise adds, in expectation, to spp_row x the squared error against it.
    double contribution(int spp_row) const;
};

/// The effective variance per sample of one run: spp x (mean over pixels and channels of
/// (pixel mean - reference pixel mean)^2) - the reference's contribution. For an unbiased
/// estimator independent of the reference this is an unbiased estimate of spp x the image's
/// mean squared error, i.e. of its variance per sample when that is finite; for a heavy-tailed
/// one it includes the error of the rare huge samples its sample variance misses in this run.
double effective_variance(const RenderStats& run, int spp, const Reference& ref);

/// The effective variance per sample from the error of the image mean: spp x pixels x (mean over
/// channels of (image mean - reference image mean)^2) - the same reference contribution (the
/// pixels are independent, so for an unbiased estimator its expectation is again the variance
/// per sample). Only 3 degrees of freedom per run, so noisy; but where a heavy-tailed estimator
/// misses the same rare samples in every pixel, its per-pixel errors add up coherently here,
/// while per pixel they hide under the sampling noise of 'spp' samples.
double effective_image_variance(const RenderStats& run, int spp, const Reference& ref);

/// Below this many nonzero samples a row's statistics rest on too few samples to mean much.
constexpr std::uint64_t kFewNonzero = 1000;

/// More standard errors than this between two rows' image means is reported (see mean_gap).
constexpr double kMeanGap = 4.0;

/// How far apart the image means of rows a and b are: the largest over channels of
/// |mean_a - mean_b| / sqrt(se_a^2 + se_b^2), and that channel.
std::pair<double, int> mean_gap(const Row& a, const Row& b);

/// The row named `name`, or nullptr.
const Row* find_row(const std::vector<Row>& rows, std::string_view name);

/// The row of estimator `key` (its name without the majorant) with majorant `majorant`, or nullptr.
const Row* find_row(const std::vector<Row>& rows, std::string_view key, std::string_view majorant);

/// The lowest-LTUV row among `rows` that `pred` accepts (nullptr if none measured a variance).
template <class P>
const Row* best_of(const std::vector<Row>& rows, const Metrics& m, P pred) {
    const Row* best = nullptr;
    for (const Row& r : rows)
        if (pred(r) && m.ltuv(r) > 0.0 && (!best || m.ltuv(r) < m.ltuv(*best))) best = &r;
    return best;
}

/// The majorants of `rows`, in the order they first appear.
std::vector<std::string> majorants_of(const std::vector<Row>& rows);

/// `v` with 3 significant digits.
std::string num(double v);

/// a / b with 3 significant digits, or "n/a" when b is not positive or the ratio not finite.
std::string ratio_text(double a, double b);

/// A row's estimator without its absorption policy, e.g. uni-nee-eq-mis_balance.
std::string without_absorption(const std::string& key);

}  // namespace nsp_examples
