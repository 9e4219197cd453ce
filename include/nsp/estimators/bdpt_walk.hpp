// nsp/estimators/bdpt_walk.hpp: BdptEstimator's subpath walk (bdpt.hpp), camera and light side
// alike, in steps: each piece of a segment tracked through its medium (grey, or every channel's
// densities), what a segment that passes its medium meets at the surface (an emitter, an
// interface to cross, a surface vertex), and the vertex a segment ends at (its densities from
// either side, roulette, the next direction). Included by bdpt.hpp, after the estimator's
// declaration.
#pragma once

#include "bdpt.hpp"

namespace nsp {

/// A subpath's walk from path[count - 1] (see trace): the subpath it extends, the segment it is
/// on and, per channel, that segment's tracking state. With `eq` (the equiangular strategy on) it
/// stores the strategy's densities: a camera subpath's (`camera_side`) at each medium vertex, a
/// light subpath's at y_1. `first`, if given, receives the first segment's FirstSegment.
/// BdptSample::subpath builds one from the sample's state.
template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class R, class C>
struct BdptEstimator<Mis, H, A, MaxDepth, Ch>::SubpathWalk {
    using V = VertexT<Sc>;
    using S = typename Sc::Spectral;
    using Spectrum = typename Sc::Spectrum;
    using P = bdpt::PdfType<Ch, S>;
    // Per channel: the segment's state since the last real vertex (f_c and p_c of channel c's
    // tracking, and in its nee slot the factor every strategy shares, prod mu_bar_c(n_j) Tbar_c:
    // ratio tracking's pdf of the nulls, which the tracking kernel keeps there as NEE's
    // alternative, times the real vertex's Tbar_c, multiplied in where it scatters), and the
    // throughput where the segment started (THEORY 5.3 with 5.5).
    using State = std::conditional_t<kPerChannel, ChannelPathState<S>, bdpt::NoGamma>;

    const BdptEstimator& est;
    const Sc& sc;
    V* const path;
    int count;
    const int max_vertices;
    Ray ray;
    int medium;
    float pdf_dir;
    Spectrum beta;
    const typename S::Wavelengths& lambda;
    const int channel;
    R& rng;
    C& counter;
    Status& status;
    const EqRegion* const eq;
    const bool camera_side;
    FirstSegment<Sc>* const first;

    const float beta_scale = float(beta.abs().maxCoeff());  // roulette's: relative to the subpath's start
    P nulls = bdpt::broadcast<P>(1.f);                      // the segment's P_n product so far
    int crossings = 0;                                      // interfaces the segment has crossed
    [[maybe_unused]] State st = fresh_state();
    [[maybe_unused]] Spectrum beta0 = beta;
    // Per channel: the product of the subpath's forward densities (the shared factors apart),
    // relative to the largest channel's: with the vertex's gamma, every channel's density of the
    // subpath, for roulette on the one-sample spectral MIS estimate of its throughput.
    [[maybe_unused]] P prefix = bdpt::broadcast<P>(1.f);

    static State fresh_state() {
        State s{};
        if constexpr (kPerChannel) s.nee = Spectrum::Ones();
        return s;
    }

    /// The subpath's shared factors up to where the walk is now (per channel; grey: none).
    auto gamma_here() const {
        if constexpr (kPerChannel) return relative_to_largest<Spectrum>(path[count - 1].gamma * st.nee);
        else return bdpt::NoGamma{};
    }

    /// The walk: segments from path[count - 1] until the subpath has max_vertices vertices or
    /// ends; returns its vertex count. `on_hit(path, count, hit, ray, nulls, beta, gamma)` where a
    /// segment reaches an emitter or leaves the scene; `on_emission` at every tentative collision
    /// in an emissive medium (EmissionVisitor, ChannelWalkVisit); `on_segment(path, count, ray,
    /// medium, pdf_dir, beta)` at the start of every segment, before it is tracked; `on_piece(path,
    /// count, ray, medium, t_max, pdf_dir, beta, nulls, gamma)` before every piece in a medium is
    /// tracked, returning the segment technique's normaliser on it (which `on_emission` then gets).
    template <class OnHit, class OnEmission = NoEmission, class OnSegment = NoSegment, class OnPiece = NoSegment>
    int run(OnHit on_hit, OnEmission on_emission = {}, OnSegment on_segment = {}, OnPiece on_piece = {}) {
        bool segment_start = true;
        while (count < max_vertices) {
            if constexpr (!std::is_same_v<OnSegment, NoSegment>) {
                if (segment_start) on_segment(path, count, ray, medium, pdf_dir, beta);
            }
            segment_start = false;
            SurfaceHit hit = sc.geometry.intersect(ray, kInf);
            if (!detail::usable_hit(sc, hit)) {
                status = Status::InvalidInput;
                return count;
            }
            hit.keep_media(medium);
            if (first && count == 1 && crossings == 0) first->first_piece_end = hit.t;
            V v;
            // The segment technique's normaliser on this piece (0: it does not run here).
            float along = 0.f;
            if constexpr (!std::is_same_v<OnPiece, NoSegment>) {
                if (sc.has_medium(medium))
                    along = on_piece(path, count, ray, medium, hit.t, pdf_dir, beta, nulls, gamma_here());
            }
            Step piece;
            if constexpr (kPerChannel) piece = track_channels(hit, along, on_emission, v);
            else piece = track(hit, along, on_emission, v);
            if (piece == Step::End) return count;
            if (piece == Step::Passed) {
                const Step at = at_surface(hit, on_hit, v);
                if (at == Step::End) return count;
                if (at == Step::Passed) continue;  // across an interface, on the same segment
            }
            if (!extend(v)) return count;
            segment_start = true;
        }
        return count;
    }

    /// How a step leaves the walk: a real vertex v to extend the subpath by, on past the piece
    /// (or across the interface), or the end of the subpath.
    enum class Step { Vertex, Passed, End };

    /// Grey: the piece up to `hit` tracked in the walk's medium with one pdf for every channel (in
    /// an emissive medium with the collision estimator at every tentative collision).
    template <class OnEmission>
    Step track(const SurfaceHit& hit, float along, OnEmission& on_emission, V& v) {
        if (!sc.has_medium(medium)) return Step::Passed;
        const auto& m = sc.media[std::size_t(medium)];
        DeltaTrack<S> seg;
        if constexpr (!std::is_same_v<OnEmission, NoEmission>) {
            // The collision estimator of volume emission: every tentative collision, with the
            // throughput and null product of the nulls before it (THEORY 5.7).
            seg = est.kernels_.track_visiting(
                m.medium, m.majorant, ray, hit.t, lambda, rng, counter,
                EmissionVisitor<Sc, OnEmission>{on_emission, path, count, medium, ray, beta, nulls, pdf_dir, along});
        } else {
            (void)along;
            seg = est.kernels_.track(m.medium, m.majorant, ray, hit.t, lambda, rng, counter);
        }
        if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
            status = fs;
            return Step::End;
        }
        beta *= seg.weight;
        if constexpr (Mis::null_pdfs) {
            nulls *= seg.null_pdf_product;
            if (first && count == 1 && crossings > 0) first->later_nulls *= seg.null_pdf_product;
        }
        if (seg.end == SegmentEnd::Passed) return Step::Passed;
        if (seg.end != SegmentEnd::Scattered) return Step::End;  // absorbed
        v.kind = bdpt::VertexKind::Medium;
        v.p = ray.at(seg.t);
        v.medium = medium;
        if constexpr (Mis::null_pdfs) v.event = seg.event_density;
        return Step::Vertex;
    }

    /// Per channel: the piece up to `hit` tracked with the sampling channel's densities, every
    /// channel's null and event densities kept (and the collision estimator, as track's).
    template <class OnEmission>
    Step track_channels(const SurfaceHit& hit, float along, OnEmission& on_emission, V& v) {
        if (!sc.has_medium(medium)) return Step::Passed;
        const auto& m = sc.media[std::size_t(medium)];
        detail::DoubleSpectrum<Spectrum> piece_nulls = detail::DoubleSpectrum<Spectrum>::Ones();
        Spectrum last_null = Spectrum::Ones(), last_event = Spectrum::Ones(), last_tbar = Spectrum::Ones();
        bool pending = false;
        using Visit = ChannelWalkVisit<Sc, OnEmission, is_control_v<typename Sc::MajorantType, typename Sc::MediumType>>;
        const ChannelTrack seg = track_channels_delta_visiting<Ch, A>(
            m.medium, m.majorant, ray, hit.t, lambda, channel, st, true, rng, counter,
            Visit{{&piece_nulls, &last_null, &last_event, &last_tbar, &pending},
                  &on_emission, path, count, medium, channel, ray, beta0, nulls, pdf_dir, along});
        if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
            status = fs;
            return Step::End;
        }
        if (seg.end != SegmentEnd::Scattered && seg.end != SegmentEnd::Passed) return Step::End;  // absorbed, or no pdf left
        if (seg.end == SegmentEnd::Passed && pending) piece_nulls *= last_null.template cast<double>();
        nulls *= piece_nulls.template cast<float>();
        if (first && count == 1 && crossings > 0) first->later_nulls *= piece_nulls.template cast<float>();
        beta = beta0 * st.f / st.uni[channel];
        if (seg.end == SegmentEnd::Passed) return Step::Passed;
        v.kind = bdpt::VertexKind::Medium;
        v.p = ray.at(seg.t);
        v.medium = medium;
        v.event = last_event;
        st.nee *= last_tbar;  // the real vertex's Tbar_c (not a null's: no mu_bar_c)
        return Step::Vertex;
    }

    /// The segment passed its medium up to `hit`: s = 0 where it reaches an emitter (or leaves the
    /// scene), across a null interface (Passed: on along the same segment), a surface vertex v,
    /// or the end of the subpath.
    template <class OnHit>
    Step at_surface(const SurfaceHit& hit, OnHit& on_hit, V& v) {
        if (!hit.found()) {
            on_hit(path, count, hit, ray, nulls, beta, gamma_here());  // the lights at infinity
            return Step::End;
        }
        if (hit.light >= 0) on_hit(path, count, hit, ray, nulls, beta, gamma_here());
        auto cross = [&] {
            if (++crossings > detail::kMaxInterfaceCrossings) {
                status = Status::InvalidInput;
                return Step::End;
            }
            medium = hit.medium_entered(ray.d);
            ray.o = hit.p;
            return Step::Passed;
        };
        if (detail::crosses(sc, hit)) return cross();
        if (hit.material < 0 || sc.materials.passes_through(hit.material)) return Step::End;  // an emitter alone
        if constexpr (detail::has_null_lobes_v<Sc>) {
            // A partly null BSDF: its null lobe with probability P (weight / P, and P a null
            // factor of the segment from either side: the lobe's P is the same both ways), else a
            // real vertex whose event factor is 1 - P (from either side; it cancels in every
            // weight, and keeps the densities true).
            const NullLobe<S> lobe = detail::null_lobe_at(sc, hit, ray.d, lambda);
            if (!detail::usable_null_lobe(lobe)) {
                status = Status::InvalidInput;
                return Step::End;
            }
            if (lobe.probability > 0.f) {
                if (rng.uniform() < lobe.probability) {
                    beta *= lobe.weight / lobe.probability;
                    if constexpr (kPerChannel) {
                        st.f *= lobe.weight;
                        st.uni *= lobe.probability;
                    }
                    if constexpr (Mis::null_pdfs) {
                        nulls *= lobe.probability;
                        if (first && count == 1) first->later_nulls *= lobe.probability;
                    }
                    return cross();
                }
                beta /= 1.f - lobe.probability;
                if constexpr (Mis::null_pdfs) v.event = bdpt::broadcast<P>(1.f - lobe.probability);
            }
        }
        v.kind = bdpt::VertexKind::Surface;
        v.p = hit.p;
        v.ng = hit.ng;
        v.ns = hit.ns;
        v.dpdu = hit.dpdu;
        v.uv = hit.uv;
        v.user = hit.user;
        v.material = hit.material;
        v.medium_front = hit.medium_front;
        v.medium_back = hit.medium_back;
        return Step::Vertex;
    }

    /// Adds the segment's real vertex v to the subpath with its forward density (and the
    /// equiangular strategy's), then, unless the subpath is full or roulette ends it, samples the
    /// next direction there, stores the previous vertex's reverse density and starts the next
    /// segment. False: the subpath ends.
    bool extend(V v) {
        using namespace bdpt;
        V& prev = path[count - 1];
        v.wo = ray.d;
        v.beta = beta;
        v.nulls_in = nulls;
        // From the camera: its own density of the ray (light tracing), or a stand-in of 1 for it,
        // a factor of every strategy with t >= 2 (the equiangular one too), so it cancels.
        const float pd = prev.kind == VertexKind::Camera && !(pdf_dir > 0.f) ? 1.f : pdf_dir;
        if (prev.at_infinity) {
            v.pdf_fwd = from_infinity_measure(pd, ray.d, v) * nulls * v.event;
        } else {
            const float g = to_vertex_measure(pd, prev.p, v);
            v.pdf_fwd = g * nulls * v.event;
            if (camera_side && eq && v.kind == VertexKind::Medium)
                v.eq = broadcast<P>(g * eq->density(sc, prev.p, ray.d, glm::length(v.p - prev.p)));
        }
        if constexpr (kPerChannel) v.gamma = gamma_here();
        path[count] = v;
        V& cur = path[count++];
        if (count >= max_vertices) return false;
        // Roulette on the throughput relative to the subpath's start (a light subpath starts at
        // Le / pdf, not 1). Per channel on the estimate the one-sample MIS over channels makes of
        // it, f / sum_c' q_c' p_c' = beta p_c / sum_c' q_c' p_c' (q_c' = 1 / C), as
        // SpectralPathEstimator's roulette: on beta = f / p_c alone, the sampling channel's, the
        // chromatic cloud under a sky (nsp_room, C1) had 1.2x the variance.
        Spectrum rr_beta = beta;
        if constexpr (kPerChannel) {
            prefix = relative_to_largest<Spectrum>(prefix * cur.pdf_fwd);
            const Spectrum pc = prefix * cur.gamma;
            const float mean = pc.mean();
            if (pc[channel] > 0.f && mean > 0.f) rr_beta *= pc[channel] / mean;
        }
        const float q = est.kernels_.survival(count - 1, rr_beta / (beta_scale > 0.f ? beta_scale : 1.f));
        if (q < 1.f) {
            if (!(rng.uniform() < q)) return false;
            beta /= q;
        }
        const SceneVertex sv = cur.scene_vertex();
        const auto next = sample_vertex(sc, sv, ray.d, rng, lambda);
        if (!(next.pdf > 0.f)) return false;
        cur.delta = next.delta;
        // The density with which the other side, arriving along -next.wi, draws prev from cur.
        const float rev = next.delta ? next.pdf : eval_vertex(sc, sv, -next.wi, -ray.d, lambda).pdf;
        const float g_rev = to_vertex_measure(rev, cur.p, prev);
        prev.pdf_rev = g_rev * nulls * prev.event;
        if (first && count == 2) first->y0_reverse = g_rev;
        if (!camera_side && eq && count == 3 && prev.kind == VertexKind::Medium) {  // y_1, drawn from y_2
            const Vec3 d = prev.p - cur.p;
            const float len = glm::length(d);
            prev.eq = broadcast<P>(len > 0.f ? g_rev * eq->density(sc, cur.p, d / len, len) : 0.f);
        }
        beta *= next.value / next.pdf;
        if (!(beta != 0.f).any()) return false;
        if (cur.kind == VertexKind::Surface) medium = cur.medium_toward(next.wi);
        pdf_dir = next.pdf;
        nulls = broadcast<P>(1.f);
        if constexpr (kPerChannel) {
            beta0 = beta;
            st = fresh_state();
        }
        crossings = 0;
        ray = Ray{cur.p, next.wi};
        return true;
    }
};

}  // namespace nsp
