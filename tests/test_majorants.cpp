// tests/test_majorants.cpp: grid majorants and bound policies (THEORY 1, 4).
//
// - The DDA visits exactly the cells a brute-force enumeration of plane crossings (in double)
//   finds, in order, with matching entry and exit distances, over random rays and the edge cases:
//   origins inside, outside, on a cell face, edge or vertex; rays along an axis, along a face,
//   through grid vertices, with zero and denormal direction components; mid-ray starts.
// - Every grid majorant bounds what the medium's lookup returns (rounding included, compared
//   exactly) at random points of every cell, its corners and points on its faces.
// - Cells whose bound is 0 cost no lookup.
// - Transmittance and every PathEstimator stay unbiased with grid majorants and with majorants
//   below the extinction under bound::Signed; bound::Clamp's estimate equals the clamped
//   medium's closed form (and differs from the true one: the bias is what the clamp predicts);
//   bound::Reject discards flights and reports it.
// - Constructors reject resolutions, scales and values the policy forbids, naming them.
//
// Statistical checks: fixed seeds, k = 5 standard errors estimated from the samples.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "majorants.hpp"
#include "spectral.hpp"

namespace {

using namespace nsp_test;
using doctest::Contains;

constexpr double kSigmas = 5.0;

// ---------------------------------------------------------------------------------------------
// The DDA against brute force

struct CellSpan {
    std::array<int, 3> cell;
    double t0, t1;
};

/// Where the grid puts plane k of axis a: lo + k h with the cell size h = (hi - lo) / res in
/// float. This defines the cells (a float grid cannot have exact thirds); the brute force below
/// finds the crossings of these planes independently, in double.
float plane(const Box& b, const std::array<int, 3>& res, int a, int k) {
    return b.lo[a] + float(k) * ((b.hi[a] - b.lo[a]) / float(res[a]));
}

/// The cells of the res grid over b that ray r crosses in [tmin, tmax], found in double by
/// sorting every crossing of an interior plane and locating each stretch's midpoint.
std::vector<CellSpan> brute_force_cells(const Box& b, const std::array<int, 3>& res, const Ray& r, float tmin,
                                        float tmax) {
    double t0 = tmin, t1 = tmax;
    for (int a = 0; a < 3; ++a) {
        if (r.d[a] == 0.f) {
            if (r.o[a] < b.lo[a] || r.o[a] > b.hi[a]) return {};
            continue;
        }
        double tn = (double(b.lo[a]) - r.o[a]) / r.d[a], tf = (double(b.hi[a]) - r.o[a]) / r.d[a];
        if (tn > tf) std::swap(tn, tf);
        t0 = std::max(t0, tn);
        t1 = std::min(t1, tf);
    }
    if (!(t0 < t1)) return {};
    std::vector<double> ts{t0, t1};
    for (int a = 0; a < 3; ++a) {
        if (r.d[a] == 0.f) continue;
        for (int k = 1; k < res[a]; ++k) {
            const double t = (double(plane(b, res, a, k)) - r.o[a]) / r.d[a];
            if (t0 < t && t < t1) ts.push_back(t);
        }
    }
    std::sort(ts.begin(), ts.end());
    std::vector<CellSpan> out;
    for (std::size_t i = 1; i < ts.size(); ++i) {
        if (!(ts[i] > ts[i - 1])) continue;
        const double mid = 0.5 * (ts[i] + ts[i - 1]);
        CellSpan s{{}, ts[i - 1], ts[i]};
        // Along each axis the cell is the number of interior planes behind the midpoint, decided
        // by crossing distances rather than positions: o + d t rounds to o for a denormal d, but
        // the crossing (plane - o) / d is exact enough in double to say which side t is on.
        for (int a = 0; a < 3; ++a) {
            int cell = 0;
            for (int k = 1; k < res[a]; ++k) {
                const double pl = plane(b, res, a, k);
                const double tk = (pl - r.o[a]) / r.d[a];
                const bool behind = r.d[a] > 0.f ? tk <= mid : r.d[a] < 0.f ? tk > mid : double(r.o[a]) >= pl;
                cell += behind;
            }
            s.cell[std::size_t(a)] = cell;
        }
        out.push_back(s);
    }
    return out;
}

/// What the DDA of a grid majorant walks for the same ray.
std::vector<CellSpan> dda_cells(const Box& b, const std::array<int, 3>& res, const Ray& r, float tmin, float tmax,
                                Interval& clipped) {
    Vec3 cell;
    for (int a = 0; a < 3; ++a) cell[a] = (b.hi[a] - b.lo[a]) / float(res[a]);
    clipped = b.clip(r, tmin, tmax);
    nsp::detail::GridWalk walk(b, res, cell, r, clipped);
    std::vector<CellSpan> out;
    std::size_t i;
    float t0, t1;
    while (walk.next(i, t0, t1)) {
        const int x = int(i % std::size_t(res[0])), y = int(i / std::size_t(res[0]) % std::size_t(res[1]));
        const int z = int(i / (std::size_t(res[0]) * std::size_t(res[1])));
        out.push_back({{x, y, z}, t0, t1});
        REQUIRE(out.size() <= std::size_t(res[0] + res[1] + res[2]));  // at most one cell per plane crossed
    }
    return out;
}

/// Compares the DDA with brute force for one ray. Crossings are computed in float by the DDA:
/// a plane's position and the origin carry ~1e-7 S of rounding (S the largest coordinate or
/// distance involved), so a crossing t is off by ~1e-7 S / |d_a|; we allow 100x that,
/// tol = 1e-5 S / min |d_a| over the axes with |d_a| >= 0.05 (the only ones the random rays
/// cross at finite t, besides exact zeros and denormals). Stretches shorter than 4 tol (grazed
/// edges and corners) are compared as absent from both lists.
void check_dda(const Box& b, const std::array<int, 3>& res, const Ray& r, float tmin, float tmax) {
    CAPTURE(r.o.x); CAPTURE(r.o.y); CAPTURE(r.o.z);
    CAPTURE(r.d.x); CAPTURE(r.d.y); CAPTURE(r.d.z);
    CAPTURE(tmin); CAPTURE(tmax);
    Interval clipped;
    const auto dda = dda_cells(b, res, r, tmin, tmax, clipped);
    const auto ref = brute_force_cells(b, res, r, tmin, tmax);
    double scale = 1.0, dmin = 1.0;
    for (int a = 0; a < 3; ++a) {
        scale = std::max({scale, double(std::abs(r.o[a])), double(std::abs(b.lo[a])), double(std::abs(b.hi[a]))});
        if (std::abs(r.d[a]) >= 0.05f) dmin = std::min(dmin, double(std::abs(r.d[a])));
    }
    if (!ref.empty()) scale = std::max(scale, std::abs(ref.back().t1));
    const double tol = 1e-5 * scale / dmin, min_len = 4.0 * tol;

    // Structure: contiguous from the clipped entry, one axis stepped by one cell at a time.
    if (!dda.empty()) {
        CHECK(dda.front().t0 == double(clipped.t0));
        CHECK(std::abs(dda.back().t1 - double(clipped.t1)) <= tol);
    }
    for (std::size_t i = 1; i < dda.size(); ++i) {
        CHECK(dda[i].t0 == dda[i - 1].t1);
        CHECK(dda[i].t1 >= dda[i].t0);
        int moved = 0;
        for (int a = 0; a < 3; ++a) moved += std::abs(dda[i].cell[std::size_t(a)] - dda[i - 1].cell[std::size_t(a)]);
        CHECK(moved == 1);
    }
    // Cells and distances against brute force.
    auto long_only = [&](const std::vector<CellSpan>& v) {
        std::vector<CellSpan> o;
        for (const auto& s : v)
            if (s.t1 - s.t0 > min_len) o.push_back(s);
        return o;
    };
    const auto a = long_only(dda), e = long_only(ref);
    REQUIRE(a.size() == e.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        CAPTURE(i);
        CHECK(a[i].cell == e[i].cell);
        CHECK(std::abs(a[i].t0 - e[i].t0) <= tol);
        CHECK(std::abs(a[i].t1 - e[i].t1) <= tol);
    }
}

TEST_CASE("grid majorant DDA visits the cells brute force finds, in order, at the same distances") {
    struct Config {
        Box box;
        std::array<int, 3> res;
    };
    const Config configs[] = {
        {{Vec3(-1.f, -0.5f, -2.f), Vec3(1.5f, 1.f, 0.5f)}, {5, 3, 7}},
        {{Vec3(-1.f), Vec3(1.f)}, {4, 4, 4}},
        {{Vec3(0.f), Vec3(1.f)}, {1, 1, 1}},
        {{Vec3(2.f, -3.f, 0.25f), Vec3(2.5f, 5.f, 0.75f)}, {2, 16, 1}},
    };
    Pcg32 rng(91, 3);
    int rays = 0;
    for (const Config& cfg : configs) {
        const Box& b = cfg.box;
        const auto& res = cfg.res;
        const Box around{b.lo - (b.hi - b.lo), b.hi + (b.hi - b.lo)};
        auto random_dir = [&] {
            // Components exactly 0 (10%), denormal (5%) or drawn on the sphere; never all 0.
            for (;;) {
                Vec3 d = random_direction(rng);
                for (int a = 0; a < 3; ++a) {
                    const float u = rng.uniform();
                    if (u < 0.1f) d[a] = 0.f;
                    else if (u < 0.15f) d[a] = std::copysign(1e-40f, d[a]);
                    else if (std::abs(d[a]) < 0.05f) d[a] = std::copysign(0.05f, d[a]);
                }
                if (std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}) >= 0.05f) return d;
            }
        };
        auto range = [&](float& tmin, float& tmax) {
            tmin = rng.uniform() < 0.7f ? 0.f : 3.f * rng.uniform();
            tmax = rng.uniform() < 0.5f ? kInf : tmin + 6.f * rng.uniform();
        };
        auto on_plane = [&](Vec3& p, int a) { p[a] = plane(b, res, a, int(rng.uniform() * float(res[a] + 1)) % (res[a] + 1)); };
        for (int i = 0; i < 1500; ++i, ++rays) {
            CAPTURE(i);
            float tmin, tmax;
            range(tmin, tmax);
            Vec3 o = random_point(rng, around);
            const int kind = i % 6;
            if (kind == 1) o = random_point(rng, b);                     // inside
            if (kind == 2) on_plane(o = random_point(rng, b), i % 3);    // on a cell face
            if (kind == 3) {                                             // on a cell edge
                o = random_point(rng, b);
                on_plane(o, i % 3);
                on_plane(o, (i + 1) % 3);
            }
            const Vec3 d = random_dir();
            if (kind == 4) {  // through a grid vertex (grazing a corner of up to eight cells)
                Vec3 v;
                for (int a = 0; a < 3; ++a) on_plane(v, a);
                o = v - 2.f * glm::length(b.hi - b.lo) * d;
                tmin = 0.f;
                tmax = kInf;
            }
            if (kind == 5) {  // origin on a vertex
                o = random_point(rng, b);
                for (int a = 0; a < 3; ++a) on_plane(o, a);
            }
            check_dda(b, res, Ray{o, d}, tmin, tmax);
        }
        // Axis-parallel rays along cell faces and edges, both directions, from inside and outside.
        for (int a = 0; a < 3; ++a)
            for (const float sign : {1.f, -1.f})
                for (int i = 0; i < 40; ++i, ++rays) {
                    Vec3 d(0.f);
                    d[a] = sign;
                    Vec3 o = random_point(rng, i % 2 ? b : around);
                    if (i % 4 < 2) on_plane(o, (a + 1) % 3);
                    if (i % 8 < 2) on_plane(o, (a + 2) % 3);
                    check_dda(b, res, Ray{o, d}, 0.f, kInf);
                }
    }
    CHECK(rays > 6000);
}

// ---------------------------------------------------------------------------------------------
// Every cell bounds the lookup

/// A 9 x 7 x 5 grid of densities, a third of them 0 and the rest uniform in [0, 3): some
/// majorant cells hold only zeros.
template <SpectralMode S>
DenseGridMedium<S> patchy_grid(const Box& b, const typename S::Coefficient& sa, const typename S::Coefficient& ss) {
    const std::array<int, 3> res{9, 7, 5};
    Pcg32 rng(5, 5);
    std::vector<float> d(std::size_t(res[0] * res[1] * res[2]));
    for (std::size_t i = 0; i < d.size(); ++i) {
        const bool empty_corner = i % 9 < 4 && i / 63 < 2;  // x < 4 and z < 2: a block of zeros
        d[i] = empty_corner || rng.uniform() < 0.33f ? 0.f : 3.f * rng.uniform();
    }
    return {b, res, std::move(d), sa, ss};
}

/// Points of cell (x, y, z) of a res grid over b: its corners, the centres of its faces, a
/// random point on each face and random interior points.
template <UniformRng R>
std::vector<Vec3> cell_points(const Box& b, const std::array<int, 3>& res, int x, int y, int z, R& rng) {
    const int c[3] = {x, y, z};
    Vec3 lo, hi;
    for (int a = 0; a < 3; ++a) {
        lo[a] = plane(b, res, a, c[a]);
        hi[a] = c[a] + 1 == res[a] ? b.hi[a] : plane(b, res, a, c[a] + 1);
    }
    std::vector<Vec3> pts;
    for (int k = 0; k < 8; ++k) pts.emplace_back(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
    for (int a = 0; a < 3; ++a)
        for (const bool high : {false, true}) {
            Vec3 centre = 0.5f * (lo + hi), random = random_point(rng, Box{lo, hi});
            centre[a] = random[a] = high ? hi[a] : lo[a];
            pts.push_back(centre);
            pts.push_back(random);
        }
    for (int i = 0; i < 30; ++i) pts.push_back(random_point(rng, Box{lo, hi}));
    return pts;
}

template <class M>
void check_bounds(const M& medium, const std::string& medium_name) {
    using S = typename M::Spectral;
    CAPTURE(medium_name);
    const Box b = medium.bounds();
    const std::array<int, 3> resolutions[] = {{1, 1, 1}, {3, 4, 2}, {4, 4, 4}, {9, 7, 5}, {5, 13, 2}, {16, 16, 16}};
    Pcg32 rng(17, 2);
    int zero_cells = 0, points = 0;
    for (const auto& res : resolutions) {
        CAPTURE(res[0]); CAPTURE(res[1]); CAPTURE(res[2]);
        const GridMajorant<M> grey_maj(medium, res);
        const ChannelGridMajorant<M> chan_maj(medium, res);
        for (int z = 0; z < res[2]; ++z)
            for (int y = 0; y < res[1]; ++y)
                for (int x = 0; x < res[0]; ++x) {
                    const auto lambda = draw_wavelengths<S>(rng);
                    const float g = grey_maj.cell(x, y, z);
                    const auto per = chan_maj.cell(x, y, z, lambda);
                    zero_cells += g == 0.f;
                    for (const Vec3& p : cell_points(b, res, x, y, z, rng)) {
                        ++points;
                        const auto mu_t = medium.coefficients(p, lambda).sigma_t();
                        CAPTURE(p.x); CAPTURE(p.y); CAPTURE(p.z);
                        CHECK(mu_t.maxCoeff() <= g);  // exact: no tolerance
                        CHECK((mu_t <= per).all());
                    }
                }
    }
    CHECK(points > 10000);
    if (medium_name == "patchy grid") CHECK(zero_cells > 0);  // cells of zero majorant were covered
}

TEST_CASE("every grid majorant cell bounds the lookup at random points, corners and faces") {
    const Box b{Vec3(-1.f, -0.5f, -2.f), Vec3(1.5f, 1.f, 0.5f)};
    check_bounds(patchy_grid<Rgb>(b, spec<Rgb>(0.3f, 0.1f, 2.f), spec<Rgb>(0.7f, 1.9f, 6.f)), "patchy grid");
    check_bounds(patchy_grid<Hero<4>>(b, TabulatedSpectrum::from_points({450.f, 650.f}, {2.f, 0.3f}),
                                      TabulatedSpectrum::from_points({450.f, 650.f}, {6.f, 0.7f})),
                 "patchy grid");
    check_bounds(ExponentialMedium<Rgb>(b, Vec3(1.f, -0.4f, 0.3f), 0.5f, 2.5f, spec<Rgb>(0.3f, 0.1f, 2.f),
                                        spec<Rgb>(0.7f, 1.9f, 6.f)),
                 "exponential");
}

TEST_CASE("cells whose bound is 0 cost no lookup; the DDA still walks them") {
    // Density only in the voxels with x < 2 of an 8^3 grid over [0, 1]^3.
    std::vector<float> d(512, 0.f);
    for (int i = 0; i < 512; ++i) d[std::size_t(i)] = i % 8 < 2 ? 1.f : 0.f;
    const DenseGridMedium<Mono> medium(Box{Vec3(0.f), Vec3(1.f)}, {8, 8, 8}, d, grey<Mono>(5.f), grey<Mono>(5.f));
    const GridMajorant<DenseGridMedium<Mono>> maj(medium, 8);
    Pcg32 rng(3, 3);
    LookupCount empty, dense;
    int segments = 0;
    for (int i = 0; i < 1000; ++i) {
        // From x = 0.6 towards +x: trilinear lookups read voxels x >= 3 only, all 0.
        const Ray away{Vec3(0.6f, 0.1f + 0.8f * rng.uniform(), 0.1f + 0.8f * rng.uniform()), Vec3(1.f, 0.f, 0.f)};
        const auto f = free_flight(medium, maj, away, 0.f, kInf, {}, rng, empty,
                                   [](float, const Coefficients<Mono>&, float, float) { return true; });
        CHECK(!f.stopped);
        auto it = maj.iterate(away, 0.f, kInf, {});
        while (it.next()) ++segments;
        const Ray toward{Vec3(0.6f, away.o.y, away.o.z), Vec3(-1.f, 0.f, 0.f)};
        free_flight(medium, maj, toward, 0.f, kInf, {}, rng, dense,
                    [](float, const Coefficients<Mono>&, float, float) { return true; });
    }
    CHECK(empty.count() == 0);
    CHECK(segments == 0);
    CHECK(empty.steps >= 1000 * 3);  // cells x = 4..7 were walked (and skipped)
    CHECK(dense.count() > 1000);     // the same rays reversed meet the dense cells
}

// ---------------------------------------------------------------------------------------------
// Unbiased with every majorant; Clamp's bias is the clamped medium's; Reject reports

/// Three rays through a medium in [-1, 1]^3: from outside, from inside, and a finite stretch.
struct TestRay {
    Ray ray;
    float tmax;
};
const TestRay kRays[] = {
    {{Vec3(-3.f, 0.2f, 0.1f), glm::normalize(Vec3(1.f, -0.05f, 0.02f))}, kInf},
    {{Vec3(0.1f, -0.2f, 0.3f), glm::normalize(Vec3(0.3f, 0.9f, -0.2f))}, kInf},
    {{Vec3(-0.7f, -0.6f, -0.8f), glm::normalize(Vec3(0.5f, 0.4f, 0.6f))}, 1.7f},
};

/// Ratio- and delta-tracking transmittance of `maj` along the test rays, each against expected(ray, tmax).
template <class M, class Maj, class Expected>
void check_transmittance(const M& medium, const Maj& maj, const std::string& name, Expected&& expected) {
    using S = typename M::Spectral;
    CAPTURE(name);
    Pcg32 rng(71, 1);
    LookupCount lookups;
    for (const TestRay& tr : kRays) {
        const auto want = expected(tr.ray, tr.tmax);
        SpecStat<S> ratio, delta;
        for (int i = 0; i < 40000; ++i) {
            ratio.add(transmittance_ratio(medium, maj, tr.ray, tr.tmax, {}, rng, lookups).value);
            delta.add(transmittance_delta(medium, maj, tr.ray, tr.tmax, {}, rng, lookups).value);
        }
        for (int c = 0; c < S::channels; ++c) {
            CAPTURE(c);
            CAPTURE(want[c]);
            for (const Stat* s : {&ratio.ch[std::size_t(c)], &delta.ch[std::size_t(c)]}) {
                CAPTURE(s->mean);
                CAPTURE(s->se());
                CHECK(std::abs(s->mean - want[c]) <= kSigmas * s->se() + kRoundingFloor);
            }
        }
    }
    CHECK(lookups.count() > 0);
}

TEST_CASE_TEMPLATE("transmittance is unbiased with grid majorants and with majorants below the extinction (Signed)",
                   S, Mono, Rgb) {
    using M = ExponentialMedium<S>;
    const Box b{Vec3(-1.f), Vec3(1.f)};
    const M medium = make_medium<M>(b, 1.f, spec<S>(0.2f, 0.1f, 0.5f), spec<S>(0.8f, 0.6f, 1.f));
    auto exact = [&](const Ray& r, float tmax) { return typename S::Spectrum((-medium.optical_depth(r, 0.f, tmax)).exp()); };
    for_each_kind<UnbiasedGreyKinds, M>([&](auto kind) {
        using K = decltype(kind);
        check_transmittance(medium, K::make(medium), K::name, exact);
    });
    check_transmittance(medium, GridMajorant<M>(medium, 16), "grid 16", exact);
    // Half the global bound: below the extinction over much of the box.
    check_transmittance(medium, GlobalMajorant<M, bound::Signed>(medium, 0.5f * medium.max_extinction()),
                        "global-signed-0.5", exact);
}

static_assert(ExtinctionBoundedMedium<TwoGridMedium<Rgb>> && CellBoundedMedium<TwoGridMedium<Mono>> &&
              !RegionBoundedMedium<TwoGridMedium<Rgb>>);

TEST_CASE_TEMPLATE("a medium made of several grids takes grid and tree majorants that bound every channel", S, Mono, Rgb) {
    using M = TwoGridMedium<S>;
    const M medium{spec<S>(3.f, 0.5f, 0.1f), spec<S>(0.2f, 1.f, 4.f)};
    const GridMajorant<M> grid(medium, 8);
    const ChannelGridMajorant<M> channel_grid(medium, 8);
    const auto tree = TreeKind::make(medium);
    const auto channel_tree = ChannelTreeKind::make(medium);
    // Every majorant bounds every channel's extinction at random points.
    Pcg32 rng(3, 3);
    for (int i = 0; i < 20000; ++i) {
        const Vec3 p(2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f, 2.f * rng.uniform() - 1.f);
        const auto mu = medium.coefficients(p).sigma_t();
        CAPTURE(p.x);
        CAPTURE(p.y);
        CHECK(grid.value_at(p, {}) >= mu.maxCoeff());
        CHECK(tree.value_at(p, {}) >= mu.maxCoeff());
        CHECK((channel_grid.value_at(p, {}) >= mu).all());
        CHECK((channel_tree.value_at(p, {}) >= mu).all());
    }
    // The grid follows the medium: the cell at the low corner (r < 1/8 in x and y) is bounded by
    // (a + b) / 8 per channel, far below the global bound a + b (padding aside).
    const auto low = channel_grid.value_at(Vec3(-0.99f, -0.99f, 0.f), {});
    CHECK((low <= 1.001f * (medium.a + medium.b) / 8.f).all());
    CHECK(grid.value_at(Vec3(-0.99f, -0.99f, 0.f), {}) <= 1.001f * (medium.a + medium.b).maxCoeff() / 8.f);
    // Ratio and delta tracking under the grey ones are unbiased: exp(-tau_c), tau linear along
    // each ray (the per-channel ones drive channel tracking: test_spectral_majorants.cpp).
    auto exact = [&](const Ray& r, float tmax) { return typename S::Spectrum((-medium.optical_depth(r, tmax)).exp()); };
    check_transmittance(medium, grid, "grid over two grids", exact);
    check_transmittance(medium, tree, "tree over two grids", exact);
}

TEST_CASE("a medium made of several grids: bad region bounds are refused with the value and the channel") {
    struct Bad : TwoGridMedium<Rgb> {
        float nan_at = 0.f;
        Rgb::Spectrum extinction_bound_over(const Box& r) const {
            Rgb::Spectrum v = TwoGridMedium<Rgb>::extinction_bound_over(r);
            if (r.hi.x < 1.f) v[1] = nan_at;  // every cell but the last column (and not the whole box)
            return v;
        }
    };
    static_assert(ExtinctionBoundedMedium<Bad>);
    Bad nan;
    nan.a = Rgb::Spectrum(1.f, 1.f, 1.f);
    nan.b = Rgb::Spectrum(1.f, 1.f, 1.f);
    nan.nan_at = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_WITH_AS(GridMajorant<Bad>(nan, 4), Contains("in channel 1 is not allowed"), InvalidArgument);
    // A channel with no extinction over the whole box but some in a cell: the bounds contradict.
    Bad zero;
    zero.a = Rgb::Spectrum(1.f, 0.f, 1.f);
    zero.b = Rgb::Spectrum(1.f, 0.f, 1.f);
    zero.nan_at = 0.5f;
    CHECK_THROWS_WITH_AS(ChannelGridMajorant<Bad>(zero, 4), Contains("exceeds its bound over its whole box"),
                         InvalidArgument);
}

TEST_CASE("bound::Clamp gives the clamped medium's transmittance: its bias is what the clamp predicts") {
    // Homogeneous mu_t = 2 under a global majorant of 1: the clamped medium has mu_t = 1.
    using H = HomogeneousMedium<Mono>;
    const H homog(Box{Vec3(-1.f), Vec3(1.f)}, grey<Mono>(0.5f), grey<Mono>(1.5f));
    const GlobalMajorant<H, bound::Clamp> low(homog, 1.f);
    check_transmittance(homog, low, "homogeneous clamped to 1", [&](const Ray& r, float tmax) {
        const Interval in = homog.bounds().clip(r, 0.f, tmax);
        return Mono::Spectrum::Constant(float(std::exp(-1.0 * (double(in.t1) - double(in.t0)))));
    });
    // The bias is real: against the true exp(-2 d) the same estimate is far off.
    Pcg32 rng(5, 9);
    NoLookupCount none;
    Stat s;
    for (int i = 0; i < 20000; ++i) s.add(transmittance_ratio(homog, low, kRays[0].ray, kInf, {}, rng, none).value[0]);
    CHECK(s.mean - std::exp(-4.0) > 20.0 * s.se() + 0.05);

    // An exponential medium under half its grid bound: expected exp(-int min(mu_t, mu_bar)),
    // by midpoint quadrature in double with 1e6 steps (error <= ~1e-4 in the optical depth from
    // the majorant's jumps at cell faces, added to the tolerance through kRoundingFloor-like slack).
    using M = ExponentialMedium<Rgb>;
    const M medium = make_medium<M>(Box{Vec3(-1.f), Vec3(1.f)}, 1.f, spec<Rgb>(0.2f, 0.1f, 0.5f),
                                    spec<Rgb>(0.8f, 0.6f, 1.f));
    const auto maj = ClampGridKind::make(medium);
    check_transmittance(medium, maj, ClampGridKind::name, [&](const Ray& r, float tmax) {
        const Interval in = medium.bounds().clip(r, 0.f, tmax);
        constexpr int n = 1000000;
        const double h = (double(in.t1) - double(in.t0)) / n;
        std::array<double, 3> tau{};
        for (int i = 0; i < n; ++i) {
            const float t = float(double(in.t0) + (i + 0.5) * h);
            const auto mu = majorant_value_at<M>(maj, r, t, {}).value_or(0.f);
            const auto k = medium.coefficients(r.at(t), {}).sigma_t();
            for (int c = 0; c < 3; ++c) tau[std::size_t(c)] += std::min(double(k[c]), double(mu)) * h;
        }
        return Rgb::Spectrum(float(std::exp(-tau[0])), float(std::exp(-tau[1])), float(std::exp(-tau[2])));
    });
}

#if defined(NDEBUG) && !defined(NSP_DEBUG)  // in a debug build the rejection asserts instead
TEST_CASE("bound::Reject discards flights that meet mu_t > mu_bar and reports Status::Rejected") {
    using H = HomogeneousMedium<Mono>;
    const H homog(Box{Vec3(-1.f), Vec3(1.f)}, grey<Mono>(0.5f), grey<Mono>(1.5f));
    Pcg32 rng(1, 1);
    NoLookupCount none;
    const GlobalMajorant<H, bound::Reject> low(homog, 1.f);
    const auto r = track_ratio<absorption::Weight, false>(homog, low, kRays[0].ray, kInf, {}, rng, none);
    CHECK(r.end == SegmentEnd::Rejected);
    CHECK(r.transmittance[0] == 0.f);
    // A majorant that does bound never rejects, and the estimate stays exact.
    const GlobalMajorant<H, bound::Reject> ok(homog, 2.f);
    Lights<Mono> lights;
    lights.set(EnvironmentLight<Mono>{grey<Mono>(1.f)});
    const H white(Box{Vec3(-1.f), Vec3(1.f)}, grey<Mono>(0.f), grey<Mono>(2.f));
    const Scene<H, GlobalMajorant<H, bound::Reject>, IsotropicPhase> bad(white, {white, 1.f}, {}, lights),
        good(white, {white, 2.f}, {}, lights);
    const PathEstimator<strategy::NullScatteringMis, mis::Balance> est;
    const auto rb = estimate_radiance(est, bad, kRays[0].ray, 2000, 4);
    const auto rg = estimate_radiance(est, good, kRays[0].ray, 2000, 4);
    // A path is rejected at its first collision: the camera ray crosses optical depth 2 of the
    // majorant 1, so it has one with probability 1 - e^-2 = 0.86 (the rest pass, Ok).
    CHECK(rb.not_ok >= 1600);
    CHECK(rb.not_ok < 2000);
    CHECK(rg.not_ok == 0);
    const Stat& s = rg.stat.ch[0];  // the furnace: 1
    CHECK(std::abs(s.mean - 1.0) <= kSigmas * s.se() + kRoundingFloor);
}
#endif

// ---------------------------------------------------------------------------------------------
// Every PathEstimator: the furnace, and agreement with the global majorant

TEST_CASE_TEMPLATE_DEFINE("furnace with grid majorants and Signed majorants below the extinction", E, grid_furnace) {
    const E est;
    const std::string name = estimator_name<E>();
    CAPTURE(name);
    const Box box{Vec3(-1.f), Vec3(1.f)};
    auto run = [&](auto tag) {
        using S = decltype(tag);
        Lights<S> lights;
        lights.set(EnvironmentLight<S>{grey<S>(1.f)});
        const auto zero = grey<S>(0.f), ss = spec<S>(1.f, 0.8f, 1.25f);
        auto medium_run = [&](const auto& medium, const char* medium_name) {
            using M = std::remove_cvref_t<decltype(medium)>;
            CAPTURE(medium_name);
            for_each_kind<std::tuple<GridKind, SignedGridKind>, M>([&](auto kind) {
                using K = decltype(kind);
                CAPTURE(K::name);
                using Maj = typename K::template type<M>;
                const Scene<M, Maj, HenyeyGreensteinPhase> scene(medium, K::make(medium), HenyeyGreensteinPhase(0.5f),
                                                                 lights);
                for (int r = 0; r < 2; ++r) {
                    CAPTURE(r);
                    const auto res = estimate_radiance(est, scene, kRays[r].ray, 10000, 300 + std::uint64_t(r));
                    CHECK(res.not_ok == 0);
                    for (int c = 0; c < S::channels; ++c) {
                        const Stat& s = res.stat.ch[std::size_t(c)];
                        CAPTURE(c); CAPTURE(s.mean); CAPTURE(s.se());
                        CHECK(std::abs(s.mean - 1.0) <= kSigmas * s.se() + kRoundingFloor);
                    }
                }
            });
        };
        medium_run(make_medium<DenseGridMedium<S>>(box, 1.f, zero, ss, 42), "grid");
        medium_run(make_medium<ExponentialMedium<S>>(box, 1.f, zero, ss), "exponential");
    };
    run(Mono{});
    run(Rgb{});
}

TEST_CASE_TEMPLATE_APPLY(grid_furnace, AllEstimators);

TEST_CASE_TEMPLATE("grid and Signed majorants agree with the global majorant on a lit, absorbing grid medium", E,
                   PathEstimator<strategy::NullScatteringMis, mis::Balance>,
                   PathEstimator<strategy::Unidirectional, mis::None, absorption::Event>,
                   PathEstimator<strategy::NextEvent>) {
    using M = DenseGridMedium<Mono>;
    const M medium = make_medium<M>(Box{Vec3(-1.f), Vec3(1.f)}, 1.5f, grey<Mono>(0.3f), grey<Mono>(0.9f), 8);
    Lights<Mono> lights;
    lights.set(EnvironmentLight<Mono>{grey<Mono>(0.5f)});
    lights.set(SphereLight<Mono>{Vec3(0.f, 3.f, 0.f), 0.8f, grey<Mono>(6.f)});
    const E est;
    auto mean_of = [&](auto kind, std::uint64_t seed) {
        using K = decltype(kind);
        using Maj = typename K::template type<M>;
        const Scene<M, Maj, HenyeyGreensteinPhase> scene(medium, K::make(medium), HenyeyGreensteinPhase(0.3f), lights);
        const auto res = estimate_radiance(est, scene, kRays[0].ray, 40000, seed);
        CHECK(res.not_ok == 0);
        return res.stat.ch[0];
    };
    const Stat global = mean_of(GlobalKind{}, 1);
    for (const Stat& other : {mean_of(GridKind{}, 2), mean_of(SignedGridKind{}, 3)}) {
        CAPTURE(global.mean); CAPTURE(other.mean);
        const double se = std::sqrt(global.se() * global.se() + other.se() * other.se());
        CHECK(std::abs(global.mean - other.mean) <= kSigmas * se);
    }
}

// ---------------------------------------------------------------------------------------------
// Input validation

TEST_CASE("majorant constructors reject resolutions, scales and values the bound policy forbids") {
    using M = DenseGridMedium<Rgb>;
    const M medium = make_medium<M>(Box{Vec3(-1.f), Vec3(1.f)}, 1.f, grey<Rgb>(1.f), grey<Rgb>(1.f));
    CHECK_THROWS_WITH_AS(GridMajorant<M>(medium, {4, 0, 4}), Contains("resolution[1] = 0"), InvalidArgument);
    CHECK_THROWS_WITH_AS(GridMajorant<M>(medium, 5000), Contains("resolution[0] = 5000"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelGridMajorant<M>(medium, {-1, 4, 4}), Contains("resolution[0] = -1"), InvalidArgument);
    CHECK_THROWS_WITH_AS(GridMajorant<M>(medium, {4096, 4096, 32}), Contains("at most 2^28"), InvalidArgument);
    CHECK_THROWS_WITH_AS(GridMajorant<M>(medium, 4, 0.5f), Contains("GridMajorant scale = 0.5 is below 1"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS((GridMajorant<M, bound::Signed>(medium, 4, 0.f)), Contains("GridMajorant scale = 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS((ChannelGridMajorant<M, bound::Clamp>(medium, 4, std::numeric_limits<float>::quiet_NaN())),
                         Contains("ChannelGridMajorant scale = nan"), InvalidArgument);
    CHECK_THROWS_WITH_AS(ChannelMajorant<M>(medium, 0.9f), Contains("ChannelMajorant scale = 0.9 is below 1"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS(GlobalMajorant<M>(medium, 1.f), Contains("GlobalMajorant value = 1 is below"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS((GlobalMajorant<M, bound::Signed>(medium, 0.f)), Contains("GlobalMajorant value = 0"),
                         InvalidArgument);
    CHECK_THROWS_WITH_AS((GlobalMajorant<M, bound::Clamp>(medium, -1.f)), Contains("GlobalMajorant value = -1"),
                         InvalidArgument);
    // Allowed: below the bound under a non-bounding policy; a grid of one cell.
    CHECK_NOTHROW(GlobalMajorant<M, bound::Signed>(medium, 0.1f));
    CHECK_NOTHROW(GridMajorant<M, bound::Clamp>(medium, 1, 0.25f));
    CHECK(GridMajorant<M>(medium, {2, 3, 4}).memory_bytes() == 24 * sizeof(float));
}

}  // namespace
