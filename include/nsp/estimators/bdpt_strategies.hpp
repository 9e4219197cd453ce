// nsp/estimators/bdpt_strategies.hpp: the strategy families of one BDPT sample, the members of
// BdptEstimator::BdptSample (bdpt_sample.hpp, where each is declared and described) that weigh a
// path against the others: s = 0 at an emitter and by emission as collision, the equiangular and
// segment strategies on the camera subpath, NEE toward the lights and the volume (s = 1), the
// light subpath, s >= 2 connections and light tracing (t = 1). Included by bdpt_sample.hpp.
#pragma once

#include "bdpt_sample.hpp"

namespace nsp {
template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
template <class G>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::hit_emitter(
    V* path, int count, const SurfaceHit& hit, const Ray& ray, const P& nulls, const Spectrum& beta, const G& gamma) {
    const int t = count + 1;  // the emitter is z_{t-1}
    if (t - 2 > depth) return;
    const V& z = path[count - 1];  // the vertex the segment left (x_1)
    if (!hit.found()) {
        for (const int i : sc.lights.infinite())
            hit_one_emitter(t, z, hit, ray, nulls, beta, gamma, i, sc.lights.emitted(i, ray.d, lambda), kInf);
    } else {
        hit_one_emitter(t, z, hit, ray, nulls, beta, gamma, hit.light,
                        sc.lights.emitted(hit.light, hit.shading(), ray.d, lambda), hit.t);
    }
}

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
template <class G>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::hit_one_emitter(
    int t, const V& z, const SurfaceHit& hit, const Ray& ray, const P& nulls, const Spectrum& beta, const G& gamma,
    int light_index, const Spectrum& Le, float dist) {
    using namespace bdpt;
    if (!(Le != 0.f).any()) return;
    const Spectrum f = beta * Le;
    if constexpr (kPerChannel) pdfs.gamma = gamma;
    else (void)gamma;
    if (t == 2) {  // the camera sees the emitter: the only strategy
        pdfs.k = 1;
        // Per channel its nulls' P_n,c still weigh the channels; grey, 1 (one strategy).
        if constexpr (kPerChannel) pdfs.from_camera[0] = nulls;
        else pdfs.from_camera[0] = 1.f;
        pdfs.nee = pdfs.emit = 0.f;
        pdfs.seg = broadcast<P>(0.f);
        add(0, 2, f, pdfs, std::isfinite(dist) ? hit.p : z.p, !std::isfinite(dist));
        return;
    }
    gather(0, t - 1, t - 1);  // camera[0..t-2]; the emitter is x_0
    const Vec3 w = ray.d;  // from x_1 toward x_0
    const float pdf_dir_z = z.kind == VertexKind::Camera ? 0.f : eval_at(z, z.wo, w).pdf;
    if (std::isfinite(dist)) {
        const Vec3 d = hit.p - z.p;
        const float d2 = glm::dot(d, d);
        const ShadingPoint at = hit.shading();  // what a light's densities may read of the hit
        const EmissionDensity e = sc.lights.emission_pdf(light_index, at, -w);
        const float cos0 = std::abs(glm::dot(hit.ng, w));
        pdfs.from_camera[0] = (z.delta ? 1.f : pdf_dir_z) * cos0 / d2 * nulls;
        pdfs.emit = q_lights * e.pdf_pos;
        pdfs.eq_nee = sc.lights.pdf(light_index, z.p, w, at) * cos0 / d2;
        pdfs.nee = nee_count * pdfs.eq_nee;
        pdfs.from_light[1] = to_vertex_measure(e.pdf_dir, hit.p, z) * nulls * z.event;
    } else {  // x_0 is the direction w; light subpaths (if any) reach z along -w
        const EmissionDensity e = sc.lights.emission_pdf(light_index, z.p, -w);
        pdfs.from_camera[0] = (z.delta ? 1.f : pdf_dir_z) * nulls;
        pdfs.emit = q_lights * e.pdf_pos;
        pdfs.eq_nee = sc.lights.pdf(light_index, z.p, w);
        pdfs.nee = nee_count * pdfs.eq_nee;
        pdfs.from_light[1] = from_infinity_measure(e.pdf_dir, -w, z) * nulls * z.event;
    }
    pdfs.eq = z.eq;
    // z's own density from the light side: from x_1 toward x_2, arriving along -w.
    if (t >= 4) {
        const V& z2 = camera[t - 3];  // x_2
        const float pd = z.delta ? 1.f : eval_at(z, -w, -z.wo).pdf;
        pdfs.from_light[2] = to_vertex_measure(pd, z.p, z2) * z.nulls_in * z2.event;
    }
    add(0, t, f, pdfs, std::isfinite(dist) ? hit.p : z.p, !std::isfinite(dist));
}

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
template <class G>
bool BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::emission_path_pdfs(
    int count, int medium, const Vec3& y, const P& nulls, const P& mu_bar, float pdf_dir, const P& nulls_before,
    float along, const G& gamma) {
    using namespace bdpt;
    if constexpr (!kEmissive) {
        (void)count, (void)medium, (void)y, (void)nulls, (void)mu_bar, (void)pdf_dir, (void)nulls_before,
            (void)along, (void)gamma;
        return false;
    } else {
        const float p_y = sc.media[std::size_t(medium)].medium.emission_pdf(y);
        if constexpr (kPerChannel) pdfs.gamma = gamma;
        else (void)gamma;
        const int t = count + 1;
        if (t == 2) {  // seen from the camera: the collision estimator and the segment technique
            pdfs.k = 1;
            // Relative to the camera's density of the ray and 1 / d^2, the same for both.
            pdfs.from_camera[0] = nulls * mu_bar;
            pdfs.nee = pdfs.emit = 0.f;
            pdfs.seg = seg_density(1.f, nulls_before, p_y, along);
            return true;
        }
        const V& z = camera[count - 1];  // x_1
        const Vec3 d = y - z.p;
        const float d2 = glm::dot(d, d);
        if (!(d2 > 0.f)) return false;
        gather(0, t - 1, t - 1);
        const float p_v = sc.emission_selection_pdf(medium) * p_y;
        pdfs.from_camera[0] = pdf_dir / d2 * nulls * mu_bar;
        pdfs.seg = seg_density(pdf_dir / d2, nulls_before, p_y, along);
        pdfs.nee = p_v;
        pdfs.emit = q_volume * p_v;
        pdfs.from_light[1] = to_vertex_measure(kInv4Pi, y, z) * nulls * z.event;
        if (t >= 4) {
            const V& z2 = camera[count - 2];  // x_2
            const float pd = z.delta ? 1.f : eval_at(z, -(d / std::sqrt(d2)), -z.wo).pdf;
            pdfs.from_light[2] = to_vertex_measure(pd, z.p, z2) * z.nulls_in * z2.event;
        }
        return true;
    }
}

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
template <class G>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::emission_collision(
    const V* path, int count, int medium, const Vec3& y, const Coefficients<typename Sc::Spectral>& c, const P& mu_bar,
    float mu_sample, const Spectrum& beta, const P& nulls, float pdf_dir, const G& gamma, const P& nulls_before,
    float along) {
    if constexpr (kEmissive) {
        const int t = count + 1;
        if (t - 2 > depth || !(c.sigma_a > 0.f).any() || !(mu_sample > 0.f)) return;
        const auto& m = sc.media[std::size_t(medium)].medium;
        const Spectrum le = m.emission(y, lambda);
        if (!(le > 0.f).any()) return;
        const Spectrum f = beta * c.sigma_a * le / mu_sample;
        (void)path;  // camera[], which emission_path_pdfs reads
        if (emission_path_pdfs(count, medium, y, nulls, mu_bar, pdf_dir, nulls_before, along, gamma))
            add(0, t, f, pdfs, y, false, true);
    } else {
        (void)path, (void)count, (void)medium, (void)y, (void)c, (void)mu_bar, (void)mu_sample, (void)beta,
            (void)nulls, (void)pdf_dir, (void)gamma, (void)nulls_before, (void)along;
    }
}

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::equiangular(
    V* path, int count, const Ray& ray, int medium, float pdf_dir, const Spectrum& beta) {
    using namespace bdpt;
    const int t = count + 1;
    if (!eq || t - 1 > depth) return;
    const V& z = path[count - 1];
    const Interval in = eq->box.clip(ray, 0.f, kInf);
    if (in.empty()) return;
    const float u_pick = rng.uniform(), u = rng.uniform();
    const DistanceSample ds = eq->sample(sc, ray, in, u_pick, u);
    if (!(ds.pdf > 0.f && ds.t > 0.f)) return;
    const double before = detail::recorder_work(counter);
    int at = -1;
    const Shadow sh = shadow(ray, ds.t, medium, &at);
    detail::record_shadow_walk(counter, before, false);
    if (sh.status != Status::Ok) status = sh.status;
    if (sh.status != Status::Ok || !(sh.tr != 0.f).any() || !sc.has_medium(at)) return;
    const auto& m = sc.media[std::size_t(at)];
    const auto c = detail::lookup_untracked(m.medium, m.majorant, ray, ds.t, lambda, counter);
    if (!c) {
        status = Status::Rejected;
        return;
    }
    if (!(c->k.sigma_s > 0.f).any()) return;
    V& x = path[count];
    x = V{};
    x.kind = VertexKind::Medium;
    x.p = ray.at(ds.t);
    x.medium = at;
    x.wo = ray.d;
    x.beta = beta * sh.tr * c->k.sigma_s / ds.pdf;
    x.nulls_in = sh.nulls;
    // Tracking's event density mu_bar P_s at x (per channel, every channel's); under a control,
    // decomposition tracking's: the sum of its control and residual routes (THEORY 5.10), as the
    // walk's DeltaTrack::event_density.
    if constexpr (kPerChannel) {
        x.event = channel_event_densities<A, typename Sc::Spectral>(c->k, majorants<P>(c->mu)).scatter;
        if constexpr (std::is_same_v<std::remove_cvref_t<decltype(c->mu)>, float>)  // a control's majorant is grey
            if (c->ctl > 0.f)
                x.event = nsp::detail::channel_decomposition_densities<Ch, A, typename Sc::Spectral>(
                              c->k, c->ctl, c->mu, Spectrum::Ones())
                              .scatter;
    } else if (c->ctl > 0.f)
        x.event = nsp::detail::decomposition_event_densities<A>(c->k, c->ctl, c->mu).scatter;
    else
        x.event = c->mu * event_probabilities<A>(c->k, c->mu).scatter;
    const float pd = z.kind == VertexKind::Camera && !(pdf_dir > 0.f) ? 1.f : pdf_dir;  // as the walk's
    const float g = to_vertex_measure(pd, z.p, x);
    x.pdf_fwd = g * sh.nulls * x.event;
    x.eq = broadcast<P>(g * ds.pdf);
    if constexpr (kPerChannel) x.gamma = path_gamma(z.gamma, sh.gamma);
    if ((x.beta != 0.f).any()) light_nee(t, true);
}

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
template <class G>
float BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::segment(
    V* path, int count, const Ray& ray, int medium, float t_max, float pdf_dir, const Spectrum& beta,
    const P& nulls_before, const G& gamma) {
    using namespace bdpt;
    if constexpr (kEmissive) {
        (void)path;  // camera[], which emission_path_pdfs reads
        const int t = count + 1;
        if (!seg_on || t - 2 > depth) return 0.f;
        // Its work is a fixed technique's to the learner: it runs whatever the learned counts.
        const double before = detail::recorder_work(counter);
        const auto d = draw_segment<P>(
            sc, medium, ray, t_max, seg_count,
            [&](const Ray& r, float t_y) { return shadow_piece(medium, r, t_y, Spectrum::Ones()); }, lambda, rng, counter);
        if (d.ran) detail::record_shadow_walk(counter, before, false);
        if (d.status != Status::Ok) status = d.status;
        if (!d.drawn) return d.along;  // (the piece is tracked only where y was drawn)
        const Shadow sh = as_shadow(Status::Ok, true, d.piece.f, d.piece.nee, d.piece.uni);
        if (!(sh.tr != 0.f).any()) return d.along;
        const Vec3 y = ray.at(d.distance.t);
        const Spectrum le = sc.media[std::size_t(medium)].medium.emission(y, lambda);
        if (!(le > 0.f).any()) return d.along;
        const Spectrum f = beta * sh.tr * d.c.k.sigma_a * le / (seg_count * d.distance.pdf);
        if (emission_path_pdfs(count, medium, y, P(nulls_before * sh.nulls), majorants<P>(d.c.mu), pdf_dir,
                               nulls_before, d.along, path_gamma(gamma, sh.gamma)))
            add(kSeg, t, f, pdfs, y, false, true);
        return d.along;
    } else {
        (void)path, (void)count, (void)ray, (void)medium, (void)t_max, (void)pdf_dir, (void)beta,
            (void)nulls_before, (void)gamma;
        return 0.f;
    }
}

// ---- s = 1: next-event estimation -------------------------------------------------------

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::light_nee(int t, bool from_eq) {
    using namespace bdpt;
    const V& z = camera[t - 1];
    const float count = from_eq ? 1.f : nee_count;
    const auto d = draw_light_nee<P>(
        sc, z.scene_vertex(), z.p, z.wo, [&](const Vec3& wi) { return z.medium_toward(wi); },
        [&](int m, const Ray& r, float t_max, const Spectrum& f, bool) { return shadow_piece(m, r, t_max, f); },
        !from_eq, lambda, rng, counter);
    if (!d) return;
    const Shadow sh = as_shadow(d->walk);
    if (sh.status != Status::Ok) status = sh.status;
    if (sh.status != Status::Ok || !(sh.tr != 0.f).any()) return;
    const SampledLight<typename Sc::Spectral>& ls = d->light;
    const auto& fz = d->vertex;
    const Vec3 w = ls.sample.wi;
    V y0;
    y0.kind = VertexKind::Light;
    y0.delta_position = ls.sample.delta;
    const bool at_infinity = !std::isfinite(ls.sample.distance);
    y0.p = at_infinity ? z.p : z.p + ls.sample.distance * w;
    const P& nulls = sh.nulls;
    const Spectrum f = z.beta * fz.value * sh.tr * ls.sample.radiance / (count * ls.sample.pdf);
    gather(0, t, t);  // camera[0..t-1]; the light point is x_0
    if constexpr (kPerChannel) pdfs.gamma = path_gamma(z.gamma, sh.gamma);
    const float d2 = ls.sample.distance * ls.sample.distance;
    if (ls.sample.delta) {  // a point or directional light: no path hits it
        pdfs.from_camera[0] = broadcast<P>(0.f);
        pdfs.eq_nee = ls.sample.pdf;
        // Light subpaths from a directional light (given a BoundingSphere) start on the
        // sphere's disk: pdf_pos its delta, pdf_dir per area across w.
        const EmissionDensity e = sc.lights.emission_pdf(ls.light, at_infinity ? z.p : y0.p, -w);
        pdfs.emit = q_lights * e.pdf_pos;
        pdfs.from_light[1] = (at_infinity ? from_infinity_measure(e.pdf_dir, -w, z)
                                          : to_vertex_measure(e.pdf_dir, y0.p, z)) *
                             nulls * z.event;
    } else if (at_infinity) {
        const EmissionDensity e = sc.lights.emission_pdf(ls.light, z.p, -w);
        pdfs.from_camera[0] = fz.pdf * nulls;
        pdfs.eq_nee = ls.sample.pdf;
        pdfs.emit = q_lights * e.pdf_pos;
        pdfs.from_light[1] = from_infinity_measure(e.pdf_dir, -w, z) * nulls * z.event;
    } else {
        const EmissionDensity e =
            sc.lights.emission_pdf(ls.light, light_point(y0.p, ls.sample.uv, ls.sample.user), -w);
        pdfs.from_camera[0] = fz.pdf * e.cos / d2 * nulls;
        pdfs.eq_nee = ls.sample.pdf * e.cos / d2;
        pdfs.emit = q_lights * e.pdf_pos;
        pdfs.from_light[1] = to_vertex_measure(e.pdf_dir, y0.p, z) * nulls * z.event;
    }
    pdfs.nee = nee_count * pdfs.eq_nee;
    pdfs.eq = z.eq;
    if (t >= 3) {
        const V& z2 = camera[t - 2];
        pdfs.from_light[2] = to_vertex_measure(eval_at(z, w * -1.f, -z.wo).pdf, z.p, z2) * z.nulls_in * z2.event;
    }
    add(from_eq ? kEq : 1, t, f, pdfs, y0.p, at_infinity);
}

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::volume_nee(int t) {
    using namespace bdpt;
    if constexpr (kEmissive) {
        const V& z = camera[t - 1];
        if (!has_volume) return;
        const auto d = draw_volume_nee<P>(
            sc, z.scene_vertex(), z.p, z.wo, [&](const Vec3& wi) { return z.medium_toward(wi); },
            seg_on, pieces(), lambda, rng, counter);
        if (d.status != Status::Ok) status = d.status;
        const Shadow sh = as_shadow(d.walk);
        if (!d.drawn || !(sh.tr != 0.f).any() || !(majorant_at(d.c.mu, channel) > 0.f)) return;
        const detail::EmissionPoint& e = d.point;
        const float p_v = e.select * e.y.pdf;
        const Spectrum f = z.beta * d.vertex.value * sh.tr * d.c.k.sigma_a *
                           sc.media[std::size_t(e.index)].medium.emission(e.y.p, lambda) / (e.dist2 * p_v);
        const P& nulls = sh.nulls;
        // The segment technique's P_n of the nulls before the point's piece: uni of the pieces
        // before it times nee of its own (walk_shadow's seg), relative as sh.nulls.
        P nulls_before;
        if constexpr (kPerChannel)
            nulls_before = (d.walk.nee > 0.f).select(d.walk.seg / d.walk.nee, 0.f);
        else
            nulls_before = Mis::null_pdfs ? d.walk.seg : 1.f;
        gather(0, t, t);  // camera[0..t-1]; the emission point is x_0
        if constexpr (kPerChannel) pdfs.gamma = path_gamma(z.gamma, sh.gamma);
        pdfs.from_camera[0] = d.vertex.pdf / e.dist2 * nulls * majorants<P>(d.c.mu);
        pdfs.seg = seg_density(d.vertex.pdf / e.dist2, nulls_before, e.y.pdf, d.walk.along);
        pdfs.nee = p_v;
        pdfs.emit = q_volume * p_v;
        pdfs.from_light[1] = to_vertex_measure(kInv4Pi, e.y.p, z) * nulls * z.event;
        if (t >= 3) {
            const V& z2 = camera[t - 2];
            pdfs.from_light[2] =
                to_vertex_measure(eval_at(z, -e.wi, -z.wo).pdf, z.p, z2) * z.nulls_in * z2.event;
        }
        add(1, t, f, pdfs, e.y.p, false, true);
    } else {
        (void)t;
    }
}

// ---- The light subpath and the strategies that use it -----------------------------------

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::trace_light_subpath() {
    const int light_vertices = kLightTracing ? depth + 1 : depth;
    const bool traced = draw_technique(est.light_probability_, rng);
    const double light_work_before = detail::recorder_work(counter);
    if (traced && depth >= (kLightTracing ? 1 : 2)) {
        const float uq = q_volume_share > 0.f && q_volume_share < 1.f ? rng.uniform() : 0.f;
        if (q_volume_share > 0.f && uq < q_volume_share) light_from_volume(light_vertices);
        else light_from_emitter(light_vertices);
    }
    if (traced) detail::record_light_walk(counter, light_work_before);
}

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::light_from_volume(
    int light_vertices) {
    using namespace bdpt;
    if constexpr (kEmissive) {
        const float us = rng.uniform(), u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform(),
                    u3 = rng.uniform(), u4 = rng.uniform(), u5 = rng.uniform();
        const int i = sc.select_emission(us);
        const float select = sc.emission_selection_pdf(i);
        const auto& m = sc.media[std::size_t(i)];
        const VolumeSample yv = m.medium.sample_emission(u0, u1, u2, u3);
        const Vec3 w = uniform_sphere(u4, u5);
        // The point counts only inside medium i's surfaces: the first boundary ahead of it
        // must be one it leaves medium i through (as the camera side's NEE walk checks).
        const int start = light_start_medium(sc, yv.p, w);
        if (start == -3) status = Status::InvalidInput;
        const bool inside = start == i;
        if (!(i >= 0 && select > 0.f && yv.pdf > 0.f && inside)) return;
        const auto c = detail::lookup_untracked(m.medium, m.majorant, Ray{yv.p, w}, 0.f, lambda, counter);
        if (!c) {
            status = Status::Rejected;
            return;
        }
        if (!((c->k.sigma_a > 0.f).any() && majorant_at(c->mu, channel) > 0.f)) return;
        const Spectrum source = c->k.sigma_a * m.medium.emission(yv.p, lambda);
        if (!(source > 0.f).any()) return;
        V& y0 = light[0] = V{};
        y0.kind = VertexKind::Medium;
        y0.p = yv.p;
        y0.medium = i;
        y0.event = majorants<P>(c->mu);  // a tentative collision's density there: mu_bar
        if constexpr (kPerChannel) y0.gamma = Spectrum::Ones();
        emit_y0 = q_volume * select * yv.pdf;
        y0.pdf_fwd = broadcast<P>(emit_y0);
        y0.beta = source / emit_y0;
        nl = subpath(light, light_vertices, Ray{yv.p, w}, i, kInv4Pi, Spectrum(y0.beta * (4.f * kPi)), false,
                     seg_on ? &first_segment : nullptr)
                 .run([](auto&&...) {});
        nee_y0 = select * yv.pdf;
        if (seg_on && nl >= 2) {
            // y_0's piece seen from y_1: from the last surface between them (the walk's first
            // piece's end, else y_1) through y_0 to the first surface beyond it.
            const float dist = glm::length(light[1].p - yv.p);
            const SurfaceHit behind = sc.geometry.intersect(Ray{yv.p, -w}, kInf);
            if (!detail::usable_hit(sc, behind)) {
                status = Status::InvalidInput;
            } else {
                const float a = std::min(first_segment.first_piece_end, dist);
                const float b = behind.found() ? behind.t : kInf;
                const float along = m.medium.emission_along(Ray{yv.p + a * w, -w}, 0.f, a + b);
                seg_y0_unit = seg_density(1.f, first_segment.later_nulls, yv.pdf, along);
            }
        }
    } else {
        (void)light_vertices;
    }
}

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::light_from_emitter(
    int light_vertices) {
    using namespace bdpt;
    const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform(),
                u4 = rng.uniform();
    volume_start = false;
    const EmittedLight<typename Sc::Spectral> e = sc.lights.sample_emission(u0, u1, u2, u3, u4, lambda);
    if (!(e.emission.pdf_pos > 0.f && e.emission.pdf_dir > 0.f && (e.emission.radiance != 0.f).any())) return;
    V& y0 = light[0] = V{};
    y0.kind = VertexKind::Light;
    y0.p = e.emission.p;
    y0.ng = y0.ns = e.emission.n;
    y0.light = e.light;
    y0.delta_position = e.emission.delta_position;
    y0.at_infinity = e.emission.at_infinity;
    emit_y0 = q_lights * e.emission.pdf_pos;
    y0.pdf_fwd = broadcast<P>(emit_y0);
    y0.beta = e.emission.radiance / (q_lights * e.emission.pdf_pos);
    if constexpr (kPerChannel) y0.gamma = Spectrum::Ones();
    const int start = light_start_medium(sc, e.emission.p, e.emission.w);
    if (start == -3) status = Status::InvalidInput;
    else
        nl = subpath(light, light_vertices, Ray{e.emission.p, e.emission.w}, start, e.emission.pdf_dir,
                     Spectrum(y0.beta * (e.emission.cos / e.emission.pdf_dir)), false)
                 .run([](auto&&...) {});
    if (nl >= 2) {
        const Vec3 d = y0.p - light[1].p;
        const float d2 = glm::dot(d, d);
        eq_nee_y0 = y0.delta_position ? sc.lights.selection_pdf(y0.light)  // a point or a direction
                    : y0.at_infinity  ? sc.lights.pdf(y0.light, light[1].p, -e.emission.w)  // solid angle
                                        : sc.lights.pdf(y0.light, light[1].p, d / std::sqrt(d2),
                                                        light_point(y0.p, e.emission.uv, e.emission.user)) *
                                              std::abs(glm::dot(y0.ng, d)) / (d2 * std::sqrt(d2));
        nee_y0 = nee_count * eq_nee_y0;
    }
}

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::connect(int t) {
    using namespace bdpt;
    const V& z = camera[t - 1];
    for (int s = 2; s <= nl && s + t - 2 <= depth; ++s) {
        const V& y = light[s - 1];
        if (y.delta) continue;
        const Vec3 d = z.p - y.p;
        const float d2 = glm::dot(d, d);
        if (!(d2 > 0.f)) continue;
        const Vec3 w = d / std::sqrt(d2);
        const auto fy = eval_at(y, y.wo, w);
        if (!(fy.value != 0.f).any()) continue;
        const auto fz = eval_at(z, z.wo, -w);
        if (!(fz.value != 0.f).any()) continue;
        P nulls = broadcast<P>(1.f);
        GammaT gamma = unit_gamma<P>();
        const Spectrum tr = transmit(y, z, nulls, gamma);
        if (!(tr != 0.f).any()) continue;
        const Spectrum f = y.beta * fy.value * tr * fz.value * z.beta / d2;
        gather(s, t, s + t - 1);
        if constexpr (kPerChannel) pdfs.gamma = path_gamma(y.gamma, gamma, z.gamma);
        pdfs.emit = emit_y0;
        pdfs.nee = nee_y0;
        // The four densities the connection changes.
        pdfs.from_light[s] = to_vertex_measure(fy.pdf, y.p, z) * nulls * z.event;
        pdfs.from_camera[s - 1] = to_vertex_measure(fz.pdf, z.p, y) * nulls * y.event;
        if (t >= 3) {
            const V& z2 = camera[t - 2];
            pdfs.from_light[s + 1] = to_vertex_measure(eval_at(z, w, -z.wo).pdf, z.p, z2) * z.nulls_in * z2.event;
        }
        const V& y2 = light[s - 2];
        const float pd_y2 = eval_at(y, -w, -y.wo).pdf;
        pdfs.from_camera[s - 2] = to_vertex_measure(pd_y2, y.p, y2) * y.nulls_in * y2.event;
        // x_1 = y_1 as the equiangular strategy draws it, from x_2 (z, y_2 toward the connection,
        // or y_2 as its light subpath stored).
        pdfs.eq_nee = eq_nee_y0;
        pdfs.eq = s == 2 ? eq_from(z.p, fz.pdf, y) : s == 3 ? eq_from(y.p, pd_y2, y2) : light[1].eq;
        // x_0 = y_0 as the segment technique draws it from x_1 = y_1, arriving there from x_2
        // (z, or y_2 as the light subpath drew it).
        pdfs.seg = seg_y0_unit * (s == 2 ? to_vertex_measure(pd_y2, y.p, y2) : first_segment.y0_reverse);
        add(s, t, f, pdfs, light[0].p, light[0].at_infinity, volume_start);
    }
}

template <bdpt::MisPolicy Mis, mis::CombiningHeuristic H, AbsorptionPolicy A, int MaxDepth, bdpt::ChannelAxis Ch>
template <class Sc, class Cam, class R, class C, class Splat, class Observe>
void BdptEstimator<Mis, H, A, MaxDepth, Ch>::BdptSample<Sc, Cam, R, C, Splat, Observe>::light_trace() {
    using namespace bdpt;
    if constexpr (kLightTracing) {
        const Vec3 eye = cam->position();
        for (int s = 2; s <= nl && s - 1 <= depth; ++s) {
            const V& y = light[s - 1];
            if (y.delta) continue;
            const Vec3 d = eye - y.p;
            const float d2 = glm::dot(d, d);
            if (!(d2 > 0.f)) continue;
            const Vec3 w = d / std::sqrt(d2);  // from y toward the camera
            float u = 0.f, v = 0.f;
            const float pc = cam->pdf_dir(-w);
            if (!(pc > 0.f) || !cam->raster(-w, u, v)) continue;
            const auto fy = eval_at(y, y.wo, w);
            if (!(fy.value != 0.f).any()) continue;
            V eye_vertex;
            eye_vertex.p = eye;
            P nulls = broadcast<P>(1.f);
            GammaT gamma = unit_gamma<P>();
            const Spectrum tr = transmit(y, eye_vertex, nulls, gamma);
            if (!(tr != 0.f).any()) continue;
            const Spectrum f = y.beta * fy.value * tr * (pc / d2);
            gather(s, 0, s);
            if constexpr (kPerChannel) pdfs.gamma = path_gamma(y.gamma, gamma);
            pdfs.emit = emit_y0;
            pdfs.nee = nee_y0;
            pdfs.from_camera[s - 1] = to_vertex_measure(pc, eye, y) * nulls * y.event;
            const V& y2 = light[s - 2];
            const float pd_y2 = eval_at(y, -w, -y.wo).pdf;
            pdfs.from_camera[s - 2] = to_vertex_measure(pd_y2, y.p, y2) * y.nulls_in * y2.event;
            pdfs.eq_nee = eq_nee_y0;
            pdfs.eq = s == 2 ? eq_from(eye, pc, y) : s == 3 ? eq_from(y.p, pd_y2, y2) : light[1].eq;
            pdfs.seg = seg_y0_unit * (s == 2 ? to_vertex_measure(pd_y2, y.p, y2) : first_segment.y0_reverse);
            const float wt = weight_of(pdfs, s);
            record(s, f, pdfs, volume_start, true);
            observe(s, 1, f, wt, pdfs,
                    PathVertices<typename Sc::Spectral, P>{light, s, camera, 1, light[0].p, light[0].at_infinity});
            const Spectrum value = f * wt;
            if (all_finite(value)) splat(u, v, value);
            else status = Status::NonFinite;
        }
    }
}

}  // namespace nsp
