// examples/invalid_combination.cpp: must NOT compile. A single-strategy estimator with a combining
// MIS heuristic is a misuse that PathEstimator rejects with a static_assert (STYLE rule 6); the
// test nsp_static_assert_rejects_bad_combination builds this file and expects that message.
#include <nsp/nsp.hpp>

int main() {
    const nsp::PathEstimator<nsp::strategy::Unidirectional, nsp::mis::Balance> estimator;
    return estimator.options().max_depth > 0 ? 0 : 1;
}
