// nsp/majorants/control.hpp: controls (minorants) beside majorants, for the estimators that pay
// lookups only for the residual extinction above a known part (THEORY 5.10).
//
// A control policy is a majorant policy whose segments are ControlSegments: on [t0, t1) the
// majorant mu_bar and the control mu_c (per channel, known without a lookup) with
// mu_c,c <= mu_t,c(x) <= mu_bar for every channel c and x on the stretch. The free-flight loop
// (tracking.hpp) tracks the residual mu_t - mu_c under the residual majorant mu_bar - mu_c, with
// the grey control mu_c = min_c mu_c,c: ratio tracking takes exp(-mu_c len) in closed form
// (residual ratio tracking), delta tracking draws control collisions at rate mu_c beside the
// residual's tentative ones (decomposition tracking). Where the control is the whole extinction
// (a homogeneous stretch) neither pays a lookup for its nulls; with a control of 0 both are
// today's trackers, draw for draw. The per-channel trackers (channel_tracking.hpp) do the same with
// every channel's pdfs; code that walks the segments without knowing of the control (pdf
// evaluation) sees an ordinary majorant.
//
// GridControl stores per cell the density's lower bound beside its upper bound (two floats per
// cell; a medium without a lower-bound query, LowerBoundedMedium, gets a control of 0 and pays
// for none). TreeControl does the same on TreeMajorant's cells (the same layout, walked by the
// same hierarchical DDA), ChannelGridControl and ChannelTreeControl give each channel of those
// cells its own majorant and control (the per-channel trackers take them with own pdfs), and
// GlobalControl is one constant control and majorant over the medium's box.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "../core/error.hpp"
#include "../majorant.hpp"
#include "../media/validate.hpp"
#include "../medium.hpp"
#include "grid.hpp"
#include "tree.hpp"

namespace nsp {

/// A RegionBoundedMedium that also bounds its density from below over any axis-aligned region
/// inside its box (`density_lower_bound(region)`, rounding included): the control of THEORY 5.10.
template <class M>
concept LowerBoundedMedium = RegionBoundedMedium<M> && requires(const M& m, const Box& b) {
    { m.density_lower_bound(b) } -> std::same_as<float>;
};

/// A stretch [t0, t1) of a ray with its majorant, grey (Maj = float) or per channel (Maj =
/// Spectrum, ChannelGridControl), and its control per channel (see the header).
template <class Spectrum, class Maj = float>
struct ControlSegment {
    float t0 = 0.f;
    float t1 = 0.f;
    Maj sigma_maj{};        ///< mu_bar: the majorant, >= mu_t,c in every channel (per channel: in its channel) on the stretch
    Spectrum sigma_ctl{};   ///< mu_c per channel, finite, >= 0 and <= mu_bar (below mu_t,c unless the caller chose otherwise)
    /// The residual majorant of a per-channel control: mu_t,c - mu_c,c <= sigma_res in every channel
    /// (transmittance_residual_ratio); at most mu_bar - min_c mu_c,c, which the loop's grey control uses.
    float sigma_res = 0.f;
};

namespace detail {
template <class S, class V>
struct is_majorant_segment<ControlSegment<S, V>> : std::true_type {};  // a majorant segment with a control
template <class T>
struct is_control_segment : std::false_type {};
template <class S, class V>
struct is_control_segment<ControlSegment<S, V>> : std::true_type {};
}  // namespace detail

/// A control policy for medium M: a majorant policy whose `iterate(ray, tmin, tmax, lambda)`
/// yields ControlSegments (see the header); `steps()` on the iterator counts its DDA steps where
/// it has them.
template <class P, class M>
concept ControlPolicy = MajorantPolicy<P, M> &&
    detail::is_control_segment<std::remove_cvref_t<decltype(*std::declval<const P&>()
                                                               .iterate(std::declval<const Ray&>(), 0.f, 0.f,
                                                                        std::declval<const typename M::Spectral::Wavelengths&>())
                                                               .next())>>::value;

/// True when majorant policy Maj carries a control (ControlPolicy).
template <class Maj, class M>
inline constexpr bool is_control_v = ControlPolicy<Maj, M>;

/// One control and one majorant over the medium's box: the control a caller gives (per channel),
/// the majorant the medium's extinction bound. Tracking under it is unbiased for any control up to
/// that bound while the residual majorant (bound - the smallest channel's control) is > 0, a
/// control above the extinction in places included: the residual is negative there and the
/// trackers weigh its nulls by sign (THEORY 5.10); at a control equal to the bound nothing is
/// looked up, and the control must be the extinction itself.
template <Medium M>
class GlobalControl {
public:
    using Spectral = typename M::Spectral;
    using Spectrum = typename Spectral::Spectrum;
    using Coefficient = typename Spectral::Coefficient;

    /// Throws InvalidArgument unless every channel of `control` is finite, >= 0 and at most the
    /// medium's extinction bound (max_extinction()) in that channel.
    GlobalControl(const M& medium, const Coefficient& control)
        : bounds_(medium.bounds()), control_(control), majorant_(medium.max_extinction()) {
        detail::require_coefficient(control_, "GlobalControl control");
        detail::require_finite_nonnegative(majorant_, "GlobalControl: the medium's extinction bound");
        const float top = max_value(control_);
        if (top > majorant_)
            detail::fail("GlobalControl control = ", top, " (its largest channel) exceeds the medium's extinction bound ",
                         majorant_, ": a control must lie below the extinction everywhere");
    }

    /// The whole [tmin, tmax] clipped to the box: majorant max_extinction and the control.
    class Iterator {
    public:
        Iterator(Interval in, float maj, const Spectrum& ctl) noexcept
            : seg_{in.t0, in.t1, maj, ctl, std::max(0.f, maj - ctl.minCoeff())}, done_(in.empty()) {}
        std::optional<ControlSegment<Spectrum>> next() noexcept {
            if (done_) return std::nullopt;
            done_ = true;
            return seg_;
        }
        std::uint32_t steps() const noexcept { return 0; }

    private:
        ControlSegment<Spectrum> seg_;
        bool done_;
    };

    Iterator iterate(const Ray& r, float tmin, float tmax, const typename Spectral::Wavelengths& l) const noexcept {
        return {bounds_.clip(r, tmin, tmax), majorant_, Spectral::sample(control_, l)};
    }

    /// The majorant at point p (0 outside the medium's box, as `iterate` clips).
    float value_at(const Vec3& p, const typename Spectral::Wavelengths&) const noexcept {
        return bounds_.contains(p) ? majorant_ : 0.f;
    }
    /// The control at point p, per channel (0 outside the box): a segment's sigma_ctl there.
    Spectrum control_value_at(const Vec3& p, const typename Spectral::Wavelengths& l) const noexcept {
        return bounds_.contains(p) ? Spectrum(Spectral::sample(control_, l)) : Spectrum(Spectrum::Zero());
    }

private:
    Box bounds_;
    Coefficient control_;
    float majorant_;
};

namespace detail {
/// GridControl (kChannels false) and ChannelGridControl (true): the same cells, walked alike; the
/// majorant is grey (d_max max_c u_c) or per channel (d_max u_c).
template <RegionBoundedMedium M, bool kChannels>
class BasicGridControl {
    static constexpr const char* kName = kChannels ? "ChannelGridControl" : "GridControl";

public:
    using Spectral = typename M::Spectral;
    using Spectrum = typename Spectral::Spectrum;

    /// Throws InvalidArgument as GridMajorant does (resolution, box, bounds), and on a lower bound
    /// that is not finite, is negative or exceeds the cell's upper bound.
    BasicGridControl(const M& medium, std::array<int, 3> resolution)
        : upper_(medium, resolution, 1.f, kName), unit_(medium.extinction_per_density()),
          unit_max_(max_value(unit_)), unit_min_(min_value(unit_)) {
        const std::array<int, 3> res = upper_.resolution();
        lower_.assign(std::size_t(res[0]) * std::size_t(res[1]) * std::size_t(res[2]), 0.f);
        if constexpr (LowerBoundedMedium<M>) {
            std::size_t i = 0;
            for (int z = 0; z < res[2]; ++z)
                for (int y = 0; y < res[1]; ++y)
                    for (int x = 0; x < res[0]; ++x, ++i) {
                        const float d = medium.density_lower_bound(upper_.region(x, y, z));
                        if (!std::isfinite(d) || d < 0.f)
                            detail::fail(kName, " cell (", x, ", ", y, ", ", z, "): the medium's density lower bound = ",
                                         d, " is not allowed: it must be finite and >= 0");
                        if (d > upper_.at(x, y, z))
                            detail::fail(kName, " cell (", x, ", ", y, ", ", z, "): the medium's density lower bound = ",
                                         d, " exceeds its upper bound ", upper_.at(x, y, z));
                        lower_[i] = d;
                    }
        }
    }
    BasicGridControl(const M& medium, int resolution) : BasicGridControl(medium, {resolution, resolution, resolution}) {}

    /// A stretch's segment: grey or per-channel majorant.
    using Segment = ControlSegment<Spectrum, std::conditional_t<kChannels, Spectrum, float>>;

    class Iterator {
    public:
        Iterator(const BasicGridControl& g, detail::GridWalk walk, const Spectrum& unit) noexcept
            : g_(&g), walk_(walk), unit_(unit) {}
        std::optional<Segment> next() noexcept {
            std::size_t i;
            float t0, t1;
            while (walk_.next(i, t0, t1)) {
                const float hi = g_->upper_.data()[i];
                if (!(hi > 0.f) || !(t1 > t0)) continue;
                const float lo = g_->lower_[i];
                if constexpr (kChannels) return Segment{t0, t1, unit_ * hi, unit_ * lo, (hi - lo) * g_->unit_max_};
                else return Segment{t0, t1, hi * g_->unit_max_, unit_ * lo, (hi - lo) * g_->unit_max_};
            }
            return std::nullopt;
        }
        std::uint32_t steps() const noexcept { return walk_.steps(); }

    private:
        const BasicGridControl* g_;
        detail::GridWalk walk_;
        Spectrum unit_;
    };

    Iterator iterate(const Ray& r, float tmin, float tmax, const typename Spectral::Wavelengths& l) const noexcept {
        return {*this, upper_.walk(r, tmin, tmax), Spectral::sample(unit_, l)};
    }

    /// The majorant at point p (its cell's, 0 outside the box): one lookup, no walk; grey, or per
    /// channel for ChannelGridControl.
    auto value_at(const Vec3& p, const typename Spectral::Wavelengths& l) const noexcept {
        if constexpr (kChannels) return Spectrum(Spectral::sample(unit_, l) * upper_.at_point(p));
        else return (void)l, upper_.at_point(p) * unit_max_;
    }
    /// The control at point p, per channel (its cell's, 0 outside the box): the sigma_ctl of the
    /// segment `iterate` gives there.
    Spectrum control_value_at(const Vec3& p, const typename Spectral::Wavelengths& l) const noexcept {
        if (!upper_.box().contains(p)) return Spectrum::Zero();
        return Spectral::sample(unit_, l) * lower_[upper_.index_at(p)];
    }

    /// The control's share of the majorant, sum d_min / sum d_max over the cells (0 for an empty
    /// medium): what residual ratio tracking saves in lookups where rays cross cells evenly.
    double controlled_fraction() const noexcept {
        double lo = 0.0, hi = 0.0;
        const float* up = upper_.data();
        for (std::size_t i = 0; i < lower_.size(); ++i) {
            lo += lower_[i];
            hi += up[i];
        }
        return hi > 0.0 ? lo / hi : 0.0;
    }

    std::array<int, 3> resolution() const noexcept { return upper_.resolution(); }
    Vec3 cell_size() const noexcept { return upper_.cell_size(); }
    /// The sum over the cells of the residual majorant that tracking under this control pays
    /// lookups for: the majorant d_max max_c u_c less the grey control d_min min_c u_c (the
    /// free-flight loop's, tracking.hpp), per unit volume of a cell (the cost model's, choose.hpp).
    /// Per channel (ChannelGridControl) the densest channel's: (d_max - d_min) max_c u_c.
    double residual_sum() const noexcept {
        double sum = 0.0;
        const float* up = upper_.data();
        for (std::size_t i = 0; i < lower_.size(); ++i)
            sum += double(up[i]) * unit_max_ - double(lower_[i]) * (kChannels ? unit_max_ : unit_min_);
        return sum;
    }
    /// Bytes of cell storage (two floats per cell).
    std::size_t memory_bytes() const noexcept { return upper_.memory_bytes() + lower_.size() * sizeof(float); }

private:
    detail::MajorantGrid<M> upper_;
    std::vector<float> lower_;
    typename Spectral::Coefficient unit_;
    float unit_max_;
    float unit_min_;
};
}  // namespace detail

/// A grid of controls and majorants over the medium's box (THEORY 5.10): per cell the medium's
/// density bounds from below (LowerBoundedMedium; 0 for a medium without one) and from above,
/// d_min <= d <= d_max; on a cell's stretch the control is d_min times each channel's extinction
/// per density u_c and the majorant d_max max_c u_c (GridMajorant's), so the residual majorant is
/// d_max max_c u_c - d_min min_c u_c ((d_max - d_min) u on a grey medium). Walked by the same DDA
/// as GridMajorant. Two floats per cell. Throws InvalidArgument as GridMajorant does (resolution,
/// box, bounds), and on a lower bound that is not finite, is negative or exceeds the cell's upper
/// bound.
template <RegionBoundedMedium M>
class GridControl : public detail::BasicGridControl<M, false> {
public:
    using detail::BasicGridControl<M, false>::BasicGridControl;
};

/// GridControl's cells with ChannelGridMajorant's per-channel majorant (THEORY 5.10 with 5.3): on
/// a cell's stretch channel c's majorant is d_max u_c and its control d_min u_c, so a chromatic
/// medium's channels each track their own residual (d_max - d_min) u_c. The per-channel trackers
/// (channel_tracking.hpp) take it with own pdfs (spectral MIS, independent tracking): the sampling
/// channel draws decomposition tracking's control and residual collisions with its own control,
/// and every channel's pdfs are its own decomposition tracking's. Two floats per cell; throws as
/// GridControl.
template <RegionBoundedMedium M>
class ChannelGridControl : public detail::BasicGridControl<M, true> {
public:
    using detail::BasicGridControl<M, true>::BasicGridControl;
};

namespace detail {
/// TreeControl (kChannels false) and ChannelTreeControl (true): the same cells, walked alike; the
/// majorant is grey (d_max max_c u_c) or per channel (d_max u_c).
template <CellBoundedMedium M, bool kChannels>
class BasicTreeControl {
    static constexpr const char* kName = kChannels ? "ChannelTreeControl" : "TreeControl";

public:
    using Spectral = typename M::Spectral;
    using Spectrum = typename Spectral::Spectrum;

    /// The adaptive layout over the medium's bounds (as TreeMajorant's default).
    explicit BasicTreeControl(const M& medium) : BasicTreeControl(medium, detail::adaptive_layout(medium)) {}
    /// Throws InvalidArgument as TreeMajorant does, and on a lower bound that is not finite, is
    /// negative or exceeds the cell's upper bound.
    BasicTreeControl(const M& medium, const TreeLayout& layout)
        : tree_(medium, layout, 1.f, kName, true), unit_(detail::CellBounds<M>(medium, kName).unit()),
          unit_max_(max_value(unit_)) {}

    /// A stretch's segment: grey or per-channel majorant.
    using Segment = ControlSegment<Spectrum, std::conditional_t<kChannels, Spectrum, float>>;

    class Iterator {
    public:
        Iterator(const detail::MajorantTree<M>* tree, const Ray& r, float tmin, float tmax, const Spectrum& unit,
                 float unit_max) noexcept
            : walk_(tree, r, tmin, tmax, 1.f), unit_(unit), unit_max_(unit_max) {}
        std::optional<Segment> next() noexcept {
            const auto s = walk_.next();
            if (!s) return std::nullopt;
            const float hi = s->sigma_maj, lo = walk_.lower();
            if constexpr (kChannels) return Segment{s->t0, s->t1, unit_ * hi, unit_ * lo, (hi - lo) * unit_max_};
            else return Segment{s->t0, s->t1, hi * unit_max_, unit_ * lo, (hi - lo) * unit_max_};
        }
        std::uint32_t steps() const noexcept { return walk_.steps(); }

    private:
        detail::TreeSegmentIterator<M, float, true> walk_;
        Spectrum unit_;
        float unit_max_;
    };

    Iterator iterate(const Ray& r, float tmin, float tmax, const typename Spectral::Wavelengths& l) const noexcept {
        return {&tree_, r, tmin, tmax, Spectral::sample(unit_, l), unit_max_};
    }

    /// The majorant at point p (its finest cell's; 0 outside the medium's bounds): grey, or per
    /// channel for ChannelTreeControl.
    auto value_at(const Vec3& p, const typename Spectral::Wavelengths& l) const noexcept {
        if constexpr (kChannels) return Spectrum(Spectral::sample(unit_, l) * tree_.at_point(p));
        else return (void)l, tree_.at_point(p) * unit_max_;
    }
    /// The control at point p, per channel (its finest cell's, 0 outside the bounds): the
    /// sigma_ctl of the segment `iterate` gives there.
    Spectrum control_value_at(const Vec3& p, const typename Spectral::Wavelengths& l) const noexcept {
        return Spectral::sample(unit_, l) * tree_.lower_at_point(p);
    }

    TreeLayout layout() const noexcept { return tree_.layout(); }
    std::size_t coarse_cells() const noexcept { return tree_.coarse_cells(); }
    std::size_t split_cells(int l = 0) const noexcept { return tree_.split_cells(l); }
    std::size_t empty_cells() const noexcept { return tree_.empty_cells(); }
    /// Bytes of cell storage (two floats per cell).
    std::size_t memory_bytes() const noexcept { return tree_.memory_bytes(); }

private:
    detail::MajorantTree<M> tree_;
    typename Spectral::Coefficient unit_;
    float unit_max_;
};
}  // namespace detail

/// A tree of controls and majorants (THEORY 5.10): TreeMajorant's cells, each that is not split
/// keeping the medium's density lower bound over it beside its upper bound (LowerBoundedMedium; 0
/// for a medium without one), so that on a cell's stretch the control is d_min u_c and the majorant
/// d_max max_c u_c, as GridControl's. The layout is the majorant's (the same cost model, which
/// prices the full majorant's lookups, decides the splits), so a TreeControl and a TreeMajorant
/// over one layout walk the same cells. Two floats per cell of every level. Throws as TreeMajorant
/// does, and on a lower bound that is not finite, is negative or exceeds the cell's upper bound.
template <CellBoundedMedium M>
class TreeControl : public detail::BasicTreeControl<M, false> {
public:
    using detail::BasicTreeControl<M, false>::BasicTreeControl;
};

/// TreeControl's cells with ChannelTreeMajorant's per-channel majorant (THEORY 5.10 with 5.3), as
/// ChannelGridControl is GridControl's: channel c's majorant d_max u_c and control d_min u_c, for
/// the per-channel trackers with own pdfs. Throws as TreeControl.
template <CellBoundedMedium M>
class ChannelTreeControl : public detail::BasicTreeControl<M, true> {
public:
    using detail::BasicTreeControl<M, true>::BasicTreeControl;
};

}  // namespace nsp
