#include "core/imu_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gins {
namespace {

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

std::string Format(const char* format, double a, double b) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), format, a, b);
  return buf;
}

}  // namespace

void ImuAxesAndUnitsCheck::Add(const Vec3& acc_b) {
  // An all-zero reading is a sensor not yet running (some loggers write them at power-up), not a unit.
  if (judged_ || norm_.size() >= kSamples || !acc_b.allFinite() || acc_b.isZero(0.0)) return;
  norm_.push_back(acc_b.norm());
  up_.push_back(acc_b.z());
}

ImuAxesAndUnitsCheck::Outcome ImuAxesAndUnitsCheck::Judge(bool land_vehicle) {
  if (judged_) return outcome_;
  if (norm_.size() < kSamples) return Outcome::kPending;
  judged_ = true;
  const double g = kStandardGravity;
  const double f = Median(norm_), up = Median(up_);
  outcome_ = Outcome::kOk;
  if (f < 0.5 * g || f > 1.5 * g) {
    outcome_ = Outcome::kRefuse;
    if (f > 0.8 && f < 1.2) {
      message_ = Format("the accelerometer reads |f| = %.3f over the first IMU records where gravity alone is "
                        "%.2f m/s²: its columns (ax ay az) are in g, not m/s² (multiply them by 9.80665)",
                        f, g);
    } else {
      message_ = Format("the accelerometer reads |f| = %.4g over the first IMU records where gravity alone is "
                        "%.2f m/s²: the columns are not t gx gy gz ax ay az in rad/s and m/s² (another unit, or "
                        "the gyro and accelerometer columns swapped)",
                        f, g);
    }
    return outcome_;
  }
  if (up < -0.5 * g) {
    outcome_ = land_vehicle ? Outcome::kRefuse : Outcome::kWarn;
    message_ = Format("the accelerometer's z axis reads %.2f m/s² over the first IMU records (+%.2f for z up): "
                      "the IMU's axes point z down (forward-right-down?) and imu.axes does not say so; set "
                      "imu.axes (FRD, RFU or a rotation) to map them into forward-left-up",
                      up, g);
    if (!land_vehicle) message_ += " (a vehicle that can be upside down: vehicle.nonholonomic is false, so it runs)";
  }
  return outcome_;
}

}  // namespace gins

namespace gins {

void TurnRateCheck::AddImu(double t, const Vec3& gyro_b, const Vec3& acc_b) {
  if (outcome_ != Outcome::kPending || !gyro_b.allFinite() || !acc_b.allFinite()) return;
  up_b_ = 0.99 * up_b_ + 0.01 * acc_b;  // about a second at 100 Hz: gravity, the accelerations averaged out
  if (last_imu_t_ >= 0.0 && t > last_imu_t_ && t - last_imu_t_ < 1.0 && up_b_.norm() > 0.0) {
    yaw_integral_ += gyro_b.dot(up_b_.normalized()) * (t - last_imu_t_);
  }
  last_imu_t_ = t;
}

void TurnRateCheck::AddFix(double t, const Vec3& p_w, double sigma_h) {
  if (outcome_ != Outcome::kPending || !p_w.allFinite() || last_imu_t_ < 0.0) return;
  const Fix f{t, yaw_integral_, p_w, sigma_h};
  if (fixes_.empty()) {
    fixes_.push_back(f);
    return;
  }
  const Fix& a = fixes_.front();
  const Vec3 d = f.p_w - a.p_w;
  const double step = d.head<2>().norm();
  if (t - a.t > 5.0) {  // too slow (or a gap) for a course: start again from here
    fixes_ = {f};
    have_course_ = false;
    return;
  }
  if (step < std::max(kMinStep, 10.0 * std::max(a.sigma_h, sigma_h))) return;
  const double course = std::atan2(d.y(), d.x());
  const double mid_yaw = 0.5 * (a.yaw_integral + f.yaw_integral);
  if (have_course_) {
    const double dc = WrapAngle(course - course_), dg = mid_yaw - course_mid_yaw_;
    if (std::abs(dc) < 0.5 * kPi) {
      s_cg_ += dc * dg;
      s_gg_ += dg * dg;
      s_cc_ += dc * dc;
      turned_ += std::abs(dg);  // the gyro's turning: the courses of metre-level fixes turn by their noise too
      ++pairs_;
    }
  }
  have_course_ = true;
  course_ = course;
  course_mid_yaw_ = mid_yaw;
  fixes_ = {f};
  if (turned_ >= kDecideTurn && pairs_ >= kMinPairs) Decide();
}

void TurnRateCheck::Decide() {
  if (s_gg_ <= 0.0 || s_cc_ <= 0.0) return;
  const double correlation = s_cg_ / std::sqrt(s_gg_ * s_cc_);
  if (std::abs(correlation) < kMinCorrelation) return;  // the turns say too little yet
  const double k = slope();
  const auto near = [k](double want) { return std::abs(k / want - 1.0) < 0.25; };
  if (near(1.0)) {
    outcome_ = Outcome::kOk;
    return;
  }
  outcome_ = Outcome::kRefuse;
  char buf[512];
  const bool mirrored = correlation < 0.0;  // a car's course cannot turn against its yaw
  if (!mirrored && !near(kDegToRad)) {
    // Neither of the two mistakes it can name: metre-level fixes' correlated errors bend short courses
    // (a legitimate single-point drive gave 2.3), so nothing is refused on a guess; it keeps watching.
    outcome_ = Outcome::kPending;
    return;
  }
  if (mirrored) {
    std::snprintf(buf, sizeof(buf),
                  "the GNSS track turns the other way from the gyro (course change %.2f × the gyro's): latitude "
                  "and longitude swapped in the GNSS records (columns t lat lon), or a mirrored gyro axis "
                  "(imu.axes)",
                  k);
  } else {
    std::snprintf(buf, sizeof(buf),
                  "the gyro turns %.1f× more than the GNSS track: its columns (gx gy gz) are in deg/s, not rad/s "
                  "(multiply them by 0.0174533)",
                  1.0 / k);
  }
  message_ = buf;
}

}  // namespace gins

namespace gins {

namespace {

// The mean of two yaws (rad), on the circle.
double MeanYaw(double a, double b) { return WrapAngle(a + 0.5 * WrapAngle(b - a)); }

}  // namespace

void HeadingCourseCheck::AddFix(double t, const Vec3& p_w, double sigma_h, double heading_deg, double mount_yaw) {
  if (outcome_ != Outcome::kPending || !p_w.allFinite() || !std::isfinite(heading_deg)) return;
  const Fix f{t, p_w, sigma_h, heading_deg};
  if (!have_anchor_ || t - anchor_.t > 5.0 || t <= anchor_.t) {  // too slow (or a gap) for a course
    anchor_ = f;
    have_anchor_ = true;
    return;
  }
  const Vec3 d = f.p_w - anchor_.p_w;
  if (d.head<2>().norm() < std::max(kMinStep, 10.0 * std::max(anchor_.sigma_h, sigma_h))) return;
  const double course = std::atan2(d.y(), d.x());
  // The course unwrapped, and its range over the chords kept (the courses' noise does not add up in it).
  unwrapped_ = have_course_ ? unwrapped_ + WrapAngle(course - last_course_) : 0.0;
  if (!have_course_ || d_deg_.empty()) low_ = high_ = unwrapped_;
  low_ = std::min(low_, unwrapped_);
  high_ = std::max(high_, unwrapped_);
  have_course_ = true;
  last_course_ = course;
  const auto offset = [&](double scale) {
    const double yaw =
        MeanYaw(CompassDegToEnuYaw(scale * anchor_.heading_deg), CompassDegToEnuYaw(scale * heading_deg));
    return WrapAngle(yaw - mount_yaw - course);
  };
  d_deg_.push_back(offset(1.0));
  d_rad_.push_back(offset(kRadToDeg));
  anchor_ = f;
  if (pairs() >= kPairs) Decide(mount_yaw);
}

void HeadingCourseCheck::Decide(double mount_yaw) {
  const auto within = [](const std::vector<double>& d) {
    int n = 0;
    for (double x : d) n += std::abs(x) < kTolerance;
    return n;
  };
  const int need = (4 * pairs() + 4) / 5;  // 80 %
  // The offsets' circular mean and spread (1 − mean resultant length ≈ σ²/2).
  double c = 0.0, s = 0.0;
  for (double x : d_deg_) c += std::cos(x), s += std::sin(x);
  const double mean = std::atan2(s, c), resultant = std::hypot(c, s) / pairs();
  const double spread = std::sqrt(std::max(0.0, 2.0 * (1.0 - resultant)));
  char buf[512];
  if (within(d_deg_) >= need) {
    outcome_ = Outcome::kOk;
  } else if (within(d_rad_) >= need) {
    outcome_ = Outcome::kRefuse;
    message_ = "the dual-antenna headings are in radians, not degrees (the GNSS records' heading column; multiply "
               "it by 57.2958)";
  } else if (spread < 0.5 * kTolerance && std::abs(mean) < 150.0 * kDegToRad) {
    if (high_ - low_ < kMinTurn) {  // keep the newest chords: the turns to come decide
      if (pairs() > 4 * kPairs) {
        d_deg_.erase(d_deg_.begin(), d_deg_.begin() + 2 * kPairs);
        d_rad_.erase(d_rad_.begin(), d_rad_.begin() + 2 * kPairs);
        low_ = high_ = unwrapped_;  // conservatively: the range from here
      }
      return;
    }
    outcome_ = Outcome::kRefuse;
    std::snprintf(buf, sizeof(buf),
                  "the dual-antenna heading is %.1f° off the GNSS track's course on straight and turning stretches "
                  "alike: gnss.mount_yaw_deg (%.2f) should be about %.2f",
                  mean * kRadToDeg, mount_yaw * kRadToDeg, (mount_yaw + mean) * kRadToDeg);
    message_ = buf;
  } else {
    d_deg_.clear();  // manoeuvres or reversing: judge the next chords afresh
    d_rad_.clear();
  }
}

}  // namespace gins
