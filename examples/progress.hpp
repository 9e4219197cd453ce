// examples/progress.hpp: the progress lines of nsp_render, nsp_room and nsp_volume on stderr, one
// per finished render, "  [k/N] name: T s (about R left)", and the estimate of the time left.
//
// The estimate: costs per sample differ by up to 10x between the rows of one table (unidirectional
// against BDPT, a global against a grid majorant) and by 16x between the tables of a run
// (nsp_render's fog against its chromatic cloud), so no rate measured on the renders done so far
// predicts a table not rendered yet. A rate per scene (the estimate before) was 0.70-2.73x the time
// actually left over nsp_render's default run, and a factor per table times one per row name,
// fitted as the run goes, no better (0.70-4.4x). So each render is timed first with a pilot: the
// same render at 1/64 of its spp (calibrate(); about 3% of the run, most of it building scenes). A
// render still to come is its pilot's seconds per sample times its samples, times the ratio of
// actual to pilot-predicted seconds of the renders done so far (what the pilots miss: the time
// outside a render's sample loop); over the same run that was 0.91-1.08x the time left at every
// render. A render without a pilot is estimated from the seconds per sample of the renders done.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace nsp_examples {

class Progress {
public:
    /// Plans a render of `samples` samples (width x height x spp); returns its id for
    /// calibrate() and done(). Plan every render before the first done(): N is the count planned.
    std::size_t add(double samples);

    /// Render `id`'s pilot rendered `samples` samples in `seconds`.
    void calibrate(std::size_t id, double samples, double seconds);

    /// Render `id` took `seconds` (all of it, outside its sample loop too): prints
    /// "  [k/N] name: T s (about R left)" on stderr, k the renders done so far (nothing about the
    /// time left when none is left).
    void done(std::size_t id, const std::string& name, double seconds);

    /// The seconds the renders not yet done should take (0 when nothing can be estimated yet).
    double seconds_left() const;

    std::size_t planned() const { return items_.size(); }

    /// "[k/N] name" for the render that will finish next (a label for a line shown while it runs).
    std::string next_label(const std::string& name) const;

    /// "12 s", "2 min 10 s", "1 h 5 min".
    static std::string duration_text(double seconds);

    /// The samples of a render's pilot: 1/64 of its spp, at least 2 (what calibrate() expects
    /// to be told about; the tools render the pilot at this spp).
    static int pilot_spp(int spp) { return spp / 64 > 2 ? spp / 64 : 2; }

private:
    struct Item {
        double samples = 0.0;
        double pilot_rate = -1.0;  ///< seconds per sample of its pilot; < 0 without one
        double seconds = -1.0;     ///< < 0 while not done
    };
    std::vector<Item> items_;
    std::size_t done_ = 0;
};

}  // namespace nsp_examples
