// examples/room_tables_grey.cpp: nsp_room's tables of the grey room (the cloud over a floor under a
// quad lamp and a dim sky; Mono, one global majorant): every grey strategy of nsp::PathEstimator
// that renders surfaces, BDPT and uni + NEE MIS with learned counts; on request BDPT with light
// subpaths from the sky; and the room's picture.
#include <cstdio>

#include "agreement.hpp"
#include "room_rows.hpp"

namespace nsp_examples {

using namespace nsp;

RoomTable grey_table(const RoomOptions& o) {
    RoomTable t{.title = "Room (mono", .sheet = "room_sheet.png", .res = o.res, .spp = o.spp, .reference = 4};
    const auto grey = share(make_room_scene());
    RowMaker rows(t, o, o.first_seed(1));
    rows.path(grey, PathEstimator<strategy::Unidirectional>{}, "unidirectional");
    rows.path(grey, PathEstimator<strategy::NextEvent>{}, "ratio-nee");
    rows.path(grey, PathEstimator<strategy::DirectionalMis, mis::Balance>{}, "directional-mis_balance");
    rows.path(grey, PathEstimator<strategy::DirectionalMis, mis::Power>{}, "directional-mis_power");
    rows.path(grey, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
    rows.path(grey, PathEstimator<strategy::NullScatteringMis, mis::Power>{}, "uni-nee-mis_power");
    rows.path(grey, PathEstimator<strategy::EquiangularNextEvent>{}, "equiangular-nee");  // aimed at the lamp's centre
    rows.path(grey, PathEstimator<strategy::EquiangularMis, mis::Balance>{}, "equiangular-mis_balance");
    rows.splatting(grey, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
    rows.learned_path(grey);  // rows[9]; appended, so the rows above keep their seeds
    t.summary = [](const std::vector<Row>& r) {
        std::size_t single = 0;
        const double best_single = best_cost(r, 4, {0, 1}, &single);
        std::printf("room: uni-nee-mis_balance / best single strategy (%s) in cpu-s*var: %.3g; unidirectional / "
                    "ratio-nee: %.3g\n",
                    single < r.size() ? r[single].name.c_str() : "none", cost(r, 4) / best_single, cost(r, 0) / cost(r, 1));
        std::printf("room: uni-nee-mis_balance_learned / best single strategy in cpu-s*var: %.3g\n", cost(r, 9) / best_single);
        std::printf("room: bdpt_null-mis_balance / best path tracer in cpu-s*var: %.3g\n",
                    cost(r, 8) / best_cost(r, 4, {0, 1, 2, 3, 4, 5, 6, 7, 9}));
    };
    return t;
}

// The grey room, BDPT with the sky reached by hits and NEE alone against BDPT whose light
// subpaths also start from the sky (a BoundingSphere).
RoomTable sky_table(const RoomOptions& o) {
    RoomTable t{.title = "Room, light subpaths from the sky (mono", .sheet = "room_sky_sheet.png", .res = o.res,
                .spp = o.spp, .reference = 0};
    const auto grey = share(make_room_scene());
    const auto sky_room = share(make_room_scene(true));
    RowMaker rows(t, o, o.first_seed(29));
    rows.path(grey, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
    rows.splatting(grey, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
    rows.splatting(sky_room, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance_sky-subpaths");
    t.summary = [](const std::vector<Row>& r) {
        std::printf("sky: bdpt with sky subpaths / without in cpu-s*var: %.3g; / uni-nee-mis_balance: %.3g\n",
                    cost(r, 2) / cost(r, 1), cost(r, 2) / cost(r, 0));
    };
    return t;
}

RoomRow room_picture(const RoomOptions& o) {
    const auto grey = share(make_room_scene());
    return {"room.png", [grey, res = o.picture_res, threads = o.threads](int spp) {
                return render_image(*grey, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "picture", res, spp,
                                    threads, 99, [](float u, float v) { return room_camera_ray(u, v, 1.f); });
            }};
}

}  // namespace nsp_examples
