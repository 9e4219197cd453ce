// nsp/media/validate.hpp: input checks shared by the constructors of media, lights and majorants.
#pragma once

#include <array>
#include <cstddef>
#include <limits>

#include "../core/error.hpp"
#include "../core/math.hpp"
#include "../spectrum.hpp"

namespace nsp::detail {

/// Rejects a spectrum with a NaN, infinite or negative channel, naming the channel. A
/// TabulatedSpectrum (Hero mode) is checked entry by entry, naming the wavelength: from_points
/// and constant() validate their input, but scaled() and operator+ can make a negative or
/// infinite entry from valid ones.
template <class Spec>
void require_coefficient(const Spec& s, const char* what) {
    if constexpr (std::is_same_v<Spec, TabulatedSpectrum>) {
        for (int k = 0; k < TabulatedSpectrum::kSize; ++k)
            if (!std::isfinite(s[k]) || s[k] < 0.f)
                fail(what, "[", kLambdaMin + TabulatedSpectrum::kStep * float(k), " nm] = ", s[k],
                     " is not allowed: coefficients must be finite and >= 0");
    } else {
        for (int c = 0; c < s.size(); ++c)
            if (!std::isfinite(s[c]) || s[c] < 0.f)
                fail(what, "[channel ", c, "] = ", s[c],
                     " is not allowed: coefficients must be finite and >= 0");
    }
}

/// Rejects a medium whose extinction bound (what majorants are built from) overflows float:
/// every majorant and pdf of the medium would be infinite. `what` names the product.
inline void require_finite_extinction(float bound, const char* what) {
    if (!std::isfinite(bound))
        fail(what, " = ", bound, " is not allowed: it must be finite (at most ",
             std::numeric_limits<float>::max(), "); scale the coefficients or densities down");
}

/// The number of voxels of a grid of resolution `res` (every axis already >= 1); throws if it
/// exceeds `max`, the most a std::vector can hold, instead of letting the product wrap around.
inline std::size_t voxel_count(const std::array<int, 3>& res, std::size_t max, const char* what) {
    const double n = double(res[0]) * double(res[1]) * double(res[2]);
    if (!(n <= double(max)))
        fail(what, " resolution ", res[0], "x", res[1], "x", res[2], " has ", n,
             " voxels; at most ", max, " are allowed");
    return std::size_t(res[0]) * std::size_t(res[1]) * std::size_t(res[2]);
}

/// Rejects a box that is not finite, has no volume, or whose extent or its reciprocal overflows.
inline void require_box(const Box& b, const char* what) {
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(b.lo[a]) || !std::isfinite(b.hi[a]))
            fail(what, " has a non-finite corner on axis ", a, ": [", b.lo[a], ", ", b.hi[a],
                 "]; corners must be finite");
        if (!(b.lo[a] < b.hi[a]))
            fail(what, " is empty on axis ", a, ": lo = ", b.lo[a], " must be < hi = ", b.hi[a]);
        // Lookups divide by the extent: it and its reciprocal must be finite floats.
        const float e = b.hi[a] - b.lo[a];
        if (!std::isfinite(e) || !std::isfinite(1.f / e))
            fail(what, " has extent hi - lo = ", e, " on axis ", a, " ([", b.lo[a], ", ", b.hi[a],
                 "]); it is not allowed: the extent and 1 / extent must be finite");
    }
}

}  // namespace nsp::detail
