// examples/render_job.hpp: what nsp_render asks of one render and what it gets back.
//
// The driver (render.cpp) plans renders by name; `render_combination<S>` turns the index of a
// combination of spectral mode S (combinations.hpp) into its types once and runs a monomorphic
// render loop (render_job_impl.hpp). Its instantiations live in one translation unit per mode
// (render_mono.cpp, render_rgb.cpp, render_hero.cpp) so that they compile in parallel.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nsp/nsp.hpp>

#include "scene_choice.hpp"

namespace nsp_examples {

/// Lights the command line adds to (or replaces in) a set-up.
struct LightOverrides {
    std::optional<float> env;                    ///< constant environment radiance
    std::optional<std::array<float, 4>> point;   ///< x, y, z, intensity
    std::optional<std::array<float, 5>> sphere;  ///< x, y, z, radius, radiance
};

/// How a spectral estimator picks a path's sampling channel (THEORY 5.3).
enum class SelectionRule {
    Uniform,    ///< q_c = 1 / C
    Luminance,  ///< q_c proportional to 0.5 / C + 0.5 y_c / sum_c y_c (Rec. 709 weights; hero: CIE y-bar)
};

/// Everything one render needs besides the combination.
struct RenderRequest {
    SceneChoice scene;
    LightOverrides lights;
    SelectionRule selection = SelectionRule::Uniform;  ///< ignored by combinations without uses_selection
    MajorantSettings majorant;  ///< grid resolution and the non-bounding majorants' scale
    int width = 0, height = 0, spp = 0, threads = 1;
    std::uint64_t seed = 1;
    nsp::EstimatorOptions estimator;
    std::string label;  ///< for the line shown in place while it renders (on a terminal)
    bool pixel_stats = false;  ///< also return every pixel's mean and sample variance (RenderStats)
    /// Learn the NEE count per tile (combinations with learns_nee_count only): the first
    /// pilot_spp(spp) samples of every pixel at pilot_count (or above: scout) with an nsp::NeeCountLearner per
    /// half of each tile_size^2 tile, the rest at the tile's chosen count (its own where its pilot shows it
    /// pays, else the image's where its pilot predicts that no worse than count 1). Every sample,
    /// the pilot's too, is in the image and the stats (weighed as weigh_pilot says).
    bool learn_nee_counts = false;
    int tile_size = 16;
    /// The pilot's samples per pixel: spp / 32, at least 2 (a pixel's sample variance needs two)
    /// and at most 16 (a 16x16 tile then learns from 512 to 4096 samples; the pilot costs 1/32 of
    /// the render at full NEE cost).
    static int pilot_spp(int spp) { return nsp::TileCounts::pilot_spp(spp); }
    /// The pilot's NEE and emission segment count (nsp::NeeCountLearner::pilot_counts): below 1
    /// the pilot costs less and still predicts every candidate without bias (--pilot-count; 1/4
    /// by default, with weigh_pilot: docs/counts.md, "A cheaper pilot").
    float pilot_count = 0.25f;
    /// A pixel's pilot samples weigh in its estimate by the variance its tile's other half
    /// predicts (nsp::TileCounts::pilot_weight; --pilot-weight variance), or as many samples
    /// (false; --pilot-weight equal).
    bool weigh_pilot = true;
    /// The learner's cost: density lookups, what the tables' LTUV counts (nsp::CostModel with
    /// per_lookup 1, per_sample 1/64 so that a tile without lookups still has a cost, nothing for
    /// DDA steps or technique runs; --count-cost lookups), or nsp's default model (false;
    /// --count-cost model).
    bool lookup_costs = true;
    /// Before the pilot, a scout (nsp::TileCounts::add_scout: 2 samples of one pixel in 16, not
    /// in the image) raises the pilot's counts from pilot_count to those it predicts best at or
    /// above it (--scout on), or the pilot runs at pilot_count (false; --scout off).
    bool scout = true;
};

/// What one render measured. The estimates of each sample are taken as linear RGB (mono: the value
/// in all three; hero: converted to linear sRGB via XYZ) before any statistic is formed.
struct RenderStats {
    double wall_seconds = 0.0;
    double cpu_seconds = 0.0;             ///< summed over worker threads
    std::uint64_t samples = 0;
    std::size_t pixels = 0;               ///< width x height
    std::uint64_t lookups = 0;            ///< density lookups, summed over threads
    std::uint64_t steps = 0;              ///< DDA steps of grid majorants, summed over threads
    std::uint64_t aborted = 0, nonfinite = 0, rejected = 0;  ///< paths by nsp::Status
    std::uint64_t nonzero = 0;            ///< samples with a nonzero estimate
    double variance_of_mean = 0.0;             ///< mean over pixels of the sample variance of the channel mean
    std::array<double, 3> channel_variance{};  ///< per channel: mean over pixels of its sample variance
    std::array<double, 3> mean{};              ///< image mean per channel (an unbiasedness check)
    /// Only with RenderRequest::pixel_stats: per pixel and channel (interleaved RGB, row-major),
    /// the mean of the spp samples and their sample variance (per sample, not of the mean).
    std::vector<double> pixel_mean, pixel_variance;
    /// With RenderRequest::learn_nee_counts: the NEE count chosen for each tile (row-major tiles),
    /// and on an emissive medium the emission segment count (empty otherwise).
    std::vector<float> nee_counts, segment_counts;
    float pilot_count = 1.f;  ///< the pilot's NEE count (after the scout, where one ran)

    /// The mean over the 3 channels of channel_variance.
    double variance_per_channel() const {
        return (channel_variance[0] + channel_variance[1] + channel_variance[2]) / 3.0;
    }
    double lookups_per_sample() const { return double(lookups) / double(samples); }
    double steps_per_sample() const { return double(steps) / double(samples); }
    double cpu_seconds_per_sample() const { return cpu_seconds / double(samples); }
};

/// Renders combination `index` of CombinationsOf<S> (an index the driver got by enumerating that
/// list) and writes the per-pixel mean as interleaved linear RGB into `rgb`. Throws
/// nsp::InvalidArgument if the scene cannot be built (e.g. a --sphere inside the medium).
template <nsp::SpectralMode S>
RenderStats render_combination(std::size_t index, const RenderRequest& request, std::vector<float>& rgb);

extern template RenderStats render_combination<nsp::Mono>(std::size_t, const RenderRequest&, std::vector<float>&);
extern template RenderStats render_combination<nsp::Rgb>(std::size_t, const RenderRequest&, std::vector<float>&);
extern template RenderStats render_combination<Hero4>(std::size_t, const RenderRequest&, std::vector<float>&);

/// render_combination in the spectral mode named `mode` (mono, rgb or hero).
inline RenderStats render_in_mode(std::string_view mode, std::size_t index, const RenderRequest& rq,
                                  std::vector<float>& rgb) {
    if (mode == nsp::Mono::name) return render_combination<nsp::Mono>(index, rq, rgb);
    if (mode == nsp::Rgb::name) return render_combination<nsp::Rgb>(index, rq, rgb);
    return render_combination<Hero4>(index, rq, rgb);
}

}  // namespace nsp_examples
