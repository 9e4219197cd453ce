// nsp/estimators/equiangular_vertex.hpp: equiangular sampling on the pieces of a path's segments
// (THEORY 5.4 with 5.8): on every piece of a segment that runs through a medium (from the ray's
// origin or a null interface up to the next surface, clipped to the medium's bounds), a real
// vertex drawn toward the light sampler's targets (a mixture over the lights with a point, by
// their selection probabilities), the nulls before it ratio-tracked, and NEE from it. Its pdf
// against tracking's is piece-local, as the pieces before it are the tracked path's in both:
// select p_mix(t) / (prod P_n(piece) mu_bar P_s); the path state keeps both, grey or per channel.
#pragma once

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../equiangular.hpp"
#include "../path_state.hpp"
#include "../pdf.hpp"
#include "nee.hpp"
#include "scene_walk.hpp"

namespace nsp {

/// The probability with which the three-way MIS (strategy::EquiangularMis) draws an equiangular
/// vertex on a segment: min(1, p_eq(t*) / mu_bar(t*)) at the equiangular density's peak t*, with
/// the largest channel's majorant there. p_eq(t*) / mu_bar(t*) compares the equiangular density
/// with the largest density tracking can have where equiangular sampling concentrates: above 1
/// (a thin medium at the scale of the light's distance from the ray) tracking rarely puts a vertex
/// where the light's 1 / r^2 peaks, and every segment draws one; below it (a dense medium) tracking
/// already does, and an equiangular vertex, which costs a second flight and a second shadow ray,
/// is drawn on that fraction of the segments. One-sample MIS with an expected sample count (Veach
/// 1997, 9.2): the equiangular technique's pdf is this probability x its density in every weight
/// and every pdf sum, which keeps the estimator unbiased for any probability in (0, 1]. A function
/// of the segment alone (ray, stretch, light, majorant), so every technique evaluates the same
/// value. 1 where the majorant is 0 at the peak.
template <Medium M, MajorantPolicy<M> Maj>
float equiangular_probability(const Maj& majorant, const Ray& ray, const EquiangularSampler& eq,
                              const typename M::Spectral::Wavelengths& lambda) noexcept {
    const float t = eq.peak();
    const auto mu = majorant_value_at_point<M>(majorant, ray, t, lambda);
    float mu_max;
    if constexpr (std::is_same_v<std::remove_cvref_t<decltype(mu)>, float>) mu_max = mu;
    else mu_max = mu.maxCoeff();
    const float r = eq.pdf(t) / mu_max;  // inf where mu_max = 0; NaN only for pdf 0 and mu 0
    return r < 1.f ? r : 1.f;            // NaN and inf give 1
}

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

    /// The probability with which the piece draws an equiangular vertex: the expected count
    /// EstimatorOptions::equiangular_count, with EstimatorOptions::adaptive_equiangular (combining
    /// strategies) times the largest over the targets of equiangular_probability; a function of
    /// the piece alone, as every technique needs it. 0 at count 0: the technique is absent.
    template <PathStrategy St, Medium M, MajorantPolicy<M> Maj>
    float selection(const EstimatorOptions& opts, const Maj& majorant,
                    const typename M::Spectral::Wavelengths& lambda) const noexcept {
        const float count = opts.equiangular_count;
        if (!St::combines || !opts.adaptive_equiangular || !(count > 0.f)) return count;
        float p = 0.f;
        for (int k = 0; k < sc_->lights.equiangular_count(); ++k)
            p = std::max(p, equiangular_probability<M>(majorant, ray_, sampler(k), lambda));
        return count * p;
    }

private:
    EquiangularSampler sampler(int k) const noexcept {
        return EquiangularSampler(ray_, sc_->lights.equiangular_point(k), t0_, t1_);
    }

    const Sc* sc_ = nullptr;
    Ray ray_{};
    float t0_ = 0.f, t1_ = 0.f;
};

/// Equiangular + NEE on one piece `ray` of a path segment in medium `index` (see the header): t
/// drawn from `eq`, the nulls on [0, t) ratio-tracked, t a real scattering vertex at path depth
/// `depth` with NEE from it. `select` is the probability with which the piece draws the vertex at
/// all (its density is select x the mixture's). Returns a failed flight's status.
template <class State, class Sc, UniformRng R, LookupCounter C>
Status equiangular_nee(const State& st, const Sc& sc, int index, const Ray& ray, const PieceEquiangular<Sc>& eq,
                       float select, int depth, const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                       typename Sc::Spectrum& L) {
    using St = typename State::Strategy;
    const auto& m = sc.media[std::size_t(index)];
    const float u_pick = rng.uniform(), u = rng.uniform();
    DistanceSample ds = eq.sample(u_pick, u);
    ds.pdf *= select;
    if (!(ds.pdf > 0.f)) return Status::Ok;
    const auto piece = st.shadow_piece(m.medium, m.majorant, ray, ds.t, st.walk_weights(), St::combines, lambda, rng,
                                       counter);
    if (piece.status != Status::Ok) return piece.status;
    if (!(piece.f != 0.f).any()) return Status::Ok;
    const auto v = detail::lookup_untracked(m.medium, m.majorant, ray, ds.t, lambda, counter);
    if (!v) return Status::Rejected;
    const auto x = st.equiangular_vertex(piece, v->k, v->mu, ds.pdf, depth, v->ctl);
    if (!x) return Status::Ok;
    const SceneVertex xv{-1, index, {}};
    return light_nee(st, sc, xv, ray.at(ds.t), ray.d, *x, [&](const Vec3&) { return index; }, lambda, rng, counter, L);
}

}  // namespace nsp
