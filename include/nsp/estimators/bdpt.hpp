// nsp/estimators/bdpt.hpp: volumetric bidirectional path tracing over a SurfaceScene with full
// null-vertex MIS (THEORY 5.5), grey (one pdf for every channel, as PathEstimator) or per channel
// (SpectralBdptEstimator: every channel's pdfs, channels x strategies in one denominator, THEORY
// 5.3 with 5.5).
//
// A camera subpath and a light subpath are delta-tracked through the scene's media and surfaces
// (the same VertexKernels and interface crossings as estimators/path.hpp). Every real
// vertex stores the density with which its own subpath drew it and the density with which the
// other side would have drawn it, in area measure on surfaces and volume measure in media, each
// with the segment's null-scattering factors: prod P_n(n_j) of the nulls on the segment it was
// drawn along, and mu_bar P_s at a medium vertex (the Tbar and mu_bar(n_j) factors appear in
// every strategy's pdf of a segment and cancel). Strategies (s, t), s light vertices and t camera
// vertices:
// - s = 0: the camera subpath hits an emitter (a surface light, or the lights at infinity);
// - s = 1: next-event estimation from the camera vertex (the scene's light sampler);
// - s >= 2: a connection between light vertex s-1 and camera vertex t-1, its transmittance and its
//   nulls' P_n product by ratio tracking across the media and null interfaces between them;
// - t = 1 (sample(), with the host's Camera): light vertex s-1 connected to the camera and
//   splatted where it appears on the image (light tracing); radiance() leaves it out, and its
//   weights leave it out for every path alike, so they still sum to 1.
// Each is weighted against every other strategy that could have drawn the same path (bdpt::
// strategy_weight). An emissive medium is a light source too (THEORY 5.7): the camera subpath
// collects its emission at every tentative collision (s = 0), NEE also draws a point in the
// volume (s = 1), and light subpaths start there (one half of them when the scene also has
// lights), so connections and light tracing carry it as well; with null-scattering MIS the
// segment technique also draws one point on every piece of a camera segment in an emitting
// medium (PathPdfs::kSegment). Toward point lights, the equiangular strategy draws a vertex on
// every camera segment and connects it by NEE (PathPdfs::kEquiangular).
//
// Policies: bdpt::NullScattering (the paper's full null-scattering MIS) or bdpt::Directional
// (the baseline: direction pdfs and geometry only, the tracking factors left out, as pbrt's BDPT
// weighs medium vertices), the heuristic (mis::Balance or mis::Power), the absorption policy of
// the tracked segments, and MaxDepth, the longest subpath the fixed-size vertex arrays hold (no
// heap allocation in the kernel). Lights at infinity start light subpaths when the scene's
// LightSampler has a BoundingSphere (their rays from a disk outside it; x_0 is then a direction,
// its densities solid angles, and x_1's the disk's per perpendicular area, converted); without one,
// and for DirectionalLight, paths to them are weighted among s = 0 and s = 1 alone. Russian roulette divides the subpaths'
// throughputs as in PathEstimator, but the weights leave it out (the same for every strategy, so
// they still sum to 1; the survival probability of a subpath read backwards is not defined).
// Expected counts (THEORY 5.9): NEE toward the lights runs at a camera vertex with probability
// EstimatorOptions::nee_count and a light subpath on a sample with light_subpath_probability,
// each folded into its strategies' densities in every weight; with a NeeCountLearner as the
// counter every strategy's contribution is recorded, so both can be learned from a pilot.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <new>
#include <type_traits>

#include "../core/counter.hpp"
#include "../core/rng.hpp"
#include "../geometry.hpp"
#include "../camera.hpp"
#include "../media/emissive.hpp"
#include "../channel_tracking.hpp"
#include "../equiangular.hpp"
#include "../mis.hpp"
#include "../path_pdf.hpp"
#include "../surface_scene.hpp"
#include "../options.hpp"
#include "../path_state.hpp"
#include "../recorder.hpp"
#include "../vertex.hpp"
#include "emission.hpp"
#include "nee.hpp"
#include "bdpt_pdfs.hpp"
#include "bdpt_vertex.hpp"
#include "scene_walk.hpp"

namespace nsp {

/// Volumetric BDPT (see the header comment): MIS policy Mis, heuristic H, absorption policy A of
/// the tracked segments, subpaths of at most MaxDepth real vertices (EstimatorOptions::max_depth
/// must not exceed it). radiance() has PathEstimator's signature, so a host's pixel loop calls
/// either the same way. Channel axis Ch: bdpt::Grey (one pdf, exact for Mono and grey media, as
/// PathEstimator) or channels::SpectralMis (every channel's pdfs: SpectralBdptEstimator).
template <bdpt::MisPolicy Mis = bdpt::NullScattering, mis::CombiningHeuristic H = mis::Balance,
          AbsorptionPolicy A = absorption::Weight, int MaxDepth = 32, bdpt::ChannelAxis Ch = bdpt::Grey>
class BdptEstimator {
    static_assert(MaxDepth >= 1 && MaxDepth <= 256, "nsp::BdptEstimator: MaxDepth must lie in [1, 256]");
    static_assert(std::same_as<Ch, bdpt::Grey> || Mis::null_pdfs,
                  "nsp::BdptEstimator: per-channel pdfs are null-scattering pdfs (bdpt::NullScattering); "
                  "bdpt::Directional has none");

public:
    using MisType = Mis;
    using HeuristicType = H;
    using Absorption = A;
    using Channels = Ch;
    static constexpr bool kPerChannel = !std::same_as<Ch, bdpt::Grey>;
    static constexpr int kMaxDepth = MaxDepth;
    static constexpr int kMaxPath = 2 * MaxDepth + 3;  ///< most vertices of a path x_0..x_k
    using Pdfs = bdpt::PathPdfs<kMaxPath>;  ///< the grey densities (PdfsFor: a scene's)
    /// The densities of a path through scenes of spectral mode S: one float or one per channel.
    template <SpectralMode S>
    using PdfsFor = bdpt::PathPdfs<kMaxPath, bdpt::PdfType<Ch, S>>;
    template <SpectralMode S>
    using VertexFor = bdpt::Vertex<S, bdpt::PdfType<Ch, S>>;

    /// EstimatorOptions' defaults with max_depth = MaxDepth (theirs, 1000, would not fit).
    static EstimatorOptions default_options() noexcept {
        EstimatorOptions o;
        o.max_depth = MaxDepth;
        return o;
    }

    /// Throws InvalidArgument on invalid roulette settings (see EstimatorOptions) or a max_depth
    /// above MaxDepth (the vertex arrays' size).
    /// `light_subpath_probability` in [0, 1]: the expected number of light subpaths per sample
    /// (THEORY 5.9). Each sample traces one with that probability; every strategy that uses it
    /// (connections, light tracing) then has that probability times its density in every weight
    /// and divides by it, so the estimate stays unbiased for any value. 1 (the default): always.
    /// 0: never, and those strategies are absent from every weight (s = 0 and NEE reach every
    /// light). EstimatorOptions::nee_count may be 0 too (s = 1 toward the lights absent), where
    /// the scene has no delta light (else Status::InvalidInput). Throws InvalidArgument on a value
    /// outside [0, 1].
    explicit BdptEstimator(EstimatorOptions opts = default_options(), H heuristic = H{},
                           float light_subpath_probability = 1.f)
        : kernels_(checked(opts), heuristic), light_probability_(light_subpath_probability) {
        validate_count("BdptEstimator light_subpath_probability", light_probability_, true);
    }

    float light_subpath_probability() const noexcept { return light_probability_; }

    const EstimatorOptions& options() const noexcept { return kernels_.options(); }

    /// An estimate of the radiance arriving at `ray.o` from direction -ray.d: every strategy
    /// (s, t >= 2) of one camera subpath and one light subpath, MIS-weighted. A camera ray that is
    /// not usable_ray gives 0 and Status::InvalidInput. Never throws.
    template <class Sc, UniformRng R, LookupCounter C>
    RadianceSample<typename Sc::Spectral> radiance(const Sc& scene, const Ray& camera_ray,
                                                   const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                   C& counter) const {
        NoObserver none;
        return radiance_observed(scene, camera_ray, lambda, rng, counter, none);
    }

    /// radiance(), calling `observe(s, t, contribution, weight, pdfs, vertices)` for every
    /// strategy's sample: its unweighted contribution (weight 1), the MIS weight it got, the path's
    /// densities (bdpt::PathPdfs) and its vertices (bdpt::PathVertices). What the tests measure
    /// each strategy alone with.
    template <class Sc, UniformRng R, LookupCounter C, class Observe>
    RadianceSample<typename Sc::Spectral> radiance_observed(const Sc& sc, const Ray& camera_ray,
                                                            const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                            C& counter, Observe& observe) const {
        NoSplat none;
        return trace(sc, camera_ray, static_cast<const NoCamera*>(nullptr), lambda, rng, counter, none, observe);
    }

    /// One sample of the image of `camera` at image coordinates (u, v), with light tracing (t = 1)
    /// among the strategies: returns the camera ray's MIS-weighted estimate for the pixel at
    /// (u, v), and calls `splat(u', v', value)` for each light-tracing contribution, which the host
    /// adds to the pixel at (u', v'). Every pixel's value is then the sum of its samples' returns
    /// and of the splats it received, divided by its own number of samples (the same for every
    /// pixel: the light subpaths are one per camera sample over the whole image). A (u, v) whose
    /// camera ray is not usable_ray (NaN) gives 0 and Status::InvalidInput. Never throws.
    template <class Sc, Camera Cam, UniformRng R, LookupCounter C, class Splat>
    RadianceSample<typename Sc::Spectral> sample(const Sc& sc, const Cam& camera, float u, float v,
                                                 const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                                                 Splat&& splat) const {
        NoObserver none;
        return trace(sc, camera.ray(u, v), &camera, lambda, rng, counter, splat, none);
    }

    /// sample(), with the observer of radiance_observed (t = 1 included: its contribution is the
    /// splat's value before weighting).
    template <class Sc, Camera Cam, UniformRng R, LookupCounter C, class Splat, class Observe>
    RadianceSample<typename Sc::Spectral> sample_observed(const Sc& sc, const Cam& camera, float u, float v,
                                                          const typename Sc::Spectral::Wavelengths& lambda, R& rng,
                                                          C& counter, Splat&& splat, Observe& observe) const {
        return trace(sc, camera.ray(u, v), &camera, lambda, rng, counter, splat, observe);
    }

private:
    struct NoObserver {
        template <class... T>
        void operator()(const T&...) const noexcept {}
    };
    using NoSplat = NoObserver;
    struct NoCamera {};

    template <class Sc, class Cam, UniformRng R, LookupCounter C, class Splat, class Observe>
    RadianceSample<typename Sc::Spectral> trace(const Sc& sc, const Ray& camera_ray, const Cam* cam,
                                                const typename Sc::Spectral::Wavelengths& lambda, R& rng, C& counter,
                                                Splat& splat, Observe& observe) const;
    /// One sample of trace: its shared state and its strategies as named parts (defined below).
    template <class Sc, class Cam, class R, class C, class Splat, class Observe>
    struct BdptSample;
    using Kernels = VertexKernels<std::conditional_t<Mis::null_pdfs, strategy::NullScatteringMis, strategy::DirectionalMis>,
                                  H, A>;

    static EstimatorOptions checked(EstimatorOptions o) {
        validate(o);
        if (o.shadow_estimator != ShadowEstimator::RatioTracking)
            detail::fail("EstimatorOptions shadow_estimator = RayMarching is not allowed with nsp::BdptEstimator: "
                         "its connections are weighed by their null-scattering pdfs (nsp::PathEstimator with "
                         "ratio-nee, directional-mis or equiangular-nee takes it)");
        if (o.max_depth > MaxDepth)
            detail::fail("BdptEstimator max_depth = ", o.max_depth, " is not allowed: it must be <= ", MaxDepth,
                         " (the estimator's MaxDepth template argument, the size of its vertex arrays)");
        return o;
    }

    template <class Sc>
    static constexpr void check_scene() {
        static_assert(is_surface_scene_v<Sc>, "nsp::BdptEstimator renders a SurfaceScene (NoSurfaces for media alone)");
        if constexpr (!kPerChannel)
            static_assert(!is_per_channel_majorant_v<typename Sc::MajorantType, typename Sc::MediumType>,
                          "nsp::BdptEstimator<..., bdpt::Grey> drives every channel with one pdf and needs a grey "
                          "majorant (channels::SpectralMis: one per channel)");
        static_assert(!(is_control_v<typename Sc::MajorantType, typename Sc::MediumType> &&
                        is_per_channel_majorant_v<typename Sc::MajorantType, typename Sc::MediumType>),
                      "nsp::BdptEstimator takes a grey majorant's control (GridControl, TreeControl, GlobalControl), "
                      "not a per-channel one (ChannelGridControl)");

        static_assert(std::remove_cvref_t<decltype(std::declval<Sc>().lights)>::bidirectional_ready(),
                      "nsp::BdptEstimator: every light model must start light subpaths (EmittingLight: "
                      "sample_emission, emission_pdf) or lie at infinity / be a delta light");
    }

    template <class Sc>
    using VertexT = VertexFor<typename Sc::Spectral>;

    /// A walk's emission callback that does nothing (light subpaths, media without emission).
    struct NoEmission {};

    /// Calls the walk's emission callback at every tentative collision of a tracked piece: `nulls`
    /// the segment's null product before the piece, `along` the segment technique's normaliser
    /// on it (0: the technique does not run).
    template <class Sc, class F>
    struct EmissionVisitor {
        static constexpr bool enabled = true;
        F& f;
        const VertexT<Sc>* path;
        int count, medium;
        const Ray& ray;
        const typename Sc::Spectrum& beta;
        float nulls, pdf_dir, along;
        void operator()(float t, const Coefficients<typename Sc::Spectral>& c, float mu_bar,
                        const typename Sc::Spectrum& w, float null_pdf_product) const {
            f(path, count, medium, ray.at(t), c, mu_bar, mu_bar, typename Sc::Spectrum(beta * w),
              Mis::null_pdfs ? nulls * null_pdf_product : 1.f, pdf_dir, bdpt::NoGamma{}, nulls, along);
        }
    };

    /// Per channel: every channel's null probabilities P_n,c over a tracked piece and its event
    /// density mu_bar_c P_s,c at the piece's real collision, from the coefficients at each
    /// tentative collision (all but a scattering end are nulls).
    template <SpectralMode S, bool kControlled = false>
    struct ChannelNullVisit {
        static constexpr bool enabled = true;
        using Spec = typename S::Spectrum;
        detail::DoubleSpectrum<Spec>* nulls;  // the product of the nulls before the last collision
        Spec* last_null;                      // the last collision's P_n,c, should it be a null
        Spec* last_event;                     // its mu_bar_c P_s,c, should it scatter
        Spec* last_tbar;                      // its Tbar_c since the collision before
        bool* pending;
        // Under a control (kControlled, THEORY 5.10): the collision's residual majorant R, whose
        // null factor P_n,r = mu_n,r / R (d.null is the residual's null density), and exp(-tau_c)
        // so far.
        struct Control {
            float rate = 0.f;
            float transmittance = 1.f;
        };
        [[no_unique_address]] std::conditional_t<kControlled, Control, detail::Empty> control{};
        void under_control(float r, float e) noexcept
            requires kControlled
        {
            control = {r, e};
        }
        /// The piece's exp(-tau_c) to its end, into its null product (tracking is done).
        void control_end(float e) const noexcept { *nulls *= double(e); }
        template <class State>
        void operator()(float, const Coefficients<S>&, const Spec& mu, const Spec& tbar, const State&,
                        const ChannelEventDensities<Spec>& d) const {
            if (*pending) *nulls *= last_null->template cast<double>();
            if constexpr (kControlled)
                *last_null = control.rate > 0.f ? Spec(d.null / control.rate) : Spec(Spec::Zero());
            else
                *last_null = (mu > 0.f).select(d.null / mu, 0.f);
            *last_event = d.scatter;
            *last_tbar = tbar;
            *pending = true;
        }
    };

    /// Per channel: the walk's visitor of a tracked piece, ChannelNullVisit's bookkeeping and, in an
    /// emissive medium, the collision estimator at every tentative collision y (THEORY 5.7 with
    /// 5.3): the throughput up to y over the sampling channel's density of reaching it, every
    /// channel's null product before y and the subpath's shared factors up to y.
    template <class Sc, class F, bool kControlled = false>
    struct ChannelWalkVisit {
        static constexpr bool enabled = true;
        using S = typename Sc::Spectral;
        using Spec = typename S::Spectrum;
        ChannelNullVisit<S, kControlled> null_visit;
        F* emission;  // the walk's emission callback (NoEmission: none)
        const VertexT<Sc>* path;
        int count, medium, channel;
        const Ray& ray;
        const Spec& beta0;  // the throughput where the segment started
        const Spec& nulls;  // the segment's null product before this piece
        float pdf_dir;
        float along;  // the segment technique's normaliser on this piece (0: it does not run)
        void under_control(float r, float e) noexcept
            requires kControlled
        {
            null_visit.under_control(r, e);
        }
        void control_end(float e) const noexcept { null_visit.control_end(e); }
        template <class State>
        void operator()(float t, const Coefficients<S>& k, const Spec& mu, const Spec& tbar, const State& st,
                        const ChannelEventDensities<Spec>& d) const {
            null_visit(t, k, mu, tbar, st, d);
            if constexpr (!std::is_same_v<F, NoEmission>) {
                const float p_here = st.uni[channel] * tbar[channel];
                if (!(p_here > 0.f)) return;
                // The nulls before y (under a control with exp(-tau_c) to y, as the state's f and uni).
                Spec before = nulls * null_visit.nulls->template cast<float>();
                if constexpr (kControlled) before *= null_visit.control.transmittance;
                (*emission)(path, count, medium, ray.at(t), k, mu, mu[channel], Spec(beta0 * st.f * tbar / p_here), before, pdf_dir,
                            relative_to_largest<Spec>(path[count - 1].gamma * st.nee * tbar), nulls, along);
            }
        }
    };

    /// Every channel's factors shared by all strategies, relative to the largest (0 where none is
    /// positive).
    template <class Spec>
    static Spec relative_to_largest(const Spec& g) noexcept {
        const float m = g.maxCoeff();
        return m > 0.f && std::isfinite(m) ? Spec(g / m) : Spec(Spec::Zero());
    }

    /// Where the equiangular strategy draws its vertices (THEORY 5.4 in 5.5): on the part of a
    /// camera segment's ray inside the box around every medium, aimed at the point lights (the
    /// light sampler's targets whose lights are delta: LightSampler::equiangular_point, by their
    /// selection probabilities renormalised over them). Lights a path can hit have tracking's
    /// hits and the light subpaths besides NEE; a point light has NEE and the light subpaths alone.
    struct EqRegion {
        Box box;
        float total = 0.f;  ///< the point lights' equiangular_pmf summed

        /// The technique's density per unit length at distance t along `r` (0 outside the box).
        template <class Sc>
        float density(const Sc& sc, const Ray& r, float t) const noexcept {
            const Interval in = box.clip(r, 0.f, kInf);
            if (in.empty()) return 0.f;
            float p = 0.f;
            for (int k = 0; k < sc.lights.equiangular_count(); ++k)
                if (sc.lights.equiangular_is_delta(k))
                    p += sc.lights.equiangular_pmf(k) * EquiangularSampler(r, sc.lights.equiangular_point(k), in.t0, in.t1).pdf(t);
            return p / total;
        }
        /// The same at distance d from o toward direction w.
        template <class Sc>
        float density(const Sc& sc, const Vec3& o, const Vec3& w, float d) const noexcept {
            return density(sc, Ray{o, w}, d);
        }
        /// A distance along `r` in `in`, the ray's part in the box (a point light by u_pick, then
        /// its equiangular distance by u), with the mixture's density there.
        template <class Sc>
        DistanceSample sample(const Sc& sc, const Ray& r, const Interval& in, float u_pick, float u) const noexcept {
            int pick = -1;
            float cdf = 0.f;
            for (int k = 0; k < sc.lights.equiangular_count(); ++k) {
                if (!sc.lights.equiangular_is_delta(k)) continue;
                pick = k;  // the last point light takes what rounding leaves
                cdf += sc.lights.equiangular_pmf(k) / total;
                if (u_pick < cdf) break;
            }
            if (pick < 0) return {};
            DistanceSample ds = EquiangularSampler(r, sc.lights.equiangular_point(pick), in.t0, in.t1).sample(u);
            if (ds.pdf > 0.f) ds.pdf = density(sc, r, ds.t);
            return ds;
        }
    };

    /// A walk's segment or piece callback that does nothing (light subpaths, the technique off).
    struct NoSegment {};

    /// What the segment technique needs of a light subpath's first segment, y_0 (in an emitting
    /// medium) to y_1: the P_n product of the nulls on its pieces after the first (y_0's own, seen
    /// from y_1), where that first piece ends (the first surface from y_0, kInf: none), and y_1's
    /// direction density toward y_0 (arriving from y_2) in y_0's measure.
    template <class Sc>
    struct FirstSegment {
        bdpt::PdfType<Ch, typename Sc::Spectral> later_nulls = bdpt::broadcast<bdpt::PdfType<Ch, typename Sc::Spectral>>(1.f);
        float first_piece_end = kInf;
        float y0_reverse = 0.f;
    };

    /// A subpath's walk (bdpt_walk.hpp): its state and its steps.
    template <class Sc, class R, class C>
    struct SubpathWalk;

    Kernels kernels_;
    float light_probability_ = 1.f;
};

// ---------------------------------------------------------------------------------------------

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, UniformRng R, LookupCounter C, class Splat, class Observe>
RadianceSample<typename Sc::Spectral> BdptEstimator<Mis, H, A, MaxDepth, Ch>::trace(
    const Sc& sc, const Ray& camera_ray, const Cam* cam, const typename Sc::Spectral::Wavelengths& lambda, R& rng,
    C& counter, Splat& splat, Observe& observe) const {
    check_scene<Sc>();
    using Spectrum = typename Sc::Spectrum;
    using V = VertexT<Sc>;
    if (!usable_ray(camera_ray)) return {Spectrum::Zero(), Status::InvalidInput};
    // NEE at count 0 leaves the lights no path can hit unreached (EstimatorOptions::nee_count).
    if (kernels_.options().nee_count == 0.f && sc.lights.has_delta_lights())
        return {Spectrum::Zero(), Status::InvalidInput};
    detail::record_nee_count_may_be_0(counter, !sc.lights.has_delta_lights());
    // The subpaths' vertices, each written whole before it is read: a Vertex is an implicit-
    // lifetime aggregate, so the storage is left as it is instead of 67 vertices being set to
    // their defaults per sample (a fifth of a sample's time where the subpaths are short).
    static_assert(std::is_aggregate_v<V> && std::is_trivially_destructible_v<V>, "implicit-lifetime vertices");
    alignas(V) std::byte camera_storage[sizeof(V) * (MaxDepth + 2)];
    alignas(V) std::byte light_storage[sizeof(V) * (MaxDepth + 1)];
    V* const camera = std::launder(reinterpret_cast<V*>(camera_storage));
    V* const light = std::launder(reinterpret_cast<V*>(light_storage));
    BdptSample<Sc, Cam, R, C, Splat, Observe> run(*this, sc, cam, lambda, rng, counter, splat, observe, camera, light);
    run.trace_camera_subpath(camera_ray);  // s = 0, the equiangular strategy, the segment technique
    run.trace_light_subpath();
    const int depth = run.depth;
    for (int t = 2; t <= std::min(run.nc, depth + 1); ++t) {
        if (camera[t - 1].delta) continue;
        // s = 1 toward a light is drawn with the NEE count (THEORY 5.9: its estimate divides by
        // it, every path's NEE density carries it); toward the volume and s >= 2 always run.
        if (draw_technique(run.nee_count, rng)) run.light_nee(t, false);
        run.volume_nee(t);
        run.connect(t);
    }
    run.light_trace();  // t = 1
    return run.result();
}

/// Volumetric BDPT with per-channel pdfs (THEORY 5.3 with 5.5): each sample tracks its subpaths
/// and connections with one channel chosen uniformly, every channel keeps its own densities of
/// every vertex (its majorant and event probabilities in the nulls' and events' factors), and the
/// heuristic runs over channels x strategies with one denominator. Any majorant (per-channel ones
/// are what it is for), emissive media included.
template <mis::CombiningHeuristic H = mis::Balance, AbsorptionPolicy A = absorption::Weight, int MaxDepth = 32>
using SpectralBdptEstimator = BdptEstimator<bdpt::NullScattering, H, A, MaxDepth, channels::SpectralMis>;

}  // namespace nsp

// The subpath walk and each sample's named parts, after the declaration of the estimator they
// belong to.
#include "bdpt_walk.hpp"
#include "bdpt_sample.hpp"
