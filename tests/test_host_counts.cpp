// tests/test_host_counts.cpp: docs/integration.md's per-tile counts host (the block marked
// consumer-header: tile_counts_host, generated into tile_counts_host.hpp) against nsp_render's
// learned rows on the same scene: a host written from the docs alone chooses the renderer's
// counts, tile for tile, and renders its image.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "render_job_impl.hpp"  // nsp_render's render loop (examples/)
#include "tile_counts_host.hpp"  // generated from docs/integration.md

using namespace nsp_examples;

namespace {

/// nsp_render's learned row of uni + NEE MIS (balance, absorption weight) under the global
/// majorant on a set-up of the cloud, grey.
using C = Combination<tl::list<nsp::Mono, Grey, GlobalMajorantPolicy<>, nsp::strategy::NullScatteringMis, nsp::mis::Balance,
                               nsp::absorption::Weight, DenseGridCloud>>;

void check_setup(LightSetup setup, int threads) {
    RenderRequest rq;
    rq.scene.kind = SceneKind::Cloud;
    rq.scene.cloud = setup;
    rq.width = 64;
    rq.height = 64;
    rq.spp = 32;
    rq.threads = threads;
    rq.seed = 7;
    rq.learn_nee_counts = true;  // the defaults: a scout, a pilot at 1/4 or above in halves, lookups as the cost
    rq.pixel_stats = true;
    const auto scene = detail::make_scene<C>(rq.scene, rq.lights, rq.majorant);
    std::vector<float> rgb;
    const RenderStats st = detail::render<C>(scene, rq, rgb);

    // The docs' host on the same scene: nsp_render's camera (jittered from the pixel's stream,
    // u then v), its seed, options and cost (lookups; 1/64 per sample).
    const float aspect = float(rq.width) / float(rq.height);
    auto camera = [&](int x, int y, nsp::Pcg32& rng) {
        const float u = (float(x) + rng.uniform()) / float(rq.width);
        const float v = 1.f - (float(y) + rng.uniform()) / float(rq.height);
        return camera_ray(u, v, aspect);
    };
    nsp::TechniqueCounts lowest;
    lowest.nee = rq.pilot_count;
    nsp::CostModel costs;
    costs.per_sample = 1.0 / 64.0;
    costs.per_dda_step = costs.per_shadow_walk = costs.per_segment_walk = costs.per_light_walk = 0.0;
    std::vector<double> image;
    const nsp::TileCounts plan = render_with_tile_counts<C::Estimator>(scene, camera, rq.width, rq.height, rq.spp,
                                                                       rq.seed, rq.estimator, lowest, costs, image);

    REQUIRE(st.nee_counts.size() == std::size_t(plan.tile_count()));
    CHECK(st.pilot_count == plan.pilot_counts().nee);
    int below_1 = 0;
    for (int t = 0; t < plan.tile_count(); ++t) {
        CAPTURE(t);
        CHECK(st.nee_counts[std::size_t(t)] == plan.counts(t).nee);
        below_1 += plan.counts(t).nee < 1.f;
    }
    // The same samples, weighted the same: each pixel's estimate to rounding (a running mean
    // against a sum over n).
    REQUIRE(image.size() * 3 == st.pixel_mean.size());
    int differ = 0;
    for (std::size_t p = 0; p < image.size(); ++p)
        differ += !(std::abs(image[p] - st.pixel_mean[3 * p]) <= 1e-9 * std::abs(image[p]) + 1e-12);
    MESSAGE("set-up " << std::string(name(setup)) << ", " << threads << " threads: pilot at NEE count " << plan.pilot_counts().nee
                      << "; " << below_1 << " of " << plan.tile_count() << " tiles below count 1");
    CHECK(differ == 0);
}

}  // namespace

TEST_CASE("docs/integration.md's counts host chooses nsp_render's counts and renders its image (set-ups A, D)") {
    // D (a sky: the pilot stays at 1/4 and tiles go below 1) on 2 threads, A (a small bright
    // light: the scout raises the pilot to 1) on 1: the renderer's counts do not depend on its
    // threads, and the docs' single-threaded host gets them exactly.
    check_setup(LightSetup::D, 2);
    check_setup(LightSetup::A, 1);
}
