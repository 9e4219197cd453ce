// examples/room_tables_rgb.cpp: nsp_room's tables of the chromatic cloud (extinction 5, 20, 80 per
// unit density; Rgb, half the size and spp): in the room, the grey-majorant PathEstimator against
// SpectralPathEstimator's per-channel pdfs and grey BDPT against SpectralBdptEstimator; in the
// lantern, the spectral path tracers against BDPT with one pdf and with every channel's pdfs.
#include <cstdio>

#include "agreement.hpp"
#include "room_rows.hpp"

namespace nsp_examples {

using namespace nsp;
using ChromaticMedium = DenseGridMedium<Rgb>;

RoomTable rgb_table(const RoomOptions& o) {
    // The chromatic cloud costs about 4x the lookups: half the size, half the spp.
    RoomTable t{.title = "Room, chromatic cloud (rgb", .sheet = "room_rgb_sheet.png", .res = std::max(1, o.res / 2),
                .spp = std::max(2, o.spp / 2), .reference = 3};
    const ChromaticMedium chroma = make_chromatic_medium<Rgb>();
    const auto chroma_grey = share(make_room_scene(chroma, GlobalMajorant<ChromaticMedium>(chroma)));
    const auto chroma_channel = share(make_room_scene(chroma, ChannelMajorant<ChromaticMedium>(chroma)));
    RowMaker rows(t, o, o.first_seed(7));  // each table its own seeds: a row added to one leaves the others' numbers
    rows.path(chroma_grey, PathEstimator<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis_grey_balance");
    rows.path(chroma_grey, SpectralPathEstimator<channels::SpectralTrackingAverage, strategy::NullScatteringMis, mis::Balance>{},
              "uni-nee-mis_spectral-tracking-avg");
    rows.path(chroma_grey, SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>{},
              "uni-nee-mis_spectral-mis_global");
    rows.path(chroma_channel, SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>{},
              "uni-nee-mis_spectral-mis_per-channel");
    // BDPT (light tracing on), grey pdfs under the grey majorant and per-channel pdfs under the
    // per-channel majorant; appended, so the rows above keep their seeds.
    rows.splatting(chroma_grey, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_grey_balance");
    rows.splatting(chroma_channel, SpectralBdptEstimator<mis::Balance>{}, "bdpt_spectral-mis_per-channel");
    rows.learned_bdpt(chroma_channel, room_pinhole(), "bdpt_spectral-mis_per-channel_learned", channels::SpectralMis{});
    t.summary = [](const std::vector<Row>& r) {
        std::printf("room chromatic: grey-majorant PathEstimator / spectral MIS (per-channel majorant) in cpu-s*var: %.3g "
                    "(the grey estimator's variance is practically infinite on this medium: its sample variance "
                    "understates it; docs/chromatic.md)\n",
                    cost(r, 0) / cost(r, 3));
        std::printf("room chromatic: bdpt_spectral-mis_per-channel / uni-nee-mis_spectral-mis_per-channel in cpu-s*var: "
                    "%.3g; / bdpt_null-mis_grey_balance: %.3g\n",
                    cost(r, 5) / cost(r, 3), cost(r, 5) / cost(r, 4));
        std::printf("room chromatic: bdpt_spectral-mis_per-channel_learned / bdpt_spectral-mis_per-channel in "
                    "cpu-s*var: %.3g\n",
                    cost(r, 6) / cost(r, 5));
    };
    return t;
}

// Directional MIS has no distance pdfs, so no per-channel pdfs either: on a chromatic medium it
// weighs every channel alike.
RoomTable lantern_rgb_table(const RoomOptions& o) {
    RoomTable t{.title = "Lantern, chromatic cloud (rgb",
                .scene = "the chromatic cloud over a floor, lit only by a lamp in a box that opens downward into it",
                .sheet = "lantern_rgb_sheet.png", .res = std::max(1, o.res / 2), .spp = std::max(2, o.spp / 2),
                .reference = 1};
    const ChromaticMedium chroma = make_chromatic_medium<Rgb>();
    const auto lantern_grey = share(make_lantern_scene(chroma, GlobalMajorant<ChromaticMedium>(chroma)));
    const auto lantern_channel = share(make_lantern_scene(chroma, ChannelMajorant<ChromaticMedium>(chroma)));
    RowMaker rows(t, o, o.first_seed(31));
    rows.path(lantern_channel, SpectralPathEstimator<channels::SpectralMis, strategy::Unidirectional>{},
              "unidirectional_spectral-mis_per-channel");
    rows.path(lantern_channel, SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>{},
              "uni-nee-mis_spectral-mis_per-channel");
    const std::uint64_t paired = rows.seed;  // the grey pair on the same subpaths, as in the lantern's table
    rows.splatting(lantern_grey, BdptEstimator<bdpt::Directional, mis::Balance>{}, "bdpt_directional-mis_grey_balance");
    rows.seed = paired;
    rows.splatting(lantern_grey, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_grey_balance");
    rows.splatting(lantern_channel, SpectralBdptEstimator<mis::Balance>{}, "bdpt_spectral-mis_per-channel");
    t.summary = [](const std::vector<Row>& r) {
        std::printf("lantern chromatic: bdpt_spectral-mis_per-channel / bdpt_directional-mis_grey_balance in cpu-s*var: "
                    "%.3g; / best path tracer: %.3g (the grey-pdf rows' variance is practically infinite on this medium: "
                    "their sample variance understates it; docs/chromatic.md)\n",
                    cost(r, 4) / cost(r, 2), cost(r, 4) / best_cost(r, 1, {0, 1}));
    };
    return t;
}

}  // namespace nsp_examples
