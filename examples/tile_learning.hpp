// examples/tile_learning.hpp: the scout and the pilot of nsp::TileCounts's protocol
// (docs/integration.md) for the example renderers that learn counts per tile (nsp_render's learned
// rows, nsp_room's): threads take whole slots, a slot's tiles in order, so the counts do not
// depend on the thread count. The renderer says how a pixel's samples run and where a learner's
// work goes; these own the order.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>

#include <nsp/tile_counts.hpp>

namespace nsp_examples {

/// The scout (pass 0): for every tile, a TileCounts::scout_learner() over its scout pixels
/// (TileCounts::is_scout), handed to add_scout in slot order; then end_scout(). `run_pool(work)`
/// runs work(Out&) on every thread; `scout_pixel(out, learner, x, y)` runs pixel (x, y)'s
/// TileCounts::scout_spp samples at the constructed pilot counts on a stream of the pixel's own
/// that the image does not use, with the learner as their counter (end_sample after each);
/// `add_work(out, learner)` counts a tile's work.
template <class Out, class Pool, class ScoutPixel, class AddWork>
void scout_tiles(nsp::TileCounts& plan, Pool&& run_pool, ScoutPixel&& scout_pixel, AddWork&& add_work) {
    std::atomic<int> next_slot{0};
    auto work = [&](Out& out) {
        for (int j; (j = next_slot.fetch_add(1)) < nsp::TileCounts::kSlots;)
            for (const int tile : plan.slot_tiles(j)) {
                nsp::NeeCountLearner learner = plan.scout_learner();
                const nsp::TileCounts::Rect r = plan.tile_rect(tile);
                for (int y = r.y0; y < r.y1; ++y)
                    for (int x = r.x0; x < r.x1; ++x) {
                        if (!nsp::TileCounts::is_scout(x, y)) continue;
                        scout_pixel(out, learner, x, y);
                        learner.end_pixel();
                    }
                add_work(out, learner);
                plan.add_scout(tile, learner);
            }
    };
    run_pool(work);
    plan.end_scout();
}

/// The pilot (pass 1) at plan.pilot_counts(): every tile's pixels in two halves (x + y even, odd),
/// each with its own learner, handed to add(tile, even, odd) (`halves`: each half's pilot then
/// weighs by the other's predictions, and a tile's count below 1 stands only where both halves
/// agree; else merged, add(tile, learner)); then choose(). `pilot_pixel(out, learner, x, y)` runs
/// pixel (x, y)'s pilot samples with the learner as their counter (end_sample after each).
template <class Out, class Pool, class PilotPixel, class AddWork>
void pilot_tiles(nsp::TileCounts& plan, bool halves, Pool&& run_pool, PilotPixel&& pilot_pixel, AddWork&& add_work) {
    std::atomic<int> next_slot{0};
    auto work = [&](Out& out) {
        for (int j; (j = next_slot.fetch_add(1)) < nsp::TileCounts::kSlots;)
            for (const int tile : plan.slot_tiles(j)) {
                std::array<nsp::NeeCountLearner, 2> by_half{plan.learner(), plan.learner()};  // not `half`: OpenEXR's type
                const nsp::TileCounts::Rect r = plan.tile_rect(tile);
                for (int y = r.y0; y < r.y1; ++y)
                    for (int x = r.x0; x < r.x1; ++x) {
                        nsp::NeeCountLearner& learner = by_half[std::size_t((x + y) & 1)];
                        pilot_pixel(out, learner, x, y);
                        learner.end_pixel();
                    }
                for (const nsp::NeeCountLearner& l : by_half) add_work(out, l);
                if (halves) {
                    plan.add(tile, by_half[0], by_half[1]);
                } else {
                    by_half[0].merge(by_half[1]);
                    plan.add(tile, by_half[0]);
                }
            }
    };
    run_pool(work);
    plan.choose();
}

}  // namespace nsp_examples
