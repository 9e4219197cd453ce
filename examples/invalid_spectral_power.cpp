// examples/invalid_spectral_power.cpp: must NOT compile. Spectral MIS + NEE is the one-sample
// balance heuristic over channels and techniques (THEORY 5.3), so SpectralPathEstimator rejects
// mis::Power with a static_assert; the test nsp_static_assert_rejects_spectral_power builds this
// file and expects that message.
#include <nsp/nsp.hpp>

int main() {
    const nsp::SpectralPathEstimator<nsp::channels::SpectralMis, nsp::strategy::NullScatteringMis, nsp::mis::Power>
        estimator;
    return estimator.options().max_depth > 0 ? 0 : 1;
}
