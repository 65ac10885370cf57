// How measurements become factors in the smoother's window: one attacher per measurement type behind one
// interface, called by the smoother at fixed moments. A new measurement type (GNSS velocity, an odometer
// integrating every wheel reading, NHC at its own rate, ...) is a new attacher added to the smoother's list;
// the others do not change.
//
// The attachers here:
// - GnssAttacher: position (Cauchy loss) and dual-antenna heading on the keyframe at the fix's epoch; after
//   the solve a χ² check of the position residual, a failing fix removed and the window solved again.
// - WheelAttacher: the wheel speed (moved to the keyframe's time with the IMU's forward acceleration) and,
//   if configured, the non-holonomic constraint, on the newest keyframe within the reading's interval.
// - StandstillAttacher: from the session's detector, a zero-velocity factor on each keyframe inside a
//   standstill (not above standstill.max_speed_m_s), checked by χ² after the solve; a zero-motion factor (no
//   translation, 0.1 mm; no rotation, the gyro noise over the interval) between consecutive confirmed
//   keyframes of one standstill, which with the IMU factor observes the gyro bias.
#pragma once

#include <ceres/loss_function.h>

#include <functional>
#include <map>
#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "solver/estimator.h"
#include "solver/keyframe.h"

namespace gins {

// What the smoother lends an attacher: the window (its problem, factors with first-estimate Jacobians) and
// what it needs of the IMU stream.
struct AttachContext {
  KeyframeStore& keyframes;
  const Vec3& g_w;                           // gravity in w
  const std::optional<ImuSample>& last_imu;  // the latest IMU sample, if any
};

class MeasurementAttacher {
 public:
  virtual ~MeasurementAttacher() = default;

  // A measurement arrived (the smoother is initialised). For GNSS the smoother's keyframe policy has run:
  // the newest keyframe is at the fix's epoch; returns true if a factor was attached (the window is then
  // solved).
  virtual bool OnGnss(const GnssMeasurement& /*m*/, const AttachContext& /*ctx*/) { return false; }
  virtual void OnWheel(const WheelMeasurement& /*m*/, const AttachContext& /*ctx*/) {}
  virtual void OnStandstill(const StandstillMeasurement& /*m*/, const AttachContext& /*ctx*/) {}
  virtual void OnGvel(const GvelMeasurement& /*m*/, const AttachContext& /*ctx*/) {}
  // A keyframe became the newest, with its IMU and random-walk factors.
  virtual void OnKeyframeCreated(Keyframe& /*kf*/, const AttachContext& /*ctx*/) {}
  // After a solve, in attacher order: the checks of what was attached. True if the problem changed, so
  // that the window must be solved again before the next attacher's check.
  virtual bool AfterSolve(const AttachContext& /*ctx*/) { return false; }
  // The oldest keyframe leaves the window; its factors are gone already.
  virtual void OnKeyframeLeaving(const Keyframe& /*kf*/) {}
  // The watchdog rebuilt the window from a fresh prior: nothing attached before is in it.
  virtual void OnWindowRebuilt() {}
  // The attacher's entries of Smoother::Stats.
  virtual void AddStats(nlohmann::json* /*stats*/) const {}
};

class GnssAttacher final : public MeasurementAttacher {
 public:
  // on_checked(t, accepted): each fix's outcome of the χ² check, for the smoother's watchdog.
  GnssAttacher(const EstimatorOptions& options, std::function<void(double t, bool accepted)> on_checked);

  bool OnGnss(const GnssMeasurement& m, const AttachContext& ctx) override;
  bool AfterSolve(const AttachContext& ctx) override;
  void OnKeyframeLeaving(const Keyframe& kf) override { records_.erase(kf.id); }
  void OnWindowRebuilt() override { records_.clear(); }
  void AddStats(nlohmann::json* stats) const override;

 private:
  struct Record {
    ceres::ResidualBlockId position_id = nullptr;
    bool checked = false;
  };
  EstimatorOptions options_;
  std::function<void(double, bool)> on_checked_;
  double gate_;  // χ² gate on the whitened position residual (3 dof)
  std::unique_ptr<ceres::LossFunction> loss_;
  std::map<uint64_t, Record> records_;  // by keyframe id
  MeasurementCounts position_counts_, heading_counts_;
};

class WheelAttacher final : public MeasurementAttacher {
 public:
  explicit WheelAttacher(const EstimatorOptions& options) : options_(options) {}

  void OnWheel(const WheelMeasurement& m, const AttachContext& ctx) override;
  void OnKeyframeCreated(Keyframe& kf, const AttachContext& ctx) override { Attach(kf, ctx); }
  // The last reading is kept across a rebuild: the new keyframe may take it.
  void OnWindowRebuilt() override { attached_to_.reset(); }
  void AddStats(nlohmann::json* stats) const override;

 private:
  void Attach(Keyframe& kf, const AttachContext& ctx);

  EstimatorOptions options_;
  std::optional<WheelMeasurement> last_wheel_;
  // The keyframe with the wheel factor, if any. Factors go to the newest keyframe only, so one id is all
  // the memory needed.
  std::optional<uint64_t> attached_to_;
  MeasurementCounts counts_;
};

// GNSS velocity on the keyframe of its epoch (made for the fix of that epoch); without one it is not used
// (counted: no_keyframe).
class GvelAttacher final : public MeasurementAttacher {
 public:
  explicit GvelAttacher(const EstimatorOptions& options) : options_(options) {}
  void OnGvel(const GvelMeasurement& m, const AttachContext& ctx) override;
  void AddStats(nlohmann::json* stats) const override { (*stats)["gnss_velocity"] = counts_.ToJson(); }

 private:
  EstimatorOptions options_;
  MeasurementCounts counts_;
};

class StandstillAttacher final : public MeasurementAttacher {
 public:
  explicit StandstillAttacher(const EstimatorOptions& options);

  void OnStandstill(const StandstillMeasurement& m, const AttachContext& ctx) override;
  void OnKeyframeCreated(Keyframe& kf, const AttachContext& ctx) override { Attach(kf, ctx); }
  bool AfterSolve(const AttachContext& ctx) override;
  void OnKeyframeLeaving(const Keyframe& kf) override { records_.erase(kf.id); }
  // A standstill detected before the rebuild is not carried into the new window.
  void OnWindowRebuilt() override;
  void AddStats(nlohmann::json* stats) const override;

 private:
  struct Record {
    bool standstill = false;  // has a zero-velocity factor
    double since = 0.0;       // start of its standstill
    ceres::ResidualBlockId zupt_id = nullptr;
    bool checked = false;
    bool ok = false;  // its zero velocity passed the χ² check
  };
  void Attach(Keyframe& kf, const AttachContext& ctx);
  const Record* Find(uint64_t id) const;

  EstimatorOptions options_;
  double gate_;  // χ² gate on the whitened zero-velocity residual (3 dof)
  std::unique_ptr<ceres::LossFunction> loss_;
  std::optional<StandstillMeasurement> last_;
  std::map<uint64_t, Record> records_;  // by keyframe id
  MeasurementCounts counts_;
  uint64_t zero_motion_factors_ = 0;
};

}  // namespace gins
