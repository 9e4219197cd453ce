// examples/room_plan.cpp: the order of nsp_room's tables (see room_plan.hpp).
#include "room_plan.hpp"

namespace nsp_examples {

std::vector<RoomTable> room_tables(const RoomOptions& o) {
    std::vector<RoomTable> tables;
    auto add = [&](const char* name, auto make) {
        if (!o.wants(name)) return;
        if constexpr (std::is_same_v<decltype(make(o)), RoomTable>) tables.push_back(make(o));
        else for (RoomTable& t : make(o)) tables.push_back(std::move(t));
    };
    add("grey", grey_table);
    add("rgb", rgb_table);
    add("plume", plume_table);
    add("lantern", lantern_table);
    add("lantern-rgb", lantern_rgb_table);
    add("glass", glass_table);
    add("sky", sky_table);
    add("cloud", cloud_tables);
    add("empty", empty_tables);
    return tables;
}

}  // namespace nsp_examples
