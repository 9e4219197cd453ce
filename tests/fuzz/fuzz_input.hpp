// tests/fuzz/fuzz_input.hpp: how the kernel fuzzer reads its bytes, and its invariant check.
//
// The structure of a case (mode, medium, majorant, rays, options) is read from the front of the
// input; the random numbers the kernels draw are read from the back, two bytes each, and once
// the two ends meet every further number comes from a fixed-seed Pcg32. So a short input is a
// valid case, and libFuzzer can steer individual tracking decisions through the tail.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include <nsp/core/rng.hpp>

namespace nsp_fuzz {

/// What the fuzzer is checking right now (printed when an invariant fails).
inline const char* g_context = "";

/// Prints the failed invariant and aborts: libFuzzer reports the abort as a crash and saves the
/// input; the corpus replay test (built without libFuzzer) fails with the signal.
[[noreturn]] inline void invariant_failed(const char* cond, const char* file, int line) {
    std::fprintf(stderr, "nsp fuzz: invariant `%s` failed at %s:%d (in %s)\n", cond, file, line, g_context);
    std::abort();
}

}  // namespace nsp_fuzz

/// Checks an invariant in every build type (unlike assert, not compiled out by NDEBUG).
#define NSP_FUZZ_CHECK(cond) \
    ((cond) ? (void)0 : ::nsp_fuzz::invariant_failed(#cond, __FILE__, __LINE__))

namespace nsp_fuzz {

/// The fuzz input: structure from the front, random numbers from the back.
class Input {
public:
    Input(const std::uint8_t* data, std::size_t size) : p_(data), lo_(0), hi_(size) {}

    /// The next structure byte (0 once the input is used up).
    std::uint8_t byte() noexcept { return lo_ < hi_ ? p_[lo_++] : 0; }
    /// A structure choice in [0, n).
    int pick(int n) noexcept { return int(byte()) % n; }
    bool flag() noexcept { return byte() & 1u; }
    /// Four structure bytes as a float bit pattern (any float, NaN and inf included).
    float raw_float() noexcept {
        std::uint32_t v = 0;
        for (int i = 0; i < 4; ++i) v = (v << 8) | byte();
        float f;
        static_assert(sizeof f == sizeof v);
        __builtin_memcpy(&f, &v, sizeof f);
        return f;
    }
    /// A float in [0, 1) on a 2^-16 grid from two structure bytes.
    float unit() noexcept {
        const unsigned v = (unsigned(byte()) << 8) | byte();
        return float(v) * 0x1p-16f;
    }

    /// Two random-number bytes from the back, or -1 once the input is used up.
    int tail16() noexcept {
        if (hi_ - lo_ < 2) return -1;
        hi_ -= 2;
        return int((unsigned(p_[hi_]) << 8) | p_[hi_ + 1]);
    }

private:
    const std::uint8_t* p_;
    std::size_t lo_, hi_;
};

/// The random numbers the kernels draw (a nsp::UniformRng): from the input's tail while it lasts,
/// mostly on a 2^-16 grid, with the top codes mapped to the edges of [0, 1) (0, the largest
/// float below 1, the smallest denormal, 2^-24); then from a fixed-seed Pcg32.
class FuzzRng {
public:
    explicit FuzzRng(Input& in) : in_(in) {}

    float uniform() noexcept {
        const int v = in_.tail16();
        if (v < 0) return pcg_.uniform();
        switch (v) {
            case 0xffff: return 0x1.fffffep-1f;  // nextafter(1, 0)
            case 0xfffe: return 0x1p-149f;       // the smallest denormal
            case 0xfffd: return 0x1p-24f;
            case 0xfffc: return 1.f - 0x1p-24f;  // Pcg32's largest value
            default: return float(v) * 0x1p-16f;
        }
    }

private:
    Input& in_;
    nsp::Pcg32 pcg_{0x5eed, 0xf022};
};

static_assert(nsp::UniformRng<FuzzRng>);

}  // namespace nsp_fuzz
