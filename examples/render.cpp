// examples/render.cpp: nsp_render, the example host renderer and the project's main job.
//
// Renders the default cloud (examples/default_scene.hpp) in light set-ups A and B with every
// path estimator nsp offers, writes one EXR per render and prints an efficiency table per set-up
// (THEORY 7: LTUV = density lookups per sample x variance of one sample). The command-line
// choices are turned into types once, in `tl::with_index` over the compile-time list of every
// valid policy combination (combinations.hpp); each render loop is monomorphic.
#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <exception>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include <unistd.h>

#include <nsp/nsp.hpp>

#include "combinations.hpp"
#include "default_scene.hpp"
#include "exr_writer.hpp"
#include "type_list.hpp"

namespace {

using namespace nsp_examples;

// ---------------------------------------------------------------------------------------------
// Command line

constexpr int kDefaultWidth = 128, kDefaultHeight = 128, kDefaultSpp = 512;

/// The estimators of the default run: every estimator, both MIS heuristics, both absorption
/// policies (THEORY 4 asks to measure both), in the Mono mode.
constexpr std::string_view kDefaultEstimators = "all";

struct Options {
    int width = kDefaultWidth, height = kDefaultHeight, spp = kDefaultSpp;
    int threads = std::max(1, int(std::thread::hardware_concurrency()));
    std::uint64_t seed = 1;
    nsp::EstimatorOptions estimator;  ///< max depth and roulette settings
    std::string out = "out";
    bool write_exr = true;
    bool list = false;
    std::vector<LightSetup> setups{LightSetup::A, LightSetup::B};
    std::vector<std::string_view> modes{nsp::Mono::name};
    std::vector<std::string> estimators;  ///< filter tokens (empty: kDefaultEstimators)
    std::optional<float> env;                    ///< constant environment radiance
    std::optional<std::array<float, 4>> point;   ///< x, y, z, intensity
    std::optional<std::array<float, 5>> sphere;  ///< x, y, z, radius, radiance
};

constexpr const char* kHelp = R"(nsp_render: render the default cloud with every nsp path estimator and print an
efficiency table per light set-up (LTUV = density lookups per sample x variance per sample).

usage: nsp_render [flags]

  --spp N            samples per pixel, N >= 2 (default 512); the variance per sample is
                     estimated from the N samples of each pixel
  --res WxH          image size in pixels (default 128x128); also --width W, --height H
  --threads N        worker threads (default: hardware concurrency)
  --seed N           random seed, an unsigned 64-bit integer (default 1); images do not depend
                     on --threads
  --max-depth N      most real scattering vertices on a path, N >= 0 (default 1000; 0 renders
                     the directly transmitted light only); Russian roulette from depth 3 on
  --out DIR          directory for the EXR images (default out), created if missing; one image
                     per render, named SETUP_ESTIMATOR[_HEURISTIC]_ABSORPTION[_rgb].exr
  --no-exr           do not write images (timings and table only)
  --setup S          A, B or both (default both). A: a small bright sphere light above the
                     cloud (NEE should win); B: a large dim sphere light behind it
                     (unidirectional should win)
  --spectral M       mono, rgb or both (default mono): the spectral mode of the renders
  --estimators LIST  comma-separated filter (default all). Each item selects the combinations
                     whose name contains all of its '_'-separated fields, e.g.
                     uni-nee-mis (4 renders), uni-nee-mis_power, absorb-event, ratio-nee;
                     'all' selects every valid combination. Names: unidirectional, ratio-nee,
                     directional-mis, uni-nee-mis; balance, power; absorb-event, absorb-weight.
  --list             list every compiled policy combination and exit
  --env L            add a constant environment light of radiance L >= 0
  --point X,Y,Z,I    add an isotropic point light of intensity I >= 0 at (X, Y, Z); only next-
                     event estimation reaches it, so unidirectional renders miss its light
  --sphere X,Y,Z,R,L replace the set-up's sphere light (radius R > 0, radiance L >= 0); it must
                     lie outside the medium box [-1, 1]^3
  --help             this text

Examples: nsp_render --setup A --spp 256 --estimators uni-nee-mis_balance
          nsp_render --spectral both --estimators all --spp 4 --res 64x64
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
        } else if (flag == "--max-depth") {
            o.estimator.max_depth = parse_number<int>(flag, value(), 0, 1 << 20);
        } else if (flag == "--out") {
            o.out = std::string(value());
            if (o.out.empty()) usage_error("--out needs a directory name");
        } else if (flag == "--no-exr") {
            no_value();
            o.write_exr = false;
        } else if (flag == "--list") {
            no_value();
            o.list = true;
        } else if (flag == "--setup") {
            const std::string_view v = value();
            if (v == "A" || v == "a") o.setups = {LightSetup::A};
            else if (v == "B" || v == "b") o.setups = {LightSetup::B};
            else if (v == "both") o.setups = {LightSetup::A, LightSetup::B};
            else usage_error("--setup: '" + std::string(v) + "' is not one of A, B, both");
        } else if (flag == "--spectral") {
            const std::string_view v = value();
            if (v == nsp::Mono::name) o.modes = {nsp::Mono::name};
            else if (v == nsp::Rgb::name) o.modes = {nsp::Rgb::name};
            else if (v == "both") o.modes = {nsp::Mono::name, nsp::Rgb::name};
            else usage_error("--spectral: '" + std::string(v) + "' is not one of mono, rgb, both");
        } else if (flag == "--estimators") {
            o.estimators.clear();
            for (const auto t : split(value(), ','))
                if (!t.empty()) o.estimators.emplace_back(t);
            if (o.estimators.empty()) usage_error("--estimators needs at least one name");
        } else if (flag == "--env") {
            o.env = parse_number<float>(flag, value(), 0.f, 1e30f);
        } else if (flag == "--point") {
            o.point = parse_floats<4>(flag, value());
            if ((*o.point)[3] < 0.f) usage_error("--point: the intensity must be >= 0");
        } else if (flag == "--sphere") {
            o.sphere = parse_floats<5>(flag, value());
            if (!((*o.sphere)[3] > 0.f)) usage_error("--sphere: the radius must be > 0");
            if ((*o.sphere)[4] < 0.f) usage_error("--sphere: the radiance must be >= 0");
        } else {
            usage_error("unknown flag '" + std::string(args[i]) + "'");
        }
    }
    return o;
}

// ---------------------------------------------------------------------------------------------
// Selecting combinations (run-time names, compile-time types)

/// The '_'-separated fields of a combination's name.
template <class C>
std::vector<std::string> fields_of() {
    const std::string name = C::name();
    std::vector<std::string> f;
    for (const auto p : split(name, '_')) f.emplace_back(p);
    return f;
}

/// True when every field of `token` is a field of the combination C.
template <class C>
bool matches(std::string_view token) {
    if (token == "all") return true;
    const auto fields = fields_of<C>();
    for (const auto t : split(token, '_'))
        if (std::find(fields.begin(), fields.end(), t) == fields.end()) return false;
    return true;
}

/// Indices into AllCombinations of the renders to run for spectral mode `mode`, in list order.
std::vector<std::size_t> select(const Options& o, std::string_view mode) {
    std::vector<std::string> tokens = o.estimators;
    if (tokens.empty()) tokens.emplace_back(kDefaultEstimators);
    std::vector<std::size_t> chosen;
    std::vector<bool> used(tokens.size(), false);
    std::size_t index = 0;
    tl::for_each<AllCombinations>([&]<class C>(std::type_identity<C>) {
        if (mode == C::Spectral::name) {
            bool any = false;
            for (std::size_t t = 0; t < tokens.size(); ++t)
                if (matches<C>(tokens[t])) used[t] = any = true;
            if (any) chosen.push_back(index);
        }
        ++index;
    });
    for (std::size_t t = 0; t < tokens.size(); ++t)
        if (!used[t]) usage_error("--estimators: '" + tokens[t] + "' matches no estimator (see --list)");
    return chosen;
}

// ---------------------------------------------------------------------------------------------
// Rendering

/// CPU time of the calling thread (POSIX): unlike wall time, not inflated by other processes.
double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// What one render measured.
struct RenderStats {
    std::string name;
    double wall_seconds = 0.0;
    double cpu_seconds = 0.0;      ///< summed over worker threads
    std::uint64_t samples = 0;
    std::uint64_t lookups = 0;     ///< density lookups, summed over threads
    std::uint64_t aborted = 0, nonfinite = 0;
    std::uint64_t nonzero = 0;     ///< samples with a nonzero estimate
    double variance = 0.0;         ///< mean over pixels of the per-pixel sample variance
    double mean = 0.0;             ///< image mean of the channel mean (an unbiasedness check)

    double lookups_per_sample() const { return double(lookups) / double(samples); }
    double ltuv() const { return lookups_per_sample() * variance; }
    double time_variance() const { return cpu_seconds / double(samples) * variance; }
};

/// Per-thread accumulators, summed after the join.
struct ThreadTotals {
    nsp::LookupCount counter;
    std::uint64_t aborted = 0, nonfinite = 0, nonzero = 0;
    double variance_sum = 0.0, mean_sum = 0.0, cpu_seconds = 0.0;
};

/// Prints "label  NN%" in place on a terminal; nothing elsewhere (the caller prints a line per render).
class Progress {
public:
    Progress(std::string label, bool tty) : label_(std::move(label)), tty_(tty) {}

    /// Called by any worker after a row; prints at most every 0.25 s.
    void update(int done, int total) {
        if (!tty_ || !mutex_.try_lock()) return;
        const auto now = std::chrono::steady_clock::now();
        if (now - last_ > std::chrono::milliseconds(250)) {
            last_ = now;
            std::fprintf(stderr, "\r  %-60s %3d%%", label_.c_str(), int(100.0 * done / total));
            std::fflush(stderr);
        }
        mutex_.unlock();
    }
    /// Replaces the progress line with a summary line.
    void finish(const std::string& summary) {
        if (tty_) std::fprintf(stderr, "\r%-80s\r", "");
        std::fprintf(stderr, "  %s\n", summary.c_str());
    }

private:
    std::string label_;
    bool tty_;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

/// Renders `scene` with combination C's estimator: per pixel, `o.spp` jittered camera rays; one
/// Pcg32 stream per pixel (so images do not depend on the thread count); rows handed out to
/// threads through an atomic counter. Writes the mean radiance into `rgb`.
template <class C>
RenderStats render(const typename C::Scene& scene, const Options& o, const std::string& label,
                   std::vector<float>& rgb) {
    using S = typename C::Spectral;
    const typename C::Estimator estimator{o.estimator};
    const int w = o.width, h = o.height;
    const float aspect = float(w) / float(h);
    rgb.assign(std::size_t(w) * std::size_t(h) * 3u, 0.f);

    std::atomic<int> next_row{0}, rows_done{0};
    std::vector<ThreadTotals> totals(std::size_t(o.threads));
    Progress progress(label, isatty(STDERR_FILENO) != 0);

    auto work = [&](ThreadTotals& out) {
        ThreadTotals t;  // local: the counters of different threads must not share a cache line
        const double cpu0 = thread_cpu_seconds();
        const typename S::Wavelengths lambda{};
        for (int y; (y = next_row.fetch_add(1)) < h;) {
            for (int x = 0; x < w; ++x) {
                const std::size_t pixel = std::size_t(y) * std::size_t(w) + std::size_t(x);
                nsp::Pcg32 rng(o.seed, pixel);
                typename S::Spectrum sum = S::Spectrum::Zero();
                double mean = 0.0, m2 = 0.0;  // Welford on the channel mean
                for (int k = 1; k <= o.spp; ++k) {
                    const float u = (float(x) + rng.uniform()) / float(w);
                    const float v = 1.f - (float(y) + rng.uniform()) / float(h);
                    const auto r = estimator.radiance(scene, camera_ray(u, v, aspect), lambda, rng, t.counter);
                    if (r.status == nsp::Status::Aborted) ++t.aborted;
                    else if (r.status == nsp::Status::NonFinite) ++t.nonfinite;
                    sum += r.value;
                    const double s = double(r.value.mean());
                    if (s != 0.0) ++t.nonzero;
                    const double d = s - mean;
                    mean += d / k;
                    m2 += d * (s - mean);
                }
                t.variance_sum += m2 / double(o.spp - 1);
                t.mean_sum += mean;
                const typename S::Spectrum avg = sum / float(o.spp);
                for (int c = 0; c < 3; ++c) rgb[3 * pixel + std::size_t(c)] = avg[S::channels == 3 ? c : 0];
            }
            progress.update(rows_done.fetch_add(1) + 1, h);
        }
        t.cpu_seconds = thread_cpu_seconds() - cpu0;
        out = t;
    };

    const auto t0 = std::chrono::steady_clock::now();
    {
        std::vector<std::jthread> pool;
        for (int i = 1; i < o.threads; ++i) pool.emplace_back(work, std::ref(totals[std::size_t(i)]));
        work(totals[0]);
    }
    RenderStats st;
    st.name = C::name();
    st.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    st.samples = std::uint64_t(w) * std::uint64_t(h) * std::uint64_t(o.spp);
    double variance_sum = 0.0, mean_sum = 0.0;
    for (const ThreadTotals& t : totals) {
        st.lookups += t.counter.count();
        st.aborted += t.aborted;
        st.nonfinite += t.nonfinite;
        st.nonzero += t.nonzero;
        st.cpu_seconds += t.cpu_seconds;
        variance_sum += t.variance_sum;
        mean_sum += t.mean_sum;
    }
    const double pixels = double(w) * double(h);
    st.variance = variance_sum / pixels;
    st.mean = mean_sum / pixels;
    std::ostringstream os;
    os.precision(3);
    os << label << ": " << std::fixed << st.wall_seconds << " s";
    progress.finish(os.str());
    return st;
}

/// The scene of combination C in `setup`, with the lights the flags add or replace.
template <class C>
typename C::Scene make_scene(LightSetup setup, const Options& o) {
    using S = typename C::Spectral;
    using Spec = typename S::Spectrum;
    nsp::Lights<S> lights = default_lights<S>(setup);
    if (o.sphere) {
        const auto& s = *o.sphere;
        lights.set(nsp::SphereLight<S>{nsp::Vec3(s[0], s[1], s[2]), s[3], Spec::Constant(s[4])});
    }
    if (o.point) {
        const auto& p = *o.point;
        lights.set(nsp::PointLight<S>{nsp::Vec3(p[0], p[1], p[2]), Spec::Constant(p[3])});
    }
    if (o.env) lights.set(nsp::EnvironmentLight<S>{Spec::Constant(*o.env)});
    auto medium = C::MediumKind::template make<S>();
    auto majorant = C::MajorantKind::make(medium);
    return typename C::Scene(std::move(medium), std::move(majorant), nsp::HenyeyGreensteinPhase(kPhaseG),
                             std::move(lights));
}

// ---------------------------------------------------------------------------------------------
// The table

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
}

const RenderStats* find_row(const std::vector<RenderStats>& rows, std::string_view name) {
    for (const RenderStats& r : rows)
        if (r.name == name) return &r;
    return nullptr;
}

void print_table(LightSetup setup, std::string_view mode, const Options& o, const std::vector<RenderStats>& rows) {
    if (rows.empty()) return;
    // Best row: the lowest LTUV among rows that measured any variance (a strategy that never
    // found the light has variance 0 and an LTUV that means nothing).
    double best = std::numeric_limits<double>::infinity();
    for (const RenderStats& r : rows)
        if (r.ltuv() > 0.0) best = std::min(best, r.ltuv());
    std::printf("\nSet-up %s (%.*s, %dx%d, %d spp, %d threads)\n", name(setup), int(mode.size()), mode.data(),
                o.width, o.height, o.spp, o.threads);
    std::printf("%-36s %5s %8s %11s %11s %11s %11s %9s %9s\n", "estimator", "spp", "seconds", "lookups/spl",
                "var/spl", "LTUV", "cpu-s*var", "LTUV/best", "mean");
    std::uint64_t aborted = 0, nonfinite = 0;
    for (const RenderStats& r : rows) {
        const bool measured = r.ltuv() > 0.0 && std::isfinite(best);
        std::printf("%-36s %5d %8.2f %11s %11s %11s %11s %9s %9s\n", r.name.c_str(), o.spp, r.wall_seconds,
                    num(r.lookups_per_sample()).c_str(), num(r.variance).c_str(), num(r.ltuv()).c_str(),
                    num(r.time_variance()).c_str(), measured ? num(r.ltuv() / best).c_str() : "n/a",
                    num(r.mean).c_str());
        aborted += r.aborted;
        nonfinite += r.nonfinite;
    }
    std::printf("var/spl: per-pixel sample variance of the %d samples of each pixel (Welford)%s, averaged over "
                "the %d pixels.\n", o.spp, mode == nsp::Rgb::name ? " of the channel mean" : "", o.width * o.height);
    std::printf("LTUV = lookups/spl x var/spl; cpu-s*var = thread CPU seconds per sample x var/spl; lower is "
                "better. mean: image mean (should agree across rows).\n");
    std::printf("paths with status Aborted: %llu, NonFinite: %llu\n", (unsigned long long)aborted,
                (unsigned long long)nonfinite);
    if (o.point)
        std::printf("note: the point light (--point) is reachable by next-event estimation only, so the "
                    "unidirectional rows leave out its light and their mean is lower\n");
    for (const RenderStats& r : rows)
        if (r.nonzero < 1000)
            std::printf("note: %s: only %llu of %llu samples were nonzero (the light is rarely found); its "
                        "variance and mean rest on those few and are themselves very noisy\n",
                        r.name.c_str(), (unsigned long long)r.nonzero, (unsigned long long)r.samples);
    // THEORY 7's claim, on the absorb-weight rows when present.
    const auto* uni = find_row(rows, "unidirectional_absorb-weight");
    const auto* nee = find_row(rows, "ratio-nee_absorb-weight");
    const auto* mis = find_row(rows, "uni-nee-mis_balance_absorb-weight");
    if (uni && nee) std::printf("ratio-nee / unidirectional LTUV: %s", num(nee->ltuv() / uni->ltuv()).c_str());
    if (uni && nee && mis)
        std::printf("; uni-nee-mis_balance / best single strategy: %s",
                    num(mis->ltuv() / std::min(uni->ltuv(), nee->ltuv())).c_str());
    if (uni && nee) std::printf(" (absorb-weight rows)\n");
    std::fflush(stdout);
}

void list_combinations() {
    std::printf("%-6s %-18s %-9s %-14s %-9s %-11s %s\n", "mode", "strategy", "heuristic", "absorption", "majorant",
                "medium", "name");
    tl::for_each<AllCombinations>([]<class C>(std::type_identity<C>) {
        std::printf("%-6s %-18s %-9s %-14s %-9s %-11s %s\n", C::Spectral::name, C::Strategy::name,
                    C::Heuristic::name, C::Absorption::name, C::MajorantKind::name, C::MediumKind::name,
                    C::name().c_str());
    });
    std::printf("%zu valid combinations (PathEstimator rejects a heuristic on a single strategy and mis::None "
                "on an MIS strategy).\n", tl::size<AllCombinations>);
}

int run(const Options& o) {
    if (o.list) {
        list_combinations();
        return 0;
    }
    if (o.write_exr) std::filesystem::create_directories(o.out);
    std::vector<std::pair<std::string_view, std::vector<std::size_t>>> plan;
    std::size_t total = 0;
    for (const auto mode : o.modes) {
        plan.emplace_back(mode, select(o, mode));
        total += plan.back().second.size() * o.setups.size();
    }
    std::fprintf(stderr, "nsp_render: %zu renders of %dx%d at %d spp on %d threads\n", total, o.width, o.height,
                 o.spp, o.threads);
    const auto t0 = std::chrono::steady_clock::now();
    std::size_t done = 0;
    for (const LightSetup setup : o.setups) {
        for (const auto& [mode, indices] : plan) {
            std::vector<RenderStats> rows;
            for (const std::size_t i : indices) {
                tl::with_index<AllCombinations>(i, [&]<class C>(std::type_identity<C>) {
                    const auto scene = make_scene<C>(setup, o);
                    std::string file = std::string(name(setup)) + "_" + C::name();
                    if constexpr (std::is_same_v<typename C::Spectral, nsp::Rgb>) file += "_rgb";
                    const std::string label = "[" + std::to_string(++done) + "/" + std::to_string(total) + "] " + file;
                    std::vector<float> rgb;
                    rows.push_back(render<C>(scene, o, label, rgb));
                    if (o.write_exr)
                        write_exr_rgb((std::filesystem::path(o.out) / (file + ".exr")).string(), o.width, o.height, rgb);
                });
            }
            print_table(setup, mode, o, rows);
        }
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("\ntotal wall time: %.1f s%s\n", secs,
                o.write_exr ? (", images in " + o.out + "/").c_str() : "");
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
