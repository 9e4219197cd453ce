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

/// Debug mode: NSP_DEBUG_ASSERT(cond, msg) checks an invariant inside a kernel (a pdf > 0 where a
/// sample was taken, finite weights, probabilities that sum to 1) and, if it fails, prints the
/// condition, the message and where, then aborts. It is on when NSP_DEBUG is defined to 1 (or
/// defined empty), or NSP_DEBUG is not defined and NDEBUG is not (a debug build); NSP_DEBUG=0
/// turns it off. Off, it compiles to nothing: the condition is not evaluated. Statuses the
/// documentation promises (Rejected, Aborted, Terminated) are results, not failed invariants.
#if defined(NSP_DEBUG)
#if (0 - NSP_DEBUG - 1 == -1)  // NSP_DEBUG=0 (an empty definition gives 0 + 1 != -1: on)
#define NSP_DEBUG_ENABLED 0
#else
#define NSP_DEBUG_ENABLED 1
#endif
#elif !defined(NDEBUG)
#define NSP_DEBUG_ENABLED 1
#else
#define NSP_DEBUG_ENABLED 0
#endif

#if NSP_DEBUG_ENABLED
#include <cstdio>
#include <cstdlib>
#define NSP_DEBUG_ASSERT(cond, msg) \
    ((cond) ? (void)0 : ::nsp::detail::debug_assert_failed(#cond, msg, __FILE__, __LINE__))
#else
#define NSP_DEBUG_ASSERT(cond, msg) ((void)0)
#endif

namespace nsp {

/// Thrown by constructors and loaders when an argument is outside what nsp allows.
class InvalidArgument : public std::invalid_argument {
public:
    using std::invalid_argument::invalid_argument;
};

/// True when NSP_DEBUG_ASSERT checks its invariants (see NSP_DEBUG_ENABLED).
inline constexpr bool kDebugChecks = NSP_DEBUG_ENABLED != 0;

namespace detail {

#if NSP_DEBUG_ENABLED
/// Reports a failed kernel invariant and aborts (debug mode only).
[[noreturn]] inline void debug_assert_failed(const char* cond, const char* msg, const char* file, int line) noexcept {
    std::fprintf(stderr, "nsp debug check failed: %s (%s) at %s:%d\n", msg, cond, file, line);
    std::abort();
}
#endif

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
