// nsp/estimators/scene_walk.hpp: a path's way through a SurfaceScene (THEORY 5.8): which host
// hits nsp can use, which surfaces a path crosses without a vertex (null interfaces), a real
// vertex's direction value, pdf and sample (BSDF or phase function), and the one shadow walk: a
// ray followed from surface to surface toward a light or a point in a medium, each medium on its
// way ratio-tracked by the path state's tracker (grey or per channel), the pieces' factors
// multiplied. Every estimator's shadow rays, connections and emission NEE walk this way.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../geometry.hpp"
#include "../media/emissive.hpp"
#include "../path_state.hpp"
#include "../pdf.hpp"
#include "../surface_scene.hpp"
#include "../tracking.hpp"

namespace nsp::detail {

/// More null interfaces on one segment than this (a host's geometry that reports the same
/// boundary again and again) stops the path with Status::InvalidInput.
inline constexpr int kMaxInterfaceCrossings = 256;

/// Whether a hit from the host's geometry is one the estimator can use: a distance that is not
/// NaN or negative, and where something was found a finite point, unit normals, handles inside
/// the scene's tables (a medium, -1 or kSameMedium on each side) and, where a BSDF or light of
/// the scene reads them (sees_hits), a finite tangent and uv.
template <class Sc>
bool usable_hit(const Sc& sc, const SurfaceHit& h) noexcept {
    if (std::isnan(h.t) || h.t < 0.f) return false;
    if (!h.found()) return true;
    if (!finite(h.p) || !unit_length(h.ng) || !unit_length(h.ns)) return false;
    if constexpr (Sc::sees_hits)
        if (!finite(h.dpdu) || !std::isfinite(h.uv.x) || !std::isfinite(h.uv.y)) return false;
    if (h.material != -1 && !sc.materials.contains(h.material)) return false;
    if (h.light != -1 && !(h.light >= 0 && h.light < sc.lights.count())) return false;
    auto medium_ok = [&](int m) { return m == -1 || m == kSameMedium || sc.has_medium(m); };
    return medium_ok(h.medium_front) && medium_ok(h.medium_back);
}

/// Whether a path crosses the surface of `h` without a vertex: no light there, and no BSDF or
/// one that passes through (a null interface).
template <class Sc>
bool crosses(const Sc& sc, const SurfaceHit& h) noexcept {
    return h.light < 0 && (h.material < 0 || sc.materials.passes_through(h.material));
}

/// Whether SurfaceScene Sc has a partly null BSDF (only then does a hit draw its null lobe).
template <class Sc>
inline constexpr bool has_null_lobes_v = std::remove_cvref_t<decltype(std::declval<const Sc&>().materials)>::has_null_lobes;

/// The null lobe a path arriving along wo meets at h (probability 0: none, or no BSDF there).
template <class Sc>
NullLobe<typename Sc::Spectral> null_lobe_at(const Sc& sc, const SurfaceHit& h, const Vec3& wo,
                                             const typename Sc::Spectral::Wavelengths& lambda) noexcept {
    if (h.material < 0) return {};
    return sc.materials.null_lobe(h.material, h.shading(), wo, lambda);
}

/// Whether a null lobe keeps PartlyNullBsdf's rules: a probability in [0, 1], finite weights >= 0,
/// and none where the probability is 0.
template <class S>
bool usable_null_lobe(const NullLobe<S>& l) noexcept {
    if (!(l.probability >= 0.f && l.probability <= 1.f)) return false;
    if (!l.weight.allFinite() || (l.weight < 0.f).any()) return false;
    return l.probability > 0.f || (l.weight == 0.f).all();
}

}  // namespace nsp::detail

namespace nsp {

/// A real vertex of a path through a SurfaceScene: on a surface (material >= 0, what its BSDF sees
/// of the hit in `shading`, SurfaceHit::shading()) or in medium `medium` (material -1; `shading`
/// unread). What the estimators ask of it: the value and pdf of a direction (NEE), and a sampled
/// direction (the path's continuation).
struct SceneVertex {
    int material = -1;
    int medium = -1;
    ShadingPoint shading{};
    bool on_surface() const noexcept { return material >= 0; }
};

/// A direction's throughput factor at a vertex (BSDF f_s |n . wi| or phase f_p) and its pdf.
template <SpectralMode S>
struct VertexDirection {
    Vec3 wi{0.f, 0.f, 1.f};
    typename S::Spectrum value = S::Spectrum::Zero();
    float pdf = 0.f;
    bool delta = false;
};

/// The value and pdf of direction wi at vertex v for a path that arrived along wo.
template <class Sc>
[[gnu::always_inline]] inline VertexDirection<typename Sc::Spectral> eval_vertex(
    const Sc& sc, const SceneVertex& v, const Vec3& wo, const Vec3& wi,
    const typename Sc::Spectral::Wavelengths& lambda) noexcept {
    VertexDirection<typename Sc::Spectral> out;
    out.wi = wi;
    if (v.on_surface()) {
        sc.materials.visit(v.material, [&](const auto& b) {
            using S = typename Sc::Spectral;
            out.value = detail::eval_bsdf<S>(b, v.shading, wo, wi, lambda);
            out.pdf = detail::bsdf_pdf<S>(b, v.shading, wo, wi);
        });
    } else {
        const auto& phase = sc.media[std::size_t(v.medium)].phase;
        out.value = Sc::Spectrum::Constant(phase.eval(wo, wi));
        out.pdf = phase.pdf(wo, wi);
    }
    return out;
}

/// The next direction at vertex v: the BSDF's or the phase function's sample from two uniforms
/// drawn from rng, and a third for a shading BSDF (ShadingBsdf); pdf 0 when there is none.
template <class Sc, UniformRng R>
[[gnu::always_inline]] inline VertexDirection<typename Sc::Spectral> sample_vertex(
    const Sc& sc, const SceneVertex& v, const Vec3& wo, R& rng,
    const typename Sc::Spectral::Wavelengths& lambda) noexcept {
    VertexDirection<typename Sc::Spectral> out;
    const float u1 = rng.uniform(), u2 = rng.uniform();
    if (v.on_surface()) {
        sc.materials.visit(v.material, [&](const auto& b) {
            const BsdfSample<typename Sc::Spectral> bs =
                detail::sample_bsdf<typename Sc::Spectral>(b, v.shading, wo, u1, u2, rng, lambda);
            out = {bs.wi, bs.value, bs.pdf, bs.delta};
        });
    } else {
        const PhaseSample ps = sc.media[std::size_t(v.medium)].phase.sample(wo, u1, u2);
        out = {ps.wi, Sc::Spectrum::Constant(ps.value), ps.pdf, false};
    }
    return out;
}

}  // namespace nsp

namespace nsp::detail {

/// What tracking would see at a vertex it did not draw itself (an equiangular or emission point).
template <Medium M, class Maj>
struct UntrackedVertex {
    Coefficients<typename M::Spectral> k;  ///< the lookup, clamped to the majorant under bound::Clamp
    MajorantValue<Maj, M> mu;              ///< the majorant there (grey or per channel)
    /// Under a control, the control there as free_flight takes it: grey (the smallest channel's), or
    /// every channel's own under a per-channel majorant (ChannelGridControl); else 0.
    std::conditional_t<is_control_v<Maj, M> && is_per_channel_majorant_v<Maj, M>, typename M::Spectral::Spectrum,
                       float>
        ctl{};
};

/// Path state st's piece of a shadow walk through medium m of SurfaceScene sc (State::shadow_piece
/// with the walk's weights f and whether tracking's null pdfs are wanted, `uni`).
template <class State, class Sc, UniformRng R, LookupCounter C>
auto state_shadow_piece(const State& st, const Sc& sc, int m, const Ray& r, float t_max,
                        const typename Sc::Spectrum& f, bool uni, const typename Sc::Spectral::Wavelengths& lambda,
                        R& rng, C& counter) {
    const auto& med = sc.media[std::size_t(m)];
    return st.shadow_piece(med.medium, med.majorant, r, t_max, f, uni, lambda, rng, counter);
}

/// An UntrackedVertex of SurfaceScene Sc's media.
template <class Sc>
using SceneUntracked = UntrackedVertex<typename Sc::MediumType, typename Sc::MajorantType>;

/// One density lookup (counted) at distance t on `ray` with the majorant there, treated as
/// free_flight treats its lookups: clamped under bound::Clamp; std::nullopt under bound::Reject
/// where mu_t exceeds mu_bar (the estimator reports Status::Rejected).
template <Medium M, MajorantPolicy<M> Maj, LookupCounter C>
std::optional<UntrackedVertex<M, Maj>> lookup_untracked(const M& medium, const Maj& majorant, const Ray& ray, float t,
                                                        const typename M::Spectral::Wavelengths& lambda, C& counter) {
    using B = bound_policy_t<Maj>;
    counter.lookup();
    UntrackedVertex<M, Maj> v{medium.coefficients(ray.at(t), lambda), majorant_value_at_point<M>(majorant, ray, t, lambda)};
    if constexpr (requires { majorant.control_value_at(ray.at(t), lambda); }) {
        if constexpr (is_per_channel_majorant_v<Maj, M>) v.ctl = channel_controls(majorant.control_value_at(ray.at(t), lambda), v.mu);
        else v.ctl = grey_control(majorant.control_value_at(ray.at(t), lambda), float(v.mu));
    }
    if constexpr (std::is_same_v<B, bound::Clamp>) {
        clamp_to_majorant(v.k, v.mu);
    } else if constexpr (std::is_same_v<B, bound::Reject>) {
        if (exceeds_majorant(v.k, v.mu)) return std::nullopt;
    }
    return v;
}

/// The part of a shadow ray's length near its end where a walk toward a light does not look for
/// blockers: 1e-4 of it, so that the surface or light the ray ends on does not block it (0 for
/// lights at infinity). The media are tracked over the whole length all the same.
inline float shadow_margin(float distance) noexcept { return std::isfinite(distance) ? distance * 1e-4f : 0.f; }

namespace walk_detail {
template <class P>
P unit() noexcept {
    if constexpr (std::is_same_v<P, float>) return 1.f;
    else return P::Ones();
}
template <class P>
float largest(const P& p) noexcept {
    if constexpr (std::is_same_v<P, float>) return p;
    else return p.maxCoeff();
}
}  // namespace walk_detail

}  // namespace nsp::detail

namespace nsp {

/// Walks the shadow ray r from a point in medium `medium` to `end`: from surface to surface
/// (the host's intersect), crossing null interfaces, each medium on the way tracked by
/// `piece(medium_index, ray, t_max, f_so_far)` (a ShadowPiece), the pieces' factors multiplied and
/// renormalised by one common factor (it cancels in every ratio the callers form). Blocked (not
/// reached, f = 0, status Ok) where a surface that is not a null interface lies before the end
/// (found before the piece up to it is tracked), a piece's estimate fell below float's range, or
/// (`end.target`) the end lies in another medium; a failed flight's status, or InvalidInput for a
/// hit the estimators cannot use.
template <class P, class Sc, class Piece>
[[gnu::always_inline]] inline ShadowWalk<P, typename Sc::Spectral> walk_shadow(
    const Sc& sc, Ray r, int medium, const WalkEnd& end, const typename Sc::Spectral::Wavelengths& lambda,
    Piece&& piece) {
    using S = typename Sc::Spectral;
    using Spec = typename S::Spectrum;
    ShadowWalk<P, S> out;
    auto fail = [](Status s) {
        ShadowWalk<P, S> b;
        b.status = s;
        return b;
    };
    Spec f = Spec::Ones();
    P nee = detail::walk_detail::unit<P>(), uni = detail::walk_detail::unit<P>(), seg = detail::walk_detail::unit<P>();
    float distance = end.distance;
    const float margin = end.margin ? detail::shadow_margin(distance) : 0.f;
    // Multiplies in the piece of medium `medium` up to t_max (the last one: up to the end); false
    // where the walk is blocked or failed (`out` then holds what to return).
    auto take_piece = [&](const Ray& ray, float t_max, bool last) {
        if (!sc.has_medium(medium)) return true;
        const ShadowPiece<P, S> s = piece(medium, ray, t_max, f);
        if (s.status != Status::Ok || !(s.f != 0.f).any()) {
            out = fail(s.status);
            return false;
        }
        if (last) {
            seg = uni * s.nee;
            out.uni_last = s.uni;
        }
        f *= s.f;
        nee *= s.nee;
        uni *= s.uni;
        // One common factor keeps many pieces inside float's range; it cancels.
        const float k = std::max(detail::walk_detail::largest(nee), detail::walk_detail::largest(uni));
        if (k > 0.f && std::isfinite(k) && k != 1.f) {
            f /= k;
            nee /= k;
            uni /= k;
            if (last) seg /= k;
        }
        if (!(f != 0.f).any()) {
            out = fail(Status::Ok);
            return false;
        }
        return true;
    };
    // The walk reached the end at `distance` along `ray`; `beyond` is the next surface's distance.
    auto reached = [&](const Ray& ray, float beyond) {
        if (end.target != -2 && medium != end.target) return fail(Status::Ok);
        out.reached = true;
        out.f = f;
        out.nee = nee;
        out.uni = uni;
        out.seg = seg;
        out.last = ray;
        out.t_last = distance;
        out.end_medium = medium;
        if constexpr (EmissiveMedium<typename Sc::MediumType>)
            if (end.with_along && sc.has_medium(medium))
                out.along = sc.media[std::size_t(medium)].medium.emission_along(ray, 0.f, beyond);
        return out;
    };
    if constexpr (is_empty_space_v<typename Sc::GeometryType>) {
        // nsp's own empty space (Scene, NoSurfaces): no interface to cross; a surface before the
        // end (Scene's sphere light) blocks. One piece, no hit records to check. A point sampled
        // on the sphere light's visible cap is not blocked by it (the medium, where every walk
        // starts, lies outside the sphere; Scene checks), so that walk needs no test.
        float t = kInf;
        if (end.with_along || !sc.geometry.ends_on(end.light))
            t = sc.geometry.distance(r, end.with_along ? kInf : distance - margin);
        if (t < distance - margin) return fail(Status::Ok);
        (void)lambda;
        if (!take_piece(r, distance, true)) return out;
        return reached(r, t);
    } else {
        for (int crossing = 0; crossing <= detail::kMaxInterfaceCrossings; ++crossing) {
            SurfaceHit h = sc.geometry.intersect(r, end.with_along ? kInf : distance - margin);
            if (!detail::usable_hit(sc, h)) return fail(Status::InvalidInput);
            h.keep_media(medium);
            const bool last = !h.found() || h.t >= distance - margin;
            // A surface before the end blocks the ray unless it is a null interface or has a null
            // lobe, which passes its weight (in the unidirectional pdf: its probability).
            NullLobe<S> lobe;
            if constexpr (detail::has_null_lobes_v<Sc>) {
                if (!last && !detail::crosses(sc, h)) {
                    lobe = detail::null_lobe_at(sc, h, r.d, lambda);
                    if (!detail::usable_null_lobe(lobe)) return fail(Status::InvalidInput);
                }
            }
            if (!last && !detail::crosses(sc, h) && !(lobe.probability > 0.f)) return fail(Status::Ok);
            if (!take_piece(r, last ? distance : h.t, last)) return out;
            if (last) return reached(r, h.t);
            if (lobe.probability > 0.f) {
                f *= lobe.weight;
                uni *= lobe.probability;
                if (!(f != 0.f).any()) return fail(Status::Ok);
            }
            medium = h.medium_entered(r.d);
            r.o = h.p;
            distance -= h.t;
        }
    }
    return fail(Status::InvalidInput);
}

}  // namespace nsp
