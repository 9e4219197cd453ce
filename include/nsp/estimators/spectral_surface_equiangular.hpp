// nsp/estimators/spectral_surface_equiangular.hpp: NEE and equiangular sampling in
// SpectralPathEstimator's loop over a SurfaceScene (THEORY 5.4 with 5.3 and 5.8): the light
// sample of a real vertex against every channel's pdfs of the strategy's techniques, and the
// equiangular vertex of a piece (surface_equiangular.hpp's mixture over the light sampler's
// targets) with every channel's equiangular and tracking pdfs, as spectral.hpp has them in media
// in empty space. The state's eq.vertex holds uni at the piece's start times the ratio-tracking
// pdfs of the piece's nulls: the equiangular prefix of a vertex on the piece.
#pragma once

#include <algorithm>
#include <cmath>

#include "../channel_tracking.hpp"
#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../path_pdf.hpp"
#include "../surface_scene.hpp"
#include "common.hpp"
#include "surface_equiangular.hpp"
#include "surface_walk.hpp"

namespace nsp::detail {

/// A shadow ray's per-channel factors through a SurfaceScene (see ChannelShadow) to the point at
/// `distance` (kInf: a light at infinity), the pieces between null interfaces multiplied and the
/// last one tracked up to the end point; f = 0 where a surface blocks it before shadow_margin of
/// the end. `end` Passed, or the first failed piece's end (Aborted, Rejected, Overflowed), or
/// InvalidInput for a bad hit. `end_medium`, if given, receives the medium the ray ends in
/// (where it passes).
template <ChannelPolicy CP, AbsorptionPolicy A, class Sc, UniformRng R, LookupCounter C>
ChannelShadow<typename Sc::Spectral> channel_shadow_through(const Sc& sc, Ray r, float distance, int medium,
                                                            const typename Sc::Spectral::Wavelengths& lambda, int c,
                                                            const typename Sc::Spectrum& weights, bool uni_alternative,
                                                            R& rng, C& counter, int* end_medium = nullptr) {
    using Sp = typename Sc::Spectral;
    ChannelShadow<Sp> out;
    auto blocked = [] {
        ChannelShadow<Sp> b;
        b.f.setZero();
        return b;
    };
    const float margin = shadow_margin(distance);
    for (int crossing = 0; crossing <= kMaxInterfaceCrossings; ++crossing) {
        const SurfaceHit h = sc.geometry.intersect(r, distance - margin);
        if (!usable_hit(sc, h)) {
            ChannelShadow<Sp> bad = blocked();
            bad.end = SegmentEnd::InvalidInput;
            return bad;
        }
        if (sc.has_medium(medium)) {
            const auto& m = sc.media[std::size_t(medium)];
            const auto s = track_channels_ratio<CP, A>(m.medium, m.majorant, r, h.found() ? h.t : distance, lambda, c,
                                                       typename Sc::Spectrum(weights * out.f), uni_alternative, rng,
                                                       counter);
            if (s.end == SegmentEnd::Terminated) return blocked();
            if (s.end != SegmentEnd::Passed) {
                ChannelShadow<Sp> failed = blocked();
                failed.end = s.end;
                return failed;
            }
            out.f *= s.f;
            out.nee *= s.nee;
            out.uni *= s.uni;
            // One common factor for the three keeps many pieces inside float's range; it cancels.
            const float k = std::max(out.nee.maxCoeff(), out.uni.maxCoeff());
            if (k > 0.f && std::isfinite(k)) {
                out.f /= k;
                out.nee /= k;
                out.uni /= k;
            }
        }
        if (!h.found()) {
            if (end_medium) *end_medium = medium;
            return out;
        }
        if (!crosses(sc, h)) return blocked();
        medium = h.medium_entered(r.d);
        r.o = h.p;
        distance -= h.t;
    }
    ChannelShadow<Sp> bad = blocked();
    bad.end = SegmentEnd::InvalidInput;
    return bad;
}

/// NEE from real vertex v at x (arrived along wo, roulette survival rr) over channels: `f_x` every
/// channel's contribution up to x, `p_track` its tracking pdf and `p_eq` its equiangular pdf (0
/// where equiangular sampling cannot draw x), relative to one normaliser; `start_medium(wi)` the
/// medium a shadow ray along wi starts in. Draws three random numbers; none at a delta BSDF.
/// Returns a failed shadow ray's status (NonFinite: the caller discards the path).
template <ChannelPolicy CP, PathStrategy St, AbsorptionPolicy A, class Sc, class StartMedium, UniformRng R,
          LookupCounter C>
Status channel_light_event(const Sc& sc, const SceneVertex& v, const Vec3& x, const Vec3& wo, float rr,
                           StartMedium start_medium, const typename Sc::Spectral::Wavelengths& lambda,
                           const typename Sc::Spectrum& q, int c, const typename Sc::Spectrum& f_x,
                           const typename Sc::Spectrum& p_track, const typename Sc::Spectrum& p_eq, float nee_count,
                           bool eq_drawn, R& rng, C& counter, typename Sc::Spectrum& L) {
    using Spectrum = typename Sc::Spectrum;
    const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
    if (v.on_surface() && sc.materials.is_delta(v.material)) return Status::Ok;
    const SampledLight<typename Sc::Spectral> ls = sc.lights.sample(x, u0, u1, u2, lambda);
    if (!(ls.sample.pdf > 0.f)) return Status::Ok;
    const auto fv = eval_vertex(sc, v, wo, ls.sample.wi, lambda);
    if (!(fv.value != 0.f).any()) return Status::Ok;
    const bool uni_alternative = St::combines && !ls.sample.delta;
    const double before = recorder_work(counter);
    const auto sh = channel_shadow_through<CP, A>(sc, Ray{x, fv.wi}, ls.sample.distance,
                                                  start_medium(fv.wi), lambda, c, f_x, uni_alternative, rng, counter);
    record_shadow_walk(counter, before, !eq_drawn);
    if (sh.end != SegmentEnd::Passed) return flight_status(sh.end);
    if (!(sh.f != 0.f).any()) return Status::Ok;
    // Tracking + NEE (its expected count), tracking + hit, and equiangular + NEE (count 1)
    // (THEORY 5.4 with 5.1, 5.3, 5.9); p_eq is 0 without equiangular sampling.
    const Spectrum nee = p_track * (ls.sample.pdf * sh.nee);
    Spectrum uni = Spectrum::Zero(), other = Spectrum::Zero();
    if (uni_alternative) uni = p_track * ((rr * fv.pdf) * sh.uni);
    if constexpr (St::equiangular) other = p_eq * (ls.sample.pdf * sh.nee);
    else (void)p_eq;
    const Spectrum f = f_x * sh.f * fv.value;
    record_channels<CP>(counter, Spectrum(f * ls.sample.radiance), uni, nee, other, q, c, nee_count,
                        eq_drawn ? LightTechnique::Other : LightTechnique::Nee);
    L += channel_estimate<CP>(f, Spectrum(nee_count * nee + uni + other), q, c) * ls.sample.radiance;
    return Status::Ok;
}

/// Equiangular + NEE over channels on one piece of a path segment in medium `index`: t drawn from
/// `eq`, the nulls on [0, t) ratio-tracked with channel c's majorant and every channel's pdfs, t
/// a real scattering vertex at path depth `depth` with NEE from it. `st` is the state at the
/// piece's origin; `select` the probability with which the piece draws the vertex at all.
template <ChannelPolicy CP, PathStrategy St, AbsorptionPolicy A, class Sc, class State, UniformRng R, LookupCounter C>
Status channel_equiangular_event(const EstimatorOptions& opts, const Sc& sc, int index, const Ray& ray,
                                 const PieceEquiangular<Sc>& eq, float select, int depth,
                                 const typename Sc::Spectral::Wavelengths& lambda, const typename Sc::Spectrum& q,
                                 int c, const State& st, R& rng, C& counter, typename Sc::Spectrum& L) {
    using S = typename Sc::Spectral;
    using Spectrum = typename Sc::Spectrum;
    const auto& m = sc.media[std::size_t(index)];
    const float u_pick = rng.uniform(), u = rng.uniform();
    DistanceSample ds = eq.sample(u_pick, u);
    ds.pdf *= select;
    if (!(ds.pdf > 0.f)) return Status::Ok;
    const auto sh = track_channels_ratio<CP, A>(m.medium, m.majorant, ray, ds.t, lambda, c, st.f, St::combines, rng,
                                                counter);
    if (const Status fs = flight_status(sh.end); fs != Status::Ok) return fs;
    if (sh.end == SegmentEnd::Terminated) return Status::Ok;
    const auto v = lookup_untracked(m.medium, m.majorant, ray, ds.t, lambda, counter);
    if (!v) return Status::Rejected;
    const auto& k = v->k;
    const auto& mu_v = v->mu;
    const Spectrum f_x = st.f * sh.f * k.sigma_s;
    if (!(f_x != 0.f).any()) return Status::Ok;
    const Spectrum p_eq = st.uni * sh.nee * ds.pdf;
    Spectrum p_track = Spectrum::Zero();
    float rr = 1.f;
    if constexpr (St::combines) {
        // Every channel's tracking pdf of the same nulls and of a real scattering vertex at x.
        const Spectrum scatter = channel_scatter_densities<CP, A, S>(k, mu_v, Spectrum(st.f * sh.f));
        p_track = st.uni * sh.uni * scatter;
        // The survival tracking would give x: a function of the path (its f and tracking pdfs).
        if (opts.russian_roulette && depth >= opts.rr_start_depth)
            rr = std::min(opts.rr_max_survival, channel_estimate<CP>(f_x, p_track, q, c).abs().maxCoeff());
    }
    const SceneVertex xv{-1, index, Vec3(0.f, 0.f, 1.f)};
    return channel_light_event<CP, St, A>(sc, xv, ray.at(ds.t), ray.d, rr, [&](const Vec3&) { return index; }, lambda,
                                          q, c, f_x, p_track, p_eq, opts.nee_count, true, rng, counter, L);
}

}  // namespace nsp::detail
