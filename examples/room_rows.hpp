// examples/room_rows.hpp: how nsp_room's tables add their rows (room_plan.hpp): RowMaker turns a
// scene and an estimator into a RoomRow that renders them at the table's size with the next
// seed. Included by the room_tables_*.cpp files only: the render loops are instantiated there, a
// few tables per translation unit, so that they compile in parallel.
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nsp/nsp.hpp>

#include "image_render.hpp"
#include "render_job.hpp"
#include "room_plan.hpp"
#include "room_scene.hpp"

namespace nsp_examples {

/// A scene shared by the rows that render it (each row's render holds it until the run ends).
template <class Sc>
std::shared_ptr<const Sc> share(Sc scene) {
    return std::make_shared<const Sc>(std::move(scene));
}

/// Adds rows to a table: each takes the table's size and the next seed (`seed`, which a table
/// may set back to pair two rows on the same random numbers); its render takes the spp (the
/// table's, or a pilot's).
class RowMaker {
public:
    RowMaker(RoomTable& table, const RoomOptions& o, std::uint64_t first_seed)
        : seed(first_seed), table_(table), threads_(o.threads) {}

    std::uint64_t seed;  ///< the next row's

    /// A row through the room's camera rays.
    template <class Sc, class E>
    void path(std::shared_ptr<const Sc> scene, const E& estimator, const std::string& name) {
        add(name, [=, res = table_.res, threads = threads_, s = seed++](int spp) {
            return render_image(*scene, estimator, name, res, spp, threads, s,
                                [](float u, float v) { return room_camera_ray(u, v, 1.f); });
        });
    }

    /// A row with light tracing (BdptEstimator::sample) through `camera`, splats included.
    template <class Sc, class E>
    void splatting(std::shared_ptr<const Sc> scene, const E& estimator, const std::string& name,
                   const nsp::PinholeCamera& camera = room_pinhole()) {
        add(name, [=, res = table_.res, threads = threads_, s = seed++](int spp) {
            return render_image_splatting(*scene, estimator, camera, name, res, spp, threads, s);
        });
    }

    /// A row through `camera`: BDPT (an estimator with kMaxPath) with light tracing, a path
    /// tracer along the camera's rays.
    template <class Sc, class E>
    void pinhole(std::shared_ptr<const Sc> scene, const nsp::PinholeCamera& camera, const E& estimator,
                 const std::string& name) {
        if constexpr (requires { estimator.kMaxPath; })
            splatting(scene, estimator, name, camera);
        else
            add(name, [=, res = table_.res, threads = threads_, s = seed++](int spp) {
                return render_image(*scene, estimator, name, res, spp, threads, s,
                                    [&](float u, float v) { return camera.ray(u, v); });
            });
    }

    /// BDPT (null-scattering MIS, balance, light tracing) with its NEE count and light subpath
    /// probability learned for the image from a pilot of spp / 32 samples per pixel (2-16) at
    /// counts 1 (THEORY 5.9, nsp::NeeCountLearner); the choice is the row's note. `channels`:
    /// bdpt::Grey{}, or channels::SpectralMis{} (per-channel pdfs, SpectralBdptEstimator);
    /// `roulette`: EstimatorOptions::russian_roulette.
    template <class Sc, class Channels>
    void learned_bdpt(std::shared_ptr<const Sc> scene, const nsp::PinholeCamera& camera, const std::string& name,
                      Channels, bool roulette = true) {
        add(name, [=, res = table_.res, threads = threads_, s = seed++](int spp) {
            auto make = [roulette](float nee, float light) {
                nsp::EstimatorOptions o = nsp::BdptEstimator<>::default_options();
                o.nee_count = nee;
                o.russian_roulette = roulette;
                return nsp::BdptEstimator<nsp::bdpt::NullScattering, nsp::mis::Balance, nsp::absorption::Weight, 32,
                                          Channels>(o, {}, light);
            };
            const int pilot = RenderRequest::pilot_spp(spp);
            nsp::TechniqueCounts chosen;
            Row row = render_image_splatting_learned(*scene, make, camera, name, res, spp, threads, s, pilot, &chosen);
            char text[256];
            std::snprintf(text, sizeof text,
                          "learned counts (%s, a %d-spp pilot at counts 1 over the image): NEE %g, light subpaths %g",
                          name.c_str(), pilot, double(chosen.nee), double(chosen.light_subpath));
            row.note = text;
            return row;
        });
    }

    /// uni + NEE MIS (balance) with its NEE count and emission segment count learned per 16x16
    /// tile from the same pilot (nsp::NeeCountLearner; per tile: every strategy stays in its
    /// pixel), through the room's camera; the tiles' choices are the row's note.
    template <class Sc>
    void learned_path(std::shared_ptr<const Sc> scene) {
        const std::string name = "uni-nee-mis_balance_learned";
        add(name, [=, res = table_.res, threads = threads_, s = seed++](int spp) {
            auto make = [](float nee, float segment) {
                nsp::EstimatorOptions o;
                o.nee_count = nee;
                o.emission_segment_count = segment;
                return nsp::PathEstimator<nsp::strategy::NullScatteringMis, nsp::mis::Balance>(o);
            };
            const int pilot = RenderRequest::pilot_spp(spp);
            std::vector<nsp::TechniqueCounts> chosen;
            const float pilot_count = RenderRequest{}.pilot_count;
            Row row = render_image_learned(*scene, make, name, res, spp, threads, s,
                                           [](float u, float v) { return room_camera_ray(u, v, 1.f); }, pilot,
                                           pilot_count, &chosen);
            std::array<int, nsp::NeeCountLearner::kCandidates> nee{}, segment{};
            for (const nsp::TechniqueCounts& c : chosen) {
                ++nee[std::size_t(nsp::NeeCountLearner::candidate_index(c.nee))];
                ++segment[std::size_t(nsp::NeeCountLearner::candidate_index(c.emission_segment))];
            }
            std::ostringstream note;  // not "(" + std::to_string(..): GCC 12 warns (-Wrestrict, bug 105329)
            note << "learned counts (" << name << ", a scout, a " << pilot << "-spp pilot at counts " << pilot_count
                 << " or above per 16x16 tile), tiles at 1, 1/2, .., 1/64, 0: NEE";
            for (const int n : nee) note << ' ' << n;
            note << "; emission segment";
            for (const int n : segment) note << ' ' << n;
            row.note = note.str();
            return row;
        });
    }

private:
    template <class Render>
    void add(const std::string& name, Render render) {
        table_.rows.push_back({name, std::move(render)});
    }

    RoomTable& table_;
    int threads_;
};

}  // namespace nsp_examples
