// tests/support/surfaces.hpp: geometry the surface tests share: the six faces of the cube
// [-1, 1]^3 facing inward (the closed boxes of the furnaces) and the distance from a point inside
// a box to its boundary (the chords of the closed-form transmittances).
#pragma once

#include <array>
#include <limits>

#include <nsp/nsp.hpp>

namespace nsp_test {

/// A parallelogram corner + a u + b v, a, b in [0, 1], with normal cross(u, v).
struct CubeFace {
    nsp::Vec3 corner, u, v;
};

/// The six faces of [-1, 1]^3, normals inward, in the order -x, +x, -y, +y, -z, +z.
inline std::array<CubeFace, 6> inward_cube_faces() {
    std::array<CubeFace, 6> faces{};
    int i = 0;
    for (int a = 0; a < 3; ++a)
        for (const float side : {-1.f, 1.f}) {
            nsp::Vec3 corner(-1.f), eb(0.f), ec(0.f);
            corner[a] = side;
            eb[(a + 1) % 3] = 2.f;
            ec[(a + 2) % 3] = 2.f;
            // cross(eb, ec) is +e_a: inward on the side -1, swapped on the side +1.
            faces[std::size_t(i++)] = side < 0.f ? CubeFace{corner, eb, ec} : CubeFace{corner, ec, eb};
        }
    return faces;
}

/// The distance from p, inside `b`, along the unit direction d to the box's boundary.
inline double exit_distance(const nsp::Box& b, const nsp::Vec3& p, const nsp::Vec3& d) {
    double t = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (d[a] > 0.f) t = std::min(t, (double(b.hi[a]) - p[a]) / d[a]);
        if (d[a] < 0.f) t = std::min(t, (double(b.lo[a]) - p[a]) / d[a]);
    }
    return t;
}

}  // namespace nsp_test
