// nsp/media/validate.hpp: input checks shared by the media constructors.
#pragma once

#include "../core/error.hpp"
#include "../core/math.hpp"
#include "../spectrum.hpp"

namespace nsp::detail {

/// Rejects a spectrum with a NaN, infinite or negative channel, naming the channel.
/// A TabulatedSpectrum (Hero mode) validated itself when it was built.
template <class Spec>
void require_coefficient(const Spec& s, const char* what) {
    if constexpr (std::is_same_v<Spec, TabulatedSpectrum>) return;
    else for (int c = 0; c < s.size(); ++c)
        if (!std::isfinite(s[c]) || s[c] < 0.f)
            fail(what, "[channel ", c, "] = ", s[c],
                 " is not allowed: coefficients must be finite and >= 0");
}

/// Rejects a box that is not finite or has no volume.
inline void require_box(const Box& b, const char* what) {
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(b.lo[a]) || !std::isfinite(b.hi[a]))
            fail(what, " has a non-finite corner on axis ", a, ": [", b.lo[a], ", ", b.hi[a], "]");
        if (!(b.lo[a] < b.hi[a]))
            fail(what, " is empty on axis ", a, ": lo = ", b.lo[a], " must be < hi = ", b.hi[a]);
    }
}

}  // namespace nsp::detail
