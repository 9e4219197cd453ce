// examples/report_scenes.cpp: the analyses particular to one scene (the chromatic cloud's
// comparisons, the fog's and the plume's summaries) and the end-of-run summary (see report.hpp).
#include "report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "catalogue.hpp"

namespace nsp_examples {

/// The fog's question (THEORY 5.4), per majorant: which single vertex sampler wins in time x
/// variance, tracking + NEE or equiangular + NEE, and how far the three-way MIS is from it.
void print_fog_summary(const std::vector<Row>& rows, const Metrics& m) {
    const bool eff = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.effective.empty(); });
    for (const std::string& maj : majorants_of(rows)) {
        const Row* nee = find_row(rows, "ratio-nee_absorb-weight", maj);
        const Row* eq = find_row(rows, "equiangular-nee_absorb-weight", maj);
        if (!nee || !eq) continue;
        const double tn = time_variance(*nee, m), te = time_variance(*eq, m);
        const bool eq_best = te < tn;
        const double best = std::min(tn, te);
        std::printf("%s majorant, time x variance (%s): ratio-nee %s, equiangular-nee %s -> best single strategy: "
                    "%s (%sx lower)", maj.c_str(), eff ? "cpu-s/spl x eff var/spl" : "cpu-s*var", num(tn).c_str(),
                    num(te).c_str(), eq_best ? "equiangular-nee" : "ratio-nee",
                    ratio_text(std::max(tn, te), best).c_str());
        for (const char* key : {"uni-nee-eq-mis_balance_absorb-weight", "uni-nee-eq-mis_power_absorb-weight",
                                "uni-nee-mis_balance_absorb-weight"})
            if (const Row* r = find_row(rows, key, maj))
                std::printf("; %s / best single: %s", without_absorption(r->c.key).c_str(),
                            ratio_text(time_variance(*r, m), best).c_str());
        std::printf("\n");
    }
}

/// The plume's question (THEORY 5.7), per majorant: the collision estimator alone against NEE
/// toward the emitting volume combined with it by MIS, in time x variance and LTUV (effective
/// ones with a reference).
void print_plume_summary(const std::vector<Row>& rows, const Metrics& m) {
    const bool eff = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.effective.empty(); });
    const auto ltuv = [&](const Row& r) { return r.effective.empty() ? m.ltuv(r) : Metrics::eff_ltuv(r); };
    for (const std::string& maj : majorants_of(rows)) {
        const Row* uni = find_row(rows, "unidirectional_absorb-weight", maj);
        if (!uni) continue;
        std::string line;
        for (const char* key : {"uni-nee-mis_balance_absorb-weight", "uni-nee-mis_power_absorb-weight",
                                "ratio-nee_absorb-weight"})
            if (const Row* r = find_row(rows, key, maj))
                line += std::string(line.empty() ? "" : "; ") + without_absorption(r->c.key) + " " +
                        ratio_text(time_variance(*uni, m), time_variance(*r, m)) + "x (LTUV " +
                        ratio_text(ltuv(*uni), ltuv(*r)) + "x)";
        if (!line.empty())
            std::printf("%s majorant, collision estimator alone (unidirectional) / each row, time x variance (%s): "
                        "%s\n", maj.c_str(), eff ? "cpu-s/spl x eff var/spl" : "cpu-s*var", line.c_str());
    }
}

void print_chromatic_table(const TablePlan& t, const Options& o, const std::vector<Row>& rows,
                           const Reference* reference) {
    const Metrics m{true};
    std::printf("\nSet-up %s (chromatic 1:4:16, %.*s, %dx%d, %d spp, %d threads%s)\n", t.scene.name(),
                int(t.mode.size()), t.mode.data(), t.width, t.height, t.spp, o.threads,
                o.runs > 1 ? (", " + std::to_string(o.runs) + " runs").c_str() : "");
    print_rows(t, o, rows, m);
    const bool hero = t.mode == Hero4::name;
    std::printf("var/spl: per-channel sample variance of the %d samples of each pixel (Welford)%s, averaged over "
                "the 3 channels and the %d pixels; the variance of the channel mean would hide independent "
                "tracking's colour noise.\n", t.spp, hero ? " of its linear sRGB values" : "", t.width * t.height);
    std::printf("LTUV = lookups/spl x var/spl; cpu-s*var = thread CPU seconds per sample x var/spl; lower is "
                "better. mean R G B: image mean per channel%s (should agree across rows).\n",
                hero ? " (linear sRGB)" : "");
    std::printf("Rows without a channel policy are nsp::PathEstimator with the grey (global) majorant; _lum: "
                "luminance channel selection, otherwise uniform.\n");
    print_common_footer(t, o, rows);
    print_majorant_comparison(rows, m);
    if (reference) print_reference_footer(t, o, rows, *reference);
    print_mean_notes(rows, m, true);

    const std::string runs_note = o.runs > 1 ? "median over " + std::to_string(o.runs) + " runs"
                                             : "one run; the baseline is heavy-tailed, see --runs, --reference-spp";
    // (a) spectral MIS + NEE (each majorant) against the grey-majorant baseline of the same mode.
    const Row* base = find_row(rows, "uni-nee-mis_balance_absorb-weight");
    std::vector<std::pair<std::string, const Row*>> compared;
    for (const char* majorant : {"per-channel", "global"})
        for (const char* suffix : {"", "_lum"}) {
            const Row* smis = find_row(rows, std::string("uni-nee-mis_spectral-mis_") + majorant +
                                                 "_balance_absorb-weight" + suffix);
            if (!base || !smis) continue;
            const auto [z, c] = mean_gap(*base, *smis);
            const std::string label = std::string("spectral-mis ") + majorant + " + NEE" + (*suffix ? " lum" : "");
            std::printf("baseline / %s: var/spl %s, LTUV %s (%s); image means %.1f standard errors apart in %c%s\n",
                        label.c_str(), num(m.var(*base) / m.var(*smis)).c_str(),
                        num(m.ltuv(*base) / m.ltuv(*smis)).c_str(), runs_note.c_str(), z, "RGB"[c],
                        z > kMeanGap ? " (too far apart: a heavy tail of the baseline, whose var/spl then "
                                       "understates its variance, or a bias)"
                                     : "");
            if (!base->effective.empty() && !smis->effective.empty()) {
                std::string each;  // run i of both rows used the same seed
                for (std::size_t i = 0; i < base->effective.size() && i < smis->effective.size(); ++i)
                    each += (each.empty() ? "" : ", ") + num(base->effective[i] / smis->effective[i]);
                std::string each_image;
                for (std::size_t i = 0; i < base->effective_image.size() && i < smis->effective_image.size(); ++i)
                    each_image += (each_image.empty() ? "" : ", ") +
                                  num(base->effective_image[i] / smis->effective_image[i]);
                std::printf("  against the reference: eff var/spl %s, eff LTUV %s, img eff var %s (%s)%s%s\n",
                            num(Metrics::eff(*base) / Metrics::eff(*smis)).c_str(),
                            num(Metrics::eff_ltuv(*base) / Metrics::eff_ltuv(*smis)).c_str(),
                            num(Metrics::eff_image(*base) / Metrics::eff_image(*smis)).c_str(),
                            o.runs > 1 ? ("ratio of the medians over " + std::to_string(o.runs) + " runs").c_str()
                                       : "one run",
                            o.runs > 1 ? ("; eff var/spl ratio per run: " + each).c_str() : "",
                            o.runs > 1 ? ("; img eff var ratio per run: " + each_image).c_str() : "");
            }
            compared.emplace_back(label, smis);
        }
    if (o.runs > 1 && !compared.empty()) {
        auto runs_of = [&](const Row& r) {
            std::string v = per_run(r, [&](const RenderStats& s) { return m.variance(s); });
            if (!r.effective.empty()) {
                std::string e, g;
                for (const double x : r.effective) e += (e.empty() ? "" : ", ") + num(x);
                for (const double x : r.effective_image) g += (g.empty() ? "" : ", ") + num(x);
                v += "; eff var/spl " + e + "; img eff var " + g;
            }
            return v;
        };
        std::printf("  per run, var/spl: baseline %s\n", runs_of(*base).c_str());
        for (const auto& [label, r] : compared) std::printf("  per run, var/spl: %s %s\n", label.c_str(), runs_of(*r).c_str());
    }
    // (b) the best of each channel policy, and the best overall, by LTUV.
    struct Family {
        const char* label;
        std::function<bool(const Row&)> pred;
    };
    const std::vector<Family> families{
        {"independent", [](const Row& r) { return r.c.channels == "independent"; }},
        {"spectral tracking", [](const Row& r) { return r.c.channels.starts_with("spectral-tracking"); }},
        {"spectral MIS", [](const Row& r) { return r.c.channels == "spectral-mis" && r.c.strategy != "uni-nee-mis"; }},
        {"spectral MIS + NEE",
         [](const Row& r) { return r.c.channels == "spectral-mis" && r.c.strategy == "uni-nee-mis"; }},
    };
    std::string line;
    std::vector<std::pair<double, const char*>> bests;
    for (const Family& f : families) {
        const Row* r = best_of(rows, m, f.pred);
        if (!r) continue;
        line += std::string(line.empty() ? "" : "; ") + f.label + " " + num(m.ltuv(*r)) + " (" + r->c.name + ")";
        bests.emplace_back(m.ltuv(*r), f.label);
    }
    if (!bests.empty()) {
        std::sort(bests.begin(), bests.end());
        std::string close;  // within 10% of the lowest: no ranking at this noise level
        for (std::size_t i = 1; i < bests.size(); ++i)
            if (bests[i].first <= 1.1 * bests[0].first)
                close += std::string(close.empty() ? "" : ", ") + bests[i].second;
        std::printf("best LTUV per channel policy: %s -> lowest: %s%s\n", line.c_str(), bests[0].second,
                    close.empty() ? "" : (" (within 10%: " + close + ")").c_str());
    }
    // (c) luminance against uniform selection, row by row.
    std::string sel;
    for (const Row& r : rows) {
        if (r.c.selection != SelectionRule::Luminance) continue;
        const Row* u = find_row(rows, r.c.name.substr(0, r.c.name.size() - 4));
        if (u && m.ltuv(*u) > 0.0)
            sel += std::string(sel.empty() ? "" : "; ") + u->c.name + " " + num(m.ltuv(r) / m.ltuv(*u));
    }
    if (!sel.empty()) std::printf("luminance / uniform selection, LTUV: %s\n", sel.c_str());
}

std::string summary_line(const TablePlan& t, const std::vector<Row>& rows) {
    const SceneEntry& e = scene_entry(t.scene.kind);
    const Metrics m{t.scene.kind == SceneKind::Chromatic};
    // With a reference (--reference-spp) the effective variances, as the table's own summaries.
    const auto ltuv = [&](const Row& r) { return r.effective.empty() ? m.ltuv(r) : Metrics::eff_ltuv(r); };
    const auto tv = [&](const Row& r) { return time_variance(r, m); };
    // The lowest positive value of `f` among the rows `pred` accepts (nullptr if none measured one).
    const auto lowest = [&](auto f, auto pred) {
        const Row* best = nullptr;
        for (const Row& r : rows)
            if (pred(r) && f(r) > 0.0 && std::isfinite(f(r)) && (!best || f(r) < f(*best))) best = &r;
        return best;
    };
    const auto any = [](const Row&) { return true; };
    const auto is_mis = [&](const Row& r) { return r.c.key == e.mis_key; };
    const auto is_single = [&](const Row& r) {
        return std::find(e.single_keys.begin(), e.single_keys.end(), r.c.key) != e.single_keys.end();
    };
    std::string line = std::string(t.scene.name()) + " (" + std::string(t.mode) + "): ";
    const Row* best = lowest(ltuv, any);
    line += best ? "lowest LTUV " + best->c.name : "no row measured a variance";
    const Row* mis_l = lowest(ltuv, is_mis);
    const Row* single_l = lowest(ltuv, is_single);
    const Row* mis_t = lowest(tv, is_mis);
    const Row* single_t = lowest(tv, is_single);
    if (mis_l && single_l && mis_t && single_t)
        line += "; MIS / best single strategy: LTUV " + ratio_text(ltuv(*mis_l), ltuv(*single_l)) + " (" +
                mis_l->c.name + " / " + single_l->c.name + "), time x variance " +
                ratio_text(tv(*mis_t), tv(*single_t)) + (mis_t == mis_l && single_t == single_l
                                                             ? std::string()
                                                             : " (" + mis_t->c.name + " / " + single_t->c.name + ")");
    // The same MIS with NEE counts learned per tile (nsp::NeeCountLearner), where the table has it.
    const auto is_learned = [&](const Row& r) { return r.c.key == e.mis_key + "_learned"; };
    const Row* learned_t = lowest(tv, is_learned);
    const Row* learned_l = lowest(ltuv, is_learned);
    if (learned_t && learned_l && single_t && single_l)
        line += "; learned NEE counts / best single: time x variance " + ratio_text(tv(*learned_t), tv(*single_t)) +
                " (" + learned_t->c.name + "), LTUV " + ratio_text(ltuv(*learned_l), ltuv(*single_l));
    if (best && !best->effective.empty()) line += "; effective variances";
    return line;
}

}  // namespace nsp_examples
