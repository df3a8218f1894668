// SIGINT, SIGTERM and SIGHUP for the foxi program: a stop leaves no helper process and no temporary
// file, only outputs that were complete, and exits 130 (SIGINT), 143 (SIGTERM) or 129 (SIGHUP) with a
// message.
#pragma once

#include <string>
#include <vector>

#include "foxi/model/run_program.hpp"

namespace foxi::cli {

// Call first in main, before any thread starts; `program` names the program in the message ("foxi
// render", "foxi-view"). foxi and foxi-view both compile this file. Blocks SIGINT, SIGTERM and SIGHUP in this
// thread and so in every thread and child started later (children are killed by foxi instead, so a terminal's
// Ctrl-C cannot make a child's death look like a mesher failure), and waits for them in a thread of its own.
// On one, that thread prints "PROGRAM: stopped by SIGINT ..." on stderr, kills the child processes and
// removes the temporary files (foxi/model/cleanup.hpp) and exits with kExitInterrupted or kExitTerminated.
// Work in progress is not unwound: the process ends at once, whatever it was doing, and the cleanup list's
// lock keeps a file from being renamed into place or a child from starting after the cleanup. If main returns
// while the stop is under way, the exit waits for it (an atexit handler), so that the status says "stopped",
// not whatever the stop did to the work.
void handle_stop_signals(const std::string& program);

// Runs a program as a tracked child (killed on a stop): foxi/model/run_program.hpp's runner.
using foxi::run_program;

}  // namespace foxi::cli
