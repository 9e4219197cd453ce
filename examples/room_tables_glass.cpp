// examples/room_tables_glass.cpp: nsp_room's table of the glass (the cloud inside a thin glass
// cube on a checkered floor beside a ball of rough glass, a lamp inside the smoke, under a sky
// image; Mono, one global majorant): every grey strategy of nsp::PathEstimator and BDPT through a
// partly null BSDF (the thin glass: reflected or passed straight through), a rough dielectric, a
// textured floor and an image light.
#include <algorithm>
#include <cstdio>

#include "agreement.hpp"
#include "room_rows.hpp"

namespace nsp_examples {

using namespace nsp;

// Half the pixels and spp: the dense smoke behind glass makes long paths.
RoomTable glass_table(const RoomOptions& o) {
    RoomTable t{.title = "Glass (mono",
                .scene = "the cloud in a thin glass cube on a checkered floor by a rough glass ball, a lamp in the smoke, a sky image",
                .sheet = "glass_sheet.png", .res = std::max(1, o.res / 2), .spp = std::max(2, o.spp / 2), .reference = 3};
    const auto glass = share(make_glass_scene());
    RowMaker rows(t, o, o.first_seed(29));
    rows.path(glass, PathEstimator<strategy::Unidirectional>{}, "unidirectional");
    rows.path(glass, PathEstimator<strategy::NextEvent>{}, "ratio-nee");
    rows.path(glass, PathEstimator<strategy::DirectionalMis, mis::Balance>{}, "directional-mis_balance");
    rows.path(glass, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_balance");
    rows.path(glass, PathEstimator<strategy::EquiangularNextEvent>{}, "equiangular-nee");
    rows.path(glass, PathEstimator<strategy::EquiangularMis, mis::Balance>{}, "equiangular-mis_balance");
    const std::uint64_t paired = rows.seed;
    rows.splatting(glass, BdptEstimator<bdpt::Directional, mis::Balance>{}, "bdpt_directional-mis_balance");
    rows.seed = paired;
    rows.splatting(glass, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
    rows.path(glass, PathEstimator<strategy::NullScatteringMis, mis::Power>{}, "uni-nee-mis_power");
    rows.seed = paired;
    rows.splatting(glass, BdptEstimator<bdpt::NullScattering, mis::Power>{}, "bdpt_null-mis_power");
    t.summary = [](const std::vector<Row>& r) {
        std::size_t single = 0;
        const double best_single = best_cost(r, 3, {0, 1}, &single);
        std::printf("glass: uni-nee-mis_balance / best single strategy (%s) in cpu-s*var: %.3g; bdpt_null-mis_balance "
                    "/ best path tracer: %.3g\n",
                    single < r.size() ? r[single].name.c_str() : "none", cost(r, 3) / best_single,
                    cost(r, 7) / best_cost(r, 3, {0, 1, 2, 3, 4, 5}));
    };
    return t;
}

}  // namespace nsp_examples
