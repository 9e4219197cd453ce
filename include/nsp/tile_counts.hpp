// nsp/tile_counts.hpp: the host protocol of expected counts (docs/integration.md) in one object:
// an image cut into tiles, each tile's pilot learned by its own NeeCountLearner, the learners
// merged in a fixed order whatever thread ran them, the image's pooled choice as every tile's
// fallback, and why each tile has the counts it has.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "counts.hpp"

namespace nsp {

/// Expected counts per pixel tile of a width x height image (THEORY 5.9, docs/counts.md). A host
///  0. (optional) renders a scout: scout_spp(spp) samples of each scout pixel (is_scout) at the
///     constructed pilot counts, scout_learner() as the counter, handed per tile to add_scout(),
///     then end_scout(); the scout's samples are not in the image. It raises the pilot's counts
///     to those the scout predicts best among the counts at or above them, so that where NEE
///     pays image-wide the pilot runs where the rest will and its samples are as good as theirs;
///  1. renders each tile's pilot (pilot_spp(spp) samples per pixel, the estimator at
///     pilot_counts(), learner() as the lookup counter: end_sample after each sample with the
///     sample's channel mean, end_pixel after each pixel) and hands the learner to add();
///  2. calls choose() once every tile is added;
///  3. renders the rest of each pixel's samples at counts(tile).
/// The pilot's samples stay in the image (they are unbiased at the pilot's counts) and a pixel's
/// random stream simply continues. A pilot learned in two halves of each tile (add(t, even, odd))
/// lets a pilot below count 1 weigh in a pixel's estimate by its predicted variance
/// (pilot_weight), so that it costs little where its count is the noisy one. Threads: add() may
/// run concurrently for tiles of different slots (tile % kSlots); the tiles of one slot must be
/// added in increasing order (one thread per slot, as slot_tiles() lists them), which makes the
/// merged learners, and so every count, the same for any thread count. Host-side: it allocates
/// (kSlots learners; per tile a Summary and two halves' predictions, about 300 bytes) and throws;
/// nothing of it runs in a kernel.
class TileCounts {
public:
    static constexpr int kSlots = 16;  ///< learners merged in parallel (about 40 KiB each)

    /// Why a tile has its counts.
    enum class Source {
        Own,       ///< its pilot showed a significant gain (or had nothing to learn from)
        Image,     ///< the image's counts, which its pilot predicts no worse than counts 1
        CountsOne,  ///< counts 1: no significant gain of its own, and the image's predicted worse
        /// counts 1: its own choice, significant over the whole tile, is predicted worse than
        /// counts 1 by one of its halves (add(t, even, odd)) alone: a tail that half saw
        Disputed
    };

    /// Tiles of tile_size^2 pixels over a width x height image; the learners take `costs` and a
    /// pilot at `pilot` counts (NeeCountLearner's constructor). Throws InvalidArgument naming a
    /// size that is not > 0, or what NeeCountLearner refuses.
    TileCounts(int width, int height, int tile_size = 16, const CostModel& costs = {},
               const TechniqueCounts& pilot = {})
        : width_(width), height_(height), tile_(tile_size), costs_(costs), floor_(pilot), pilot_(pilot) {
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
        halves_.resize(std::size_t(tile_count()));
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

    /// The scout's pixels: one in kScoutStride^2, (x, y) with x % kScoutStride and y %
    /// kScoutStride both kScoutStride / 2.
    static constexpr int kScoutStride = 4;
    static constexpr bool is_scout(int x, int y) noexcept {
        return x % kScoutStride == kScoutStride / 2 && y % kScoutStride == kScoutStride / 2;
    }
    /// The scout's samples per scout pixel: 2 (at most spp). Over a 128 x 128 image, 2048
    /// samples: 1/2048 of a 256-spp render's samples.
    static constexpr int scout_spp(int spp) noexcept { return std::min(spp, 2); }
    /// A fresh learner for one tile's scout pixels, at the constructed pilot counts.
    NeeCountLearner scout_learner() const { return NeeCountLearner(costs_, floor_); }
    /// Tile t's scout pixels are done (none is fine: an empty learner): merges `l` into slot t %
    /// kSlots. Every tile, in slot_tiles() order per slot, as add(). Throws InvalidArgument for a
    /// tile out of range, std::logic_error for one out of order, or after end_scout() or add().
    void add_scout(int t, const NeeCountLearner& l) {
        if (scout_ended_ || adding_) throw std::logic_error("nsp::TileCounts::add_scout after end_scout() or add()");
        check_add(t);
        scouting_ = true;
        slots_[std::size_t(t % kSlots)].merge(l);
        next_[std::size_t(t % kSlots)] = t + kSlots;
    }
    /// Every tile scouted: merges the slots in order and sets pilot_counts() to the pair, among
    /// the candidates at or above the constructed pilot counts, with the smallest predicted
    /// variance x cost over the scout pooled (ties to the larger counts; no significance test:
    /// every such pair is a fair pilot). Unchanged where the scout recorded nothing to predict
    /// from. A BDPT pilot's light subpath stays at 1. Throws std::logic_error where a tile was
    /// not scouted, or twice.
    void end_scout() {
        if (scout_ended_ || adding_) throw std::logic_error("nsp::TileCounts::end_scout twice or after add()");
        check_all_added("end_scout");
        NeeCountLearner scout(costs_, floor_);
        for (const NeeCountLearner& l : slots_) scout.merge(l);
        const int fn = candidate_of(floor_.nee), fs = candidate_of(floor_.emission_segment);
        const bool segment_axis = !scout.summary().light_subpath;
        if (!scout.invalid_pilot() && scout.predicted_variance(0, 0) > 0.0 && fn >= 0 && fs >= 0) {
            // From the lowest counts up, so that ties go to the larger; a prediction that is not
            // > 0 (a small sample's can be) is no evidence for its pair.
            int bn = fn, bs = segment_axis ? fs : 0;
            double best = std::numeric_limits<double>::infinity();
            for (int jn = fn; jn >= 0; --jn)
                for (int js = segment_axis ? fs : 0; js >= 0; --js) {
                    const double e = scout.predicted_variance(jn, js) * scout.predicted_cost(jn, js);
                    if (scout.allowed(jn, js) && e > 0.0 && std::isfinite(e) && e <= best) bn = jn, bs = js, best = e;
                }
            pilot_.nee = NeeCountLearner::candidate(bn);
            if (segment_axis) pilot_.emission_segment = NeeCountLearner::candidate(bs);
        }
        scout_ = scout.summary().own;
        const NeeCountLearner prototype(costs_, pilot_);
        slots_.assign(std::size_t(kSlots), prototype);
        for (int j = 0; j < kSlots; ++j) next_[std::size_t(j)] = j;
        scout_ended_ = true;
    }
    /// The scout's own choice of counts (after end_scout(); counts 1 before or without one).
    const TechniqueCounts& scout_counts() const noexcept { return scout_; }

    /// The counts the pilot runs at (EstimatorOptions::nee_count, emission_segment_count): the
    /// constructed ones, raised by end_scout() where a scout ran.
    const TechniqueCounts& pilot_counts() const noexcept { return pilot_; }
    /// A fresh learner for one tile's pilot.
    NeeCountLearner learner() const { return NeeCountLearner(costs_, pilot_); }

    /// Tile t's pilot is done: keeps its Summary and merges its learner into slot t % kSlots.
    /// Throws InvalidArgument for a tile out of range, std::logic_error for one out of its slot's
    /// order, after choose(), or after add_scout() without end_scout(). Its pilot samples then
    /// weigh as many of the pixel's samples (pilot_weight).
    void add(int t, const NeeCountLearner& l) {
        check_pilot_add(t);
        summaries_[std::size_t(t)] = l.summary();
        slots_[std::size_t(t % kSlots)].merge(l);
        next_[std::size_t(t % kSlots)] = t + kSlots;
    }
    /// Tile t's pilot is done, learned in two halves of its pixels: `even` from the pixels with
    /// x + y even, `odd` from the others. The tile's counts are chosen from both merged, as by
    /// add(t, learner), with one cross-check: its own choice below counts 1 stands only where
    /// each half alone predicts it no worse than counts 1, else the tile keeps counts 1
    /// (Source::Disputed; on the chromatic cloud's set-up C2, one tile of four chose NEE 1/2 in
    /// 3 renders of 15, significant over the tile, and the image's variance rose 1.55-2.15x; with
    /// the cross-check every tile keeps 1 in those 15, while D's and C3's tiles keep their low
    /// counts). Each half's predicted variances at the pilot's counts and at its own choice are
    /// kept so that a pixel's pilot samples can be weighted by the other half's (pilot_weight).
    /// Throws as add(t, learner).
    void add(int t, const NeeCountLearner& even, const NeeCountLearner& odd) {
        check_pilot_add(t);
        NeeCountLearner both = even;
        both.merge(odd);
        summaries_[std::size_t(t)] = both.summary();
        slots_[std::size_t(t % kSlots)].merge(both);
        next_[std::size_t(t % kSlots)] = t + kSlots;
        Halves& h = halves_[std::size_t(t)];
        h.learned = true;
        // The cross-check: the tile's own choice below counts 1 stands only where each half alone
        // predicts it no worse than counts 1.
        const NeeCountLearner::Summary& s = summaries_[std::size_t(t)];
        const int on = candidate_of(s.own.nee),
                  os = candidate_of(s.light_subpath ? s.own.light_subpath : s.own.emission_segment);
        if (!s.open && on >= 0 && os >= 0 && (on != 0 || os != 0))
            for (const NeeCountLearner* l : {&even, &odd}) {
                const double e = l->predicted_variance(on, os) * l->predicted_cost(on, os),
                             e1 = l->predicted_variance(0, 0) * l->predicted_cost(0, 0);
                if (!(e <= e1)) h.disputed = true;
            }
        for (int half = 0; half < 2; ++half) {
            const NeeCountLearner& l = half == 0 ? even : odd;
            const NeeCountLearner::Summary own = l.summary();  // its choose_counts() and axis
            const int cn = candidate_of(own.own.nee),
                      cs = candidate_of(own.light_subpath ? own.own.light_subpath : own.own.emission_segment);
            const int pn = candidate_of(pilot_.nee), ps = candidate_of(pilot_.emission_segment);
            if (cn < 0 || cs < 0 || pn < 0 || ps < 0) continue;  // equal weights
            h.pilot_variance[std::size_t(half)] = float(l.predicted_variance(pn, ps));
            h.chosen_variance[std::size_t(half)] = float(l.predicted_variance(cn, cs));
        }
    }

    /// The weight of pixel (x, y)'s pilot mean in its estimate, after choose(): the pixel's
    /// estimate is a m_pilot + (1 - a) m_rest, the means of its `pilot_samples` pilot samples and
    /// of the other spp - pilot_samples. Where its tile was added in halves,
    /// a = n_p V_c / (n_p V_c + n_r V_p) (inverse-variance weights), V_p and V_c the variance per
    /// sample that the *other* half of the tile predicts at the pilot's counts and at the counts
    /// that half alone chooses (its choose_counts(), most often the tile's): a pilot at a low
    /// count that is noisy where NEE pays weighs little there. Nothing of the pixel's own samples
    /// enters the weight (not even through the tile's counts, which its pilot helped choose), so
    /// its estimate stays unbiased: E[a m_pilot] = E[a] L, and the rest, drawn after the counts
    /// are fixed, has mean L whatever they are. Elsewhere (one learner per tile, a count that is
    /// not a candidate, no variance predicted, fewer than 2 samples on either side) a =
    /// pilot_samples / spp: every sample weighs the same. Throws InvalidArgument for a pixel
    /// outside the image or pilot_samples not in [0, spp].
    double pilot_weight(int x, int y, int pilot_samples, int spp) const {
        if (pilot_samples < 0 || pilot_samples > spp)
            throw InvalidArgument("nsp::TileCounts::pilot_weight: pilot_samples is " + std::to_string(pilot_samples) +
                                  "; it must be in [0, spp = " + std::to_string(spp) + "]");
        if (x < 0 || x >= width_ || y < 0 || y >= height_)
            throw InvalidArgument("nsp::TileCounts::pilot_weight: pixel (" + std::to_string(x) + ", " +
                                  std::to_string(y) + ") is not in the " + std::to_string(width_) + " x " +
                                  std::to_string(height_) + " image");
        const double equal = spp > 0 ? double(pilot_samples) / double(spp) : 0.0;
        const int t = tile_at(x, y), rest = spp - pilot_samples;
        if (!chosen_ || !halves_[std::size_t(t)].learned || pilot_samples < 2 || rest < 2) return equal;
        const Halves& h = halves_[std::size_t(t)];
        const std::size_t other = std::size_t(1 - ((x + y) & 1));
        const double vp = h.pilot_variance[other], vc = h.chosen_variance[other];
        if (!(vp > 0.0 && vc > 0.0 && std::isfinite(vp) && std::isfinite(vc))) return equal;
        const double np = double(pilot_samples) * vc, nr = double(rest) * vp;
        return np / (np + nr);
    }

    /// Every tile added: merges the slots in order into the image's learner, chooses its counts
    /// and each tile's (its own where its pilot shows a gain, else the image's where it predicts
    /// them no worse than counts 1, else 1). Throws std::logic_error where a tile is missing.
    void choose() {
        check_all_added("choose");
        image_ = NeeCountLearner(costs_, pilot_);
        for (const NeeCountLearner& l : slots_) image_.merge(l);
        image_counts_ = image_.choose_counts();
        for (int t = 0; t < tile_count(); ++t) {
            const NeeCountLearner::Summary& s = summaries_[std::size_t(t)];
            if (halves_[std::size_t(t)].disputed) {
                counts_[std::size_t(t)] = TechniqueCounts{};
                sources_[std::size_t(t)] = Source::Disputed;
                continue;
            }
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
    void check_all_added(const char* what) const {
        for (int j = 0; j < kSlots; ++j)
            if (next_[std::size_t(j)] < tile_count())
                throw std::logic_error(std::string("nsp::TileCounts::") + what + ": tile " +
                                       std::to_string(next_[std::size_t(j)]) + " was not added");
    }
    void check_pilot_add(int t) {
        if (scouting_ && !scout_ended_)
            throw std::logic_error("nsp::TileCounts::add: the scout was not ended (end_scout())");
        check_add(t);
        adding_ = true;
    }
    void check_add(int t) const {
        if (chosen_) throw std::logic_error("nsp::TileCounts::add after choose()");
        if (t < 0 || t >= tile_count())
            throw InvalidArgument("nsp::TileCounts::add: tile " + std::to_string(t) + " is not in [0, " +
                             std::to_string(tile_count()) + ")");
        const std::size_t j = std::size_t(t % kSlots);
        if (next_[j] != t)
            throw std::logic_error("nsp::TileCounts::add: tile " + std::to_string(t) + " out of order; slot " +
                             std::to_string(j) + " expects tile " + std::to_string(next_[j]) + " next");
    }
    /// The candidate index of `count`, -1 where it is not a candidate.
    static int candidate_of(float count) noexcept {
        const int j = NeeCountLearner::candidate_index(count);
        return j >= 0 && j < NeeCountLearner::kCandidates && NeeCountLearner::candidate(j) == count ? j : -1;
    }

    int width_, height_, tile_, tiles_x_ = 0, tiles_y_ = 0;
    CostModel costs_;
    TechniqueCounts floor_, pilot_, scout_;  // the constructed pilot counts, the pilot's, the scout's choice
    bool scouting_ = false, scout_ended_ = false, adding_ = false;
    std::vector<NeeCountLearner> slots_;
    std::vector<int> next_;  // per slot: the tile add() expects next
    std::vector<NeeCountLearner::Summary> summaries_;
    std::vector<TechniqueCounts> counts_;
    /// Per tile added in halves: each half's predicted variance at the pilot's counts and at
    /// the counts it chooses alone (0: no weight from it).
    struct Halves {
        bool learned = false, disputed = false;
        std::array<float, 2> pilot_variance{}, chosen_variance{};
    };
    std::vector<Halves> halves_;
    std::vector<Source> sources_;
    NeeCountLearner image_;
    TechniqueCounts image_counts_;
    bool chosen_ = false;
};

}  // namespace nsp
