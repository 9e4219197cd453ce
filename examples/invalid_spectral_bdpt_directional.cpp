// examples/invalid_spectral_bdpt_directional.cpp: must NOT compile. Directional MIS leaves the
// tracking factors out of BDPT's weights, so it has no per-channel pdfs to combine: a BdptEstimator
// with the channels::SpectralMis axis rejects bdpt::Directional with a static_assert (STYLE rule
// 6); the test nsp_static_assert_rejects_spectral_bdpt_directional builds this file and expects
// that message.
#include <nsp/nsp.hpp>

int main() {
    const nsp::BdptEstimator<nsp::bdpt::Directional, nsp::mis::Balance, nsp::absorption::Weight, 32,
                             nsp::channels::SpectralMis>
        estimator;
    return estimator.options().max_depth > 0 ? 0 : 1;
}
