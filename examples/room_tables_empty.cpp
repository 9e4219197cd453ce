// examples/room_tables_empty.cpp: nsp_room's tables of nsp_render's other scenes in empty space,
// as SurfaceScenes through its camera (on request, --tables empty: the set-ups SA, F1-F3, C1, C2
// and P1): the path tracers against BDPT with light tracing, plain and with its counts learned
// over the image, and uni + NEE MIS and BDPT under a grid control.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <string>
#include <type_traits>

#include "agreement.hpp"
#include "combinations.hpp"
#include "room_rows.hpp"

namespace nsp_examples {

using namespace nsp;

namespace {

/// The path tracers stop at BDPT's 32 real vertices too, so that every row estimates the same
/// integral (at the default 1000, C1's image is 0.1% brighter: 4 SE of BDPT's at 512 spp).
const EstimatorOptions kDepth = BdptEstimator<>::default_options();

/// The empty table of set-up `c` (its rows still to add): half the size and spp, z against row 2.
/// Its summary: BDPT and every row after it against the best of the first `n_path` rows (the
/// path tracers).
RoomTable empty_table(const SceneChoice& c, const char* mode, std::size_t n_path, const RoomOptions& o) {
    RoomTable t{.title = std::string(c.name()) + " in empty space (" + mode,
                .scene = "nsp_render's scene as a SurfaceScene, every row's paths at most 32 real vertices",
                .sheet = "empty_bdpt_sheet.png", .res = std::max(1, o.res / 2), .spp = std::max(2, o.spp / 2),
                .reference = 2};
    t.summary = [name = c.name(), n_path](const std::vector<Row>& r) {
        std::vector<std::size_t> paths(n_path);
        for (std::size_t i = 0; i < n_path; ++i) paths[i] = i;
        const double best = best_cost(r, 2, paths);
        std::printf("%s: bdpt / best path tracer in cpu-s*var: %.3g; bdpt learned: %.3g", name, cost(r, n_path) / best,
                    cost(r, n_path + 1) / best);
        for (std::size_t i = n_path + 2; i < r.size(); ++i) std::printf("; %s: %.3g", r[i].name.c_str(), cost(r, i) / best);
        std::printf("\n");
    };
    return t;
}

/// The first seed of set-up c: 37 + 100 i, i its place in SA, F1-F3, C1, C2, P1, so that --setups
/// renders a set-up as the whole table does.
std::uint64_t first_empty_seed(const SceneChoice& c, const RoomOptions& o) {
    static constexpr const char* order[] = {"SA", "F1", "F2", "F3", "C1", "C2", "P1"};
    const auto at = std::find_if(std::begin(order), std::end(order), [&](const char* n) { return std::string(n) == c.name(); });
    return o.first_seed(37 + 100 * std::uint64_t(at - std::begin(order)));
}

bool wanted(const SceneChoice& c, const RoomOptions& o) {
    return std::find(o.setups.begin(), o.setups.end(), c.name()) != o.setups.end();
}

/// The grey pdfs' rows of scene `sc`: the path tracers (with the equiangular one when
/// `equiangular`), BDPT, BDPT learned (and then, where a point light gives BDPT its equiangular
/// strategy, BDPT without it; where an emitting medium gives BDPT its segment technique, BDPT
/// without that; with `fixed_light` BDPT with that light subpath probability), and last uni + NEE
/// MIS and BDPT on `controlled`, the scene under a grid control of the same cells (THEORY 5.10).
template <class Sc, class CtlSc, bool kEquiangular>
RoomTable grey_empty_table(std::shared_ptr<const Sc> sc, std::shared_ptr<const CtlSc> controlled, const SceneChoice& c,
                           const char* mode, std::bool_constant<kEquiangular>, const RoomOptions& o,
                           float fixed_light = 0.f) {
    RoomTable t = empty_table(c, mode, kEquiangular ? 4 : 3, o);
    const PinholeCamera camera = cloud_pinhole();
    RowMaker rows(t, o, first_empty_seed(c, o));
    rows.pinhole(sc, camera, PathEstimator<strategy::Unidirectional>(kDepth), "unidirectional");
    rows.pinhole(sc, camera, PathEstimator<strategy::NextEvent>(kDepth), "ratio-nee");
    rows.pinhole(sc, camera, PathEstimator<strategy::NullScatteringMis, mis::Balance>(kDepth), "uni-nee-mis_balance");
    if constexpr (kEquiangular)
        rows.pinhole(sc, camera, PathEstimator<strategy::EquiangularMis, mis::Balance>(kDepth), "uni-nee-eq-mis_balance");
    rows.pinhole(sc, camera, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance");
    rows.learned_bdpt(sc, camera, "bdpt_null-mis_balance_learned", bdpt::Grey{});
    // BDPT with one of its strategies off (`off` clears its option), on the seed the next row
    // takes too: the rows after it keep the seeds they had before it.
    auto without = [&](auto off, const char* name) {
        EstimatorOptions opt = kDepth;
        off(opt);
        const std::uint64_t next = rows.seed;
        rows.pinhole(sc, camera, BdptEstimator<bdpt::NullScattering, mis::Balance>(opt), name);
        rows.seed = next;
    };
    bool point_light = false;  // without its equiangular strategy, where it has one (a point light)
    for (int k = 0; k < sc->lights.equiangular_count(); ++k) point_light = point_light || sc->lights.equiangular_is_delta(k);
    if (point_light) without([](EstimatorOptions& opt) { opt.bdpt_equiangular = false; }, "bdpt_null-mis_balance_no-eq");
    if constexpr (EmissiveMedium<typename Sc::MediumType>)  // without its segment technique (an emitting medium)
        without([](EstimatorOptions& opt) { opt.emission_along_segments = false; }, "bdpt_null-mis_balance_no-seg");
    if (fixed_light > 0.f)  // a fixed light subpath probability, after the learned row
        rows.pinhole(sc, camera, BdptEstimator<bdpt::NullScattering, mis::Balance>(kDepth, {}, fixed_light),
                     "bdpt_null-mis_balance_light-1/" + std::to_string(int(std::lround(1.f / fixed_light))));
    rows.pinhole(controlled, camera, PathEstimator<strategy::NullScatteringMis, mis::Balance>(kDepth),
                 "uni-nee-mis_balance_grid-control");
    rows.pinhole(controlled, camera, BdptEstimator<bdpt::NullScattering, mis::Balance>{}, "bdpt_null-mis_balance_grid-control");
    return t;
}

/// C1 (a white sky) or C2 (set-up A's sphere light): Rgb, per-channel majorants, the spectral path
/// tracers against per-channel BDPT; then both under a grid control, and spectral MIS + NEE under
/// the per-channel grid and the per-channel grid control.
RoomTable chromatic_empty_table(const SceneChoice& c, const RoomOptions& o) {
    RoomTable t = empty_table(c, "rgb, per-channel majorants", 3, o);
    const auto sc = share(make_setup_surface_scene<Rgb, DenseGridCloud, ChannelMajorantPolicy>(c));
    const PinholeCamera camera = cloud_pinhole();
    RowMaker rows(t, o, first_empty_seed(c, o));
    rows.pinhole(sc, camera, SpectralPathEstimator<channels::SpectralMis, strategy::Unidirectional>(kDepth),
                 "unidirectional_spectral-mis");
    rows.pinhole(sc, camera, SpectralPathEstimator<channels::SpectralMis, strategy::NextEvent>(kDepth), "ratio-nee_spectral-mis");
    rows.pinhole(sc, camera, SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>(kDepth),
                 "uni-nee-mis_spectral-mis");
    rows.pinhole(sc, camera, SpectralBdptEstimator<mis::Balance>{}, "bdpt_spectral-mis");
    rows.learned_bdpt(sc, camera, "bdpt_spectral-mis_learned", channels::SpectralMis{});
    if (c.chromatic == ChromaticSetup::Env) {
        // C1 without roulette: under the sky every path that escapes carries its throughput, so
        // roulette's survival on it adds more variance than it saves work.
        EstimatorOptions no_rr = kDepth;
        no_rr.russian_roulette = false;
        rows.pinhole(sc, camera, SpectralPathEstimator<channels::SpectralMis, strategy::Unidirectional>(no_rr),
                     "unidirectional_spectral-mis_no-rr");
        rows.learned_bdpt(sc, camera, "bdpt_spectral-mis_learned_no-rr", channels::SpectralMis{}, false);
    }
    // Under a grid control of the medium's cells (a grey majorant with each cell's minorant; the
    // loop's control is the smallest channel's): spectral MIS + NEE and per-channel BDPT by
    // decomposition and residual ratio tracking (THEORY 5.10).
    const auto controlled = share(make_setup_surface_scene<Rgb, DenseGridCloud, GridControlPolicy>(c));
    rows.pinhole(controlled, camera,
                 SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>(kDepth),
                 "uni-nee-mis_spectral-mis_grid-control");
    rows.pinhole(controlled, camera, SpectralBdptEstimator<mis::Balance>{}, "bdpt_spectral-mis_grid-control");
    // Under each channel's own majorant and control over the same cells (ChannelGridControl): the
    // per-channel grid alone, then with its control (spectral MIS + NEE; per-channel BDPT takes a
    // grey majorant's control only).
    const auto channel_grid = share(make_setup_surface_scene<Rgb, DenseGridCloud, ChannelGridMajorantPolicy>(c));
    rows.pinhole(channel_grid, camera,
                 SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>(kDepth),
                 "uni-nee-mis_spectral-mis_channel-grid");
    const auto channel_controlled = share(make_setup_surface_scene<Rgb, DenseGridCloud, ChannelGridControlPolicy>(c));
    rows.pinhole(channel_controlled, camera,
                 SpectralPathEstimator<channels::SpectralMis, strategy::NullScatteringMis, mis::Balance>(kDepth),
                 "uni-nee-mis_spectral-mis_channel-grid-control");
    return t;
}

}  // namespace

std::vector<RoomTable> empty_tables(const RoomOptions& o) {
    std::vector<RoomTable> tables;
    // Grey: the sparse medium under set-up A's light, the fog under its lamp; grid majorants (16^3).
    for (const SceneChoice c : {SceneChoice{SceneKind::Sparse, LightSetup::A}, SceneChoice{SceneKind::Fog, {}, {}, FogSetup::F1},
                                SceneChoice{SceneKind::Fog, {}, {}, FogSetup::F2}, SceneChoice{SceneKind::Fog, {}, {}, FogSetup::F3}})
        if (wanted(c, o))
            tables.push_back(grey_empty_table(share(make_setup_surface_scene<Mono, DenseGridCloud, GridMajorantPolicy<>>(c)),
                                              share(make_setup_surface_scene<Mono, DenseGridCloud, GridControlPolicy>(c)),
                                              c, "mono, grid majorant", std::true_type{}, o));
    for (const SceneChoice c : {SceneChoice{SceneKind::Chromatic, {}, ChromaticSetup::Env},
                                SceneChoice{SceneKind::Chromatic, {}, ChromaticSetup::Small}})
        if (wanted(c, o)) tables.push_back(chromatic_empty_table(c, o));
    // The plume (an emissive medium, no other light); Rgb (its flame's colour), grid majorant;
    // BDPT also with light subpaths on 1/64 of the samples.
    if (const SceneChoice c{SceneKind::Plume}; wanted(c, o))
        tables.push_back(grey_empty_table(share(make_setup_surface_scene<Rgb, EmissivePlume, GridMajorantPolicy<>>(c)),
                                          share(make_setup_surface_scene<Rgb, EmissivePlume, GridControlPolicy>(c)), c,
                                          "rgb, grid majorant", std::false_type{}, o, 1.f / 64.f));
    return tables;
}

}  // namespace nsp_examples
