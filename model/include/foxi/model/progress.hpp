// Progress reporting and cancellation, shared by the mesher, the solver and the renderer.
#pragma once

#include <functional>
#include <string_view>

namespace foxi {

// Called with the stage name and the fraction done in [0, 1]; returns false to cancel.
using ProgressFn = std::function<bool(std::string_view stage, double fraction)>;

}  // namespace foxi
