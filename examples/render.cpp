// examples/render.cpp: nsp_render, the example host renderer and the project's main job.
//
// Renders the scenes of examples/default_scene.hpp with the path estimators nsp offers, writes
// one EXR per render and prints an efficiency table per light set-up and spectral mode (THEORY 7:
// LTUV = density lookups per sample x variance of one sample):
// - the grey cloud in set-ups A and B (mono), with every nsp::PathEstimator;
// - the chromatic cloud (extinction 1 : 4 : 16) in set-ups C1 and C2 (rgb and hero), with the
//   spectral estimators (independent tracking, spectral tracking, spectral MIS) beside the
//   grey-majorant baseline (THEORY 5.3);
// - the sparse medium in set-up SA (mono, set-up A's light), the global majorant against the grid
//   majorant (THEORY 4) for each grey strategy;
// - the fog bank lit by a lamp in set-ups F1, F2, F3 (mono): tracking + NEE against equiangular
//   sampling and their three-way MIS (THEORY 5.4), global and grid majorant;
// - the flame inside the cloud, set-up P1 (rgb, an emissive medium): the collision estimator of
//   emission against NEE toward the emitting volume and their MIS (THEORY 5.7).
// The majorant is an axis of its own (--majorant): every table can compare majorants, the
// non-bounding ones (bound::Signed, Clamp with a deliberately low majorant) included.
// This file plans renders by name and prints the tables; the command-line choices become types
// once, in render_combination<S> (render_job.hpp), whose render loops are monomorphic.
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include <nsp/nsp.hpp>

#include "combinations.hpp"
#include "default_scene.hpp"
#include "exr_writer.hpp"
#include "render_job.hpp"
#include "type_list.hpp"

namespace {

using namespace nsp_examples;

// ---------------------------------------------------------------------------------------------
// Defaults

/// The grey cloud keeps the resolution and sample count of the existing table.
constexpr int kCloudWidth = 128, kCloudHeight = 128, kCloudSpp = 256;
/// The chromatic cloud: its tracking costs several times the grey cloud's lookups per sample, and
/// scripts/run-main.sh (the grey cloud's ~100 s, these 4 tables, the heavy-tail comparison with its
/// reference images) must render in about 200 s on 2 cores. The size of the comparison, so that
/// a default table's row is run 1 (seed 1) of the comparison.
constexpr int kChromaticWidth = 32, kChromaticHeight = 32, kChromaticSpp = 128;

/// The sparse medium: a global majorant spends most of its lookups on empty space here (extinction
/// 60 in ~2% of the box), so a sample costs several times the grey cloud's; a smaller image keeps
/// the main job's budget (~20 s for the 8 renders on 2 cores). The grid majorant's resolution is --grid-res (default 16: a neutral
/// middle, not tuned to this medium).
constexpr int kSparseWidth = 64, kSparseHeight = 64, kSparseSpp = 256;

/// The fog: thin (F1, F2) or dense (F3) fog lit by a lamp. A thin-fog sample is cheap (most camera
/// rays cross the fog without a real collision: 0.1-1.5 us), a dense-fog one costs 30-70 lookups
/// (2-8 us), so F3 gets half the samples; the 30 renders take about 15 s on 2 cores. The size of
/// run-main.sh's F1 comparison, so that a default table's row is its run 1 (seed 1).
constexpr int kFogWidth = 64, kFogHeight = 64, kFogSpp = 128, kDenseFogSpp = 64;
/// The plume: 8 renders (4 estimators, 2 majorants) in about 4 s on 2 cores; the size of
/// run-main.sh's P1 comparison.
constexpr int kPlumeWidth = 64, kPlumeHeight = 64, kPlumeSpp = 256;

/// The estimators of the grey cloud by default: every PathEstimator but the equiangular ones (the
/// existing table; its sphere lights are the fog's business), both absorption policies.
const std::vector<std::string> kCloudEstimators{"unidirectional_grey", "ratio-nee_grey", "directional-mis_grey",
                                                "uni-nee-mis_grey"};
/// The estimators of the sparse medium by default: each grey strategy once (absorb-weight, the
/// balance heuristic for the MIS strategies); each with every majorant of --majorant.
const std::vector<std::string> kSparseEstimators{
    "unidirectional_grey_absorb-weight",
    "ratio-nee_grey_absorb-weight",
    "directional-mis_grey_balance_absorb-weight",
    "uni-nee-mis_grey_balance_absorb-weight",
};

/// The estimators of the fog by default (absorb-weight): tracking + NEE (ratio-nee; with a point
/// light, uni-nee-mis is the same estimator: a point light cannot be hit), equiangular + NEE, and
/// the three-way MIS with the balance and the power heuristic.
const std::vector<std::string> kFogEstimators{
    "ratio-nee_grey_absorb-weight",
    "uni-nee-mis_grey_balance_absorb-weight",
    "equiangular-nee_grey_absorb-weight",
    "uni-nee-eq-mis_grey_absorb-weight",
};
/// The estimators of the plume by default (absorb-weight): the collision estimator alone
/// (unidirectional), NEE toward the emitting volume (ratio-nee; collisions on camera rays only),
/// and their MIS with the balance and the power heuristic.
const std::vector<std::string> kPlumeEstimators{
    "unidirectional_grey_absorb-weight",
    "ratio-nee_grey_absorb-weight",
    "uni-nee-mis_grey_absorb-weight",
};

/// The majorants of each scene by default (--majorant overrides them for every scene).
const std::vector<std::string> kCloudMajorants{"global"};
const std::vector<std::string> kChromaticMajorants{"global", "per-channel"};
const std::vector<std::string> kSparseMajorants{"global", "grid"};
const std::vector<std::string> kFogMajorants{"global", "grid"};
const std::vector<std::string> kPlumeMajorants{"global", "grid"};
/// The estimators of the chromatic cloud by default (absorb-weight rows): the grey-majorant
/// baseline with NEE MIS; each spectral channel policy unidirectional and with NEE MIS; spectral
/// MIS also with NEE alone; with --selection both, spectral MIS + NEE and independent + NEE also
/// with luminance selection.
const std::vector<std::string> kChromaticEstimators{
    "uni-nee-mis_grey_balance_absorb-weight",
    "unidirectional_independent_absorb-weight_uniform",
    "uni-nee-mis_independent_absorb-weight",
    "unidirectional_spectral-tracking-max_absorb-weight",
    "uni-nee-mis_spectral-tracking-max_absorb-weight",
    "unidirectional_spectral-tracking-avg_absorb-weight",
    "uni-nee-mis_spectral-tracking-avg_absorb-weight",
    "unidirectional_spectral-mis_per-channel_absorb-weight_uniform",
    "ratio-nee_spectral-mis_per-channel_absorb-weight_uniform",
    "uni-nee-mis_spectral-mis_per-channel_absorb-weight",
    "unidirectional_spectral-mis_global_absorb-weight_uniform",
    "uni-nee-mis_spectral-mis_global_absorb-weight",
};

/// The estimator of --reference-spp on the chromatic cloud: unbiased, finite variance there (one
/// shared pdf under the grey majorant, weights mu_c / (mu_bar P) bounded), and none of the compared
/// ones.
constexpr const char* kReferenceEstimator = "uni-nee-mis_spectral-tracking-avg_global_balance_absorb-weight";
/// The estimator of --reference-spp on the fog: the three-way MIS with absorb-event (none of the
/// default rows). Its NEE from tracked vertices near the lamp is weighted down by the equiangular
/// pdf there, so unlike tracking + NEE it has no 1/r^2 tail around a lamp inside the fog.
constexpr const char* kFogReferenceEstimator = "uni-nee-eq-mis_balance_absorb-event";
/// The estimator of --reference-spp on the plume: emission NEE and collisions combined by the
/// directional MIS weights under the grid majorant (none of the default rows; its weights sum to
/// 1 and tame NEE's 1/d^2 near the flame as the null-scattering ones do).
constexpr const char* kPlumeReferenceEstimator = "directional-mis_grid_balance_absorb-weight";
/// The reference's seeds: seed + this (the rows use seed .. seed + runs - 1, runs <= 1000).
constexpr std::uint64_t kReferenceSeedOffset = 1000000;

// ---------------------------------------------------------------------------------------------
// Command line

struct Options {
    std::optional<int> width, height, spp;  ///< empty: the scene's default
    int threads = std::max(1, int(std::thread::hardware_concurrency()));
    std::uint64_t seed = 1;
    int runs = 1;
    std::optional<int> reference_spp;  ///< --reference-spp: effective (error-based) variance
    nsp::EstimatorOptions estimator;  ///< max depth and roulette settings
    std::string out = "out";
    bool write_exr = true;
    bool list = false;
    std::vector<SceneKind> scenes{SceneKind::Cloud, SceneKind::Chromatic, SceneKind::Sparse, SceneKind::Fog,
                                  SceneKind::Plume};
    std::vector<std::string> setups{"A", "B", "C1", "C2", "SA", "F1", "F2", "F3", "P1"};
    std::vector<std::string> majorants;  ///< majorant names (empty: the scene's defaults)
    bool all_majorants = false;          ///< --majorant all: names without a row in a mode are no error
    MajorantSettings majorant;           ///< --grid-res, --majorant-scale
    std::vector<std::string_view> modes;  ///< empty: mono for the cloud, rgb and hero for the chromatic cloud
    std::vector<std::string> estimators;  ///< filter tokens (empty: the scene's defaults)
    std::vector<SelectionRule> selections{SelectionRule::Uniform, SelectionRule::Luminance};
    LightOverrides lights;
};

constexpr const char* kHelp = R"(nsp_render: render the example scenes with nsp's path estimators and print an efficiency
table per light set-up and spectral mode (LTUV = density lookups per sample x variance per
sample; cpu-s*var = CPU seconds per sample x variance per sample; lower is better).

Default run (no flags): the grey cloud, set-ups A and B, mono, 128x128, 256 spp, every
PathEstimator but the equiangular ones (24 renders); then the chromatic cloud, set-ups C1 and
C2, rgb and hero, 32x32, 128 spp, the grey-majorant baseline uni-nee-mis_balance_absorb-weight
and the spectral estimators listed under --estimators, uniform and luminance selection
(absorb-weight; 15 renders per set-up and mode, 60 in all), one run each; then the sparse
medium, set-up SA, mono, 64x64, 256 spp, each grey strategy (absorb-weight) with the global and
the grid majorant (8 renders); then the fog, set-ups F1, F2 (64x64, 128 spp) and F3 (64x64, 64
spp), mono: ratio-nee, uni-nee-mis balance, equiangular-nee and uni-nee-eq-mis balance and power
(absorb-weight) with the global and the grid majorant (30 renders); then the plume, set-up P1,
rgb, 64x64, 256 spp: unidirectional (the collision estimator of emission alone), ratio-nee (NEE
toward the emitting volume), uni-nee-mis balance and power (collisions, NEE and the segment
technique; absorb-weight), global and grid
majorant (8 renders). scripts/run-main.sh then adds two comparisons with effective variances
against reference images: the chromatic heavy-tail one (baseline against spectral MIS + NEE with
each majorant, --runs 3 at 32x32 with a 2048-spp reference; the second-to-last example below,
there with --runs 5), and F1 and P1 with --runs 3 and a 2048-spp reference (the last example).

usage: nsp_render [flags]

  --scene LIST       comma-separated scenes from cloud, chromatic, sparse, fog, plume; 'both' =
                     cloud,chromatic; 'all' = all five (default). cloud: the grey cloud
                     (extinction 20, albedo 0.9, HG g 0.9), set-ups A and B. chromatic: the same
                     cloud with extinction 5 : 20 : 80 in R : G : B (hero: a spectrum through
                     those values), albedo 0.95, set-ups C1 and C2. sparse: a thin plume and five
                     small dense puffs filling ~2% of the box (grey, extinction 60, albedo 0.9),
                     set-ups SA and SB. fog: a bank of ground fog over x in [-2.2, 0.8], thinning
                     upward (grey, albedo 0.9, HG g 0.7), lit by a lamp (point light, intensity
                     5), set-ups F1, F2, F3. plume: the cloud's density with extinction 5,
                     isotropic smoke, and a small flickering flame inside, behind its dense
                     core (nsp::Emissive: emission strength up to 80 x colour (6, 2, 0.5); no
                     other light), set-up P1
  --setup LIST       comma-separated set-ups of the chosen scenes, from A, B, C1, C2, SA, SB, F1,
                     F2, F3, P1, or 'all' ('both' also means all; default: all but SB). A: a
                     small bright sphere light above the grey cloud (NEE should win); B: a large
                     dim sphere light behind it (unidirectional should win); C1: a constant white
                     environment around the chromatic cloud (unidirectional paths dominate); C2:
                     set-up A's small light above the chromatic cloud (NEE matters); SA, SB:
                     set-up A's and B's lights around the sparse medium; F1: the lamp inside the
                     thin fog (extinction 0.12 per unit density: 0.03-0.28 optical depths along
                     camera rays; equiangular sampling should win); F2: the lamp 0.4 beside the
                     thin fog; F3: F2's lamp beside the fog 40x denser (~3 optical depths on the
                     median camera ray, up to 11; tracking should win); P1: the flame in the
                     plume scene (emission NEE + MIS should beat the collision estimator)
  --majorant LIST    comma-separated majorants, or 'all' (default: global for the cloud; global
                     and per-channel for the chromatic cloud; global and grid for the sparse
                     medium, the fog and the plume; a list given here applies to every scene).
                     Bounding: global (one grey value, the medium's extinction bound),
                     per-channel (each channel's own bound; rgb and hero), grid (a grey voxel
                     grid of density bounds walked by a DDA, --grid-res), channel-grid (the same
                     grid times each channel's extinction per unit density; rgb and hero).
                     Non-bounding, deliberately low (--majorant-scale), mono and
                     nsp::PathEstimator only: global-signed, grid-signed (bound::Signed: signed
                     null weights, unbiased), global-clamp, grid-clamp (bound::Clamp: density
                     clamped to the majorant, biased). The majorants other than global and
                     per-channel are compiled with absorb-weight only (build time; the
                     equiangular strategies also with absorb-event under grid). Grey rows with another majorant than global name it,
                     e.g. uni-nee-mis_grid_balance_absorb-weight; each table has a majorant
                     column, and steps/spl (DDA steps per sample) where a grid is walked
  --grid-res N       cells per axis of the grid majorants (default 16)
  --majorant-scale S the non-bounding majorants' value as a fraction of the bound: global-*
                     use S x the medium's largest extinction, grid-* S x each cell's bound
                     (default 0.5)
  --spectral LIST    comma-separated spectral modes from mono, rgb, hero; 'both' = mono,rgb;
                     'all' = all three (default: mono for the cloud, the sparse medium and the
                     fog, rgb,hero for the chromatic cloud, rgb for the plume; a list given here
                     applies to every scene). hero: 4 wavelengths per path (stratified
                     rotation), drawn from the pixel's random stream; every sample is converted
                     to linear sRGB via CIE XYZ before any statistic. Compiled for the build's
                     sake: the equiangular strategies in mono only, the plume's emissive medium
                     in rgb only (a scene's default row that a mode lacks is left out with a
                     note)
  --estimators LIST  comma-separated filter. Each item selects the rows whose fields include all
                     of its '_'-separated fields, e.g. uni-nee-mis (every NEE-MIS row),
                     uni-nee-mis_power, spectral-mis_lum, absorb-event; 'all' selects every
                     valid combination. Fields of a row's name: strategy (unidirectional,
                     ratio-nee, directional-mis, uni-nee-mis, equiangular-nee: a real vertex on
                     every segment drawn toward the lamp with the equiangular pdf, nulls before
                     it ratio-tracked, NEE from it; uni-nee-eq-mis: tracking + NEE, tracking +
                     hit and equiangular + NEE weighed by their null-scattering pdfs; both aim
                     at the point light, else the sphere light's centre), channel policy (independent,
                     spectral-tracking-max, spectral-tracking-avg, spectral-mis), majorant
                     (global, per-channel, grid, ...), heuristic (balance, power), absorption
                     (absorb-event, absorb-weight), lum (luminance selection). Rows of
                     nsp::PathEstimator keep their names without channel policy and majorant
                     and also match 'grey' and 'global'; uniform-selection rows also match
                     'uniform'; the plume's rows also match 'emissive'. Default for the cloud:
                     unidirectional_grey, ratio-nee_grey, directional-mis_grey,
                     uni-nee-mis_grey (every PathEstimator but the equiangular ones; 'grey'
                     adds those). Default for the fog:
                     ratio-nee_grey_absorb-weight, uni-nee-mis_grey_balance_absorb-weight,
                     equiangular-nee_grey_absorb-weight, uni-nee-eq-mis_grey_absorb-weight.
                     Default for the plume: unidirectional_grey_absorb-weight,
                     ratio-nee_grey_absorb-weight, uni-nee-mis_grey_absorb-weight. Default for
                     the sparse medium: unidirectional_grey_absorb-weight,
                     ratio-nee_grey_absorb-weight, directional-mis_grey_balance_absorb-weight,
                     uni-nee-mis_grey_balance_absorb-weight. Default for the chromatic cloud:
                       uni-nee-mis_grey_balance_absorb-weight (the grey-majorant baseline),
                       unidirectional_independent_absorb-weight_uniform,
                       uni-nee-mis_independent_absorb-weight,
                       unidirectional_spectral-tracking-max_absorb-weight,
                       uni-nee-mis_spectral-tracking-max_absorb-weight,
                       unidirectional_spectral-tracking-avg_absorb-weight,
                       uni-nee-mis_spectral-tracking-avg_absorb-weight,
                       unidirectional_spectral-mis_per-channel_absorb-weight_uniform,
                       ratio-nee_spectral-mis_per-channel_absorb-weight_uniform,
                       uni-nee-mis_spectral-mis_per-channel_absorb-weight,
                       unidirectional_spectral-mis_global_absorb-weight_uniform,
                       uni-nee-mis_spectral-mis_global_absorb-weight
                     Spectral MIS comes with either majorant: per-channel (each channel's own
                     tight free-flight density; with extinction 1 : 4 : 16 the channels' pdfs
                     barely overlap) or global (one grey free-flight density, per-channel event
                     probabilities: the pdfs overlap and the balance heuristic combines them)
  --selection R      uniform, luminance or both (default both): how the spectral estimators that
                     use it (independent tracking, spectral MIS) choose a path's sampling
                     channel. luminance: q_c proportional to 0.5/C + 0.5 y_c / sum(y), y = Rec. 709
                     weights (0.2126, 0.7152, 0.0722) in rgb, the CIE y-bar of each of the path's
                     wavelengths in hero. Luminance rows get the name field 'lum'. Spectral
                     tracking (one shared pdf) does not depend on the selection and is rendered
                     once, with uniform selection
  --runs K           render each selected row K times with seeds seed, seed+1, ..., seed+K-1
                     and report the median over the runs of seconds, lookups/spl, var/spl, LTUV
                     and cpu-s*var (default 1); K > 1 adds the min..max of var/spl. For
                     heavy-tailed estimators, whose sample variance is itself unreliable (and
                     understates their error: see --reference-spp)
  --reference-spp N  effective (error-based) variance: before the rows of each table of the
                     chromatic cloud (rgb, hero), the fog and the plume, render a reference image
                     of the same set-up, mode and resolution with an estimator that is unbiased
                     and of finite variance there and none of the default rows (chromatic:
                     uni-nee-mis_spectral-tracking-avg_global_balance_absorb-weight; fog:
                     uni-nee-eq-mis_balance_absorb-event; plume:
                     directional-mis_grid_balance_absorb-weight), N spp, seed + 1000000; then for
                     every row and run
                     report eff var/spl = spp x mean over pixels and channels of (pixel mean -
                     reference pixel mean)^2 - spp x mean(var_ref / N): an unbiased estimate of
                     spp x the image's MSE, which is the variance per sample of a finite-variance
                     estimator and, for a heavy-tailed one, includes the error its sample
                     variance misses. Adds the columns eff var/spl, eff LTUV and img eff var
                     (the same from the error of the image mean: spp x pixels x (image mean -
                     reference's)^2 - the same reference term; 3 degrees of freedom per run, but
                     a tail missed in every pixel adds up there); on the chromatic cloud the
                     ratios baseline / spectral MIS + NEE of all three, on the fog and the plume
                     time x variance from eff var/spl in the summary lines (eff var/spl is per
                     channel, as var/spl of the chromatic tables; in the plume's rgb table
                     var/spl is the channel mean's, so compare eff with eff; default: off)
  --spp N            samples per pixel, N >= 2 (default 256 for the cloud, 128 for the
                     chromatic cloud, 256 for the sparse medium, 128 for the fog's F1 and F2 and
                     64 for F3, 256 for the plume); the variance per sample is estimated from
                     the N samples of each pixel
  --res WxH          image size in pixels (default 128x128 for the cloud, 32x32 for the
                     chromatic cloud, 64x64 for the sparse medium, the fog and the plume); also
                     --width W, --height H
  --threads N        worker threads (default: hardware concurrency)
  --seed N           random seed, an unsigned 64-bit integer (default 1); images do not depend
                     on --threads
  --max-depth N      most real scattering vertices on a path, N >= 0 (default 1000; 0 renders
                     the directly transmitted light only); Russian roulette from depth 3 on
  --equiangular-every-segment
                     the three-way MIS (uni-nee-eq-mis) draws an equiangular vertex on every
                     segment, not with probability min(1, p_eq / mu_bar) at the density's peak
  --no-emission-segments
                     the combining strategies on the plume leave out the segment technique (a
                     point drawn on every segment in proportion to the emitted power along it):
                     emission by collisions and NEE toward the volume only
  --out DIR          directory for the EXR images (default out), created if missing; one linear
                     RGB image (linear sRGB in hero mode) per row, from its first run, named
                     SETUP_ROW[_rgb|_hero].exr, e.g. C1_uni-nee-mis_balance_absorb-weight_hero.exr
  --no-exr           do not write images (timings and tables only)
  --list             list every compiled policy combination and exit
  --env L            add a constant environment light of radiance L >= 0
  --point X,Y,Z,I    add an isotropic point light of intensity I >= 0 at (X, Y, Z), or move the
                     fog's lamp there; only next-event estimation reaches it, so unidirectional
                     renders miss its light; the equiangular strategies aim at it
  --sphere X,Y,Z,R,L replace the set-up's sphere light (radius R > 0, radiance L >= 0); it must
                     lie outside the medium's box ([-1, 1]^3; the fog's [-2.2, 0.8] x
                     [-1.6, 1.6] x [-1.5, 2.5])
  --help             this text

Examples: nsp_render --scene cloud --setup A --spp 256 --estimators uni-nee-mis_balance
          nsp_render --scene sparse --majorant all --spp 32
          nsp_render --scene cloud --majorant global,grid,global-signed,grid-clamp --spp 64
          nsp_render --scene chromatic --estimators all --spp 16 --res 32x32
          nsp_render --scene fog --setup F3 --point=-0.5,0,0.4,5   (F1's lamp, in the dense fog)
          nsp_render --scene chromatic --runs 5 --res 32x32 --spp 128 --no-exr \
                     --reference-spp 2048 --selection uniform \
                     --estimators uni-nee-mis_grey_balance_absorb-weight,uni-nee-mis_spectral-mis_absorb-weight
          nsp_render --scene fog,plume --setup F1,P1 --runs 3 --reference-spp 2048 --no-exr
)";

[[noreturn]] void usage_error(const std::string& msg) {
    std::cerr << "nsp_render: " << msg << "\n(nsp_render --help lists the flags)\n";
    std::exit(2);
}

template <class T>
T parse_number(std::string_view flag, std::string_view text, T lo, T hi) {
    T v{};
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || text.empty())
        usage_error(std::string(flag) + ": '" + std::string(text) + "' is not a number");
    if constexpr (std::is_floating_point_v<T>)
        if (!std::isfinite(v)) usage_error(std::string(flag) + ": '" + std::string(text) + "' is not finite");
    if (v < lo || v > hi) {
        std::ostringstream os;
        os << flag << ": " << text << " is out of range [" << lo << ", " << hi << "]";
        usage_error(os.str());
    }
    return v;
}

std::vector<std::string_view> split(std::string_view s, char sep) {
    std::vector<std::string_view> parts;
    for (;;) {
        const auto p = s.find(sep);
        parts.push_back(s.substr(0, p));
        if (p == std::string_view::npos) return parts;
        s.remove_prefix(p + 1);
    }
}

template <std::size_t N>
std::array<float, N> parse_floats(std::string_view flag, std::string_view text) {
    const auto parts = split(text, ',');
    if (parts.size() != N)
        usage_error(std::string(flag) + ": expected " + std::to_string(N) + " comma-separated numbers, got '" +
                    std::string(text) + "'");
    std::array<float, N> v{};
    for (std::size_t i = 0; i < N; ++i)
        v[i] = parse_number<float>(flag, parts[i], -1e30f, 1e30f);
    return v;
}

/// The spectral mode names, in the order of SpectralModes.
std::vector<std::string_view> mode_names() {
    std::vector<std::string_view> names;
    tl::for_each<SpectralModes>([&]<class S>(std::type_identity<S>) { names.emplace_back(S::name); });
    return names;
}

/// The majorant policy names, in the order of Majorants.
std::vector<std::string_view> majorant_names() {
    std::vector<std::string_view> names;
    tl::for_each<Majorants>([&]<class M>(std::type_identity<M>) { names.emplace_back(M::name); });
    return names;
}

Options parse(int argc, char** argv) {
    Options o;
    std::vector<std::string_view> args(argv + 1, argv + argc);
    for (std::size_t i = 0; i < args.size(); ++i) {
        std::string_view flag = args[i];
        std::optional<std::string_view> inline_value;
        if (const auto eq = flag.find('='); flag.starts_with("--") && eq != std::string_view::npos) {
            inline_value = flag.substr(eq + 1);
            flag = flag.substr(0, eq);
        }
        auto value = [&]() -> std::string_view {
            if (inline_value) return *inline_value;
            if (i + 1 >= args.size()) usage_error(std::string(flag) + " needs a value");
            return args[++i];
        };
        auto no_value = [&] {
            if (inline_value) usage_error(std::string(flag) + " takes no value");
        };
        if (flag == "--help" || flag == "-h") {
            std::cout << kHelp;
            std::exit(0);
        } else if (flag == "--spp") {
            o.spp = parse_number<int>(flag, value(), 2, 1 << 20);
        } else if (flag == "--res") {
            const std::string_view v = value();
            const auto x = v.find('x');
            if (x == std::string_view::npos) usage_error("--res: expected WxH, e.g. 128x128, got '" + std::string(v) + "'");
            o.width = parse_number<int>("--res width", v.substr(0, x), 1, 16384);
            o.height = parse_number<int>("--res height", v.substr(x + 1), 1, 16384);
        } else if (flag == "--width") {
            o.width = parse_number<int>(flag, value(), 1, 16384);
        } else if (flag == "--height") {
            o.height = parse_number<int>(flag, value(), 1, 16384);
        } else if (flag == "--threads") {
            o.threads = parse_number<int>(flag, value(), 1, 1024);
        } else if (flag == "--seed") {
            o.seed = parse_number<std::uint64_t>(flag, value(), 0, std::numeric_limits<std::uint64_t>::max());
        } else if (flag == "--reference-spp") {
            o.reference_spp = parse_number<int>(flag, value(), 2, 1 << 24);
        } else if (flag == "--runs") {
            o.runs = parse_number<int>(flag, value(), 1, 1000);
        } else if (flag == "--max-depth") {
            o.estimator.max_depth = parse_number<int>(flag, value(), 0, 1 << 20);
        } else if (flag == "--equiangular-every-segment") {
            no_value();
            o.estimator.adaptive_equiangular = false;
        } else if (flag == "--no-emission-segments") {
            no_value();
            o.estimator.emission_along_segments = false;
        } else if (flag == "--out") {
            o.out = std::string(value());
            if (o.out.empty()) usage_error("--out needs a directory name");
        } else if (flag == "--no-exr") {
            no_value();
            o.write_exr = false;
        } else if (flag == "--list") {
            no_value();
            o.list = true;
        } else if (flag == "--scene") {
            o.scenes.clear();
            auto add = [&](SceneKind k) {
                if (std::find(o.scenes.begin(), o.scenes.end(), k) == o.scenes.end()) o.scenes.push_back(k);
            };
            for (const auto t : split(value(), ',')) {
                if (t == "cloud") add(SceneKind::Cloud);
                else if (t == "chromatic") add(SceneKind::Chromatic);
                else if (t == "sparse") add(SceneKind::Sparse);
                else if (t == "fog") add(SceneKind::Fog);
                else if (t == "plume") add(SceneKind::Plume);
                else if (t == "both") add(SceneKind::Cloud), add(SceneKind::Chromatic);
                else if (t == "all")
                    for (const SceneKind k : {SceneKind::Cloud, SceneKind::Chromatic, SceneKind::Sparse, SceneKind::Fog,
                                              SceneKind::Plume})
                        add(k);
                else
                    usage_error("--scene: '" + std::string(t) +
                                "' is not one of cloud, chromatic, sparse, fog, plume, both, all");
            }
        } else if (flag == "--setup") {
            o.setups.clear();
            const std::vector<std::string> known{"A", "B", "C1", "C2", "SA", "SB", "F1", "F2", "F3", "P1"};
            for (const auto t : split(value(), ',')) {
                std::string up(t);
                for (char& ch : up) ch = char(std::toupper(static_cast<unsigned char>(ch)));
                if (up == "ALL" || up == "BOTH") o.setups = known;
                else if (std::find(known.begin(), known.end(), up) != known.end()) o.setups.push_back(up);
                else
                    usage_error("--setup: '" + std::string(t) + "' is not one of A, B, C1, C2, SA, SB, F1, F2, F3, P1, all");
            }
        } else if (flag == "--majorant") {
            const auto known = majorant_names();
            o.majorants.clear();
            for (const auto t : split(value(), ',')) {
                if (t == "all") o.majorants.assign(known.begin(), known.end()), o.all_majorants = true;
                else if (std::find(known.begin(), known.end(), t) != known.end()) o.majorants.emplace_back(t);
                else {
                    std::string list;
                    for (const auto k : known) list += std::string(k) + ", ";
                    usage_error("--majorant: '" + std::string(t) + "' is not one of " + list + "all");
                }
            }
            if (o.majorants.empty()) usage_error("--majorant needs at least one name");
        } else if (flag == "--grid-res") {
            o.majorant.grid_res = parse_number<int>(flag, value(), 1, 1024);
        } else if (flag == "--majorant-scale") {
            o.majorant.scale = parse_number<float>(flag, value(), 1e-3f, 1e3f);
        } else if (flag == "--spectral") {
            const auto known = mode_names();
            o.modes.clear();
            for (const auto t : split(value(), ',')) {
                if (t == "all") o.modes = known;
                else if (t == "both") o.modes = {nsp::Mono::name, nsp::Rgb::name};
                else if (const auto it = std::find(known.begin(), known.end(), t); it != known.end())
                    o.modes.push_back(*it);
                else usage_error("--spectral: '" + std::string(t) + "' is not one of mono, rgb, hero, both, all");
            }
        } else if (flag == "--estimators") {
            o.estimators.clear();
            for (const auto t : split(value(), ','))
                if (!t.empty()) o.estimators.emplace_back(t);
            if (o.estimators.empty()) usage_error("--estimators needs at least one name");
        } else if (flag == "--selection") {
            const std::string_view v = value();
            if (v == "uniform") o.selections = {SelectionRule::Uniform};
            else if (v == "luminance") o.selections = {SelectionRule::Luminance};
            else if (v == "both") o.selections = {SelectionRule::Uniform, SelectionRule::Luminance};
            else usage_error("--selection: '" + std::string(v) + "' is not one of uniform, luminance, both");
        } else if (flag == "--env") {
            o.lights.env = parse_number<float>(flag, value(), 0.f, 1e30f);
        } else if (flag == "--point") {
            o.lights.point = parse_floats<4>(flag, value());
            if ((*o.lights.point)[3] < 0.f) usage_error("--point: the intensity must be >= 0");
        } else if (flag == "--sphere") {
            o.lights.sphere = parse_floats<5>(flag, value());
            if (!((*o.lights.sphere)[3] > 0.f)) usage_error("--sphere: the radius must be > 0");
            if ((*o.lights.sphere)[4] < 0.f) usage_error("--sphere: the radiance must be >= 0");
        } else {
            usage_error("unknown flag '" + std::string(args[i]) + "'");
        }
    }
    return o;
}

// ---------------------------------------------------------------------------------------------
// Planning: which rows to render (run-time names of compile-time combinations)

/// One row of a table: a combination of one mode with a selection rule, and its names.
struct Candidate {
    std::size_t index = 0;  ///< into CombinationsOf<S>
    SelectionRule selection = SelectionRule::Uniform;
    std::string name;                 ///< e.g. uni-nee-mis_spectral-mis_per-channel_balance_absorb-weight_lum
    std::vector<std::string> fields;  ///< the name's '_'-separated fields and the implied ones (grey, global, uniform)
    std::string channels;             ///< the channel policy ("grey" for PathEstimator)
    std::string majorant;             ///< the majorant policy's name (global, grid, grid-signed, ...)
    std::string key;                  ///< the name without the majorant: rows that differ only in it share it
    bool bounding = true;             ///< false for the non-bounding majorants (bound::Signed, Clamp)
    bool per_channel_majorant = false;  ///< per-channel or channel-grid
    std::string strategy;
    std::string absorption;
    bool uses_selection = false;
    bool emissive = false;  ///< the emissive medium (the plume scene's)
};

/// The run-time descriptions of every combination of spectral mode `mode`, in index order.
std::vector<CombinationInfo> infos(std::string_view mode) {
    std::vector<CombinationInfo> out;
    tl::for_each<SpectralModes>([&]<class S>(std::type_identity<S>) {
        if (mode == S::name) out.assign(combination_infos<S>().begin(), combination_infos<S>().end());
    });
    return out;
}

/// Every row spectral mode `mode` offers with selection rules `rules`, in list order (a row that
/// uses the selection once per rule, the luminance one right after the uniform one).
std::vector<Candidate> candidates(std::string_view mode, const std::vector<SelectionRule>& rules) {
    std::vector<Candidate> out;
    std::size_t index = 0;
    for (const CombinationInfo& info : infos(mode)) {
        Candidate c;
        c.index = index++;
        c.channels = info.channels;
        c.majorant = info.majorant;
        c.bounding = info.bounding;
        c.per_channel_majorant = info.per_channel_majorant;
        c.strategy = info.strategy;
        c.absorption = info.absorption;
        c.uses_selection = info.uses_selection;
        c.emissive = info.emissive;
        c.name = info.name();
        for (const auto f : split(c.name, '_')) {
            c.fields.emplace_back(f);
            if (f == c.majorant) continue;
            if (!c.key.empty()) c.key += '_';  // not "_" + std::string(f): GCC 12 warns (-Wrestrict, bug 105329)
            c.key += f;
        }
        if (!info.spectral) c.fields.emplace_back("grey");
        if (info.plain_global) c.fields.emplace_back("global");
        if (info.emissive) c.fields.emplace_back("emissive");
        if (!info.uses_selection) {
            out.push_back(c);
            continue;
        }
        for (const SelectionRule r : rules) {
            Candidate s = c;
            s.selection = r;
            if (r == SelectionRule::Luminance) {
                s.name += "_lum";
                s.key += "_lum";
                s.fields.emplace_back("lum");
            } else {
                s.fields.emplace_back("uniform");
            }
            out.push_back(std::move(s));
        }
    }
    return out;
}

/// True when every field of `token` is a field of the row.
bool matches(const Candidate& c, std::string_view token) {
    if (token == "all") return true;
    for (const auto t : split(token, '_'))
        if (std::find(c.fields.begin(), c.fields.end(), t) == c.fields.end()) return false;
    return true;
}

/// The renders of one table: one set-up of one scene in one spectral mode.
struct TablePlan {
    SceneChoice scene;
    std::string_view mode;
    int width = 0, height = 0, spp = 0;
    std::vector<Candidate> rows;
};

/// What a scene renders when the flags do not say: its set-ups, spectral modes, image size,
/// estimators and majorants.
struct SceneDefaults {
    struct Setup {
        std::string name;  ///< as --setup names it
        SceneChoice choice;
        int spp = 0;  ///< 0: the scene's
    };
    std::vector<Setup> setups;
    std::vector<std::string_view> modes;
    int width = 0, height = 0, spp = 0;
    const std::vector<std::string>* estimators = nullptr;
    const std::vector<std::string>* majorants = nullptr;
};

SceneDefaults scene_defaults(SceneKind kind) {
    using K = SceneKind;
    const std::vector<std::string_view> mono{nsp::Mono::name};
    switch (kind) {
        case K::Chromatic:
            return {{{"C1", {kind, LightSetup::A, ChromaticSetup::Env}}, {"C2", {kind, LightSetup::A, ChromaticSetup::Small}}},
                    {nsp::Rgb::name, Hero4::name}, kChromaticWidth, kChromaticHeight, kChromaticSpp,
                    &kChromaticEstimators, &kChromaticMajorants};
        case K::Sparse:
            return {{{"SA", {kind, LightSetup::A}}, {"SB", {kind, LightSetup::B}}}, mono, kSparseWidth,
                    kSparseHeight, kSparseSpp, &kSparseEstimators, &kSparseMajorants};
        case K::Fog: {
            SceneDefaults d{{}, mono, kFogWidth, kFogHeight, kFogSpp, &kFogEstimators, &kFogMajorants};
            for (const FogSetup f : {FogSetup::F1, FogSetup::F2, FogSetup::F3}) {
                SceneChoice c{kind};
                c.fog = f;
                d.setups.push_back({name(f), c, f == FogSetup::F3 ? kDenseFogSpp : 0});
            }
            return d;
        }
        case K::Plume:
            return {{{"P1", {kind}}}, {nsp::Rgb::name}, kPlumeWidth, kPlumeHeight, kPlumeSpp, &kPlumeEstimators,
                    &kPlumeMajorants};
        default:
            return {{{"A", {kind, LightSetup::A}}, {"B", {kind, LightSetup::B}}}, mono, kCloudWidth, kCloudHeight,
                    kCloudSpp, &kCloudEstimators, &kCloudMajorants};
    }
}

std::vector<TablePlan> plan(const Options& o) {
    std::vector<TablePlan> tables;
    std::vector<std::string> all_tokens = o.estimators;
    std::vector<bool> used(all_tokens.size(), false);
    std::vector<bool> majorant_used(o.majorants.size(), false);
    for (const SceneKind kind : o.scenes) {
        const SceneDefaults d = scene_defaults(kind);
        std::vector<SceneDefaults::Setup> choices;
        for (const auto& s : o.setups)
            for (const SceneDefaults::Setup& setup : d.setups)
                if (s == setup.name) choices.push_back(setup);
        const std::vector<std::string_view> modes = o.modes.empty() ? d.modes : o.modes;
        const std::vector<std::string>& tokens = !o.estimators.empty() ? o.estimators : *d.estimators;
        const std::vector<std::string>& majorants = !o.majorants.empty() ? o.majorants : *d.majorants;
        const bool emissive = kind == SceneKind::Plume;  // the plume renders the emissive medium, the others not
        for (const auto& [setup_name, choice, setup_spp] : choices) {
            for (const auto mode : modes) {
                TablePlan t{choice, mode, o.width.value_or(d.width), o.height.value_or(d.height),
                            o.spp.value_or(setup_spp > 0 ? setup_spp : d.spp), {}};
                std::vector<bool> token_used(tokens.size(), false);
                for (const Candidate& c : candidates(mode, o.selections)) {
                    if (c.emissive != emissive) continue;
                    const auto maj = std::find(majorants.begin(), majorants.end(), c.majorant);
                    if (maj == majorants.end()) continue;
                    if (!o.majorants.empty()) majorant_used[std::size_t(maj - majorants.begin())] = true;
                    bool any = false;
                    for (std::size_t k = 0; k < tokens.size(); ++k) {
                        if (!matches(c, tokens[k])) continue;
                        any = token_used[k] = true;
                        if (!o.estimators.empty()) used[k] = true;
                    }
                    if (any) t.rows.push_back(c);
                }
                // A scene's default row that this mode does not compile (e.g. the equiangular
                // strategies outside mono) is left out with a note rather than silently.
                for (std::size_t k = 0; k < tokens.size() && o.estimators.empty(); ++k)
                    if (!token_used[k] && !t.rows.empty())
                        std::fprintf(stderr, "nsp_render: note: set-up %s, %.*s: no row '%s' (not compiled in this "
                                     "mode, see --list)\n", choice.name(), int(mode.size()), mode.data(),
                                     tokens[k].c_str());
                if (!t.rows.empty()) tables.push_back(std::move(t));
            }
        }
    }
    for (std::size_t k = 0; k < all_tokens.size(); ++k)
        if (!used[k])
            usage_error("--estimators: '" + all_tokens[k] + "' matches no row of the chosen scenes, set-ups, "
                        "spectral modes and majorants (see --list)");
    for (std::size_t k = 0; k < o.majorants.size(); ++k)
        if (!majorant_used[k] && !o.all_majorants)
            usage_error("--majorant: '" + o.majorants[k] + "' has no row in the chosen spectral modes (see --list: "
                        "per-channel majorants need rgb or hero, the non-bounding ones mono)");
    if (tables.empty())
        usage_error("nothing to render: the chosen scenes, set-ups, spectral modes and majorants have no row in "
                    "common (--scene and --setup must share a set-up; see --list: the plume's emissive medium is "
                    "compiled in rgb only, the equiangular strategies in mono only)");
    return tables;
}

// ---------------------------------------------------------------------------------------------
// The tables

/// A rendered row: its runs.
struct Row {
    Candidate c;
    std::vector<RenderStats> runs;
    /// With --reference-spp, per run: the effective variance per sample (see effective_variance).
    std::vector<double> effective;
    /// With --reference-spp, per run: the same from the error of the image mean (effective_image_variance).
    std::vector<double> effective_image;

    /// The median over runs of metric f (the mean of the two middle values for an even count).
    template <class F>
    double median(F f) const {
        std::vector<double> v;
        for (const RenderStats& r : runs) v.push_back(f(r));
        std::sort(v.begin(), v.end());
        const std::size_t n = v.size();
        return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    }
    /// Channel c's image mean over the runs, and its standard error (from the per-pixel variances).
    double mean(int ch) const {
        double m = 0.0;
        for (const RenderStats& r : runs) m += r.mean[std::size_t(ch)];
        return m / double(runs.size());
    }
    double standard_error(int ch) const {
        double v = 0.0;
        for (const RenderStats& r : runs) v += r.channel_variance[std::size_t(ch)] / double(r.samples);
        return std::sqrt(v) / double(runs.size());
    }
    std::uint64_t nonzero() const {
        std::uint64_t n = 0;
        for (const RenderStats& r : runs) n += r.nonzero;
        return n;
    }
    template <class F>
    std::pair<double, double> range(F f) const {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const RenderStats& r : runs) {
            lo = std::min(lo, f(r));
            hi = std::max(hi, f(r));
        }
        return {lo, hi};
    }
};

/// The statistics of one table: which variance it reports (see the footers).
struct Metrics {
    bool per_channel = false;  ///< per-channel variance (chromatic) or variance of the channel mean (cloud)

    double variance(const RenderStats& r) const { return per_channel ? r.variance_per_channel() : r.variance_of_mean; }
    double ltuv(const RenderStats& r) const { return r.lookups_per_sample() * variance(r); }
    double time_variance(const RenderStats& r) const { return r.cpu_seconds_per_sample() * variance(r); }

    double var(const Row& row) const { return row.median([&](const RenderStats& r) { return variance(r); }); }
    double ltuv(const Row& row) const { return row.median([&](const RenderStats& r) { return ltuv(r); }); }

    /// With --reference-spp: the median over runs of the effective variance per sample, and of the
    /// effective LTUV (lookups/spl x effective variance of the same run); NaN without a reference.
    static double eff(const Row& row) { return median_of(row.effective); }
    static double eff_image(const Row& row) { return median_of(row.effective_image); }
    static double eff_ltuv(const Row& row) {
        std::vector<double> v;
        for (std::size_t i = 0; i < row.effective.size(); ++i)
            v.push_back(row.runs[i].lookups_per_sample() * row.effective[i]);
        return median_of(v);
    }
    static double median_of(std::vector<double> v) {
        if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
        std::sort(v.begin(), v.end());
        const std::size_t n = v.size();
        return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    }
};

/// The reference image of --reference-spp for one table, and what it cost.
struct Reference {
    std::string estimator;  ///< the row name of the estimator that rendered it
    int spp = 0;
    std::uint64_t seed = 0;
    RenderStats stats;  ///< with pixel_mean and pixel_variance
    /// spp_row x the mean over pixels and channels of var_ref / spp_ref: what the reference's own
    /// noise adds, in expectation, to spp_row x the squared error against it.
    double contribution(int spp_row) const {
        double v = 0.0;
        for (const double x : stats.pixel_variance) v += x;
        return double(spp_row) * v / double(stats.pixel_variance.size()) / double(spp);
    }
};

/// The effective variance per sample of one run: spp x (mean over pixels and channels of
/// (pixel mean - reference pixel mean)^2) - the reference's contribution. For an unbiased
/// estimator independent of the reference this is an unbiased estimate of spp x the image's
/// mean squared error, i.e. of its variance per sample when that is finite; for a heavy-tailed
/// one it includes the error of the rare huge samples its sample variance misses in this run.
double effective_variance(const RenderStats& run, int spp, const Reference& ref) {
    const auto& a = run.pixel_mean;
    const auto& b = ref.stats.pixel_mean;
    if (a.size() != b.size() || a.empty()) throw std::logic_error("effective_variance: image sizes differ");
    double sq = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) sq += (a[i] - b[i]) * (a[i] - b[i]);
    return double(spp) * sq / double(a.size()) - ref.contribution(spp);
}

/// The effective variance per sample from the error of the image mean: spp x pixels x (mean over
/// channels of (image mean - reference image mean)^2) - the same reference contribution (the
/// pixels are independent, so for an unbiased estimator its expectation is again the variance
/// per sample). Only 3 degrees of freedom per run, so noisy; but where a heavy-tailed estimator
/// misses the same rare samples in every pixel, its per-pixel errors add up coherently here,
/// while per pixel they hide under the sampling noise of 'spp' samples.
double effective_image_variance(const RenderStats& run, int spp, const Reference& ref) {
    const auto& a = run.pixel_mean;
    const auto& b = ref.stats.pixel_mean;
    const std::size_t pixels = a.size() / 3;
    double sq = 0.0;
    for (int c = 0; c < 3; ++c) {
        double d = 0.0;
        for (std::size_t i = 0; i < pixels; ++i) d += a[3 * i + std::size_t(c)] - b[3 * i + std::size_t(c)];
        d /= double(pixels);
        sq += d * d;
    }
    return double(spp) * double(pixels) * sq / 3.0 - ref.contribution(spp);
}

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
}

const Row* find_row(const std::vector<Row>& rows, std::string_view name) {
    for (const Row& r : rows)
        if (r.c.name == name) return &r;
    return nullptr;
}

/// "a, b, c": a metric of every run.
template <class F>
std::string per_run(const Row& row, F f) {
    std::string s;
    for (const RenderStats& r : row.runs) s += (s.empty() ? "" : ", ") + num(f(r));
    return s;
}

/// The rows and columns every table shares; returns the best (lowest positive) LTUV.
double print_rows(const TablePlan& t, const Options& o, const std::vector<Row>& rows, const Metrics& m) {
    const bool chromatic = t.scene.kind == SceneKind::Chromatic;
    // Best row: the lowest LTUV among rows that measured any variance (a strategy that never
    // found the light has variance 0 and an LTUV that means nothing).
    double best = std::numeric_limits<double>::infinity();
    for (const Row& r : rows)
        if (m.ltuv(r) > 0.0) best = std::min(best, m.ltuv(r));
    std::size_t width = 36;
    for (const Row& r : rows) width = std::max(width, r.c.name.size());
    const int wn = int(width);
    // DDA steps per sample: only where a row walks a grid majorant.
    const bool steps = std::any_of(rows.begin(), rows.end(), [](const Row& r) {
        return r.c.majorant.find("grid") != std::string::npos;
    });
    std::printf("%-*s %-13s %5s %8s %11s", wn, "estimator", "majorant", "spp", "seconds", "lookups/spl");
    if (steps) std::printf(" %9s", "steps/spl");
    std::printf(" %11s %11s %11s %9s", "var/spl", "LTUV", "cpu-s*var", "LTUV/best");
    if (o.runs > 1) std::printf(" %19s", "var/spl min..max");
    const bool effective = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.effective.empty(); });
    if (effective) std::printf(" %11s %11s %11s", "eff var/spl", "eff LTUV", "img eff var");
    std::printf(chromatic ? " %s\n" : " %9s\n", chromatic ? "mean R G B" : "mean");
    for (const Row& r : rows) {
        const double ltuv = m.ltuv(r);
        const bool measured = ltuv > 0.0 && std::isfinite(best);
        std::printf("%-*s %-13s %5d %8.2f %11s", wn, r.c.name.c_str(), r.c.majorant.c_str(), t.spp,
                    r.median([](const RenderStats& s) { return s.wall_seconds; }),
                    num(r.median([](const RenderStats& s) { return s.lookups_per_sample(); })).c_str());
        if (steps) std::printf(" %9s", num(r.median([](const RenderStats& s) { return s.steps_per_sample(); })).c_str());
        std::printf(" %11s %11s %11s %9s", num(m.var(r)).c_str(), num(ltuv).c_str(),
                    num(r.median([&](const RenderStats& s) { return m.time_variance(s); })).c_str(),
                    measured ? num(ltuv / best).c_str() : "n/a");
        if (o.runs > 1) {
            const auto [lo, hi] = r.range([&](const RenderStats& s) { return m.variance(s); });
            std::printf(" %19s", (num(lo) + ".." + num(hi)).c_str());
        }
        if (effective)
            std::printf(" %11s %11s %11s", num(Metrics::eff(r)).c_str(), num(Metrics::eff_ltuv(r)).c_str(),
                        num(Metrics::eff_image(r)).c_str());
        if (chromatic)
            std::printf(" %s %s %s\n", num(r.mean(0)).c_str(), num(r.mean(1)).c_str(), num(r.mean(2)).c_str());
        else
            std::printf(" %9s\n", num((r.mean(0) + r.mean(1) + r.mean(2)) / 3.0).c_str());
    }
    return best;
}

/// Below this many nonzero samples a row's statistics rest on too few samples to mean much.
constexpr std::uint64_t kFewNonzero = 1000;

/// More standard errors than this between two rows' image means is reported (see mean_gap).
constexpr double kMeanGap = 4.0;

/// How far apart the image means of rows a and b are: the largest over channels of
/// |mean_a - mean_b| / sqrt(se_a^2 + se_b^2), and that channel.
std::pair<double, int> mean_gap(const Row& a, const Row& b) {
    std::pair<double, int> worst{0.0, 0};
    for (int c = 0; c < 3; ++c) {
        const double se = std::hypot(a.standard_error(c), b.standard_error(c));
        const double z = se > 0.0 ? std::abs(a.mean(c) - b.mean(c)) / se : 0.0;
        if (z > worst.first) worst = {z, c};
    }
    return worst;
}

/// What the majorants of a table's rows are, when any is not the plain global or per-channel one.
void print_majorant_notes(const Options& o, const std::vector<Row>& rows) {
    const auto any = [&](auto pred) { return std::any_of(rows.begin(), rows.end(), pred); };
    if (any([](const Row& r) { return r.c.majorant.find("grid") != std::string::npos; })) {
        const long long n = o.majorant.grid_res;
        std::printf("grid majorants (grid, channel-grid, grid-*): %lldx%lldx%lld cells over the medium's box "
                    "(--grid-res), %lld KiB, each cell the density bound over it, walked by a DDA. steps/spl: DDA "
                    "steps (cells crossed, empty ones included) per sample; lookups/spl counts density lookups "
                    "only.\n", n, n, n, n * n * n * 4 / 1024);
    }
    if (any([](const Row& r) { return !r.c.bounding; }))
        std::printf("non-bounding majorants (*-signed, *-clamp): %g x the bound (--majorant-scale), below the "
                    "extinction where the medium is dense. signed (bound::Signed): negative null weights, "
                    "unbiased; clamp (bound::Clamp): the density clamped to the majorant, biased by design.\n",
                    double(o.majorant.scale));
}

/// Rows that differ only in their majorant, against the same estimator with the table's reference
/// majorant of the same kind: per-channel for per-channel majorants, grid for the non-bounding
/// grids (when rendered), global otherwise. Prints the cost and variance ratios and how far apart
/// the image means are (they must agree for any unbiased pair; bound::Clamp is biased by design).
void print_majorant_comparison(const std::vector<Row>& rows, const Metrics& m) {
    bool header = false;
    for (const Row& r : rows) {
        auto same_estimator = [&](const std::string& majorant) {
            return std::find_if(rows.begin(), rows.end(), [&](const Row& x) {
                return x.c.key == r.c.key && x.c.majorant == majorant;
            });
        };
        std::string base_name = r.c.per_channel_majorant ? "per-channel" : "global";
        if (r.c.majorant.starts_with("grid-") && same_estimator("grid") != rows.end()) base_name = "grid";
        if (r.c.majorant == base_name) continue;
        const auto b = same_estimator(base_name);
        if (b == rows.end()) continue;
        if (!header)
            std::printf("majorants compared (ratio = row / same estimator with the reference majorant; < 1: the "
                        "row is cheaper or less noisy):\n");
        header = true;
        const auto med = [](const Row& x, auto f) { return x.median(f); };
        const auto ratio = [](double x, double y) { return y > 0.0 && std::isfinite(x / y) ? num(x / y) : "n/a"; };
        const auto lookups = [](const RenderStats& s) { return s.lookups_per_sample(); };
        const auto cpu = [](const RenderStats& s) { return s.cpu_seconds_per_sample(); };
        const auto [z, c] = mean_gap(r, *b);
        const bool few = r.nonzero() < kFewNonzero || b->nonzero() < kFewNonzero;
        const char* verdict = few ? " (too few nonzero samples to compare)"
                              : r.c.majorant.ends_with("clamp") ? (z > kMeanGap ? " (clamp: biased by design)" : "")
                              : z > kMeanGap ? " (TOO FAR APART: a bias or a heavy tail)"
                                             : "";
        std::printf("  %s vs %s, %s: lookups/spl %s, cpu-s/spl %s, var/spl %s, LTUV %s, cpu-s*var %s; image "
                    "means %.1f standard errors apart%s%s\n",
                    r.c.majorant.c_str(), base_name.c_str(), r.c.key.c_str(),
                    ratio(med(r, lookups), med(*b, lookups)).c_str(), ratio(med(r, cpu), med(*b, cpu)).c_str(),
                    ratio(m.var(r), m.var(*b)).c_str(), ratio(m.ltuv(r), m.ltuv(*b)).c_str(),
                    ratio(r.median([&](const RenderStats& s) { return m.time_variance(s); }),
                          b->median([&](const RenderStats& s) { return m.time_variance(s); }))
                        .c_str(),
                    z, r.c.channels != "grey" ? (std::string(" in ") + "RGB"[c]).c_str() : "",
                    verdict);
    }
}

/// Footer lines every table shares: medians, status counts, majorants, rarely nonzero rows.
void print_common_footer(const TablePlan& t, const Options& o, const std::vector<Row>& rows) {
    if (o.runs > 1)
        std::printf("seconds, lookups/spl, var/spl, LTUV, cpu-s*var: MEDIAN over %d runs (seeds %llu..%llu), "
                    "LTUV/best from the median LTUV; min..max: var/spl over the runs; mean: over the runs.\n",
                    o.runs, (unsigned long long)o.seed, (unsigned long long)(o.seed + std::uint64_t(o.runs) - 1));
    std::uint64_t aborted = 0, nonfinite = 0, rejected = 0;
    for (const Row& r : rows)
        for (const RenderStats& s : r.runs) {
            aborted += s.aborted;
            nonfinite += s.nonfinite;
            rejected += s.rejected;
        }
    std::printf("paths with status Aborted: %llu, NonFinite: %llu, Rejected: %llu\n", (unsigned long long)aborted,
                (unsigned long long)nonfinite, (unsigned long long)rejected);
    print_majorant_notes(o, rows);
    if (o.lights.point)
        std::printf("note: the point light (--point) is reachable by next-event estimation only, so the "
                    "unidirectional rows leave out its light and their mean is lower\n");
    else if (t.scene.kind == SceneKind::Fog &&
             std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.c.strategy == "unidirectional"; }))
        std::printf("note: the lamp is a point light, reachable by next-event estimation only: the "
                    "unidirectional rows cannot see it\n");
    for (const Row& r : rows) {
        std::uint64_t samples = 0;
        for (const RenderStats& s : r.runs) samples += s.samples;
        if (r.nonzero() < kFewNonzero)
            std::printf("note: %s: only %llu of %llu samples were nonzero (the light is rarely found); its "
                        "variance and mean rest on those few and are themselves very noisy\n",
                        r.c.name.c_str(), (unsigned long long)r.nonzero(), (unsigned long long)samples);
    }
}

/// The lowest-LTUV row among `rows` that `pred` accepts (nullptr if none measured a variance).
template <class P>
const Row* best_of(const std::vector<Row>& rows, const Metrics& m, P pred) {
    const Row* best = nullptr;
    for (const Row& r : rows)
        if (pred(r) && m.ltuv(r) > 0.0 && (!best || m.ltuv(r) < m.ltuv(*best))) best = &r;
    return best;
}

/// What the eff var/spl columns are (--reference-spp), and the reference they were measured against.
void print_reference_footer(const TablePlan& t, const Options& o, const std::vector<Row>& rows,
                            const Reference& reference) {
    double smallest = std::numeric_limits<double>::infinity();
    for (const Row& r : rows)
        if (!r.effective.empty()) smallest = std::min(smallest, Metrics::eff(r));
    const double contrib = reference.contribution(t.spp);
    std::printf("eff var/spl: effective variance per sample against a reference image of this set-up, mode "
                "and resolution: %s, %d spp, seed %llu (independent of every row), %.1f s, var/spl %s. Per "
                "run: %d x mean over pixels and channels of (pixel mean - reference pixel mean)^2, minus the "
                "reference's own noise, %d x mean(var_ref/%d) = %s (%.1f%% of the lowest eff var/spl). For an "
                "unbiased estimator it is an unbiased estimate of %d x the image's MSE = its variance per "
                "sample; for a heavy-tailed one it also holds the error its sample variance misses. eff LTUV "
                "= lookups/spl x eff var/spl; img eff var: the same from the image mean's error, %d x %d "
                "pixels x mean over channels of (image mean - reference's)^2 minus the same reference term "
                "(3 degrees of freedom per run, noisy, but a tail missed in every pixel adds up there); all "
                "%s. Reference image mean R G B: %s %s %s.\n",
                reference.estimator.c_str(), reference.spp, (unsigned long long)reference.seed,
                reference.stats.wall_seconds, num(reference.stats.variance_per_channel()).c_str(), t.spp, t.spp,
                reference.spp, num(contrib).c_str(),
                std::isfinite(smallest) && smallest > 0.0 ? 100.0 * contrib / smallest : 0.0, t.spp, t.spp,
                t.width * t.height, o.runs > 1 ? ("median over " + std::to_string(o.runs) + " runs").c_str() : "one run",
                num(reference.stats.mean[0]).c_str(), num(reference.stats.mean[1]).c_str(),
                num(reference.stats.mean[2]).c_str());
}

/// Means that disagree: the per-pixel variances give each image mean a standard error, and a row
/// far from the best row is heavy-tailed (its sample variance understates its variance, and its
/// mean is low in most runs) or biased. `channels`: name the channel (not in mono tables).
void print_mean_notes(const std::vector<Row>& rows, const Metrics& m, bool channels) {
    const Row* ref = best_of(rows, m, [](const Row& r) { return r.nonzero() >= kFewNonzero; });
    for (const Row& r : rows) {
        if (!ref || &r == ref || r.nonzero() < kFewNonzero) continue;
        const auto [z, c] = mean_gap(r, *ref);
        if (z > kMeanGap)
            std::printf("note: %s: image mean %s%s is %.1f standard errors from %s's %s: a heavy tail (its var/spl "
                        "then understates the variance) or a bias\n", r.c.name.c_str(), num(r.mean(c)).c_str(),
                        channels ? (std::string(" in ") + "RGB"[c]).c_str() : "", z, ref->c.name.c_str(),
                        num(ref->mean(c)).c_str());
    }
}

/// Time x variance of a row: the median over its runs of thread CPU seconds per sample x var/spl,
/// or x eff var/spl of the same run when the table has a reference (--reference-spp).
double time_variance(const Row& r, const Metrics& m) {
    if (r.effective.empty()) return r.median([&](const RenderStats& s) { return m.time_variance(s); });
    std::vector<double> v;
    for (std::size_t i = 0; i < r.effective.size(); ++i)
        v.push_back(r.runs[i].cpu_seconds_per_sample() * r.effective[i]);
    return Metrics::median_of(v);
}

/// The row of estimator `key` (its name without the majorant) with majorant `majorant`.
const Row* find_row(const std::vector<Row>& rows, std::string_view key, std::string_view majorant) {
    for (const Row& r : rows)
        if (r.c.key == key && r.c.majorant == majorant) return &r;
    return nullptr;
}

/// The majorants of `rows`, in the order they first appear.
std::vector<std::string> majorants_of(const std::vector<Row>& rows) {
    std::vector<std::string> out;
    for (const Row& r : rows)
        if (std::find(out.begin(), out.end(), r.c.majorant) == out.end()) out.push_back(r.c.majorant);
    return out;
}

std::string ratio_text(double a, double b) { return b > 0.0 && std::isfinite(a / b) ? num(a / b) : "n/a"; }

/// A row's estimator without its absorption policy, e.g. uni-nee-eq-mis_balance.
std::string without_absorption(const std::string& key) {
    const auto p = key.rfind("_absorb-");
    return p == std::string::npos ? key : key.substr(0, p);
}

/// The fog's question (THEORY 5.4), per majorant: which single vertex sampler wins in time x
/// variance, tracking + NEE or equiangular + NEE, and how far the three-way MIS is from it.
void print_fog_summary(const std::vector<Row>& rows, const Metrics& m) {
    const bool eff = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.effective.empty(); });
    for (const std::string& maj : majorants_of(rows)) {
        const Row* nee = find_row(rows, "ratio-nee_absorb-weight", maj);
        const Row* eq = find_row(rows, "equiangular-nee_absorb-weight", maj);
        if (!nee || !eq) continue;
        const double tn = time_variance(*nee, m), te = time_variance(*eq, m);
        const bool eq_best = te < tn;
        const double best = std::min(tn, te);
        std::printf("%s majorant, time x variance (%s): ratio-nee %s, equiangular-nee %s -> best single strategy: "
                    "%s (%sx lower)", maj.c_str(), eff ? "cpu-s/spl x eff var/spl" : "cpu-s*var", num(tn).c_str(),
                    num(te).c_str(), eq_best ? "equiangular-nee" : "ratio-nee",
                    ratio_text(std::max(tn, te), best).c_str());
        for (const char* key : {"uni-nee-eq-mis_balance_absorb-weight", "uni-nee-eq-mis_power_absorb-weight",
                                "uni-nee-mis_balance_absorb-weight"})
            if (const Row* r = find_row(rows, key, maj))
                std::printf("; %s / best single: %s", without_absorption(r->c.key).c_str(),
                            ratio_text(time_variance(*r, m), best).c_str());
        std::printf("\n");
    }
}

/// The plume's question (THEORY 5.7), per majorant: the collision estimator alone against NEE
/// toward the emitting volume combined with it by MIS, in time x variance and LTUV (effective
/// ones with a reference).
void print_plume_summary(const std::vector<Row>& rows, const Metrics& m) {
    const bool eff = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.effective.empty(); });
    const auto ltuv = [&](const Row& r) { return r.effective.empty() ? m.ltuv(r) : Metrics::eff_ltuv(r); };
    for (const std::string& maj : majorants_of(rows)) {
        const Row* uni = find_row(rows, "unidirectional_absorb-weight", maj);
        if (!uni) continue;
        std::string line;
        for (const char* key : {"uni-nee-mis_balance_absorb-weight", "uni-nee-mis_power_absorb-weight",
                                "ratio-nee_absorb-weight"})
            if (const Row* r = find_row(rows, key, maj))
                line += std::string(line.empty() ? "" : "; ") + without_absorption(r->c.key) + " " +
                        ratio_text(time_variance(*uni, m), time_variance(*r, m)) + "x (LTUV " +
                        ratio_text(ltuv(*uni), ltuv(*r)) + "x)";
        if (!line.empty())
            std::printf("%s majorant, collision estimator alone (unidirectional) / each row, time x variance (%s): "
                        "%s\n", maj.c_str(), eff ? "cpu-s/spl x eff var/spl" : "cpu-s*var", line.c_str());
    }
}

/// The scene words of a grey table's title.
std::string scene_words(const SceneChoice& c) {
    switch (c.kind) {
        case SceneKind::Sparse: return "sparse medium, ";
        case SceneKind::Fog:
            return c.fog == FogSetup::F1 ? "thin fog, lamp inside, "
                   : c.fog == FogSetup::F2 ? "thin fog, lamp beside, "
                                           : "dense fog (40x F2's), lamp beside, ";
        case SceneKind::Plume: return "flame in the smoke (emissive medium), ";
        default: return "";
    }
}

void print_cloud_table(const TablePlan& t, const Options& o, const std::vector<Row>& rows, const Reference* reference) {
    const Metrics m{false};
    std::printf("\nSet-up %s (%s%.*s, %dx%d, %d spp, %d threads%s)\n", t.scene.name(), scene_words(t.scene).c_str(),
                int(t.mode.size()), t.mode.data(), t.width, t.height, t.spp, o.threads,
                o.runs > 1 ? (", " + std::to_string(o.runs) + " runs").c_str() : "");
    print_rows(t, o, rows, m);
    std::printf("var/spl: per-pixel sample variance of the %d samples of each pixel (Welford)%s, averaged over "
                "the %d pixels.\n", t.spp,
                t.mode == nsp::Mono::name ? ""
                : t.mode == Hero4::name   ? " of the channel mean of its linear sRGB values"
                                          : " of the channel mean",
                t.width * t.height);
    std::printf("LTUV = lookups/spl x var/spl; cpu-s*var = thread CPU seconds per sample x var/spl; lower is "
                "better. mean: image mean (should agree across rows).\n");
    print_common_footer(t, o, rows);
    print_majorant_comparison(rows, m);
    if (reference) print_reference_footer(t, o, rows, *reference);
    if (t.scene.kind == SceneKind::Fog || t.scene.kind == SceneKind::Plume)
        print_mean_notes(rows, m, t.mode != nsp::Mono::name);
    if (t.scene.kind == SceneKind::Fog) return print_fog_summary(rows, m);
    if (t.scene.kind == SceneKind::Plume) return print_plume_summary(rows, m);
    // THEORY 7's claim, on the absorb-weight rows when present.
    const auto* uni = find_row(rows, "unidirectional_absorb-weight");
    const auto* nee = find_row(rows, "ratio-nee_absorb-weight");
    const auto* mis = find_row(rows, "uni-nee-mis_balance_absorb-weight");
    if (uni && m.ltuv(*uni) <= 0.0) return;  // unidirectional never found the light: no ratio
    if (uni && nee) std::printf("ratio-nee / unidirectional LTUV: %s", num(m.ltuv(*nee) / m.ltuv(*uni)).c_str());
    if (uni && nee && mis)
        std::printf("; uni-nee-mis_balance / best single strategy: %s",
                    num(m.ltuv(*mis) / std::min(m.ltuv(*uni), m.ltuv(*nee))).c_str());
    if (uni && nee) std::printf(" (absorb-weight rows)\n");
}

void print_chromatic_table(const TablePlan& t, const Options& o, const std::vector<Row>& rows,
                           const Reference* reference) {
    const Metrics m{true};
    std::printf("\nSet-up %s (chromatic 1:4:16, %.*s, %dx%d, %d spp, %d threads%s)\n", t.scene.name(),
                int(t.mode.size()), t.mode.data(), t.width, t.height, t.spp, o.threads,
                o.runs > 1 ? (", " + std::to_string(o.runs) + " runs").c_str() : "");
    print_rows(t, o, rows, m);
    const bool hero = t.mode == Hero4::name;
    std::printf("var/spl: per-channel sample variance of the %d samples of each pixel (Welford)%s, averaged over "
                "the 3 channels and the %d pixels; the variance of the channel mean would hide independent "
                "tracking's colour noise.\n", t.spp, hero ? " of its linear sRGB values" : "", t.width * t.height);
    std::printf("LTUV = lookups/spl x var/spl; cpu-s*var = thread CPU seconds per sample x var/spl; lower is "
                "better. mean R G B: image mean per channel%s (should agree across rows).\n",
                hero ? " (linear sRGB)" : "");
    std::printf("Rows without a channel policy are nsp::PathEstimator with the grey (global) majorant; _lum: "
                "luminance channel selection, otherwise uniform.\n");
    print_common_footer(t, o, rows);
    print_majorant_comparison(rows, m);
    if (reference) print_reference_footer(t, o, rows, *reference);
    print_mean_notes(rows, m, true);

    const std::string runs_note = o.runs > 1 ? "median over " + std::to_string(o.runs) + " runs"
                                             : "one run; the baseline is heavy-tailed, see --runs, --reference-spp";
    // (a) spectral MIS + NEE (each majorant) against the grey-majorant baseline of the same mode.
    const Row* base = find_row(rows, "uni-nee-mis_balance_absorb-weight");
    std::vector<std::pair<std::string, const Row*>> compared;
    for (const char* majorant : {"per-channel", "global"})
        for (const char* suffix : {"", "_lum"}) {
            const Row* smis = find_row(rows, std::string("uni-nee-mis_spectral-mis_") + majorant +
                                                 "_balance_absorb-weight" + suffix);
            if (!base || !smis) continue;
            const auto [z, c] = mean_gap(*base, *smis);
            const std::string label = std::string("spectral-mis ") + majorant + " + NEE" + (*suffix ? " lum" : "");
            std::printf("baseline / %s: var/spl %s, LTUV %s (%s); image means %.1f standard errors apart in %c%s\n",
                        label.c_str(), num(m.var(*base) / m.var(*smis)).c_str(),
                        num(m.ltuv(*base) / m.ltuv(*smis)).c_str(), runs_note.c_str(), z, "RGB"[c],
                        z > kMeanGap ? " (too far apart: a heavy tail of the baseline, whose var/spl then "
                                       "understates its variance, or a bias)"
                                     : "");
            if (!base->effective.empty() && !smis->effective.empty()) {
                std::string each;  // run i of both rows used the same seed
                for (std::size_t i = 0; i < base->effective.size() && i < smis->effective.size(); ++i)
                    each += (each.empty() ? "" : ", ") + num(base->effective[i] / smis->effective[i]);
                std::string each_image;
                for (std::size_t i = 0; i < base->effective_image.size() && i < smis->effective_image.size(); ++i)
                    each_image += (each_image.empty() ? "" : ", ") +
                                  num(base->effective_image[i] / smis->effective_image[i]);
                std::printf("  against the reference: eff var/spl %s, eff LTUV %s, img eff var %s (%s)%s%s\n",
                            num(Metrics::eff(*base) / Metrics::eff(*smis)).c_str(),
                            num(Metrics::eff_ltuv(*base) / Metrics::eff_ltuv(*smis)).c_str(),
                            num(Metrics::eff_image(*base) / Metrics::eff_image(*smis)).c_str(),
                            o.runs > 1 ? ("ratio of the medians over " + std::to_string(o.runs) + " runs").c_str()
                                       : "one run",
                            o.runs > 1 ? ("; eff var/spl ratio per run: " + each).c_str() : "",
                            o.runs > 1 ? ("; img eff var ratio per run: " + each_image).c_str() : "");
            }
            compared.emplace_back(label, smis);
        }
    if (o.runs > 1 && !compared.empty()) {
        auto runs_of = [&](const Row& r) {
            std::string v = per_run(r, [&](const RenderStats& s) { return m.variance(s); });
            if (!r.effective.empty()) {
                std::string e, g;
                for (const double x : r.effective) e += (e.empty() ? "" : ", ") + num(x);
                for (const double x : r.effective_image) g += (g.empty() ? "" : ", ") + num(x);
                v += "; eff var/spl " + e + "; img eff var " + g;
            }
            return v;
        };
        std::printf("  per run, var/spl: baseline %s\n", runs_of(*base).c_str());
        for (const auto& [label, r] : compared) std::printf("  per run, var/spl: %s %s\n", label.c_str(), runs_of(*r).c_str());
    }
    // (b) the best of each channel policy, and the best overall, by LTUV.
    struct Family {
        const char* label;
        std::function<bool(const Row&)> pred;
    };
    const std::vector<Family> families{
        {"independent", [](const Row& r) { return r.c.channels == "independent"; }},
        {"spectral tracking", [](const Row& r) { return r.c.channels.starts_with("spectral-tracking"); }},
        {"spectral MIS", [](const Row& r) { return r.c.channels == "spectral-mis" && r.c.strategy != "uni-nee-mis"; }},
        {"spectral MIS + NEE",
         [](const Row& r) { return r.c.channels == "spectral-mis" && r.c.strategy == "uni-nee-mis"; }},
    };
    std::string line;
    std::vector<std::pair<double, const char*>> bests;
    for (const Family& f : families) {
        const Row* r = best_of(rows, m, f.pred);
        if (!r) continue;
        line += std::string(line.empty() ? "" : "; ") + f.label + " " + num(m.ltuv(*r)) + " (" + r->c.name + ")";
        bests.emplace_back(m.ltuv(*r), f.label);
    }
    if (!bests.empty()) {
        std::sort(bests.begin(), bests.end());
        std::string close;  // within 10% of the lowest: no ranking at this noise level
        for (std::size_t i = 1; i < bests.size(); ++i)
            if (bests[i].first <= 1.1 * bests[0].first)
                close += std::string(close.empty() ? "" : ", ") + bests[i].second;
        std::printf("best LTUV per channel policy: %s -> lowest: %s%s\n", line.c_str(), bests[0].second,
                    close.empty() ? "" : (" (within 10%: " + close + ")").c_str());
    }
    // (c) luminance against uniform selection, row by row.
    std::string sel;
    for (const Row& r : rows) {
        if (r.c.selection != SelectionRule::Luminance) continue;
        const Row* u = find_row(rows, r.c.name.substr(0, r.c.name.size() - 4));
        if (u && m.ltuv(*u) > 0.0)
            sel += std::string(sel.empty() ? "" : "; ") + u->c.name + " " + num(m.ltuv(r) / m.ltuv(*u));
    }
    if (!sel.empty()) std::printf("luminance / uniform selection, LTUV: %s\n", sel.c_str());
}

void list_combinations() {
    std::printf("%-5s %-21s %-13s %-15s %-9s %-13s %-10s %s\n", "mode", "channels", "majorant", "strategy",
                "heuristic", "absorption", "medium", "name");
    std::size_t total = 0;
    for (const auto mode : mode_names()) {
        const std::vector<CombinationInfo> all = infos(mode);
        for (const CombinationInfo& c : all)
            std::printf("%-5s %-21s %-13s %-15s %-9s %-13s %-10s %s\n", c.mode, c.channels, c.majorant, c.strategy,
                        c.heuristic, c.absorption, c.medium, c.name().c_str());
        std::printf("  %.*s: %zu combinations\n", int(mode.size()), mode.data(), all.size());
        total += all.size();
    }
    std::printf("%zu valid combinations. channels 'grey' is nsp::PathEstimator (a grey majorant: global or grid, "
                "and in mono also the non-bounding global-signed, global-clamp, grid-signed, grid-clamp; a "
                "heuristic on a single strategy and mis::None on an MIS strategy are rejected); the others are "
                "nsp::SpectralPathEstimator, only in multi-channel modes: independent tracking with a per-channel "
                "majorant (per-channel, channel-grid), spectral tracking with a grey one (global, grid), "
                "spectral-mis with any of the four; no directional-mis; mis::None for single strategies, balance "
                "for uni-nee-mis. Majorants other than global and per-channel: absorb-weight only (build time), "
                "except the equiangular strategies (equiangular-nee, uni-nee-eq-mis), which take both absorption "
                "policies with grid too and are compiled for nsp::PathEstimator in mono only (build time; the "
                "library also has them in nsp::SpectralPathEstimator). Medium 'emissive' (the plume scene's flame, "
                "nsp::Emissive): nsp::PathEstimator in rgb with global or grid, absorb-weight, without the "
                "equiangular strategies (build time; nsp::SpectralPathEstimator takes emissive media too). Independent and spectral-mis rows are rendered once per --selection rule "
                "(luminance rows end in _lum).\n", total);
}

RenderStats render_in_mode(std::string_view mode, std::size_t index, const RenderRequest& rq, std::vector<float>& rgb) {
    if (mode == nsp::Mono::name) return render_combination<nsp::Mono>(index, rq, rgb);
    if (mode == nsp::Rgb::name) return render_combination<nsp::Rgb>(index, rq, rgb);
    return render_combination<Hero4>(index, rq, rgb);
}

int run(const Options& o) {
    if (o.list) {
        list_combinations();
        return 0;
    }
    const std::vector<TablePlan> tables = plan(o);
    if (o.write_exr) std::filesystem::create_directories(o.out);
    // --reference-spp: the chromatic cloud's tables (rgb, hero: mono has no spectral tracking), the
    // fog's and the plume's get a reference image.
    auto reference_name = [](const TablePlan& t) -> const char* {
        switch (t.scene.kind) {
            case SceneKind::Chromatic: return kReferenceEstimator;
            case SceneKind::Fog: return kFogReferenceEstimator;
            case SceneKind::Plume: return kPlumeReferenceEstimator;
            default: return nullptr;
        }
    };
    auto reference_index = [&](const TablePlan& t) -> std::optional<std::size_t> {
        const char* name = reference_name(t);
        if (!o.reference_spp || !name) return std::nullopt;
        for (const Candidate& c : candidates(t.mode, {SelectionRule::Uniform}))
            if (c.emissive == (t.scene.kind == SceneKind::Plume) && c.name == name) return c.index;
        return std::nullopt;
    };
    std::size_t total = 0;
    for (const TablePlan& t : tables) total += t.rows.size() * std::size_t(o.runs) + (reference_index(t) ? 1 : 0);
    std::fprintf(stderr, "nsp_render: %zu renders in %zu tables on %d threads\n", total, tables.size(), o.threads);
    const auto t0 = std::chrono::steady_clock::now();
    std::size_t done = 0;
    auto request = [&](const TablePlan& t, std::uint64_t seed, SelectionRule selection) {
        RenderRequest rq;
        rq.scene = t.scene;
        rq.lights = o.lights;
        rq.selection = selection;
        rq.width = t.width;
        rq.height = t.height;
        rq.spp = t.spp;
        rq.threads = o.threads;
        rq.seed = seed;
        rq.estimator = o.estimator;
        rq.majorant = o.majorant;
        return rq;
    };
    for (const TablePlan& t : tables) {
        std::optional<Reference> reference;
        if (const auto index = reference_index(t)) {
            reference.emplace();
            reference->estimator = reference_name(t);
            reference->spp = *o.reference_spp;
            reference->seed = o.seed + kReferenceSeedOffset;
            RenderRequest rq = request(t, reference->seed, SelectionRule::Uniform);
            rq.spp = reference->spp;
            rq.pixel_stats = true;
            std::ostringstream label;
            label << '[' << ++done << '/' << total << "] " << t.scene.name() << "_reference_" << t.mode;
            rq.label = label.str();
            std::vector<float> rgb;
            reference->stats = render_in_mode(t.mode, *index, rq, rgb);
        } else if (o.reference_spp) {
            const char* name = reference_name(t);
            if (name)
                std::fprintf(stderr, "nsp_render: --reference-spp: no reference for set-up %s in %.*s mode (it needs "
                             "%s)\n", t.scene.name(), int(t.mode.size()), t.mode.data(), name);
            else
                std::fprintf(stderr, "nsp_render: --reference-spp: set-up %s has no reference estimator (only the "
                             "chromatic cloud's, the fog's and the plume's tables have one)\n", t.scene.name());
        }
        std::vector<Row> rows;
        for (const Candidate& c : t.rows) {
            Row row{c, {}, {}, {}};
            std::string file = std::string(t.scene.name()) + "_" + c.name;
            if (t.mode != nsp::Mono::name) file.append("_").append(t.mode);
            for (int run = 0; run < o.runs; ++run) {
                RenderRequest rq = request(t, o.seed + std::uint64_t(run), c.selection);
                rq.pixel_stats = reference.has_value();
                std::ostringstream label;  // not "[" + std::to_string(..): GCC 12 warns (-Wrestrict, bug 105329)
                label << '[' << ++done << '/' << total << "] " << file;
                if (o.runs > 1) label << " run " << run + 1;
                rq.label = label.str();
                std::vector<float> rgb;
                row.runs.push_back(render_in_mode(t.mode, c.index, rq, rgb));
                if (reference) {
                    row.effective.push_back(effective_variance(row.runs.back(), t.spp, *reference));
                    row.effective_image.push_back(effective_image_variance(row.runs.back(), t.spp, *reference));
                    row.runs.back().pixel_mean = {};
                    row.runs.back().pixel_variance = {};
                }
                if (o.write_exr && run == 0)
                    write_exr_rgb((std::filesystem::path(o.out) / (file + ".exr")).string(), t.width, t.height, rgb);
            }
            rows.push_back(std::move(row));
        }
        if (t.scene.kind != SceneKind::Chromatic) print_cloud_table(t, o, rows, reference ? &*reference : nullptr);
        else print_chromatic_table(t, o, rows, reference ? &*reference : nullptr);
        std::fflush(stdout);
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("\ntotal wall time: %.1f s%s\n", secs, o.write_exr ? (", images in " + o.out + "/").c_str() : "");
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const Options o = parse(argc, argv);
    try {
        return run(o);
    } catch (const std::exception& e) {
        std::cerr << "nsp_render: error: " << e.what() << "\n";
        return 1;
    }
}
