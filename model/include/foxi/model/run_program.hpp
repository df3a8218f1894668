// Running another program (ccx, foxi solve for a sweep's run) as a child process that a stop or a user's
// Cancel kills: the one child-process runner of foxi and its hosts (the foxi CLI and the workbench).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "foxi/api.hpp"

namespace foxi {

// run_program's status when `keep_going` said stop: the child was killed and reaped.
inline constexpr int kProgramCancelled = -2;

// Runs a program (argv[0] looked up in PATH) with stdin from /dev/null as a tracked child
// (cleanup.hpp: killed by cleanup::interrupt(), and by the kernel when this process dies) and waits
// for it; returns its exit status, or -1 if it could not be run or died on a signal. A non-empty
// `output` gets the program's stdout and stderr (created or truncated); a non-empty `stdout_to` then
// takes its stdout alone. `keep_going` (when given) is asked about every 50 ms while the program
// runs, on the calling thread: false kills it (SIGKILL) and returns kProgramCancelled. Only
// async-signal-safe calls run between the fork and the exec, so a multithreaded host may call it.
FOXI_API int run_program(const std::vector<std::string>& argv, const std::string& output = {},
                         const std::string& stdout_to = {}, const std::function<bool()>& keep_going = {});

}  // namespace foxi
