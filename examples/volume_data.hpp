// examples/volume_data.hpp: the volumes nsp_volume and the file tests make rather than download:
// the default cloud and a sparse procedural smoke plume, as voxel callbacks any writer can take
// (NanoVDB's GridBuilder, OpenVDB's FloatGrid, nsp::io::VoxelGrid). No dependency.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "default_scene.hpp"

namespace nsp_examples {

/// The plume's box: res^3 voxels, index (i, j, k) at world -1 + (i + 1/2) 2 / res per axis (the
/// box [-1, 1]^3, the same index-to-world map as nsp::io::to_nanovdb gives a VoxelGrid over it).
inline double plume_voxel_size(int res) { return 2.0 / double(res); }

/// One puff of the plume: centre and radius in world units.
struct Puff {
    float x, y, z, r;
};

/// The plume's puffs: 90 along a rising, widening helix with jitter, from a narrow source near the
/// floor (radius 0.02) to a broad top (0.11), as a turbulent plume breaks into eddies.
inline std::vector<Puff> plume_puffs() {
    std::vector<Puff> puffs;
    constexpr int n = 90;
    std::uint32_t state = 12345u;
    auto jitter = [&] {  // a fixed LCG: the plume is the same on every machine
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / float(1u << 24) - 0.5f;
    };
    for (int i = 0; i < n; ++i) {
        const float s = (float(i) + 0.5f) / float(n);
        const float r = 0.02f + 0.09f * s;
        puffs.push_back({0.55f * s * std::sin(7.f * s) + 0.12f * jitter(), -0.88f + 1.72f * s + 0.03f * jitter(),
                         0.55f * s * std::cos(7.f * s) + 0.12f * jitter(), r * (1.f + 0.4f * jitter())});
    }
    return puffs;
}

/// Calls f(i, j, k, density) once for every voxel of a smoke plume of res^3 voxels whose density
/// is not 0, slice by slice in j. The plume is a union of puffs (plume_puffs) along a rising
/// helix, each dense at its centre and falling off to 0 at its radius, thinning with height and
/// broken into wisps by two octaves of value noise. It fills about 0.5% of its box and 3% of its own
/// bounding box: most of the space a ray crosses is empty, the case tree majorants are for.
template <class F>
void for_each_plume_voxel(int res, F&& f) {
    const double h = plume_voxel_size(res);
    const std::vector<Puff> puffs = plume_puffs();
    auto index = [&](float w) { return int(std::floor((w + 1.f) / float(h))); };
    std::vector<const Puff*> near;
    for (int j = 0; j < res; ++j) {
        const float y = float(-1.0 + (j + 0.5) * h);
        near.clear();
        int i0 = res, i1 = -1, k0 = res, k1 = -1;
        for (const Puff& p : puffs)
            if (std::abs(y - p.y) < p.r) {
                near.push_back(&p);
                i0 = std::min(i0, std::max(0, index(p.x - p.r)));
                i1 = std::max(i1, std::min(res - 1, index(p.x + p.r)));
                k0 = std::min(k0, std::max(0, index(p.z - p.r)));
                k1 = std::max(k1, std::min(res - 1, index(p.z + p.r)));
            }
        for (int k = k0; k <= k1; ++k)
            for (int i = i0; i <= i1; ++i) {
                const float x = float(-1.0 + (i + 0.5) * h), z = float(-1.0 + (k + 0.5) * h);
                float core = 0.f;
                for (const Puff* p : near) {
                    const float d = std::sqrt((x - p->x) * (x - p->x) + (y - p->y) * (y - p->y) + (z - p->z) * (z - p->z)) / p->r;
                    if (d < 1.f) core = std::max(core, (1.f - d) * (1.f - d));
                }
                if (!(core > 0.f)) continue;
                const float u = 0.5f * (y + 1.f);
                const float n = 0.65f * value_noise(9.f * x + 3.f, 7.f * y, 9.f * z) +
                                0.35f * value_noise(23.f * x, 21.f * y + 2.f, 23.f * z + 4.f);
                const float v = std::clamp(2.5f * core * (1.f - 0.5f * u) * (0.3f + n) - 0.05f, 0.f, 1.f);
                if (v > 0.f) f(i, j, k, v);
            }
    }
}

/// The plume's temperature in kelvin at a voxel of slice j (of res) whose density is `density`: a
/// flame at the source, up to 2600 K, cooling to 0 over the lower 0.9 of the plume's 1.7 rise,
/// hotter where the smoke is denser (0.6 + 0.4 sqrt(density)). 0 where the density is 0, so the
/// temperature grid's active voxels are a subset of the density's.
inline float plume_temperature(int j, int res, float density) {
    const double y = -1.0 + (j + 0.5) * plume_voxel_size(res);
    const double h = std::clamp(1.0 - (y + 0.88) / 0.9, 0.0, 1.0);
    return density > 0.f ? float(2600.0 * std::sqrt(h) * (0.6 + 0.4 * std::sqrt(double(density)))) : 0.f;
}

}  // namespace nsp_examples
