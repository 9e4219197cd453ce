// The majorant cost model (nsp/majorants/choose.hpp):
// - its steps and lookups per line are what a DDA walk and the majorant's optical depth average
//   over isotropic uniform random lines through the bounds (the Crofton measure it assumes),
//   within 5 standard errors of 20000 lines (fixed seed: deterministic; 5 SE: a false failure
//   has probability below 1e-6 per check);
// - closed forms: a constant medium (lookups = mu 4V/S, steps = cells crossed, sum S_c / S_B);
// - the choice: global for a constant medium, a grid for a sparse one, the grid of the fewest
//   lookups when steps are free, global when they are dear; bad arguments rejected with their value.
#include <cmath>
#include <limits>
#include <vector>

#include "common.hpp"
#include <nsp/nsp.hpp>

using namespace nsp;
using namespace nsp_test;
using doctest::Contains;

namespace {

using M = DenseGridMedium<Mono>;

/// A 16^3 voxel grid over `box`, density 1 in the voxels [0, 2)^3 and 0 elsewhere, mu_t = 100.
M corner_block(const Box& box) {
    std::vector<float> d(16 * 16 * 16, 0.f);
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) d[std::size_t(x + 16 * (y + 16 * z))] = 1.f;
    return M(box, {16, 16, 16}, std::move(d), grey<Mono>(10.f), grey<Mono>(90.f));
}

/// A random line through box b with the Crofton measure: a uniform direction, then a uniform
/// point of the plane perpendicular to it within the box's circumscribed disk; lines that miss b
/// are drawn again.
template <class R>
Ray random_line(R& rng, const Box& b) {
    const Vec3 c = 0.5f * (b.lo + b.hi);
    const float radius = 0.5f * glm::length(b.hi - b.lo);
    for (;;) {
        const Vec3 d = random_direction(rng);
        const Vec3 u = glm::normalize(std::abs(d.x) < 0.9f ? glm::cross(d, Vec3(1.f, 0.f, 0.f)) : glm::cross(d, Vec3(0.f, 1.f, 0.f)));
        const Vec3 v = glm::cross(d, u);
        const float r = radius * std::sqrt(rng.uniform()), phi = 2.f * kPi * rng.uniform();
        const Ray ray{c + r * std::cos(phi) * u + r * std::sin(phi) * v - 2.f * radius * d, d};
        if (!b.clip(ray, 0.f, kInf).empty()) return ray;
    }
}

}  // namespace

TEST_CASE("the cost model's steps and lookups are the DDA steps and majorant optical depth of random lines") {
    const Box box{Vec3(0.f, 0.f, 0.f), Vec3(2.f, 1.f, 1.5f)};  // not a cube: the surfaces weigh the axes
    const M medium = corner_block(box);
    for (const std::array<int, 3> res : {std::array<int, 3>{4, 4, 4}, std::array<int, 3>{8, 3, 5}, std::array<int, 3>{16, 16, 16}}) {
        CAPTURE(res[0]); CAPTURE(res[1]); CAPTURE(res[2]);
        const MajorantCost model = grid_majorant_cost(medium, res);
        const GridMajorant<M> grid(medium, res);
        Pcg32 rng(11, 5);
        Stat steps, depth;
        for (int i = 0; i < 20000; ++i) {
            const Ray ray = random_line(rng, box);
            auto it = grid.iterate(ray, 0.f, kInf, {});
            double tau = 0.0;
            while (auto s = it.next()) tau += double(s->t1 - s->t0) * double(s->sigma_maj);
            steps.add(double(it.steps()));
            depth.add(tau);
        }
        CAPTURE(model.steps); CAPTURE(steps.mean); CAPTURE(model.lookups); CAPTURE(depth.mean);
        CHECK(std::abs(steps.mean - model.steps) <= 5.0 * steps.se());
        CHECK(std::abs(depth.mean - model.lookups) <= 5.0 * depth.se());
        CHECK(model.cost == doctest::Approx(model.lookups + double(kDefaultStepCost) * model.steps).epsilon(1e-12));
    }
    // The global majorant: its optical depth over the same lines.
    const MajorantCost global = global_majorant_cost(medium);
    const GlobalMajorant<M> maj(medium);
    Pcg32 rng(12, 5);
    Stat depth;
    for (int i = 0; i < 20000; ++i) {
        const Ray ray = random_line(rng, box);
        const Interval in = box.clip(ray, 0.f, kInf);
        depth.add(double(in.t1 - in.t0) * double(maj.value()));
    }
    CHECK(global.global);
    CHECK(global.steps == 0.0);
    CHECK(std::abs(depth.mean - global.lookups) <= 5.0 * depth.se());
}

TEST_CASE("the cost model's closed forms on a constant medium, and its choice there: the global majorant") {
    // A cube of side 2, density 1, mu_t = 3: a random line's mean chord is 4V/S = 4/3.
    const Box box{Vec3(0.f), Vec3(2.f)};
    const M medium(box, {8, 8, 8}, std::vector<float>(512, 1.f), grey<Mono>(1.f), grey<Mono>(2.f));
    const MajorantCost global = global_majorant_cost(medium);
    CHECK(global.lookups == doctest::Approx(3.0 * 4.0 / 3.0).epsilon(1e-6));
    for (int r : {1, 2, 4, 8, 32}) {
        CAPTURE(r);
        const MajorantCost c = grid_majorant_cost(medium, {r, r, r});
        CHECK(c.steps == doctest::Approx(double(r)).epsilon(1e-9));  // r^3 cells of surface 6 (2/r)^2 over 24
        CHECK(c.lookups == doctest::Approx(4.0 * (1.0 + 1.0 / 65536.0)).epsilon(1e-6));  // padded by 2^-16
        CHECK(!c.global);
    }
    // Unequal cells: 4 x 2 x 1 unit cubes in a 4 x 2 x 1 box cross 8 x 6 / 28 cells per line.
    const Box slab{Vec3(0.f), Vec3(4.f, 2.f, 1.f)};
    const M flat(slab, {4, 4, 4}, std::vector<float>(64, 1.f), grey<Mono>(1.f), grey<Mono>(2.f));
    CHECK(grid_majorant_cost(flat, {4, 2, 1}).steps == doctest::Approx(48.0 / 28.0).epsilon(1e-9));
    // Nothing a grid bounds more tightly than the global value: steps only add.
    CHECK(choose_grid_resolution(medium).global);
    CHECK(choose_grid_resolution(medium, 64, 0.f).global);  // even free steps: the padding tips it
}

TEST_CASE("the cost model picks a grid for a sparse medium, the fewest lookups when steps are free, global when dear") {
    const Box box{Vec3(0.f), Vec3(1.f)};
    const M medium = corner_block(box);
    const MajorantCost global = global_majorant_cost(medium);
    const MajorantCost best = choose_grid_resolution(medium);
    CAPTURE(best.resolution[0]); CAPTURE(best.cost); CAPTURE(global.cost);
    CHECK(!best.global);
    CHECK(best.lookups < 0.1 * global.lookups);
    // It is the least of every candidate (the global majorant and 2, 4, ..., 64 cells per axis).
    CHECK(best.cost <= global.cost);
    double finer_lookups = std::numeric_limits<double>::infinity();
    for (int r = 2; r <= 64; r *= 2) {
        const MajorantCost c = grid_majorant_cost(medium, {r, r, r});
        CHECK(best.cost <= c.cost);
        CHECK(c.lookups <= finer_lookups);  // nested cells bound no looser than their parents
        finer_lookups = c.lookups;
    }
    CHECK(grid_majorant_cost(medium, best.resolution).cost == best.cost);
    // Free steps: the grid of the fewest lookups; very dear steps: global.
    const MajorantCost free_steps = choose_grid_resolution(medium, 64, 0.f);
    CHECK(!free_steps.global);
    for (int r = 2; r <= 64; r *= 2) CHECK(free_steps.lookups <= grid_majorant_cost(medium, {r, r, r}).lookups);
    CHECK(choose_grid_resolution(medium, 64, 1000.f).global);
    CHECK(choose_grid_resolution(medium, 1).global);  // no grid candidate below 2 cells
}

TEST_CASE("the cost model rejects a bad step cost or resolution, naming it") {
    const M medium = corner_block(Box{Vec3(0.f), Vec3(1.f)});
    CHECK_THROWS_WITH_AS(choose_grid_resolution(medium, 0), Contains("max_res = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(choose_grid_resolution(medium, 5000), Contains("max_res = 5000"), InvalidArgument);
    CHECK_THROWS_WITH_AS(choose_grid_resolution(medium, 16, -1.f), Contains("step_cost = -1"), InvalidArgument);
    CHECK_THROWS_WITH_AS(grid_majorant_cost(medium, {4, 4, 4}, std::numeric_limits<float>::quiet_NaN()),
                         Contains("step_cost = nan"), InvalidArgument);
    CHECK_THROWS_WITH_AS(grid_majorant_cost(medium, {4, 0, 4}), Contains("resolution[1] = 0"), InvalidArgument);
}

TEST_CASE("the control's cost model: the residual optical depth of random lines, and its choice") {
    // Lookups: the residual majorant's optical depth (majorant less the grey control) over random
    // lines, within 5 SE of 20000 lines, as decomposition and residual ratio tracking draw their
    // tentative collisions at that rate; steps: the grid's.
    const Box box{Vec3(0.f, 0.f, 0.f), Vec3(2.f, 1.f, 1.5f)};
    std::vector<float> d(16 * 16 * 16);
    Pcg32 fill(3, 3);
    for (float& v : d) v = 0.5f + fill.uniform();  // everywhere between 0.5 and 1.5: a large minorant
    const M medium(box, {16, 16, 16}, std::move(d), grey<Mono>(2.f), grey<Mono>(8.f));
    for (const std::array<int, 3> res : {std::array<int, 3>{4, 4, 4}, std::array<int, 3>{8, 3, 5}}) {
        CAPTURE(res[0]); CAPTURE(res[1]); CAPTURE(res[2]);
        const MajorantCost model = grid_control_cost(medium, res);
        const MajorantCost plain = grid_majorant_cost(medium, res);
        const GridControl<M> control(medium, res);
        Pcg32 rng(13, 5);
        Stat steps, depth;
        for (int i = 0; i < 20000; ++i) {
            const Ray ray = random_line(rng, box);
            auto it = control.iterate(ray, 0.f, kInf, {});
            double tau = 0.0;
            while (auto s = it.next()) tau += double(s->t1 - s->t0) * (double(s->sigma_maj) - double(s->sigma_ctl[0]));
            steps.add(double(it.steps()));
            depth.add(tau);
        }
        CAPTURE(model.steps); CAPTURE(steps.mean); CAPTURE(model.lookups); CAPTURE(depth.mean);
        CHECK(model.control);
        CHECK(std::abs(steps.mean - model.steps) <= 5.0 * steps.se());
        CHECK(std::abs(depth.mean - model.lookups) <= 5.0 * depth.se());
        CHECK(model.steps == doctest::Approx(plain.steps).epsilon(1e-12));
        // The density's minimum is at least 1/3 of its maximum in every cell: the control removes at
        // least a third of the lookups.
        CHECK(model.lookups < (2.0 / 3.0) * plain.lookups);
    }
    // The choice: with the control's steps at the grid's cost, a control (it never costs more
    // lookups than the same grid); with dear control steps, no control.
    const MajorantCost cheap = choose_majorant(medium, 64, kDefaultStepCost, kDefaultStepCost);
    CHECK(cheap.control);
    CHECK(cheap.cost < choose_grid_resolution(medium).cost);
    const MajorantCost dear = choose_majorant(medium, 64, kDefaultStepCost, 1e6f);
    CHECK(!dear.control);
    CHECK(dear.cost == choose_grid_resolution(medium).cost);
    CHECK_THROWS_WITH_AS(choose_majorant(medium, 64, kDefaultStepCost, -1.f), Contains("step_cost = -1"),
                         InvalidArgument);
}

TEST_CASE("the control's cost model takes no control for a chromatic medium") {
    // The same densities with extinction per density 2 : 8 : 4 in Rgb: the grey control would leave
    // the denser channels' null weights far from 1, a variance the lookup model cannot see.
    const Box box{Vec3(0.f), Vec3(1.f)};
    std::vector<float> d(8 * 8 * 8);
    Pcg32 fill(4, 4);
    for (float& v : d) v = 0.5f + fill.uniform();
    const DenseGridMedium<Rgb> chromatic(box, {8, 8, 8}, std::vector<float>(d), Rgb::Spectrum(1.f, 4.f, 2.f),
                                         Rgb::Spectrum(1.f, 4.f, 2.f));
    const DenseGridMedium<Rgb> grey_rgb(box, {8, 8, 8}, std::move(d), Rgb::Spectrum::Constant(2.f),
                                        Rgb::Spectrum::Constant(2.f));
    CHECK(!choose_majorant(chromatic, 64, kDefaultStepCost, kDefaultStepCost).control);
    CHECK(choose_majorant(grey_rgb, 64, kDefaultStepCost, kDefaultStepCost).control);
}
