// nsp/media/blackbody.hpp: emission from a temperature grid (THEORY 5.7): Planck's law at each
// point's temperature, the emission field of a flame or of hot smoke, for Emissive.
//
// L_e(p, lambda) = radiance_scale * B(lambda, T(p)), T(p) = temperature_scale * field.value(p) in
// kelvin (a trilinear temperature, then Planck's law, as pbrt-v4's grid media do), B in
// W sr^-1 m^-2 nm^-1. With `normalize`, each temperature's spectrum is divided by its peak
// B(lambda_max(T), T) (Wien's displacement law), the convention of pbrt-v4, so that
// radiance_scale alone sets the brightness and temperature only the colour.
//
// Per spectral mode: Hero<N> evaluates Planck's law at the path's wavelengths (exact); Rgb gives
// each temperature's linear sRGB (XYZ = int B xyz-bar / int y-bar over [kLambdaMin, kLambdaMax],
// color.hpp's observer, the normalisation hero_to_xyz uses; a channel below 0, out of gamut, is 0);
// Mono its luminance Y. Rgb and Mono read a table of 4096 temperature intervals over
// [0, T_max] built once (48 KiB in Rgb), linear between entries: within 1e-3 of direct
// integration above T_max / 4 (tests/test_blackbody.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "../color.hpp"
#include "../core/error.hpp"
#include "../geometry.hpp"
#include "../spectrum.hpp"
#include "emissive.hpp"

namespace nsp {

/// Planck's law: the spectral radiance of a blackbody at `kelvin` and wavelength `nm`, in
/// W sr^-1 m^-2 nm^-1 (CODATA 2018 constants); 0 for kelvin <= 0. Finite for every finite input.
inline double planck(double nm, double kelvin) noexcept {
    constexpr double c1 = 1.191042972397188e-16;  // 2 h c^2, W m^2 sr^-1
    constexpr double c2 = 1.438776877503933e-2;   // h c / k, m K
    if (!(kelvin > 0.0) || !(nm > 0.0)) return 0.0;
    const double m = nm * 1e-9;
    const double x = c2 / (m * kelvin);
    if (x > 700.0) return 0.0;  // exp(x) overflows double: B underflows to 0 long before
    const double m2 = m * m;
    return c1 / (m2 * m2 * m * std::expm1(x)) * 1e-9;
}

/// The wavelength in nm where Planck's law peaks at `kelvin` (Wien's displacement law).
inline double wien_peak_nm(double kelvin) noexcept { return 2.897771955e6 / kelvin; }

/// The largest of planck(nm, kelvin) over all wavelengths (at Wien's peak).
inline double planck_peak(double kelvin) noexcept { return planck(wien_peak_nm(kelvin), kelvin); }

/// A grid of scalars over a box: what BlackbodyEmission reads temperatures from. EmissionGrid is
/// one, io/nanovdb.hpp's NanoScalarField another. value(p) is 0 outside bounds(); bound(region)
/// bounds value over the region; max_value() bounds it everywhere.
template <class F>
concept ScalarField = requires(const F& f, const Vec3& p, const Box& b) {
    { f.value(p) } -> std::same_as<float>;
    { f.bound(b) } -> std::same_as<float>;
    { f.bounds() } -> std::same_as<Box>;
    { f.max_value() } -> std::same_as<float>;
};

namespace detail {
/// Temperature-table intervals of BlackbodyEmission's Rgb and Mono modes.
inline constexpr int kBlackbodyTable = 4096;
/// The hottest temperature BlackbodyEmission allows, in kelvin (hotter is a unit mistake).
inline constexpr double kMaxBlackbodyKelvin = 1e6;

/// Linear sRGB of the spectrum B(., kelvin) (normalised to its peak when asked), as color.hpp
/// maps spectra: Simpson's rule on 1 nm steps over [kLambdaMin, kLambdaMax].
inline Eigen::Array3d blackbody_rgb(double kelvin, bool normalize) noexcept {
    if (!(kelvin > 0.0)) return Eigen::Array3d::Zero();
    const int n = int(kLambdaMax - kLambdaMin);
    Eigen::Array3d xyz = Eigen::Array3d::Zero();
    for (int i = 0; i <= n; ++i) {
        const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        const double nm = double(kLambdaMin) + i;
        xyz += w * planck(nm, kelvin) * cie_xyz_bar(nm);
    }
    xyz /= 3.0 * cie_y_integral();
    if (normalize) xyz /= planck_peak(kelvin);
    return xyz_to_linear_srgb(xyz).max(0.0);
}
}  // namespace detail

/// Blackbody emission from a temperature field F (an EmissionGrid, or a NanoScalarField): an
/// EmissionField for Emissive<M, BlackbodyEmission<S, F>> (see the header comment). Read-only after
/// construction; radiance() allocates nothing and never throws.
template <SpectralMode S, ScalarField F = EmissionGrid>
class BlackbodyEmission {
public:
    using Spectrum = typename S::Spectrum;

    /// Throws InvalidArgument on a temperature_scale or radiance_scale that is negative or not
    /// finite, a hottest temperature (field max x temperature_scale) above 1e6 K (a unit mistake:
    /// give kelvin), or a largest radiance that overflows float.
    BlackbodyEmission(F temperature, float temperature_scale = 1.f, float radiance_scale = 1.f, bool normalize = false)
        : field_(std::move(temperature)), t_scale_(temperature_scale), scale_(radiance_scale), normalize_(normalize) {
        if (!std::isfinite(t_scale_) || t_scale_ < 0.f)
            detail::fail("BlackbodyEmission temperature_scale = ", t_scale_,
                         " is not allowed: it must be finite and >= 0 (kelvin per unit grid value)");
        if (!std::isfinite(scale_) || scale_ < 0.f)
            detail::fail("BlackbodyEmission radiance_scale = ", scale_, " is not allowed: it must be finite and >= 0");
        t_max_ = double(field_.max_value()) * double(t_scale_);
        if (!(t_max_ <= detail::kMaxBlackbodyKelvin))
            detail::fail("BlackbodyEmission: the hottest temperature, grid max ", field_.max_value(),
                         " x temperature_scale ", t_scale_, " = ", t_max_, " K, is not allowed: it must be at most ",
                         detail::kMaxBlackbodyKelvin, " K (give temperatures in kelvin)");
        // B grows with T at every wavelength: the hottest point bounds every radiance.
        const double peak = t_max_ > 0.0 ? (normalize_ ? 1.0 : largest_visible(t_max_)) * double(scale_) : 0.0;
        if (!(peak <= double(std::numeric_limits<float>::max())))
            detail::fail("BlackbodyEmission: the largest radiance, ", peak, " at ", t_max_, " K x radiance_scale ", scale_,
                         ", is not allowed: it must be finite in float");
        if constexpr (!is_hero_v<S>) {
            table_.resize(std::size_t(detail::kBlackbodyTable) + 1);
            for (int k = 0; k <= detail::kBlackbodyTable; ++k) {
                const Eigen::Array3d rgb = detail::blackbody_rgb(t_max_ * k / detail::kBlackbodyTable, normalize_) * double(scale_);
                if constexpr (S::channels == 3)
                    table_[std::size_t(k)] = rgb.cast<float>();
                else  // luminance Y of linear sRGB (Rec. 709)
                    table_[std::size_t(k)] = Spectrum::Constant(float(0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]));
            }
            for (const Spectrum& v : table_)
                if (!v.isFinite().all())
                    detail::fail("BlackbodyEmission: radiance_scale ", scale_, " makes the colour of ", t_max_,
                                 " K overflow float; choose a smaller radiance_scale");
            inv_step_ = t_max_ > 0.0 ? float(detail::kBlackbodyTable / t_max_) : 0.f;
        }
    }

    /// The temperature at p in kelvin (0 outside the field's box).
    float temperature(const Vec3& p) const noexcept { return field_.value(p) * t_scale_; }

    /// L_e(p) at the path's channels or wavelengths.
    Spectrum radiance(const Vec3& p, const typename S::Wavelengths& l) const noexcept {
        const float t = temperature(p);
        if (!(t > 0.f)) return Spectrum::Zero();
        if constexpr (is_hero_v<S>) {
            Spectrum out;
            for (int c = 0; c < S::channels; ++c) out[c] = float(planck(double(l.nm[std::size_t(c)]), double(t)));
            if (normalize_) out *= float(1.0 / planck_peak(double(t)));
            return out * scale_;
        } else {
            const float x = std::min(t * inv_step_, float(detail::kBlackbodyTable));
            const int k = std::min(int(x), detail::kBlackbodyTable - 1);
            const float f = x - float(k);
            return table_[std::size_t(k)] * (1.f - f) + table_[std::size_t(k) + 1] * f;
        }
    }

    bool may_emit(const Box& region) const noexcept { return scale_ > 0.f && t_scale_ > 0.f && field_.bound(region) > 0.f; }
    Box bounds() const noexcept { return field_.bounds(); }

    const F& temperature_field() const noexcept { return field_; }
    float temperature_scale() const noexcept { return t_scale_; }
    float radiance_scale() const noexcept { return scale_; }
    bool normalized() const noexcept { return normalize_; }
    /// The hottest temperature, in kelvin.
    double max_temperature() const noexcept { return t_max_; }

private:
    /// The largest B(., kelvin) over the visible range: at Wien's peak if it lies inside, else at
    /// the nearer end (B has one maximum over wavelength).
    static double largest_visible(double kelvin) noexcept {
        const double nm = std::clamp(wien_peak_nm(kelvin), double(kLambdaMin), double(kLambdaMax));
        return planck(nm, kelvin);
    }

    F field_;
    float t_scale_, scale_;
    bool normalize_;
    double t_max_ = 0.0;
    std::vector<Spectrum> table_;  ///< Rgb, Mono: per temperature step, the channel values
    float inv_step_ = 0.f;
};

}  // namespace nsp
