// Progress reporting and cancellation, shared by the mesher, the solver and the renderer.
#pragma once

#include <functional>
#include <string_view>

#include "foxi/api.hpp"

namespace foxi {

// Called with the stage name and the fraction done in [0, 1]; returns false to cancel.
using ProgressFn = std::function<bool(std::string_view stage, double fraction)>;

// The one outcome of a progress function returning false, whichever library it stopped: what each
// library throws then (StructureCancelled, MesherCancelled, SolverCancelled, MovieCancelled) derives
// from Cancelled as well as from that library's own error type, so a host catches
// `const foxi::Cancelled&` for all of them while the catches by library error type (SolverError,
// MesherError, std::runtime_error) still see them. Cancelled is not a std::exception itself, so
// that each of those is one std::exception, unambiguously (a catch of std::exception still works);
// what() is the std::exception's.
struct FOXI_API Cancelled {
  virtual ~Cancelled() = default;
};

}  // namespace foxi
