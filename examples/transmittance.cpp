// examples/transmittance.cpp: nsp_transmittance, the transmittance estimators side by side
// (THEORY 5.10, nsp/transmittance.hpp): ratio tracking under a global and a grid majorant,
// residual ratio tracking under a grid control (per-cell minorants), unbiased ray marching under
// a global and a grid majorant, and on the media ratio tracking on the tree majorant's cells and
// residual ratio tracking under the tree control of the same cells. Two tables: a 1-D set of
// analytic extinction profiles along one ray (constant, linear ramp, Gaussian bump, a hole, a
// step, a high-frequency cosine; optical depth 2 each), each against its exact transmittance, and
// shadow rays through the example media (the cloud, the sparse medium, the fog, the plume's smoke)
// and through any .nvdb or .vdb files given with --volume (NanoVdbMedium: the sparse tree's
// lookups, its leaves' bounds for the grids). Per estimator: the variance of one estimate, its
// lookups, their product LTUV (lookups x variance: the cost of a given error, machine
// independent) and LTUV over the better of the global and grid ratio-tracking rows'. Exits 0, or
// 1 when an estimate failed or a 1-D mean is more than 5 standard errors from its exact value.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include <nsp/nsp.hpp>

#include "default_scene.hpp"
#include "tool.hpp"
#include "volume_files.hpp"

namespace {

using namespace nsp;
using M = DenseGridMedium<Mono>;

struct Options {
    int samples = 100000;  ///< estimates per 1-D profile
    int rays = 64;         ///< shadow rays per example medium
    int per_ray = 2000;    ///< estimates per shadow ray
    int grid = 16;         ///< grid majorant and control resolution (per axis; 1-D: along x)
    std::uint64_t seed = 1;
    RayMarchingOptions marching;
    std::vector<std::string> volumes;  ///< .nvdb / .vdb files whose grid `grid` joins the media table
    std::string grid_name = "density";
    float density_scale = 20.f;  ///< extinction per unit of the files' density (albedo 1: mu_s)
};

/// Running mean and variance.
struct Welford {
    double n = 0.0, mean = 0.0, m2 = 0.0;
    void add(double x) {
        n += 1.0;
        const double d = x - mean;
        mean += d / n;
        m2 += d * (x - mean);
    }
    double variance() const { return n > 1.0 ? m2 / (n - 1.0) : 0.0; }
};

/// One row: an estimator's mean variance of one estimate, lookups per estimate, and (1-D) its mean.
struct Result {
    double variance = 0.0, lookups = 0.0, mean = 0.0, se = 0.0;
    std::uint64_t failed = 0;
    double ltuv() const { return variance * lookups; }
};

/// The estimators, in table order: each (ray, tmax, rng, counter) -> TransmittanceSample.
struct Estimators {
    std::vector<std::string> names;
    std::vector<std::function<TransmittanceSample<Mono>(const Ray&, float, Pcg32&, LookupCount&)>> run;
};

/// With `tree`, also ratio tracking on the tree majorant's cells (its adaptive layout) and residual
/// ratio tracking under the tree control of the same cells, after the others.
template <class Med>
Estimators estimators_for(const Med& medium, std::array<int, 3> res, const RayMarchingOptions& marching, bool tree = false) {
    // Owned by the closures (shared_ptr: std::function copies them).
    auto global = std::make_shared<GlobalMajorant<Med>>(medium);
    auto grid = std::make_shared<GridMajorant<Med>>(medium, res);
    auto control = std::make_shared<GridControl<Med>>(medium, res);
    Estimators e;
    const std::string g = std::to_string(res[0]) + (res[1] == 1 ? "" : "^3");
    e.names = {"ratio, global majorant", "ratio, grid " + g, "residual ratio, grid control " + g,
               "ray marching, global majorant", "ray marching, grid " + g};
    e.run.push_back([&medium, global](const Ray& r, float t, Pcg32& rng, LookupCount& n) {
        return transmittance_ratio(medium, *global, r, t, {}, rng, n);
    });
    e.run.push_back([&medium, grid](const Ray& r, float t, Pcg32& rng, LookupCount& n) {
        return transmittance_ratio(medium, *grid, r, t, {}, rng, n);
    });
    e.run.push_back([&medium, control](const Ray& r, float t, Pcg32& rng, LookupCount& n) {
        return transmittance_residual_ratio(medium, *control, r, t, {}, rng, n);
    });
    e.run.push_back([&medium, global, marching](const Ray& r, float t, Pcg32& rng, LookupCount& n) {
        return transmittance_ray_marching(medium, *global, r, t, {}, rng, n, marching);
    });
    e.run.push_back([&medium, grid, marching](const Ray& r, float t, Pcg32& rng, LookupCount& n) {
        return transmittance_ray_marching(medium, *grid, r, t, {}, rng, n, marching);
    });
    if (tree) {
        auto majorant = std::make_shared<TreeMajorant<Med>>(medium);
        auto tree_control = std::make_shared<TreeControl<Med>>(medium);
        e.names.push_back("ratio, tree");
        e.names.push_back("residual ratio, tree control");
        e.run.push_back([&medium, majorant](const Ray& r, float t, Pcg32& rng, LookupCount& n) {
            return transmittance_ratio(medium, *majorant, r, t, {}, rng, n);
        });
        e.run.push_back([&medium, tree_control](const Ray& r, float t, Pcg32& rng, LookupCount& n) {
            return transmittance_residual_ratio(medium, *tree_control, r, t, {}, rng, n);
        });
    }
    return e;
}

/// n estimates along each of `rays` (with its tmax) by estimator k: the variance averaged over the
/// rays, lookups per estimate, and (one ray) the mean and its standard error.
Result measure(const Estimators& e, std::size_t k, const std::vector<std::pair<Ray, float>>& rays, int n,
               std::uint64_t seed) {
    Result out;
    LookupCount lookups;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        Pcg32 rng(seed, 1000 * k + i);
        Welford w;
        for (int s = 0; s < n; ++s) {
            const auto tr = e.run[k](rays[i].first, rays[i].second, rng, lookups);
            if (tr.status != Status::Ok) ++out.failed;
            w.add(double(tr.value[0]));
        }
        out.variance += w.variance() / double(rays.size());
        out.mean = w.mean;
        out.se = std::sqrt(w.variance() / w.n);
    }
    out.lookups = double(lookups.count()) / (double(n) * double(rays.size()));
    return out;
}

/// A 1-D profile d(x), x in [0, 1], on `n` voxels along x, scaled so that its trilinear
/// interpolant integrates to 2 between x = 0 and 1 (the optical depth of the ray along x).
M profile_medium(const std::function<double(double)>& d, int n) {
    std::vector<float> v(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) v[std::size_t(i)] = float(d((i + 0.5) / n));
    auto integral = [&](const std::vector<float>& vox) {  // of the clamped piecewise-linear interpolant
        const M m(Box{Vec3(0.f, -1.f, -1.f), Vec3(1.f, 1.f, 1.f)}, {n, 1, 1}, vox, constant_coefficient<Mono>(0.f),
                  constant_coefficient<Mono>(1.f));
        const int steps = 200000;  // Simpson: the interpolant is linear between centres
        double s = 0.0;
        for (int j = 0; j <= steps; ++j) {
            const double x = std::min(double(j) / steps, 1.0 - 1e-7);
            const double w = (j == 0 || j == steps) ? 1.0 : (j % 2 ? 4.0 : 2.0);
            s += w * m.density(Vec3(float(x), 0.f, 0.f));
        }
        return s / (3.0 * steps);
    };
    const double scale = 2.0 / integral(v);
    for (float& x : v) x = float(x * scale);
    return M(Box{Vec3(0.f, -1.f, -1.f), Vec3(1.f, 1.f, 1.f)}, {n, 1, 1}, std::move(v), constant_coefficient<Mono>(0.f),
             constant_coefficient<Mono>(1.f));
}

void print_header(const char* first) {
    std::printf("| %s | estimator | variance | lookups | LTUV | vs best ratio |\n|---|---|---|---|---|---|\n", first);
}

/// Set-up A's lamp, over the example media's box [-1, 1]^3.
constexpr float kLampX = 0.8f, kLampY = 2.2f, kLampZ = -0.6f;

/// Shadow rays through `medium` (o.rays of them, from points with density toward `lamp`, o.per_ray
/// estimates each): one table row per estimator. Returns the number of rows with a failed estimate.
template <class Med>
int media_rows(const char* name, const Med& medium, const Vec3& lamp, const Options& o) {
    Pcg32 pick(o.seed, 7);
    std::vector<std::pair<Ray, float>> rays;
    const Box b = medium.bounds();
    for (std::uint64_t tries = 0; int(rays.size()) < o.rays; ++tries) {
        if (tries > 1'000'000u)
            throw std::runtime_error(std::string(name) + ": no point with density > 0 in 1e6 uniform draws over its box");
        const Vec3 p = b.lo + (b.hi - b.lo) * Vec3(pick.uniform(), pick.uniform(), pick.uniform());
        if (!(medium.density(p) > 0.f)) continue;  // start where there is medium, as a scattering vertex does
        const Vec3 to = lamp - p;
        rays.push_back({Ray{p, glm::normalize(to)}, glm::length(to)});
    }
    const Estimators e = estimators_for(medium, {o.grid, o.grid, o.grid}, o.marching, true);
    std::vector<Result> results;
    for (std::size_t k = 0; k < e.run.size(); ++k) results.push_back(measure(e, k, rays, o.per_ray, o.seed));
    const double best = std::min(results[0].ltuv(), results[1].ltuv());
    int bad = 0;
    for (std::size_t k = 0; k < results.size(); ++k) {
        const Result& r = results[k];
        bad += r.failed > 0;
        std::printf("| %s | %s | %.3g | %.2f | %.3g | %s |\n", name, e.names[k].c_str(), r.variance, r.lookups,
                    r.ltuv(), best > 0.0 ? (std::to_string(r.ltuv() / best).substr(0, 5) + "x").c_str() : "-");
    }
    return bad;
}

/// The cost model's pick for `medium` (choose_majorant) beside its pick without controls.
template <class Med>
void pick_row(const char* name, const Med& medium) {
    const MajorantCost pick = choose_majorant(medium);
    const MajorantCost plain = choose_grid_resolution(medium);
    const auto label = [](const MajorantCost& c) {
        return c.global ? std::string("global") : (c.control ? "grid control " : "grid ") + std::to_string(c.resolution[0]) + "^3";
    };
    std::printf("| %s | %s | %.3g | %.3g | %.3g | %s, cost %.3g |\n", name, label(pick).c_str(), pick.lookups, pick.steps,
                pick.cost, label(plain).c_str(), plain.cost);
}

#if NSP_HAVE_NANOVDB
using FileMedium = io::NanoVdbMedium<Mono>;
#else
using FileMedium = M;  // never built: --volume is refused without NanoVDB
#endif

/// A volume file of the media table: its grid as a NanoVdbMedium, scattering only (albedo 1).
struct VolumeRow {
    std::string name;
    FileMedium medium;
};

/// Loads o.volumes (their format and that they are regular files checked first: usage errors).
std::vector<VolumeRow> load_volumes(const Options& o) {
    std::vector<VolumeRow> out;
    for (const std::string& path : o.volumes) {
        const std::string ext = nsp_examples::extension_of(path);
        if (ext == ".vol")
            throw nsp_examples::UsageError("--volume '" + path + "': a .nvdb or .vdb file is needed (a sparse NanoVDB "
                                           "grid); the table's example media are dense grids already");
        nsp_examples::usage_checked([&] { nsp_examples::require_format(path, ext); });
        nsp_examples::require_regular_file(path, "a volume file");
#if NSP_HAVE_NANOVDB
        const auto g = nsp_examples::usage_checked([&] {
            std::shared_ptr<const io::NanoDensityGrid> grid;
#if NSP_HAVE_OPENVDB
            if (ext == ".vdb") grid = io::load_vdb(path, o.grid_name);
#endif
            if (ext == ".nvdb") grid = io::load_nvdb(path, o.grid_name);
            return grid;
        });
        const std::string base = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
        char scale[32];
        std::snprintf(scale, sizeof scale, "%g", double(o.density_scale));
        out.push_back({base + " (NanoVDB, x" + scale + ")",
                       FileMedium(g, Mono::Spectrum::Constant(0.f), Mono::Spectrum::Constant(o.density_scale))});
#endif
    }
    return out;
}

int run(int argc, char** argv) {
    Options o;
    CLI::App app("nsp_transmittance: ratio tracking, residual ratio tracking and unbiased ray marching on 1-D "
                 "profiles and on the example media: variance, lookups and LTUV per estimator. Exits 0, 1 if an "
                 "estimate failed or a 1-D mean missed its exact value by more than 5 standard errors, 2 on a bad "
                 "command line.",
                 "nsp_transmittance");
    app.add_option("--samples", o.samples, "estimates per 1-D profile")->check(nsp_examples::integer_in(100, 1 << 26));
    app.add_option("--rays", o.rays, "shadow rays per example medium")->check(nsp_examples::integer_in(1, 1 << 16));
    app.add_option("--per-ray", o.per_ray, "estimates per shadow ray")->check(nsp_examples::integer_in(2, 1 << 24));
    app.add_option("--grid", o.grid, "grid majorant and control resolution")->check(nsp_examples::integer_in(1, 512));
    app.add_option("--seed", o.seed, "random seed")->check(nsp_examples::integer_in(0, 1'000'000'000'000));
    app.add_option("--lookups-per-depth", o.marching.lookups_per_depth,
                   "ray marching: comb lookups per unit of majorant optical depth")
        ->check(CLI::Range(1e-3, 1e3));
    app.add_option("--term-scale", o.marching.term_scale, "ray marching: the roulette's term scale")
        ->check(CLI::Range(1e-6, 1e3));
    app.add_option("--volume", o.volumes,
                   "a .nvdb or .vdb file whose grid (--grid-name) joins the media table (repeatable)");
    app.add_option("--grid-name", o.grid_name, "the files' density grid");
    app.add_option("--density-scale", o.density_scale, "extinction per unit of the files' density")
        ->check(CLI::Range(1e-6, 1e6));
    nsp_examples::parse_flags(app, argc, argv);
    validate(o.marching);
    const std::vector<VolumeRow> volumes = load_volumes(o);  // bad paths fail before any work

    int bad = 0;
    std::printf("## 1-D extinction profiles (optical depth 2 along x, 256 voxels, grid %d x 1 x 1; %d estimates)\n\n",
                o.grid, o.samples);
    std::printf("exact T = exp(-2) = %.6f; every mean is checked against it within 5 standard errors\n\n",
                std::exp(-2.0));
    print_header("profile");
    const double pi = 3.14159265358979323846;
    const std::vector<std::pair<const char*, std::function<double(double)>>> profiles = {
        {"constant", [](double) { return 1.0; }},
        {"linear ramp", [](double x) { return x; }},
        {"Gaussian bump", [](double x) { return 0.05 + std::exp(-0.5 * (x - 0.5) * (x - 0.5) / (0.08 * 0.08)); }},
        {"hole", [](double x) { return (x > 0.4 && x < 0.6) ? 0.0 : 1.0; }},
        {"step", [](double x) { return x < 0.5 ? 0.2 : 1.0; }},
        {"cosine (16 periods)", [pi](double x) { return 1.0 + 0.9 * std::cos(2.0 * pi * 16.0 * x); }},
    };
    for (const auto& [name, d] : profiles) {
        const M medium = profile_medium(d, 256);
        const Estimators e = estimators_for(medium, {o.grid, 1, 1}, o.marching);
        const std::vector<std::pair<Ray, float>> ray{{Ray{Vec3(0.f), Vec3(1.f, 0.f, 0.f)}, 1.f}};
        std::vector<Result> results;
        for (std::size_t k = 0; k < e.run.size(); ++k) results.push_back(measure(e, k, ray, o.samples, o.seed));
        const double best = std::min(results[0].ltuv(), results[1].ltuv());
        for (std::size_t k = 0; k < results.size(); ++k) {
            const Result& r = results[k];
            const bool off = std::abs(r.mean - std::exp(-2.0)) > 5.0 * r.se + 1e-6;
            bad += off || r.failed > 0;
            std::printf("| %s | %s | %.3g | %.2f | %.3g | %s |%s\n", name, e.names[k].c_str(), r.variance, r.lookups,
                        r.ltuv(), best > 0.0 ? (std::to_string(r.ltuv() / best).substr(0, 5) + "x").c_str() : "-",
                        off ? " MEAN OFF" : "");
        }
    }

    std::printf("\n## Shadow rays through the example media (%d rays from points inside toward set-up A's lamp%s, "
                "%d estimates each, grid %d^3)\n\n",
                o.rays, volumes.empty() ? "" : "; for a volume file at the same place relative to its box", o.per_ray,
                o.grid);
    print_header("medium");
    using namespace nsp_examples;
    const std::vector<std::pair<const char*, M>> media = {
        {"cloud (A, B)", make_default_medium<Mono>()},
        {"sparse (SA)", make_sparse_medium<Mono>()},
        {"fog (F1, F2)", make_fog_medium<Mono>(FogSetup::F1)},
        {"dense fog (F3)", make_fog_medium<Mono>(FogSetup::F3)},
        {"plume's smoke (P1)", make_plume_medium<Mono>().base()},
    };
    for (const auto& [name, medium] : media) bad += media_rows(name, medium, Vec3(kLampX, kLampY, kLampZ), o);
    for (const auto& v : volumes) {  // the lamp where set-up A's is, relative to the file's box
        const Box b = v.medium.bounds();
        const Vec3 lamp = 0.5f * (b.lo + b.hi) + 0.5f * (b.hi - b.lo) * Vec3(kLampX, kLampY, kLampZ);
        bad += media_rows(v.name.c_str(), v.medium, lamp, o);
    }
    // The cost model's pick per medium (choose_majorant: choose_grid_resolution's majorants and the
    // grid controls, lookups + step cost x steps per random line through the box).
    std::printf("\n## The cost model's pick (choose_majorant; per random line: lookups + %.2f x steps, a control's "
                "steps at %.2f)\n\n| medium | pick | lookups | steps | cost | best grid alone |\n|---|---|---|---|---|---|\n",
                double(kDefaultStepCost), double(kDefaultControlStepCost));
    for (const auto& [name, medium] : media) pick_row(name, medium);
    for (const auto& v : volumes) pick_row(v.name.c_str(), v.medium);
    return bad ? kExitRuntime : kExitOk;
}

}  // namespace

int main(int argc, char** argv) { return nsp_examples::run_tool("nsp_transmittance", [&] { return run(argc, argv); }); }
