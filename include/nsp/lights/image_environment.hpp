// nsp/lights/image_environment.hpp: a light at infinity whose radiance comes from a bitmap in
// latitude-longitude layout (an "environment map" the host loads), importance-sampled by
// luminance times each pixel's solid angle.
//
// Orientation. nsp's scenes are y-up (PinholeCamera's convention; the example rooms' floors are
// planes of constant y), so the map's poles lie on the y axis. A unit direction
// w = (sin theta sin phi, cos theta, -sin theta cos phi) reads the image at
//   u = phi / (2 pi) in [0, 1) (column u x width),  v = theta / pi in [0, 1] (row v x height),
// with theta in [0, pi] measured from +y and phi = atan2(w.x, -w.z) in [0, 2 pi): row 0 is the
// top of the image (theta = 0, straight up, +y), the image's left edge (u = 0) looks along -z and
// u = 1/4 along +x. This is Mitsuba 3's `envmap` convention, so maps made for it line up. A
// direction w is the one a ray travels to reach the sky: emitted(w) is the pixel w points at.
//
// Sampling (THEORY 5.8): a pixel with probability proportional to luminance x the pixel's solid
// angle (2 pi / width) (cos theta_top - cos theta_bottom), as a marginal over rows and a
// conditional per row; then a direction uniform in solid angle inside the pixel (phi uniform,
// cos theta uniform). The solid-angle pdf is therefore constant over a pixel, P(pixel) /
// Omega(pixel): no 1 / sin theta at the poles, and where radiance is proportional to luminance
// (any Mono map) radiance / pdf is the same for every sample.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../core/error.hpp"
#include "../core/math.hpp"
#include "../light.hpp"
#include "../spectrum.hpp"

namespace nsp {

/// Rec. 709 / linear sRGB luminance of a linear RGB triple.
inline float luminance_rec709(float r, float g, float b) noexcept { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

/// Radiance at infinity read from a latitude-longitude RGB image (see the file comment for the
/// mapping), importance-sampled by luminance x pixel solid angle. Mono: each pixel's luminance;
/// Rgb: its three channels. Immutable after construction; sample / pdf / emitted never allocate
/// or throw. Hero<N> is rejected at compile time: nsp has no RGB-to-spectrum rule to evaluate an
/// RGB pixel at a wavelength.
template <SpectralMode S>
class ImageEnvironmentLight {
    static_assert(!is_hero_v<S>,
                  "nsp::ImageEnvironmentLight supports the Mono and Rgb modes only: nsp has no RGB-to-spectrum "
                  "rule to evaluate an RGB image at hero wavelengths (use EnvironmentLight with a TabulatedSpectrum)");

public:
    static constexpr bool is_delta = false;
    static constexpr bool is_infinite = true;  ///< reached by every ray that leaves the scene

    /// `rgb`: width x height x 3 linear RGB values, row-major, row 0 the top (theta = 0); every
    /// value is multiplied by `scale`. Throws InvalidArgument naming the bad value: a width or
    /// height that is not > 0, a size other than width x height x 3, a pixel value that is not
    /// finite and >= 0, a scale that is not finite and >= 0, or an image without a pixel of
    /// luminance > 0 (nothing to sample).
    ImageEnvironmentLight(int width, int height, const std::vector<float>& rgb, float scale = 1.f)
        : width_(width), height_(height) {
        if (width <= 0) detail::fail("ImageEnvironmentLight width = ", width, " is not allowed: it must be > 0");
        if (height <= 0) detail::fail("ImageEnvironmentLight height = ", height, " is not allowed: it must be > 0");
        const std::size_t pixels = std::size_t(width) * std::size_t(height);
        if (rgb.size() != 3 * pixels)
            detail::fail("ImageEnvironmentLight rgb size = ", rgb.size(), " is not allowed: it must be width x height x 3 = ",
                         width, " x ", height, " x 3 = ", 3 * pixels);
        if (!std::isfinite(scale) || scale < 0.f)
            detail::fail("ImageEnvironmentLight scale = ", scale, " is not allowed: it must be finite and >= 0");
        for (std::size_t i = 0; i < rgb.size(); ++i)
            if (!std::isfinite(rgb[i]) || rgb[i] < 0.f)
                detail::fail("ImageEnvironmentLight pixel (x ", (i / 3) % std::size_t(width), ", y ",
                             (i / 3) / std::size_t(width), ") channel ", i % 3, " = ", rgb[i],
                             " is not allowed: every value must be finite and >= 0");

        // Row edges in cos theta, from +1 (row 0's top) down to -1.
        z_edge_.resize(std::size_t(height) + 1);
        for (int j = 0; j <= height; ++j) z_edge_[std::size_t(j)] = float(std::cos(double(kPi) * double(j) / double(height)));
        z_edge_.front() = 1.f;
        z_edge_.back() = -1.f;

        // A pixel's solid angle (2 pi / W)(cos theta_top - cos theta_bottom), in the stable form
        // (2 pi / W) 2 sin((t1 - t0) / 2) sin((t1 + t0) / 2); the same for every pixel of a row.
        std::vector<double> omega(static_cast<std::size_t>(height));
        for (int j = 0; j < height; ++j) {
            const double t0 = double(kPi) * j / height, t1 = double(kPi) * (j + 1) / height;
            omega[std::size_t(j)] = 2.0 * double(kPi) / width * 2.0 * std::sin(0.5 * (t1 - t0)) * std::sin(0.5 * (t1 + t0));
        }

        // Radiance per pixel, and the sampling weight luminance x solid angle.
        radiance_.resize(pixels * channels);
        std::vector<double> weight(pixels), row_weight(static_cast<std::size_t>(height), 0.0);
        double total = 0.0, max_channel_integral = 0.0;
        for (std::size_t p = 0; p < pixels; ++p) {
            const std::size_t j = p / std::size_t(width);
            const float r = rgb[3 * p], g = rgb[3 * p + 1], b = rgb[3 * p + 2];
            if constexpr (channels == 1) radiance_[p] = scale * luminance_rec709(r, g, b);
            else for (std::size_t c = 0; c < 3; ++c) radiance_[3 * p + c] = scale * rgb[3 * p + c];
            weight[p] = double(luminance_rec709(r, g, b)) * omega[j];
            row_weight[j] += weight[p];
            total += weight[p];
            max_channel_integral += double(value(p).maxCoeff()) * omega[j];
        }
        if (!(total > 0.0))
            detail::fail("ImageEnvironmentLight: all ", pixels,
                         " pixels have luminance 0, which is not allowed: the image needs a pixel of luminance > 0");
        power_integral_ = float(max_channel_integral);

        // Cumulative tables: the marginal over rows, and per row the conditional over its pixels
        // (uniform in a row of weight 0, which the marginal never picks). The solid-angle pdf of
        // a pixel is its probability over its solid angle.
        marginal_cdf_.resize(std::size_t(height) + 1);
        conditional_cdf_.resize(std::size_t(height) * (std::size_t(width) + 1));
        pixel_pdf_.resize(pixels);
        double cdf = 0.0;
        for (std::size_t j = 0; j < std::size_t(height); ++j) {
            marginal_cdf_[j] = float(cdf / total);
            cdf += row_weight[j];
            float* row = conditional_cdf_.data() + j * (std::size_t(width) + 1);
            double c = 0.0;
            for (std::size_t i = 0; i < std::size_t(width); ++i) {
                const std::size_t p = j * std::size_t(width) + i;
                row[i] = float(c);
                c += row_weight[j] > 0.0 ? weight[p] / row_weight[j] : 1.0 / width;
                pixel_pdf_[p] = float(weight[p] / (total * omega[j]));
            }
            row[width] = 1.f;
        }
        marginal_cdf_.back() = 1.f;
    }

    int width() const noexcept { return width_; }
    int height() const noexcept { return height_; }

    /// A direction toward the sky by (u1, u2): a row by u1 (marginal), a pixel in it by u2
    /// (conditional), the point inside the pixel by what is left of each. pdf: the solid-angle
    /// density (constant over the pixel) times `selection`; 0 (no sample) only in the measure-zero
    /// case that the direction rounds into a pixel of weight 0.
    LightSample<S> sample(const Vec3&, float u1, float u2, const typename S::Wavelengths& = {},
                          float selection = 1.f) const noexcept {
        LightSample<S> s;
        float fv, fu;
        const int j = pick(marginal_cdf_.data(), height_, u1, fv);
        const int i = pick(conditional_cdf_.data() + std::size_t(j) * (std::size_t(width_) + 1), width_, u2, fu);
        const float z_top = z_edge_[std::size_t(j)], z_bottom = z_edge_[std::size_t(j) + 1];
        const float z = std::clamp(z_top + fv * (z_bottom - z_top), -1.f, 1.f);
        const float phi = 2.f * kPi * (float(i) + fu) / float(width_);
        const float r = std::sqrt(std::max(0.f, 1.f - z * z));
        s.wi = Vec3(r * std::sin(phi), z, -r * std::cos(phi));
        // The pixel read back from the direction, as pdf() and emitted() will: the three agree
        // even where rounding moves a direction across a pixel edge.
        const std::size_t p = pixel(s.wi);
        s.radiance = value(p);
        s.pdf = selection * pixel_pdf_[p];
        return s;
    }

    /// The solid-angle density with which `sample` produces w, times `selection` (0 for a
    /// pixel of luminance 0 or a non-finite w).
    float pdf(const Vec3&, const Vec3& w, float selection = 1.f) const noexcept {
        if (!finite(w)) return 0.f;
        return selection * pixel_pdf_[pixel(w)];
    }

    /// The radiance a ray travelling along w receives from the sky: the pixel w points at.
    typename S::Spectrum emitted(const Vec3& w, const typename S::Wavelengths& = {}) const noexcept {
        if (!finite(w)) return S::Spectrum::Zero();
        return value(pixel(w));
    }

    /// What it sends into a sphere of radius `scene_radius` around the scene: pi R^2 x the
    /// integral over directions of the largest channel (EnvironmentLight's pi L 4 pi R^2 for a
    /// constant image).
    float power(float scene_radius = 1.f) const noexcept { return kPi * scene_radius * scene_radius * power_integral_; }

private:
    static constexpr int channels = S::channels;
    static_assert(is_hero_v<S> || channels == 1 || channels == 3,
                  "nsp::ImageEnvironmentLight: a mode of 1 channel (grey, the luminance) or 3 (RGB)");

    /// The bin of a cumulative table `cdf` (n + 1 entries, 0 ... 1) that holds u, and u's
    /// position inside it in `frac`; never a bin of width 0.
    static int pick(const float* cdf, int n, float u, float& frac) noexcept {
        u = std::clamp(u, 0.f, 0x1.fffffep-1f);
        // The last entry <= u: bins of width 0 before it end at or below u and are skipped.
        const float* it = std::upper_bound(cdf, cdf + n + 1, u);
        const int k = std::clamp(int(it - cdf) - 1, 0, n - 1);
        const float width = cdf[k + 1] - cdf[k];
        frac = width > 0.f ? std::clamp((u - cdf[k]) / width, 0.f, 1.f) : 0.5f;
        return k;
    }

    /// The index of the pixel unit direction w points at. The row is read from w.y against the
    /// table of row edges (the same floats sample() draws between), the column from phi.
    std::size_t pixel(const Vec3& w) const noexcept {
        const float z = std::clamp(w.y, -1.f, 1.f);
        // Row j holds z in (z_edge[j + 1], z_edge[j]]: the count of inner edges >= z.
        const auto inner_begin = z_edge_.begin() + 1, inner_end = z_edge_.end() - 1;
        const int j = int(std::partition_point(inner_begin, inner_end, [z](float e) { return e >= z; }) - inner_begin);
        float u = std::atan2(w.x, -w.z) / (2.f * kPi);
        if (u < 0.f) u += 1.f;
        const int i = std::clamp(int(u * float(width_)), 0, width_ - 1);
        return std::size_t(j) * std::size_t(width_) + std::size_t(i);
    }

    typename S::Spectrum value(std::size_t p) const noexcept {
        typename S::Spectrum v;
        for (int c = 0; c < channels; ++c) v[c] = radiance_[p * channels + std::size_t(c)];
        return v;
    }

    int width_, height_;
    std::vector<float> radiance_;         ///< scale x pixel, `channels` per pixel, row-major
    std::vector<float> pixel_pdf_;        ///< solid-angle pdf of sample() in each pixel
    std::vector<float> z_edge_;           ///< cos theta at the row edges, height + 1 values from 1 to -1
    std::vector<float> marginal_cdf_;     ///< over rows, height + 1 values from 0 to 1
    std::vector<float> conditional_cdf_;  ///< per row, width + 1 values from 0 to 1
    float power_integral_ = 0.f;          ///< integral over the sphere of the largest channel
};

static_assert(Light<ImageEnvironmentLight<Mono>, Mono> && Light<ImageEnvironmentLight<Rgb>, Rgb>);

}  // namespace nsp
