// examples/room_tables_cloud.cpp: nsp_room's tables of the main job's cloud in empty space (on
// request, --tables cloud: set-ups A and B) as a SurfaceScene whose sphere light is a shape the
// geometry reports, through nsp_render's camera: the path tracers against BDPT with light
// tracing, plain, with a fixed light subpath probability and with its counts learned; then
// uni + NEE MIS and BDPT under a grid control.
#include <algorithm>
#include <cstdio>

#include "agreement.hpp"
#include "combinations.hpp"
#include "room_rows.hpp"

namespace nsp_examples {

using namespace nsp;

std::vector<RoomTable> cloud_tables(const RoomOptions& o) {
    std::vector<RoomTable> tables;
    for (const LightSetup setup : {LightSetup::A, LightSetup::B}) {
        const bool a = setup == LightSetup::A;
        RoomTable& t = tables.emplace_back(RoomTable{
            .title = a ? "Cloud, set-up A (mono" : "Cloud, set-up B (mono",
            .scene = a ? "the main job's cloud in empty space, a small bright sphere light above it"
                       : "the main job's cloud in empty space, a large dim sphere light behind it",
            .sheet = "cloud_bdpt_sheet.png", .res = std::max(1, o.res / 2), .spp = std::max(2, o.spp / 2), .reference = 2});
        const auto cloud = share(make_cloud_surface_scene(setup));
        const PinholeCamera camera = cloud_pinhole();
        RowMaker rows(t, o, o.first_seed(a ? 17 : 23));
        rows.pinhole(cloud, camera, PathEstimator<strategy::Unidirectional>{}, "unidirectional");
        rows.pinhole(cloud, camera, PathEstimator<strategy::NextEvent>{}, "ratio-nee");
        rows.pinhole(cloud, camera, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
        rows.pinhole(cloud, camera, BdptEstimator<bdpt::Directional, mis::Balance>{}, "bdpt_directional-mis_balance");
        rows.pinhole(cloud, camera, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
        rows.pinhole(cloud, camera, BdptEstimator<bdpt::NullScattering, mis::Balance>(BdptEstimator<>::default_options(), {}, 0.25f),
                     "bdpt_null-mis_balance_light-0.25");  // a light subpath on 1/4 of the samples
        rows.learned_bdpt(cloud, camera, "bdpt_null-mis_balance_learned", bdpt::Grey{});
        // Under a grid control of 16^3 (decomposition tracking, residual ratio tracking: THEORY 5.10),
        // nsp_render's default grid resolution.
        const auto controlled =
            share(make_setup_surface_scene<Mono, DenseGridCloud, GridControlPolicy>(SceneChoice{SceneKind::Cloud, setup}));
        rows.pinhole(controlled, camera, PathEstimator<strategy::NullScatteringMis, mis::Balance>{},
                     "uni-nee-mis_balance_grid-control");
        rows.pinhole(controlled, camera, BdptEstimator<bdpt::NullScattering, mis::Balance>{},
                     "bdpt_null-mis_balance_grid-control");
        t.summary = [name = a ? "A" : "B"](const std::vector<Row>& r) {
            const double best_path = best_cost(r, 2, {0, 1, 2});
            std::printf("cloud %s: bdpt_null-mis_balance / best path tracer in cpu-s*var: %.3g; / "
                        "bdpt_directional-mis_balance: %.3g\n",
                        name, cost(r, 4) / best_path, cost(r, 4) / cost(r, 3));
            std::printf("cloud %s: bdpt_null-mis_balance_learned / best path tracer in cpu-s*var: %.3g\n", name,
                        cost(r, 6) / best_path);
            std::printf("cloud %s under a grid control: uni-nee-mis_balance / best path tracer in cpu-s*var: %.3g; "
                        "bdpt_null-mis_balance / bdpt_null-mis_balance without: %.3g\n",
                        name, cost(r, 7) / best_path, cost(r, 8) / cost(r, 4));
        };
    }
    return tables;
}

}  // namespace nsp_examples
