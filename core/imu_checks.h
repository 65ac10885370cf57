// The IMU's units and axes checked from its first samples, before anything is estimated (docs/robustness.md,
// "Sanity checks"): a log written in the wrong units or axes must not give a trajectory that looks fine.
//   |f| far from g (the median over the first kSamples, outside [0.5, 1.5]·g): no vehicle accelerates that
//       hard for that long. About 1: the accelerometer columns are in g; else another unit or the gyro and
//       accelerometer columns swapped. Refused: the data cannot be used as they are.
//   f_z < −0.5·g (the median): the body z axis points down, i.e. the IMU's axes are FRD-like and imu.axes
//       does not say so. Refused for a car (vehicle.nonholonomic: a car is not upside down); a warning for
//       others (a drone or a hand-held unit may start so).
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/conventions.h"

namespace gins {

class ImuAxesAndUnitsCheck {
 public:
  static constexpr size_t kSamples = 200;

  enum class Outcome { kPending, kOk, kWarn, kRefuse };

  // A sample's specific force in body axes (after imu.axes). Ignored once judged.
  void Add(const Vec3& acc_b);
  // kPending until kSamples have come; then the verdict (and message() says why when not kOk).
  Outcome Judge(bool land_vehicle);
  const std::string& message() const { return message_; }

 private:
  std::vector<double> norm_, up_;
  bool judged_ = false;
  Outcome outcome_ = Outcome::kPending;
  std::string message_;
};

}  // namespace gins

namespace gins {

// The gyro's turning against the GNSS track's (docs/robustness.md), for a car (vehicle.nonholonomic: it
// drives along its body x, so its yaw turns with its course). Over successive fixes the course change Δc
// (from the track between fixes at least kMinStep and 10 σ apart) is regressed on the gyro's integrated rate
// about gravity Δg over the same time: Δc = k·Δg. Decided once the vehicle has turned kDecideTurn in all
// by the gyro (its integral, not the courses, which turn by the fixes' noise too) over at least kMinPairs
// course changes, with a correlation above kMinCorrelation in size:
//   k ≈ 1 (within 25 %): ok;
//   k < 0: the track turns the other way (latitude and longitude swapped, which also stretches it: about −1.5
//          at 31° N, 60° E; or a mirrored gyro axis): refused;
//   k ≈ 1/57.3: the gyro columns are in deg/s: refused;
//   any other k: still watching (short courses of metre-level fixes bend: nothing is refused on a guess).
class TurnRateCheck {
 public:
  static constexpr double kMinStep = 1.0;                 // m between the fixes a course comes from
  static constexpr double kDecideTurn = 45.0 * kDegToRad;  // course turned in all before a verdict
  static constexpr double kMinCorrelation = 0.9;
  static constexpr int kMinPairs = 10;  // course changes before a verdict

  enum class Outcome { kPending, kOk, kRefuse };

  void AddImu(double t, const Vec3& gyro_b, const Vec3& acc_b);
  // A fix: its position in w (east, north) and horizontal 1-σ (m).
  void AddFix(double t, const Vec3& p_w, double sigma_h);
  Outcome outcome() const { return outcome_; }
  const std::string& message() const { return message_; }
  double slope() const { return s_gg_ > 0.0 ? s_cg_ / s_gg_ : 0.0; }
  double turned() const { return turned_; }  // rad the gyro turned over the course changes used so far
  double correlation() const { return s_gg_ > 0.0 && s_cc_ > 0.0 ? s_cg_ / std::sqrt(s_gg_ * s_cc_) : 0.0; }

 private:
  void Decide();

  Vec3 up_b_ = Vec3::Zero();  // running mean of the specific force: gravity's direction in b
  double last_imu_t_ = -1.0, yaw_integral_ = 0.0;
  struct Fix {
    double t, yaw_integral;
    Vec3 p_w;
    double sigma_h;
  };
  std::vector<Fix> fixes_;  // the anchor fix of the current course and the newest
  bool have_course_ = false;
  double course_ = 0.0, course_mid_yaw_ = 0.0;
  double s_cg_ = 0.0, s_gg_ = 0.0, s_cc_ = 0.0, turned_ = 0.0;
  int pairs_ = 0;
  Outcome outcome_ = Outcome::kPending;
  std::string message_;
};

}  // namespace gins

namespace gins {

// The dual-antenna heading against the GNSS track's course, for a car (docs/robustness.md; its yaw is
// its course, sideslip a few degrees). Over successive fixes with a valid heading at least kMinStep and 10 σ
// apart (within 5 s), the chord's course is compared with the mean of the two headings less the mount
// (gnss.mount_yaw_deg): d = heading − mount − course. After kPairs such chords:
//   most |d| within kTolerance: ok;
//   most within it once the logged headings are read as radians: refused (the column is in radians);
//   one offset for all (spread under kTolerance / 2, not the 180° of reversing) once the course has
//       spanned kMinTurn over those chords (on a straight road a constant offset may be a stuck heading): refused,
//       naming gnss.mount_yaw_deg and the offset measured;
//   anything else (reversing, manoeuvres, a poor heading): still watching, from the next chords.
class HeadingCourseCheck {
 public:
  static constexpr int kPairs = 20;
  static constexpr double kMinStep = 2.0;                   // m
  static constexpr double kTolerance = 10.0 * kDegToRad;   // rad
  static constexpr double kMinTurn = 45.0 * kDegToRad;     // rad of course change before a mount verdict

  enum class Outcome { kPending, kOk, kRefuse };

  // A fix with a valid heading: its position in w (east, north), horizontal 1-σ (m), the heading as logged
  // (deg clockwise from north) and the configured mount yaw (rad).
  void AddFix(double t, const Vec3& p_w, double sigma_h, double heading_deg, double mount_yaw);
  Outcome outcome() const { return outcome_; }
  const std::string& message() const { return message_; }
  int pairs() const { return static_cast<int>(d_deg_.size()); }

 private:
  void Decide(double mount_yaw);

  struct Fix {
    double t;
    Vec3 p_w;
    double sigma_h, heading_deg;
  };
  bool have_anchor_ = false;
  Fix anchor_{};
  // d per chord, with the headings read as logged (degrees) and as radians.
  std::vector<double> d_deg_, d_rad_;
  bool have_course_ = false;
  double last_course_ = 0.0, unwrapped_ = 0.0;
  double low_ = 0.0, high_ = 0.0;  // the unwrapped course's range over the chords kept
  Outcome outcome_ = Outcome::kPending;
  std::string message_;
};

}  // namespace gins
