// The exit statuses of every foxi command: one table, documented in the README ("Exit status").
#pragma once

namespace foxi::cli {

enum ExitCode : int {
  kExitOk = 0,             // done; every printed result passed its own checks
  kExitFailure = 1,        // the work failed (mesher, solver or writer gave up; out of memory; I/O)
  kExitUsage = 2,          // the command line is wrong (unknown option, missing value, bad syntax)
  kExitBadInput = 3,       // an input file, model or parameter is invalid (the message names it)
  kExitUnreliable = 4,     // a result was computed but failed its own checks (figures printed)
  kExitHangup = 129,       // stopped by SIGHUP (the terminal closed); nothing partial left behind
  kExitInterrupted = 130,  // stopped by SIGINT (Ctrl-C); nothing partial left behind
  kExitTerminated = 143,   // stopped by SIGTERM; nothing partial left behind
};

}  // namespace foxi::cli
