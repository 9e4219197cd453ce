// examples/volume.cpp: nsp_volume renders a user's volume file (Mitsuba's .vol, nsp/io/vol.hpp)
// with a camera that frames its bounds, under a dim white sky and a small sphere light above it, with three
// strategies of nsp::PathEstimator, and prints their efficiency table; or exports the default
// cloud as a .vol, the data the tests and this example's smoke test read.
//
//   nsp_volume FILE.vol [--channel C] [--density-scale S] [--albedo A] [--g G]
//              [--majorant global|grid] [--grid-res N] [--res N] [--spp N] [--threads N]
//              [--out DIR] [--no-png]
//   nsp_volume --export-cloud FILE.vol
//
// The file's values are densities at voxel centres over its box; the medium's extinction is
// density x density-scale, its albedo `albedo` (grey), its phase function Henyey-Greenstein g.
// Writes DIR/volume.png (uni-nee-mis balance) unless --no-png. Exits 1 if a path ended with a
// status other than Ok, 2 on a bad command line or a bad file (with the loader's message).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nsp/io/vol.hpp>

#include "default_scene.hpp"
#include "image_render.hpp"
#include "png_writer.hpp"

namespace {

using nsp_examples::Row;

/// Renders `medium` under `majorant` with the three strategies and prints the table; returns the
/// number of failed paths.
template <class Maj>
std::uint64_t run_all(const nsp::DenseGridMedium<nsp::Mono>& medium, const Maj& majorant, float g, int res, int spp,
                      int threads, const std::string& out, bool no_png) {
    using namespace nsp;
    const Box b = medium.bounds();
    const Vec3 centre = 0.5f * (b.lo + b.hi);
    const float radius = 0.5f * glm::length(b.hi - b.lo);
    Lights<Mono> lights;
    lights.set(EnvironmentLight<Mono>{Mono::Spectrum::Constant(0.1f)});
    // A small sphere light above (radius 0.15 half-diagonals, 2.2 away): every strategy reaches it.
    lights.set(SphereLight<Mono>{centre + radius * Vec3(0.6f, 2.f, -0.8f), 0.15f * radius, Mono::Spectrum::Constant(250.f)});
    const auto scene = Scene(medium, majorant, HenyeyGreensteinPhase(g), lights);
    // 40 degrees vertical field of view from 2.2 half-diagonals in front of the centre, a little
    // above it: the box's inscribed sphere fills the frame.
    const Vec3 eye = centre + radius * Vec3(0.f, 0.6f, -2.1f);
    const Vec3 f = glm::normalize(centre - eye);
    const Vec3 r = glm::normalize(glm::cross(Vec3(0.f, 1.f, 0.f), f));
    const Vec3 up = glm::cross(f, r);
    const float tan_half = std::tan(0.5f * 40.f * kPi / 180.f);
    auto camera = [&](float u, float v) {
        return Ray{eye, glm::normalize(f + (2.f * u - 1.f) * tan_half * r + (2.f * v - 1.f) * tan_half * up)};
    };
    std::vector<Row> rows;
    rows.push_back(nsp_examples::render_image(scene, PathEstimator<strategy::Unidirectional>{}, "unidirectional", res,
                                              spp, threads, 1, camera));
    rows.push_back(nsp_examples::render_image(scene, PathEstimator<strategy::NextEvent>{}, "ratio-nee", res, spp,
                                              threads, 2, camera));
    rows.push_back(nsp_examples::render_image(scene, PathEstimator<strategy::NullScatteringMis, mis::Balance>{},
                                              "uni-nee-mis_balance", res, spp, threads, 3, camera));
    const double samples = double(res) * res * spp;
    double best = kInf;
    for (const Row& row : rows) best = std::min(best, row.cpu_seconds / samples * row.variance);
    std::printf("%-24s %8s %11s %11s %11s %10s %9s %9s\n", "estimator", "seconds", "lookups/spl", "var/spl", "cpu-s*var",
                "cpu/best", "mean", "se");
    std::uint64_t failed = 0;
    for (const Row& row : rows) {
        const double cv = row.cpu_seconds / samples * row.variance;
        std::printf("%-24s %8.2f %11.3g %11.3g %11.3g %10.3g %9.4g %9.2g\n", row.name.c_str(), row.seconds, row.lookups,
                    row.variance, cv, cv / best, row.mean, row.se);
        failed += row.failed;
    }
    std::printf("Paths with a failed status: %llu\n", static_cast<unsigned long long>(failed));
    if (!no_png) {
        std::filesystem::create_directories(out);
        const std::string path = out + "/volume.png";
        nsp_examples::write_png(path, rows.back().image, nsp_examples::exposure_for({&rows.back().image}));
        std::printf("wrote %s\n", path.c_str());
    }
    return failed;
}

}  // namespace

int main(int argc, char** argv) {
    std::string file, export_path, majorant = "global", out = "out";
    int channel = 0, grid_res = 32, res = 128, spp = 64, threads = int(std::max(1u, std::thread::hardware_concurrency()));
    float density_scale = 10.f, albedo = 0.9f, g = 0.5f;
    bool no_png = false;
    CLI::App app("nsp_volume: render a volume file (Mitsuba .vol) with nsp's path estimators", "nsp_volume");
    app.add_option("file", file, "the .vol file to render");
    app.add_option("--export-cloud", export_path, "write the default cloud (64^3 over [-1, 1]^3) to this .vol file and exit");
    app.add_option("--channel", channel, "the file's channel that holds the density")->check(CLI::NonNegativeNumber);
    app.add_option("--density-scale", density_scale, "extinction per unit of the file's density")
        ->check(CLI::PositiveNumber);
    app.add_option("--albedo", albedo, "single-scattering albedo (grey)")->check(CLI::Range(0.f, 1.f));
    app.add_option("--g", g, "Henyey-Greenstein asymmetry")->check(CLI::Range(-0.99f, 0.99f));
    app.add_option("--majorant", majorant, "global (one value) or grid (a grid of cell maxima)")
        ->check(CLI::IsMember({"global", "grid"}));
    app.add_option("--grid-res", grid_res, "cells per axis of the grid majorant")->check(CLI::Range(1, 256));
    app.add_option("--res", res, "image width and height in pixels")->check(CLI::Range(1, 4096));
    app.add_option("--spp", spp, "samples per pixel")->check(CLI::Range(2, 1 << 20));
    app.add_option("--threads", threads, "worker threads")->check(CLI::Range(1, 256));
    app.add_option("--out", out, "directory for volume.png");
    app.add_flag("--no-png", no_png, "write no picture");
    CLI11_PARSE(app, argc, argv);

    try {
        if (!export_path.empty()) {
            nsp::io::VoxelGrid cloud;
            cloud.bounds = nsp::Box{nsp::Vec3(-1.f), nsp::Vec3(1.f)};
            cloud.resolution = {nsp_examples::kGridRes, nsp_examples::kGridRes, nsp_examples::kGridRes};
            cloud.values = nsp_examples::default_cloud_density();
            nsp::io::write_vol(export_path, cloud);
            std::printf("wrote %s: the default cloud, %dx%dx%d voxels over [-1, 1]^3\n", export_path.c_str(),
                        cloud.resolution[0], cloud.resolution[1], cloud.resolution[2]);
            return 0;
        }
        if (file.empty()) {
            std::fprintf(stderr, "nsp_volume: give a .vol file to render, or --export-cloud FILE.vol\n");
            return 2;
        }
        const nsp::io::VoxelGrid grid = nsp::io::load_vol(file);
        using M = nsp::DenseGridMedium<nsp::Mono>;
        const M medium = nsp::io::to_dense_medium<nsp::Mono>(grid, M::Spectrum::Constant(density_scale * (1.f - albedo)),
                                                             M::Spectrum::Constant(density_scale * albedo), channel);
        const nsp::Vec3 lo = grid.bounds.lo, hi = grid.bounds.hi;
        std::printf("%s: %dx%dx%d voxels, %d channel(s), box [%g, %g, %g] - [%g, %g, %g], largest extinction %g\n",
                    file.c_str(), grid.resolution[0], grid.resolution[1], grid.resolution[2], grid.channels, lo.x, lo.y,
                    lo.z, hi.x, hi.y, hi.z, double(medium.max_extinction()));
        std::printf("Volume (mono, %dx%d, %d spp, %d threads, %s majorant): a dim sky and a small sphere light\n", res, res,
                    spp, threads, majorant == "grid" ? ("grid " + std::to_string(grid_res) + "^3").c_str() : "global");
        const std::uint64_t failed =
            majorant == "grid" ? run_all(medium, nsp::GridMajorant<M>(medium, grid_res), g, res, spp, threads, out, no_png)
                               : run_all(medium, nsp::GlobalMajorant<M>(medium), g, res, spp, threads, out, no_png);
        return failed == 0 ? 0 : 1;
    } catch (const nsp::InvalidArgument& e) {
        std::fprintf(stderr, "nsp_volume: %s\n", e.what());
        return 2;
    }
}
