// Sliding-window smoother (reference ch. 4, DESIGN §7): keyframes at GNSS epochs (and every
// smoother.max_keyframe_interval_s without GNSS), each with pose (7), velocity (3), biases (6) and the
// odometer scale (1); IMU preintegration, bias and scale random-walk, GNSS (robust loss + χ² check),
// heading, wheel-speed and zero-velocity factors; the oldest keyframe is marginalised by a Schur complement
// of every factor touching it into a prior on what stays (factors/marginalization_prior.h).
//
// Outputs: the final estimate of each keyframe when it leaves the window, with IMU-rate states between
// keyframes propagated from it (final stream), and the newest keyframe after each solve (online stream).
//
// In parts: the keyframes and their state blocks (solver/keyframe.h), first-estimate Jacobians
// (factors/fej_cost.h), one attacher per measurement type (solver/smoother_attachers.h), the marginaliser
// (solver/marginalizer.h) and the output with covariance recovery (solver/smoother_output.h); this class
// integrates the IMU, decides the keyframes, solves, and runs the watchdog.
//
// Robustness (config standstill.*, watchdog.*, imu.max_gap_s):
// - Standstill (AddStandstill, from the session's detector): a zero-velocity factor on each keyframe inside
//   a standstill, and a zero-motion factor (no translation, 0.1 mm; no rotation, the gyro noise over the
//   interval) between consecutive keyframes of one standstill, which with the IMU factor observes the gyro
//   bias. A detection is ignored while the keyframe's speed is above standstill.max_speed_m_s.
// - IMU gap longer than imu.max_gap_s: preintegrated as a coast (no rotation, no acceleration from the
//   current estimate) with the covariance of an unknown 2 m/s² and 10 deg/s held over the gap.
// - GNSS: Cauchy loss, then a χ² check of each fix's residual after the solve; a failing fix is removed and
//   the window solved again (counted, times listed).
// - Watchdog: when every GNSS fix for watchdog.max_reject_s (at least 3) was rejected, or the last
//   marginalised position 1-σ exceeds watchdog.max_position_sigma_m, or the newest state is not finite,
//   the window is flushed to the output and rebuilt from a fresh prior at the current fix (position from
//   the fix, velocity from the last two fixes, attitude, biases and scale kept), as the ESKF does.
#pragma once

#include <ceres/ceres.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/preintegration.h"
#include "factors/pose_manifold.h"
#include "solver/estimator.h"
#include "solver/estimator_options.h"
#include "solver/keyframe.h"
#include "solver/smoother_attachers.h"

namespace gins {

class Smoother : public Estimator {
 public:
  Smoother(const EstimatorOptions& options, StateCallback on_final, StateCallback on_online);
  ~Smoother() override;

  std::string name() const override { return "smoother"; }
  void Initialize(const InitResult& init) override;
  void AddImu(const ImuSample& imu) override;
  void AddGnss(const GnssMeasurement& gnss) override;
  void AddGvel(const GvelMeasurement& gvel) override;
  void AddWheel(const WheelMeasurement& wheel) override;
  void AddStandstill(const StandstillMeasurement& m) override;
  void Finish() override;
  nlohmann::json Stats() const override;

  // Newest keyframe's state (after the last solve).
  NavState NewestState() const;

 private:
  void IntegrateTo(double t, const ImuSample* held = nullptr);
  Keyframe& CreateKeyframe(double t);
  ceres::ResidualBlockId AddImuFactor(Keyframe& prev, Keyframe& kf);
  void WatchGnss(double t, bool accepted);
  void ResetFromGnss(const GnssMeasurement& m, const std::string& reason);
  // One Ceres solve of the window with the configured options; false if the solution is not usable.
  bool Solve();
  void SolveAndSlide();
  void ReintegrateIfNeeded();
  void MarginalizeOldest();
  // A keyframe leaves the window: its final estimate and the IMU-rate states after it.
  void OutputFinal(const Keyframe& kf, const Keyframe* next, const Mat15* cov);

  EstimatorOptions options_;
  StateCallback on_final_, on_online_;
  EarthModel earth_;
  Vec3 g_w_ = Vec3::Zero();  // gravity at the newest prediction (the attachers read it)
  bool initialized_ = false;

  KeyframeStore window_;
  std::unique_ptr<ceres::Problem> problem_;  // after window_: the problem goes first, its blocks are there

  // Between the newest keyframe and now.
  std::shared_ptr<Preintegration> preint_;
  std::vector<HeldImuSample> interval_samples_;
  std::optional<ImuSample> last_imu_;
  double t_now_ = 0.0;
  NavState pred_;  // IMU-propagated from the newest keyframe, for initial values
  double initial_scale_ = 1.0;  // odometer scale of the first keyframe (kept across a watchdog reset)

  // The measurements' attachers, in the order of their checks after a solve.
  std::vector<std::unique_ptr<MeasurementAttacher>> attachers_;
  AttachContext context_;

  GnssWatchdog watchdog_;
  std::string reset_reason_;      // set by the checks, acted on at the end of AddGnss
  std::optional<GnssMeasurement> prev_fix_;
  double last_sigma_p_ = 0.0;     // largest position 1-σ of the last keyframe marginalised
  ImuGapLog imu_gaps_;

  // Statistics.
  uint64_t solves_ = 0, iterations_ = 0, marginalizations_ = 0, keyframes_ = 0, reintegrations_ = 0;
  uint64_t gnss_decimated_ = 0, solver_failures_ = 0;
  double last_scale_ = 1.0;  // of the last keyframe to leave the window
  double solve_time_ = 0.0, max_solve_time_ = 0.0, marg_time_ = 0.0;
};

}  // namespace gins
