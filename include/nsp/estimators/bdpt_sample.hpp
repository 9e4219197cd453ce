// nsp/estimators/bdpt_sample.hpp: one sample of BdptEstimator::trace (bdpt.hpp) as named parts:
// the state the strategies share, the path's densities, weights and records, the shadow walks and
// the camera subpath here; each strategy family (s = 0 at an emitter and by emission as
// collision, the equiangular and segment strategies, NEE toward the lights and the volume, s >= 2
// connections, light tracing) declared here and defined in bdpt_strategies.hpp. Included by
// bdpt.hpp, after the estimator's declaration.
#pragma once

#include "bdpt.hpp"

namespace nsp {

/// One sample of trace: the state its strategies share (the scene, the sample's wavelengths and
/// random numbers, both subpaths, the path's densities, the estimate) and each strategy family
/// as a named part. trace calls the parts in the order their random numbers are drawn.
template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
struct BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample {
    static constexpr bool kLightTracing = !std::is_same_v<Cam, NoCamera>;
    static constexpr bool kEmissive = EmissiveMedium<typename Sc::MediumType>;
    using Spectrum = typename Sc::Spectrum;
    using V = VertexT<Sc>;
    using P = bdpt::PdfType<Ch, typename Sc::Spectral>;
    using PathPdfsT = PdfsFor<typename Sc::Spectral>;
    using GammaT = bdpt::GammaOf<P>;
    static constexpr int kEq = PathPdfsT::kEquiangular;
    static constexpr int kSeg = PathPdfsT::kSegment;

    const BdptEstimator& est;
    const Sc& sc;
    const Cam* cam;
    const typename Sc::Spectral::Wavelengths& lambda;
    R& rng;
    C& counter;
    Splat& splat;
    Observe& observe;
    V* const camera;  // z_0 .. z_{depth+1}
    V* const light;   // y_0 .. y_{depth-1}, y_depth (light tracing)
    const int depth = est.kernels_.options().max_depth;
    Spectrum L = Spectrum::Zero();
    Status status = Status::Ok;
    PathPdfsT pdfs;
    EqRegion eq_region;
    const EqRegion* eq = nullptr;  // the equiangular strategy's region (null: off)
    int channel = 0;               // per channel: the sample's sampling channel
    // A light subpath is traced with probability light_probability_; it starts in the emitting
    // volume with probability q_volume_share, at a light otherwise (both kinds: one half each);
    // every density of a light subpath's start carries both.
    const bool has_volume = kEmissive && sc.select_emission(0.5f) >= 0;
    // Both carry the light subpath's expected count (THEORY 5.9): a start density times it is the
    // density of a light subpath starting there per sample.
    const float q_volume_share = has_volume ? (sc.lights.has_emitters() ? 0.5f : 1.f) : 0.f;
    const float q_volume = est.light_probability_ * q_volume_share;
    const float q_lights = est.light_probability_ * (1.f - q_volume_share);
    // The segment technique (THEORY 5.7 in 5.5): with null-scattering MIS (directional MIS has no
    // distance pdfs to weigh it against tracking by) in emitting media, the option on.
    const bool seg_on = kEmissive && Mis::null_pdfs && est.kernels_.options().emission_along_segments;
    const float seg_count = est.kernels_.options().emission_segment_count;
    const float nee_count = est.kernels_.options().nee_count;

    // The subpaths' lengths, and what the strategies need of the light subpath's start.
    int nc = 0;
    int nl = 0;
    float nee_y0 = 0.f;         // NEE's density of y_0 from y_1 (with its count at a light)
    float eq_nee_y0 = 0.f;      // the same without the count (the equiangular strategy's; 0 in the volume)
    float emit_y0 = 0.f;        // the light subpath's density of y_0
    bool volume_start = true;  // y_0 lies in the emitting volume (else on a light)
    // The segment technique's density of y_0 (in the volume) drawn from y_1, without y_1's
    // direction density (which depends on where x_2 is), and y_1's from y_2 (s >= 3).
    P seg_y0_unit = bdpt::broadcast<P>(0.f);
    FirstSegment<Sc> first_segment;

    BdptSample(const BdptEstimator& e, const Sc& scene, const Cam* c, const typename Sc::Spectral::Wavelengths& lam,
               R& r, C& cnt, Splat& spl, Observe& obs, V* camera_vertices, V* light_vertices)
        : est(e), sc(scene), cam(c), lambda(lam), rng(r), counter(cnt), splat(spl), observe(obs),
          camera(camera_vertices), light(light_vertices) {
        pdfs.light_tracing = kLightTracing;
        // The equiangular strategy: with null-scattering MIS (directional MIS has no distance pdfs
        // to weigh it against tracking by), the option on, a light with a target and a medium.
        if constexpr (Mis::null_pdfs) {
            for (int k = 0; k < sc.lights.equiangular_count(); ++k)
                if (sc.lights.equiangular_is_delta(k)) eq_region.total += sc.lights.equiangular_pmf(k);
            if (est.kernels_.options().bdpt_equiangular && eq_region.total > 0.f && !sc.media.empty()) {
                eq_region.box = sc.media[0].medium.bounds();
                for (const auto& m : sc.media) {
                    const Box b = m.medium.bounds();
                    eq_region.box.lo = glm::min(eq_region.box.lo, b.lo);
                    eq_region.box.hi = glm::max(eq_region.box.hi, b.hi);
                }
                eq = &eq_region;
            }
        }
        // Per channel: the sample's sampling channel, chosen uniformly (THEORY 5.3). Its light
        // subpath, connections and splats use the same channel, so the one-sample weights of every
        // pixel's strategies share one denominator.
        if constexpr (kPerChannel) {
            constexpr int kChannels = int(Spectrum::SizeAtCompileTime);
            channel = std::min(int(rng.uniform() * float(kChannels)), kChannels - 1);
            pdfs.channel = channel;
        }
    }
    BdptSample(const BdptSample&) = delete;
    BdptSample& operator=(const BdptSample&) = delete;

    /// The sample's estimate: L, or 0 and Status::NonFinite where it is not finite.
    RadianceSample<typename Sc::Spectral> result() const {
        if (!all_finite(L)) return {Spectrum::Zero(), Status::NonFinite};
        return {L, status};
    }

    // ---- The path's densities and the estimate ------------------------------------------------

    /// The equiangular strategy's density of `to` drawn from `from` with direction pdf pdf_dir
    /// there (0 off, and where `to` is no medium vertex).
    P eq_from(const Vec3& from, float pdf_dir, const V& to) const {
        using namespace bdpt;
        if (!eq || to.kind != VertexKind::Medium) return broadcast<P>(0.f);
        const Vec3 d = to.p - from;
        const float len = glm::length(d);
        if (!(len > 0.f)) return broadcast<P>(0.f);
        return broadcast<P>(to_vertex_measure(pdf_dir, from, to) * eq->density(sc, from, d / len, len));
    }

    /// The weight of strategy s for the path in p (per channel: its factor of the sampling
    /// channel's throughput).
    auto weight_of(const PathPdfsT& p, int s) const {
        using namespace bdpt;
        if constexpr (kPerChannel) return channel_strategy_weight(est.kernels_.heuristic(), p, s);
        else return strategy_weight(est.kernels_.heuristic(), p, s);
    }

    /// The segment technique's density of x_0 = y drawn from x_1 on y's piece: the direction
    /// density at x_1 in y's measure (g), the nulls of the pieces before y's, p_V(y) / W with W the
    /// normaliser `along`.
    P seg_density(float g, const P& nulls_before, float p_v, float along) const {
        using namespace bdpt;
        if (!seg_on) return broadcast<P>(0.f);
        return nulls_before * (g * segment_density(est.kernels_.options(), p_v, along));
    }

    /// A BdptRecorder (NeeCountLearner) sees every strategy's contribution with the path's pdfs
    /// summed by count group: s = 0 (and NEE toward the volume, `volume_x0`) at count 1, NEE toward
    /// a light at nee_count, s >= 2 and t = 1 at the light subpath probability (THEORY 5.9).
    /// Per channel the sums run over channels x strategies, each channel's weighed by its
    /// selection probability (the one-sample denominator, THEORY 5.3 with 5.9).
    void record(int s, const Spectrum& f, const PathPdfsT& p, bool volume_x0, bool splatted) {
        using namespace bdpt;
        if constexpr (BdptRecorder<C>) {
            const int n = strategy_count(p);
            double p_fixed = 0.0, p_nee = 0.0, p_light = 0.0, own = 0.0;
            auto add_group = [&](const double* q, double selection) {
                // The equiangular strategy (count 1) and the segment technique (its own count).
                p_fixed += selection * (q[0] + q[kEq] + q[kSeg]);
                if (n > 1) (volume_x0 ? p_fixed : p_nee) += selection * q[1];
                for (int r = 2; r < n; ++r) p_light += selection * q[r];
            };
            if constexpr (kPerChannel) {
                constexpr int kChannels = int(Spectrum::SizeAtCompileTime);
                double q[kChannels * PathPdfsT::kSlots];
                if (!channel_strategy_pdfs(p, q)) return;
                for (int ch = 0; ch < kChannels; ++ch) add_group(q + ch * PathPdfsT::kSlots, 1.0 / kChannels);
                own = q[p.channel * PathPdfsT::kSlots + s];
            } else {
                double q[PathPdfsT::kSlots];
                if (!strategy_pdfs(p, q)) return;
                add_group(q, 1.0);
                own = q[s];
            }
            const BdptTechnique group = s == 0 || s == kEq || s == kSeg ? BdptTechnique::Fixed
                                        : s == 1 ? (volume_x0 ? BdptTechnique::Fixed : BdptTechnique::Nee)
                                                 : BdptTechnique::Light;
            detail::record_bdpt(counter, float(double(f.mean()) * own), float(p_fixed),
                                nee_count > 0.f ? float(p_nee / double(nee_count)) : 0.f,
                                est.light_probability_ > 0.f ? float(p_light / double(est.light_probability_)) : 0.f,
                                nee_count, est.light_probability_, group,
                                splatted);
        } else {
            (void)s, (void)f, (void)p, (void)volume_x0, (void)splatted;
        }
    }

    /// Adds strategy s's contribution f (t camera vertices, x_0 at `x0`) to L with its weight.
    void add(int s, int t, const Spectrum& f, const PathPdfsT& p, const Vec3& x0, bool x0_at_infinity = false,
             bool volume_x0 = false) {
        using namespace bdpt;
        const float w = weight_of(p, s);
        record(s, f, p, volume_x0, false);
        // The equiangular strategy's vertices are s = 1's, the segment technique's s = 0's.
        const int sv = s == kEq ? 1 : s == kSeg ? 0 : s;
        observe(s, t, f, w, p,
                PathVertices<typename Sc::Spectral, P>{light, sv, camera, sv == 0 ? t - 1 : t, x0, x0_at_infinity});
        L += f * w;
    }

    /// The BSDF or phase function at vertex v.
    auto eval_at(const V& v, const Vec3& wo, const Vec3& wi) const {
        return eval_vertex(sc, v.scene_vertex(), wo, wi, lambda);
    }

    /// Fills pdfs with the path of k + 1 vertices made of light[0..s-1] (x_0..x_{s-1}) and
    /// camera[0..nz-1] (x_k..x_{k-nz+1}) from the subpaths' stored densities; the caller then sets
    /// x_0's and the densities that its connection changes.
    void gather(int s, int nz, int k) {
        using namespace bdpt;
        pdfs.k = k;
        pdfs.eq = broadcast<P>(0.f);
        pdfs.seg = broadcast<P>(0.f);
        pdfs.eq_nee = 0.f;
        for (int i = 0; i < s; ++i) {
            pdfs.from_light[i] = light[i].pdf_fwd;
            pdfs.from_camera[i] = light[i].pdf_rev;
            pdfs.connectible[i] = !light[i].delta;
        }
        for (int j = 0; j < nz; ++j) {
            const int i = k - j;
            pdfs.from_camera[i] = camera[j].pdf_fwd;
            pdfs.from_light[i] = camera[j].pdf_rev;
            pdfs.connectible[i] = !camera[j].delta;
        }
        pdfs.connectible[0] = true;
    }

    // ---- Shadow walks -------------------------------------------------------------------------

    /// A shadow ray's (a connection's) transmittance through the scene, ratio-tracked: its
    /// throughput (per channel f_lambda / p_c*), its nulls' P_n product and, per channel, the
    /// factor every strategy of the path shares over it (prod mu_bar_c(n_j) Tbar_c).
    struct Shadow {
        Status status = Status::Ok;
        Spectrum tr = Spectrum::Zero();
        P nulls = bdpt::broadcast<P>(1.f);
        GammaT gamma = bdpt::unit_gamma<P>();
    };

    /// One piece of a shadow walk (ratio tracking through one medium), grey or per channel.
    auto shadow_piece(int m, const Ray& r, float t_max, const Spectrum& f) {
        const auto& med = sc.media[std::size_t(m)];
        if constexpr (kPerChannel)
            return detail::channel_shadow_piece<Ch, A>(med.medium, med.majorant, r, t_max, lambda, channel, f, true, rng,
                                                       counter);
        else
            return (void)f, detail::grey_shadow_piece(est.kernels_, med.medium, med.majorant, r, t_max, lambda, rng,
                                                      counter);
    }

    /// The shadow walk along r up to `distance` from medium `start`. `end_medium`, if given,
    /// receives the medium the ray ends in.
    Shadow shadow(const Ray& r, float distance, int start, int* end_medium = nullptr) {
        const auto sh = walk_shadow<P>(sc, r, start, WalkEnd{distance}, lambda, pieces());
        if (end_medium && sh.status == Status::Ok && sh.reached) *end_medium = sh.end_medium;
        return as_shadow(sh);
    }

    /// A walk's or one piece's products (f, nee, uni, on one scale: walk_shadow) as a Shadow: per
    /// channel f_lambda / p_c* and the nulls' P_n relative to the sampling channel's NEE density.
    Shadow as_shadow(Status walked, bool reached, const Spectrum& f, const P& nee, const P& uni) const {
        Shadow out;
        out.status = walked;
        if (walked != Status::Ok || !reached) return out;
        if constexpr (kPerChannel) {
            // A sampling channel's density below float's range beside another's: its weight is 0.
            if (!(f != 0.f).any() || !(nee[channel] > 0.f)) return out;
            out.tr = f / nee[channel];
            out.nulls = (nee > 0.f).select(uni / nee, 0.f);
            out.gamma = relative_to_largest<Spectrum>(nee);
        } else {
            (void)nee;
            out.tr = f;
            out.nulls = Mis::null_pdfs ? uni : 1.f;
        }
        return out;
    }

    /// A shadow walk's (walk_shadow's) Shadow.
    Shadow as_shadow(const ShadowWalk<P, typename Sc::Spectral>& sh) const {
        return as_shadow(sh.status, sh.reached, sh.f, sh.nee, sh.uni);
    }

    /// shadow_piece as the callable walk_shadow takes.
    auto pieces() {
        return [this](int m, const Ray& r, float t_max, const Spectrum& f) { return shadow_piece(m, r, t_max, f); };
    }

    /// Transmittance of a connection a -> b through the scene, with its nulls' P_n product and
    /// shared factors (its work the light subpath's).
    Spectrum transmit(const V& a, const V& b, P& nulls, GammaT& gamma) {
        const Vec3 d = b.p - a.p;
        const float dist = glm::length(d);
        if (!(dist > 0.f)) return Spectrum::Zero();
        const Vec3 w = d / dist;
        const double before = detail::recorder_work(counter);
        const Shadow sh = shadow(Ray{a.p, w}, dist, a.medium_toward(w));
        detail::record_light_walk(counter, before);
        if (sh.status != Status::Ok) {
            status = sh.status;
            return Spectrum::Zero();
        }
        nulls = sh.nulls;
        gamma = sh.gamma;
        return sh.tr;
    }

    /// The shared factors of a path made of pieces (per channel), relative to the largest.
    template <class... G>
    auto path_gamma(const G&... g) const {
        if constexpr (kPerChannel) return relative_to_largest<Spectrum>((... * g));
        else return bdpt::NoGamma{};
    }

    /// The walk of a subpath from path[0] (the camera or y_0) along `ray`, in `medium`, with
    /// direction density `pdf_dir` and throughput `beta` (SubpathWalk).
    SubpathWalk<Sc, R, C> subpath(V* path, int max_vertices, const Ray& ray, int medium, float pdf_dir,
                                  const Spectrum& beta, bool camera_side, FirstSegment<Sc>* first = nullptr) {
        return {est, sc, path, 1, max_vertices, ray, medium, pdf_dir, beta, lambda, channel, rng, counter, status, eq,
                camera_side, first};
    }

    // ---- The camera subpath and the strategies that run while it is tracked -----------------

    /// Tracks the camera subpath from camera_ray; s = 0 (hit_emitter, emission_collision), the
    /// equiangular strategy and the segment technique run inside the walk as it goes.
    void trace_camera_subpath(const Ray& camera_ray) {
        using namespace bdpt;
        camera[0] = V{};
        camera[0].kind = VertexKind::Camera;
        camera[0].p = camera_ray.o;
        camera[0].beta = Spectrum::Ones();
        camera[0].medium = sc.camera_medium;
        if constexpr (kPerChannel) camera[0].gamma = Spectrum::Ones();
        float camera_pdf = 0.f;  // the camera's density of the ray's direction (light tracing), else 0
        if constexpr (kLightTracing) camera_pdf = cam->pdf_dir(camera_ray.d);
        auto on_hit = [&](V* path, int count, const SurfaceHit& hit, const Ray& ray, const P& nulls,
                          const Spectrum& beta, const auto& gamma) {
            hit_emitter(path, count, hit, ray, nulls, beta, gamma);
        };
        auto on_segment = [this](V* path, int count, const Ray& ray, int medium, float pdf_dir, const Spectrum& beta) {
            equiangular(path, count, ray, medium, pdf_dir, beta);
        };
        if constexpr (kEmissive) {
            auto on_emission = [&](const V* path, int count, int medium, const Vec3& y,
                                   const Coefficients<typename Sc::Spectral>& c, const P& mu_bar, float mu_sample,
                                   const Spectrum& beta, const P& nulls, float pdf_dir, const auto& gamma,
                                   const P& nulls_before, float along) {
                emission_collision(path, count, medium, y, c, mu_bar, mu_sample, beta, nulls, pdf_dir, gamma,
                                   nulls_before, along);
            };
            auto on_piece = [&](V* path, int count, const Ray& ray, int medium, float t_max, float pdf_dir,
                                const Spectrum& beta, const P& nulls_before, const auto& gamma) -> float {
                return segment(path, count, ray, medium, t_max, pdf_dir, beta, nulls_before, gamma);
            };
            nc = subpath(camera, depth + 2, camera_ray, sc.camera_medium, camera_pdf, Spectrum::Ones(), true)
                     .run(on_hit, on_emission, on_segment, on_piece);
        } else {
            nc = subpath(camera, depth + 2, camera_ray, sc.camera_medium, camera_pdf, Spectrum::Ones(), true)
                     .run(on_hit, NoEmission{}, on_segment);
        }
    }

    /// s = 0: the camera subpath reaches an emitter after camera[0..t-2]; and the lights at
    /// infinity.
    template <class G>
    void hit_emitter(V* path, int count, const SurfaceHit& hit, const Ray& ray, const P& nulls, const Spectrum& beta,
                     const G& gamma);

    /// s = 0 for one light: its emission Le toward the camera subpath's vertex z = x_1, at
    /// distance `dist` (kInf: a light at infinity).
    template <class G>
    void hit_one_emitter(int t, const V& z, const SurfaceHit& hit, const Ray& ray, const P& nulls,
                         const Spectrum& beta, const G& gamma, int light_index, const Spectrum& Le, float dist);

    /// The densities of the path made of the camera subpath camera[0..count-1] and x_0 = y in
    /// emitting medium `medium` (the collision estimator's and the segment technique's paths): y
    /// reached from x_1 = camera[count - 1] with direction density pdf_dir, `nulls` the P_n of
    /// the segment's nulls before y, `nulls_before` those of the pieces before y's, mu_bar the
    /// majorant at y, `along` the segment technique's W on y's piece, `gamma` (per channel) the
    /// shared factors up to y. False where y is x_1 itself (a flight of length 0: no direction).
    template <class G>
    bool emission_path_pdfs(int count, int medium, const Vec3& y, const P& nulls, const P& mu_bar, float pdf_dir,
                            const P& nulls_before, float along, const G& gamma);

    /// s = 0 in an emissive medium: the camera subpath's tentative collision at y, after
    /// camera[0..count-1], collects mu_a L_e / mu_bar (the collision estimator); as a path ending
    /// at y its camera-side density is the direction pdf / d^2 x the nulls' P_n x mu_bar(y).
    /// `mu_bar` the majorant at y (per channel: every channel's), `mu_sample` the sampling
    /// channel's, `beta` the throughput up to y over the density of reaching it, `gamma` (per
    /// channel) the shared factors up to y, `nulls_before` the nulls' P_n on the segment's pieces
    /// before y's and `along` the segment technique's normaliser on y's piece.
    template <class G>
    void emission_collision(const V* path, int count, int medium, const Vec3& y,
                            const Coefficients<typename Sc::Spectral>& c, const P& mu_bar, float mu_sample,
                            const Spectrum& beta, const P& nulls, float pdf_dir, const G& gamma, const P& nulls_before,
                            float along);

    /// The equiangular strategy (THEORY 5.4 in 5.5) on the camera segment from z = path[count - 1]
    /// along `ray` (in `medium`, throughput `beta` past z's direction sample): x drawn on the ray's
    /// part in the media's box by equiangular sampling toward the lights' targets, the nulls before
    /// it ratio-tracked, stored as z_t-1 = path[count] (the walk writes its own next vertex there
    /// afterwards) and connected to the lights by NEE.
    void equiangular(V* path, int count, const Ray& ray, int medium, float pdf_dir, const Spectrum& beta);

    /// The segment technique (THEORY 5.7 in 5.5) on a camera segment's piece in emitting medium
    /// `medium` (from z = path[count - 1] along `ray` up to t_max; `pdf_dir` z's direction density,
    /// `beta` the throughput at the piece's start, `nulls_before` the P_n of the segment's nulls
    /// before it, `gamma` the shared factors up to it): x_0 drawn in proportion to the medium's
    /// power grid along the piece (with the count EstimatorOptions::emission_segment_count), the
    /// nulls before it ratio-tracked, mu_a L_e collected there. Returns the piece's normaliser W,
    /// which the collision estimator's weights on the piece need (0: the technique does not run).
    template <class G>
    float segment(V* path, int count, const Ray& ray, int medium, float t_max, float pdf_dir, const Spectrum& beta,
                  const P& nulls_before, const G& gamma);

    // ---- s = 1: next-event estimation -------------------------------------------------------

    /// s = 1 from camera vertex z = camera[t - 1] toward the lights (THEORY 5.9: drawn with the
    /// NEE count), or, `from_eq`, the equiangular strategy's NEE from its vertex there, which
    /// always runs: no count.
    void light_nee(int t, bool from_eq);

    /// s = 1 toward the emitting volume (THEORY 5.7) from camera vertex z = camera[t - 1]: a point
    /// drawn by the power grids, the shadow walk through every medium up to it.
    void volume_nee(int t);

    // ---- The light subpath and the strategies that use it -----------------------------------

    /// The light subpath, traced with probability light_probability_ (THEORY 5.9): from the
    /// emitting volume (light_from_volume) or from a light (light_from_emitter).
    void trace_light_subpath();

    /// A light subpath of at most light_vertices vertices from a point y_0 drawn in the emitting
    /// volume by the media's power, with y_0's densities for NEE and the segment technique.
    void light_from_volume(int light_vertices);

    /// A light subpath of at most light_vertices vertices from a light's emission sample, with
    /// y_0's densities for NEE (and the equiangular strategy's NEE).
    void light_from_emitter(int light_vertices);

    /// s >= 2: connects every light vertex y = y_{s-1} to camera vertex z = camera[t - 1].
    void connect(int t);

    /// t = 1 (light tracing): every light vertex y = y_{s-1} seen by the camera, splatted where it
    /// appears on the image.
    void light_trace();
};

}  // namespace nsp

#include "bdpt_strategies.hpp"
