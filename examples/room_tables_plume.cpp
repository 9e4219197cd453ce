// examples/room_tables_plume.cpp: nsp_room's tables of the glowing plume in the room (the cloud's
// smoke with a flame in it, an emissive medium; Mono, half the size and spp: emission and the
// lights in one MIS) and of the lantern (the lamp boxed above the cloud, opening into it: the
// BDPT scene), the path tracers against BDPT with directional and null-scattering MIS.
#include <cstdio>

#include "agreement.hpp"
#include "room_rows.hpp"

namespace nsp_examples {

using namespace nsp;

RoomTable plume_table(const RoomOptions& o) {
    RoomTable t{.title = "Room, glowing plume (mono", .sheet = "room_plume_sheet.png", .res = std::max(1, o.res / 2),
                .spp = std::max(2, o.spp / 2), .reference = 2};
    using PlumeMedium = Emissive<DenseGridMedium<Mono>>;
    const PlumeMedium plume = make_plume_medium<Mono>();
    const auto room = share(make_room_scene(plume, GlobalMajorant<PlumeMedium>(plume)));
    RowMaker rows(t, o, o.first_seed(11));
    rows.path(room, PathEstimator<strategy::Unidirectional>{}, "unidirectional");
    rows.path(room, PathEstimator<strategy::NextEvent>{}, "ratio-nee");
    rows.path(room, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
    rows.path(room, PathEstimator<strategy::EquiangularMis, mis::Balance>{}, "equiangular-mis_balance");
    rows.splatting(room, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
    rows.learned_path(room);  // rows[5]
    EstimatorOptions no_seg = BdptEstimator<>::default_options();  // rows[6]: BDPT without its segment technique
    no_seg.emission_along_segments = false;
    rows.splatting(room, BdptEstimator<bdpt::NullScattering, mis::Balance>(no_seg), "bdpt_null-mis_balance_no-seg");
    t.summary = [](const std::vector<Row>& r) {
        std::size_t single = 0;
        const double best_single = best_cost(r, 2, {0, 1}, &single);
        std::printf("room plume: uni-nee-mis_balance / best single strategy (%s) in cpu-s*var: %.3g\n",
                    single < r.size() ? r[single].name.c_str() : "none", cost(r, 2) / best_single);
        std::printf("room plume: uni-nee-mis_balance_learned / best single strategy in cpu-s*var: %.3g\n",
                    cost(r, 5) / best_single);
        const double best_path = best_cost(r, 2, {0, 1, 2, 3, 5});
        std::printf("room plume: bdpt_null-mis_balance / best path tracer in cpu-s*var: %.3g; without the segment "
                    "technique: %.3g\n",
                    cost(r, 4) / best_path, cost(r, 6) / best_path);
    };
    return t;
}

// A quarter of the pixels (BDPT costs several paths a sample). Each null-scattering row takes its
// directional row's seed: the same subpaths (the weights draw no random numbers), so the pair
// differs by its weights alone (a paired comparison).
RoomTable lantern_table(const RoomOptions& o) {
    RoomTable t{.title = "Lantern (mono",
                .scene = "the cloud over a floor, lit only by a lamp in a box that opens downward into it",
                .sheet = "lantern_sheet.png", .res = std::max(1, o.res / 2), .spp = std::max(2, o.spp / 2), .reference = 4};
    const auto lantern = share(make_lantern_scene(make_default_medium<Mono>(),
                                                  GlobalMajorant<DenseGridMedium<Mono>>(make_default_medium<Mono>())));
    RowMaker rows(t, o, o.first_seed(13));
    rows.path(lantern, PathEstimator<strategy::Unidirectional>{}, "unidirectional");
    rows.path(lantern, PathEstimator<strategy::NextEvent>{}, "ratio-nee");
    rows.path(lantern, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
    const std::uint64_t paired = rows.seed;
    rows.splatting(lantern, BdptEstimator<bdpt::Directional, mis::Balance>{}, "bdpt_directional-mis_balance");
    rows.seed = paired;
    rows.splatting(lantern, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
    rows.splatting(lantern, BdptEstimator<bdpt::NullScattering, mis::Power>{}, "bdpt_null-mis_power");
    const std::uint64_t paired_no_t1 = rows.seed;  // without light tracing: radiance() along the camera's rays
    rows.path(lantern, BdptEstimator<bdpt::Directional, mis::Balance>{}, "bdpt_directional-mis_balance_no-t1");
    rows.seed = paired_no_t1;
    rows.path(lantern, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance_no-t1");
    rows.learned_bdpt(lantern, room_pinhole(), "bdpt_null-mis_balance_learned", bdpt::Grey{});
    t.summary = [](const std::vector<Row>& r) {
        std::printf("lantern: bdpt_null-mis_balance / bdpt_directional-mis_balance in cpu-s*var: %.3g (without light "
                    "tracing: %.3g); / best path tracer: %.3g\n",
                    cost(r, 4) / cost(r, 3), cost(r, 7) / cost(r, 6), cost(r, 4) / best_cost(r, 4, {0, 1, 2}));
        std::printf("lantern: bdpt_null-mis_balance_learned / bdpt_null-mis_balance in cpu-s*var: %.3g\n",
                    cost(r, 8) / cost(r, 4));
    };
    return t;
}

}  // namespace nsp_examples
