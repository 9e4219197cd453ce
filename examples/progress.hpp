// examples/progress.hpp: the progress lines of nsp_render, nsp_room and nsp_volume on stderr, one
// per finished render, "  [k/N] name: T s (about R left)", and the estimate of the time left.
//
// The estimate: a render's seconds per sample are modelled as a factor of its table (the scene,
// its size and mode: what every row of the table pays) times a factor of its kind (the row's
// estimator, which recurs across tables: BDPT costs several path tracers' time per sample in
// every scene), both fitted to the renders done so far (least squares on the logarithms). A
// render still to come is estimated from its samples times both factors: the kind's where that
// kind was rendered before (in another table, or an earlier run of the same row), else the mean
// kind's; the table's where that table has begun, else the mean table's. Costs per sample differ
// by 20x between rows of one table (unidirectional against BDPT) and between scenes; a rate per
// table alone (the estimate before) was off by up to 2x either way.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace nsp_examples {

class Progress {
public:
    /// Plans a render: `table` groups the renders of one table, `kind` names its estimator the
    /// same way in every table (the row's name), `samples` is width x height x spp. Returns its
    /// id for done(). Plan every render before the first done(): N is the count planned.
    std::size_t add(std::string table, std::string kind, double samples);

    /// Render `id` took `seconds`: prints "  [k/N] name: T s (about R left)" on stderr, k the
    /// renders done so far (nothing about the time left when none is left).
    void done(std::size_t id, const std::string& name, double seconds);

    /// The seconds the renders not yet done should take; 0 when none is left or nothing was done.
    double seconds_left() const;

    std::size_t planned() const { return items_.size(); }

    /// "[k/N] name" for the render that will finish next (a label for a line shown while it runs).
    std::string next_label(const std::string& name) const;

    /// "12 s", "2 min 10 s", "1 h 5 min".
    static std::string duration_text(double seconds);

private:
    struct Item {
        std::string table, kind;
        double samples = 0.0;
        double seconds = -1.0;  ///< < 0 while not done
    };
    std::vector<Item> items_;
    std::size_t done_ = 0;
};

}  // namespace nsp_examples
