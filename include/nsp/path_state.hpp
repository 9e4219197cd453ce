// nsp/path_state.hpp: the state of one path, grey or per channel, and every update and MIS weight
// the path loop and the technique kernels make with it (THEORY 5.1, 5.3, 5.4, 5.6-5.9).
//
// The channel axis is a value here, not a file: PathState<Ch, St, H, A, S> is chosen by its axis
// `Ch`, channels::Grey (one pdf for every channel, event probabilities from the channel means under
// a grey majorant: PathEstimator) or a ChannelPolicy (every channel's pdfs, THEORY 5.3:
// SpectralPathEstimator). Both keep what a path needs for the MIS weight of whatever it reaches:
//
//     grey:        beta = f / p (the throughput), the last real vertex's roulette survival and
//                  direction pdf (VertexPdf), prod P_n of the nulls since it (THEORY 5.1), and
//                  the equiangular ratio p_eq / p_track of that vertex (THEORY 5.4);
//     per channel: f_c and every technique's p_c relative to one normaliser, as ratios to the
//                  sampling channel's tracking (ChannelPathState, STYLE rule 7).
//
// The loop and the technique kernels (estimators/*.hpp) sample, walk and look up once; what they
// find goes to the state as a plain record (a light sample and its shadow walk, an equiangular or
// emission point), and the state adds its contribution with the weight its axis computes: the
// grey weights of vertex.hpp (weight_among over the techniques' pdfs) or the one-sample balance
// heuristic over channels x techniques (channel_estimate).
//
// The records the kernels hand the state are in path_records.hpp; the grey state in
// path_state_grey.hpp, the per-channel one in path_state_channels.hpp.
#pragma once

#include "path_records.hpp"
#include "path_state_channels.hpp"
#include "path_state_grey.hpp"
