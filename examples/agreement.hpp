// examples/agreement.hpp: whether the rows of an nsp_room or nsp_volume table agree on the image's
// mean. Every row estimates the same image, so a row whose mean lies many combined standard
// errors from the reference row's (the table's MIS row) has a standard error that is too small:
// its sample variance missed a heavy tail (a light it rarely finds, at a low spp). Such a row is
// flagged, and its time x variance, which rests on that variance, is left out of "best".
#pragma once

#include <cstddef>
#include <vector>

#include "image_row.hpp"

namespace nsp_examples {

/// A row is flagged when its z (below) exceeds this.
inline constexpr double kFlagZ = 4.0;

/// |mean - reference's mean| in combined standard errors of the two image means; 0 for the
/// reference itself (infinite when the means differ and both errors are 0).
double z_score(const Row& row, const Row& reference);

/// Whether row `i` is flagged: z > kFlagZ against rows[reference].
bool flagged(const std::vector<Row>& rows, std::size_t i, std::size_t reference);

/// CPU seconds x variance of row i: what cpu-s*var orders by (per sample, up to a common factor).
double cost(const std::vector<Row>& rows, std::size_t i);

/// The lowest cost() among rows `among` (every row when empty) that found something (variance > 0)
/// and are not flagged; NaN when none is left (so that a ratio to it reads "nan", not a number).
/// With `index`, the row that has it (or rows.size()).
double best_cost(const std::vector<Row>& rows, std::size_t reference, const std::vector<std::size_t>& among = {},
                 std::size_t* index = nullptr);

/// One line per flagged row, for under its table: how far its mean is, and that its variance
/// estimate is not to be trusted at this spp.
void print_flag_notes(const std::vector<Row>& rows, std::size_t reference);

}  // namespace nsp_examples
