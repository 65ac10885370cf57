// Ctrl-C in the commands that write their files at the end (all but `gins stream`, which ends its input on
// a signal instead): SIGINT or SIGTERM removes the files not yet committed (core/io/trajectory_writer.h:
// AbandonUncommittedFiles) and ends the process at once with exit code 128 + the signal, saying so on
// stderr. An interrupted `gins run` leaves no half-written file, and none of a run's files if it had not
// begun to commit them (a CommitGroup), all of them if it had.
#pragma once

namespace gins {

// From the main thread, before any other thread starts: the signals are blocked in every thread (the mask
// is inherited) and a thread of its own waits for them. For the `gins` executable only (tests call RunCli
// in their own process).
void RemoveUnfinishedFilesOnInterrupt();

}  // namespace gins
