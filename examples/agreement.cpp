// examples/agreement.cpp: the rows' agreement on the image mean (see agreement.hpp).
#include "agreement.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

namespace nsp_examples {

double z_score(const Row& row, const Row& reference) {
    return &row == &reference ? 0.0 : std::abs(row.mean - reference.mean) / std::hypot(row.se, reference.se);
}

bool flagged(const std::vector<Row>& rows, std::size_t i, std::size_t reference) {
    return z_score(rows[i], rows[reference]) > kFlagZ;
}

double cost(const std::vector<Row>& rows, std::size_t i) { return rows[i].cpu_seconds * rows[i].variance; }

double best_cost(const std::vector<Row>& rows, std::size_t reference, const std::vector<std::size_t>& among,
                 std::size_t* index) {
    double best = std::numeric_limits<double>::infinity();
    std::size_t at = rows.size();
    auto consider = [&](std::size_t i) {
        if (rows[i].variance > 0.0 && !flagged(rows, i, reference) && cost(rows, i) < best) best = cost(rows, i), at = i;
    };
    if (among.empty())
        for (std::size_t i = 0; i < rows.size(); ++i) consider(i);
    for (const std::size_t i : among) consider(i);
    if (index) *index = at;
    return at < rows.size() ? best : std::numeric_limits<double>::quiet_NaN();
}

void print_flag_notes(const std::vector<Row>& rows, std::size_t reference) {
    for (std::size_t i = 0; i < rows.size(); ++i)
        if (flagged(rows, i, reference))
            std::printf("! %s: its mean is %.3g combined standard errors from %s's: its variance estimate is not to "
                        "be trusted at this spp (a heavy tail it missed); left out of cpu/best and of every best row\n",
                        rows[i].name.c_str(), z_score(rows[i], rows[reference]), rows[reference].name.c_str());
}

}  // namespace nsp_examples
