// nsp/transmittance.hpp: transmittance estimators beyond ratio tracking (THEORY 5.10), for uses
// that need an unbiased transmittance and no path pdf: a host's own shadow query, NEE alone, NEE
// under directional MIS (THEORY 5.2). Ratio and delta tracking stay in tracking.hpp.
//
// - transmittance_residual_ratio (Novak, Selle and Jarosz 2014): under a control policy
//   (majorants/control.hpp), exp(-tau_c) in closed form times ratio tracking of the residual at
//   rate mu_bar_r. Lookups scale with the residual majorant's optical depth instead of the
//   majorant's: none where the control is the whole extinction; with a control of 0 it is ratio
//   tracking, draw for draw.
// - transmittance_ray_marching (after Kettunen, d'Eon, Pantaleoni and Novak 2021, "An unbiased
//   ray-marching transmittance estimator"): jittered combs of lookups, each an unbiased estimate
//   X of the optical depth tau; the first is the pivot X_0 of the series
//   exp(-tau) = exp(-X_0) sum_k (X_0 - tau)^k / k!, whose k-th power is the product of k further
//   combs' (X_0 - X_i) (independent, so unbiased), its order ended by roulette on the size of the
//   last term. Exact (no variance) where lookup / majorant is constant along the ray (a
//   homogeneous medium under its own majorant); its estimate may leave [0, 1] (it is unbiased, not
//   bounded).
//
// Every kernel: never throws, allocates nothing, status InvalidInput (value 0) for a ray that is not
// usable_ray or a NaN tmax, Aborted where a limit was reached, NonFinite where the estimate left
// float's range (value 0).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "core/counter.hpp"
#include "core/math.hpp"
#include "core/rng.hpp"
#include "core/status.hpp"
#include "majorant.hpp"
#include "majorants/control.hpp"
#include "medium.hpp"
#include "options.hpp"
#include "tracking.hpp"

namespace nsp {

/// Residual ratio tracking of the transmittance along `ray` over [0, tmax] (see the header): per
/// channel exp(-sum mu_c,c len) times prod_i (1 - (mu_t,c(x_i) - mu_c,c) / mu_bar_r) over
/// tentative collisions x_i at rate mu_bar_r, each channel with its own control (the free-flight
/// loop's residual ratio tracking, track_ratio under a control, takes one grey control for every
/// channel so that its null probabilities pair with decomposition tracking's; per channel, a
/// chromatic medium's residual is smaller). At most `max_collisions` tentative collisions (then
/// Aborted).
template <Medium M, ControlPolicy<M> Ctl, UniformRng R, LookupCounter C>
TransmittanceSample<typename M::Spectral> transmittance_residual_ratio(
    const M& medium, const Ctl& control, const Ray& ray, float tmax, const typename M::Spectral::Wavelengths& lambda,
    R& rng, C& counter, std::uint32_t max_collisions = kDefaultMaxCollisions) {
    using Spec = typename M::Spectral::Spectrum;
    const Spec zero = Spec::Zero();
    if (!usable_ray(ray) || tmax != tmax) [[unlikely]]
        return {zero, Status::InvalidInput};
    auto segments = control.iterate(ray, 0.f, tmax, lambda);
    const detail::StepReport<decltype(segments), C> report{segments, counter};
    Spec tau_c = zero;
    // The product in double and its end below float's smallest normal, as ratio tracking's
    // (tracking.hpp, RatioCollision): a control of 0 gives its estimates, draw for draw.
    detail::DoubleSpectrum<Spec> T = detail::DoubleSpectrum<Spec>::Ones();
    std::uint32_t collisions = 0;
    float e = -1.f;  // residual optical depth left to the next tentative collision (as free_flight)
    while (auto seg = segments.next()) {
        tau_c += seg->sigma_ctl * (seg->t1 - seg->t0);
        const float rate = seg->sigma_res;
        if (!(rate > 0.f)) continue;  // the control is the whole extinction here: no lookup
        float t = seg->t0;
        for (;;) {
            if (!(e > 0.f)) e = -std::log(1.f - rng.uniform());
            const float dt = e / rate;
            if (!(dt < seg->t1 - t)) {
                e -= rate * (seg->t1 - t);
                break;
            }
            t += dt;
            e = -1.f;
            if (++collisions > max_collisions) return {zero, Status::Aborted};
            counter.lookup();
            const Spec residual = medium.coefficients(ray.at(t), lambda).sigma_t() - seg->sigma_ctl;
            T *= (double(rate) - residual.template cast<double>()) / double(rate);
            if ((T.abs() < double(std::numeric_limits<float>::min())).all()) return {zero, Status::Ok};
        }
    }
    const Spec out = Spec(T.template cast<float>()) * (-tau_c).exp();
    if (!all_finite(out)) return {zero, Status::NonFinite};
    return {out, Status::Ok};
}

namespace detail {

/// One jittered comb along `ray` over [0, tmax] under a grey majorant: n lookups at majorant
/// optical depths (i + u) tau_bar / n, i = 0 .. n - 1, each lookup's extinction over the majorant
/// there times tau_bar / n: an unbiased estimate of the optical depth (each point uniform in its
/// stratum of majorant depth), exact where mu_t / mu_bar is constant.
template <Medium M, MajorantPolicy<M> Maj, LookupCounter C>
typename M::Spectral::Spectrum comb_depth(const M& medium, const Maj& majorant, const Ray& ray, float tmax,
                                          const typename M::Spectral::Wavelengths& lambda, double tau_bar, int n,
                                          float u, C& counter) {
    using Spec = typename M::Spectral::Spectrum;
    Spec sum = Spec::Zero();
    const double stride = tau_bar / double(n);
    auto segments = majorant.iterate(ray, 0.f, tmax, lambda);
    const StepReport<decltype(segments), C> report{segments, counter};
    double depth = 0.0;  // the majorant depth at the start of the segment
    int i = 0;
    float last_t = 0.f, last_mu = 0.f;
    auto add = [&](float t, float mu_bar) {
        counter.lookup();
        sum += medium.coefficients(ray.at(t), lambda).sigma_t() / mu_bar;
    };
    while (auto seg = segments.next()) {
        const float mu_bar = seg->sigma_maj;
        if (!(mu_bar > 0.f)) continue;
        const double end = depth + double(mu_bar) * double(seg->t1 - seg->t0);
        for (; i < n; ++i) {
            const double s = (double(i) + double(u)) * stride;
            if (!(s < end)) break;
            add(std::min(seg->t1, seg->t0 + float((s - depth) / double(mu_bar))), mu_bar);
        }
        depth = end;
        last_t = seg->t1;
        last_mu = mu_bar;
    }
    // A point that rounding put at or past the last segment's end (the same sums made tau_bar
    // and `end`, so only (i + u) stride can round up): it belongs at that end.
    for (; i < n && last_mu > 0.f; ++i) add(last_t, last_mu);
    return sum * float(stride);
}

}  // namespace detail

/// Unbiased ray marching of the transmittance along `ray` over [0, tmax] under a grey majorant
/// (see the header): the pivot comb and, by roulette, one comb per further order. Lookups: n per
/// comb (RayMarchingOptions), 2 combs where the medium is homogeneous along the ray.
template <Medium M, MajorantPolicy<M> Maj, UniformRng R, LookupCounter C>
TransmittanceSample<typename M::Spectral> transmittance_ray_marching(const M& medium, const Maj& majorant,
                                                                     const Ray& ray, float tmax,
                                                                     const typename M::Spectral::Wavelengths& lambda,
                                                                     R& rng, C& counter,
                                                                     const RayMarchingOptions& options = {}) {
    static_assert(!is_per_channel_majorant_v<Maj, M>,
                  "transmittance_ray_marching places its combs by a grey majorant (GlobalMajorant, GridMajorant, a tree)");
    using Spec = typename M::Spectral::Spectrum;
    const Spec zero = Spec::Zero();
    if (!usable_ray(ray) || tmax != tmax) [[unlikely]]
        return {zero, Status::InvalidInput};
    double tau_bar = 0.0;
    {
        auto segments = majorant.iterate(ray, 0.f, tmax, lambda);
        const detail::StepReport<decltype(segments), C> report{segments, counter};
        while (auto seg = segments.next())
            if (seg->sigma_maj > 0.f) tau_bar += double(seg->sigma_maj) * double(seg->t1 - seg->t0);
    }
    if (!(tau_bar > 0.0)) return {Spec::Ones(), Status::Ok};  // nothing to extinguish
    if (!std::isfinite(tau_bar)) return {zero, Status::Aborted};
    const double want = std::ceil(tau_bar * double(options.lookups_per_depth));
    const int n = int(std::clamp(want, double(options.min_lookups), double(options.max_lookups)));
    const Spec pivot = detail::comb_depth(medium, majorant, ray, tmax, lambda, tau_bar, n, rng.uniform(), counter);
    Spec sum = Spec::Ones();
    Spec term = Spec::Ones();  // prod_{i <= k} (X_0 - X_i) / k!
    float weight = 1.f;        // 1 / the probability of having reached this order
    for (int k = 1;; ++k) {
        const Spec x = detail::comb_depth(medium, majorant, ray, tmax, lambda, tau_bar, n, rng.uniform(), counter);
        term *= (pivot - x) / float(k);
        sum += term * weight;
        const float size = (term * weight).abs().maxCoeff();
        if (!(size > 0.f)) break;  // the comb saw no difference: the series ends exactly
        const float go_on = std::min(1.f, size / options.term_scale);
        if (go_on < 1.f && !(rng.uniform() < go_on)) break;
        if (k >= options.max_order) return {zero, Status::Aborted};
        weight /= go_on;
    }
    const Spec out = sum * (-pivot).exp();
    if (!all_finite(out)) return {zero, Status::NonFinite};
    return {out, Status::Ok};
}

}  // namespace nsp
