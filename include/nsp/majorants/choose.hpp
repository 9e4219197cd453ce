// nsp/majorants/choose.hpp: the grid resolution a medium pays for, from a cost model, before any
// rendering (THEORY 4, step 1; issue 19's "the majorant's cost too").
//
// A grid majorant trades DDA steps for lookups: finer cells bound the density more tightly, so a
// flight meets fewer null collisions (each a density lookup), but it crosses more cells. Over
// random lines through the medium's bounds (isotropic, uniform: the Crofton measure, as a BVH's
// surface-area heuristic assumes), a line that meets the bounds B crosses a convex cell c with
// probability S_c / S_B (surfaces), along a mean chord 4 V_c / S_c. So per line
//   steps   = sum_c S_c / S_B                      (cells crossed, empty ones included)
//   lookups = sum_c (S_c / S_B) mu_bar_c 4 V_c / S_c = (4 / S_B) sum_c mu_bar_c V_c
// (tentative collisions of a flight that tracks the whole chord), and a resolution costs
// lookups + step_cost x steps, step_cost a step's cost in lookups. The global majorant takes no
// step. The model ignores where flights start and stop (inside the medium, at real collisions),
// which scales steps and lookups alike where the medium is uniform, and the variance a majorant
// changes (none for delta tracking's weights; ratio-tracked NEE varies a little more under tighter
// bounds): it ranks resolutions, measured against the renders in docs/majorants.md.
//
// A control (GridControl, THEORY 5.10) keeps the grid's steps and removes lookups: decomposition
// and residual ratio tracking draw tentative collisions only for the residual above each cell's
// minorant, (4 / S_B) sum_c (mu_bar_c - mu_c) V_c per line (a real collision costs one lookup
// either way). Its cells cost `control_step_cost` per step instead of step_cost: the second
// float, the control's clock and the residual's rescaling of each lookup.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "../core/error.hpp"
#include "../majorant.hpp"
#include "../medium.hpp"
#include "control.hpp"
#include "grid.hpp"

namespace nsp {

/// The DDA step's cost in density lookups that choose_grid_resolution assumes by default
/// (core/counter.hpp: kDdaStepCost).
inline constexpr float kDefaultStepCost = kDdaStepCost;

/// A GridControl cell's step cost in density lookups that choose_majorant assumes by default:
/// measured 0.31 against the grid's 0.3 (residual ratio and decomposition tracking through the
/// cloud at 16^3 and 64^3, docs/transmittance.md), rounded up.
inline constexpr float kDefaultControlStepCost = 0.32f;

/// What the cost model expects of a majorant per random line through the medium's bounds.
struct MajorantCost {
    bool global = false;                 ///< the GlobalMajorant (no grid, no steps)
    bool control = false;                ///< a GridControl (per-cell minorants beside the grid's bounds)
    std::array<int, 3> resolution{1, 1, 1};  ///< the grid's cells per axis (global: {1, 1, 1})
    double steps = 0.0;                  ///< DDA steps (cells crossed)
    double lookups = 0.0;                ///< tentative collisions, each a density lookup
    double cost = 0.0;                   ///< lookups + step_cost x steps
};

namespace detail {

inline void require_step_cost(float step_cost) {
    if (!std::isfinite(step_cost) || step_cost < 0.f)
        detail::fail("majorant cost model: step_cost = ", step_cost,
             " is not allowed: it must be finite and >= 0 (a DDA step's cost in density lookups)");
}

/// The cost model's line through a grid of `res` cells of size `h` over box `b` whose cells' (residual)
/// majorants sum to `mu_sum`: steps sum_c S_c / S_B, lookups (4 / S_B) sum_c mu_c V_c (see the header).
inline MajorantCost grid_line_cost(const Box& b, std::array<int, 3> res, const Vec3& h, double mu_sum, float step_cost) {
    const double s = box_surface(b);
    const double cell_surface = 2.0 * (double(h.x) * h.y + double(h.y) * h.z + double(h.z) * h.x);
    MajorantCost c;
    c.resolution = res;
    c.steps = double(res[0]) * res[1] * res[2] * cell_surface / s;
    c.lookups = 4.0 * mu_sum * (double(h.x) * h.y * h.z) / s;
    c.cost = c.lookups + double(step_cost) * c.steps;
    return c;
}

}  // namespace detail

/// The cost model's steps and lookups per random line for the GlobalMajorant of `medium`.
template <CellBoundedMedium M>
MajorantCost global_majorant_cost(const M& medium) {
    const Box b = medium.bounds();
    const double s = detail::box_surface(b);
    if (!std::isfinite(s) || !(s > 0.0))
        detail::fail("global_majorant_cost: the medium's bounds have surface ", s, "; they must be finite and non-empty");
    MajorantCost c;
    c.global = true;
    c.lookups = double(GlobalMajorant<M>(medium).value()) * detail::mean_chord(b);
    c.cost = c.lookups;
    return c;
}

/// The cost model's steps and lookups per random line for a GridMajorant of `res` cells over
/// `medium`'s bounds (its cells as GridMajorant builds them, padding included). Throws as
/// GridMajorant does, and on a step_cost that is negative or not finite.
template <CellBoundedMedium M>
MajorantCost grid_majorant_cost(const M& medium, std::array<int, 3> res, float step_cost = kDefaultStepCost) {
    detail::require_step_cost(step_cost);
    const GridMajorant<M> grid(medium, res);
    double mu_sum = 0.0;
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) mu_sum += double(grid.cell(x, y, z));
    return detail::grid_line_cost(medium.bounds(), res, grid.cell_size(), mu_sum, step_cost);
}

/// The cost model's steps and lookups per random line for a GridControl of `res` cells over `medium`'s
/// bounds: the grid's steps at `step_cost` each, and lookups for the residual above the cells'
/// minorants (see the header). Throws as GridControl does, and on a step_cost that is negative or
/// not finite.
template <RegionBoundedMedium M>
MajorantCost grid_control_cost(const M& medium, std::array<int, 3> res, float step_cost = kDefaultStepCost) {
    detail::require_step_cost(step_cost);
    const GridControl<M> grid(medium, res);
    MajorantCost c = detail::grid_line_cost(medium.bounds(), res, grid.cell_size(), grid.residual_sum(), step_cost);
    c.control = true;
    return c;
}

/// The majorant the cost model prefers for `medium`: the GlobalMajorant, or a GridMajorant of
/// 2, 4, 8, ... up to max_res cells per axis (as GridMajorant(medium, R) builds it), whichever
/// costs least per random line (ties to the coarser). Builds each candidate grid once (at 64,
/// 262144 density bounds). Throws on max_res outside [1, 4096] or a bad step_cost.
template <CellBoundedMedium M>
MajorantCost choose_grid_resolution(const M& medium, int max_res = 64, float step_cost = kDefaultStepCost) {
    if (max_res < 1 || max_res > 4096)
        detail::fail("choose_grid_resolution: max_res = ", max_res, " is not allowed: it must lie in [1, 4096]");
    detail::require_step_cost(step_cost);
    MajorantCost best = global_majorant_cost(medium);
    for (int r = 2; r <= max_res; r *= 2) {
        const MajorantCost c = grid_majorant_cost(medium, {r, r, r}, step_cost);
        if (c.cost < best.cost) best = c;
    }
    return best;
}

/// The majorant or control the cost model prefers for `medium`: choose_grid_resolution's pick, or a
/// GridControl of 2, 4, 8, ... up to max_res cells per axis where the medium bounds its density
/// from below (LowerBoundedMedium; a medium without that query gets no control), its extinction per
/// unit density is grey (the same in every channel and wavelength), and the control costs less
/// with its steps at `control_step_cost` (ties to the majorant). A chromatic medium gets no
/// control: the loop's control is grey (the smallest channel's), the denser channels' residual
/// nulls then weigh far from 1, and the variance that costs (2-7x on the chromatic cloud at 16^3,
/// docs/transmittance.md) is not in a model of lookups. The estimators that take a control are
/// PathEstimator's, every strategy (THEORY 5.10; SpectralPathEstimator and BDPT do not); the
/// caller decides whether its estimator is one. Throws as choose_grid_resolution.
template <CellBoundedMedium M>
MajorantCost choose_majorant(const M& medium, int max_res = 64, float step_cost = kDefaultStepCost,
                             float control_step_cost = kDefaultControlStepCost) {
    MajorantCost best = choose_grid_resolution(medium, max_res, step_cost);
    if constexpr (LowerBoundedMedium<M>) {
        detail::require_step_cost(control_step_cost);
        const auto unit = medium.extinction_per_density();
        if (min_value(unit) != max_value(unit)) return best;
        for (int r = 2; r <= max_res; r *= 2) {
            const MajorantCost c = grid_control_cost(medium, {r, r, r}, control_step_cost);
            if (c.cost < best.cost) best = c;
        }
    }
    return best;
}

}  // namespace nsp
