// examples/room_report.hpp: what nsp_room prints and writes: a table per RoomTable (room_plan.hpp)
// with its summary lines and notes, and the contact sheets.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "image_row.hpp"
#include "room_plan.hpp"

namespace nsp_examples {

/// Prints table `t` over its rendered `rows` (seconds, lookups, var/spl, LTUV, cpu-s*var and
/// cpu/best, mean and z against the reference row; a row with z > 4 marked "!" and left out of
/// cpu/best), then the flagged rows' notes, its summary lines and its rows' notes. Returns the
/// number of paths with a failed status.
std::uint64_t print_table(const RoomTable& t, const std::vector<Row>& rows, int threads);

/// Writes DIR/<sheet> with rows [from, to) of `rows` (their images at one exposure, numbered from
/// 1); nothing when the range is empty. Returns the path written, or "".
std::string write_sheet(const std::string& dir, const std::string& sheet, const std::vector<Row>& rows, std::size_t from,
                        std::size_t to);

}  // namespace nsp_examples
