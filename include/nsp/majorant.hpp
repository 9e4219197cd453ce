// nsp/majorant.hpp: majorant policies, piecewise-constant bounds walked segment by segment.
//
// The free-flight loop (tracking.hpp) iterates over majorant segments from the start, so a grid
// majorant walked by a DDA (ROADMAP 3) is a new model of this concept, not a new loop. A segment
// carries either one grey value (`float`) or one value per channel (the mode's Spectrum): free
// flight samples with the sampling channel's value, and the other channels' pdfs of the same
// vertices are evaluated from theirs (THEORY 5.3).
#pragma once

#include <concepts>
#include <optional>
#include <type_traits>

#include "core/error.hpp"
#include "medium.hpp"

namespace nsp {

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
/// bound over every channel (and wavelength), or a value the caller gives that must bound it.
template <Medium M>
class GlobalMajorant {
public:
    static constexpr bool bounds_density = true;

    /// The tightest global majorant the medium's extinction bound allows.
    explicit GlobalMajorant(const M& medium) : bounds_(medium.bounds()), value_(medium.max_extinction()) {
        detail::require_finite_nonnegative(value_, "GlobalMajorant: the medium's extinction bound");
    }

    /// A caller-chosen majorant; throws InvalidArgument unless it is finite and at least the
    /// medium's extinction bound in every channel (this policy does not allow negative nulls).
    GlobalMajorant(const M& medium, float value) : bounds_(medium.bounds()), value_(value) {
        detail::require_finite_nonnegative(value, "GlobalMajorant value");
        if constexpr (!is_hero_v<typename M::Spectral>) {  // fixed channels: name the one violated
            const auto bound = medium.extinction_bound(typename M::Spectral::Wavelengths{});
            for (int c = 0; c < bound.size(); ++c)
                if (value < bound[c])
                    detail::fail("GlobalMajorant value = ", value, " is below the medium's extinction bound ",
                                 bound[c], " in channel ", c, "; this policy requires mu_bar >= mu_t everywhere");
        } else if (value < medium.max_extinction()) {
            detail::fail("GlobalMajorant value = ", value, " is below the medium's extinction bound ",
                         medium.max_extinction(), " over the visible range; this policy requires mu_bar >= mu_t "
                         "everywhere");
        }
    }

    /// The majorant value.
    float value() const noexcept { return value_; }

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
/// 0: no collisions are sampled with it, and its pdf of any collision is 0.
template <ChannelBoundedMedium M>
class ChannelMajorant {
public:
    static constexpr bool bounds_density = true;
    using Spectral = typename M::Spectral;
    using Spectrum = typename Spectral::Spectrum;

    /// Each channel's extinction bound; throws InvalidArgument if one is not finite.
    explicit ChannelMajorant(const M& medium)
        : bounds_(medium.bounds()), bound_(medium.extinction_bound_coefficient()) {
        detail::require_finite_nonnegative(max_value(bound_), "ChannelMajorant: the medium's extinction bound");
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
