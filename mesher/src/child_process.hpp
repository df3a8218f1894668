// Internal to foxi_mesher: running a mesher in a child process, so that a crash or an abort inside a
// third-party library becomes a MesherError and a user can cancel it (the child is killed).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "foxi/model/progress.hpp"

namespace foxi::detail {

// Runs `work` in a forked child and returns the bytes it returned. A MesherError or other exception
// thrown in the child is thrown again here as MesherError (same code and message; 2 for others); a
// child that dies gives MesherError(2, "<what> crashed (signal N)"). While waiting, `progress(stage, -1)`
// is asked every 100 ms; false kills the child and throws MesherCancelled (a MesherError with
// MesherFailure::cancelled). `work` must not rely on other threads of the caller (a forked child has only the
// calling thread).
std::vector<char> run_in_child(const std::function<std::vector<char>()>& work, const ProgressFn& progress,
                               const std::string& stage, const std::string& what);

}  // namespace foxi::detail
