// examples/room_cli.hpp: nsp_room's command line: the options of a run and their parser (CLI11).
// docs/renderer.md explains the flags; --help is the one-screen summary.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace nsp_examples {

/// Everything a run of nsp_room is asked to do.
struct RoomOptions {
    int res = 96, spp = 256, threads = 1, picture_res = 256;
    std::string out = "out";
    bool no_png = false;
    std::uint64_t seed = 0;  ///< --seed: added (x 1000) to every row's seed
    std::vector<std::string> tables{"grey", "rgb", "plume", "lantern", "lantern-rgb", "glass"};
    std::vector<std::string> setups{"SA", "F1", "F2", "F3", "C1", "C2", "P1"};  ///< with --tables empty

    bool wants(const std::string& table) const { return std::find(tables.begin(), tables.end(), table) != tables.end(); }
    /// The first seed of a table whose own first seed is `base`: runs 1000 apart share none.
    std::uint64_t first_seed(std::uint64_t base) const { return base + 1000 * seed; }
};

/// Parses the command line; throws UsageError (tool.hpp) naming the bad flag or value; prints
/// the help and exits 0 on --help.
RoomOptions parse_room_flags(int argc, char** argv);

}  // namespace nsp_examples
