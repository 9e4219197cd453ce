// tests/test_spectral_majorants.cpp: every spectral estimator stays unbiased with grid majorants
// (per channel for the policies with their own pdfs, grey for spectral tracking) and with grid
// majorants at half the bound under bound::Signed: directly transmitted light against the
// closed-form exp(-tau_c) of an exponential medium (channels 1e4 apart, one empty), and the
// furnace on a grid medium; and transmitted light through a medium made of two grids (bounded per
// channel). Fixed seeds, k = 5 standard errors estimated from the samples.
#include <string>
#include <type_traits>

#include "majorants.hpp"
#include "spectral.hpp"

namespace {

using namespace nsp_test;

constexpr double kSigmas = 5.0;
const Box kBox{Vec3(-1.f), Vec3(1.f)};

/// The grid kinds of a channel policy: per channel with its own pdfs, grey for one shared pdf.
template <ChannelPolicy CP>
using GridKindsFor = std::conditional_t<CP::own_pdfs, std::tuple<ChannelGridKind, SignedChannelGridKind>,
                                        std::tuple<GridKind, SignedGridKind>>;

template <SpectralMode S>
void check_unbiased(const RadianceStats<S>& res) {
    CHECK(res.not_ok == 0);
    for (int c = 0; c < S::channels; ++c) {
        const Stat& s = res.stat.ch[std::size_t(c)];
        CAPTURE(c); CAPTURE(s.mean); CAPTURE(s.se());
        CHECK(std::abs(s.mean) <= kSigmas * s.se() + kRoundingFloor);
    }
}

/// Runs f(scene, kind name) for medium m with every grid kind of E's channel policy.
template <class E, Medium M, class F>
void with_grid_scenes(const M& m, Lights<typename M::Spectral> lights, F&& f) {
    for_each_kind<GridKindsFor<typename E::Channels>, M>([&](auto kind) {
        using K = decltype(kind);
        using Maj = typename K::template type<M>;
        const Scene<M, Maj, HenyeyGreensteinPhase> scene(m, K::make(m), HenyeyGreensteinPhase(0.5f), lights);
        f(scene, K::name);
    });
}

template <SpectralMode S>
Lights<S> unit_environment() {
    Lights<S> l;
    l.set(EnvironmentLight<S>{constant_coefficient<S>(1.f)});
    return l;
}

TEST_CASE_TEMPLATE_DEFINE("spectral estimators with grid majorants: transmitted light equals exp(-tau_c)", E,
                          grid_transmitted) {
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    EstimatorOptions opts;
    opts.max_depth = 0;
    const E est(opts);
    auto for_mode = [&](auto tag) {
        using S = decltype(tag);
        const std::string mode = S::name;
        CAPTURE(mode);
        // Extinction per unit density 2e-4, 0 and 2: optical depths about 4e-4, 0 and 4.
        const auto sa = chroma<S>(1e-4f, 0.f, 1.f), ss = chroma<S>(1e-4f, 0.f, 1.f);
        const auto medium = make_medium<ExponentialMedium<S>>(kBox, 1.f, sa, ss);
        const Ray ray{Vec3(-3.f, 0.1f, 0.2f), glm::normalize(Vec3(1.f, 0.05f, -0.1f))};
        with_grid_scenes<E>(medium, unit_environment<S>(), [&](const auto& scene, const char* kind) {
            CAPTURE(kind);
            check_unbiased(estimate_error(est, scene, ray, 20000, 41, [&](const typename S::Wavelengths& l) {
                return typename S::Spectrum((-medium.optical_depth(ray, 0.f, kInf, l)).exp());
            }));
        });
    };
    for_mode(Rgb{});
    for_mode(Hero<4>{});
}

TEST_CASE_TEMPLATE_APPLY(grid_transmitted, AllSpectralEstimators);

TEST_CASE_TEMPLATE_DEFINE("spectral estimators with grid majorants over a medium of two grids: exp(-tau_c)", E,
                          two_grid_transmitted) {
    // support/majorants.hpp's TwoGridMedium (an ExtinctionBoundedMedium: no single density), its
    // channels' extinctions far apart in x and y; tau linear along the ray.
    CAPTURE(spectral_estimator_name<E>());
    EstimatorOptions opts;
    opts.max_depth = 0;
    const TwoGridMedium<Rgb> medium{Rgb::Spectrum(3.f, 0.5f, 0.f), Rgb::Spectrum(0.2f, 1.f, 4.f)};
    const Ray ray{Vec3(-3.f, 0.1f, 0.2f), glm::normalize(Vec3(1.f, 0.3f, -0.1f))};
    with_grid_scenes<E>(medium, unit_environment<Rgb>(), [&](const auto& scene, const char* kind) {
        CAPTURE(kind);
        check_unbiased(estimate_error(E(opts), scene, ray, 20000, 43, [&](const Rgb::Wavelengths&) {
            return Rgb::Spectrum((-medium.optical_depth(ray, kInf)).exp());
        }));
    });
}

TEST_CASE_TEMPLATE_APPLY(two_grid_transmitted, AllSpectralEstimators);

TEST_CASE_TEMPLATE_DEFINE("spectral estimators with grid majorants: the furnace gives 1 in every channel", E,
                          grid_spectral_furnace) {
    const std::string name = spectral_estimator_name<E>();
    CAPTURE(name);
    const E est;
    auto for_mode = [&](auto tag) {
        using S = decltype(tag);
        const std::string mode = S::name;
        CAPTURE(mode);
        const auto zero = constant_coefficient<S>(0.f), ss = chroma<S>(0.5f, 0.f, 1.5f);
        const auto medium = make_medium<DenseGridMedium<S>>(kBox, 1.f, zero, ss, 42);
        const Ray ray{Vec3(-3.f, 0.2f, 0.1f), glm::normalize(Vec3(1.f, -0.05f, 0.02f))};
        with_grid_scenes<E>(medium, unit_environment<S>(), [&](const auto& scene, const char* kind) {
            CAPTURE(kind);
            const auto res = estimate_error(est, scene, ray, 10000, 42, [](const typename S::Wavelengths&) {
                return S::Spectrum::Ones().eval();
            });
            check_unbiased(res);
            CHECK(res.lookups > 0);
        });
    };
    for_mode(Rgb{});
    for_mode(Hero<4>{});
}

TEST_CASE_TEMPLATE_APPLY(grid_spectral_furnace, AllSpectralEstimators);

}  // namespace
