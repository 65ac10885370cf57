// The IMU's units and axes checked from its first samples, before anything is estimated (README "Sanity
// checks"): a log written in the wrong units or axes must not give a trajectory that looks fine.
//   |f| far from g (the median over the first kSamples, outside [0.5, 1.5]·g): no vehicle accelerates that
//       hard for that long. About 1: the accelerometer columns are in g; else another unit or the gyro and
//       accelerometer columns swapped. Refused: the data cannot be used as they are.
//   f_z < −0.5·g (the median): the body z axis points down, i.e. the IMU's axes are FRD-like and imu.axes
//       does not say so. Refused for a car (vehicle.nonholonomic: a car is not upside down); a warning for
//       others (a drone or a hand-held unit may start so).
#pragma once

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
