// tests/test_tree_majorant.cpp: the two-level (tree) majorant of nsp/majorants/tree.hpp.
//
// - Every segment the walk yields bounds what the medium's lookup returns (compared exactly) at
//   its ends and at random points, over random rays through sparse and dense grids, grey and per
//   channel; and every point where the density is not 0 lies in a segment (no gaps).
// - The walk yields, segment by segment, the value of the finest cell at the segment's midpoint,
//   and its stretches are contiguous and increasing.
// - An empty coarse cell costs one DDA step and no lookup; a uniform one is not split; a cell
//   splits where the cost model says it pays, not where it does not.
// - Ratio and delta tracking (and ratio tracking under half the bound, bound::Signed) match the closed-form transmittance through a volume of constant
//   blocks (different values, trilinear between them): along an axis through voxel centres the
//   density is piecewise linear, so the optical depth is a trapezoid sum, exact.
// - Constructors reject layouts and scales that are not allowed, naming them.
//
// Statistical checks: fixed seeds, k = 5 standard errors estimated from the samples.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <nsp/majorants/tree.hpp>

#include "majorants.hpp"
#include "spectral.hpp"

namespace {

using namespace nsp_test;
using doctest::Contains;

constexpr double kSigmas = 5.0;

/// A res grid over b whose densities are 0 outside a few blobs (a sparse volume), or, with
/// `dense`, everywhere in [0.5, 3).
template <SpectralMode S>
DenseGridMedium<S> test_volume(const Box& b, std::array<int, 3> res, bool dense, const typename S::Coefficient& sa,
                               const typename S::Coefficient& ss, std::uint64_t seed) {
    Pcg32 rng(seed, 7);
    const std::size_t voxels = std::size_t(res[0]) * std::size_t(res[1]) * std::size_t(res[2]);
    std::vector<float> d(voxels, 0.f);
    const Vec3 centres[] = {Vec3(0.2f, 0.3f, 0.25f), Vec3(0.7f, 0.6f, 0.8f), Vec3(0.8f, 0.15f, 0.3f)};
    std::size_t i = 0;
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x, ++i) {
                const Vec3 u((float(x) + 0.5f) / float(res[0]), (float(y) + 0.5f) / float(res[1]),
                             (float(z) + 0.5f) / float(res[2]));
                if (dense) {
                    d[i] = 0.5f + 2.5f * rng.uniform();
                    continue;
                }
                for (const Vec3& c : centres)
                    if (glm::length(u - c) < 0.12f) d[i] = 3.f * rng.uniform();
            }
    return {b, res, std::move(d), sa, ss};
}

/// Walks `maj` along r over [tmin, tmax] and checks the segments: increasing and contiguous
/// where both are yielded, each bounding the lookup at its ends and at random points inside,
/// each with the value value_at gives at its midpoint. Returns the segments.
template <class M, class Maj, class R>
std::vector<MajorantSegment<MajorantValue<Maj, M>>> check_walk(const M& medium, const Maj& maj, const Ray& r,
                                                                float tmin, float tmax,
                                                                const typename M::Spectral::Wavelengths& l, R& rng) {
    std::vector<MajorantSegment<MajorantValue<Maj, M>>> segs;
    auto it = maj.iterate(r, tmin, tmax, l);
    while (auto s = it.next()) segs.push_back(*s);
    float last = tmin;
    for (const auto& s : segs) {
        CHECK(s.t0 >= last);
        CHECK(s.t1 > s.t0);
        last = s.t1;
        if (s.t1 - s.t0 > 1e-4f) {  // a stretch grazing a cell's edge may round into its neighbour
            const auto at_mid = maj.value_at(r.at(0.5f * (s.t0 + s.t1)), l);
            for (int c = 0; c < M::Spectral::channels; ++c) CHECK(channel_of(at_mid, c) == channel_of(s.sigma_maj, c));
        }
        for (int k = 0; k < 12; ++k) {
            const float t = k == 0 ? s.t0 : k == 1 ? std::nextafter(s.t1, s.t0) : s.t0 + (s.t1 - s.t0) * rng.uniform();
            const auto mu_t = medium.coefficients(r.at(t), l).sigma_t();
            for (int c = 0; c < M::Spectral::channels; ++c) {
                CAPTURE(t);
                CHECK(mu_t[c] <= channel_of(s.sigma_maj, c));  // exact: no tolerance
            }
        }
    }
    return segs;
}

template <class M, class Maj>
void check_tree_bounds(const M& medium, const Maj& maj, const std::string& name, int min_covered) {
    using S = typename M::Spectral;
    CAPTURE(name);
    const Box b = medium.bounds();
    const Box around{b.lo - 0.5f * (b.hi - b.lo), b.hi + 0.5f * (b.hi - b.lo)};
    Pcg32 rng(29, 4);
    int covered = 0;
    for (int i = 0; i < 600; ++i) {
        CAPTURE(i);
        Vec3 d = random_direction(rng);
        if (i % 10 == 0) {  // along an axis
            d = Vec3(0.f);
            d[i / 10 % 3] = i % 20 ? 1.f : -1.f;
        }
        const Ray r{i % 3 ? random_point(rng, around) : random_point(rng, b), d};
        const float tmin = i % 4 == 3 ? 0.3f * rng.uniform() : 0.f;
        const auto lambda = draw_wavelengths<S>(rng);
        const auto segs = check_walk(medium, maj, r, tmin, kInf, lambda, rng);
        // No gaps: wherever the density is not 0 along the ray, a segment covers the point.
        const Interval in = b.clip(r, tmin, kInf);
        if (in.empty()) continue;
        for (int k = 0; k < 40; ++k) {
            const float t = in.t0 + (in.t1 - in.t0) * rng.uniform();
            if (!(medium.coefficients(r.at(t), lambda).sigma_t().maxCoeff() > 0.f)) continue;
            ++covered;
            const bool inside = std::any_of(segs.begin(), segs.end(), [&](const auto& s) { return s.t0 <= t && t < s.t1; });
            CAPTURE(t);
            CHECK(inside);
        }
    }
    CHECK(covered > min_covered);  // the rays met density (a few hundred points in the sparse volume)
}

TEST_CASE("every tree majorant segment bounds the lookup, and the segments leave no density uncovered") {
    const Box b{Vec3(-1.f, -0.5f, -2.f), Vec3(1.5f, 1.f, 0.5f)};
    for (const bool dense : {false, true}) {
        CAPTURE(dense);
        const auto rgb = test_volume<Rgb>(b, {40, 24, 33}, dense, spec<Rgb>(0.3f, 0.1f, 2.f), spec<Rgb>(0.7f, 1.9f, 6.f), 3);
        using M = DenseGridMedium<Rgb>;
        // Coarse cells that do not align with the voxels, bricks of 1 to 8 fine cells.
        for (const auto& case_ : {std::pair{std::array<int, 3>{3, 2, 4}, 4}, std::pair{std::array<int, 3>{5, 3, 4}, 8},
                                  std::pair{std::array<int, 3>{1, 1, 1}, 16}, std::pair{std::array<int, 3>{7, 5, 6}, 1}}) {
            const auto& coarse = case_.first;
            const int brick = case_.second;
            CAPTURE(brick);
            check_tree_bounds(rgb, TreeMajorant<M>(rgb, coarse, brick), "grey", dense ? 2000 : 200);
            check_tree_bounds(rgb, ChannelTreeMajorant<M>(rgb, coarse, brick), "per channel", dense ? 2000 : 200);
        }
        // Deeper trees: two and three splits below the coarse grid.
        for (const auto& split : {std::array<int, 3>{2, 3, 0}, std::array<int, 3>{3, 2, 2}, std::array<int, 3>{4, 4, 0}}) {
            CAPTURE(split[0]); CAPTURE(split[1]); CAPTURE(split[2]);
            const TreeLayout layout{rgb.bounds(), {2, 1, 3}, split, 0.f, 0.f};  // split wherever the bound varies
            check_tree_bounds(rgb, TreeMajorant<M>(rgb, layout), "grey, deep", dense ? 2000 : 200);
            check_tree_bounds(rgb, ChannelTreeMajorant<M>(rgb, layout), "per channel, deep", dense ? 2000 : 200);
        }
        const auto hero = test_volume<Hero<4>>(b, {16, 16, 16}, dense,
                                               TabulatedSpectrum::from_points({450.f, 650.f}, {2.f, 0.3f}),
                                               TabulatedSpectrum::from_points({450.f, 650.f}, {6.f, 0.7f}), 5);
        check_tree_bounds(hero, ChannelTreeMajorant<DenseGridMedium<Hero<4>>>(hero, {2, 2, 2}, 4), "hero per channel",
                          dense ? 2000 : 200);
    }
}

TEST_CASE("an empty coarse cell costs one DDA step and no lookup; uniform coarse cells are not split") {
    // 32^3 voxels over [0, 4]^3, density 2 in the block x, y, z < 8 voxels (1 unit) and 0 elsewhere;
    // coarse cells of 1 unit (8 voxels), bricks of 4.
    std::vector<float> d(32 * 32 * 32, 0.f);
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) d[std::size_t(x + 32 * (y + 32 * z))] = 2.f;
    using M = DenseGridMedium<Mono>;
    const M medium(Box{Vec3(0.f), Vec3(4.f)}, {32, 32, 32}, d, grey<Mono>(1.f), grey<Mono>(1.f));
    // Split wherever the bound varies (step and descent cost 0), to count the cells exactly.
    const TreeMajorant<M> tree(medium, TreeLayout{medium.bounds(), {4, 4, 4}, {4, 0, 0}, 0.f, 0.f});
    // The block's own coarse cell is uniform: every fine cell of it reads voxels of density 2.
    // Its seven face, edge and corner neighbours read the block's last voxel layer across their
    // faces: split, their first fine cells bound 2 and the rest 0. Every other cell is empty.
    CHECK(tree.coarse_cells() == 64);
    CHECK(tree.empty_cells() == 64 - 8);
    CHECK(tree.split_cells() == 7);
    CHECK(tree.memory_bytes() == 64 * 4 + 7 * 64 * 4);  // 4 bytes per cell: a bound or a node
    Pcg32 rng(3, 3);
    LookupCount empty;
    for (int i = 0; i < 200; ++i) {
        // Along +x at y, z in the empty cells y, z in [2, 4): four coarse cells, all empty.
        const Ray r{Vec3(-1.f, 2.f + 2.f * rng.uniform(), 2.f + 2.f * rng.uniform()), Vec3(1.f, 0.f, 0.f)};
        const auto f = free_flight(medium, tree, r, 0.f, kInf, {}, rng, empty,
                                   [](float, const Coefficients<Mono>&, float, float) { return true; });
        CHECK(!f.stopped);
    }
    CHECK(empty.count() == 0);
    CHECK(empty.steps == 200 * 4);  // one step per coarse cell, none per fine cell
}

TEST_CASE("a cell splits only where the cost model says the steps pay for the lookups they save") {
    // One dense voxel block (density 2, 2^3 voxels of 0.125) in the corner of a 1^3 coarse cell of
    // 32^3 voxels, split into 4^3: as one cell a ray meets mu_bar = 2 x 10 over a mean chord of
    // 4 V / S = 2/3, 13.3 tentative collisions; split, the descent (1 lookup) and the 64 parts in
    // proportion to their surface (1/16 each: a step each, and the block's 20 x 1/6), about 1 +
    // 4 steps + 1.4 in all. With steps at 0.3 lookups it splits; at 10 lookups per step
    // (5 x 10 > 13.3) it does not.
    std::vector<float> d(32 * 32 * 32, 0.f);
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) d[std::size_t(x + 32 * (y + 32 * z))] = 2.f;
    using M = DenseGridMedium<Mono>;
    const M medium(Box{Vec3(0.f), Vec3(1.f)}, {32, 32, 32}, d, grey<Mono>(5.f), grey<Mono>(5.f));
    const TreeMajorant<M> cheap(medium, TreeLayout{medium.bounds(), {1, 1, 1}, {4, 0, 0}, 0.3f});
    const TreeMajorant<M> dear(medium, TreeLayout{medium.bounds(), {1, 1, 1}, {4, 0, 0}, 10.f});
    CHECK(cheap.split_cells() == 1);
    CHECK(dear.split_cells() == 0);
    CHECK(dear.memory_bytes() == 4);  // the coarse cell alone
    // The bound of the unsplit cell is the block's; the split one is 0 away from the block.
    CHECK(dear.value_at(Vec3(0.9f), {}) == doctest::Approx(20.0).epsilon(1e-4));
    CHECK(cheap.value_at(Vec3(0.9f), {}) == 0.f);
    CHECK(cheap.value_at(Vec3(0.01f), {}) == doctest::Approx(20.0).epsilon(1e-4));
}

TEST_CASE_TEMPLATE("tracking through a volume of constant blocks matches the closed-form transmittance", S, Mono, Rgb) {
    // 24 x 16 x 16 voxels over [0, 24] x [0, 16] x [0, 16] (voxel centres at half integers),
    // constant in blocks of 4^3 voxels with values 0 (a third), 0.5, 1 or 3, trilinear between.
    const std::array<int, 3> res{24, 16, 16};
    Pcg32 pick(11, 2);
    float block[6][4][4];
    for (auto& plane : block)
        for (auto& row : plane)
            for (float& v : row) {
                const float u = pick.uniform();
                v = u < 0.33f ? 0.f : u < 0.55f ? 0.5f : u < 0.8f ? 1.f : 3.f;
            }
    std::vector<float> d(std::size_t(res[0] * res[1] * res[2]));
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) d[std::size_t(x + res[0] * (y + res[1] * z))] = block[x / 4][y / 4][z / 4];
    using M = DenseGridMedium<S>;
    const auto sa = spec<S>(0.02f, 0.01f, 0.05f), ss = spec<S>(0.08f, 0.06f, 0.1f);
    const M medium(Box{Vec3(0.f), Vec3(24.f, 16.f, 16.f)}, res, d, sa, ss);
    const auto mu = S::sample(sa + ss, {});
    // Along +x through voxel centres (y, z at half integers): the density is d(x0) up to the first
    // centre, linear between centres and d(x_last) after the last (clamped at the faces).
    auto exact = [&](int y, int z) {
        double tau = 0.5 * d[std::size_t(res[0] * (y + res[1] * z))] + 0.5 * d[std::size_t(res[0] - 1 + res[0] * (y + res[1] * z))];
        for (int x = 0; x + 1 < res[0]; ++x)
            tau += 0.5 * (d[std::size_t(x + res[0] * (y + res[1] * z))] + d[std::size_t(x + 1 + res[0] * (y + res[1] * z))]);
        typename S::Spectrum t;
        for (int c = 0; c < S::channels; ++c) t[c] = float(std::exp(-tau * double(mu[c])));
        return t;
    };
    const TreeMajorant<M> grey_tree(medium, {3, 2, 2}, 2);
    // Half the bound, signed weights (bound::Signed): unbiased too, over finer bricks.
    const TreeMajorant<M, bound::Signed> low_tree(medium, {6, 4, 4}, 4, 0.5f);
    Pcg32 rng(71, 1);
    LookupCount lookups;
    int rays = 0;
    for (const auto& yz : {std::pair{1, 2}, std::pair{6, 9}, std::pair{13, 3}, std::pair{10, 14}}) {
        const int y = yz.first, z = yz.second;
        CAPTURE(y);
        CAPTURE(z);
        const Ray r{Vec3(-2.f, float(y) + 0.5f, float(z) + 0.5f), Vec3(1.f, 0.f, 0.f)};
        const auto want = exact(y, z);
        SpecStat<S> ratio_g, delta_g, ratio_low;
        for (int i = 0; i < 40000; ++i) {
            ratio_g.add(transmittance_ratio(medium, grey_tree, r, kInf, {}, rng, lookups).value);
            delta_g.add(transmittance_delta(medium, grey_tree, r, kInf, {}, rng, lookups).value);
            ratio_low.add(transmittance_ratio(medium, low_tree, r, kInf, {}, rng, lookups).value);
        }
        for (int c = 0; c < S::channels; ++c) {
            CAPTURE(c);
            CAPTURE(want[c]);
            for (const Stat* s : {&ratio_g.ch[std::size_t(c)], &delta_g.ch[std::size_t(c)], &ratio_low.ch[std::size_t(c)]}) {
                CAPTURE(s->mean);
                CAPTURE(s->se());
                CHECK(std::abs(s->mean - want[c]) <= kSigmas * s->se() + kRoundingFloor);
            }
        }
        ++rays;
        CHECK(want[0] < 0.9f);  // the ray meets density
    }
    CHECK(rays == 4);
    CHECK(lookups.count() > 0);
}

TEST_CASE("tree majorant constructors reject layouts and scales that are not allowed") {
    using M = DenseGridMedium<Mono>;
    const M medium(Box{Vec3(0.f), Vec3(1.f)}, {2, 2, 2}, std::vector<float>(8, 1.f), grey<Mono>(1.f), grey<Mono>(1.f));
    CHECK_THROWS_WITH_AS(TreeMajorant<M>(medium, {0, 1, 1}, 4), Contains("coarse resolution[0] = 0 is not allowed"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(TreeMajorant<M>(medium, {1, 1, 1}, 0), Contains("brick = 0 cells per coarse cell and axis is not allowed"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(TreeMajorant<M>(medium, {1, 1, 1}, 65), Contains("it must lie in [1, 64]"), InvalidArgument);
    CHECK_THROWS_WITH_AS(TreeMajorant<M>(medium, TreeLayout{Box{Vec3(0.f), Vec3(0.5f, 1.f, 1.f)}, {1, 1, 1}, {2, 0, 0}}),
                         Contains("does not contain the medium's bounds [0, 1]"), InvalidArgument);
    CHECK_THROWS_WITH_AS(TreeMajorant<M>(medium, {1, 1, 1}, 2, 0.5f), Contains("TreeMajorant scale = 0.5 is below 1"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelTreeMajorant<M>(medium, {1, 1, 1}, 2, -1.f),
                         Contains("ChannelTreeMajorant scale = -1 is not allowed"), InvalidArgument);
    CHECK_THROWS_WITH_AS(TreeMajorant<M>(medium, TreeLayout{medium.bounds(), {1, 1, 1}, {2, 0, 3}}),
                         Contains("split[2] = 3 follows a 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(TreeMajorant<M>(medium, TreeLayout{medium.bounds(), {1, 1, 1}, {2, 65, 0}}),
                         Contains("split[1] = 65 cells per axis is not allowed"), InvalidArgument);
    CHECK_THROWS_WITH_AS(TreeMajorant<M>(medium, TreeLayout{medium.bounds(), {1, 1, 1}, {2, 0, 0}, -1.f}),
                         Contains("step_cost = -1 is not allowed"), InvalidArgument);
    CHECK_THROWS_WITH_AS(TreeMajorant<M>(medium, TreeLayout{medium.bounds(), {1, 1, 1}, {2, 0, 0}, 0.3f, kInf}),
                         Contains("descent_cost = inf is not allowed"), InvalidArgument);
    CHECK_NOTHROW(TreeMajorant<M, bound::Signed>(medium, {1, 1, 1}, 2, 0.5f));
}

}  // namespace
