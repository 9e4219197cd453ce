// examples/room.cpp: nsp_room, the main job's scene with surfaces (room_scene.hpp): the cloud over
// a diffuse floor in an open room under a small rectangular light and a dim sky, rendered over an
// nsp::SurfaceScene with the efficiency tables the other scenes have (docs/surfaces.md reads
// them): the grey cloud (Mono, 96x96 by default) with every strategy of nsp::PathEstimator that
// renders surfaces (the equiangular ones aimed at the lamp's centre) and nsp::BdptEstimator, then
// the chromatic cloud (Rgb, half the size and spp) with the grey-majorant PathEstimator against
// nsp::SpectralPathEstimator's per-channel pdfs and grey BDPT against nsp::SpectralBdptEstimator,
// then the glowing plume (the cloud's smoke with a flame in it, an emissive medium; Mono, half
// the size and spp) with emission and lights in one MIS, then the lantern (the lamp boxed above
// the cloud, opening into it: the BDPT scene; half the size and spp) with the path tracers
// against BdptEstimator's directional and null-scattering MIS and BDPT with its expected counts
// learned (_learned: nsp::NeeCountLearner over the image), then the chromatic lantern (the
// chromatic cloud in it; Rgb) with the spectral path tracers against BDPT with one pdf
// (directional and null-scattering MIS) and with every channel's pdfs, then the glass (the
// cloud in a thin glass cube on a checkered floor, a lamp in the smoke, a sky image; Mono, half
// the size and spp) with every grey path tracer and BDPT. The grey room's and the
// plume's tables end with uni + NEE MIS at counts learned per 16x16 tile. On request (--tables
// cloud) the main job's cloud in empty space, set-ups A and B, as a SurfaceScene (its sphere
// light a shape the geometry reports), path tracers against BDPT; (--tables sky) the grey room's
// BDPT with and without light subpaths from the sky; (--tables empty) nsp_render's other scenes.
//
//   nsp_room [--res N] [--spp N] [--threads N] [--out DIR] [--no-png] [--picture-res N]
//            [--tables grey,rgb,plume,lantern,lantern-rgb,glass,cloud,sky,empty] [--setups ...] [--seed N]
//
// The files, one concern each: room_cli (the flags), room_plan (which tables run, in order) and
// room_tables_*.cpp (each table's scene, rows and summary lines; the render loops are
// instantiated there, spread over several files that compile in parallel), room_report (the
// tables and sheets); this file runs the plan, with a progress line per render on stderr.
//
// Writes DIR/room_sheet.png, DIR/room_rgb_sheet.png, DIR/room_plume_sheet.png,
// DIR/lantern_sheet.png, DIR/lantern_rgb_sheet.png and DIR/glass_sheet.png (each table's rows
// at one exposure; with --tables sky, cloud or empty also DIR/room_sky_sheet.png, DIR/cloud_bdpt_sheet.png,
// DIR/empty_bdpt_sheet.png) and DIR/room.png (the grey room, uni-nee-mis balance, 128 spp,
// --picture-res pixels square) unless --no-png; DIR is created, and checked to be writable,
// before the first render.
//
// Exit codes (tool.hpp, the same in nsp_render and nsp_volume): 0; 1 if a path ended with a
// status other than Ok or a write failed; 2 on a bad command line (an unknown flag, a bad value,
// an --out that cannot be created or written), with a message that names the flag.
#include <cstdio>
#include <iterator>
#include <utility>
#include <string>
#include <vector>

#include "png_writer.hpp"
#include "progress.hpp"
#include "room_cli.hpp"
#include "room_plan.hpp"
#include "room_report.hpp"
#include "tool.hpp"

namespace {

using namespace nsp_examples;

int run(int argc, char** argv) {
    const RoomOptions o = parse_room_flags(argc, argv);
    if (!o.no_png) require_writable_directory("--out", o.out);
    const std::vector<RoomTable> tables = room_tables(o);
    const bool picture = !o.no_png && o.wants("grey");

    // Every render, in order, with its spp; each timed first with a pilot at 1/64 of its spp for
    // the estimate of the time left (progress.hpp).
    std::vector<std::pair<const RoomRow*, int>> renders;
    Progress progress;
    for (const RoomTable& t : tables)
        for (const RoomRow& r : t.rows) {
            renders.emplace_back(&r, t.spp);
            progress.add(double(t.res) * t.res * t.spp);
        }
    const RoomRow picture_row = room_picture(o);
    if (picture) {
        renders.emplace_back(&picture_row, kRoomPictureSpp);
        progress.add(double(o.picture_res) * o.picture_res * kRoomPictureSpp);
    }
    std::fprintf(stderr, "nsp_room: %zu renders in %zu tables on %d threads; timing each at 1/64 of its spp\n",
                 renders.size(), tables.size(), o.threads);
    double pilots = 0.0;
    for (std::size_t i = 0; i < renders.size(); ++i) {
        const int spp = Progress::pilot_spp(renders[i].second);
        const Row pilot = renders[i].first->render(spp);
        progress.calibrate(i, double(pilot.image.width) * pilot.image.height * spp, pilot.seconds);
        pilots += pilot.seconds;
    }
    std::fprintf(stderr, "nsp_room: about %s to render (the timing took %.1f s)\n",
                 Progress::duration_text(progress.seconds_left()).c_str(), pilots);

    std::vector<Row> all;
    std::uint64_t failed = 0;
    auto exit_code = [&] {
        if (failed == 0) return kExitOk;
        std::fprintf(stderr, "nsp_room: %llu paths ended with a status other than Ok\n", (unsigned long long)failed);
        return kExitRuntime;
    };
    std::size_t id = 0;
    for (const RoomTable& t : tables) {
        std::vector<Row> rows;
        for (const RoomRow& r : t.rows) {
            rows.push_back(r.render(t.spp));
            progress.done(id++, r.name, rows.back().seconds);
        }
        failed += print_table(t, rows, o.threads);
        all.insert(all.end(), std::make_move_iterator(rows.begin()), std::make_move_iterator(rows.end()));
    }
    if (o.no_png) return exit_code();

    // One contact sheet per group of tables that name the same sheet, each at one exposure.
    std::fflush(stdout);  // the tables before any failed write's message
    std::size_t start = 0, end = 0;
    for (std::size_t i = 0; i < tables.size(); ++i) {
        end += tables[i].rows.size();
        if (i + 1 == tables.size() || tables[i + 1].sheet != tables[i].sheet) {
            if (const std::string path = write_sheet(o.out, tables[i].sheet, all, start, end); !path.empty())
                std::fprintf(stderr, "  room: %s\n", path.c_str());
            start = end;
        }
    }
    if (picture) {
        const Row row = picture_row.render(kRoomPictureSpp);
        progress.done(id++, "room.png", row.seconds);
        const std::string path = o.out + "/room.png";
        write_png(path, row.image, exposure_for({&row.image}));
        std::fprintf(stderr, "  room: %s\n", path.c_str());
    }
    return exit_code();
}

}  // namespace

int main(int argc, char** argv) {
    return run_tool("nsp_room", [&] { return run(argc, argv); });
}
