// examples/cli.cpp: nsp_render's command line (see cli.hpp), parsed with CLI11 through parse_flags
// (tool.hpp). Every value is checked here with a message that names the flag, the bad value and
// what is allowed.
#include "cli.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <limits>
#include <thread>

#include <CLI/CLI.hpp>

#include "catalogue.hpp"
#include "plan.hpp"
#include "tool.hpp"

namespace nsp_examples {

void usage_error(const std::string& msg) { throw UsageError(msg, true); }

std::vector<std::string_view> split(std::string_view s, char sep) {
    std::vector<std::string_view> parts;
    for (;;) {
        const auto p = s.find(sep);
        parts.push_back(s.substr(0, p));
        if (p == std::string_view::npos) return parts;
        s.remove_prefix(p + 1);
    }
}

namespace {

template <std::size_t N>
std::array<float, N> parse_floats(std::string_view flag, std::string_view text) {
    const auto parts = split(text, ',');
    if (parts.size() != N)
        throw UsageError(std::string(flag) + ": expected " + std::to_string(N) + " comma-separated numbers, got '" +
                       std::string(text) + "'", true);
    std::array<float, N> v{};
    for (std::size_t i = 0; i < N; ++i) v[i] = parse_number<float>(flag, parts[i], -1e30f, 1e30f);
    return v;
}

std::string joined(const std::vector<std::string_view>& names) {
    std::string s;
    for (const auto n : names) s += std::string(n) + ", ";
    return s;
}

void parse_scenes(Options& o, std::string_view value) {
    o.scenes.clear();
    auto add = [&](SceneKind k) {
        if (std::find(o.scenes.begin(), o.scenes.end(), k) == o.scenes.end()) o.scenes.push_back(k);
    };
    std::vector<std::string_view> names;
    for (const SceneEntry& e : catalogue()) names.emplace_back(e.name);
    for (const auto t : split(value, ',')) {
        if (t == "both") add(SceneKind::Cloud), add(SceneKind::Chromatic);
        else if (t == "all") for (const SceneEntry& e : catalogue()) add(e.kind);
        else if (const auto it = std::find(names.begin(), names.end(), t); it != names.end())
            add(catalogue()[std::size_t(it - names.begin())].kind);
        else throw UsageError("--scene: '" + std::string(t) + "' is not one of " + joined(names) + "both, all", true);
    }
}

void parse_setups(Options& o, std::string_view value) {
    o.setups.clear();
    const std::vector<std::string> known = setup_names();
    for (const auto t : split(value, ',')) {
        std::string up(t);
        for (char& ch : up) ch = char(std::toupper(static_cast<unsigned char>(ch)));
        if (up == "ALL" || up == "BOTH") o.setups = known;
        else if (std::find(known.begin(), known.end(), up) != known.end()) o.setups.push_back(up);
        else {
            std::string list;
            for (const auto& k : known) list += k + ", ";
            throw UsageError("--setup: '" + std::string(t) + "' is not one of " + list + "all", true);
        }
    }
}

void parse_majorants(Options& o, std::string_view value) {
    const auto known = majorant_names();
    o.majorants.clear();
    for (const auto t : split(value, ',')) {
        if (t == "all") o.majorants.assign(known.begin(), known.end()), o.all_majorants = true;
        else if (std::find(known.begin(), known.end(), t) != known.end()) o.majorants.emplace_back(t);
        else throw UsageError("--majorant: '" + std::string(t) + "' is not one of " + joined(known) + "all", true);
    }
    if (o.majorants.empty()) throw UsageError("--majorant needs at least one name", true);
}

void parse_modes(Options& o, std::string_view value) {
    const auto known = mode_names();
    o.modes.clear();
    for (const auto t : split(value, ',')) {
        if (t == "all") o.modes = known;
        else if (t == "both") o.modes = {nsp::Mono::name, nsp::Rgb::name};
        else if (const auto it = std::find(known.begin(), known.end(), t); it != known.end()) o.modes.push_back(*it);
        else throw UsageError("--spectral: '" + std::string(t) + "' is not one of mono, rgb, hero, both, all", true);
    }
}

constexpr const char* kDescription =
    "nsp_render: renders the example scenes with nsp's estimators and prints an efficiency table per\n"
    "light set-up and spectral mode (LTUV = density lookups per sample x variance per sample;\n"
    "cpu-s*var = CPU seconds per sample x variance per sample; lower is better). Writes an EXR per\n"
    "row, a PNG contact sheet per table and a PNG picture per scene. docs/renderer.md explains\n"
    "every flag at length. Exits 0; 1 if a path ended with status Aborted or NonFinite or a write\n"
    "failed; 2 on a bad command line (a message names the flag).";

constexpr const char* kFooter =
    "Examples: nsp_render --scene cloud --setup A --estimators uni-nee-mis_balance\n"
    "          nsp_render --scene sparse --majorant all --spp 32\n"
    "          nsp_render --scene fog,plume --setup F1,P1 --runs 3 --reference-spp 2048 --no-exr";

}  // namespace

Options parse_command_line(int argc, char** argv) {
    Options o;
    o.threads = std::max(1, int(std::thread::hardware_concurrency()));
    o.setups = default_setup_names();
    for (const SceneEntry& e : catalogue()) o.scenes.push_back(e.kind);

    CLI::App app(kDescription, "nsp_render");
    app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    app.get_formatter()->column_width(28);
    app.footer(kFooter);
    app.set_help_flag("-h,--help", "this text");
    // One value: `parse` turns it into the option's field or throws UsageError.
    auto value = [&](const char* flag, const char* type, const char* help, auto parse) {
        app.add_option_function<std::string>(flag, [=](const std::string& v) { parse(std::string_view(v)); }, help)
            ->type_name(type);
    };
    auto flag = [&](const char* name, const char* help, auto set) {
        app.add_flag_callback(name, set, help)->disable_flag_override();
    };
    // What is rendered
    value("--scene", "LIST", "cloud, chromatic, sparse, fog, plume, both (cloud,chromatic), all",
          [&](std::string_view v) { parse_scenes(o, v); });
    value("--setup", "LIST", "A, B, D, C1, C2, C3, SA, SB, F1, F2, F3, P1, all (default: all but SB)",
          [&](std::string_view v) { parse_setups(o, v); });
    value("--spectral", "LIST", "spectral modes: mono, rgb, hero, both (= mono,rgb), all",
          [&](std::string_view v) { parse_modes(o, v); });
    value("--estimators", "LIST", "rows whose name has all '_'-separated fields of an item, or 'all'",
          [&](std::string_view v) {
              o.estimators.clear();
              for (const auto t : split(v, ','))
                  if (!t.empty()) o.estimators.emplace_back(t);
              if (o.estimators.empty()) throw UsageError("--estimators needs at least one name", true);
          });
    value("--majorant", "LIST", "global, per-channel, grid, channel-grid, grid-control, channel-grid-control, grid-signed, ..., all",
          [&](std::string_view v) { parse_majorants(o, v); });
    value("--grid-res", "N", "cells per axis of the grid majorants (default 16)",
          [&](std::string_view v) { o.majorant.grid_res = parse_number<int>("--grid-res", v, 1, 1024); });
    value("--majorant-scale", "S", "the non-bounding majorants' fraction of the bound (default 0.5)",
          [&](std::string_view v) { o.majorant.scale = parse_number<float>("--majorant-scale", v, 1e-3f, 1e3f); });
    value("--selection", "R", "spectral channel selection: uniform, luminance, both (default)", [&](std::string_view v) {
        if (v == "uniform") o.selections = {SelectionRule::Uniform};
        else if (v == "luminance") o.selections = {SelectionRule::Luminance};
        else if (v == "both") o.selections = {SelectionRule::Uniform, SelectionRule::Luminance};
        else throw UsageError("--selection: '" + std::string(v) + "' is not one of uniform, luminance, both", true);
    });
    // How much
    value("--spp", "N", "samples per pixel, N >= 2 (default: the scene's)",
          [&](std::string_view v) { o.spp = parse_number<int>("--spp", v, 2, 1 << 20); });
    value("--res", "WxH", "image size (default: the scene's); also --width W, --height H", [&](std::string_view v) {
        const auto x = v.find('x');
        if (x == std::string_view::npos)
            throw UsageError("--res: expected WxH, e.g. 128x128, got '" + std::string(v) + "'", true);
        o.width = parse_number<int>("--res width", v.substr(0, x), 1, 16384);
        o.height = parse_number<int>("--res height", v.substr(x + 1), 1, 16384);
    });
    value("--width", "W", "image width", [&](std::string_view v) { o.width = parse_number<int>("--width", v, 1, 16384); });
    value("--height", "H", "image height",
          [&](std::string_view v) { o.height = parse_number<int>("--height", v, 1, 16384); });
    value("--pilot-count", "C", "learned rows: run the pilot at NEE and segment count C in [1/64, 1] (default 0.25)",
          [&](std::string_view v) { o.pilot_count = parse_number<float>("--pilot-count", v, 1.f / 64.f, 1.f); });
    value("--pilot-weight", "W",
          "learned rows: a pixel's pilot samples weigh by the variance its tile predicts (variance, default) "
          "or as much as its other samples (equal)",
          [&](std::string_view v) {
              if (v != "variance" && v != "equal")
                  throw UsageError("--pilot-weight: expected variance or equal, got '" + std::string(v) + "'", true);
              o.weigh_pilot = v == "variance";
          });
    value("--count-cost", "M",
          "learned rows: the learner's cost, density lookups as LTUV counts them (lookups, default) or nsp's "
          "default cost model (model)",
          [&](std::string_view v) {
              if (v != "lookups" && v != "model")
                  throw UsageError("--count-cost: expected lookups or model, got '" + std::string(v) + "'", true);
              o.lookup_costs = v == "lookups";
          });
    value("--scout", "S",
          "learned rows: a scout of 2 samples in one pixel of 16 raises the pilot's counts to those it predicts "
          "best at or above --pilot-count (on, default), or none (off)",
          [&](std::string_view v) {
              if (v != "on" && v != "off")
                  throw UsageError("--scout: expected on or off, got '" + std::string(v) + "'", true);
              o.scout = v == "on";
          });
    value("--runs", "K", "render each row K times (seeds seed..seed+K-1), report medians",
          [&](std::string_view v) { o.runs = parse_number<int>("--runs", v, 1, 1000); });
    value("--reference-spp", "N", "effective variance against an N-spp reference (chromatic, fog, plume)",
          [&](std::string_view v) { o.reference_spp = parse_number<int>("--reference-spp", v, 2, 1 << 24); });
    value("--threads", "N", "worker threads (default: all cores; images do not depend on it)",
          [&](std::string_view v) { o.threads = parse_number<int>("--threads", v, 1, 1024); });
    value("--seed", "N", "random seed, unsigned 64-bit (default 1)", [&](std::string_view v) {
        o.seed = parse_number<std::uint64_t>("--seed", v, 0, std::numeric_limits<std::uint64_t>::max());
    });
    // The estimators' options
    value("--max-depth", "N", "real scattering vertices per path (default 1000; 0: direct light)",
          [&](std::string_view v) { o.estimator.max_depth = parse_number<int>("--max-depth", v, 0, 1 << 20); });
    flag("--equiangular-every-segment", "uni-nee-eq-mis: an equiangular vertex on every segment",
         [&] { o.estimator.adaptive_equiangular = false; });
    value("--equiangular-count", "C",
          "draw the equiangular vertex on a fraction C in [0, 1] of the pieces (0: uni-nee-eq-mis is uni-nee-mis; "
          "equiangular-nee refuses 0)",
          [&](std::string_view v) {
              o.estimator.equiangular_count = parse_number<float>("--equiangular-count", v, 0.f, 1.f);
          });
    value("--shadow", "ratio|marching",
          "shadow rays' transmittance: ratio tracking (default) or unbiased ray marching; marching renders only the rows "
          "that take it (grey ratio-nee, directional-mis, equiangular-nee), named _marched",
          [&](std::string_view v) {
              if (v == "ratio") o.estimator.shadow_estimator = nsp::ShadowEstimator::RatioTracking;
              else if (v == "marching") o.estimator.shadow_estimator = nsp::ShadowEstimator::RayMarching;
              else throw UsageError("--shadow: '" + std::string(v) + "' is not ratio or marching", true);
          });
    flag("--no-emission-segments", "leave out the emission segment technique (plume)",
         [&] { o.estimator.emission_along_segments = false; });
    value("--emission-segment-count", "C", "run the emission segment technique on a fraction C in (0, 1] of segments",
          [&](std::string_view v) {
              o.estimator.emission_segment_count = parse_number<float>("--emission-segment-count", v, 1e-6f, 1.f);
          });
    // Lights
    value("--env", "L", "add a constant environment light of radiance L >= 0",
          [&](std::string_view v) { o.lights.env = parse_number<float>("--env", v, 0.f, 1e30f); });
    value("--point", "X,Y,Z,I", "add a point light of intensity I >= 0 (the fog: move its lamp)", [&](std::string_view v) {
        o.lights.point = parse_floats<4>("--point", v);
        if ((*o.lights.point)[3] < 0.f) throw UsageError("--point: the intensity must be >= 0", true);
    });
    value("--sphere", "X,Y,Z,R,L", "replace the sphere light (R > 0, L >= 0; outside the medium)",
          [&](std::string_view v) {
              o.lights.sphere = parse_floats<5>("--sphere", v);
              if (!((*o.lights.sphere)[3] > 0.f)) throw UsageError("--sphere: the radius must be > 0", true);
              if ((*o.lights.sphere)[4] < 0.f) throw UsageError("--sphere: the radiance must be >= 0", true);
          });
    // Output
    value("--out", "DIR", "directory for the images (default out), created if missing", [&](std::string_view v) {
        o.out = std::string(v);
        if (o.out.empty()) throw UsageError("--out needs a directory name", true);
    });
    flag("--no-exr", "write no EXR images", [&] { o.write_exr = false; });
    flag("--no-png", "write no PNG images (contact sheets, pictures)", [&] { o.write_png = false; });
    value("--picture-res", "N", "size of each scene's larger PNG picture (default 256; 0: none)",
          [&](std::string_view v) { o.picture_res = parse_number<int>("--picture-res", v, 0, 4096); });
    flag("--list", "list every compiled policy combination and exit", [&] { o.list = true; });

    parse_flags(app, argc, argv);
    return o;
}

}  // namespace nsp_examples
