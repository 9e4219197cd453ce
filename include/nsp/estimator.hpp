// nsp/estimator.hpp: every estimator nsp offers (THEORY 4, 5).
//
// - estimators/path.hpp: PathEstimator (one pdf for every channel: grey media, Mono) and
//   SpectralPathEstimator (per-channel pdfs: chromatic media, THEORY 5.3), one path loop over a
//   SurfaceScene or a Scene;
// - estimators/bdpt.hpp: BdptEstimator, bidirectional with null-vertex MIS (THEORY 5.5), grey or
//   per channel.
// The techniques they share, each a kernel a host's loop calls too: estimators/nee.hpp,
// equiangular_vertex.hpp, emission.hpp, over the walk of estimators/scene_walk.hpp and the path
// state of path_state.hpp.
#pragma once

#include "estimators/bdpt.hpp"
#include "estimators/path.hpp"
