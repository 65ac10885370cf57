// Sliding-window smoother (reference ch. 4, docs/formats.md §7): keyframes at GNSS epochs at least
// smoother.min_keyframe_interval_s apart (and every smoother.max_keyframe_interval_s without GNSS), each with
// pose (7), velocity (3), biases (6) and the odometer scale (1) (solver/keyframe.h); IMU preintegration,
// bias and scale random-walk factors between them; the measurements through their attachers
// (solver/smoother_attachers.h, solver/vehicle_attacher.h): each checked against the window's prediction
// at its own time (the innovation's χ² with the predicted marginal covariance) and attached at its own time
// (at a keyframe, or through the IMU preintegrated from the newest one), so none is lost to keyframe
// placement. All the measurements of one epoch join before one solve (the solve waits for the next IMU
// sample). The oldest keyframe is marginalised by a Schur complement of every factor touching it into a
// prior on what stays (solver/marginalizer.h), with first-estimate Jacobians from then on.
//
// Outputs: the final estimate of each keyframe when it leaves the window, with the IMU-rate states between
// it and the next keyframe (solver/smoother_output.h), and the newest keyframe after each solve (online).
//
// Standstills, IMU gaps and the watchdog behave as docs/robustness.md ("Field robustness") describes, in
// both estimators alike (solver/estimator_common.h). Particular to the window:
// - GNSS: a run of rejected fixes that agree with one another inflates the gate (GateInflation); a fix
//   accepted under it makes the marginalisation prior's position uncertain by a common translation of its
//   poses (the factor times its position covariance; attitude, velocity and biases kept), and joins
//   without the robust loss, so the window moves to where the fixes are (re-acquisition after an outage or
//   a step of the GNSS positions by design, not by the watchdog).
// - an IMU gap is preintegrated as the coast (no rotation, no acceleration from the current estimate);
// - the watchdog's position σ is the larger of the prediction at the fix and the last marginalised
//   keyframe's; a reset flushes the window to the output and rebuilds it from a fresh prior at the current
//   fix (ResetPositionFromFix; the scale and the time offset kept).
#pragma once

#include <ceres/ceres.h>

#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "core/preintegration.h"
#include "factors/pose_manifold.h"
#include "solver/estimator.h"
#include "solver/estimator_common.h"
#include "solver/estimator_options.h"
#include "solver/pre_init_output.h"
#include "solver/factor_log.h"
#include "solver/keyframe.h"
#include "solver/smoother_attachers.h"

namespace gins {

class Smoother : public Estimator {
 public:
  // The sections it reads: the sensors, eskf.* (the ESKF that runs backwards before the initialisation,
  // solver/pre_init_backward.h), smoother.*, batch.* (with on_batch), standstill.* and watchdog.*.
  // on_batch (optional): the whole-log solution (solver/batch_smoother.h), emitted at Finish; the window
  // then keeps every factor and keyframe it built.
  Smoother(const SensorOptions& sensors, const EskfOptions& eskf, const SmootherOptions& smoother,
           const BatchOptions& batch, const StandstillOptions& standstill, const WatchdogOptions& watchdog,
           StateCallback on_final, StateCallback on_online, StateCallback on_batch = nullptr);
  ~Smoother() override;

  std::string name() const override { return "smoother"; }
  void Initialize(const InitResult& init) override;
  void AddImu(const ImuSample& imu) override;
  void Add(const Measurement& m) override {
    std::visit(
        [&](const auto& x) {
          if constexpr (MeasurementModules::kHasMeasurement<std::decay_t<decltype(x)>>) {
            UseModule(x.t, m);
          } else {
            Use(x, m);
          }
        },
        m);
  }
  void AddRestState(const StateEstimate& s) override;
  void Finish() override;
  nlohmann::json Stats() const override;

  // Newest keyframe's state (after the last solve).
  NavState NewestState() const;

 private:
  static constexpr double kSameEpoch = 1e-6;  // s: a fix at a keyframe's time belongs to it

  // The measurements, one overload per type of Measurement; m holds x, as the attachers take it.
  void Use(const GnssMeasurement& x, const Measurement& m);  // smoother_gnss.cc
  void Use(const GnssVelocityMeasurement& x, const Measurement& m);
  void Use(const WheelMeasurement& x, const Measurement& m);
  void Use(const StandstillMeasurement& x, const Measurement& m);
  // A raw epoch: its pseudoranges and range rates (solver/raw_gnss_attacher.h).
  void Use(const RawGnssMeasurement& x, const Measurement& m);
  // A measurement module's, at t (its attacher: AddModuleAttachers).
  void UseModule(double t, const Measurement& m);
  // Offers m to every attacher; true if one asks for a solve before the next IMU sample.
  bool Attach(const Measurement& m);
  void IntegrateTo(double t, const ImuSample* held = nullptr);
  Keyframe& CreateKeyframe(double t);
  // The attachers' services (AttachContext): the prediction at t, and the keyframe policy's anchor.
  Prediction PredictAt(double t);
  NavState PredictStateAt(double t);
  // t is past the newest keyframe's epoch and the IMU integrated from it (the prediction is pred_).
  bool BeyondNewest(double t) const;
  Anchor AnchorAt(double t, bool keyframe = false);  // keyframe: a keyframe at t, whatever the policy
  Anchor PartialAt(double t);
  // Solves the window if measurements joined it since the last solve.
  void SolveIfPending();
  // The joint covariance of the two newest keyframes (or the newest alone) after a solve.
  // oldest_cov (optional): the oldest keyframe's too, from the same recovery.
  void UpdateNewestCovariance(MatX* oldest_cov = nullptr);
  // A fix was accepted under an inflated gate: the prior's position was overconfident by about `factor`.
  void RelievePrior(double factor);
  // A covariance recovery failed (the information is not positive definite): counted, warned once.
  void CountCovarianceFailure(const char* what);
  ceres::ResidualBlockId AddImuFactor(Keyframe& prev, Keyframe& kf);
  void WatchGnss(double t, bool accepted);
  // The watchdog's verdict before a fix (logged, or a raw epoch's own) is used: true if it took the fix
  // (held for a course, or the window rebuilt from it).
  bool WatchdogTakes(const GnssMeasurement& m);
  // Attaches the measurement carrying fix, and rebuilds the window from fix if its outcome made the
  // watchdog fire (WatchGnss).
  void AttachWatched(const GnssMeasurement& fix, const Measurement& measurement);
  void ResetFromGnss(const GnssMeasurement& m, const std::string& reason);
  // One Ceres solve of the window with the configured options; false if the solution is not usable.
  bool Solve();
  void SolveAndSlide();
  void ReintegrateIfNeeded();
  // block_cov: the oldest keyframe's covariance (block order) if known, else recovered here.
  void MarginalizeOldest(const MatX* block_cov);
  // A keyframe leaves the window: its final estimate and the IMU-rate states after it.
  void OutputFinal(const Keyframe& kf, const Keyframe* next, const Mat15* cov);

  SensorOptions sensors_;
  EskfOptions eskf_options_;
  SmootherOptions smoother_options_;
  BatchOptions batch_options_;
  StandstillOptions standstill_options_;
  WatchdogOptions watchdog_options_;
  StateCallback on_final_, on_online_;
  EarthModel earth_;
  Vec3 g_w_ = Vec3::Zero();  // gravity at the newest prediction (the attachers read it)
  bool initialized_ = false;

  StateCallback on_batch_;
  PreInitOutput pre_init_{BridgeNoise{sensors_.imu.gyro_noise_density, sensors_.imu.acc_noise_density}};
  std::unique_ptr<FactorLog> factor_log_;  // with on_batch_; before window_, which records into it
  nlohmann::json batch_stats_;
  KeyframeStore window_;
  std::unique_ptr<ceres::Problem> problem_;  // after window_: the problem goes first, its blocks are there

  // Between the newest keyframe and now.
  std::shared_ptr<Preintegration> preint_;
  std::vector<HeldImuSample> interval_samples_;
  std::optional<ImuSample> last_imu_;
  double last_sample_t_ = 0.0;  // the newest sample's time; the initialisation's epoch before the first one
  double t_now_ = 0.0;
  NavState pred_;  // IMU-propagated from the newest keyframe, for initial values

  // The measurements' attachers.
  std::vector<std::unique_ptr<MeasurementAttacher>> attachers_;
  AttachContext context_;
  bool solve_pending_ = false;
  // After the last solve: the covariance of the newest keyframe then (id newest_cov_id_), block order, and
  // the joint one of it and the keyframe before it (older first; empty with one keyframe).
  MatX newest_cov_, newest_two_cov_;
  uint64_t newest_cov_id_ = 0;
  ceres::ResidualBlockId prior_id_ = nullptr;  // the marginalisation (or initial) prior

  GnssWatchdog watchdog_;
  std::string reset_reason_;      // set by the checks, acted on at the end of Use(GnssMeasurement)
  std::optional<GnssMeasurement> prev_fix_;
  CourseWait course_wait_;        // a rebuild waiting for a later fix's course
  double last_sigma_p_ = 0.0;     // largest position 1-σ of the last keyframe marginalised
  ImuGapLog imu_gaps_;

  // Statistics.
  uint64_t solves_ = 0, iterations_ = 0, marginalizations_ = 0, keyframes_ = 0, reintegrations_ = 0;
  uint64_t solver_failures_ = 0, prior_reliefs_ = 0, covariance_failures_ = 0;
  double last_scale_ = 1.0;  // of the last keyframe to leave the window
  double final_time_offset_ = 0.0, final_time_offset_sigma_ = 0.0;  // at Finish (td beyond the stated offset)
  double solve_time_ = 0.0, max_solve_time_ = 0.0, marg_time_ = 0.0;
};

}  // namespace gins
