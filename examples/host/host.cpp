// examples/host/host.cpp: a host renderer with its own geometry, lights and path loop, which takes
// from nsp only what a renderer would: a medium, its majorant, the path-vertex kernels
// (nsp/vertex.hpp), a BSDF, a phase function, the light sampler and the SurfaceHit record its
// geometry (shapes.hpp, an nsp::Geometry) reports. The scene: a cloud over a diffuse floor under a
// rectangular light and a dim sky.
//
//   nsp_host [--res N] [--spp N] [--out FILE.png]   renders the scene, prints its image mean
//   nsp_host --compare                              renders the scene with this loop and with
//       nsp::PathEstimator over an nsp::SurfaceScene of the same shapes, medium and lights, and
//       checks that the image means agree within 5 standard errors (exit 1 if not; independent
//       seeds): the host's loop and the library's are the same estimator.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

#include <nsp/nsp.hpp>

#include "shapes.hpp"

namespace {

using S = nsp::Mono;
using Spectrum = S::Spectrum;
using Medium = nsp::DenseGridMedium<S>;
using Lights = nsp::LightSampler<S, nsp::QuadLight<S>, nsp::SphereLight<S>, nsp::EnvironmentLight<S>>;
using Kernels = nsp::VertexKernels<nsp::strategy::NullScatteringMis, nsp::mis::Balance, nsp::absorption::Weight>;

/// A soft ball of density on a 32^3 grid over [-1, 1]^3.
Medium make_cloud() {
    const int n = 32;
    std::vector<float> d(std::size_t(n) * n * n);
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const nsp::Vec3 p = -1.f + 2.f * (nsp::Vec3(float(x), float(y), float(z)) + 0.5f) / float(n);
                d[std::size_t(x) + std::size_t(n) * (std::size_t(y) + std::size_t(n) * std::size_t(z))] =
                    std::max(0.f, 1.f - glm::dot(p, p) / 0.8f);
            }
    return Medium(nsp::Box{nsp::Vec3(-1.f), nsp::Vec3(1.f)}, {n, n, n}, std::move(d), Spectrum::Constant(0.5f),
                  Spectrum::Constant(8.f));
}

/// The host's world: its shapes (examples/host/shapes.hpp; the floor and the lights' own
/// surfaces), one medium, one BSDF and the light sampler whose indices the shapes' light handles are.
struct World {
    Medium cloud = make_cloud();
    nsp::GlobalMajorant<Medium> majorant{cloud};
    nsp::HenyeyGreensteinPhase phase{0.6f};
    nsp::LambertianBsdf<S> floor_bsdf{Spectrum::Constant(0.6f)};  ///< material 0
    nsp_host::Shapes shapes;
    Lights lights{nsp::LightSelection::Uniform, 1.f, {}, {}, {}};
    int sky = -1;  ///< the light index of the environment, or -1
};

/// One path of the host's loop: delta tracking to the next surface, NEE at every real vertex
/// (floor or medium) through the light sampler, null-scattering MIS by the kernels.
float radiance(const Kernels& k, const World& w, nsp::Ray ray, nsp::Pcg32& rng) {
    nsp::NoLookupCount counter;
    float L = 0.f;
    Spectrum beta = Spectrum::Ones();
    nsp::VertexPdf from = nsp::VertexPdf::from_camera();
    float nulls = 1.f;
    nsp::Vec3 prev = ray.o, n(0.f, 1.f, 0.f);
    for (int depth = 0;;) {
        const nsp::SurfaceHit hit = w.shapes.intersect(ray, nsp::kInf);
        const auto seg = k.track(w.cloud, w.majorant, ray, hit.t, {}, rng, counter);
        if (nsp::flight_status(seg.end) != nsp::Status::Ok) return 0.f;  // a failed flight: no estimate
        beta *= seg.weight;
        nulls *= seg.null_pdf_product;
        bool on_floor = false;
        nsp::Vec3 x;
        if (seg.end == nsp::SegmentEnd::Passed) {
            const int light = hit.found() ? hit.light : w.sky;
            if (light >= 0 || !hit.found()) {  // an emitter's surface, the sky, or nothing
                if (light >= 0 && k.counts_hit(from))
                    L += beta[0] * w.lights.emitted(light, ray.d)[0] * k.hit_weight(from, nulls, w.lights.pdf(light, prev, ray.d));
                break;
            }
            x = hit.p;
            n = hit.ns;
            on_floor = true;  // the scene's only material
        } else if (seg.end == nsp::SegmentEnd::Scattered) {
            x = ray.at(seg.t);
        } else {
            break;  // absorbed
        }
        if (++depth > k.options().max_depth) break;
        const float q = k.survival(depth, beta);
        const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
        const nsp::SampledLight<S> ls = w.lights.sample(x, u0, u1, u2);
        if (ls.sample.pdf > 0.f) {
            const nsp::Vec3 wi = ls.sample.wi;
            if (!w.shapes.occluded(nsp::Ray{x, wi}, ls.sample.distance * (1.f - 1e-4f))) {
                const float f = on_floor ? w.floor_bsdf.eval(ray.d, wi, n)[0] : w.phase.eval(ray.d, wi);
                const float p = on_floor ? w.floor_bsdf.pdf(ray.d, wi, n) : w.phase.pdf(ray.d, wi);
                const auto sh = k.shadow(w.cloud, w.majorant, nsp::Ray{x, wi}, ls.sample.distance, {}, rng, counter);
                if (sh.status != nsp::Status::Ok) return 0.f;
                L += beta[0] * sh.transmittance[0] * ls.sample.radiance[0] * f *
                     k.light_weight(q, p, sh.null_pdf_product, ls.sample.pdf, ls.sample.delta) / ls.sample.pdf;
            }
        }
        if (q < 1.f) {
            if (!(rng.uniform() < q)) break;
            beta /= q;
        }
        const float v1 = rng.uniform(), v2 = rng.uniform();
        nsp::Vec3 wi;
        float pdf;
        if (on_floor) {
            const nsp::BsdfSample<S> b = w.floor_bsdf.sample(ray.d, n, v1, v2);
            if (!(b.pdf > 0.f)) break;
            beta *= b.value / b.pdf;
            wi = b.wi;
            pdf = b.pdf;
        } else {
            const nsp::PhaseSample ps = w.phase.sample(ray.d, v1, v2);
            beta *= ps.value / ps.pdf;
            wi = ps.wi;
            pdf = ps.pdf;
        }
        from = nsp::VertexPdf::scattered(q, pdf);
        nulls = 1.f;
        prev = x;
        ray = nsp::Ray{x, wi};
    }
    return L;
}

/// The camera ray through (u, v) in [0, 1)^2 of the image (pinhole, 40 degrees).
nsp::Ray camera(float u, float v) {
    const float s = std::tan(0.5f * 40.f * nsp::kPi / 180.f);
    return {nsp::Vec3(0.f, 0.3f, -4.5f), glm::normalize(nsp::Vec3((1.f - 2.f * u) * s, (1.f - 2.f * v) * s, 1.f))};
}

/// A rendered image and the mean and standard error of all its samples.
struct Image {
    std::vector<float> pixels;
    double mean = 0.0, se = 0.0;
};
template <class Estimate>
Image render(int res, int spp, std::uint64_t seed, Estimate estimate) {
    Image img;
    img.pixels.resize(std::size_t(res) * std::size_t(res));
    double sum = 0.0, sum2 = 0.0;
    for (int y = 0; y < res; ++y)
        for (int x = 0; x < res; ++x) {
            nsp::Pcg32 rng(seed, std::uint64_t(y) * std::uint64_t(res) + std::uint64_t(x));
            double p = 0.0;
            for (int i = 0; i < spp; ++i) {
                const double L = estimate(camera((float(x) + rng.uniform()) / float(res), (float(y) + rng.uniform()) / float(res)), rng);
                p += L;
                sum += L;
                sum2 += L * L;
            }
            img.pixels[std::size_t(y) * std::size_t(res) + std::size_t(x)] = float(p / spp);
        }
    const double n = double(res) * res * spp;
    img.mean = sum / n;
    img.se = std::sqrt(std::max(0.0, sum2 / n - img.mean * img.mean) / (n - 1.0));
    return img;
}

}  // namespace

int main(int argc, char** argv) {
    int res = 96, spp = 64;
    std::string out;
    bool compare = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--compare") compare = true;
        else if (a == "--res" && i + 1 < argc) res = std::atoi(argv[++i]);
        else if (a == "--spp" && i + 1 < argc) spp = std::atoi(argv[++i]);
        else if (a == "--out" && i + 1 < argc) out = argv[++i];
        else return std::fprintf(stderr, "usage: nsp_host [--res N] [--spp N] [--out FILE.png] | --compare\n"), 2;
    }
    if (res < 1 || spp < 2) return std::fprintf(stderr, "nsp_host: --res must be >= 1 and --spp >= 2\n"), 2;
    const Kernels kernels;
    World w;
    w.lights = Lights(nsp::LightSelection::Power, 4.f,
                      {nsp::QuadLight<S>{nsp::Vec3(-0.6f, 2.6f, -0.6f), nsp::Vec3(1.2f, 0.f, 0.f), nsp::Vec3(0.f, 0.f, 1.2f),
                                         Spectrum::Constant(12.f)}},
                      {}, {nsp::EnvironmentLight<S>{Spectrum::Constant(0.05f)}});
    w.sky = 1;
    const auto& lamp = w.lights.lights<nsp::QuadLight<S>>()[0];
    w.shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 0, -1, -1}});  // light 0
    w.shapes.quads.push_back({nsp::Vec3(-3.f, -1.05f, 3.f), nsp::Vec3(6.f, 0.f, 0.f), nsp::Vec3(0.f, 0.f, -6.f),
                              {0, -1, -1, -1}});  // the floor, material 0, normal up
    if (compare) {
        // The same scene as an nsp::SurfaceScene for nsp::PathEstimator: the host tracks its one
        // medium everywhere, so every shape there has medium 0 on both sides and so does the camera.
        nsp_host::Shapes shapes = w.shapes;
        for (auto& q : shapes.quads) q.h.inside = q.h.outside = 0;
        using Scene = nsp::SurfaceScene<nsp_host::Shapes, Medium, nsp::GlobalMajorant<Medium>, nsp::HenyeyGreensteinPhase,
                                        nsp::Materials<S, nsp::LambertianBsdf<S>>, Lights>;
        const Scene scene(shapes, {{w.cloud, w.majorant, w.phase}}, nsp::Materials<S, nsp::LambertianBsdf<S>>({w.floor_bsdf}),
                          w.lights, 0);
        const nsp::PathEstimator<nsp::strategy::NullScatteringMis, nsp::mis::Balance> estimator;
        const Image host = render(32, 128, 1, [&](const nsp::Ray& r, nsp::Pcg32& rng) { return radiance(kernels, w, r, rng); });
        const Image lib = render(32, 128, 2, [&](const nsp::Ray& r, nsp::Pcg32& rng) {
            nsp::NoLookupCount c;
            return double(estimator.radiance(scene, r, {}, rng, c).value[0]);
        });
        const double z = std::abs(host.mean - lib.mean) / std::hypot(host.se, lib.se);
        std::printf("nsp_host --compare: host loop %.5f +- %.5f, PathEstimator %.5f +- %.5f: %.2f standard errors apart "
                    "(allowed: 5)\n", host.mean, host.se, lib.mean, lib.se, z);
        return z <= 5.0 ? 0 : 1;
    }
    const Image img = render(res, spp, 1, [&](const nsp::Ray& r, nsp::Pcg32& rng) { return radiance(kernels, w, r, rng); });
    std::printf("nsp_host: %dx%d, %d spp, image mean %.5f +- %.5f\n", res, res, spp, img.mean, img.se);
    if (!out.empty()) {
        std::vector<unsigned char> rgb(img.pixels.size() * 3);
        for (std::size_t i = 0; i < img.pixels.size(); ++i) {
            const float v = std::clamp(img.pixels[i] * 2.f, 0.f, 1.f);  // exposure 2, then sRGB
            const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
            rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = static_cast<unsigned char>(std::lround(255.f * s));
        }
        if (!stbi_write_png(out.c_str(), res, res, 3, rgb.data(), 3 * res))
            return std::fprintf(stderr, "nsp_host: cannot write '%s'\n", out.c_str()), 1;
    }
    return 0;
}
