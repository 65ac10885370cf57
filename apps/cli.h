// The gins command line: parses arguments and dispatches to the library. Kept thin and testable
// (tests call RunCli directly).
#pragma once

namespace gins {

// Returns the process exit code: 0 on success, 1 on bad input/config/run failure, 2 on usage errors.
// own_process: RunCli is the process's main (the `gins` executable): every command but `gins stream`
// then ends on SIGINT/SIGTERM at once, without leaving a half-written file (apps/interrupt.h).
int RunCli(int argc, const char* const* argv, bool own_process = false);

}  // namespace gins
