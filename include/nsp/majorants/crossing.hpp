// nsp/majorants/crossing.hpp: how many tentative collisions a flight through a medium can take
// under a majorant, and the limit past which a scene refuses the pair (a render that would run
// away).
//
// A flight makes mu_bar tentative collisions per unit length, and it ends at its first real
// collision (delta tracking) or once its estimate is below float's range (ratio tracking:
// prod (1 - mu_t / mu_bar) < FLT_MIN, which needs at most int mu_t dt = kFlightDepth of real
// optical depth, since -ln(1 - r) >= r). So a flight takes about int mu_bar dt collisions up to
// where int mu_t dt reaches kFlightDepth, or to the end of the medium: few in a dense medium under
// a tight or twice-loose majorant, however thick; mu_bar x length over a sparse or empty stretch
// under a loose one. `flight_collisions` measures that along probe lines through the medium's box,
// in both directions; scenes refuse a majorant whose worst probe takes more than
// kMaxFlightCollisions (scene.hpp, surface_scene.hpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <type_traits>
#include <vector>

#include "../core/error.hpp"
#include "../majorant.hpp"
#include "../medium.hpp"

namespace nsp {

/// The most tentative collisions a scene lets a flight through one of its media expect: 2^20. One
/// such flight costs tens of milliseconds of lookups, a render of them hours, and past
/// kDefaultMaxCollisions (2^24, tracking.hpp) a flight gives up with Status::Aborted, a biased
/// estimate. Real media under reasonable majorants are far below it (a flight through a sparse
/// cloud under a majorant 1000 times its mean extinction over a crossing of 10 mean free paths
/// takes 1e4).
inline constexpr double kMaxFlightCollisions = double(1u << 20);

/// The real optical depth after which no flight goes on: ratio tracking's product is then below
/// FLT_MIN (e^-88 < 2^-126), and delta tracking has met a real collision with probability 1 - e^-88.
inline constexpr double kFlightDepth = 88.0;

/// The worst probe of flight_collisions: the collisions expected along it, the majorant's optical
/// depth along it (an upper bound of the former that needs no lookup) and the probe.
struct FlightCollisions {
    double collisions = 0.0;      ///< int mu_bar dt up to where int mu_t dt reaches kFlightDepth (largest channel)
    double majorant_depth = 0.0;  ///< int mu_bar dt along the whole probe (largest channel)
    Ray probe{};                  ///< the probe, from where the worst flight starts, unit direction
    float length = 0.f;           ///< the probe's length inside the box
};

namespace detail {
/// The largest channel of a majorant value (a grey one is every channel's).
template <class V>
float largest_channel(const V& v) noexcept {
    if constexpr (std::is_same_v<V, float>) return v;
    else return v.maxCoeff();
}

/// The probe lines of a box: its four diagonals, and along each axis a 4 x 4 lattice of lines at
/// 1/8, 3/8, 5/8 and 7/8 of the other two extents (52 lines in all). `visit(ray, length)` each.
template <class F>
void for_each_probe(const Box& b, F&& visit) {
    const Vec3 e = b.hi - b.lo;
    for (int k = 0; k < 4; ++k) {  // corner (x, y, z) -> its opposite; k flips y and z
        const Vec3 from(b.lo.x, (k & 1) ? b.hi.y : b.lo.y, (k & 2) ? b.hi.z : b.lo.z);
        const Vec3 to(b.hi.x, (k & 1) ? b.lo.y : b.hi.y, (k & 2) ? b.lo.z : b.hi.z);
        const float len = glm::length(to - from);
        if (len > 0.f && std::isfinite(len)) visit(Ray{from, (to - from) / len}, len);
    }
    constexpr std::array<float, 4> f{0.125f, 0.375f, 0.625f, 0.875f};
    for (int a = 0; a < 3; ++a) {
        const int u = (a + 1) % 3, v = (a + 2) % 3;
        if (!(e[a] > 0.f) || !std::isfinite(e[a])) continue;
        for (const float fu : f)
            for (const float fv : f) {
                Vec3 o = b.lo, d(0.f);
                o[u] += fu * e[u];
                o[v] += fv * e[v];
                d[a] = 1.f;
                visit(Ray{o, d}, e[a]);
            }
    }
}

/// One stretch of a probe: its length, the majorant there and the extinction looked up at its
/// middle (largest channel each).
struct ProbeStretch {
    double length, mu_bar, mu_t;
};

/// The collisions of a flight over `stretches` in order: int mu_bar dt until int mu_t dt reaches
/// kFlightDepth.
template <class It>
double flight_over(It first, It last) noexcept {
    double collisions = 0.0, depth = 0.0;
    for (; first != last; ++first) {
        const ProbeStretch& s = *first;
        const double need = kFlightDepth - depth, real = s.mu_t * s.length;
        if (real >= need) return collisions + s.mu_bar * s.length * (need / real);
        collisions += s.mu_bar * s.length;
        depth += real;
    }
    return collisions;
}
}  // namespace detail

/// The most tentative collisions a flight through `medium`'s box takes under `majorant` (see the
/// header), over the probes of detail::for_each_probe in both directions, at wavelengths
/// `lambda`. The majorant's optical depth along each probe comes first (no lookups); only a probe
/// where it exceeds `threshold` is looked up, at the middles of 1024 stretches (at least one per
/// majorant segment), so a scene whose majorant stays below the threshold costs no lookup.
template <Medium M, MajorantPolicy<M> Maj>
FlightCollisions flight_collisions(const M& medium, const Maj& majorant,
                                   const typename M::Spectral::Wavelengths& lambda,
                                   double threshold = kMaxFlightCollisions) {
    FlightCollisions worst;
    std::vector<detail::ProbeStretch> stretches;
    detail::for_each_probe(medium.bounds(), [&](const Ray& ray, float len) {
        double depth = 0.0;
        {
            auto it = majorant.iterate(ray, 0.f, len, lambda);
            while (auto seg = it.next()) depth += double(detail::largest_channel(seg->sigma_maj)) * (double(seg->t1) - seg->t0);
        }
        double forward = depth, backward = depth;
        if (depth > threshold) {  // look the medium up where the majorant alone does not settle it
            stretches.clear();
            auto it = majorant.iterate(ray, 0.f, len, lambda);
            while (auto seg = it.next()) {
                const double mu = detail::largest_channel(seg->sigma_maj), l = double(seg->t1) - seg->t0;
                if (!(l > 0.0)) continue;
                const int n = std::clamp(int(std::ceil(1024.0 * l / double(len))), 1, 1024);
                for (int i = 0; i < n; ++i) {
                    const float t = float(seg->t0 + (i + 0.5) / n * l);
                    const auto k = medium.coefficients(ray.at(t), lambda);
                    stretches.push_back({l / n, mu, double(k.sigma_t().maxCoeff())});
                }
            }
            forward = detail::flight_over(stretches.begin(), stretches.end());
            backward = detail::flight_over(stretches.rbegin(), stretches.rend());
        }
        const double collisions = std::max(forward, backward);
        if (collisions > worst.collisions || worst.length == 0.f) {
            const Ray from = backward > forward ? Ray{ray.at(len), -ray.d} : ray;
            worst = {collisions, depth, from, len};
        }
    });
    return worst;
}

namespace detail {
/// Throws InvalidArgument when a flight through `medium` under `majorant` takes more than
/// kMaxFlightCollisions tentative collisions (flight_collisions), naming the count, the probe and
/// the limit; `what` names the caller.
template <Medium M, MajorantPolicy<M> Maj>
void require_trackable(const M& medium, const Maj& majorant, const char* what) {
    const FlightCollisions c = flight_collisions(medium, majorant, typename M::Spectral::Wavelengths{});
    if (c.collisions > kMaxFlightCollisions || std::isnan(c.collisions))
        fail(what, ": a flight through the medium takes ", c.collisions, " tentative collisions under this majorant ",
             "(from (", c.probe.o.x, ", ", c.probe.o.y, ", ", c.probe.o.z, ") in direction (", c.probe.d.x, ", ",
             c.probe.d.y, ", ", c.probe.d.z, ") over ", c.length, ", where the majorant's optical depth is ",
             c.majorant_depth, "); at most kMaxFlightCollisions = 2^20 = 1048576 are allowed: such flights ",
             "take tens of milliseconds each, a render of them hours, and give up at 2^24 (Status::Aborted). Lower the medium's density or ",
             "extent, or tighten the majorant (a grid or tree majorant where the medium is sparse)");
}
}  // namespace detail

}  // namespace nsp
