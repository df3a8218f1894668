// The mesher vocabulary shared by the TetGen and CGAL paths: why meshing failed, as a type.
//
// MesherFailure's values are TetGen's own return codes where TetGen has one (1 .. 5, 10), so a code
// that crosses the pipe from a mesher's child process (child_process.hpp) keeps its meaning; the
// others are foxi's. tetgen_code() is that integer, kept for the callers that still compare it.
#pragma once

#include <stdexcept>
#include <string>

#include "foxi/api.hpp"
#include "foxi/model/progress.hpp"

namespace foxi {

enum class MesherFailure : int {
  cancelled = -1,         // the caller's progress function said stop
  out_of_memory = 1,      // also: no pipe or process could be made
  internal_error = 2,     // the mesher failed in a way it does not explain (or its child died)
  self_intersection = 3,  // the PLC's facets cross
  feature_too_small = 4,  // a PLC feature below the mesher's tolerance
  facets_too_close = 5,   // two facets closer than the mesher can separate
  bad_input = 10,         // a PLC or parameter the mesher refuses; the message names the facet, seed or value
  time_limit = 20,        // stopped at its time limit (the message states the limit)
  crashed = 21,           // the mesher's child process died on a signal
};

// A short name of the failure ("bad input", "time limit", ...) for messages.
inline const char* failure_name(MesherFailure f) {
  switch (f) {
    case MesherFailure::cancelled:
      return "cancelled";
    case MesherFailure::out_of_memory:
      return "out of memory";
    case MesherFailure::internal_error:
      return "internal error";
    case MesherFailure::self_intersection:
      return "self-intersecting facets";
    case MesherFailure::feature_too_small:
      return "feature too small";
    case MesherFailure::facets_too_close:
      return "facets too close";
    case MesherFailure::bad_input:
      return "bad input";
    case MesherFailure::time_limit:
      return "time limit";
    case MesherFailure::crashed:
      return "crashed";
  }
  return "internal error";
}

// A PLC a mesher rejects, a mesh it cannot finish, or a cancelled run; what() says which and why.
class FOXI_API MesherError : public std::runtime_error {
 public:
  MesherError(MesherFailure failure, const std::string& message)
      : std::runtime_error(message), code_(static_cast<int>(failure)) {}
  // A TetGen return code (or another MesherFailure value as an integer).
  MesherError(int tetgen_code, const std::string& message)
      : std::runtime_error(message), code_(tetgen_code) {}
  int tetgen_code() const { return code_; }
  MesherFailure failure() const {
    switch (code_) {
      case -1:
      case 1:
      case 2:
      case 3:
      case 4:
      case 5:
      case 10:
      case 20:
      case 21:
        return static_cast<MesherFailure>(code_);
      default:
        return MesherFailure::internal_error;  // a TetGen code foxi does not know
    }
  }

 private:
  int code_;
};

// A run the progress function stopped: MesherFailure::cancelled, and a foxi::Cancelled.
struct FOXI_API MesherCancelled : MesherError, Cancelled {
  explicit MesherCancelled(const std::string& message) : MesherError(MesherFailure::cancelled, message) {}
};

// MesherError(code, message), as MesherCancelled when the code is MesherFailure::cancelled (a code
// that crossed the pipe from a mesher's child process, say).
[[noreturn]] inline void throw_mesher_error(int code, const std::string& message) {
  if (code == static_cast<int>(MesherFailure::cancelled)) throw MesherCancelled(message);
  throw MesherError(code, message);
}

}  // namespace foxi
