// The vehicle's constraints and the wheels in the smoother's window (core/wheel_model.h,
// core/odometry_model.h), every one checked against the window's prediction before it is attached:
// - the non-holonomic constraint (vehicle.nonholonomic), a constraint of the vehicle whether or not the log
//   has wheels: at each keyframe (the rear-axle centre's sideways and vertical speed, with the lever arm and
//   the body rate) and over each interval between keyframes (the axle's chord along the path its body x
//   axis traced, from the IMU's attitude and the predicted speed at every step: the constraint integrated
//   over the interval, with the σ of the mean of vehicle.nhc_rate_hz white samples, the information the
//   ESKF's updates at that rate carry);
// - the odometer: every encoder record between two keyframes, integrated into a displacement in the
//   earlier keyframe's body frame (each record's distance along the preintegrated attitude at its middle; a
//   record that straddles a keyframe split between the two intervals), compared with the axle's
//   displacement along it with the odometer scale; an interval the records do not cover (the wheels
//   stopped reporting) gives no factor;
// - the wheels' yaw: the left/right difference over the track summed over the same interval, against the
//   turn between the two keyframes (wheel.track_m > 0).
#pragma once

#include <optional>

#include "solver/smoother_attachers.h"

namespace gins {

class VehicleAttacher final : public AttacherOf<WheelMeasurement> {
 public:
  explicit VehicleAttacher(const SensorOptions& options);  // wheel.*, vehicle.*; imu.* for the chord's gate

  // False: the records join the interval's odometer factor at the next keyframe.
  bool On(const WheelMeasurement& m, const AttachContext& ctx) override;
  void OnImuStep(const ImuStepView& step) override;
  void OnKeyframeCreated(Keyframe& kf, const AttachContext& ctx) override;
  void OnWindowRebuilt() override;
  void AddStats(nlohmann::json* stats) const override;

 private:
  // The encoders' records over one interval between keyframes, from keyframe `from` on.
  struct Accumulator {
    uint64_t from = 0;
    double t0 = 0.0;
    Vec3 displacement = Vec3::Zero();  // in the body frame at `from`, m
    double var_distance = 0.0;          // m²
    double yaw = 0.0, var_yaw = 0.0;     // rad, rad²
    double covered = 0.0;               // s of the interval the records cover
    bool has_yaw = false;
  };
  void Add(Accumulator* acc, const WheelMeasurement& m, double fraction, const Quat& dR_mid);
  void AttachNonHolonomic(Keyframe& kf, const AttachContext& ctx);
  void AttachChord(Keyframe& prev, Keyframe& kf, const AttachContext& ctx);
  // The odometer and wheel-yaw factors of the closed interval between the two keyframes before kf.
  void AttachOdometry(const AttachContext& ctx);

  SensorOptions options_;
  double gate_nhc_, gate_wheel_, gate_yaw_;
  std::optional<Accumulator> open_;     // from the newest keyframe to now
  std::optional<Accumulator> closing_;  // the interval before it, until the record that straddles its end
  std::optional<double> closing_t1_;    // that interval's end
  Vec3 path_ = Vec3::Zero();            // the axle's path P_i from the newest keyframe (core/odometry_model.h)
  MeasurementCounts nhc_counts_, chord_counts_, odometer_counts_, yaw_counts_;
  uint64_t wheel_records_ = 0;
};

}  // namespace gins
