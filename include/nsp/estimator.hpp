// nsp/estimator.hpp: every path estimator nsp offers (THEORY 4, 5).
//
// - estimators/common.hpp: the path strategies, options and result type they share;
// - estimators/path.hpp: PathEstimator, one pdf for every channel (grey media, Mono);
// - estimators/spectral.hpp: SpectralPathEstimator, per-channel pdfs (chromatic media, THEORY 5.3);
// - estimators/bdpt.hpp: BdptEstimator, bidirectional with null-vertex MIS (THEORY 5.5), grey.
#pragma once

#include "estimators/bdpt.hpp"
#include "estimators/common.hpp"
#include "estimators/path.hpp"
#include "estimators/spectral.hpp"
