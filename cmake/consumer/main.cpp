// A host renderer's first use of nsp: ratio-tracking transmittance through a homogeneous box,
// checked against the closed form exp(-mu_t d), then one hero-wavelength sample of a chromatic
// box with spectral MIS. Exits non-zero if the package is unusable.
#include <cmath>
#include <cstdio>

#include <nsp/nsp.hpp>

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
        sum += nsp::transmittance_ratio(medium, majorant, ray, 10.f, {}, rng, counter)[0];
    const double estimate = sum / n, exact = std::exp(-1.0);
    std::printf("consumer: T = %.4f, exact %.4f\n", estimate, exact);
    // Ratio tracking here has per-sample standard deviation < 0.5, so the SE is < 0.0016; 0.01 is > 6 SE.
    if (!(std::abs(estimate - exact) < 0.01)) return 1;

    // A chromatic medium in Hero mode with the per-channel estimator (README's second snippet).
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
    return rgb.allFinite() && lh.status == nsp::Status::Ok ? 0 : 1;
}
