// nsp/estimators/spectral.hpp: path estimators over channels (THEORY 5.1, 5.3, 5.6).
//
// `SpectralPathEstimator<CP, St, H, A>` composes a channel policy CP (independent tracking,
// spectral tracking, spectral MIS; path_pdf.hpp) with a path strategy St (unidirectional, NEE, or
// both combined by null-scattering MIS; estimators/common.hpp), its heuristic H and an absorption
// policy A. Each path picks a
// sampling channel c* with probabilities q (ChannelSelection), tracks every segment with c*'s
// majorant and keeps every channel's contribution and pdf in a ChannelPathState, so one formula
// weighs the 2 x C techniques of spectral MIS + NEE:
//
//     estimate_lambda = f_lambda / sum_c q_c (p_uni,c + p_nee,c),
//
// and the 3 x C of spectral MIS + NEE + equiangular sampling (strategy::EquiangularMis,
// THEORY 5.4): a real vertex drawn toward the point light, its nulls ratio-tracked with c*'s
// majorant, every channel's tracking and equiangular pdf of it in the same sum.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <type_traits>

#include "../channel_tracking.hpp"
#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../equiangular.hpp"
#include "../media/emissive.hpp"
#include "../mis.hpp"
#include "../path_pdf.hpp"
#include "../pdf.hpp"
#include "../scene.hpp"
#include "../surface_scene.hpp"
#include "common.hpp"
#include "spectral_surface_path.hpp"

namespace nsp {

/// A path estimator over channels: channel policy CP, strategy St (Unidirectional, NextEvent,
/// NullScatteringMis, EquiangularNextEvent or EquiangularMis), heuristic H (mis::None for a single
/// strategy, mis::Balance for the combining ones: the weights are the one-sample balance heuristic
/// over channels and techniques) and absorption policy A. An emissive medium adds emission as
/// PathEstimator does (collisions where the strategy counts hits, NEE toward the volume where it
/// samples lights, the segment technique where it combines), every channel's pdfs of all of them
/// in the same sum.
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

    /// Throws InvalidArgument on the option values PathEstimator rejects.
    explicit SpectralPathEstimator(EstimatorOptions opts = {}) : opts_(opts) { validate(opts); }

    const EstimatorOptions& options() const noexcept { return opts_; }

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
        using M = typename Sc::MediumType;
        using Maj = typename Sc::MajorantType;
        static_assert(CP::own_pdfs || !is_per_channel_majorant_v<Maj, M>,
                      "nsp::SpectralPathEstimator: spectral tracking shares one pdf over channels and needs a "
                      "grey majorant bounding every channel (GlobalMajorant)");
        if (!usable_ray(camera_ray)) return {Sc::Spectrum::Zero(), Status::InvalidInput};
        if constexpr (is_surface_scene_v<Sc>)
            return detail::spectral_surface_radiance<CP, St, A>(opts_, scene, camera_ray, lambda, selection, rng, counter);
        else
            return media_radiance(scene, camera_ray, lambda, selection, rng, counter);
    }

private:
    /// One path through a Scene: one medium in empty space under Lights<S>.
    template <class Sc, UniformRng R, LookupCounter C>
    RadianceSample<typename Sc::Spectral> media_radiance(const Sc& scene, const Ray& camera_ray,
                                                         const typename Sc::Spectral::Wavelengths& lambda,
                                                         const ChannelSelection<typename Sc::Spectral>& selection, R& rng,
                                                         C& counter) const {
        using M = typename Sc::MediumType;
        using Spectrum = typename Sc::Spectrum;
        const Spectrum& q = selection.probabilities();
        const int c = selection.sample(rng.uniform());
        ChannelPathState<typename Sc::Spectral, St::equiangular> st;
        Spectrum L = Spectrum::Zero();
        Status status = Status::Ok;
        Ray ray = camera_ray;
        Vec3 prev_x(0.f);  // the real vertex the current ray left from
        float dir_pdf = 1.f;  // rr p_w of the current ray's direction (1 for the camera ray)
        bool from_camera = true;
        std::optional<Vec3> target;
        if constexpr (St::equiangular) target = scene.lights.equiangular_target();

        for (int depth = 0;;) {
            const LightHit hit = scene.lights.intersect(ray);
            const bool nee_alternative = St::combines && !from_camera;
            // Equiangular: a real vertex on this segment aimed at the light, NEE from it; and the
            // equiangular pdf of the vertex tracking is about to draw starts from the same prefix.
            EquiangularSampler eq;
            float eq_select = 1.f;  // the probability of drawing this segment's equiangular vertex
            if constexpr (St::equiangular) {
                st.eq.vertex = st.uni;
                if (target) {
                    const Interval in = scene.medium.bounds().clip(ray, 0.f, hit.t);
                    eq = EquiangularSampler(ray, *target, in.t0, in.t1);
                    eq_select = equiangular_selection<St>(opts_, scene, ray, eq, lambda);
                    if (depth < opts_.max_depth && draw_technique(eq_select, rng)) {
                        const Status es =
                            equiangular_vertex(scene, ray, eq, eq_select, depth + 1, lambda, q, c, st, rng, counter, L);
                        if (es == Status::NonFinite) return {Spectrum::Zero(), es};  // an overflowed flight: see below
                        if (es != Status::Ok) status = es;
                    }
                }
            }
            ChannelTrack seg;
            if constexpr (EmissiveMedium<M>) {
                // The segment technique (THEORY 5.7): a point drawn on this segment in proportion to
                // the power grid along it (`along`: its normaliser; 0 where it does not run). Its
                // nulls are ratio-tracked: their pdfs are st.nee's, so the tracker keeps st.nee on
                // the camera ray too, from the prefix without the direction (dir_pdf apart).
                float along = 0.f;
                if constexpr (St::combines) {
                    if (opts_.emission_along_segments) {
                        along = scene.medium.emission_along(ray, 0.f, hit.t);
                        if (along > 0.f) {
                            if (from_camera) st.nee = st.uni;
                            // With the expected count EstimatorOptions::emission_segment_count (THEORY 5.9).
                            if (draw_technique(opts_.emission_segment_count, rng)) {
                                const double before = detail::recorder_work(counter);
                                const Status es = emission_segment(scene, ray, hit.t, along, nee_alternative, dir_pdf,
                                                                   lambda, q, c, st, rng, counter, L);
                                detail::record_segment_walk(counter, before);
                                if (es == Status::NonFinite) return {Spectrum::Zero(), es};  // an overflowed flight: see below
                                if (es != Status::Ok) status = es;
                            }
                        }
                    }
                }
                if (from_camera || St::hits_lights)
                    seg = track_channels_delta_visiting<CP, A>(
                        scene.medium, scene.majorant, ray, hit.t, lambda, c, st, nee_alternative || along > 0.f, rng,
                        counter, EmissionCollector<Sc, C>{scene, ray, lambda, q, c, L, opts_, counter,
                                                                    nee_alternative, along, dir_pdf});
                else
                    seg = track_channels_delta<CP, A>(scene.medium, scene.majorant, ray, hit.t, lambda, c, st,
                                                      nee_alternative, rng, counter);
            } else {
                seg = track_channels_delta<CP, A>(scene.medium, scene.majorant, ray, hit.t, lambda, c, st,
                                                  nee_alternative, rng, counter);
            }
            if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
                status = fs;
                break;
            }
            if (seg.end == SegmentEnd::Passed) {
                if (from_camera || St::hits_lights) {
                    // NEE's pdf with its expected count (THEORY 5.9; equiangular + NEE has count 1)
                    const float n = opts_.nee_count;
                    Spectrum pdf = st.uni;
                    const Spectrum le = scene.lights.emitted(hit, lambda);
                    if (nee_alternative) {
                        const float p_light = scene.lights.pdf(prev_x, hit);
                        Spectrum other = Spectrum::Zero();
                        if constexpr (St::equiangular) other = p_light * st.eq.nee;
                        pdf += n * p_light * st.nee + other;
                        record_channels<CP>(counter, Spectrum(st.f * le), st.uni, Spectrum(p_light * st.nee), other, q, c,
                                            n, LightTechnique::Hit);
                    }
                    L += channel_estimate<CP>(st.f, pdf, q, c) * le;
                }
                break;
            }
            if (seg.end != SegmentEnd::Scattered) break;  // absorbed, or no pdf left
            if (++depth > opts_.max_depth) break;

            const Vec3 x = ray.at(seg.t);
            // Every channel's equiangular pdf of x (same prefix and normaliser as st.uni).
            Spectrum eq_pdf = Spectrum::Zero();
            if constexpr (St::equiangular)
                if (target) eq_pdf = st.eq.vertex * (eq_select * eq.pdf(seg.t));
            // Roulette survival is fixed before NEE: the continuing unidirectional path carries it.
            // It follows what the path would contribute per unit of incident light, the largest
            // channel estimate, as PathEstimator's max |beta| does.
            float rr = 1.f;
            if (opts_.russian_roulette && depth >= opts_.rr_start_depth)
                rr = std::min(opts_.rr_max_survival, channel_estimate<CP>(st.f, st.uni, q, c).abs().maxCoeff());
            if constexpr (St::samples_lights) {
                // Equiangular + NEE alone leaves the lights to its own vertices when it has a target.
                // NEE at the expected count EstimatorOptions::nee_count (THEORY 5.9).
                if ((St::combines || !St::equiangular || !target) && draw_technique(opts_.nee_count, rng)) {
                    const Status ns =
                        next_event(scene, x, ray.d, rr, lambda, q, c, st.f, st.uni, eq_pdf, false, rng, counter, L);
                    if (ns == Status::NonFinite) return {Spectrum::Zero(), ns};  // an overflowed flight: see below
                    if (ns != Status::Ok) status = ns;
                }
                if constexpr (EmissiveMedium<M>) {
                    const Status es = emission_event(scene, x, ray.d, rr, lambda, q, c, st, rng, counter, L);
                    if (es == Status::NonFinite) return {Spectrum::Zero(), es};  // an overflowed flight: see below
                    if (es != Status::Ok) status = es;
                }
            }
            if (rr < 1.f && !(rng.uniform() < rr)) break;
            const float u1 = rng.uniform(), u2 = rng.uniform();
            const PhaseSample ps = scene.phase.sample(ray.d, u1, u2);
            if (!(ps.pdf > 0.f)) break;
            // The NEE alternative of the next segment starts from the prefix, without roulette
            // (with equiangular sampling also from the equiangular pdf of x, kept apart because
            // NEE toward emission is done from tracked vertices only).
            if constexpr (St::combines) {
                st.nee = st.uni;
                if constexpr (St::equiangular) st.eq.nee = eq_pdf;
            }
            st.f *= ps.value;
            dir_pdf = rr * ps.pdf;
            st.uni *= dir_pdf;
            if (const StateScale r = st.template renormalize<CP>(c); r != StateScale::Ok) {
                if (r == StateScale::Overflowed) status = Status::NonFinite;
                break;
            }
            prev_x = x;
            from_camera = false;
            ray = Ray{x, ps.wi};
        }
        // A flight or path state that overflowed (NonFinite) had a value beyond float's range: the
        // whole estimate is replaced by 0, as a non-finite sum would be.
        if (status == Status::NonFinite || !all_finite(L)) return {Spectrum::Zero(), Status::NonFinite};
        return {L, status};
    }

    /// Adds NEE's contribution at real vertex x (arrived along wo, roulette survival rr) to L:
    /// `f` is every channel's contribution of the path up to x, `p_track` its tracking pdf and
    /// `p_eq` its equiangular pdf (0 without equiangular sampling), all relative to one
    /// normaliser; `equiangular_drawn` says x is an equiangular vertex (NEE there has count 1,
    /// from a tracked vertex nee_count: tracking + NEE's pdf carries it either way). Returns
    /// Aborted or Rejected if the shadow flight was, else Ok.
    template <class Sc, UniformRng R, LookupCounter C>
    Status next_event(const Sc& scene, const Vec3& x, const Vec3& wo, float rr,
                      const typename Sc::Spectral::Wavelengths& lambda, const typename Sc::Spectrum& q, int c,
                      const typename Sc::Spectrum& f_x, const typename Sc::Spectrum& p_track,
                      const typename Sc::Spectrum& p_eq, bool equiangular_drawn, R& rng, C& counter,
                      typename Sc::Spectrum& L) const {
        const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
        const LightSample<typename Sc::Spectral> ls = scene.lights.sample(x, u0, u1, u2, lambda);
        if (!(ls.pdf > 0.f)) return Status::Ok;
        const Ray shadow{x, ls.wi};
        if (ls.occludable_by_sphere && scene.lights.sphere_blocks(shadow, ls.distance)) return Status::Ok;
        const bool uni_alternative = St::combines && !ls.delta;  // a point light cannot be hit
        const double before = detail::recorder_work(counter);
        const auto sh = track_channels_ratio<CP, A>(scene.medium, scene.majorant, shadow, ls.distance, lambda, c,
                                                    f_x, uni_alternative, rng, counter);
        detail::record_shadow_walk(counter, before, !equiangular_drawn);
        if (const Status fs = flight_status(sh.end); fs != Status::Ok) return fs;
        if (sh.end == SegmentEnd::Terminated) return Status::Ok;
        using Spectrum = typename Sc::Spectrum;
        const Spectrum f = f_x * sh.f * scene.phase.eval(wo, ls.wi);
        // Tracking + NEE (its count n), tracking + hit, and equiangular + NEE (count 1) (THEORY 5.4
        // with 5.1, 5.3, 5.9); p_eq is 0 without equiangular sampling.
        const float n = opts_.nee_count;
        const Spectrum nee = p_track * (ls.pdf * sh.nee);
        Spectrum uni = Spectrum::Zero(), other = Spectrum::Zero();
        if (uni_alternative) uni = p_track * ((rr * scene.phase.pdf(wo, ls.wi)) * sh.uni);
        if constexpr (St::equiangular) other = p_eq * (ls.pdf * sh.nee);
        else (void)p_eq;
        record_channels<CP>(counter, Spectrum(f * ls.radiance), uni, nee, other, q, c, n,
                            equiangular_drawn ? LightTechnique::Other : LightTechnique::Nee);
        L += channel_estimate<CP, Spectrum>(f, Spectrum(n * nee + uni + other), q, c) * ls.radiance;
        return Status::Ok;
    }

    /// The collision estimator of volume emission over channels (THEORY 5.7 with 5.3): at every
    /// tentative collision y, f_c = f_c(prefix) Tbar_c mu_a,c L_e,c and the collision pdf
    /// mu_bar_c Tbar_c of every channel; with `nee_alternative` also NEE's pdf of y toward the
    /// volume (ratio-tracked nulls from the last real vertex, p_V(y) t^2 in the same measure), and
    /// where the segment technique can run (`along` > 0) its pdf: the same nulls, dir_pdf p_seg(y)
    /// times its count.
    template <class Sc, class C>
    struct EmissionCollector {
        static constexpr bool enabled = true;
        using S = typename Sc::Spectral;
        using Spec = typename S::Spectrum;
        const Sc& scene;
        const Ray& ray;
        const typename S::Wavelengths& lambda;
        const Spec& q;
        int c;
        Spec& L;
        const EstimatorOptions& opts;
        C& counter;  ///< a MisRecorder records the contribution (counts.hpp)
        bool nee_alternative;
        float along, dir_pdf;

        template <class State>
        void operator()(float t, const Coefficients<S>& k, const Spec& mu, const Spec& tbar, const State& st,
                        const ChannelEventDensities<Spec>&) const {
            if (!(k.sigma_a > 0.f).any()) return;
            const Vec3 y = ray.at(t);
            const Spec le = scene.medium.emission(y, lambda);
            if (!(le > 0.f).any()) return;
            Spec pdf = st.uni * tbar * mu;
            if (nee_alternative || along > 0.f) {
                const float p_v = scene.medium.emission_pdf(y);
                const float to_volume = nee_alternative ? p_v * t * t : 0.f;
                const float on_segment = dir_pdf * segment_density(opts, p_v, along);
                pdf += st.nee * tbar * (to_volume + on_segment);
                if constexpr (MisRecorder<C> && St::combines)
                    record_emission_channels<CP>(counter, Spec(st.f * tbar * k.sigma_a * le), Spec(st.uni * tbar * mu),
                                                 Spec(st.nee * tbar * on_segment), Spec(st.nee * tbar * to_volume), q, c,
                                                 opts.emission_segment_count, EmissionTechnique::Collision);
            }
            L += channel_estimate<CP, Spec>(Spec(st.f * tbar * k.sigma_a * le), pdf, q, c);
        }
    };

    /// NEE toward the emitting volume over channels at real vertex x (THEORY 5.7 with 5.3): y drawn
    /// by the power grid, the nulls ratio-tracked with c's majorant; weighed against the collision
    /// estimator of every channel. `st` is the state at x (before roulette and the next direction).
    template <class Sc, UniformRng R, LookupCounter C, class State>
    Status emission_event(const Sc& scene, const Vec3& x, const Vec3& wo, float rr,
                          const typename Sc::Spectral::Wavelengths& lambda, const typename Sc::Spectrum& q, int c,
                          const State& st, R& rng, C& counter, typename Sc::Spectrum& L) const {
        using Spectrum = typename Sc::Spectrum;
        const auto e = sample_emission_from(scene.medium, scene.lights, x, rng);
        if (!e) return Status::Ok;
        const auto sh = track_channels_ratio<CP, A>(scene.medium, scene.majorant, e->shadow, e->dist, lambda, c, st.f,
                                                    St::combines, rng, counter);
        if (const Status fs = flight_status(sh.end); fs != Status::Ok) return fs;
        if (sh.end == SegmentEnd::Terminated) return Status::Ok;
        const auto v = lookup_untracked(scene.medium, scene.majorant, e->shadow, e->dist, lambda, counter);
        if (!v) return Status::Rejected;
        const Vec3& wi = e->shadow.d;
        const Spectrum le = scene.medium.emission(e->y.p, lambda);
        const Spectrum f = st.f * sh.f * v->k.sigma_a * le * scene.phase.eval(wo, wi);
        Spectrum pdf = sh.nee * (e->y.pdf * e->dist2);
        if constexpr (St::combines) {
            const float dir = rr * scene.phase.pdf(wo, wi);
            const Spectrum collision = sh.uni * detail::broadcast_majorant<Spectrum>(v->mu) * dir;
            // The segment technique on the ray from x toward y, with the same ratio-tracked nulls.
            const Spectrum segment = sh.nee * (dir * emission_segment_pdf(opts_, scene, *e));
            if constexpr (MisRecorder<C>)
                record_emission_channels<CP>(counter, f, Spectrum(st.uni * collision), Spectrum(st.uni * segment),
                                             Spectrum(st.uni * pdf), q, c, opts_.emission_segment_count,
                                             EmissionTechnique::Nee);
            pdf += collision;
            pdf += segment;
        }
        L += channel_estimate<CP, Spectrum>(f, Spectrum(st.uni * pdf), q, c);
        return Status::Ok;
    }

    /// The segment technique of volume emission over channels on `ray` over [0, tmax) (THEORY 5.7
    /// with 5.3): y drawn with density p_seg = emission_pdf / `along` along the ray, the nulls
    /// ratio-tracked with c's majorant and every channel's pdfs, against the collision estimator
    /// of the segment and, with `nee_alternative`, NEE toward the volume from its real vertex. `st`
    /// is the state at the segment's start: uni with the direction's pdf `dir_pdf` (rr p_w), nee
    /// without it.
    template <class Sc, UniformRng R, LookupCounter C, class State>
    Status emission_segment(const Sc& scene, const Ray& ray, float tmax, float along, bool nee_alternative,
                            float dir_pdf, const typename Sc::Spectral::Wavelengths& lambda,
                            const typename Sc::Spectrum& q, int c, const State& st, R& rng, C& counter,
                            typename Sc::Spectrum& L) const {
        using Spectrum = typename Sc::Spectrum;
        const DistanceSample ds = scene.medium.sample_emission_along(ray, 0.f, tmax, along, rng.uniform());
        if (!(ds.pdf > 0.f)) return Status::Ok;
        const auto sh = track_channels_ratio<CP, A>(scene.medium, scene.majorant, ray, ds.t, lambda, c, st.f, true, rng,
                                                    counter);
        if (const Status fs = flight_status(sh.end); fs != Status::Ok) return fs;
        if (sh.end == SegmentEnd::Terminated) return Status::Ok;
        const auto v = lookup_untracked(scene.medium, scene.majorant, ray, ds.t, lambda, counter);
        if (!v) return Status::Rejected;
        if (!(v->k.sigma_a > 0.f).any()) return Status::Ok;
        const Vec3 y = ray.at(ds.t);
        const Spectrum f = st.f * sh.f * v->k.sigma_a * scene.medium.emission(y, lambda);
        // Every channel's pdf of the three techniques, p_seg where each technique evaluates it (the
        // point's own cell).
        const float p_v = scene.medium.emission_pdf(y);
        const Spectrum collision = st.uni * sh.uni * detail::broadcast_majorant<Spectrum>(v->mu);
        if constexpr (MisRecorder<C>)
            record_emission_channels<CP>(counter, f, collision,
                                         Spectrum(st.nee * sh.nee * (dir_pdf * segment_density(opts_, p_v, along))),
                                         Spectrum(st.nee * sh.nee * (nee_alternative ? p_v * ds.t * ds.t : 0.f)), q, c,
                                         opts_.emission_segment_count, EmissionTechnique::Segment);
        Spectrum pdf = collision;
        pdf += st.nee * sh.nee * ((nee_alternative ? p_v * ds.t * ds.t : 0.f) + dir_pdf * segment_density(opts_, p_v, along));
        // channel_estimate divides by the techniques' sum, where this one's pdf is count x p_seg:
        // that is the estimate of a technique run with its count (THEORY 5.9). The density actually
        // sampled is ds.pdf, which differs from p_v / along only within rounding of a cell face.
        L += channel_estimate<CP, Spectrum>(f, pdf, q, c);
        return Status::Ok;
    }

    /// Equiangular + NEE on the segment `ray` (THEORY 5.4 per channel): draws t with `eq`,
    /// ratio-tracks the nulls on [0, t) with channel c's majorant and every channel's pdfs, makes t
    /// a real scattering vertex at path depth `depth` and does NEE from it. `st` is the prefix up
    /// to the ray's origin, its direction included; `select` the probability with which this
    /// segment draws an equiangular vertex at all (its density is select x eq's).
    template <class Sc, UniformRng R, LookupCounter C, class State>
    Status equiangular_vertex(const Sc& scene, const Ray& ray, const EquiangularSampler& eq, float select, int depth,
                              const typename Sc::Spectral::Wavelengths& lambda, const typename Sc::Spectrum& q, int c,
                              const State& st, R& rng, C& counter, typename Sc::Spectrum& L) const {
        using S = typename Sc::Spectral;
        using Spectrum = typename Sc::Spectrum;
        DistanceSample ds = eq.sample(rng.uniform());
        ds.pdf *= select;
        if (!(ds.pdf > 0.f)) return Status::Ok;
        const auto sh = track_channels_ratio<CP, A>(scene.medium, scene.majorant, ray, ds.t, lambda, c, st.f,
                                                    St::combines, rng, counter);
        if (const Status fs = flight_status(sh.end); fs != Status::Ok) return fs;
        if (sh.end == SegmentEnd::Terminated) return Status::Ok;
        const Vec3 x = ray.at(ds.t);
        const auto v = lookup_untracked(scene.medium, scene.majorant, ray, ds.t, lambda, counter);
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
            if (opts_.russian_roulette && depth >= opts_.rr_start_depth)
                rr = std::min(opts_.rr_max_survival, channel_estimate<CP>(f_x, p_track, q, c).abs().maxCoeff());
        }
        return next_event(scene, x, ray.d, rr, lambda, q, c, f_x, p_track, p_eq, true, rng, counter, L);
    }

    EstimatorOptions opts_;
};

}  // namespace nsp
