// examples/invalid_spectral_directional.cpp: must NOT compile. DirectionalMis weighs by direction
// pdfs alone, so SpectralPathEstimator, which combines per-channel path pdfs, rejects it with a
// static_assert (STYLE rule 6); the test nsp_static_assert_rejects_spectral_directional_mis builds
// this file and expects that message.
#include <nsp/nsp.hpp>

int main() {
    const nsp::SpectralPathEstimator<nsp::channels::SpectralMis, nsp::strategy::DirectionalMis, nsp::mis::Balance>
        estimator;
    return estimator.options().max_depth > 0 ? 0 : 1;
}
