// A host renderer's first use of nsp: ratio-tracking transmittance through a homogeneous box,
// checked against the closed form exp(-mu_t d), then one hero-wavelength sample of a chromatic
// box with spectral MIS; then every code snippet of nsp's README.md (readme_snippets.hpp, generated
// by CMakeLists.txt from the blocks marked <!-- consumer-snippet: NAME -->), run and checked.
// Exits non-zero if the package is unusable or a README snippet is wrong.
#include <cmath>
#include <cstdio>
#include <cstring>

#include <nsp/nsp.hpp>

#include "readme_snippets.hpp"

namespace {

/// Runs every README snippet: each must return a finite value, and the ones named here must
/// return what the README says they compute. Returns the number of failures.
int check_readme_snippets() {
    int failures = 0;
    for (const readme::Snippet& s : readme::kSnippets) {
        const double v = s.run();
        bool ok = std::isfinite(v);
        const char* expected = "a finite value";
        if (std::strcmp(s.name, "transmittance") == 0) {
            // README: 10000 ratio-tracking estimates through mu_t = 1 over length 1 under a majorant
            // of 2; each has standard deviation ~0.30 (E[0.25^k] - e^-2 with k ~ Poisson(2)), so the
            // mean's SE is ~0.003 and 0.02 is > 6 SE.
            ok = ok && std::abs(v - std::exp(-1.0)) < 0.02;
            expected = "exp(-1) = 0.3679 within 0.02";
        } else if (std::strcmp(s.name, "estimator") == 0) {
            // README: the mean radiance of 1024 samples along a camera ray through a lit grey
            // medium: positive (the light reaches the ray by single scattering already).
            ok = ok && v > 0.0;
            expected = "a finite value > 0";
        } else if (std::strcmp(s.name, "surfaces") == 0) {
            // README: fog over a Lambertian floor (albedo 0.7) under a sky of radiance 1, seen from
            // inside the fog: nothing emits but the sky and nothing reflects more than it receives,
            // so 0 < L < 1; the fog and floor send back well over 0.05 (the mean of 1024 samples
            // has a standard error near 0.01).
            ok = ok && v > 0.05 && v < 1.0;
            expected = "a value in (0.05, 1)";
        }
        std::printf("consumer: README snippet '%s' (README.md line %d) returned %.6g: %s\n", s.name, s.line, v,
                    ok ? "ok" : "FAILED");
        if (!ok) {
            std::printf("consumer: README snippet '%s' should return %s\n", s.name, expected);
            ++failures;
        }
    }
    return failures;
}

}  // namespace

int main() {
    using S = nsp::Mono;
    const nsp::HomogeneousMedium<S> medium(nsp::Box{nsp::Vec3(0.f), nsp::Vec3(1.f)},
                                           S::Spectrum::Constant(0.5f), S::Spectrum::Constant(0.5f));
    const nsp::GlobalMajorant<nsp::HomogeneousMedium<S>> majorant(medium, 2.f);  // loose: real nulls
    nsp::Pcg32 rng(42);
    nsp::NoLookupCount counter;
    const nsp::Ray ray{nsp::Vec3(0.5f, 0.5f, -1.f), nsp::Vec3(0.f, 0.f, 1.f)};
    const int n = 100000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
        sum += nsp::transmittance_ratio(medium, majorant, ray, 10.f, {}, rng, counter).value[0];
    const double estimate = sum / n, exact = std::exp(-1.0);
    std::printf("consumer: T = %.4f, exact %.4f\n", estimate, exact);
    // Ratio tracking here has per-sample standard deviation < 0.5, so the SE is < 0.0016; 0.01 is > 6 SE.
    if (!(std::abs(estimate - exact) < 0.01)) return 1;

    // A chromatic medium in Hero mode with the per-channel estimator (docs/integration.md, "Chromatic media").
    using H = nsp::Hero<4>;
    using HMedium = nsp::HomogeneousMedium<H>;
    const HMedium hmedium(nsp::Box{nsp::Vec3(0.f), nsp::Vec3(1.f)},
                          nsp::TabulatedSpectrum::from_points({450.f, 650.f}, {0.4f, 0.1f}),
                          nsp::TabulatedSpectrum::constant(2.f));
    nsp::Lights<H> hlights;
    hlights.set(nsp::EnvironmentLight<H>{nsp::TabulatedSpectrum::constant(1.f)});
    const nsp::Scene<HMedium, nsp::ChannelMajorant<HMedium>, nsp::IsotropicPhase> hscene(
        hmedium, nsp::ChannelMajorant<HMedium>(hmedium), {}, hlights);
    const nsp::SpectralPathEstimator<nsp::channels::SpectralMis, nsp::strategy::NullScatteringMis, nsp::mis::Balance> sest;
    const auto lambda = H::Wavelengths::sample(rng.uniform());
    const auto lh = sest.radiance(hscene, ray, lambda, rng, counter);
    const Eigen::Array3d rgb = nsp::xyz_to_linear_srgb(nsp::hero_to_xyz<4>(lh.value, lambda));
    std::printf("consumer: one hero sample, linear sRGB %.3f %.3f %.3f\n", rgb[0], rgb[1], rgb[2]);
    if (!(rgb.allFinite() && lh.status == nsp::Status::Ok)) return 1;

    return check_readme_snippets() == 0 ? 0 : 1;
}
