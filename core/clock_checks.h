// A whole-second offset between the GNSS and the IMU clocks (docs/robustness.md): leap seconds (GPS
// time against UTC: 18 s since 2017), a GPS/TAI mix-up, a logger stamping one stream a second off. For a car
// (vehicle.nonholonomic: its forward specific force is its speed's rate, on a level road), the IMU's forward
// specific force and the GNSS track's acceleration, each averaged per second of its own stamps, are
// correlated at every whole-second lag within ±kMaxLag. Decided once kMinSeconds of driving with
// accelerations of at least kMinAccStd (RMS) overlap:
//   the best lag 0, or no lag correlating above kMinCorrelation: ok / still watching;
//   a lag L ≠ 0 above kMinCorrelation and kSigmas standard errors ((1 − r²)/√n) above lag 0's: refused,
//       naming gnss.time_offset_s: L.
// Latency below a second is the time-offset state's (gnss.time_offset_s: estimate), not this check's.
#pragma once

#include <map>
#include <string>
#include <utility>

#include "core/conventions.h"

namespace gins {

class ClockOffsetCheck {
 public:
  static constexpr int kMaxLag = 60;            // s
  static constexpr int kMinSeconds = 60;        // overlapping seconds of driving before a verdict
  static constexpr double kMinAccStd = 0.3;     // m/s², RMS of the track's acceleration over them
  static constexpr double kMinCorrelation = 0.8;
  static constexpr double kSigmas = 5.0;  // lag 0 this many standard errors below the best before a refusal

  enum class Outcome { kPending, kOk, kRefuse };

  void AddImu(double t, const Vec3& acc_b);
  // A fix: its position in w and horizontal 1-σ (m).
  void AddFix(double t, const Vec3& p_w, double sigma_h);
  Outcome outcome() const { return outcome_; }
  const std::string& message() const { return message_; }
  // The correlation at a lag (GNSS stamps minus IMU stamps, s) over the seconds seen so far.
  double Correlation(int lag) const;

 private:
  void Decide();
  std::pair<double, size_t> CorrelationAndCount(int lag) const;

  struct Bin {
    double sum = 0.0;
    int n = 0;
  };
  std::map<long long, Bin> imu_, gnss_;  // per whole second of each stream's stamps (only the newest kept)
  Bin* imu_bin_ = nullptr;                // the IMU's current second's bin (map nodes do not move)
  long long imu_second_ = 0;
  bool have_fix_ = false, have_speed_ = false;
  double fix_t_ = 0.0, speed_t_ = 0.0, speed_ = 0.0;
  Vec3 fix_p_ = Vec3::Zero();
  long long next_decision_ = 0;
  Outcome outcome_ = Outcome::kPending;
  std::string message_;
};

}  // namespace gins
