// nsp/spectrum.hpp: spectral modes, the policy that says what one "channel" is.
//
// A spectral mode names a fixed-size spectrum type (an Eigen array: element-wise, no heap), a
// per-path wavelength context, and the type in which media and lights give their coefficients
// (`Coefficient`). Monochromatic and RGB modes have fixed channels: their context is empty and a
// coefficient is already a spectrum. The hero-wavelength mode `Hero<N>` samples N wavelengths
// per path (Wilkie et al. 2014) and evaluates tabulated spectra at them. Code that differs per
// mode branches with `if constexpr` on the traits below, nowhere else.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "core/error.hpp"

namespace nsp {

/// A spectral mode provides:
/// - `channels`: the number of spectral samples carried by each path;
/// - `Spectrum`: an Eigen array of `channels` floats;
/// - `Wavelengths`: the per-path channel context passed to every medium lookup;
/// - `Coefficient`: how media and lights give a spectral quantity (a Spectrum for fixed channels,
///   a tabulated spectrum for hero wavelengths), and `sample(coefficient, lambda)`, its values at
///   the path's channels;
/// - `name`: a short name for tables and test output.
template <class S>
concept SpectralMode = requires(const typename S::Coefficient& k, const typename S::Wavelengths& l) {
    { S::channels } -> std::convertible_to<int>;
    typename S::Spectrum;
    typename S::Wavelengths;
    { S::name } -> std::convertible_to<const char*>;
    { S::sample(k, l) } -> std::convertible_to<typename S::Spectrum>;
    requires S::Spectrum::RowsAtCompileTime == S::channels;
    requires S::Spectrum::ColsAtCompileTime == 1;
};

/// One grey channel.
struct Mono {
    static constexpr int channels = 1;
    using Spectrum = Eigen::Array<float, 1, 1>;
    using Coefficient = Spectrum;
    struct Wavelengths {};
    static constexpr const char* name = "mono";
    static const Spectrum& sample(const Coefficient& k, const Wavelengths&) noexcept { return k; }
};

/// Three fixed channels, red, green and blue.
struct Rgb {
    static constexpr int channels = 3;
    using Spectrum = Eigen::Array<float, 3, 1>;
    using Coefficient = Spectrum;
    struct Wavelengths {};
    static constexpr const char* name = "rgb";
    static const Spectrum& sample(const Coefficient& k, const Wavelengths&) noexcept { return k; }
};

// ---------------------------------------------------------------------------------------------
// Hero wavelengths

/// The visible range hero wavelengths are drawn from, in nm.
inline constexpr float kLambdaMin = 360.f, kLambdaMax = 830.f;

/// A spectrum tabulated every 10 nm over [kLambdaMin, kLambdaMax] (48 values), evaluated by
/// linear interpolation. Trivially copyable; media and lights give Hero-mode coefficients in it.
class TabulatedSpectrum {
public:
    static constexpr int kSize = 48;
    static constexpr float kStep = (kLambdaMax - kLambdaMin) / float(kSize - 1);  // 10 nm

    /// The zero spectrum.
    TabulatedSpectrum() { v_.fill(0.f); }

    /// The same value v at every wavelength; throws InvalidArgument unless v is finite and >= 0.
    static TabulatedSpectrum constant(float v) {
        detail::require_finite_nonnegative(v, "TabulatedSpectrum value");
        TabulatedSpectrum s;
        s.v_.fill(v);
        s.max_ = v;
        return s;
    }

    /// A piecewise-linear spectrum through the points (nm[i], value[i]) (increasing nm), constant
    /// beyond the first and last point, resampled on the 10 nm grid. Throws InvalidArgument on
    /// mismatched or empty input, non-increasing wavelengths, or a non-finite or negative value.
    static TabulatedSpectrum from_points(const std::vector<float>& nm, const std::vector<float>& value) {
        if (nm.empty() || nm.size() != value.size())
            detail::fail("TabulatedSpectrum: ", nm.size(), " wavelengths and ", value.size(),
                         " values given; both must be non-empty and of equal size");
        for (std::size_t i = 0; i < nm.size(); ++i) {
            detail::require_finite(nm[i], "TabulatedSpectrum wavelength");
            detail::require_finite_nonnegative(value[i], "TabulatedSpectrum value");
            if (i > 0 && !(nm[i] > nm[i - 1]))
                detail::fail("TabulatedSpectrum: wavelength[", i, "] = ", nm[i], " is not above wavelength[",
                             i - 1, "] = ", nm[i - 1], "; wavelengths must increase");
        }
        TabulatedSpectrum s;
        for (int k = 0; k < kSize; ++k) {
            const float l = kLambdaMin + kStep * float(k);
            const auto hi = std::upper_bound(nm.begin(), nm.end(), l);
            if (hi == nm.begin()) s.v_[k] = value.front();
            else if (hi == nm.end()) s.v_[k] = value.back();
            else {
                const std::size_t j = std::size_t(hi - nm.begin());
                const float f = (l - nm[j - 1]) / (nm[j] - nm[j - 1]);
                s.v_[k] = value[j - 1] + f * (value[j] - value[j - 1]);
            }
            s.max_ = std::max(s.max_, s.v_[k]);
        }
        return s;
    }

    /// The value at table position `index` + `frac` (see HeroWavelengths).
    float at(int index, float frac) const noexcept { return v_[index] + frac * (v_[index + 1] - v_[index]); }

    /// The value at wavelength nm (clamped to the range).
    float operator()(float nm) const noexcept {
        const float x = std::clamp((nm - kLambdaMin) / kStep, 0.f, float(kSize - 1));
        const int i = std::min(int(x), kSize - 2);
        return at(i, x - float(i));
    }

    /// The largest value over the range (what a majorant must bound).
    float max_value() const noexcept { return max_; }

    /// The value of table entry k (0 <= k < kSize), at wavelength kLambdaMin + k kStep.
    float operator[](int k) const noexcept { return v_[std::size_t(k)]; }

    /// The sum of two spectra, wavelength by wavelength.
    friend TabulatedSpectrum operator+(const TabulatedSpectrum& a, const TabulatedSpectrum& b) noexcept {
        TabulatedSpectrum s;
        for (int k = 0; k < kSize; ++k) {
            s.v_[k] = a.v_[k] + b.v_[k];
            s.max_ = std::max(s.max_, s.v_[k]);
        }
        return s;
    }

    /// The scaled spectrum.
    TabulatedSpectrum scaled(float k) const noexcept {
        TabulatedSpectrum s = *this;
        for (float& x : s.v_) x *= k;
        s.max_ *= k;
        return s;
    }

private:
    std::array<float, kSize> v_;
    float max_ = 0.f;
};

/// The N wavelengths of one path, with their table positions precomputed so that evaluating a
/// tabulated spectrum costs one interpolation per channel.
template <int N>
struct HeroWavelengths {
    std::array<float, N> nm{};    ///< the wavelengths in nm (a default context evaluates spectra at kLambdaMin)
    std::array<int, N> index{};   ///< table index of each wavelength
    std::array<float, N> frac{};  ///< position between table entries index and index + 1

    /// Stratified rotation (Wilkie 2014): lambda_i = min + (max - min) frac(u + i / N). Each
    /// wavelength is uniform over the range, with pdf 1 / (kLambdaMax - kLambdaMin).
    static HeroWavelengths sample(float u) noexcept {
        HeroWavelengths w;
        for (int i = 0; i < N; ++i) {
            float v = u + float(i) / float(N);
            v -= std::floor(v);
            w.nm[std::size_t(i)] = kLambdaMin + (kLambdaMax - kLambdaMin) * v;
            const float x = std::clamp((w.nm[std::size_t(i)] - kLambdaMin) / TabulatedSpectrum::kStep, 0.f,
                                       float(TabulatedSpectrum::kSize - 1));
            w.index[std::size_t(i)] = std::min(int(x), TabulatedSpectrum::kSize - 2);
            w.frac[std::size_t(i)] = x - float(w.index[std::size_t(i)]);
        }
        return w;
    }

    /// The pdf of each wavelength, per nm.
    static constexpr float pdf() noexcept { return 1.f / (kLambdaMax - kLambdaMin); }
};

/// N hero wavelengths per path, stratified over [kLambdaMin, kLambdaMax] (N = 4 by default).
template <int N = 4>
struct Hero {
    static_assert(N >= 1, "nsp::Hero<N>: a path needs at least one wavelength");
    static constexpr int channels = N;
    using Spectrum = Eigen::Array<float, N, 1>;
    using Coefficient = TabulatedSpectrum;
    using Wavelengths = HeroWavelengths<N>;
    static constexpr const char* name = "hero";
    static Spectrum sample(const Coefficient& k, const Wavelengths& l) noexcept {
        Spectrum s;
        for (int i = 0; i < N; ++i) s[i] = k.at(l.index[std::size_t(i)], l.frac[std::size_t(i)]);
        return s;
    }
};

static_assert(SpectralMode<Mono> && SpectralMode<Rgb> && SpectralMode<Hero<4>>);

/// True when S samples wavelengths per path (so its context must be drawn per path).
template <class S>
inline constexpr bool is_hero_v = false;
template <int N>
inline constexpr bool is_hero_v<Hero<N>> = true;

/// The spectrum type of mode S.
template <SpectralMode S>
using SpectrumOf = typename S::Spectrum;

/// A coefficient of mode S equal to v at every channel or wavelength.
template <SpectralMode S>
typename S::Coefficient constant_coefficient(float v) {
    if constexpr (is_hero_v<S>) return TabulatedSpectrum::constant(v);
    else return S::Spectrum::Constant(v);
}

/// The largest value of a coefficient over all channels or wavelengths.
template <class K>
float max_value(const K& k) noexcept {
    if constexpr (std::is_same_v<K, TabulatedSpectrum>) return k.max_value();
    else return k.maxCoeff();
}

/// The smallest value of a coefficient over all channels or wavelengths.
template <class K>
float min_value(const K& k) noexcept {
    if constexpr (std::is_same_v<K, TabulatedSpectrum>) {
        float m = k[0];
        for (int i = 1; i < TabulatedSpectrum::kSize; ++i) m = std::min(m, k[i]);
        return m;
    } else {
        return k.minCoeff();
    }
}

/// A coefficient scaled by k.
template <class K>
K scale(const K& c, float k) {
    if constexpr (std::is_same_v<K, TabulatedSpectrum>) return c.scaled(k);
    else return c * k;
}

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
