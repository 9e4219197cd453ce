// nsp/color.hpp: from hero-wavelength estimates to CIE XYZ and linear sRGB.
//
// The observer is the CIE 1931 2-degree standard observer in the analytic multi-lobe Gaussian fit
// of Wyman, Sloan and Shirley ("Simple Analytic Approximations to the CIE XYZ Color Matching
// Functions", JCGT 2(2), 2013, eq. 2): no table is shipped. The fit is within a few percent of
// the tabulated functions; nsp's tests integrate against the fit itself, so it is the reference.
// XYZ is normalised so that a spectrum equal to 1 at every wavelength has Y = 1.
#pragma once

#include <cmath>

#include <Eigen/Core>

#include "spectrum.hpp"

namespace nsp {

namespace detail {
/// The piecewise Gaussian lobe of the fit: exp(-(l - mu)^2 / (2 s^2)), s = s1 left of mu, s2 right.
inline double cie_lobe(double l, double mu, double s1, double s2) noexcept {
    const double t = (l - mu) / (l < mu ? s1 : s2);
    return std::exp(-0.5 * t * t);
}
}  // namespace detail

/// The CIE 1931 colour matching functions (x-bar, y-bar, z-bar) at wavelength `nm` (fit, see above).
inline Eigen::Array3d cie_xyz_bar(double nm) noexcept {
    using detail::cie_lobe;
    const double x = 1.056 * cie_lobe(nm, 599.8, 37.9, 31.0) + 0.362 * cie_lobe(nm, 442.0, 16.0, 26.7) -
                     0.065 * cie_lobe(nm, 501.1, 20.4, 26.2);
    const double y = 0.821 * cie_lobe(nm, 568.8, 46.9, 40.5) + 0.286 * cie_lobe(nm, 530.9, 16.3, 31.1);
    const double z = 1.217 * cie_lobe(nm, 437.0, 11.8, 36.0) + 0.681 * cie_lobe(nm, 459.0, 26.0, 13.8);
    return {x, y, z};
}

/// int y-bar over [kLambdaMin, kLambdaMax] (Simpson's rule on 1 nm steps, computed once).
inline double cie_y_integral() noexcept {
    static const double value = [] {
        const int n = int(kLambdaMax - kLambdaMin);  // 470 intervals of 1 nm (even)
        double s = 0.0;
        for (int i = 0; i <= n; ++i) {
            const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
            s += w * cie_xyz_bar(double(kLambdaMin) + i)[1];
        }
        return s / 3.0;
    }();
    return value;
}

/// The XYZ estimate of one hero path: its N channel values L_i at wavelengths nm_i, each drawn
/// uniformly over the range, give XYZ = (1/N) sum_i L_i xyz_bar(nm_i) / (pdf * int y-bar).
template <int N>
Eigen::Array3d hero_to_xyz(const Eigen::Array<float, N, 1>& L, const HeroWavelengths<N>& lambda) noexcept {
    Eigen::Array3d xyz = Eigen::Array3d::Zero();
    for (int i = 0; i < N; ++i) xyz += double(L[i]) * cie_xyz_bar(double(lambda.nm[std::size_t(i)]));
    return xyz / (double(N) * double(HeroWavelengths<N>::pdf()) * cie_y_integral());
}

/// Linear sRGB (D65 white, Rec. 709 primaries) from CIE XYZ.
inline Eigen::Array3d xyz_to_linear_srgb(const Eigen::Array3d& xyz) noexcept {
    return {3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2],
            -0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2],
            0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2]};
}

}  // namespace nsp
