// examples/room_cli.cpp: nsp_room's flags (see room_cli.hpp), parsed with CLI11 through
// parse_flags (tool.hpp): every value checked here, with a message that names the flag.
#include "room_cli.hpp"

#include <thread>

#include <CLI/CLI.hpp>

#include "tool.hpp"

namespace nsp_examples {

RoomOptions parse_room_flags(int argc, char** argv) {
    RoomOptions o;
    o.threads = int(std::max(1u, std::thread::hardware_concurrency()));
    CLI::App app("nsp_room: the cloud over a floor in an open room, every surface strategy, one efficiency table "
                 "per scene. Exits 0, 1 if a path ended with a failed status or a write failed, 2 on a bad "
                 "command line.",
                 "nsp_room");
    app.add_option("--res", o.res, "image width and height in pixels")->check(integer_in(1, 4096));
    app.add_option("--spp", o.spp, "samples per pixel")->check(integer_in(2, 1 << 20));
    app.add_option("--threads", o.threads, "worker threads")->check(integer_in(1, 256));
    app.add_option("--out", o.out, "directory for the PNG pictures, created if missing");
    app.add_option("--picture-res", o.picture_res, "size of room.png")->check(integer_in(16, 4096));
    app.add_flag("--no-png", o.no_png, "write no pictures");
    app.add_option("--seed", o.seed, "added to every row's seed (independent runs), 0 to 10^12")
        ->check(integer_in(0, 1'000'000'000'000));
    app.add_option("--tables", o.tables,
                   "which tables to render (default: grey,rgb,plume,lantern,lantern-rgb,glass; cloud: the main job's cloud, set-ups A "
                   "and B, with BDPT; sky: the grey room's BDPT with and without light subpaths from the sky; empty: "
                   "nsp_render's other scenes, SA, F1-F3, C1, C2, P1, with BDPT)")
        ->check(CLI::IsMember({"grey", "rgb", "plume", "lantern", "lantern-rgb", "glass", "cloud", "sky", "empty"}))
        ->delimiter(',');
    app.add_option("--setups", o.setups, "with --tables empty: which of nsp_render's set-ups to render (default: all)")
        ->check(CLI::IsMember({"SA", "F1", "F2", "F3", "C1", "C2", "P1"}))
        ->delimiter(',');
    parse_flags(app, argc, argv);
    return o;
}

}  // namespace nsp_examples
