// nsp/spectrum.hpp: spectral modes, the policy that says what one "channel" is.
//
// A spectral mode names a fixed-size spectrum type (an Eigen array: element-wise, no heap) and
// a per-path wavelength context. Monochromatic and RGB modes have fixed channels, so their
// context is empty; a hero-wavelength mode (ROADMAP 2) stores the sampled wavelengths in it and
// media evaluate their coefficients at them. Code that differs per mode branches with
// `if constexpr` on the traits below, nowhere else.
#pragma once

#include <cmath>
#include <concepts>

#include <Eigen/Core>

namespace nsp {

/// A spectral mode provides:
/// - `channels`: the number of spectral samples carried by each path;
/// - `Spectrum`: an Eigen array of `channels` floats;
/// - `Wavelengths`: the per-path channel context passed to every medium lookup;
/// - `name`: a short name for tables and test output.
template <class S>
concept SpectralMode = requires {
    { S::channels } -> std::convertible_to<int>;
    typename S::Spectrum;
    typename S::Wavelengths;
    { S::name } -> std::convertible_to<const char*>;
    requires S::Spectrum::RowsAtCompileTime == S::channels;
    requires S::Spectrum::ColsAtCompileTime == 1;
};

/// One grey channel.
struct Mono {
    static constexpr int channels = 1;
    using Spectrum = Eigen::Array<float, 1, 1>;
    struct Wavelengths {};
    static constexpr const char* name = "mono";
};

/// Three fixed channels, red, green and blue.
struct Rgb {
    static constexpr int channels = 3;
    using Spectrum = Eigen::Array<float, 3, 1>;
    struct Wavelengths {};
    static constexpr const char* name = "rgb";
};

static_assert(SpectralMode<Mono> && SpectralMode<Rgb>);

/// The spectrum type of mode S.
template <SpectralMode S>
using SpectrumOf = typename S::Spectrum;

/// True when every channel is finite.
template <class Spec>
bool all_finite(const Spec& s) noexcept {
    for (int i = 0; i < s.size(); ++i)
        if (!std::isfinite(s[i])) return false;
    return true;
}

/// The scalar that drives event probabilities when one pdf serves all channels: the channel
/// mean (the "average" variant of spectral tracking, Kutz et al. 2017; exact for Mono).
template <class Spec>
float sampling_scalar(const Spec& s) noexcept {
    return s.mean();
}

}  // namespace nsp
