// nsp/majorant.hpp: majorant policies, piecewise-constant bounds walked segment by segment, and
// the bound policies that say what tracking does where a majorant lies below the extinction.
//
// The free-flight loop (tracking.hpp) iterates over majorant segments from the start, so every
// majorant model is an iterator over segments: one segment for the global and per-channel
// majorants here, one per grid cell for the voxel-grid majorants of majorants/grid.hpp (walked
// by a DDA). A segment carries either one grey value (`float`) or one value per channel (the
// mode's Spectrum): free flight samples with the sampling channel's value, and the other
// channels' pdfs of the same vertices are evaluated from theirs (THEORY 5.3).
#pragma once

#include <cmath>
#include <concepts>
#include <optional>
#include <type_traits>

#include "core/error.hpp"
#include "media/validate.hpp"
#include "medium.hpp"

namespace nsp {

// ---------------------------------------------------------------------------------------------
// Bound policies: what tracking does where a majorant does not bound the extinction

/// Where mu_bar < mu_t the null coefficient mu_n = mu_bar - mu_t is negative (THEORY 1). A
/// majorant policy names one of these at compile time:
/// - `Guaranteed`: the majorant bounds mu_t by construction (its constructor checks a value the
///   caller gives); rounding-sized negative nulls are weighted like (a). The default.
/// - `Signed` (a): unbiased. Event probabilities are P_x = |mu_x| / (mu_a + mu_s + |mu_n|), in
///   [0, 1], and the weights mu_x / (mu_bar P_x) carry the sign of mu_n. Needs mu_bar > 0
///   wherever mu_t > 0; the variance grows without bound as mu_bar falls below mu_t.
/// - `Clamp` (b): biased, bounded variance. Each lookup's coefficients are scaled (albedo kept)
///   so that mu_t <= mu_bar in every channel: the estimate is exact for the clamped medium.
/// - `Reject` (c): a collision with mu_t > mu_bar (1 + kBoundSlack) in any channel ends the flight
///   with SegmentEnd::Rejected: the path contributes 0 and reports Status::Rejected.
namespace bound {
struct Guaranteed {
    static constexpr const char* name = "bounding";
    static constexpr bool allows_below = false;
};
struct Signed {
    static constexpr const char* name = "signed";
    static constexpr bool allows_below = true;
};
struct Clamp {
    static constexpr const char* name = "clamp";
    static constexpr bool allows_below = true;
};
struct Reject {
    static constexpr const char* name = "reject";
    static constexpr bool allows_below = true;
};
}  // namespace bound

/// A bound policy: its name and whether a majorant may lie below the extinction.
template <class B>
concept BoundPolicy = requires {
    { B::name } -> std::convertible_to<const char*>;
    { B::allows_below } -> std::convertible_to<bool>;
};

/// Relative excess of mu_t over mu_bar that bound::Reject tolerates (rounding of the lookup).
inline constexpr float kBoundSlack = 1e-5f;

namespace detail {
template <class Maj, class = void>
struct bound_of {
    using type = bound::Guaranteed;
};
template <class Maj>
struct bound_of<Maj, std::void_t<typename Maj::Bound>> {
    using type = typename Maj::Bound;
};

/// Rejects a caller-chosen majorant value for policy B: below the medium's extinction bound
/// `bound` where B requires a bound, or 0 where the medium is not empty (then no collision would
/// ever be sampled and any B would be silently wrong).
template <class B>
void require_majorant_value(float value, float bound, const char* what, const char* where) {
    require_finite_nonnegative(value, what);
    if constexpr (!B::allows_below) {
        if (value < bound)
            fail(what, " = ", value, " is below the medium's extinction bound ", bound, where,
                 "; bound::Guaranteed requires mu_bar >= mu_t everywhere (bound::Signed, Clamp or "
                 "Reject allow a lower majorant)");
    } else if (!(value > 0.f) && bound > 0.f) {
        fail(what, " = 0 is not allowed for a medium with extinction bound ", bound, where,
             ": no collision would ever be sampled; it must be > 0");
    }
}

/// Returns a majorant scale allowed for policy B, or throws: it must be finite, >= 1 under
/// bound::Guaranteed and > 0 under the others.
template <class B>
float require_majorant_scale(float scale, const char* what) {
    if (!std::isfinite(scale) || !(scale > 0.f))
        fail(what, " = ", scale, " is not allowed: it must be finite and > 0");
    if constexpr (!B::allows_below)
        if (scale < 1.f)
            fail(what, " = ", scale, " is below 1: bound::Guaranteed requires mu_bar >= mu_t everywhere "
                 "(bound::Signed, Clamp or Reject allow a scale below 1)");
    return scale;
}
}  // namespace detail

/// The bound policy of majorant policy Maj (`Maj::Bound`, else bound::Guaranteed).
template <class Maj>
using bound_policy_t = typename detail::bound_of<Maj>::type;

/// A stretch [t0, t1) of a ray over which the majorant mu_bar is constant. V is `float` for a grey
/// majorant (one value for every channel) or a Spectrum (one value per channel).
template <class V = float>
struct MajorantSegment {
    float t0 = 0.f;
    float t1 = 0.f;
    V sigma_maj{};  ///< mu_bar on the segment, finite and >= 0 (per channel when V is a Spectrum)
};

namespace detail {
template <class T>
struct is_majorant_segment : std::false_type {};
template <class V>
struct is_majorant_segment<MajorantSegment<V>> : std::true_type {};
}  // namespace detail

/// A majorant iterator: `next()` returns the ray's segments in increasing t, then std::nullopt.
template <class I>
concept MajorantIterator = requires(I& it) {
    { it.next().has_value() } -> std::same_as<bool>;
    requires detail::is_majorant_segment<std::remove_cvref_t<decltype(*it.next())>>::value;
};

/// A majorant policy for medium type M provides `iterate(ray, tmin, tmax, lambda)`: a
/// MajorantIterator over the segments of [tmin, tmax] (only the part where the medium may be
/// non-zero need be covered; segment boundaries must not depend on tmin and tmax beyond the
/// clipping, so that pdfs evaluated piecewise agree with the flight). Optionally `Bound`, its
/// bound policy (bound::Guaranteed when absent).
template <class P, class M>
concept MajorantPolicy = Medium<M> &&
    requires(const P& p, const Ray& r, float t, const typename M::Spectral::Wavelengths& l) {
        { p.iterate(r, t, t, l) } -> MajorantIterator;
        requires BoundPolicy<bound_policy_t<P>>;
    };

/// The value type of policy Maj's segments for medium M: float (grey) or M's Spectrum.
template <class Maj, class M>
using MajorantValue = std::remove_cvref_t<decltype(std::declval<const Maj&>()
                                                       .iterate(std::declval<const Ray&>(), 0.f, 0.f,
                                                                std::declval<const typename M::Spectral::Wavelengths&>())
                                                       .next()
                                                       ->sigma_maj)>;

/// True when policy Maj gives one majorant per channel.
template <class Maj, class M>
inline constexpr bool is_per_channel_majorant_v = !std::is_same_v<MajorantValue<Maj, M>, float>;

/// Channel c of a majorant value (a grey value is every channel's).
template <class V>
float channel_of(const V& v, int c) noexcept {
    if constexpr (std::is_same_v<V, float>) return (void)c, v;
    else return v[c];
}

namespace detail {
/// A majorant value as a spectrum (a grey value in every channel).
template <class Spec, class V>
Spec broadcast_majorant(const V& v) noexcept {
    if constexpr (std::is_same_v<V, float>) return Spec::Constant(v);
    else return v;
}
}  // namespace detail

/// Yields at most one segment: the given majorant over the part of the ray inside the box.
template <class V = float>
class SingleSegmentIterator {
public:
    SingleSegmentIterator() = default;
    SingleSegmentIterator(Interval in, const V& sigma_maj) noexcept
        : seg_{in.t0, in.t1, sigma_maj}, done_(in.empty()) {}

    std::optional<MajorantSegment<V>> next() noexcept {
        if (done_) return std::nullopt;
        done_ = true;
        return seg_;
    }

private:
    MajorantSegment<V> seg_{};
    bool done_ = true;
};

/// One grey majorant for the whole medium and every channel (THEORY 1): the medium's extinction
/// bound over every channel (and wavelength), or a value the caller gives, which must bound it
/// under bound policy B = bound::Guaranteed and may be lower (e.g. the mean extinction, to go
/// faster) under the others.
template <Medium M, BoundPolicy B = bound::Guaranteed>
class GlobalMajorant {
public:
    using Bound = B;

    /// The tightest global majorant the medium's extinction bound allows.
    explicit GlobalMajorant(const M& medium) : bounds_(medium.bounds()), value_(medium.max_extinction()) {
        detail::require_finite_nonnegative(value_, "GlobalMajorant: the medium's extinction bound");
    }

    /// A caller-chosen majorant; throws InvalidArgument unless it is finite and >= 0, > 0 for a
    /// medium that is not empty, and (bound::Guaranteed) at least the medium's extinction bound in
    /// every channel.
    GlobalMajorant(const M& medium, float value) : bounds_(medium.bounds()), value_(value) {
        if constexpr (!B::allows_below && !is_hero_v<typename M::Spectral>) {  // name the channel violated
            detail::require_finite_nonnegative(value, "GlobalMajorant value");
            const auto bound = medium.extinction_bound(typename M::Spectral::Wavelengths{});
            for (int c = 0; c < bound.size(); ++c)
                if (value < bound[c])
                    detail::fail("GlobalMajorant value = ", value, " is below the medium's extinction bound ",
                                 bound[c], " in channel ", c, "; bound::Guaranteed requires mu_bar >= mu_t "
                                 "everywhere (bound::Signed, Clamp or Reject allow a lower majorant)");
        } else {
            detail::require_majorant_value<B>(value, medium.max_extinction(), "GlobalMajorant value",
                                              " over every channel");
        }
    }

    /// The majorant value.
    float value() const noexcept { return value_; }

    /// The majorant at point p: the value inside the medium's box, 0 outside (as `iterate` clips).
    float value_at(const Vec3& p, const typename M::Spectral::Wavelengths&) const noexcept {
        return bounds_.contains(p) ? value_ : 0.f;
    }

    /// One segment: [tmin, tmax] clipped to the medium's box.
    SingleSegmentIterator<float> iterate(const Ray& r, float tmin, float tmax,
                                         const typename M::Spectral::Wavelengths&) const noexcept {
        return {bounds_.clip(r, tmin, tmax), value_};
    }

private:
    Box bounds_;
    float value_;
};

/// A medium that can state its per-channel extinction bound as a coefficient (a Spectrum, or a
/// tabulated spectrum in Hero mode), as the per-channel global majorant needs.
template <class M>
concept ChannelBoundedMedium = Medium<M> && requires(const M& m) {
    { m.extinction_bound_coefficient() } -> std::same_as<typename M::Spectral::Coefficient>;
};

/// One constant majorant per channel (THEORY 5.3): each channel bounded by its own extinction
/// bound (at the path's wavelengths in Hero mode), so a weakly extinguishing channel is not
/// tracked with a strongly extinguishing one's majorant. A channel whose bound is 0 has majorant
/// 0: no collisions are sampled with it, and its pdf of any collision is 0. `scale` multiplies
/// every channel's bound: it must be >= 1 under bound::Guaranteed and > 0 under the others.
template <ChannelBoundedMedium M, BoundPolicy B = bound::Guaranteed>
class ChannelMajorant {
public:
    using Bound = B;
    using Spectral = typename M::Spectral;
    using Spectrum = typename Spectral::Spectrum;

    /// Each channel's extinction bound times `scale`; throws InvalidArgument if one is not
    /// finite or `scale` is not allowed.
    explicit ChannelMajorant(const M& medium, float scale = 1.f)
        : bounds_(medium.bounds()),
          bound_(nsp::scale(medium.extinction_bound_coefficient(),
                            detail::require_majorant_scale<B>(scale, "ChannelMajorant scale"))) {
        detail::require_coefficient(bound_, "ChannelMajorant: the medium's extinction bound x scale");
    }

    /// The per-channel values at wavelengths l.
    Spectrum value(const typename Spectral::Wavelengths& l) const noexcept { return Spectral::sample(bound_, l); }

    /// One segment: [tmin, tmax] clipped to the medium's box, with every channel's bound.
    SingleSegmentIterator<Spectrum> iterate(const Ray& r, float tmin, float tmax,
                                            const typename Spectral::Wavelengths& l) const noexcept {
        return {bounds_.clip(r, tmin, tmax), value(l)};
    }

private:
    Box bounds_;
    typename Spectral::Coefficient bound_;
};

}  // namespace nsp
