#include "apps/interrupt.h"

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <thread>

#include "core/io/trajectory_writer.h"

namespace gins {

void RemoveUnfinishedFilesOnInterrupt() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  if (pthread_sigmask(SIG_BLOCK, &signals, nullptr) != 0) return;  // the default action stays
  std::thread([signals] {
    int sig = 0;
    if (sigwait(&signals, &sig) != 0) return;
    const size_t removed = AbandonUncommittedFiles();
    std::fprintf(stderr, "gins: interrupted by %s: %zu unfinished output file%s removed\n",
                 sig == SIGINT ? "SIGINT" : "SIGTERM", removed, removed == 1 ? "" : "s");
    std::fflush(stderr);
    _exit(128 + sig);
  }).detach();
}

}  // namespace gins
