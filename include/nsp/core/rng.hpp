// nsp/core/rng.hpp: the random number generator concept and a PCG32 model.
#pragma once

#include <concepts>
#include <cstdint>

namespace nsp {

/// What kernels need of a random number generator: `uniform()` returns a float in [0, 1).
/// Hosts may pass their own generator (Sobol, a GPU counter-based RNG) that models this.
template <class R>
concept UniformRng = requires(R& r) {
    { r.uniform() } -> std::same_as<float>;
};

/// PCG32 (O'Neill 2014, XSH-RR output): small state, seedable, with independent streams.
class Pcg32 {
public:
    /// Seeds the generator; different `stream` values give statistically independent sequences.
    explicit Pcg32(std::uint64_t seed = 0x853c49e6748fea9bULL,
                   std::uint64_t stream = 0xda3e39cb94b95bdbULL) noexcept {
        seed_stream(seed, stream);
    }

    /// Restarts the sequence for (seed, stream).
    void seed_stream(std::uint64_t seed, std::uint64_t stream) noexcept {
        state_ = 0u;
        inc_ = (stream << 1u) | 1u;
        next_u32();
        state_ += seed;
        next_u32();
    }

    /// A uniform 32-bit integer.
    std::uint32_t next_u32() noexcept {
        const std::uint64_t old = state_;
        state_ = old * 6364136223846793005ULL + inc_;
        const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
        const auto rot = static_cast<std::uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
    }

    /// A uniform float in [0, 1) with 24 random bits (never returns 1).
    float uniform() noexcept { return static_cast<float>(next_u32() >> 8) * 0x1p-24f; }

private:
    std::uint64_t state_ = 0;
    std::uint64_t inc_ = 1;
};

static_assert(UniformRng<Pcg32>);

}  // namespace nsp
