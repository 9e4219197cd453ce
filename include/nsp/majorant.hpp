// nsp/majorant.hpp: majorant policies, piecewise-constant bounds walked segment by segment.
//
// The free-flight loop (tracking.hpp) iterates over majorant segments from the start, so a grid
// majorant walked by a DDA (ROADMAP 3) is a new model of this concept, not a new loop.
#pragma once

#include <concepts>
#include <optional>

#include "core/error.hpp"
#include "medium.hpp"

namespace nsp {

/// A stretch [t0, t1) of a ray over which the majorant mu_bar is constant.
struct MajorantSegment {
    float t0 = 0.f;
    float t1 = 0.f;
    float sigma_maj = 0.f;  ///< mu_bar on the segment, finite and >= 0
};

/// A majorant iterator: `next()` returns the ray's segments in increasing t, then std::nullopt.
template <class I>
concept MajorantIterator = requires(I& it) {
    { it.next() } -> std::same_as<std::optional<MajorantSegment>>;
};

/// A majorant policy for medium type M provides:
/// - `iterate(ray, tmin, tmax, lambda)`: a MajorantIterator over the segments of [tmin, tmax]
///   (only the part where the medium may be non-zero need be covered);
/// - `bounds_density`: true when mu_bar >= mu_t holds everywhere by construction, so null
///   coefficients are never negative (a policy for non-bounding majorants sets it false).
template <class P, class M>
concept MajorantPolicy = Medium<M> &&
    requires(const P& p, const Ray& r, float t, const typename M::Spectral::Wavelengths& l) {
        { p.iterate(r, t, t, l) } -> MajorantIterator;
        { P::bounds_density } -> std::convertible_to<bool>;
    };

/// Yields at most one segment: the given majorant over the part of the ray inside the box.
class SingleSegmentIterator {
public:
    SingleSegmentIterator() = default;
    SingleSegmentIterator(Interval in, float sigma_maj) noexcept
        : seg_{in.t0, in.t1, sigma_maj}, done_(in.empty()) {}

    std::optional<MajorantSegment> next() noexcept {
        if (done_) return std::nullopt;
        done_ = true;
        return seg_;
    }

private:
    MajorantSegment seg_{};
    bool done_ = true;
};

/// One constant majorant for the whole medium and every channel (THEORY 1): the maximum over
/// channels of the medium's extinction bound, or a value the caller gives that must bound it.
template <Medium M>
class GlobalMajorant {
public:
    static constexpr bool bounds_density = true;

    /// The tightest global majorant the medium's extinction bound allows.
    explicit GlobalMajorant(const M& medium)
        : bounds_(medium.bounds()),
          value_(medium.extinction_bound(typename M::Spectral::Wavelengths{}).maxCoeff()) {
        detail::require_finite_nonnegative(value_, "GlobalMajorant: the medium's extinction bound");
    }

    /// A caller-chosen majorant; throws InvalidArgument unless it is finite and at least the
    /// medium's extinction bound in every channel (this policy does not allow negative nulls).
    GlobalMajorant(const M& medium, float value) : bounds_(medium.bounds()), value_(value) {
        detail::require_finite_nonnegative(value, "GlobalMajorant value");
        const auto bound = medium.extinction_bound(typename M::Spectral::Wavelengths{});
        for (int c = 0; c < bound.size(); ++c)
            if (value < bound[c])
                detail::fail("GlobalMajorant value = ", value, " is below the medium's extinction ",
                             "bound ", bound[c], " in channel ", c,
                             "; this policy requires mu_bar >= mu_t everywhere");
    }

    /// The majorant value.
    float value() const noexcept { return value_; }

    /// One segment: [tmin, tmax] clipped to the medium's box.
    SingleSegmentIterator iterate(const Ray& r, float tmin, float tmax,
                                  const typename M::Spectral::Wavelengths&) const noexcept {
        return {bounds_.clip(r, tmin, tmax), value_};
    }

private:
    Box bounds_;
    float value_;
};

}  // namespace nsp
