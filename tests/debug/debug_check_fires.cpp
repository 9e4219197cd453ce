// tests/debug/debug_check_fires.cpp: debug mode (NSP_DEBUG=1) catches a broken invariant inside
// the free-flight loop: a host medium that returns a negative coefficient (the Medium concept
// requires >= 0) must stop the program with "nsp debug check failed". The test passes when the
// check aborts the program (caught here by a SIGABRT handler that exits 0) and fails if tracking
// runs to the end without noticing.
#include <csignal>
#include <cstdio>
#include <unistd.h>

#include <nsp/nsp.hpp>

#if !NSP_DEBUG_ENABLED
#error "tests/debug/debug_check_fires.cpp is built with NSP_DEBUG=1"
#endif

namespace {

/// A medium that breaks its contract: mu_a = -1 everywhere inside a unit box.
struct NegativeMedium {
    using Spectral = nsp::Mono;
    nsp::Box bounds() const { return {nsp::Vec3(0.f), nsp::Vec3(1.f)}; }
    nsp::Coefficients<nsp::Mono> coefficients(const nsp::Vec3&, const nsp::Mono::Wavelengths&) const {
        return {nsp::Mono::Spectrum::Constant(-1.f), nsp::Mono::Spectrum::Constant(2.f)};
    }
    nsp::Mono::Spectrum extinction_bound(const nsp::Mono::Wavelengths&) const { return nsp::Mono::Spectrum::Constant(2.f); }
    float max_extinction() const { return 2.f; }
};
static_assert(nsp::Medium<NegativeMedium>);

extern "C" void on_abort(int) {
    static const char msg[] = "debug check fired as expected\n";
    (void)!write(2, msg, sizeof msg - 1);
    _exit(0);
}

}  // namespace

int main() {
    std::signal(SIGABRT, on_abort);
    const NegativeMedium medium;
    const nsp::GlobalMajorant<NegativeMedium> majorant(medium, 4.f);
    nsp::Pcg32 rng(1, 1);
    nsp::LookupCount lookups;
    const nsp::Ray ray{nsp::Vec3(0.5f, 0.5f, -1.f), nsp::Vec3(0.f, 0.f, 1.f)};
    for (int i = 0; i < 100; ++i) (void)nsp::transmittance_ratio(medium, majorant, ray, 10.f, {}, rng, lookups);
    std::fprintf(stderr, "FAIL: 100 flights through a medium with mu_a = -1 ran without a debug check firing\n");
    return 1;
}
