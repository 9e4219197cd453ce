// nsp/estimators/path.hpp: the path estimators (THEORY 4, 5.1-5.9): one path loop over a
// SurfaceScene (nsp::Scene, media in empty space, is one) for PathEstimator (the grey axis: one
// pdf for every channel) and SpectralPathEstimator (a channel policy: every channel's pdfs).
//
// Each segment is followed from surface to surface; in a medium it is delta-tracked up to the
// surface the host's geometry reports, a null interface (no BSDF, or one that passes through)
// switches the medium and the segment goes on, and a surface with a BSDF is a real vertex like a
// scattering one, with the BSDF where a medium vertex has the phase function. The techniques each
// run once, as kernels a host's loop can call too, and the path state (path_state.hpp) weighs
// what they find:
// - lights reached by tracking (surfaces naming a light, and the lights at infinity);
// - NEE toward the lights at every real vertex (nee.hpp), with its expected count;
// - equiangular + NEE on every piece in a medium (equiangular_vertex.hpp), for the equiangular
//   strategies;
// - in emissive media the collision estimator at every tentative collision, the segment
//   technique on every piece and NEE toward the volume (emission.hpp).
// The strategy's traits say which run and whether they combine (options.hpp).
#pragma once

#include <cmath>
#include <type_traits>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../geometry.hpp"
#include "../media/emissive.hpp"
#include "../mis.hpp"
#include "../options.hpp"
#include "../path_pdf.hpp"
#include "../path_state.hpp"
#include "../scene.hpp"
#include "../surface_scene.hpp"
#include "../vertex.hpp"
#include "emission.hpp"
#include "equiangular_vertex.hpp"
#include "nee.hpp"
#include "scene_walk.hpp"

namespace nsp {

namespace detail {

/// One path through SurfaceScene `sc` on channel axis Ch with the kernels `k` (strategy,
/// heuristic, absorption and options), from `camera_ray` (usable_ray), the sampling channel drawn
/// by `selection` where the axis has channels.
template <class Ch, class K, class Sc, UniformRng R, LookupCounter C>
RadianceSample<typename Sc::Spectral> trace_path(const K& k, const Sc& sc, const Ray& camera_ray,
                                                 const typename Sc::Spectral::Wavelengths& lambda,
                                                 const ChannelSelection<typename Sc::Spectral>* selection, R& rng,
                                                 C& counter) {
    using St = typename K::Strategy;
    using S = typename Sc::Spectral;
    using Spectrum = typename Sc::Spectrum;
    constexpr bool kEmissive = EmissiveMedium<typename Sc::MediumType>;
    // Per channel, the equiangular strategies and an emissive medium's segment technique keep
    // their pdfs in the state's second slot (the pdf of a piece's prefix with its nulls ratio-tracked).
    constexpr bool kEq = !is_grey_axis_v<Ch> && (St::equiangular || kEmissive);
    using State = PathState<Ch, St, typename K::Heuristic, typename K::Absorption, S, kEq>;
    using P = typename State::P;
    const EstimatorOptions& opts = k.options();
    State st(k, selection, rng);
    Spectrum L = Spectrum::Zero();
    Status status = Status::Ok;
    Ray ray = camera_ray;
    int medium = sc.camera_medium;
    st.prev = ray.o;
    int crossings = 0;
    // Media in empty space (Scene): its surface, a sphere light, lies outside every medium, so a
    // segment from a medium vertex leaves the medium's box before it can reach it. Such a segment
    // looks for the surface only where it passes its medium, not on every segment (NoSurfaces has
    // none to look for).
    constexpr bool kEmptySpace = is_empty_space_v<typename Sc::GeometryType>;
    constexpr bool kSphereLater = std::is_same_v<typename Sc::GeometryType, EmptySpace>;
    bool from_medium_vertex = false;
    for (int depth = 0;;) {
        SurfaceHit hit;  // t = kInf until the geometry is asked
        const bool surface_later = kSphereLater && from_medium_vertex;
        if (!surface_later) hit = sc.geometry.intersect(ray, kInf);
        // nsp's own empty space (Scene) reports only hits it built; a host's are checked.
        if constexpr (!kEmptySpace) {
            if (!usable_hit(sc, hit)) {
                status = Status::InvalidInput;
                break;
            }
            hit.keep_media(medium);
        }
        bool in_medium = false;
        float t_medium = 0.f;
        P eq_x{};                // the equiangular pdf of a medium vertex drawn on this piece (0: none)
        if constexpr (!is_grey_axis_v<Ch>) eq_x.setZero();
        bool eq_covers = false;  // the equiangular technique could have drawn it
        if (sc.has_medium(medium)) {
            const auto& m = sc.media[std::size_t(medium)];
            st.start_piece();
            // Equiangular: a real vertex on this piece aimed at the lights, and NEE from it.
            [[maybe_unused]] PieceEquiangular<Sc> eq;
            [[maybe_unused]] float eq_select = 1.f;  // the probability of drawing this piece's equiangular vertex
            if constexpr (St::equiangular) {
                const Interval in = m.medium.bounds().clip(ray, 0.f, hit.t);
                eq = PieceEquiangular<Sc>(sc, ray, in.t0, in.t1);
                if (eq.valid()) {
                    eq_select = eq.template selection<St, typename Sc::MediumType>(opts, m.majorant, lambda);
                    // At count 0 no number is drawn: the loop is uni + NEE MIS's, draw for draw.
                    if (depth < opts.max_depth && eq_select > 0.f && draw_technique(eq_select, rng)) {
                        const Status es =
                            equiangular_nee(st, sc, medium, ray, eq, eq_select, depth + 1, lambda, rng, counter, L);
                        if (es == Status::NonFinite) return {Spectrum::Zero(), es};  // an overflowed flight
                        if (es != Status::Ok) status = es;
                    }
                }
            }
            float t = 0.f;
            SegmentEnd end;
            if constexpr (kEmissive) {
                // The segment technique first; then the collision estimator where what the piece
                // reaches counts (THEORY 5.7).
                const float along = emission_segment(st, sc, medium, ray, hit.t, lambda, rng, counter, L, status);
                if (st.counts_hits()) {
                    const float select = St::samples_lights ? sc.emission_selection_pdf(medium) : 0.f;
                    end = st.track(m.medium, m.majorant, ray, hit.t, lambda, rng, counter,
                                   st.collector(m.medium, ray, lambda, L, counter, along, select), t);
                } else {
                    end = st.track(m.medium, m.majorant, ray, hit.t, lambda, rng, counter, NoVisit{}, t);
                }
            } else {
                end = st.track(m.medium, m.majorant, ray, hit.t, lambda, rng, counter, NoVisit{}, t);
            }
            if (const Status fs = flight_status(end); fs != Status::Ok) {
                status = fs;
                break;
            }
            if (end == SegmentEnd::Scattered) {
                in_medium = true;
                t_medium = t;
                if constexpr (St::equiangular) {
                    eq_covers = eq.valid() && eq_select > 0.f;  // at count 0 tracking's alone
                    // inf (grey) where the tracking pdf underflowed: equiangular then takes the weight
                    if (eq_covers) eq_x = st.vertex_eq(eq_select * eq.density(t));
                }
            } else if (end != SegmentEnd::Passed) {
                break;  // absorbed, or no pdf left
            }
            st.end_piece();
        }
        int material = -1;
        Vec3 x;
        if (in_medium) {
            x = ray.at(t_medium);
        } else {
            if (surface_later) hit = sc.geometry.intersect(ray, kInf);
            // An emitter reached: weighed against NEE from the last real vertex where it exists,
            // whose density on a surface light may read where (`at`: the hit; none at infinity).
            auto add_emitter = [&](int light, const Spectrum& le, const ShadingPoint* at) {
                float light_pdf = 0.f;
                if (st.nee_alternative())
                    light_pdf = at ? sc.lights.pdf(light, st.prev, ray.d, *at) : sc.lights.pdf(light, st.prev, ray.d);
                L += st.light_hit(le, light_pdf, counter);
            };
            if (!hit.found()) {  // the ray leaves the scene: the lights at infinity
                if (st.counts_hits())
                    for (const int i : sc.lights.infinite()) add_emitter(i, sc.lights.emitted(i, ray.d, lambda), nullptr);
                break;
            }
            if (hit.light >= 0 && st.counts_hits()) {
                const ShadingPoint at = hit.shading();
                add_emitter(hit.light, sc.lights.emitted(hit.light, at, ray.d, lambda), &at);
            }
            // A null interface, or a null lobe taken: no vertex, the segment goes on in the next medium.
            auto cross = [&] {
                if (++crossings > kMaxInterfaceCrossings) return false;
                medium = hit.medium_entered(ray.d);
                ray.o = hit.p;
                st.walked += hit.t;
                from_medium_vertex = false;
                return true;
            };
            if (crosses(sc, hit)) {
                if (cross()) continue;
                status = Status::InvalidInput;
                break;
            }
            if (hit.material < 0 || sc.materials.passes_through(hit.material))
                break;  // an emitter without a BSDF: what reaches it ends there
            if constexpr (has_null_lobes_v<Sc>) {
                // A partly null BSDF: its null lobe with its probability, else a real vertex.
                const NullLobe<S> lobe = null_lobe_at(sc, hit, ray.d, lambda);
                if (!usable_null_lobe(lobe)) {
                    status = Status::InvalidInput;
                    break;
                }
                if (lobe.probability > 0.f) {
                    const bool pass = rng.uniform() < lobe.probability;
                    if (const StateScale r = st.choose_lobe(pass, lobe); r != StateScale::Ok) {
                        if (r == StateScale::Overflowed) status = Status::NonFinite;
                        break;
                    }
                    if (pass) {
                        if (cross()) continue;
                        status = Status::InvalidInput;
                        break;
                    }
                }
            }
            material = hit.material;
            x = hit.p;
        }
        if (++depth > opts.max_depth) break;
        // Roulette survival is fixed before NEE: the continuing unidirectional path carries it.
        const float q = st.survival(depth);
        const SceneVertex v{material, medium, hit.shading()};
        if constexpr (St::samples_lights) {
            auto side = [&](const Vec3& wi) { return v.on_surface() ? hit.medium_entered(wi) : medium; };
            // Equiangular + NEE alone leaves the lights of a vertex its own vertices cover to them.
            // NEE at the expected count EstimatorOptions::nee_count (THEORY 5.9).
            if ((St::combines || !St::equiangular || !eq_covers) && st.draw_nee(rng)) {
                const Status ns = light_nee(st, sc, v, x, ray.d, st.vertex(q, eq_x), side, lambda, rng, counter, L);
                if (ns == Status::NonFinite) return {Spectrum::Zero(), ns};  // an overflowed flight
                if (ns != Status::Ok) status = ns;
            }
            if constexpr (kEmissive) {
                if (!(v.on_surface() && sc.materials.is_delta(material))) {
                    const Status es = volume_nee(st, sc, v, x, ray.d, st.vertex(q, eq_x), side, lambda, rng, counter, L);
                    if (es == Status::NonFinite) return {Spectrum::Zero(), es};
                    if (es != Status::Ok) status = es;
                }
            }
        }
        if (!st.roulette(q, rng)) break;
        const auto next = sample_vertex(sc, v, ray.d, rng, lambda);
        if (!(next.pdf > 0.f)) break;
        if (v.on_surface()) medium = hit.medium_entered(next.wi);
        if (const StateScale r = st.scatter(next, q, eq_x, x); r != StateScale::Ok) {
            if (r == StateScale::Overflowed) status = Status::NonFinite;
            break;
        }
        crossings = 0;
        from_medium_vertex = in_medium;
        ray = Ray{x, next.wi};
    }
    // A flight or path state that overflowed (NonFinite) had a value beyond float's range: the
    // whole estimate is replaced by 0, as a non-finite sum would be.
    if (status == Status::NonFinite || !all_finite(L)) return {Spectrum::Zero(), Status::NonFinite};
    return {L, status};
}

/// Whether kernels k refuse scene sc: NEE at count 0 leaves the lights no path can hit unreached
/// (EstimatorOptions::nee_count). Checked before trace_path, outside its loop.
template <class K, class Sc>
bool refuses_nee_count(const K& k, const Sc& sc) noexcept {
    return K::Strategy::samples_lights && k.options().nee_count == 0.f && sc.lights.has_delta_lights();
}

}  // namespace detail

/// A path estimator with one pdf for every channel: strategy St, MIS heuristic H (mis::None
/// exactly for single-strategy estimators) and absorption policy A for the delta-tracked segments.
/// Exact for Mono and grey media; on chromatic media the per-channel weights multiply along a path,
/// which is what SpectralPathEstimator is for.
template <PathStrategy St, mis::Heuristic H = mis::None, AbsorptionPolicy A = absorption::Weight>
class PathEstimator {
    static_assert(St::combines || !H::combines,
                  "nsp::PathEstimator: a single-strategy estimator (Unidirectional, NextEvent) "
                  "takes mis::None; a heuristic would weigh a strategy against nothing");
    static_assert(!St::combines || H::combines,
                  "nsp::PathEstimator: DirectionalMis and NullScatteringMis combine two strategies "
                  "and need a combining heuristic (mis::Balance or mis::Power), not mis::None");

public:
    using Strategy = St;
    using HeuristicType = H;
    using Absorption = A;

    /// Throws InvalidArgument on max_depth < 0, rr_start_depth < 1 or rr_max_survival outside (0, 1].
    explicit PathEstimator(EstimatorOptions opts = {}, H heuristic = H{}) : kernels_(opts, heuristic) {}

    const EstimatorOptions& options() const noexcept { return kernels_.options(); }

    /// An estimate of the radiance arriving at `ray.o` from direction -ray.d in a SurfaceScene
    /// (the host's surfaces, media and lights) or a Scene (media in empty space). A camera ray
    /// that is not usable_ray (a non-finite origin, a direction that is not unit length) gives 0
    /// and Status::InvalidInput. Never throws.
    template <class Sc, UniformRng R, LookupCounter C>
    RadianceSample<typename Sc::Spectral> radiance(const Sc& scene, const Ray& camera_ray,
                                                   const typename Sc::Spectral::Wavelengths& lambda,
                                                   R& rng, C& counter) const {
        static_assert(is_surface_scene_v<Sc>, "nsp::PathEstimator renders a SurfaceScene or a Scene");
        static_assert(!is_per_channel_majorant_v<typename Sc::MajorantType, typename Sc::MediumType>,
                      "nsp::PathEstimator drives every channel with one pdf and needs a grey majorant "
                      "(GlobalMajorant or GridMajorant); per-channel majorants go with nsp::SpectralPathEstimator");
        if (!usable_ray(camera_ray) || detail::refuses_nee_count(kernels_, scene))
            return {Sc::Spectrum::Zero(), Status::InvalidInput};
        detail::record_nee_count_may_be_0(counter, !scene.lights.has_delta_lights());
        return detail::trace_path<channels::Grey>(kernels_, scene, camera_ray, lambda, nullptr, rng, counter);
    }

private:
    VertexKernels<St, H, A> kernels_;
};

/// A path estimator over channels (THEORY 5.3): channel policy CP, strategy St (Unidirectional,
/// NextEvent, NullScatteringMis, EquiangularNextEvent or EquiangularMis), heuristic H (mis::None
/// for a single strategy, mis::Balance for the combining ones: the weights are the one-sample
/// balance heuristic over channels and techniques) and absorption policy A. Each path picks a
/// sampling channel with probabilities q (ChannelSelection), tracks every segment with its
/// majorant and keeps every channel's contribution and pdfs, so one formula weighs every technique:
///
///     estimate_lambda = f_lambda / sum_c q_c (p_uni,c + n p_nee,c [+ p_eq,c] ...).
template <ChannelPolicy CP, PathStrategy St, mis::Heuristic H = mis::None, AbsorptionPolicy A = absorption::Weight>
class SpectralPathEstimator {
    static_assert(St::null_pdfs || !St::combines,
                  "nsp::SpectralPathEstimator: DirectionalMis weighs by direction pdfs alone and has no "
                  "per-channel path pdfs to combine; use strategy::NullScatteringMis");
    static_assert(St::combines || !H::combines,
                  "nsp::SpectralPathEstimator: a single-strategy estimator (Unidirectional, NextEvent) "
                  "takes mis::None; a heuristic would weigh a strategy against nothing");
    static_assert(!St::combines || std::is_same_v<H, mis::Balance>,
                  "nsp::SpectralPathEstimator: NullScatteringMis over channels is the one-sample balance "
                  "heuristic (THEORY 5.3); pass mis::Balance");

public:
    using Channels = CP;
    using Strategy = St;
    using HeuristicType = H;
    using Absorption = A;

    /// Throws InvalidArgument on the option values PathEstimator rejects, and on
    /// shadow_estimator = RayMarching (its shadow rays track every channel's pdfs).
    explicit SpectralPathEstimator(EstimatorOptions opts = {}) : kernels_(refuse_marching(opts)) {}

    const EstimatorOptions& options() const noexcept { return kernels_.options(); }

    /// An estimate of the radiance arriving at `ray.o` from -ray.d, every channel, with the
    /// sampling channel chosen uniformly. A camera ray that is not usable_ray gives 0 and
    /// Status::InvalidInput. Never throws.
    template <class Sc, UniformRng R, LookupCounter C>
    RadianceSample<typename Sc::Spectral> radiance(const Sc& scene, const Ray& camera_ray,
                                                   const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                   C& counter) const {
        return radiance(scene, camera_ray, lambda, ChannelSelection<typename Sc::Spectral>{}, rng, counter);
    }

    /// As above, with the sampling channel chosen with probabilities `selection`.
    template <class Sc, UniformRng R, LookupCounter C>
    RadianceSample<typename Sc::Spectral> radiance(const Sc& scene, const Ray& camera_ray,
                                                   const typename Sc::Spectral::Wavelengths& lambda,
                                                   const ChannelSelection<typename Sc::Spectral>& selection, R& rng,
                                                   C& counter) const {
        static_assert(is_surface_scene_v<Sc>, "nsp::SpectralPathEstimator renders a SurfaceScene or a Scene");
        static_assert(CP::own_pdfs || !is_per_channel_majorant_v<typename Sc::MajorantType, typename Sc::MediumType>,
                      "nsp::SpectralPathEstimator: spectral tracking shares one pdf over channels and needs a "
                      "grey majorant bounding every channel (GlobalMajorant)");
        if (!usable_ray(camera_ray) || detail::refuses_nee_count(kernels_, scene))
            return {Sc::Spectrum::Zero(), Status::InvalidInput};
        detail::record_nee_count_may_be_0(counter, !scene.lights.has_delta_lights());
        return detail::trace_path<CP>(kernels_, scene, camera_ray, lambda, &selection, rng, counter);
    }

private:
    static EstimatorOptions refuse_marching(const EstimatorOptions& o) {
        if (o.shadow_estimator != ShadowEstimator::RatioTracking)
            detail::fail("EstimatorOptions shadow_estimator = RayMarching is not allowed with "
                         "nsp::SpectralPathEstimator: its shadow rays track every channel's pdfs (nsp::PathEstimator "
                         "with ratio-nee, directional-mis or equiangular-nee takes it)");
        return o;
    }

    VertexKernels<St, H, A> kernels_;
};

}  // namespace nsp
