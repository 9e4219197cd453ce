// nsp/core/error.hpp: the one way constructors and loaders reject bad input.
//
// Errors come in three tiers (STYLE.md rule 6): constructors throw nsp::InvalidArgument with a
// message naming the bad value and what is allowed; kernels never throw and report a Status;
// nonsensical policy combinations are static_asserts.
#pragma once

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

/// Debug mode: NSP_DEBUG_ASSERT checks an invariant inside a kernel when NSP_DEBUG is defined or
/// NDEBUG is not (a debug build), and compiles to nothing otherwise.
#if defined(NSP_DEBUG) || !defined(NDEBUG)
#include <cassert>
#define NSP_DEBUG_ASSERT(cond, msg) assert((cond) && (msg))
#else
#define NSP_DEBUG_ASSERT(cond, msg) ((void)0)
#endif

namespace nsp {

/// Thrown by constructors and loaders when an argument is outside what nsp allows.
class InvalidArgument : public std::invalid_argument {
public:
    using std::invalid_argument::invalid_argument;
};

namespace detail {

/// Builds a message from streamable parts and throws InvalidArgument("nsp: ...").
template <class... Parts>
[[noreturn]] void fail(const Parts&... parts) {
    std::ostringstream os;
    os << "nsp: ";
    (os << ... << parts);
    throw InvalidArgument(os.str());
}

/// Rejects a value that is NaN, infinite or negative; `what` names it in the message.
inline void require_finite_nonnegative(double v, const char* what) {
    if (!std::isfinite(v) || v < 0.0)
        fail(what, " = ", v, " is not allowed: it must be finite and >= 0");
}

/// Rejects a value that is NaN or infinite.
inline void require_finite(double v, const char* what) {
    if (!std::isfinite(v)) fail(what, " = ", v, " is not allowed: it must be finite");
}

}  // namespace detail
}  // namespace nsp
