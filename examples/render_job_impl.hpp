// examples/render_job_impl.hpp: the render loop of nsp_render (see render_job.hpp), included only
// by the per-mode translation units that instantiate render_combination<S>.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include <unistd.h>

#include <Eigen/Core>

#include <nsp/nsp.hpp>

#include "combinations.hpp"
#include "default_scene.hpp"
#include "render_job.hpp"
#include "tile_learning.hpp"
#include "type_list.hpp"

namespace nsp_examples {

namespace detail {

/// CPU time of the calling thread (POSIX): unlike wall time, not inflated by other processes.
inline double thread_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// Welford's running mean and sum of squared deviations of one quantity.
struct Welford {
    double mean = 0.0, m2 = 0.0;
    void add(double x, int k) {  // k: 1-based count including x
        const double d = x - mean;
        mean += d / k;
        m2 += d * (x - mean);
    }
};

/// The mean a m_p + (1 - a) m_r of two independent sample means (n_p and n_r samples, n_p, n_r
/// >= 2) and its variance, times n_p + n_r (per sample, comparable to an unweighted pixel's),
/// each side's variance from its own samples (unbiased; with a = n_p / (n_p + n_r) it is the
/// plain mean's).
inline std::pair<double, double> weighted_mean(const Welford& p, int np, const Welford& r, int nr, double a) {
    const double var = a * a * p.m2 / double(np - 1) / double(np) +
                       (1.0 - a) * (1.0 - a) * r.m2 / double(nr - 1) / double(nr);
    return {a * p.mean + (1.0 - a) * r.mean, var * double(np + nr)};
}

/// Per-thread accumulators, summed after the join.
struct ThreadTotals {
    nsp::LookupCount counter;
    std::uint64_t aborted = 0, nonfinite = 0, rejected = 0, nonzero = 0;
    double variance_of_mean_sum = 0.0, cpu_seconds = 0.0;
    std::array<double, 3> variance_sum{}, mean_sum{};
};

/// Prints "label  NN%" in place on a terminal while a render runs; nothing elsewhere (the driver
/// prints a line per finished render, progress.hpp).
class InPlaceProgress {
public:
    InPlaceProgress(std::string label, bool tty) : label_(std::move(label)), tty_(tty) {}

    /// Called by any worker after a row; prints at most every 0.25 s.
    void update(int done, int total) {
        if (!tty_ || !mutex_.try_lock()) return;
        const auto now = std::chrono::steady_clock::now();
        if (now - last_ > std::chrono::milliseconds(250)) {
            last_ = now;
            std::fprintf(stderr, "\r  %-70s %3d%%", label_.c_str(), int(100.0 * done / total));
            std::fflush(stderr);
        }
        mutex_.unlock();
    }
    /// Clears the line.
    void finish() {
        if (tty_) std::fprintf(stderr, "\r%-90s\r", "");
    }

private:
    std::string label_;
    bool tty_;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

/// The luminance-based channel selection of the chromatic tables: q_c proportional to
/// 0.5 / C + 0.5 y_c / sum_c y_c, with y the Rec. 709 luminance weights in Rgb and the CIE y-bar
/// of each of the path's wavelengths in Hero mode. The uniform half keeps every q_c >= 0.5 / C.
template <nsp::SpectralMode S>
nsp::ChannelSelection<S> luminance_selection(const typename S::Wavelengths& lambda) {
    using Spectrum = typename S::Spectrum;
    Spectrum y;
    if constexpr (nsp::is_hero_v<S>) {
        for (int i = 0; i < S::channels; ++i) y[i] = float(nsp::cie_xyz_bar(double(lambda.nm[std::size_t(i)]))[1]);
    } else if constexpr (S::channels == 3) {
        (void)lambda;
        y = Spectrum(0.2126f, 0.7152f, 0.0722f);
    } else {
        (void)lambda;
        y = Spectrum::Ones();
    }
    Spectrum w = Spectrum::Constant(0.5f / float(S::channels));
    if (const float sum = y.sum(); sum > 0.f) w += 0.5f * y / sum;
    return nsp::ChannelSelection<S>(w);
}

/// A radiance estimate of mode S as linear RGB: Mono in all three channels, Rgb as it is, Hero
/// through CIE XYZ to linear sRGB (color.hpp).
template <nsp::SpectralMode S>
Eigen::Array3d to_linear_rgb(const typename S::Spectrum& L, const typename S::Wavelengths& lambda) {
    if constexpr (nsp::is_hero_v<S>) return nsp::xyz_to_linear_srgb(nsp::hero_to_xyz<S::channels>(L, lambda));
    else if constexpr (S::channels == 3) return L.template cast<double>();
    else return Eigen::Array3d::Constant(double(L[0]));
}

/// The scene of combination C in `choice`, with the lights the flags add or replace and the
/// majorant built with `settings`.
template <class C>
typename C::Scene make_scene(const SceneChoice& choice, const LightOverrides& o, const MajorantSettings& settings) {
    using S = typename C::Spectral;
    nsp::Lights<S> lights = scene_lights<S>(choice);
    if (o.sphere) {
        const auto& s = *o.sphere;
        lights.set(nsp::SphereLight<S>{nsp::Vec3(s[0], s[1], s[2]), s[3], nsp::constant_coefficient<S>(s[4])});
    }
    if (o.point) {
        const auto& p = *o.point;
        lights.set(nsp::PointLight<S>{nsp::Vec3(p[0], p[1], p[2]), nsp::constant_coefficient<S>(p[3])});
    }
    if (o.env) lights.set(nsp::EnvironmentLight<S>{nsp::constant_coefficient<S>(*o.env)});
    auto medium = C::MediumKind::template make<S>(choice);
    auto majorant = C::MajorantKind::make(medium, settings);
    return typename C::Scene(std::move(medium), std::move(majorant), nsp::HenyeyGreensteinPhase(phase_g(choice.kind)),
                             std::move(lights));
}

/// One pixel's running statistics and random stream (kept across the two passes of a render with
/// learned NEE counts).
struct PixelState {
    nsp::Pcg32 rng;
    std::array<Welford, 3> channel{};
    Welford channel_mean{};
    Eigen::Array3d sum = Eigen::Array3d::Zero();
    int k = 0;  ///< samples so far (since the pilot, once end_pilot ran)
    /// The pilot's statistics (learned rows), kept apart from the rest's by end_pilot().
    std::array<Welford, 3> pilot_channel{};
    Welford pilot_channel_mean{};
    int pilot_k = 0;
    void end_pilot() {
        pilot_channel = channel;
        pilot_channel_mean = channel_mean;
        pilot_k = k;
        channel = {};
        channel_mean = {};
        sum = Eigen::Array3d::Zero();
        k = 0;
    }
    /// Folds the pilot's statistics back into the running ones (the pairwise update of Welford
    /// sums: Chan, Golub and LeVeque).
    void merge_pilot() {
        const int n = pilot_k + k;
        if (pilot_k == 0 || n == 0) return;
        const auto merged = [&](const Welford& p, const Welford& r) {
            const double d = r.mean - p.mean;
            return Welford{p.mean + d * double(k) / double(n), p.m2 + r.m2 + d * d * double(pilot_k) * double(k) / double(n)};
        };
        for (int i = 0; i < 3; ++i) {
            channel[std::size_t(i)] = merged(pilot_channel[std::size_t(i)], channel[std::size_t(i)]);
            sum[i] = channel[std::size_t(i)].mean * double(n);
        }
        channel_mean = merged(pilot_channel_mean, channel_mean);
        k = n;
        pilot_k = 0;
    }
};

/// Renders `scene` with combination C's estimator: per pixel, `spp` jittered camera rays (and in
/// Hero mode a wavelength draw per path); one Pcg32 stream per pixel (so images do not depend on
/// the thread count); rows handed out to threads through an atomic counter. Writes the mean
/// linear RGB into `rgb`. With rq.learn_nee_counts (C::learns_nee_count), a scout (rq.scout: 2
/// samples of one pixel in 16, not in the image) raises the pilot's counts from rq.pilot_count,
/// then a first pass renders each tile's pilot samples with an nsp::NeeCountLearner per half of the tile
/// as their counter, tiles handed out to threads in fixed slots (the chosen counts do not depend
/// on the thread count); a tile keeps its own counts where its pilot shows they pay, else takes
/// the image's (every tile's pilot merged) where its pilot predicts them no worse than counts 1;
/// the second pass renders the rest at each tile's counts (NEE's and, on an emissive medium, the
/// emission segment technique's), and a pixel's pilot mean weighs pilot_weight in its estimate
/// (rq.weigh_pilot) or as many samples.
template <class C>
RenderStats render(const typename C::Scene& scene, const RenderRequest& rq, std::vector<float>& rgb) {
    using S = typename C::Spectral;
    using Estimator = typename C::Estimator;
    const Estimator estimator{rq.estimator};
    const int w = rq.width, h = rq.height;
    const float aspect = float(w) / float(h);
    rgb.assign(std::size_t(w) * std::size_t(h) * 3u, 0.f);
    std::vector<double> pixel_mean, pixel_variance;  // written by pixel index: no sharing between threads
    if (rq.pixel_stats) {
        pixel_mean.assign(rgb.size(), 0.0);
        pixel_variance.assign(rgb.size(), 0.0);
    }
    // Fixed channels: one selection for the whole image; hero wavelengths: one per path.
    const nsp::ChannelSelection<S> fixed_selection =
        rq.selection == SelectionRule::Luminance ? luminance_selection<S>({}) : nsp::ChannelSelection<S>{};

    // One sample of pixel (x, y) with estimator `est` and counter `counter`; returns the
    // estimate's channel mean (what a NeeCountLearner records its contributions in).
    auto sample = [&](const auto& est, auto& counter, PixelState& px, int x, int y, ThreadTotals& t) {
        nsp::Pcg32& rng = px.rng;
        const float u = (float(x) + rng.uniform()) / float(w);
        const float v = 1.f - (float(y) + rng.uniform()) / float(h);
        typename S::Wavelengths lambda{};
        if constexpr (nsp::is_hero_v<S>) lambda = S::Wavelengths::sample(rng.uniform());
        const nsp::Ray ray = camera_ray(u, v, aspect);
        nsp::RadianceSample<S> r;
        if constexpr (!C::uses_selection) {
            r = est.radiance(scene, ray, lambda, rng, counter);
        } else if constexpr (nsp::is_hero_v<S>) {  // luminance at this path's wavelengths
            if (rq.selection == SelectionRule::Luminance)
                r = est.radiance(scene, ray, lambda, luminance_selection<S>(lambda), rng, counter);
            else
                r = est.radiance(scene, ray, lambda, fixed_selection, rng, counter);
        } else {
            r = est.radiance(scene, ray, lambda, fixed_selection, rng, counter);
        }
        if (r.status == nsp::Status::Aborted) ++t.aborted;
        else if (r.status == nsp::Status::NonFinite) ++t.nonfinite;
        else if (r.status == nsp::Status::Rejected) ++t.rejected;
        if ((r.value != 0.f).any()) ++t.nonzero;
        const Eigen::Array3d c = to_linear_rgb<S>(r.value, lambda);
        px.sum += c;
        ++px.k;
        for (int i = 0; i < 3; ++i) px.channel[std::size_t(i)].add(c[i], px.k);
        px.channel_mean.add(c.mean(), px.k);
        return double(r.value.mean());
    };
    // A learned row's pixel: its pilot mean weighs a, the rest's 1 - a (weighted_mean).
    auto finish_learned_pixel = [&](const PixelState& px, std::size_t pixel, double a, ThreadTotals& t) {
        const int np = px.pilot_k, nr = px.k;
        t.variance_of_mean_sum += weighted_mean(px.pilot_channel_mean, np, px.channel_mean, nr, a).second;
        for (int i = 0; i < 3; ++i) {
            const auto [m, var] =
                weighted_mean(px.pilot_channel[std::size_t(i)], np, px.channel[std::size_t(i)], nr, a);
            t.variance_sum[std::size_t(i)] += var;
            t.mean_sum[std::size_t(i)] += m;
            rgb[3 * pixel + std::size_t(i)] = float(m);
            if (rq.pixel_stats) {
                pixel_mean[3 * pixel + std::size_t(i)] = m;
                pixel_variance[3 * pixel + std::size_t(i)] = var;
            }
        }
    };
    auto finish_pixel = [&](const PixelState& px, std::size_t pixel, ThreadTotals& t) {
        const double n1 = double(rq.spp - 1);
        t.variance_of_mean_sum += px.channel_mean.m2 / n1;
        for (int i = 0; i < 3; ++i) {
            const Welford& ch = px.channel[std::size_t(i)];
            t.variance_sum[std::size_t(i)] += ch.m2 / n1;
            t.mean_sum[std::size_t(i)] += ch.mean;
            rgb[3 * pixel + std::size_t(i)] = float(px.sum[i] / double(rq.spp));
            if (rq.pixel_stats) {
                pixel_mean[3 * pixel + std::size_t(i)] = ch.mean;
                pixel_variance[3 * pixel + std::size_t(i)] = ch.m2 / n1;
            }
        }
    };

    std::atomic<int> next_row{0}, rows_done{0};
    std::vector<ThreadTotals> totals(std::size_t(rq.threads)), pilot_totals(std::size_t(rq.threads)),
        scout_totals(std::size_t(rq.threads));
    InPlaceProgress progress(rq.label, isatty(STDERR_FILENO) != 0);
    RenderStats st;
    const auto t0 = std::chrono::steady_clock::now();
    auto run_pool = [&](auto& work, std::vector<ThreadTotals>& out) {
        std::vector<std::jthread> pool;
        for (int i = 1; i < rq.threads; ++i) pool.emplace_back(work, std::ref(out[std::size_t(i)]));
        work(out[0]);
    };

    if constexpr (C::learns_nee_count) {
        if (rq.learn_nee_counts) {
            // The protocol of docs/integration.md (nsp::TileCounts): slot j learns tiles j, j +
            // kSlots, ... in order (threads take whole slots), so the counts do not depend on the
            // thread count; a tile keeps its own counts where its pilot shows they pay, else it
            // takes the image's where its pilot predicts them no worse than counts 1.
            nsp::TechniqueCounts floor_counts;
            floor_counts.nee = rq.pilot_count;
            floor_counts.emission_segment = C::MediumKind::emissive ? rq.pilot_count : 1.f;
            nsp::CostModel costs;
            if (rq.lookup_costs) {
                costs.per_sample = 1.0 / 64.0;
                costs.per_dda_step = costs.per_shadow_walk = costs.per_segment_walk = costs.per_light_walk = 0.0;
            }
            nsp::TileCounts plan(w, h, rq.tile_size, costs, floor_counts);
            const int pilot = RenderRequest::pilot_spp(rq.spp);
            std::vector<PixelState> px(std::size_t(w) * std::size_t(h));
            for (std::size_t p = 0; p < px.size(); ++p) px[p].rng = nsp::Pcg32(rq.seed, p);
            constexpr bool kEmissive = C::MediumKind::emissive;
            const int n_tiles = plan.tile_count();
            // Each pass's per-thread totals, timed (thread CPU time) into `list`.
            auto pool_into = [&](std::vector<ThreadTotals>& list) {
                return [&run_pool, &list](auto& work) {
                    auto timed = [&work](ThreadTotals& out) {
                        ThreadTotals t;  // local: the counters of different threads must not share a cache line
                        const double cpu0 = thread_cpu_seconds();
                        work(t);
                        t.cpu_seconds = thread_cpu_seconds() - cpu0;
                        out = t;
                    };
                    run_pool(timed, list);
                };
            };
            auto add_work = [](ThreadTotals& t, const nsp::NeeCountLearner& l) {
                t.counter.n += l.count();
                t.counter.steps += l.steps();
            };
            // Pass 0, the scout: 2 samples of one pixel in 16 at rq.pilot_count, on streams of their
            // own and not in the image (only their work is counted), raise the pilot's counts.
            if (rq.scout) {
                nsp::EstimatorOptions scout_options = rq.estimator;
                scout_options.nee_count = floor_counts.nee;
                scout_options.emission_segment_count = floor_counts.emission_segment;
                const Estimator scout_estimator{scout_options};
                const int scout_spp = nsp::TileCounts::scout_spp(rq.spp);
                scout_tiles<ThreadTotals>(
                    plan, pool_into(scout_totals),
                    [&](ThreadTotals& t, nsp::NeeCountLearner& learner, int x, int y) {
                        const std::size_t p = std::size_t(y) * std::size_t(w) + std::size_t(x);
                        PixelState state{nsp::Pcg32(rq.seed, px.size() + p)};
                        ThreadTotals discarded;
                        for (int k = 0; k < scout_spp; ++k)
                            learner.end_sample(sample(scout_estimator, learner, state, x, y, discarded));
                        t.aborted += discarded.aborted;  // a scout's failed path is reported like any other
                        t.nonfinite += discarded.nonfinite;
                        t.rejected += discarded.rejected;
                    },
                    add_work);
            }
            // Pass 1: the pilot, tile by tile, at the counts the scout raised rq.pilot_count to.
            const nsp::TechniqueCounts pilot_counts = plan.pilot_counts();
            nsp::EstimatorOptions pilot_options = rq.estimator;
            pilot_options.nee_count = pilot_counts.nee;
            pilot_options.emission_segment_count = pilot_counts.emission_segment;
            const Estimator pilot_estimator{pilot_options};
            st.nee_counts.assign(std::size_t(n_tiles), 1.f);
            st.pilot_count = pilot_counts.nee;
            if (kEmissive) st.segment_counts.assign(st.nee_counts.size(), 1.f);
            // In two halves of each tile's pixels (x + y even, odd): each half's pilot is weighted
            // by the other's predictions (TileCounts::pilot_weight).
            pilot_tiles<ThreadTotals>(
                plan, rq.weigh_pilot, pool_into(pilot_totals),
                [&](ThreadTotals& t, nsp::NeeCountLearner& learner, int x, int y) {
                    PixelState& state = px[std::size_t(y) * std::size_t(w) + std::size_t(x)];
                    for (int k = 0; k < pilot; ++k) learner.end_sample(sample(pilot_estimator, learner, state, x, y, t));
                    state.end_pilot();
                },
                add_work);
            for (int tile = 0; tile < n_tiles; ++tile) {
                const nsp::TechniqueCounts& n = plan.counts(tile);
                st.nee_counts[std::size_t(tile)] = n.nee;
                if (kEmissive) st.segment_counts[std::size_t(tile)] = n.emission_segment;
            }
            // Pass 2: the rest of each pixel's samples at its tile's counts: one estimator per
            // candidate pair (NEE x segment; the segment's at 1 only where nothing emits).
            constexpr int kC = nsp::NeeCountLearner::kCandidates, kS = kEmissive ? kC : 1;
            std::vector<Estimator> at_count;
            for (int j = 0; j < kC; ++j)
                for (int js = 0; js < kS; ++js) {
                    nsp::EstimatorOptions o = rq.estimator;
                    o.nee_count = nsp::NeeCountLearner::candidate(j);
                    o.emission_segment_count = nsp::NeeCountLearner::candidate(js);
                    at_count.emplace_back(o);
                }
            auto work = [&](ThreadTotals& out) {
                ThreadTotals t;
                const double cpu0 = thread_cpu_seconds();
                for (int y; (y = next_row.fetch_add(1)) < h;) {
                    for (int x = 0; x < w; ++x) {
                        const std::size_t pixel = std::size_t(y) * std::size_t(w) + std::size_t(x);
                        const std::size_t tile = std::size_t(plan.tile_at(x, y));
                        const int js = kEmissive ? nsp::NeeCountLearner::candidate_index(st.segment_counts[tile]) : 0;
                        const Estimator& est =
                            at_count[std::size_t(nsp::NeeCountLearner::candidate_index(st.nee_counts[tile]) * kS + js)];
                        PixelState& state = px[pixel];
                        while (state.pilot_k + state.k < rq.spp) sample(est, t.counter, state, x, y, t);
                        if (state.pilot_k >= 2 && state.k >= 2) {
                            finish_learned_pixel(state, pixel, plan.pilot_weight(x, y, state.pilot_k, rq.spp), t);
                        } else {  // fewer than 2 on one side: every sample weighs the same
                            state.merge_pilot();
                            finish_pixel(state, pixel, t);
                        }
                    }
                    progress.update(rows_done.fetch_add(1) + 1, h);
                }
                t.cpu_seconds = thread_cpu_seconds() - cpu0;
                out = t;
            };
            run_pool(work, totals);
        }
    }
    if (!rq.learn_nee_counts || !C::learns_nee_count) {
        auto work = [&](ThreadTotals& out) {
            ThreadTotals t;  // local: the counters of different threads must not share a cache line
            const double cpu0 = thread_cpu_seconds();
            for (int y; (y = next_row.fetch_add(1)) < h;) {
                for (int x = 0; x < w; ++x) {
                    const std::size_t pixel = std::size_t(y) * std::size_t(w) + std::size_t(x);
                    PixelState state{nsp::Pcg32(rq.seed, pixel)};
                    for (int k = 1; k <= rq.spp; ++k) sample(estimator, t.counter, state, x, y, t);
                    finish_pixel(state, pixel, t);
                }
                progress.update(rows_done.fetch_add(1) + 1, h);
            }
            t.cpu_seconds = thread_cpu_seconds() - cpu0;
            out = t;
        };
        run_pool(work, totals);
    }
    st.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    st.samples = std::uint64_t(w) * std::uint64_t(h) * std::uint64_t(rq.spp);
    st.pixels = std::size_t(w) * std::size_t(h);
    double var_mean = 0.0;
    std::array<double, 3> var_channel{}, mean{};
    for (const auto* list : {&totals, &pilot_totals, &scout_totals})
        for (const ThreadTotals& t : *list) {
            st.lookups += t.counter.count();
            st.steps += t.counter.steps;
            st.aborted += t.aborted;
            st.nonfinite += t.nonfinite;
            st.rejected += t.rejected;
            st.nonzero += t.nonzero;
            st.cpu_seconds += t.cpu_seconds;
            var_mean += t.variance_of_mean_sum;
            for (int i = 0; i < 3; ++i) {
                var_channel[std::size_t(i)] += t.variance_sum[std::size_t(i)];
                mean[std::size_t(i)] += t.mean_sum[std::size_t(i)];
            }
        }
    const double pixels = double(w) * double(h);
    st.variance_of_mean = var_mean / pixels;
    for (int i = 0; i < 3; ++i) {
        st.channel_variance[std::size_t(i)] = var_channel[std::size_t(i)] / pixels;
        st.mean[std::size_t(i)] = mean[std::size_t(i)] / pixels;
    }
    st.pixel_mean = std::move(pixel_mean);
    st.pixel_variance = std::move(pixel_variance);
    progress.finish();
    return st;
}

}  // namespace detail

template <nsp::SpectralMode S>
RenderStats render_combination(std::size_t index, const RenderRequest& request, std::vector<float>& rgb) {
    RenderStats stats;
    const bool found = tl::with_index<CombinationsOf<S>>(index, [&]<class C>(std::type_identity<C>) {
        const auto scene = detail::make_scene<C>(request.scene, request.lights, request.majorant);
        stats = detail::render<C>(scene, request, rgb);
    });
    if (!found) throw std::out_of_range("render_combination: no combination " + std::to_string(index));
    return stats;
}

}  // namespace nsp_examples
