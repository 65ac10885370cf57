// `gins stream`: records on stdin, each state on stdout as soon as it is estimated, through the public API
// (gins/gins.h) like `gins run`, so the numbers are the same; for live data and pipelines.
#pragma once

#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

namespace gins {

struct StreamRequest {
  std::string config_path;
  std::string mode = "eskf";       // eskf | smoother
  std::string out_format = "tum";  // tum | csv | lla: the lines of `gins run`'s <stream>.tum, _states.csv,
                                   // _lla.csv; nmea: `gins export`'s sentences (docs/formats.md §5.7)
  double rate_hz = 1.0;            // nmea: epochs per second (0: every state)
  std::string time_scale = "gps";  // nmea: what the log's times count
  bool online = false;             // smoother: its causal estimate (smoother_online), not its final one
};

// Adds the `stream` subcommand to `app`, parsing into *req.
CLI::App* AddStreamCommand(CLI::App& app, StreamRequest* req);

// Reads in_fd to its end (or to SIGINT / SIGTERM, which end the input after its last complete line), writes
// to out, flushed after every line, and a one-line report to stderr. Returns the exit code: 0 at the end of
// the input or on a signal (what was read is processed and written), 1 for bad config or input or no
// solution (one line on stderr, as `gins run`).
int RunStream(const StreamRequest& req, int in_fd, std::FILE* out);

}  // namespace gins
