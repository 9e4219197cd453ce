// examples/host/host.cpp: a host renderer with its own geometry and path loop, which takes from
// nsp only what a renderer would: a chromatic, emissive medium, its majorant, a BSDF, a phase
// function, the light sampler, the SurfaceHit record its geometry (shapes.hpp, an nsp::Geometry)
// reports, and the path-vertex layer: the path state (nsp/path_state.hpp, here per channel with
// spectral MIS) and the technique kernels that update it (equiangular_nee, emission_segment,
// light_nee, volume_nee). The scene: a glowing, chromatic cloud over a diffuse floor under a
// rectangular light, a point light and a dim sky.
//
//   nsp_host [--res N] [--spp N] [--out FILE.png]   renders the scene, prints its image mean
//   nsp_host --compare                              renders the scene with this loop and with
//       nsp::SpectralPathEstimator over the same nsp::SurfaceScene, and checks that every
//       channel's image mean agrees within 5 standard errors (exit 1 if not; independent seeds):
//       the host's loop and the library's are the same estimator.
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

using S = nsp::Rgb;
using Spectrum = S::Spectrum;
using Cloud = nsp::Emissive<nsp::DenseGridMedium<S>>;
using Majorant = nsp::GlobalMajorant<Cloud>;
using Lights = nsp::LightSampler<S, nsp::PointLight<S>, nsp::QuadLight<S>, nsp::EnvironmentLight<S>>;
using Materials = nsp::Materials<S, nsp::LambertianBsdf<S>>;
using Scene = nsp::SurfaceScene<nsp_host::Shapes, Cloud, Majorant, nsp::HenyeyGreensteinPhase, Materials, Lights>;
// Tracking, NEE and equiangular sampling in one MIS (with the emission techniques), per channel.
using Strategy = nsp::strategy::EquiangularMis;
using Kernels = nsp::VertexKernels<Strategy, nsp::mis::Balance, nsp::absorption::Weight>;
using State = nsp::PathState<nsp::channels::SpectralMis, Strategy, nsp::mis::Balance, nsp::absorption::Weight, S, true>;

/// A soft ball of density on a 32^3 grid over [-1, 1]^3, bluish (more scattering at short
/// wavelengths), glowing orange in its core.
Cloud make_cloud() {
    const int n = 32;
    std::vector<float> density(std::size_t(n) * n * n), glow(density.size());
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const nsp::Vec3 p = -1.f + 2.f * (nsp::Vec3(float(x), float(y), float(z)) + 0.5f) / float(n);
                const std::size_t i = std::size_t(x) + std::size_t(n) * (std::size_t(y) + std::size_t(n) * std::size_t(z));
                density[i] = std::max(0.f, 1.f - glm::dot(p, p) / 0.8f);
                glow[i] = std::max(0.f, 1.f - glm::dot(p, p) / 0.2f);
            }
    const nsp::Box box{nsp::Vec3(-1.f), nsp::Vec3(1.f)};
    nsp::DenseGridMedium<S> smoke(box, {n, n, n}, std::move(density), Spectrum(0.6f, 0.5f, 0.4f), Spectrum(4.f, 6.f, 9.f));
    return Cloud(std::move(smoke), nsp::EmissionGrid(box, {n, n, n}, std::move(glow)), Spectrum(3.f, 1.2f, 0.3f));
}

/// The host's world as an nsp::SurfaceScene: its shapes (the floor, material 0, and the lamp's
/// quad, light 1), the cloud (medium 0, filling the world: tracking clips it to its box), the
/// floor's BSDF and the lights (0: the point light, 1: the lamp, 2: the sky).
Scene make_scene() {
    Cloud cloud = make_cloud();
    const Majorant majorant(cloud);
    const nsp::QuadLight<S> lamp{nsp::Vec3(-0.6f, 2.6f, -0.6f), nsp::Vec3(1.2f, 0.f, 0.f), nsp::Vec3(0.f, 0.f, 1.2f),
                                 Spectrum::Constant(12.f)};
    Lights lights(nsp::LightSelection::Power, 4.f, {nsp::PointLight<S>{nsp::Vec3(1.8f, 0.4f, -1.2f), Spectrum(6.f, 8.f, 10.f)}},
                  {lamp}, {nsp::EnvironmentLight<S>{Spectrum::Constant(0.05f)}});
    nsp_host::Shapes shapes;
    shapes.quads.push_back({lamp.corner, lamp.edge_u, lamp.edge_v, {-1, 1, 0, 0}});
    shapes.quads.push_back({nsp::Vec3(-3.f, -1.05f, 3.f), nsp::Vec3(6.f, 0.f, 0.f), nsp::Vec3(0.f, 0.f, -6.f), {0, -1, 0, 0}});
    return Scene(std::move(shapes), {{std::move(cloud), majorant, nsp::HenyeyGreensteinPhase{0.6f}}},
                 Materials({nsp::LambertianBsdf<S>{Spectrum(0.6f, 0.6f, 0.5f)}}), std::move(lights), 0);
}

/// One path of the host's loop, every channel's estimate. Each segment: an equiangular vertex
/// toward the lights' points and NEE from it; a point drawn along it by the emission grid (the
/// segment technique); delta tracking, whose tentative collisions collect the emission; then at
/// a real vertex (floor or medium) NEE toward the lights and toward the glowing volume. The path
/// state weighs them all against each other, over channels (spectral MIS). A failed flight or a
/// value beyond float's range gives no estimate (0).
Spectrum radiance(const Kernels& k, const Scene& sc, nsp::Ray ray, nsp::Pcg32& rng) {
    const S::Wavelengths lambda{};
    const nsp::ChannelSelection<S> selection;  // the sampling channel, drawn uniformly
    nsp::NoLookupCount counter;
    State st(k, &selection, rng);
    const auto& m = sc.media[0];
    auto cloud_side = [](const nsp::Vec3&) { return 0; };  // the medium on every side of every vertex
    Spectrum L = Spectrum::Zero();
    st.prev = ray.o;
    for (int depth = 0;;) {
        const nsp::SurfaceHit hit = sc.geometry.intersect(ray, nsp::kInf);
        st.start_piece();
        const nsp::Interval in = m.medium.bounds().clip(ray, 0.f, hit.t);
        const nsp::PieceEquiangular<Scene> eq(sc, ray, in.t0, in.t1);
        const float eq_select = eq.valid() ? eq.selection<Strategy, Cloud>(k.options(), m.majorant, lambda) : 1.f;
        if (eq.valid() && depth < k.options().max_depth && nsp::draw_technique(eq_select, rng))
            if (nsp::equiangular_nee(st, sc, 0, ray, eq, eq_select, depth + 1, lambda, rng, counter, L) != nsp::Status::Ok)
                return Spectrum::Zero();
        nsp::Status status = nsp::Status::Ok;
        const float along = nsp::emission_segment(st, sc, 0, ray, hit.t, lambda, rng, counter, L, status);
        if (status != nsp::Status::Ok) return Spectrum::Zero();
        float t = 0.f;
        const nsp::SegmentEnd end =
            st.counts_hits()
                ? st.track(m.medium, m.majorant, ray, hit.t, lambda, rng, counter,
                           st.collector(m.medium, ray, lambda, L, counter, along, sc.emission_selection_pdf(0)), t)
                : st.track(m.medium, m.majorant, ray, hit.t, lambda, rng, counter, nsp::NoVisit{}, t);
        if (nsp::flight_status(end) != nsp::Status::Ok) return Spectrum::Zero();
        if (end != nsp::SegmentEnd::Scattered && end != nsp::SegmentEnd::Passed) break;  // absorbed
        State::P eq_x = State::P::Zero();  // the equiangular technique's pdf of a medium vertex here
        if (end == nsp::SegmentEnd::Scattered && eq.valid()) eq_x = st.vertex_eq(eq_select * eq.density(t));
        st.end_piece();
        int material = -1;
        nsp::Vec3 x = ray.at(t);
        if (end == nsp::SegmentEnd::Passed) {  // a surface, or the sky: a light there, weighed against NEE
            const int light = hit.found() ? hit.light : 2;
            if (light >= 0) {
                // On a surface the light sees the hit, in its radiance and its density.
                if (st.counts_hits() && hit.found()) {
                    const nsp::ShadingPoint at = hit.shading();
                    L += st.light_hit(sc.lights.emitted(light, at, ray.d, lambda),
                                      st.nee_alternative() ? sc.lights.pdf(light, st.prev, ray.d, at) : 0.f, counter);
                } else if (st.counts_hits()) {
                    L += st.light_hit(sc.lights.emitted(light, ray.d, lambda),
                                      st.nee_alternative() ? sc.lights.pdf(light, st.prev, ray.d) : 0.f, counter);
                }
                break;
            }
            material = hit.material;
            x = hit.p;
        }
        if (++depth > k.options().max_depth) break;
        const float q = st.survival(depth);  // decided before NEE: the continuing path carries it
        const nsp::SceneVertex v{material, 0, hit.shading()};
        if (st.draw_nee(rng) &&
            nsp::light_nee(st, sc, v, x, ray.d, st.vertex(q, eq_x), cloud_side, lambda, rng, counter, L) != nsp::Status::Ok)
            return Spectrum::Zero();
        if (nsp::volume_nee(st, sc, v, x, ray.d, st.vertex(q, eq_x), cloud_side, lambda, rng, counter, L) != nsp::Status::Ok)
            return Spectrum::Zero();
        if (!st.roulette(q, rng)) break;
        const auto next = nsp::sample_vertex(sc, v, ray.d, rng, lambda);
        if (!(next.pdf > 0.f)) break;
        if (const nsp::StateScale r = st.scatter(next, q, eq_x, x); r != nsp::StateScale::Ok) {
            if (r == nsp::StateScale::Overflowed) return Spectrum::Zero();
            break;
        }
        ray = nsp::Ray{x, next.wi};
    }
    return nsp::all_finite(L) ? L : Spectrum::Zero();
}

/// The camera ray through (u, v) in [0, 1)^2 of the image (pinhole, 40 degrees).
nsp::Ray camera(float u, float v) {
    const float s = std::tan(0.5f * 40.f * nsp::kPi / 180.f);
    return {nsp::Vec3(0.f, 0.3f, -4.5f), glm::normalize(nsp::Vec3((1.f - 2.f * u) * s, (1.f - 2.f * v) * s, 1.f))};
}

/// A rendered image (RGB) and every channel's mean and standard error over all its samples.
struct Image {
    std::vector<float> pixels;
    double mean[3] = {}, se[3] = {};
};
template <class Estimate>
Image render(int res, int spp, std::uint64_t seed, Estimate estimate) {
    Image img;
    img.pixels.resize(std::size_t(res) * std::size_t(res) * 3);
    double sum[3] = {}, sum2[3] = {};
    for (int y = 0; y < res; ++y)
        for (int x = 0; x < res; ++x) {
            nsp::Pcg32 rng(seed, std::uint64_t(y) * std::uint64_t(res) + std::uint64_t(x));
            Spectrum p = Spectrum::Zero();
            for (int i = 0; i < spp; ++i) {
                const Spectrum L = estimate(camera((float(x) + rng.uniform()) / float(res), (float(y) + rng.uniform()) / float(res)), rng);
                p += L;
                for (int c = 0; c < 3; ++c) {
                    sum[c] += double(L[c]);
                    sum2[c] += double(L[c]) * double(L[c]);
                }
            }
            for (int c = 0; c < 3; ++c) img.pixels[3 * (std::size_t(y) * std::size_t(res) + std::size_t(x)) + std::size_t(c)] = p[c] / float(spp);
        }
    const double n = double(res) * res * spp;
    for (int c = 0; c < 3; ++c) {
        img.mean[c] = sum[c] / n;
        img.se[c] = std::sqrt(std::max(0.0, sum2[c] / n - img.mean[c] * img.mean[c]) / (n - 1.0));
    }
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
    const Scene scene = make_scene();
    auto host_loop = [&](const nsp::Ray& r, nsp::Pcg32& rng) { return radiance(kernels, scene, r, rng); };
    if (compare) {
        // The library's own loop over the same scene, with the same strategy and options.
        const nsp::SpectralPathEstimator<nsp::channels::SpectralMis, Strategy, nsp::mis::Balance> estimator;
        const Image host = render(32, 128, 1, host_loop);
        const Image lib = render(32, 128, 2, [&](const nsp::Ray& r, nsp::Pcg32& rng) {
            nsp::NoLookupCount c;
            const auto e = estimator.radiance(scene, r, {}, rng, c);
            return e.status == nsp::Status::Ok ? Spectrum(e.value) : Spectrum(Spectrum::Zero());
        });
        double worst = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double z = std::abs(host.mean[c] - lib.mean[c]) / std::hypot(host.se[c], lib.se[c]);
            worst = std::max(worst, z);
            std::printf("nsp_host --compare, channel %d: host loop %.5f +- %.5f, SpectralPathEstimator %.5f +- %.5f: "
                        "%.2f standard errors apart (allowed: 5)\n", c, host.mean[c], host.se[c], lib.mean[c], lib.se[c], z);
        }
        return worst <= 5.0 ? 0 : 1;
    }
    const Image img = render(res, spp, 1, host_loop);
    std::printf("nsp_host: %dx%d, %d spp, image mean (%.5f +- %.5f, %.5f +- %.5f, %.5f +- %.5f)\n", res, res, spp,
                img.mean[0], img.se[0], img.mean[1], img.se[1], img.mean[2], img.se[2]);
    if (!out.empty()) {
        std::vector<unsigned char> rgb(img.pixels.size());
        for (std::size_t i = 0; i < img.pixels.size(); ++i) {
            const float v = std::clamp(img.pixels[i] * 2.f, 0.f, 1.f);  // exposure 2, then sRGB
            const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.f / 2.4f) - 0.055f;
            rgb[i] = static_cast<unsigned char>(std::lround(255.f * s));
        }
        if (!stbi_write_png(out.c_str(), res, res, 3, rgb.data(), 3 * res))
            return std::fprintf(stderr, "nsp_host: cannot write '%s'\n", out.c_str()), 1;
    }
    return 0;
}
