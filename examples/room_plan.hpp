// examples/room_plan.hpp: nsp_room's render plan: which rows each table renders, at which size and
// seeds, and the lines printed under it. Each table is one function in a room_tables_*.cpp file
// (its scene, its rows and its summary lines side by side); room_tables() lists them in the
// order they run, so a new table is a function there and a line in room_plan.cpp. The whole plan
// is made before the first render, so the progress lines count every render of the run.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "image_row.hpp"
#include "room_cli.hpp"

namespace nsp_examples {

/// One render of a table: its row's name and how to render it at `spp` samples per pixel (the
/// table's; a pilot renders fewer to time it) at the table's size with its seed.
struct RoomRow {
    std::string name;
    std::function<Row(int spp)> render;
};

/// One table: its rows, the row the z column compares with, the lines printed under it.
struct RoomTable {
    std::string title;  ///< the header's start, e.g. "Room (mono" (the size, spp and threads follow)
    std::string scene = "the cloud over a floor, a quad light and a sky";
    std::string sheet;  ///< the contact sheet its rows go to (tables with the same one share it)
    int res = 0, spp = 0;
    std::size_t reference = 0;  ///< the MIS row
    std::vector<RoomRow> rows{};
    /// The summary lines after the table (the rows' notes follow them); may be empty.
    std::function<void(const std::vector<Row>&)> summary{};
};

// The tables, one function each (room_tables_*.cpp).
RoomTable grey_table(const RoomOptions& o);
RoomTable sky_table(const RoomOptions& o);
RoomTable rgb_table(const RoomOptions& o);
RoomTable lantern_rgb_table(const RoomOptions& o);
RoomTable plume_table(const RoomOptions& o);
RoomTable lantern_table(const RoomOptions& o);
RoomTable glass_table(const RoomOptions& o);
std::vector<RoomTable> cloud_tables(const RoomOptions& o);
std::vector<RoomTable> empty_tables(const RoomOptions& o);

/// The tables --tables asks for, in the order they run: grey, rgb, plume, lantern, lantern-rgb,
/// glass, sky, cloud, empty.
std::vector<RoomTable> room_tables(const RoomOptions& o);

/// DIR/room.png's render: the grey room with uni + NEE MIS (balance), --picture-res pixels square,
/// seed 99, at kRoomPictureSpp.
RoomRow room_picture(const RoomOptions& o);
inline constexpr int kRoomPictureSpp = 128;

}  // namespace nsp_examples
