// nsp/tile_counts.hpp: the host protocol of expected counts (docs/integration.md) in one object:
// an image cut into tiles, each tile's pilot learned by its own NeeCountLearner, the learners
// merged in a fixed order whatever thread ran them, the image's pooled choice as every tile's
// fallback, and why each tile has the counts it has.
#pragma once

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "counts.hpp"

namespace nsp {

/// Expected counts per pixel tile of a width x height image (THEORY 5.9, docs/counts.md). A host
///  1. renders each tile's pilot (pilot_spp(spp) samples per pixel, the estimator at
///     pilot_counts(), learner() as the lookup counter: end_sample after each sample with the
///     sample's channel mean, end_pixel after each pixel) and hands the learner to add();
///  2. calls choose() once every tile is added;
///  3. renders the rest of each pixel's samples at counts(tile).
/// The pilot's samples stay in the image (they are unbiased at the pilot's counts) and a pixel's
/// random stream simply continues. Threads: add() may run concurrently for tiles of different
/// slots (tile % kSlots); the tiles of one slot must be added in increasing order (one thread per
/// slot, as slot_tiles() lists them), which makes the merged learners, and so every count, the
/// same for any thread count. Host-side: it allocates (kSlots learners, a Summary per tile) and
/// throws; nothing of it runs in a kernel.
class TileCounts {
public:
    static constexpr int kSlots = 16;  ///< learners merged in parallel (about 40 KiB each)

    /// Why a tile has its counts.
    enum class Source {
        Own,       ///< its pilot showed a significant gain (or had nothing to learn from)
        Image,     ///< the image's counts, which its pilot predicts no worse than counts 1
        CountsOne  ///< counts 1: no significant gain of its own, and the image's predicted worse
    };

    /// Tiles of tile_size^2 pixels over a width x height image; the learners take `costs` and a
    /// pilot at `pilot` counts (NeeCountLearner's constructor). Throws InvalidArgument naming a
    /// size that is not > 0, or what NeeCountLearner refuses.
    TileCounts(int width, int height, int tile_size = 16, const CostModel& costs = {},
               const TechniqueCounts& pilot = {})
        : width_(width), height_(height), tile_(tile_size), costs_(costs), pilot_(pilot) {
        const auto positive = [](const char* what, int v) {
            if (v <= 0)
                throw InvalidArgument(std::string("nsp::TileCounts: ") + what + " is " + std::to_string(v) +
                                      "; it must be > 0");
        };
        positive("width", width);
        positive("height", height);
        positive("tile_size", tile_size);
        tiles_x_ = (width + tile_size - 1) / tile_size;
        tiles_y_ = (height + tile_size - 1) / tile_size;
        const NeeCountLearner prototype(costs, pilot);  // validates costs and pilot
        slots_.assign(std::size_t(kSlots), prototype);
        next_.assign(std::size_t(kSlots), 0);
        for (int j = 0; j < kSlots; ++j) next_[std::size_t(j)] = j;
        summaries_.resize(std::size_t(tile_count()));
        counts_.assign(std::size_t(tile_count()), TechniqueCounts{});
        sources_.assign(std::size_t(tile_count()), Source::Own);
    }

    /// The pilot's samples per pixel for a render of `spp`: spp / 32, at least 2 (a pixel's
    /// sample variance needs two) and at most 16 (a 16x16 tile then learns from 512 to 4096
    /// samples), never more than spp.
    static int pilot_spp(int spp) noexcept { return std::min(spp, std::clamp(spp / 32, 2, 16)); }

    int tile_count() const noexcept { return tiles_x_ * tiles_y_; }
    int tiles_x() const noexcept { return tiles_x_; }
    int tiles_y() const noexcept { return tiles_y_; }
    /// The tile of pixel (x, y).
    int tile_at(int x, int y) const noexcept { return (y / tile_) * tiles_x_ + x / tile_; }
    /// Tile t's pixels: x in [x0, x1), y in [y0, y1).
    struct Rect {
        int x0, y0, x1, y1;
    };
    Rect tile_rect(int t) const noexcept {
        const int x0 = (t % tiles_x_) * tile_, y0 = (t / tiles_x_) * tile_;
        return {x0, y0, std::min(width_, x0 + tile_), std::min(height_, y0 + tile_)};
    }
    /// The tiles of slot j in the order add() takes them: j, j + kSlots, ...
    std::vector<int> slot_tiles(int j) const {
        std::vector<int> out;
        for (int t = j; t < tile_count(); t += kSlots) out.push_back(t);
        return out;
    }

    /// The counts the pilot runs at (EstimatorOptions::nee_count, emission_segment_count).
    const TechniqueCounts& pilot_counts() const noexcept { return pilot_; }
    /// A fresh learner for one tile's pilot.
    NeeCountLearner learner() const { return NeeCountLearner(costs_, pilot_); }

    /// Tile t's pilot is done: keeps its Summary and merges its learner into slot t % kSlots.
    /// Throws InvalidArgument for a tile out of range, std::logic_error for one out of its slot's
    /// order or after choose().
    void add(int t, const NeeCountLearner& l) {
        if (chosen_) throw std::logic_error("nsp::TileCounts::add after choose()");
        if (t < 0 || t >= tile_count())
            throw InvalidArgument("nsp::TileCounts::add: tile " + std::to_string(t) + " is not in [0, " +
                             std::to_string(tile_count()) + ")");
        const std::size_t j = std::size_t(t % kSlots);
        if (next_[j] != t)
            throw std::logic_error("nsp::TileCounts::add: tile " + std::to_string(t) + " out of order; slot " +
                             std::to_string(j) + " expects tile " + std::to_string(next_[j]) + " next");
        summaries_[std::size_t(t)] = l.summary();
        slots_[j].merge(l);
        next_[j] = t + kSlots;
    }

    /// Every tile added: merges the slots in order into the image's learner, chooses its counts
    /// and each tile's (its own where its pilot shows a gain, else the image's where it predicts
    /// them no worse than counts 1, else 1). Throws std::logic_error where a tile is missing.
    void choose() {
        for (int j = 0; j < kSlots; ++j)
            if (next_[std::size_t(j)] < tile_count())
                throw std::logic_error("nsp::TileCounts::choose: tile " + std::to_string(next_[std::size_t(j)]) +
                                 " was not added");
        image_ = NeeCountLearner(costs_, pilot_);
        for (const NeeCountLearner& l : slots_) image_.merge(l);
        image_counts_ = image_.choose_counts();
        for (int t = 0; t < tile_count(); ++t) {
            const NeeCountLearner::Summary& s = summaries_[std::size_t(t)];
            const TechniqueCounts c = NeeCountLearner::choose_counts(s, image_counts_);
            counts_[std::size_t(t)] = c;
            sources_[std::size_t(t)] = !s.open                  ? Source::Own
                                       : c == TechniqueCounts{} ? Source::CountsOne
                                                                : Source::Image;
        }
        chosen_ = true;
    }

    /// Tile t's counts (after choose(); counts 1 before).
    const TechniqueCounts& counts(int t) const { return counts_.at(std::size_t(t)); }
    /// Why tile t has its counts (after choose()).
    Source source(int t) const { return sources_.at(std::size_t(t)); }
    /// The image's counts: every tile's pilot pooled (after choose()).
    const TechniqueCounts& image_counts() const noexcept { return image_counts_; }
    /// Every tile's pilot merged (after choose()): its predictions, samples and work.
    const NeeCountLearner& image() const noexcept { return image_; }
    const NeeCountLearner::Summary& summary(int t) const { return summaries_.at(std::size_t(t)); }

private:
    int width_, height_, tile_, tiles_x_ = 0, tiles_y_ = 0;
    CostModel costs_;
    TechniqueCounts pilot_;
    std::vector<NeeCountLearner> slots_;
    std::vector<int> next_;  // per slot: the tile add() expects next
    std::vector<NeeCountLearner::Summary> summaries_;
    std::vector<TechniqueCounts> counts_;
    std::vector<Source> sources_;
    NeeCountLearner image_;
    TechniqueCounts image_counts_;
    bool chosen_ = false;
};

}  // namespace nsp
