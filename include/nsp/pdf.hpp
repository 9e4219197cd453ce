// nsp/pdf.hpp: independent evaluation of segment pdfs from the vertices alone (THEORY 4, 6).
//
// Samplers report their pdfs as running ratios (tracking.hpp). These functions recompute the
// absolute pdf of a given set of vertices from scratch, from the majorant and the medium, so
// tests can check that what a sampler reports is what it did, and hosts can weight paths that
// another strategy produced. No sampler produces vertices on a ray that is not usable_ray (a
// non-finite origin, a direction that is not unit length) or up to a NaN distance: the log pdfs of
// such a ray are -inf.
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>
#include <span>

#include "majorant.hpp"
#include "tracking.hpp"

namespace nsp {

/// The majorant optical depth int_a^b mu_bar dt along `ray` (Tbar(a, b) = exp(-result)), of
/// channel `c` for a per-channel majorant.
template <Medium M, MajorantPolicy<M> Maj>
double majorant_optical_depth(const Maj& majorant, const Ray& ray, float a, float b,
                              const typename M::Spectral::Wavelengths& lambda, int c = 0) {
    double tau = 0.0;
    auto it = majorant.iterate(ray, a, b, lambda);
    while (auto seg = it.next()) {
        const float lo = std::max(seg->t0, a), hi = std::min(seg->t1, b);
        const double mu = channel_of(seg->sigma_maj, c);
        if (hi > lo && mu > 0.0) tau += mu * (double(hi) - double(lo));
    }
    return tau;
}

/// The majorant value (grey, or every channel's) of the segment covering distance t along
/// `ray`, or std::nullopt where no segment covers t.
template <Medium M, MajorantPolicy<M> Maj>
std::optional<MajorantValue<Maj, M>> majorant_value_at(const Maj& majorant, const Ray& ray, float t,
                                                       const typename M::Spectral::Wavelengths& lambda) {
    auto it = majorant.iterate(ray, 0.f, kInf, lambda);
    while (auto seg = it.next())
        if (seg->t0 <= t && t < seg->t1) return seg->sigma_maj;
    return std::nullopt;
}

/// The majorant at the point ray.at(t): one cell lookup when the policy has
/// `value_at(point, lambda)` (GlobalMajorant, GridMajorant, ChannelGridMajorant), else the segment
/// walk of majorant_value_at (zero where no segment covers t). The two differ only on the measure-
/// zero set of cell faces, so estimators that need mu_bar at a vertex they did not track (an
/// equiangular or emission sample) use this.
template <Medium M, MajorantPolicy<M> Maj>
MajorantValue<Maj, M> majorant_value_at_point(const Maj& majorant, const Ray& ray, float t,
                                              const typename M::Spectral::Wavelengths& lambda) {
    if constexpr (requires { { majorant.value_at(ray.at(t), lambda) } -> std::convertible_to<MajorantValue<Maj, M>>; }) {
        return majorant.value_at(ray.at(t), lambda);
    } else {
        if (const auto mu = majorant_value_at<M>(majorant, ray, t, lambda)) return *mu;
        MajorantValue<Maj, M> zero{};
        if constexpr (!std::is_same_v<MajorantValue<Maj, M>, float>) zero.setZero();
        return zero;
    }
}

/// The majorant mu_bar at distance t along `ray` (0 where no segment covers t), of channel `c`
/// for a per-channel majorant.
template <Medium M, MajorantPolicy<M> Maj>
float majorant_at(const Maj& majorant, const Ray& ray, float t,
                  const typename M::Spectral::Wavelengths& lambda, int c = 0) {
    const auto mu = majorant_value_at<M>(majorant, ray, t, lambda);
    return mu ? channel_of(*mu, c) : 0.f;
}

/// The coefficients tracking sees at distance t along `ray`: the medium's, clamped to the
/// majorant under bound::Clamp (free_flight does the same), so pdfs of clamped flights agree.
template <Medium M, MajorantPolicy<M> Maj>
Coefficients<typename M::Spectral> tracked_coefficients(const M& medium, const Maj& majorant, const Ray& ray,
                                                        float t, const typename M::Spectral::Wavelengths& lambda) {
    auto k = medium.coefficients(ray.at(t), lambda);
    if constexpr (std::is_same_v<bound_policy_t<Maj>, bound::Clamp>)
        if (const auto mu = majorant_value_at<M>(majorant, ray, t, lambda)) detail::clamp_to_majorant(k, *mu);
    return k;
}

/// log pdf that delta tracking (policy A) from `ray.o` creates null vertices at `nulls`
/// (increasing) and then either passes tmax (`end` = Passed) or has event `end` at `t_end`:
/// prod_j mu_bar(n_j) Tbar(n_j-1, n_j) P_n(n_j) * [mu_bar(y) Tbar(n_m, y) P_end(y) or Tbar(n_m, tmax)].
template <AbsorptionPolicy A, Medium M, MajorantPolicy<M> Maj>
double delta_segment_log_pdf(const M& medium, const Maj& majorant, const Ray& ray, float tmax,
                             const typename M::Spectral::Wavelengths& lambda,
                             std::span<const float> nulls, SegmentEnd end, float t_end) {
    if (!usable_ray(ray) || std::isnan(tmax)) return -std::numeric_limits<double>::infinity();
    double lp = 0.0;
    float prev = 0.f;
    for (const float t : nulls) {
        const float mu = majorant_at<M>(majorant, ray, t, lambda);
        const auto p = event_probabilities<A>(tracked_coefficients(medium, majorant, ray, t, lambda), mu);
        lp += std::log(double(mu) * p.null) - majorant_optical_depth<M>(majorant, ray, prev, t, lambda);
        prev = t;
    }
    if (end == SegmentEnd::Passed) return lp - majorant_optical_depth<M>(majorant, ray, prev, tmax, lambda);
    const float mu = majorant_at<M>(majorant, ray, t_end, lambda);
    const auto p = event_probabilities<A>(tracked_coefficients(medium, majorant, ray, t_end, lambda), mu);
    const float p_end = end == SegmentEnd::Absorbed ? p.absorb : p.scatter;
    return lp + std::log(double(mu) * p_end) - majorant_optical_depth<M>(majorant, ray, prev, t_end, lambda);
}

/// log pdf that ratio tracking from `ray.o` to tmax creates null vertices at `nulls`:
/// prod_j mu_bar(n_j) Tbar(n_j-1, n_j) * Tbar(n_m, tmax).
template <Medium M, MajorantPolicy<M> Maj>
double ratio_segment_log_pdf(const M&, const Maj& majorant, const Ray& ray, float tmax,
                             const typename M::Spectral::Wavelengths& lambda,
                             std::span<const float> nulls) {
    if (!usable_ray(ray) || std::isnan(tmax)) return -std::numeric_limits<double>::infinity();
    double lp = 0.0;
    float prev = 0.f;
    for (const float t : nulls) {
        lp += std::log(double(majorant_at<M>(majorant, ray, t, lambda))) -
              majorant_optical_depth<M>(majorant, ray, prev, t, lambda);
        prev = t;
    }
    return lp - majorant_optical_depth<M>(majorant, ray, prev, tmax, lambda);
}

// ---------------------------------------------------------------------------------------------
// Per-channel pdfs (THEORY 5.3), evaluated from the vertices in double, independently of the
// samplers in channel_tracking.hpp

/// Channel c's probability of event `end` (Absorbed, Scattered, or Passed for a null) at a
/// collision with coefficients k under channel c's majorant mu > 0, when channel c is tracked
/// with its own event probabilities of policy A (|mu_x| / (mu_a + mu_s + |mu_n|), THEORY 4).
template <AbsorptionPolicy A, SpectralMode S>
double channel_event_probability(const Coefficients<S>& k, double mu, int c, SegmentEnd end) {
    const double a = std::max(0.0, double(k.sigma_a[c])), s = std::max(0.0, double(k.sigma_s[c]));
    const double n = std::abs(mu - a - s);
    const double total = a + s + n;
    if (!(total > 0.0)) return 0.0;
    if (end == SegmentEnd::Passed) return n / total;
    if constexpr (A::as_event) return (end == SegmentEnd::Absorbed ? a : s) / total;
    else return end == SegmentEnd::Scattered ? (a + s) / total : 0.0;
}

/// log of channel c's pdf of a delta-tracked segment when channel c is tracked alone with its
/// own majorant and event probabilities: nulls at `nulls`, then event `end` at t_end or the pass
/// of tmax (see delta_segment_log_pdf). -inf where channel c cannot produce these vertices.
template <AbsorptionPolicy A, Medium M, MajorantPolicy<M> Maj>
double channel_delta_segment_log_pdf(const M& medium, const Maj& majorant, const Ray& ray, float tmax,
                                     const typename M::Spectral::Wavelengths& lambda, int c,
                                     std::span<const float> nulls, SegmentEnd end, float t_end) {
    if (!usable_ray(ray) || std::isnan(tmax)) return -std::numeric_limits<double>::infinity();
    double lp = 0.0;
    float prev = 0.f;
    auto vertex = [&](float t, SegmentEnd e) {
        const double mu = majorant_at<M>(majorant, ray, t, lambda, c);
        const double p = mu > 0.0 ? channel_event_probability<A>(tracked_coefficients(medium, majorant, ray, t, lambda), mu, c, e) : 0.0;
        lp += std::log(mu * p) - majorant_optical_depth<M>(majorant, ray, prev, t, lambda, c);
        prev = t;
    };
    for (const float t : nulls) vertex(t, SegmentEnd::Passed);
    if (end == SegmentEnd::Passed) return lp - majorant_optical_depth<M>(majorant, ray, prev, tmax, lambda, c);
    vertex(t_end, end);
    return lp;
}

/// log of channel c's ratio-tracking pdf of nulls at `nulls` on [0, tmax]:
/// prod_j mu_bar_c(n_j) Tbar_c(n_j-1, n_j) * Tbar_c(n_m, tmax).
template <Medium M, MajorantPolicy<M> Maj>
double channel_ratio_segment_log_pdf(const Maj& majorant, const Ray& ray, float tmax,
                                     const typename M::Spectral::Wavelengths& lambda, int c,
                                     std::span<const float> nulls) {
    if (!usable_ray(ray) || std::isnan(tmax)) return -std::numeric_limits<double>::infinity();
    double lp = 0.0;
    float prev = 0.f;
    for (const float t : nulls) {
        lp += std::log(double(majorant_at<M>(majorant, ray, t, lambda, c))) -
              majorant_optical_depth<M>(majorant, ray, prev, t, lambda, c);
        prev = t;
    }
    return lp - majorant_optical_depth<M>(majorant, ray, prev, tmax, lambda, c);
}

}  // namespace nsp
