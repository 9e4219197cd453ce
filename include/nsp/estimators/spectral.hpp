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
//     estimate_lambda = f_lambda / sum_c q_c (p_uni,c + p_nee,c).
#pragma once

#include <algorithm>
#include <cstdint>
#include <type_traits>

#include "../channel_tracking.hpp"
#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../media/emissive.hpp"
#include "../mis.hpp"
#include "../path_pdf.hpp"
#include "../scene.hpp"
#include "common.hpp"

namespace nsp {

/// A path estimator over channels: channel policy CP, strategy St (Unidirectional, NextEvent or
/// NullScatteringMis), heuristic H (mis::None for a single strategy, mis::Balance for
/// NullScatteringMis: the weights are the one-sample balance heuristic over channels and
/// techniques) and absorption policy A.
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
    /// sampling channel chosen uniformly. Never throws.
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
        static_assert(!St::equiangular,
                      "nsp::SpectralPathEstimator does not draw equiangular vertices yet; equiangular "
                      "strategies go with nsp::PathEstimator (a grey majorant, every spectral mode)");
        static_assert(!EmissiveMedium<M>,
                      "nsp::SpectralPathEstimator does not collect volume emission yet; emissive media go "
                      "with nsp::PathEstimator (a grey majorant, every spectral mode)");
        using Spectrum = typename Sc::Spectrum;
        const Spectrum& q = selection.probabilities();
        const int c = selection.sample(rng.uniform());
        ChannelPathState<typename Sc::Spectral> st;
        Spectrum L = Spectrum::Zero();
        Status status = Status::Ok;
        Ray ray = camera_ray;
        Vec3 prev_x(0.f);  // the real vertex the current ray left from
        bool from_camera = true;

        for (int depth = 0;;) {
            const LightHit hit = scene.lights.intersect(ray);
            const bool nee_alternative = St::combines && !from_camera;
            const ChannelTrack seg = track_channels_delta<CP, A>(scene.medium, scene.majorant, ray, hit.t, lambda, c,
                                                                 st, nee_alternative, rng, counter);
            if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
                status = fs;
                break;
            }
            if (seg.end == SegmentEnd::Passed) {
                if (from_camera || St::hits_lights) {
                    Spectrum pdf = st.uni;
                    if (nee_alternative) pdf += scene.lights.pdf(prev_x, hit) * st.nee;
                    L += channel_estimate<CP>(st.f, pdf, q, c) * scene.lights.emitted(hit, lambda);
                }
                break;
            }
            if (seg.end != SegmentEnd::Scattered) break;  // absorbed, or no pdf left
            if (++depth > opts_.max_depth) break;

            const Vec3 x = ray.at(seg.t);
            // Roulette survival is fixed before NEE: the continuing unidirectional path carries it.
            // It follows what the path would contribute per unit of incident light, the largest
            // channel estimate, as PathEstimator's max |beta| does.
            float rr = 1.f;
            if (opts_.russian_roulette && depth >= opts_.rr_start_depth)
                rr = std::min(opts_.rr_max_survival, channel_estimate<CP>(st.f, st.uni, q, c).abs().maxCoeff());
            if constexpr (St::samples_lights) {
                const Status ns = next_event(scene, x, ray.d, rr, lambda, q, c, st, rng, counter, L);
                if (ns != Status::Ok) status = ns;
            }
            if (rr < 1.f && !(rng.uniform() < rr)) break;
            const float u1 = rng.uniform(), u2 = rng.uniform();
            const PhaseSample ps = scene.phase.sample(ray.d, u1, u2);
            if (!(ps.pdf > 0.f)) break;
            // The NEE alternative of the next segment starts from the prefix, without roulette.
            if constexpr (St::combines) st.nee = st.uni;
            st.f *= ps.value;
            st.uni *= rr * ps.pdf;
            if (!st.template renormalize<CP>(c)) break;
            prev_x = x;
            from_camera = false;
            ray = Ray{x, ps.wi};
        }
        if (!all_finite(L)) return {Spectrum::Zero(), Status::NonFinite};
        return {L, status};
    }

private:
    /// Adds NEE's contribution at real vertex x (arrived along wo, roulette survival rr) to L;
    /// returns Aborted or Rejected if its shadow flight was, else Ok.
    template <class Sc, UniformRng R, LookupCounter C>
    Status next_event(const Sc& scene, const Vec3& x, const Vec3& wo, float rr,
                    const typename Sc::Spectral::Wavelengths& lambda, const typename Sc::Spectrum& q, int c,
                    const ChannelPathState<typename Sc::Spectral>& st, R& rng, C& counter,
                    typename Sc::Spectrum& L) const {
        const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
        const LightSample<typename Sc::Spectral> ls = scene.lights.sample(x, u0, u1, u2, lambda);
        if (!(ls.pdf > 0.f)) return Status::Ok;
        const Ray shadow{x, ls.wi};
        if (ls.occludable_by_sphere && scene.lights.sphere_blocks(shadow, ls.distance)) return Status::Ok;
        const bool uni_alternative = St::combines && !ls.delta;  // a point light cannot be hit
        const auto sh = track_channels_ratio<CP, A>(scene.medium, scene.majorant, shadow, ls.distance, lambda, c,
                                                    st.f, uni_alternative, rng, counter);
        if (sh.end == SegmentEnd::Aborted || sh.end == SegmentEnd::Rejected) return flight_status(sh.end);
        if (sh.end == SegmentEnd::Terminated) return Status::Ok;
        using Spectrum = typename Sc::Spectrum;
        Spectrum pdf = ls.pdf * sh.nee;
        if (uni_alternative) pdf += (rr * scene.phase.pdf(wo, ls.wi)) * sh.uni;
        const Spectrum f = st.f * sh.f * scene.phase.eval(wo, ls.wi);
        L += channel_estimate<CP, Spectrum>(f, st.uni * pdf, q, c) * ls.radiance;
        return Status::Ok;
    }

    EstimatorOptions opts_;
};

}  // namespace nsp
