// examples/report.cpp: what every table of nsp_render shares, and the grey tables (see report.hpp).
#include "report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace nsp_examples {

/// The rows and columns every table shares; returns the best (lowest positive) LTUV.
double print_rows(const TablePlan& t, const Options& o, const std::vector<Row>& rows, const Metrics& m) {
    const bool chromatic = t.scene.kind == SceneKind::Chromatic;
    // Best row: the lowest LTUV among rows that measured any variance (a strategy that never
    // found the light has variance 0 and an LTUV that means nothing).
    double best = std::numeric_limits<double>::infinity();
    for (const Row& r : rows)
        if (m.ltuv(r) > 0.0) best = std::min(best, m.ltuv(r));
    std::size_t width = 36;
    for (const Row& r : rows) width = std::max(width, r.c.name.size());
    const int wn = int(width);
    // DDA steps per sample: only where a row walks a grid majorant.
    const bool steps = std::any_of(rows.begin(), rows.end(), [](const Row& r) {
        return r.c.majorant.find("grid") != std::string::npos;
    });
    std::printf("%-*s %-13s %5s %8s %11s", wn, "estimator", "majorant", "spp", "seconds", "lookups/spl");
    if (steps) std::printf(" %9s", "steps/spl");
    std::printf(" %11s %11s %11s %9s", "var/spl", "LTUV", "cpu-s*var", "LTUV/best");
    if (o.runs > 1) std::printf(" %19s", "var/spl min..max");
    const bool effective = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.effective.empty(); });
    if (effective) std::printf(" %11s %11s %11s", "eff var/spl", "eff LTUV", "img eff var");
    std::printf(chromatic ? " %s\n" : " %9s\n", chromatic ? "mean R G B" : "mean");
    for (const Row& r : rows) {
        const double ltuv = m.ltuv(r);
        const bool measured = ltuv > 0.0 && std::isfinite(best);
        std::printf("%-*s %-13s %5d %8.2f %11s", wn, r.c.name.c_str(), r.c.majorant.c_str(), t.spp,
                    r.median([](const RenderStats& s) { return s.wall_seconds; }),
                    num(r.median([](const RenderStats& s) { return s.lookups_per_sample(); })).c_str());
        if (steps) std::printf(" %9s", num(r.median([](const RenderStats& s) { return s.steps_per_sample(); })).c_str());
        std::printf(" %11s %11s %11s %9s", num(m.var(r)).c_str(), num(ltuv).c_str(),
                    num(r.median([&](const RenderStats& s) { return m.time_variance(s); })).c_str(),
                    measured ? num(ltuv / best).c_str() : "n/a");
        if (o.runs > 1) {
            const auto [lo, hi] = r.range([&](const RenderStats& s) { return m.variance(s); });
            std::printf(" %19s", (num(lo) + ".." + num(hi)).c_str());
        }
        if (effective)
            std::printf(" %11s %11s %11s", num(Metrics::eff(r)).c_str(), num(Metrics::eff_ltuv(r)).c_str(),
                        num(Metrics::eff_image(r)).c_str());
        if (chromatic)
            std::printf(" %s %s %s\n", num(r.mean(0)).c_str(), num(r.mean(1)).c_str(), num(r.mean(2)).c_str());
        else
            std::printf(" %9s\n", num((r.mean(0) + r.mean(1) + r.mean(2)) / 3.0).c_str());
    }
    return best;
}

/// What the majorants of a table's rows are, when any is not the plain global or per-channel one.
void print_majorant_notes(const Options& o, const std::vector<Row>& rows) {
    const auto any = [&](auto pred) { return std::any_of(rows.begin(), rows.end(), pred); };
    if (any([](const Row& r) { return r.c.majorant.find("grid") != std::string::npos; })) {
        const long long n = o.majorant.grid_res;
        std::printf("grid majorants (grid, channel-grid, grid-*): %lldx%lldx%lld cells over the medium's box "
                    "(--grid-res), %lld KiB, each cell the density bound over it, walked by a DDA. steps/spl: DDA "
                    "steps (cells crossed, empty ones included) per sample; lookups/spl counts density lookups "
                    "only.\n", n, n, n, n * n * n * 4 / 1024);
    }
    if (any([](const Row& r) { return r.c.majorant == "grid-control"; }))
        std::printf("grid-control (nsp::GridControl): the grid majorant with each cell's density lower bound beside "
                    "it (two floats per cell); segments by decomposition tracking, shadow rays by residual ratio "
                    "tracking: lookups only for the density above each cell's minorant.\n");
    if (any([](const Row& r) { return r.c.majorant == "channel-grid-control"; }))
        std::printf("channel-grid-control (nsp::ChannelGridControl): the same cells with each channel's own majorant "
                    "and control; each channel tracks its own residual.\n");
    if (any([](const Row& r) { return !r.c.bounding; }))
        std::printf("non-bounding majorants (*-signed, *-clamp): %g x the bound (--majorant-scale), below the "
                    "extinction where the medium is dense. signed (bound::Signed): negative null weights, "
                    "unbiased; clamp (bound::Clamp): the density clamped to the majorant, biased by design.\n",
                    double(o.majorant.scale));
}

/// Rows that differ only in their majorant, against the same estimator with the table's reference
/// majorant of the same kind: per-channel for per-channel majorants, grid for the non-bounding
/// grids (when rendered), global otherwise. Prints the cost and variance ratios and how far apart
/// the image means are (they must agree for any unbiased pair; bound::Clamp is biased by design).
void print_majorant_comparison(const std::vector<Row>& rows, const Metrics& m) {
    bool header = false;
    for (const Row& r : rows) {
        auto same_estimator = [&](const std::string& majorant) {
            return std::find_if(rows.begin(), rows.end(), [&](const Row& x) {
                return x.c.key == r.c.key && x.c.majorant == majorant;
            });
        };
        std::string base_name = r.c.per_channel_majorant ? "per-channel" : "global";
        if (r.c.majorant.starts_with("grid-") && same_estimator("grid") != rows.end()) base_name = "grid";
        if (r.c.majorant == base_name) continue;
        const auto b = same_estimator(base_name);
        if (b == rows.end()) continue;
        if (!header)
            std::printf("majorants compared (ratio = row / same estimator with the reference majorant; < 1: the "
                        "row is cheaper or less noisy):\n");
        header = true;
        const auto med = [](const Row& x, auto f) { return x.median(f); };
        const auto ratio = [](double x, double y) { return y > 0.0 && std::isfinite(x / y) ? num(x / y) : "n/a"; };
        const auto lookups = [](const RenderStats& s) { return s.lookups_per_sample(); };
        const auto cpu = [](const RenderStats& s) { return s.cpu_seconds_per_sample(); };
        const auto [z, c] = mean_gap(r, *b);
        const bool few = r.nonzero() < kFewNonzero || b->nonzero() < kFewNonzero;
        const char* verdict = few ? " (too few nonzero samples to compare)"
                              : r.c.majorant.ends_with("clamp") ? (z > kMeanGap ? " (clamp: biased by design)" : "")
                              : z > kMeanGap ? " (TOO FAR APART: a bias or a heavy tail)"
                                             : "";
        std::printf("  %s vs %s, %s: lookups/spl %s, cpu-s/spl %s, var/spl %s, LTUV %s, cpu-s*var %s; image "
                    "means %.1f standard errors apart%s%s\n",
                    r.c.majorant.c_str(), base_name.c_str(), r.c.key.c_str(),
                    ratio(med(r, lookups), med(*b, lookups)).c_str(), ratio(med(r, cpu), med(*b, cpu)).c_str(),
                    ratio(m.var(r), m.var(*b)).c_str(), ratio(m.ltuv(r), m.ltuv(*b)).c_str(),
                    ratio(r.median([&](const RenderStats& s) { return m.time_variance(s); }),
                          b->median([&](const RenderStats& s) { return m.time_variance(s); }))
                        .c_str(),
                    z, r.c.channels != "grey" ? (std::string(" in ") + "RGB"[c]).c_str() : "",
                    verdict);
    }
}

/// For each row with learned NEE counts, how many tiles (of the first run) chose each count.
void print_learned_counts(const std::vector<Row>& rows) {
    for (const Row& r : rows) {
        if (!r.c.learned || r.runs.empty()) continue;
        const RenderRequest defaults;
        const int spp = r.runs[0].samples > 0 && !r.runs[0].nee_counts.empty()
                            ? int(r.runs[0].samples / std::uint64_t(std::max<std::size_t>(1, r.runs[0].pixels)))
                            : 0;
        std::printf("learned NEE counts (%s, %d-spp pilot at count %g per %dx%d tile, nsp::NeeCountLearner): tiles at",
                    r.c.name.c_str(), RenderRequest::pilot_spp(spp), double(r.runs[0].pilot_count), defaults.tile_size,
                    defaults.tile_size);
        auto histogram = [](const std::vector<float>& counts) {
            for (int j = 0; j < nsp::NeeCountLearner::kCandidates; ++j) {
                const float c = nsp::NeeCountLearner::candidate(j);
                const auto n = std::count(counts.begin(), counts.end(), c);
                if (n == 0) continue;
                if (c == 0.f) std::printf(" 0: %lld", (long long)n);
                else std::printf(" 1/%d: %lld", 1 << j, (long long)n);
            }
        };
        histogram(r.runs[0].nee_counts);
        if (!r.runs[0].segment_counts.empty()) {
            std::printf("; emission segment counts: tiles at");
            histogram(r.runs[0].segment_counts);
        }
        std::printf("\n");
    }
}

/// Footer lines every table shares: medians, status counts, majorants, rarely nonzero rows.
void print_common_footer(const TablePlan& t, const Options& o, const std::vector<Row>& rows) {
    if (o.runs > 1)
        std::printf("seconds, lookups/spl, var/spl, LTUV, cpu-s*var: MEDIAN over %d runs (seeds %llu..%llu), "
                    "LTUV/best from the median LTUV; min..max: var/spl over the runs; mean: over the runs.\n",
                    o.runs, (unsigned long long)o.seed, (unsigned long long)(o.seed + std::uint64_t(o.runs) - 1));
    std::uint64_t aborted = 0, nonfinite = 0, rejected = 0;
    for (const Row& r : rows)
        for (const RenderStats& s : r.runs) {
            aborted += s.aborted;
            nonfinite += s.nonfinite;
            rejected += s.rejected;
        }
    std::printf("paths with status Aborted: %llu, NonFinite: %llu, Rejected: %llu\n", (unsigned long long)aborted,
                (unsigned long long)nonfinite, (unsigned long long)rejected);
    print_majorant_notes(o, rows);
    if (o.lights.point)
        std::printf("note: the point light (--point) is reachable by next-event estimation only, so the "
                    "unidirectional rows leave out its light and their mean is lower\n");
    else if (t.scene.kind == SceneKind::Fog &&
             std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.c.strategy == "unidirectional"; }))
        std::printf("note: the lamp is a point light, reachable by next-event estimation only: the "
                    "unidirectional rows cannot see it\n");
    for (const Row& r : rows) {
        std::uint64_t samples = 0;
        for (const RenderStats& s : r.runs) samples += s.samples;
        if (r.nonzero() < kFewNonzero)
            std::printf("note: %s: only %llu of %llu samples were nonzero (the light is rarely found); its "
                        "variance and mean rest on those few and are themselves very noisy\n",
                        r.c.name.c_str(), (unsigned long long)r.nonzero(), (unsigned long long)samples);
    }
    print_learned_counts(rows);
}

/// What the eff var/spl columns are (--reference-spp), and the reference they were measured against.
void print_reference_footer(const TablePlan& t, const Options& o, const std::vector<Row>& rows,
                            const Reference& reference) {
    double smallest = std::numeric_limits<double>::infinity();
    for (const Row& r : rows)
        if (!r.effective.empty()) smallest = std::min(smallest, Metrics::eff(r));
    const double contrib = reference.contribution(t.spp);
    std::printf("eff var/spl: effective variance per sample against a reference image of this set-up, mode "
                "and resolution: %s, %d spp, seed %llu (independent of every row), %.1f s, var/spl %s. Per "
                "run: %d x mean over pixels and channels of (pixel mean - reference pixel mean)^2, minus the "
                "reference's own noise, %d x mean(var_ref/%d) = %s (%.1f%% of the lowest eff var/spl). For an "
                "unbiased estimator it is an unbiased estimate of %d x the image's MSE = its variance per "
                "sample; for a heavy-tailed one it also holds the error its sample variance misses. eff LTUV "
                "= lookups/spl x eff var/spl; img eff var: the same from the image mean's error, %d x %d "
                "pixels x mean over channels of (image mean - reference's)^2 minus the same reference term "
                "(3 degrees of freedom per run, noisy, but a tail missed in every pixel adds up there); all "
                "%s. Reference image mean R G B: %s %s %s.\n",
                reference.estimator.c_str(), reference.spp, (unsigned long long)reference.seed,
                reference.stats.wall_seconds, num(reference.stats.variance_per_channel()).c_str(), t.spp, t.spp,
                reference.spp, num(contrib).c_str(),
                std::isfinite(smallest) && smallest > 0.0 ? 100.0 * contrib / smallest : 0.0, t.spp, t.spp,
                t.width * t.height, o.runs > 1 ? ("median over " + std::to_string(o.runs) + " runs").c_str() : "one run",
                num(reference.stats.mean[0]).c_str(), num(reference.stats.mean[1]).c_str(),
                num(reference.stats.mean[2]).c_str());
}

/// Means that disagree: the per-pixel variances give each image mean a standard error, and a row
/// far from the best row is heavy-tailed (its sample variance understates its variance, and its
/// mean is low in most runs) or biased. `channels`: name the channel (not in mono tables).
void print_mean_notes(const std::vector<Row>& rows, const Metrics& m, bool channels) {
    const Row* ref = best_of(rows, m, [](const Row& r) { return r.nonzero() >= kFewNonzero; });
    for (const Row& r : rows) {
        if (!ref || &r == ref || r.nonzero() < kFewNonzero) continue;
        const auto [z, c] = mean_gap(r, *ref);
        if (z > kMeanGap)
            std::printf("note: %s: image mean %s%s is %.1f standard errors from %s's %s: a heavy tail (its var/spl "
                        "then understates the variance) or a bias\n", r.c.name.c_str(), num(r.mean(c)).c_str(),
                        channels ? (std::string(" in ") + "RGB"[c]).c_str() : "", z, ref->c.name.c_str(),
                        num(ref->mean(c)).c_str());
    }
}

/// The scene words of a grey table's title.
std::string scene_words(const SceneChoice& c) {
    switch (c.kind) {
        case SceneKind::Sparse: return "sparse medium, ";
        case SceneKind::Fog:
            return c.fog == FogSetup::F1 ? "thin fog, lamp inside, "
                   : c.fog == FogSetup::F2 ? "thin fog, lamp beside, "
                                           : "dense fog (40x F2's), lamp beside, ";
        case SceneKind::Plume: return "flame in the smoke (emissive medium), ";
        default: return "";
    }
}

void print_grey_table(const TablePlan& t, const Options& o, const std::vector<Row>& rows, const Reference* reference) {
    const Metrics m{false};
    std::printf("\nSet-up %s (%s%.*s, %dx%d, %d spp, %d threads%s)\n", t.scene.name(), scene_words(t.scene).c_str(),
                int(t.mode.size()), t.mode.data(), t.width, t.height, t.spp, o.threads,
                o.runs > 1 ? (", " + std::to_string(o.runs) + " runs").c_str() : "");
    print_rows(t, o, rows, m);
    std::printf("var/spl: per-pixel sample variance of the %d samples of each pixel (Welford)%s, averaged over "
                "the %d pixels.\n", t.spp,
                t.mode == nsp::Mono::name ? ""
                : t.mode == Hero4::name   ? " of the channel mean of its linear sRGB values"
                                          : " of the channel mean",
                t.width * t.height);
    std::printf("LTUV = lookups/spl x var/spl; cpu-s*var = thread CPU seconds per sample x var/spl; lower is "
                "better. mean: image mean (should agree across rows).\n");
    print_common_footer(t, o, rows);
    print_majorant_comparison(rows, m);
    if (reference) print_reference_footer(t, o, rows, *reference);
    if (t.scene.kind == SceneKind::Fog || t.scene.kind == SceneKind::Plume)
        print_mean_notes(rows, m, t.mode != nsp::Mono::name);
    if (t.scene.kind == SceneKind::Fog) return print_fog_summary(rows, m);
    if (t.scene.kind == SceneKind::Plume) return print_plume_summary(rows, m);
    // THEORY 7's claim, on the absorb-weight rows when present.
    const auto* uni = find_row(rows, "unidirectional_absorb-weight");
    const auto* nee = find_row(rows, "ratio-nee_absorb-weight");
    const auto* mis = find_row(rows, "uni-nee-mis_balance_absorb-weight");
    if (uni && m.ltuv(*uni) <= 0.0) return;  // unidirectional never found the light: no ratio
    if (uni && nee) std::printf("ratio-nee / unidirectional LTUV: %s", num(m.ltuv(*nee) / m.ltuv(*uni)).c_str());
    if (uni && nee && mis)
        std::printf("; uni-nee-mis_balance / best single strategy: %s",
                    num(m.ltuv(*mis) / std::min(m.ltuv(*uni), m.ltuv(*nee))).c_str());
    if (uni && nee) std::printf(" (absorb-weight rows)\n");
}

void print_table(const TablePlan& t, const Options& o, const std::vector<Row>& rows, const Reference* reference) {
    if (t.scene.kind == SceneKind::Chromatic) print_chromatic_table(t, o, rows, reference);
    else print_grey_table(t, o, rows, reference);
    std::fflush(stdout);
}

}  // namespace nsp_examples
