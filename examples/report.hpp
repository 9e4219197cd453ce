// examples/report.hpp: the tables nsp_render prints, one per set-up and spectral mode, and the
// summary at the end of a run. report.cpp has what every table shares (the rows, the footers,
// the grey tables); report_scenes.cpp the analyses particular to a scene (the chromatic cloud's
// comparisons, the fog's and the plume's summaries) and the end-of-run summary.
#pragma once

#include <string>
#include <vector>

#include "cli.hpp"
#include "plan.hpp"
#include "stats.hpp"

namespace nsp_examples {

/// Prints the table of `t`: print_grey_table or print_chromatic_table. `reference`: the
/// --reference-spp image, or nullptr.
void print_table(const TablePlan& t, const Options& o, const std::vector<Row>& rows, const Reference* reference);

/// One line for the end-of-run summary: the table's best row (lowest LTUV) and its scene's MIS
/// estimator against the best single strategy, in LTUV and time x variance.
std::string summary_line(const TablePlan& t, const std::vector<Row>& rows);

// The pieces of a table, for the tables of report.cpp and report_scenes.cpp.

/// "a, b, c": a metric of every run.
template <class F>
std::string per_run(const Row& row, F f) {
    std::string s;
    for (const RenderStats& r : row.runs) s += (s.empty() ? "" : ", ") + num(f(r));
    return s;
}


/// The rows and columns every table shares; returns the best (lowest positive) LTUV.
double print_rows(const TablePlan& t, const Options& o, const std::vector<Row>& rows, const Metrics& m);
/// What the majorants of a table's rows are, when any is not the plain global or per-channel one.
void print_majorant_notes(const Options& o, const std::vector<Row>& rows);
/// Rows that differ only in their majorant, against the same estimator with the reference majorant.
void print_majorant_comparison(const std::vector<Row>& rows, const Metrics& m);
/// Footer lines every table shares: medians, status counts, majorants, rarely nonzero rows.
void print_common_footer(const TablePlan& t, const Options& o, const std::vector<Row>& rows);
/// What the eff var/spl columns are (--reference-spp), and the reference they were measured against.
void print_reference_footer(const TablePlan& t, const Options& o, const std::vector<Row>& rows,
                            const Reference& reference);
/// Rows whose image mean is far (kMeanGap standard errors) from the best row's.
void print_mean_notes(const std::vector<Row>& rows, const Metrics& m, bool channels);

/// The tables of the grey scenes (cloud, sparse, fog, plume) and of the chromatic cloud.
void print_grey_table(const TablePlan& t, const Options& o, const std::vector<Row>& rows, const Reference* reference);
void print_chromatic_table(const TablePlan& t, const Options& o, const std::vector<Row>& rows,
                           const Reference* reference);
/// The fog's question (THEORY 5.4) and the plume's (THEORY 5.7), per majorant.
void print_fog_summary(const std::vector<Row>& rows, const Metrics& m);
void print_plume_summary(const std::vector<Row>& rows, const Metrics& m);

}  // namespace nsp_examples
