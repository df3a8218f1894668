// Internal invariant checks: FOXI_ASSERT(condition, message) for what the code itself guarantees
// (CSR sizes, bucket bounds, undraw's bookkeeping), never for input, which gets a typed error.
//
// Active in Debug builds (NDEBUG not defined), under the sanitizers, and wherever FOXI_CHECKS is
// defined (-DFOXI_CHECKS=1 in a Release build); compiled out otherwise, the condition and message
// then not evaluated, so a check may cost what it likes. `message` is streamed (MFEM_VERIFY style):
//   FOXI_ASSERT(next == end, "row " << i << " filled " << next - first << " of " << end - first);
// A broken invariant is a bug in foxi, not a state a caller can handle: like assert(), it writes the
// condition, the place and the message to stderr and aborts (the one place a library writes).
#pragma once

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#if !defined(NDEBUG) || defined(FOXI_CHECKS) || defined(__SANITIZE_ADDRESS__)
#define FOXI_ASSERT_ACTIVE 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
#define FOXI_ASSERT_ACTIVE 1
#endif
#endif

namespace foxi::detail {

[[noreturn]] inline void assertion_failed(const char* condition, const char* file, int line,
                                          const std::string& message) {
  std::fprintf(stderr, "foxi: internal invariant broken: %s (%s) at %s:%d\n", message.c_str(), condition,
               file, line);
  std::fflush(stderr);
  std::abort();
}

}  // namespace foxi::detail

#ifdef FOXI_ASSERT_ACTIVE
#define FOXI_ASSERT(condition, message)                                                             \
  do {                                                                                              \
    if (!(condition)) {                                                                             \
      std::ostringstream foxi_assert_message_;                                                      \
      foxi_assert_message_ << message;                                                              \
      ::foxi::detail::assertion_failed(#condition, __FILE__, __LINE__, foxi_assert_message_.str()); \
    }                                                                                               \
  } while (0)
#else
// Not evaluated; sizeof keeps the names it uses "used" (no unused-variable warnings in Release).
#define FOXI_ASSERT(condition, message) \
  do {                                  \
    (void)sizeof((condition) ? 1 : 0);  \
  } while (0)
#endif
