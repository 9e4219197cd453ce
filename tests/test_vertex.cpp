// tests/test_vertex.cpp: the path-vertex kernels (vertex.hpp) and the BSDF models (bsdf.hpp) in a
// host's own path loop with surfaces (THEORY 5.8), against closed forms: a furnace of emitting
// Lambertian and mirror walls around a non-absorbing medium, a mirror behind an absorbing slab,
// a shadow ray across three media; the weights of one path sum to 1; bad host input never
// becomes a NaN.
#include <algorithm>
#include <array>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"

namespace {

using namespace nsp_test;
using S = Mono;
using Spectrum = S::Spectrum;

// k = 5 standard errors, estimated from the samples, with fixed seeds: deterministic.
constexpr double kSigmas = 5.0;

/// An axis-aligned rectangle: the plane x[axis] = pos over [lo, hi] in the other two axes, with
/// `normal_sign` giving the side its emission and its BSDF's normal face.
struct Quad {
    int axis;
    float pos, normal_sign;
    float lo[2], hi[2];
    float emission;  ///< radiance emitted on the normal's side (0: none)
    bool mirror;     ///< a MirrorBsdf, else a LambertianBsdf (albedo of the scene)
    bool black = false;  ///< reflects nothing: a path ends there

    Vec3 normal() const {
        Vec3 n(0.f);
        n[axis] = normal_sign;
        return n;
    }
    float area() const { return (hi[0] - lo[0]) * (hi[1] - lo[1]); }
    /// The point at (u, v) in [0, 1)^2.
    Vec3 point(float u, float v) const {
        Vec3 p(0.f);
        p[axis] = pos;
        p[(axis + 1) % 3] = lo[0] + u * (hi[0] - lo[0]);
        p[(axis + 2) % 3] = lo[1] + v * (hi[1] - lo[1]);
        return p;
    }
    float intersect(const Ray& r) const {
        if (r.d[axis] == 0.f) return kInf;
        const float t = (pos - r.o[axis]) / r.d[axis];
        if (!(t > 1e-4f)) return kInf;
        const Vec3 p = r.at(t);
        const float a = p[(axis + 1) % 3], b = p[(axis + 2) % 3];
        return a >= lo[0] && a <= hi[0] && b >= lo[1] && b <= hi[1] ? t : kInf;
    }
};

/// A host's scene: quads, one medium and its majorant, a phase function, Lambertian walls of
/// one albedo; NEE samples a point uniformly on the emitting quads' area.
template <class M>
struct HostScene {
    std::vector<Quad> quads;
    M medium;
    GlobalMajorant<M> majorant;
    HenyeyGreensteinPhase phase{0.3f};
    LambertianBsdf<S> diffuse{Spectrum::Constant(0.5f)};
    MirrorBsdf<S> mirror{Spectrum::Constant(0.5f)};

    struct Hit {
        float t = kInf;
        int quad = -1;
    };
    Hit intersect(const Ray& r) const {
        Hit h;
        for (int i = 0; i < int(quads.size()); ++i)
            if (const float t = quads[std::size_t(i)].intersect(r); t < h.t) h = {t, i};
        return h;
    }
    float emitting_area() const {
        float a = 0.f;
        for (const Quad& q : quads) a += q.emission > 0.f ? q.area() : 0.f;
        return a;
    }
    /// Solid-angle pdf at x of NEE's uniform area sampling picking point y on quad q.
    float light_pdf(const Vec3& x, const Vec3& y, const Quad& q) const {
        const Vec3 d = y - x;
        const float d2 = glm::dot(d, d), cos_y = std::abs(glm::dot(q.normal(), d)) / std::sqrt(d2);
        return q.emission > 0.f && cos_y > 0.f ? d2 / (cos_y * emitting_area()) : 0.f;
    }
    /// Emission of quad q seen along direction d (toward the quad).
    static float emitted(const Quad& q, const Vec3& d) { return glm::dot(q.normal(), d) < 0.f ? q.emission : 0.f; }
};

/// One radiance estimate along `ray` of a host's path loop written on the kernels `k` alone.
template <class K, class M>
float host_radiance(const K& k, const HostScene<M>& sc, Ray ray, Pcg32& rng, Status& status) {
    LookupCount counter;
    float L = 0.f;
    Spectrum beta = Spectrum::Ones();
    VertexPdf from = VertexPdf::from_camera();
    float nulls = 1.f;
    Vec3 prev_x = ray.o;
    for (int depth = 0;;) {
        const auto hit = sc.intersect(ray);
        const auto seg = k.track(sc.medium, sc.majorant, ray, hit.t, {}, rng, counter);
        if (const Status fs = flight_status(seg.end); fs != Status::Ok) {
            status = fs;
            return 0.f;
        }
        beta *= seg.weight;
        nulls *= seg.null_pdf_product;
        const Quad* surface = nullptr;
        Vec3 x;
        if (seg.end == SegmentEnd::Passed) {
            if (hit.quad < 0) break;  // left the scene
            surface = &sc.quads[std::size_t(hit.quad)];
            x = ray.at(hit.t);
            if (const float le = HostScene<M>::emitted(*surface, ray.d); le > 0.f && k.counts_hit(from))
                L += beta[0] * le * k.hit_weight(from, nulls, sc.light_pdf(prev_x, x, *surface));
            if (surface->black) break;
        } else if (seg.end == SegmentEnd::Scattered) {
            x = ray.at(seg.t);
        } else {
            break;  // absorbed
        }
        if (++depth > k.options().max_depth || !(beta > 0.f).any()) break;
        const float q = k.survival(depth, beta);
        const bool delta = surface && surface->mirror;
        // The surface's normal on the side the path arrived from, for the BSDF.
        const Vec3 n = surface ? surface->normal() : Vec3(0.f, 0.f, 1.f);
        if (K::Strategy::samples_lights && !delta && sc.emitting_area() > 0.f) {
            // NEE: a point uniform on the emitting area.
            float u = rng.uniform() * sc.emitting_area();
            const float u1 = rng.uniform(), u2 = rng.uniform();
            const Quad* light = nullptr;
            for (const Quad& qd : sc.quads) {
                if (!(qd.emission > 0.f)) continue;
                light = &qd;
                if (u < qd.area()) break;
                u -= qd.area();
            }
            const Vec3 y = light->point(u1, u2);
            const Vec3 d = y - x;
            const float dist = glm::length(d);
            const Vec3 wi = d / dist;
            const float le = HostScene<M>::emitted(*light, wi);
            const float lpdf = sc.light_pdf(x, y, *light);
            const bool blocked = sc.intersect(Ray{x, wi}).t < dist * (1.f - 1e-4f);
            if (le > 0.f && lpdf > 0.f && !blocked) {
                const float f = surface ? sc.diffuse.eval(ray.d, wi, n)[0] : sc.phase.eval(ray.d, wi);
                const float p = surface ? sc.diffuse.pdf(ray.d, wi, n) : sc.phase.pdf(ray.d, wi);
                const auto sh = k.shadow(sc.medium, sc.majorant, Ray{x, wi}, dist, {}, rng, counter);
                if (sh.status != Status::Ok) {
                    status = sh.status;
                    return 0.f;
                }
                L += beta[0] * sh.transmittance[0] * le * f * k.light_weight(q, p, sh.null_pdf_product, lpdf, false) / lpdf;
            }
        }
        if (q < 1.f) {
            if (!(rng.uniform() < q)) break;
            beta /= q;
        }
        const float u1 = rng.uniform(), u2 = rng.uniform();
        Vec3 wi;
        float pdf;
        if (surface) {
            const BsdfSample<S> bs = delta ? sc.mirror.sample(ray.d, n, u1, u2) : sc.diffuse.sample(ray.d, n, u1, u2);
            if (!(bs.pdf > 0.f)) break;
            beta *= bs.value / bs.pdf;
            wi = bs.wi;
            pdf = bs.pdf;
        } else {
            const PhaseSample ps = sc.phase.sample(ray.d, u1, u2);
            if (!(ps.pdf > 0.f)) break;
            beta *= ps.value / ps.pdf;
            wi = ps.wi;
            pdf = ps.pdf;
        }
        from = VertexPdf::scattered(q, pdf, delta);
        nulls = 1.f;
        prev_x = x;
        ray = Ray{x, wi};
    }
    return L;
}

/// The six walls of [-1, 1]^3, normals inward, each emitting `le`; walls in `mirrors` are mirrors.
std::vector<Quad> box_walls(float le, std::vector<int> mirrors = {}) {
    std::vector<Quad> walls;
    for (int axis = 0; axis < 3; ++axis)
        for (const float side : {-1.f, 1.f}) {
            const int index = int(walls.size());
            const bool mirror = std::find(mirrors.begin(), mirrors.end(), index) != mirrors.end();
            walls.push_back({axis, side, -side, {-1.f, -1.f}, {1.f, 1.f}, le, mirror});
        }
    return walls;
}

template <class K>
Stat furnace(const K& k, const std::vector<Quad>& walls, std::uint64_t seed) {
    using M = HomogeneousMedium<S>;
    const M medium(Box{Vec3(-1.f), Vec3(1.f)}, Spectrum::Constant(0.f), Spectrum::Constant(1.5f));
    // A majorant twice the extinction: every segment has nulls, so their P_n enter the MIS.
    const HostScene<M> sc{walls, medium, GlobalMajorant<M>(medium, 3.f)};
    Pcg32 rng(seed, 3);
    Stat s;
    for (int i = 0; i < 20000; ++i) {
        Status status = Status::Ok;
        const Ray ray{Vec3(0.1f, -0.2f, 0.3f), uniform_sphere(rng.uniform(), rng.uniform())};
        const float L = host_radiance(k, sc, ray, rng, status);
        REQUIRE(status == Status::Ok);
        s.add(L);
    }
    return s;
}

template <class K>
void check_furnace(const K& k, const char* name) {
    CAPTURE(name);
    // Walls of albedo 0.5 emitting 1 around a medium that does not absorb: the radiance is
    // L = Le / (1 - 0.5) = 2 everywhere and in every direction, whatever the phase function, the
    // density, and which walls are Lambertian or mirrors of the same reflectance.
    for (const auto& mirrors : {std::vector<int>{}, std::vector<int>{1, 4}}) {
        CAPTURE(mirrors.size());
        const Stat s = furnace(k, box_walls(1.f, mirrors), 11 + mirrors.size());
        CAPTURE(s.mean);
        CAPTURE(s.se());
        CHECK(std::abs(s.mean - 2.0) <= kSigmas * s.se());
    }
}

TEST_CASE("vertex kernels: a host's loop with surfaces renders the furnace of emitting walls (L = 2)") {
    check_furnace(VertexKernels<strategy::Unidirectional>{}, "unidirectional");
    // NEE alone is left out: the quads are sampled by area, and in a closed box the second moment
    // of that estimate diverges (logarithmically) at vertices near an edge or a wall, so its
    // standard error means nothing there. tests/test_surface_estimators.cpp checks NEE alone
    // on the same kernels in a white furnace under a uniform sky, where its variance is finite.
    check_furnace(VertexKernels<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis balance");
    check_furnace(VertexKernels<strategy::NullScatteringMis, mis::Power, absorption::Event>{}, "uni-nee-mis power event");
    check_furnace(VertexKernels<strategy::DirectionalMis, mis::Balance>{}, "directional-mis");
}

TEST_CASE("vertex kernels: a mirror behind an absorbing slab (delta lobe: no NEE, hit weight 1)") {
    // The camera at the origin looks along +z through a slab z in [0.5, 1.5] of sigma_a = 1 at a
    // mirror (reflectance 0.5) at z = 2; the reflected ray crosses the slab again and meets a black
    // emitter (Le = 3) at z = -1: L = R T^2 Le with T = exp(-1 / cos theta) for the ray's angle
    // theta to the slab's normal, for every strategy (NEE has no vertex to start from: a mirror and
    // an absorbing medium, whose delta-tracked "scattering" events carry weight 0).
    using M = HomogeneousMedium<S>;
    const M slab(Box{Vec3(-5.f, -5.f, 0.5f), Vec3(5.f, 5.f, 1.5f)}, Spectrum::Constant(1.f), Spectrum::Constant(0.f));
    const std::vector<Quad> quads{{2, 2.f, -1.f, {-5.f, -5.f}, {5.f, 5.f}, 0.f, true, false},
                                  {2, -1.f, 1.f, {-5.f, -5.f}, {5.f, 5.f}, 3.f, false, true}};
    const HostScene<M> sc{quads, slab, GlobalMajorant<M>(slab, 2.f)};
    const Vec3 d = glm::normalize(Vec3(0.05f, -0.02f, 1.f));
    const double exact = 0.5 * std::exp(-2.0 / double(d.z)) * 3.0;
    auto check = [&](const auto& k, const char* name) {
        CAPTURE(name);
        Pcg32 rng(5, 7);
        Stat s;
        for (int i = 0; i < 20000; ++i) {
            Status status = Status::Ok;
            s.add(host_radiance(k, sc, Ray{Vec3(0.f), d}, rng, status));
            REQUIRE(status == Status::Ok);
        }
        CAPTURE(s.mean);
        CAPTURE(s.se());
        CHECK(std::abs(s.mean - exact) <= kSigmas * s.se() + kRoundingFloor);
    };
    check(VertexKernels<strategy::Unidirectional>{}, "unidirectional");
    check(VertexKernels<strategy::NextEvent>{}, "ratio-nee");
    check(VertexKernels<strategy::NullScatteringMis, mis::Balance>{}, "uni-nee-mis");
}

TEST_CASE("vertex kernels: a shadow ray across three media multiplies their transmittances") {
    // Three slabs along x, [0,1] [1,2] [2,3], of extinction 0.5, 2 and 1 (albedo 0.6), majorants
    // 2x, 1.5x and 3x: T = exp(-3.5). Under a bounding majorant ratio tracking's weight of a null,
    // mu_n / mu_bar, is delta tracking's P_n there, so the null-pdf product equals the estimate
    // sample by sample; with directional MIS (no null pdfs) it is 1.
    using M = HomogeneousMedium<S>;
    const float sigma[3] = {0.5f, 2.f, 1.f}, loose[3] = {2.f, 1.5f, 3.f};
    std::vector<M> media;
    std::vector<GlobalMajorant<M>> majorants;
    media.reserve(3);
    for (int i = 0; i < 3; ++i) {
        media.emplace_back(Box{Vec3(float(i), 0.f, 0.f), Vec3(float(i + 1), 1.f, 1.f)}, Spectrum::Constant(0.4f * sigma[i]),
                           Spectrum::Constant(0.6f * sigma[i]));
        majorants.emplace_back(media.back(), loose[i] * sigma[i]);
    }
    const VertexKernels<strategy::NullScatteringMis, mis::Balance> k;
    const VertexKernels<strategy::DirectionalMis, mis::Balance> kd;
    const Ray ray{Vec3(-0.5f, 0.5f, 0.5f), Vec3(1.f, 0.f, 0.f)};
    Pcg32 rng(9, 1);
    NoLookupCount counter;
    Stat t;
    for (int i = 0; i < 40000; ++i) {
        float T = 1.f, nulls = 1.f;
        for (int m = 0; m < 3; ++m) {
            const auto sh = k.shadow(media[std::size_t(m)], majorants[std::size_t(m)], ray, 4.f, {}, rng, counter);
            REQUIRE(sh.status == Status::Ok);
            T *= sh.transmittance[0];
            nulls *= sh.null_pdf_product;
            const auto shd = kd.shadow(media[std::size_t(m)], majorants[std::size_t(m)], ray, 4.f, {}, rng, counter);
            CHECK(shd.null_pdf_product == 1.f);
        }
        CHECK(nulls == doctest::Approx(T).epsilon(1e-5));
        t.add(T);
    }
    CAPTURE(t.mean);
    CAPTURE(t.se());
    CHECK(std::abs(t.mean - std::exp(-3.5)) <= kSigmas * t.se());
}

TEST_CASE("vertex kernels: the weights of one path sum to 1; delta vertices and lights weigh 1") {
    const VertexKernels<strategy::NullScatteringMis, mis::Balance> kb;
    const VertexKernels<strategy::NullScatteringMis, mis::Power> kp;
    Pcg32 rng(3, 3);
    for (int i = 0; i < 1000; ++i) {
        const float q = 0.05f + 0.95f * rng.uniform(), p_dir = 10.f * rng.uniform() + 1e-3f;
        const float nulls = rng.uniform(), p_light = 100.f * rng.uniform() + 1e-4f;
        for (const float sum : {kb.hit_weight(VertexPdf::scattered(q, p_dir), nulls, p_light) +
                                    kb.light_weight(q, p_dir, nulls, p_light, false),
                                kp.hit_weight(VertexPdf::scattered(q, p_dir), nulls, p_light) +
                                    kp.light_weight(q, p_dir, nulls, p_light, false)})
            CHECK(sum == doctest::Approx(1.f).epsilon(1e-5));
        CHECK(kb.hit_weight(VertexPdf::scattered(q, 1.f, true), nulls, p_light) == 1.f);
        CHECK(kb.hit_weight(VertexPdf::from_camera(), nulls, p_light) == 1.f);
        CHECK(kb.light_weight(q, p_dir, nulls, p_light, true) == 1.f);
    }
    CHECK(VertexKernels<strategy::NextEvent>::counts_hit(VertexPdf::scattered(1.f, 1.f, true)));
    CHECK(!VertexKernels<strategy::NextEvent>::counts_hit(VertexPdf::scattered(1.f, 1.f, false)));
    CHECK(VertexKernels<strategy::Unidirectional>::counts_hit(VertexPdf::scattered(1.f, 1.f, false)));
}

TEST_CASE("vertex kernels: bad host input gives weight 0 and a status, never NaN") {
    const VertexKernels<strategy::NullScatteringMis, mis::Balance> k;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    using M = HomogeneousMedium<S>;
    const M medium(Box{Vec3(-1.f), Vec3(1.f)}, Spectrum::Constant(0.5f), Spectrum::Constant(0.5f));
    const GlobalMajorant<M> majorant(medium, 2.f);
    Pcg32 rng(1, 1);
    NoLookupCount counter;
    const Ray good{Vec3(0.f, 0.f, -3.f), Vec3(0.f, 0.f, 1.f)};
    // A NaN or negative distance, a NaN, zero or not unit direction, an infinite origin: nothing
    // tracked, and the status says the input was bad.
    for (const auto& [ray, t] : {std::pair{good, nan}, std::pair{good, -1.f}, std::pair{Ray{good.o, Vec3(nan, 0.f, 1.f)}, 5.f},
                                 std::pair{Ray{good.o, Vec3(0.f)}, 5.f}, std::pair{Ray{Vec3(kInf, 0.f, 0.f), good.d}, 5.f},
                                 std::pair{Ray{good.o, Vec3(0.f, 0.f, 2.f)}, 5.f}, std::pair{Ray{good.o, Vec3(0.f, 0.f, 0.5f)}, 5.f}}) {
        const auto seg = k.track(medium, majorant, ray, t, {}, rng, counter);
        CHECK(seg.end == SegmentEnd::InvalidInput);
        CHECK(flight_status(seg.end) == Status::InvalidInput);
        CHECK(seg.weight[0] == 0.f);
        const auto sh = k.shadow(medium, majorant, ray, t, {}, rng, counter);
        CHECK(sh.status == Status::InvalidInput);
        CHECK(sh.transmittance[0] == 0.f);
    }
    CHECK(k.track(medium, majorant, good, kInf, {}, rng, counter).end != SegmentEnd::InvalidInput);  // no surface: fine
    // A BSDF given a NaN normal draws nothing.
    CHECK(LambertianBsdf<S>(Spectrum::Constant(0.5f)).sample(good.d, Vec3(nan, 0.f, 1.f), 0.3f, 0.3f).pdf == 0.f);
    CHECK(MirrorBsdf<S>(Spectrum::Constant(0.5f)).sample(good.d, Vec3(nan, 0.f, 1.f), 0.3f, 0.3f).pdf == 0.f);
    CHECK(k.hit_weight(VertexPdf::scattered(1.f, nan), 1.f, 1.f) == 0.f);
    CHECK(k.hit_weight(VertexPdf::scattered(1.f, -1.f), 1.f, 1.f) == 0.f);
    CHECK(k.hit_weight(VertexPdf::scattered(1.f, 1.f), 1.f, nan) == 0.f);
    CHECK(k.light_weight(1.f, nan, 1.f, 1.f, false) == 0.f);
    CHECK(k.light_weight(1.f, 1.f, nan, 1.f, false) == 0.f);
    CHECK(k.light_weight(1.f, 1.f, 1.f, -2.f, false) == 0.f);
}

TEST_CASE("BSDF models: OneSided scatters only paths arriving on the normal's side, and is black behind") {
    const LambertianBsdf<S> lambert(Spectrum::Constant(0.6f));
    const OneSided<S, LambertianBsdf<S>> front{lambert};
    const Vec3 n(0.f, 1.f, 0.f);
    const Vec3 down = glm::normalize(Vec3(0.3f, -1.f, 0.1f)), up = -down;  // arriving from above / below
    const Vec3 wi_up = glm::normalize(Vec3(-0.2f, 1.f, 0.4f));
    // From the front: the wrapped model, value for value.
    CHECK(front.eval(down, wi_up, n, {})[0] == lambert.eval(down, wi_up, n, {})[0]);
    CHECK(front.pdf(down, wi_up, n) == lambert.pdf(down, wi_up, n));
    const auto s = front.sample(down, n, 0.3f, 0.7f, {});
    const auto t = lambert.sample(down, n, 0.3f, 0.7f, {});
    CHECK(s.pdf == t.pdf);
    CHECK(s.wi == t.wi);
    CHECK(s.pdf > 0.f);
    // From behind (the two-sided model reflects there): nothing.
    CHECK(lambert.pdf(up, -wi_up, n) > 0.f);
    CHECK(front.eval(up, -wi_up, n, {})[0] == 0.f);
    CHECK(front.pdf(up, -wi_up, n) == 0.f);
    CHECK(front.sample(up, n, 0.3f, 0.7f, {}).pdf == 0.f);
    // Delta-ness and null interfaces pass through the adapter.
    CHECK(OneSided<S, MirrorBsdf<S>>::is_delta);
    CHECK(!OneSided<S, LambertianBsdf<S>>::is_delta);
    CHECK(OneSided<S, NullInterface<S>>::passes_through);
}

TEST_CASE("BSDF models: sampling matches eval and pdf; Lambertian reflects albedo; validation") {
    const LambertianBsdf<Rgb> lambert(Rgb::Spectrum(0.2f, 0.5f, 0.9f));
    const Vec3 n(0.f, 0.f, 1.f);
    Pcg32 rng(2, 2);
    // Arriving from above (wo points down) or from below (wo up): reflection on the arrival side.
    for (const Vec3 wo : {glm::normalize(Vec3(0.3f, 0.1f, -1.f)), glm::normalize(Vec3(-0.2f, 0.4f, 1.f))}) {
        SpecStat<Rgb> albedo;
        for (int i = 0; i < 20000; ++i) {
            const BsdfSample<Rgb> s = lambert.sample(wo, n, rng.uniform(), rng.uniform());
            REQUIRE(s.pdf > 0.f);
            CHECK(glm::dot(s.wi, n) * glm::dot(wo, n) < 0.f);  // back to the side the path came from
            CHECK(lambert.pdf(wo, s.wi, n) == doctest::Approx(s.pdf).epsilon(1e-4));
            CHECK((lambert.eval(wo, s.wi, n) - s.value).abs().maxCoeff() <= 1e-5f);
            CHECK(!s.delta);
            albedo.add(s.value / s.pdf);
        }
        // value / pdf = albedo for every sample of a cosine-sampled Lambertian: exactly the albedo.
        for (int c = 0; c < 3; ++c) CHECK(albedo.ch[std::size_t(c)].mean == doctest::Approx(std::array{0.2, 0.5, 0.9}[std::size_t(c)]).epsilon(1e-4));
        CHECK(lambert.eval(wo, -glm::reflect(wo, n), n).isZero());  // transmission: none
    }
    const MirrorBsdf<S> mirror(Spectrum::Constant(0.7f));
    const Vec3 wo = glm::normalize(Vec3(1.f, 0.f, -1.f));
    const BsdfSample<S> m = mirror.sample(wo, n, 0.5f, 0.5f);
    CHECK(m.delta);
    CHECK(glm::length(m.wi - glm::normalize(Vec3(1.f, 0.f, 1.f))) < 1e-6f);
    CHECK(m.value[0] / m.pdf == doctest::Approx(0.7f));
    CHECK(mirror.pdf(wo, m.wi, n) == 0.f);
    CHECK(NullInterface<S>::passes_through);
    CHECK(NullInterface<S>{}.sample(wo, n, 0.f, 0.f).wi == wo);
    CHECK_THROWS_WITH_AS(LambertianBsdf<S>(Spectrum::Constant(1.5f)),
                         doctest::Contains("LambertianBsdf albedo = 1.5"), InvalidArgument);
    CHECK_THROWS_WITH_AS(MirrorBsdf<S>(Spectrum::Constant(std::numeric_limits<float>::quiet_NaN())),
                         doctest::Contains("MirrorBsdf reflectance"), InvalidArgument);
    static_assert(Bsdf<LambertianBsdf<S>, S> && Bsdf<MirrorBsdf<S>, S> && Bsdf<NullInterface<S>, S>);
    static_assert(Bsdf<LambertianBsdf<Hero<4>>, Hero<4>>);
}

}  // namespace
