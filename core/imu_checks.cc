#include "core/imu_checks.h"

#include <algorithm>
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
  if (judged_ || norm_.size() >= kSamples || !acc_b.allFinite()) return;
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
