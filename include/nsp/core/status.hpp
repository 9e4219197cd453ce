// nsp/core/status.hpp: how a kernel's estimate ended. Kernels never throw (STYLE rule 6): every
// estimate comes with a Status, and an estimate whose status is not Ok is 0 where it failed.
#pragma once

#include <cstdint>

namespace nsp {

/// How a radiance or transmittance estimate ended.
enum class Status : std::uint8_t {
    Ok,         ///< a finite estimate
    Aborted,    ///< a flight hit the collision limit; that flight contributed 0 (rare, biased)
    NonFinite,  ///< the estimate was NaN or Inf and has been replaced by 0
    Rejected,   ///< bound::Reject met mu_t > mu_bar on a flight; that flight contributed 0 (biased)
    InvalidInput,  ///< the host's input was unusable: a ray with a non-finite origin or a direction that is
                   ///< not unit length (usable_ray), a NaN distance, or a hit nsp cannot use (a NaN or
                   ///< negative distance, a non-unit normal, a handle outside its tables); nothing was
                   ///< estimated from it (0)
};

}  // namespace nsp
