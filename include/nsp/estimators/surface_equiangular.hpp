// nsp/estimators/surface_equiangular.hpp: equiangular sampling in PathEstimator's loop over a
// SurfaceScene (THEORY 5.4 with 5.8). On every piece of a path segment that runs through a
// medium (from the ray's origin or a null interface up to the next surface, clipped to the
// medium's bounds) the strategy draws, with probability `select`, a real vertex aimed at the light
// sampler's targets (LightSampler::equiangular_point: a mixture over the lights with a point, by
// their selection probabilities), ratio-tracks the nulls before it and does NEE from it. Its pdf
// against tracking's is piece-local, as the pieces before it are the tracked path's in both:
// select p_mix(t) / (prod P_n(piece) mu_bar P_s). Surface vertices are tracking's alone.
#pragma once

#include <algorithm>
#include <cmath>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../equiangular.hpp"
#include "../surface_scene.hpp"
#include "../vertex.hpp"
#include "common.hpp"
#include "surface_walk.hpp"

namespace nsp::detail {

/// The equiangular technique on one piece [t0, t1] of `ray`: the mixture over the light
/// sampler's targets. Default-constructed: off (density 0).
template <class Sc>
class PieceEquiangular {
public:
    PieceEquiangular() = default;
    PieceEquiangular(const Sc& sc, const Ray& ray, float t0, float t1) noexcept : sc_(&sc), ray_(ray), t0_(t0), t1_(t1) {}

    /// Whether the technique runs on this piece: a stretch of positive length and a target.
    bool valid() const noexcept { return sc_ != nullptr && t1_ > t0_ && sc_->lights.equiangular_count() > 0; }

    /// The mixture density sum_k P_k p_k(t) per unit length (0 off the stretch).
    float density(float t) const noexcept {
        if (!valid()) return 0.f;
        float p = 0.f;
        for (int k = 0; k < sc_->lights.equiangular_count(); ++k)
            p += sc_->lights.equiangular_pmf(k) * sampler(k).pdf(t);
        return p;
    }

    /// t drawn from the mixture (a target by u_pick, then its equiangular distance by u), with
    /// the mixture density there.
    DistanceSample sample(float u_pick, float u) const noexcept {
        if (!valid()) return {};
        const int k = sc_->lights.pick_equiangular(u_pick);
        DistanceSample ds = sampler(k).sample(u);
        if (ds.pdf > 0.f) ds.pdf = density(ds.t);
        return ds;
    }

    /// The probability with which the piece draws an equiangular vertex: 1, or with
    /// EstimatorOptions::adaptive_equiangular (combining strategies) the largest over the targets
    /// of equiangular_probability; a function of the piece alone, as every technique needs it.
    template <PathStrategy St, Medium M, MajorantPolicy<M> Maj>
    float selection(const EstimatorOptions& opts, const Maj& majorant,
                    const typename M::Spectral::Wavelengths& lambda) const noexcept {
        if (!St::combines || !opts.adaptive_equiangular) return 1.f;
        float p = 0.f;
        for (int k = 0; k < sc_->lights.equiangular_count(); ++k)
            p = std::max(p, equiangular_probability<M>(majorant, ray_, sampler(k), lambda));
        return p;
    }

private:
    EquiangularSampler sampler(int k) const noexcept {
        return EquiangularSampler(ray_, sc_->lights.equiangular_point(k), t0_, t1_);
    }

    const Sc* sc_ = nullptr;
    Ray ray_{};
    float t0_ = 0.f, t1_ = 0.f;
};

/// NEE from real vertex v at x (arrived along wo, roulette survival q, throughput beta) toward
/// the light sampler's lights, its weight against the other techniques of the strategy: hitting
/// the light from x, and with the equiangular strategies the third technique for x, with
/// `track` and `eq` the tracking and equiangular pdfs of x relative to the pdf of the technique
/// that drew it (`eq_drawn`: equiangular). Draws three random numbers; none at a delta BSDF.
template <class K, class Sc, class StartMedium, UniformRng R, LookupCounter C>
Status light_event(const K& k, const Sc& sc, const SceneVertex& v, const Vec3& x, const Vec3& wo, float q,
                   StartMedium start_medium, float track, float eq, bool eq_drawn,
                   const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                   const typename Sc::Spectrum& beta, typename Sc::Spectrum& L) {
    using St = typename K::Strategy;
    const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
    if (v.on_surface() && sc.materials.is_delta(v.material)) return Status::Ok;
    const SampledLight<typename Sc::Spectral> ls = sc.lights.sample(x, u0, u1, u2, lambda);
    if (!(ls.sample.pdf > 0.f)) return Status::Ok;
    const auto f = eval_vertex(sc, v, wo, ls.sample.wi, lambda);
    if (!(f.value != 0.f).any()) return Status::Ok;
    const double before = recorder_work(counter);
    const auto sh = shadow_through(k, sc, Ray{x, f.wi}, ls.sample.distance, start_medium(f.wi), lambda,
                                   rng, counter);
    record_shadow_walk(counter, before, !eq_drawn);
    if (sh.status != Status::Ok) return sh.status;
    if (!(sh.transmittance != 0.f).any()) return Status::Ok;
    // NEE from a tracked vertex or a surface ran with the expected count nee_count; from an
    // equiangular vertex always (THEORY 5.9).
    const float count = eq_drawn ? 1.f : k.nee_count();
    const typename Sc::Spectrum contribution = beta * sh.transmittance * ls.sample.radiance * f.value / ls.sample.pdf;
    float w;
    if constexpr (St::equiangular && St::combines) {
        // Relative to the technique that drew x followed by NEE (uncounted): tracking + NEE (its
        // count), tracking + hit (not for a delta light) and equiangular + NEE.
        const float s = ls.sample.delta ? 0.f
                                        : unidirectional_pdf<St>(q, f.pdf, sh.null_pdf_product) / ls.sample.pdf;
        w = equiangular_mis_weight(k.heuristic(), eq_drawn ? VertexTechnique::EquiangularNee : VertexTechnique::TrackNee,
                                   track * k.nee_count(), track * s, eq);
        record_light(counter, contribution.mean(), track * s, track, eq, k.nee_count(),
                     eq_drawn ? LightTechnique::Other : LightTechnique::Nee);
    } else {
        (void)track, (void)eq, (void)eq_drawn;
        w = k.light_weight(q, f.pdf, sh.null_pdf_product, ls.sample.pdf, ls.sample.delta);
        if constexpr (St::combines && MisRecorder<C>)
            record_light(counter, contribution.mean(),
                         ls.sample.delta ? 0.f : unidirectional_pdf<St>(q, f.pdf, sh.null_pdf_product) / ls.sample.pdf,
                         1.f, 0.f, k.nee_count(), LightTechnique::Nee);
    }
    L += contribution * (w / count);
    return Status::Ok;
}

/// Equiangular + NEE on one piece of a path segment in medium `index` (see the header): t drawn
/// from `eq`, the nulls on [0, t) ratio-tracked, t a real scattering vertex at path depth `depth`
/// with NEE from it. `beta` is the throughput up to the piece's origin; `select` the probability
/// with which the piece draws the vertex at all (its density is select x the mixture's).
template <class K, class Sc, UniformRng R, LookupCounter C>
Status equiangular_event(const K& k, const Sc& sc, int index, const Ray& ray, const PieceEquiangular<Sc>& eq,
                         float select, int depth, const typename Sc::Spectrum& beta,
                         const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                         typename Sc::Spectrum& L) {
    using St = typename K::Strategy;
    const auto& m = sc.media[std::size_t(index)];
    const float u_pick = rng.uniform(), u = rng.uniform();
    DistanceSample ds = eq.sample(u_pick, u);
    ds.pdf *= select;
    if (!(ds.pdf > 0.f)) return Status::Ok;
    const auto tr = k.shadow(m.medium, m.majorant, ray, ds.t, lambda, rng, counter);
    if (tr.status != Status::Ok) return tr.status;
    if (!(tr.transmittance != 0.f).any()) return Status::Ok;
    const auto v = lookup_untracked(m.medium, m.majorant, ray, ds.t, lambda, counter);
    if (!v) return Status::Rejected;
    const typename Sc::Spectrum beta_eq = beta * tr.transmittance * v->k.sigma_s / ds.pdf;
    if (!(beta_eq != 0.f).any()) return Status::Ok;
    float track = 0.f, q = 1.f;  // p_track / p_eq of x; the roulette survival tracking would use at x
    if constexpr (St::combines) {
        track = tracking_over_equiangular<typename K::Absorption>(ds.pdf, tr.null_pdf_product, v->k, v->mu);
        // Roulette survival is a function of the path: the throughput tracking would carry at x.
        if (track > 0.f) q = k.survival(depth, beta_eq / track);
    }
    const SceneVertex x_vertex{-1, index, Vec3(0.f, 0.f, 1.f)};
    return light_event(k, sc, x_vertex, ray.at(ds.t), ray.d, q, [&](const Vec3&) { return index; }, track, 1.f, true,
                       lambda, rng, counter, beta_eq, L);
}

}  // namespace nsp::detail
