// gins_example CONFIG LOG [eskf|smoother]: reads a gins log through the public API and prints one line per
// state: time, position (ENU and geodetic), speed, heading and horizontal 1-σ; a status line on stderr.
#include <gins/gins.h>

#include <cmath>
#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: %s CONFIG LOG [eskf|smoother]\n", argv[0]);
    return 2;
  }
  gins::api::SessionOptions options;
  if (argc == 4 && (!gins::api::ParseMode(argv[3], &options.mode) || options.mode == gins::api::Mode::kBoth)) {
    std::fprintf(stderr, "unknown mode '%s'\n", argv[3]);
    return 2;
  }
  try {
    const gins::api::Config config = gins::api::Config::FromFile(argv[1]);
    gins::api::Session session(config, options);
    // The smoother also has an online stream; print its final estimate only.
    const gins::api::Stream wanted =
        options.mode == gins::api::Mode::kEskf ? gins::api::Stream::kEskf : gins::api::Stream::kSmoother;
    session.OnState([wanted](const gins::api::State& s) {
      if (s.stream != wanted) return;
      std::printf("%.3f %.3f %.3f %.3f %.9f %.9f %.3f %.3f %.2f %.3f\n", s.t, s.p_enu[0], s.p_enu[1], s.p_enu[2],
                  s.lla[0], s.lla[1], s.lla[2], std::hypot(s.v_enu[0], s.v_enu[1]), gins::api::HeadingDeg(s),
                  std::hypot(s.sigma_p[0], s.sigma_p[1]));
    });
    // A driver would push gins::api::Imu, Wheel, Gnss and GnssVelocity structs as they arrive; here they
    // come from a log file.
    gins::api::LogReader log(argv[2], config);
    gins::api::Record record;
    while (log.Next(&record)) session.Push(record);
    session.Finish();

    const gins::api::Status status = session.status();
    std::fprintf(stderr, "gins_example: gins %s, %llu measurements, %llu states, %llu rejected:", gins::api::Version(),
                 static_cast<unsigned long long>(status.accepted), static_cast<unsigned long long>(status.states),
                 static_cast<unsigned long long>(status.rejected));
    for (const gins::api::Rejection& r : status.rejections) {
      std::fprintf(stderr, " %s.%s.%s=%llu", r.source.c_str(), r.measurement.c_str(), r.reason.c_str(),
                   static_cast<unsigned long long>(r.count));
    }
    std::fprintf(stderr, "\n");
    return 0;
  } catch (const gins::api::Error& e) {
    std::fprintf(stderr, "gins_example: %s\n", e.what());
    return 1;
  }
}
