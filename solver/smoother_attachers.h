// How measurements become factors in the smoother's window: one attacher per measurement type behind one
// interface, called by the smoother at fixed moments. A new measurement type is a new attacher added to the
// smoother's list; the others do not change.
//
// Every measurement is first checked against what the window predicts at its time (solver/smoother_gate.h:
// the innovation's χ² with S = H·P·Hᵀ + R, P the predicted state's marginal covariance from the whole
// window), as the ESKF does; one that passes is attached at full weight, at its own time (at a keyframe of
// its epoch, or through the IMU preintegrated from the newest keyframe: factors/preint_attached_factor.h),
// so no measurement is lost to keyframe placement. The robust loss on GNSS factors is a Huber loss whose
// corner is the gate itself: every residual the gate accepts is inside its quadratic part (full weight);
// it only bounds the pull of a measurement the solution later moves away from.
//
// The attachers here:
// - GnssAttacher: position and dual-antenna heading; a run of rejected fixes that agree with one another
//   inflates the gate (GateInflation, solver/estimator_common.h), and a fix accepted under it relieves the prior;
//   fixes that disagree with the prediction by more than stated on most fixes scale the gate and its Huber
//   corner (GateConsistency, the same file).
// - GnssVelocityAttacher: GNSS (Doppler) velocity.
// - StandstillAttacher: from the session's detector, a zero-velocity factor on each keyframe inside a
//   standstill (checked against the predicted velocity, not above standstill.max_speed_m_s), and a
//   zero-motion factor (no translation, 0.1 mm; no rotation, the gyro noise over the interval) between
//   consecutive such keyframes, which with the IMU factor observes the gyro bias.
// - each measurement module's (AddModuleAttachers).
// The vehicle's own constraints and the wheels are solver/vehicle_attacher.h's.
#pragma once

#include <ceres/loss_function.h>

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/earth.h"
#include "solver/estimator.h"
#include "solver/estimator_common.h"
#include "solver/keyframe.h"

namespace gins {

// What the window predicts at a time t (≥ the newest keyframe's): the state, and the covariance of its
// blocks' tangents (KeyframeStore::EstimatedTypes order) from everything in the window before t.
struct Prediction {
  NavState x;
  MatX cov;
};

// One IMU step of the preintegration from the newest keyframe (every step, a coast over a gap included):
// the rotation from that keyframe's body frame to the step's start and end, the predicted body velocity
// there, and the body rate against w over the step.
struct ImuStepView {
  double dt = 0.0;
  Quat dR_begin, dR_end;
  Vec3 v_b_begin, v_b_end, omega_b;
};

// Where a measurement at t attaches: a keyframe, and the IMU preintegrated from it to t (null at its time).
struct Anchor {
  Keyframe* kf = nullptr;
  std::shared_ptr<const Preintegration> partial;
};

// What the smoother lends an attacher: the window (its problem, factors with first-estimate Jacobians), the
// Earth, the IMU stream, and its services (an attacher holds the options it reads).
struct AttachContext {
  KeyframeStore& keyframes;
  const EarthModel& earth;
  const std::optional<ImuSample>& last_imu;
  std::function<Prediction(double t)> predict;
  // Applies the keyframe policy for a measurement at t: the newest keyframe if t is its epoch, a new
  // keyframe at t if it is at least smoother.min_keyframe_interval_s later, else the newest keyframe and
  // the IMU preintegrated from it to t.
  std::function<Anchor(double t)> anchor;
  // After the last solve: the joint covariance of the two newest keyframes (older first), or null.
  std::function<const MatX*()> newest_two_cov;
  // The newest keyframe and the IMU preintegrated from it to t, never a new keyframe: where a measurement
  // the window rejects is kept for the whole-log smoother (only with a factor log).
  std::function<Anchor(double t)> partial;
  // The state `predict` gives, without its covariance (a fraction of the cost): for what needs only the
  // attitude or the biases at t.
  std::function<NavState(double t)> predict_state;
  // A keyframe at t whatever smoother.min_keyframe_interval_s says (the newest if t is its epoch): for a
  // measurement between two epochs' states, which must be keyframes.
  std::function<Anchor(double t)> keyframe;
  // The Earth terms of an IMU interval around p (gravity there, Earth rate).
  ImuEarthTerms EarthTermsAt(const Vec3& p_w) const;
  // The body's rate against w from the last IMU sample, with the biases of x.
  Vec3 BodyRate(const NavState& x) const;
  // The acceleration in w from the last IMU sample, with the state x (gravity and Coriolis included).
  Vec3 Acceleration(const NavState& x) const;
};

class MeasurementAttacher {
 public:
  virtual ~MeasurementAttacher() = default;

  // A measurement arrived (the smoother is initialised; every attacher sees every one, AttacherOf picks its
  // type); true if the window is to be solved before the next IMU sample (a factor attached that the
  // epoch's solve needs).
  virtual bool OnMeasurement(const Measurement& m, const AttachContext& ctx) = 0;
  // An IMU step was integrated from the newest keyframe (before the keyframe it ends at, if any, is made).
  virtual void OnImuStep(const ImuStepView& /*step*/) {}
  // A keyframe became the newest, with its IMU and random-walk factors.
  virtual void OnKeyframeCreated(Keyframe& /*kf*/, const AttachContext& /*ctx*/) {}
  // The oldest keyframe leaves the window; its factors are gone already.
  virtual void OnKeyframeLeaving(const Keyframe& /*kf*/) {}
  // The watchdog rebuilt the window from a fresh prior: nothing attached before is in it.
  virtual void OnWindowRebuilt() {}
  // The watchdog's re-initialisation took fix m (or held it for the course of the next), not the attachers.
  virtual void OnResetFix(const GnssMeasurement& /*m*/) {}
  // The attacher's entries of Smoother::Stats.
  virtual void AddStats(nlohmann::json* /*stats*/) const {}
};

// The attacher of one measurement type M: On gets the measurements of that type, the others pass by.
template <typename M>
class AttacherOf : public MeasurementAttacher {
 public:
  bool OnMeasurement(const Measurement& m, const AttachContext& ctx) final {
    const M* x = std::get_if<M>(&m);
    return x != nullptr && On(*x, ctx);
  }
  virtual bool On(const M& m, const AttachContext& ctx) = 0;
};

class GnssAttacher final : public AttacherOf<GnssMeasurement> {
 public:
  // on_checked(t, accepted): each fix's outcome, for the smoother's watchdog; on_reacquired(factor): a fix
  // was accepted under an inflated gate (the window was overconfident by about that factor).
  GnssAttacher(const GnssOptions& gnss, std::function<void(double t, bool accepted)> on_checked,
               std::function<void(double factor)> on_reacquired);

  bool On(const GnssMeasurement& m, const AttachContext& ctx) override;
  void OnWindowRebuilt() override { inflation_.Accepted(); }
  void OnResetFix(const GnssMeasurement& /*m*/) override { ++position_counts_.used; }
  void AddStats(nlohmann::json* stats) const override;

 private:
  // The position factor of m at anchor a (at its keyframe, or through the IMU preintegrated from it).
  ceres::CostFunction* PositionFactor(const GnssMeasurement& m, const Prediction& pred, const Anchor& a,
                                      const AttachContext& ctx, std::vector<BlockRef>* blocks) const;
  bool AttachPosition(const GnssMeasurement& m, const Prediction& pred, const AttachContext& ctx);
  ceres::LossFunction* PositionLoss(double scale);
  bool AttachHeading(const GnssMeasurement& m, const Prediction& pred, const AttachContext& ctx);

  GnssOptions gnss_;
  std::function<void(double, bool)> on_checked_;
  std::function<void(double)> on_reacquired_;
  double gate_position_, gate_heading_;
  std::unique_ptr<ceres::LossFunction> loss_position_, loss_heading_;
  GateInflation inflation_;
  GateConsistency consistency_;
  std::map<int, std::unique_ptr<ceres::LossFunction>> scaled_losses_;  // PositionLoss's, by scale step
  MeasurementCounts position_counts_, heading_counts_;
};

class GnssVelocityAttacher final : public AttacherOf<GnssVelocityMeasurement> {
 public:
  explicit GnssVelocityAttacher(const GnssOptions& gnss);
  bool On(const GnssVelocityMeasurement& m, const AttachContext& ctx) override;
  void AddStats(nlohmann::json* stats) const override { (*stats)["gnss_velocity"] = counts_.ToJson(); }

 private:
  Vec3 lever_b_;
  double gate_;
  std::unique_ptr<ceres::LossFunction> loss_;
  MeasurementCounts counts_;
};

class StandstillAttacher final : public AttacherOf<StandstillMeasurement> {
 public:
  // gate_probability: the zero velocity's χ² gate (standstill.* has none: the wheels', wheel.gate_probability).
  StandstillAttacher(const StandstillOptions& standstill, const ImuOptions& imu, double gate_probability);

  // False: its factors join the next solve.
  bool On(const StandstillMeasurement& m, const AttachContext& ctx) override;
  void OnKeyframeCreated(Keyframe& kf, const AttachContext& ctx) override { Attach(kf, ctx); }
  void OnKeyframeLeaving(const Keyframe& kf) override { standing_.erase(kf.id); }
  // A standstill detected before the rebuild is not carried into the new window.
  void OnWindowRebuilt() override;
  void AddStats(nlohmann::json* stats) const override;

 private:
  void Attach(Keyframe& kf, const AttachContext& ctx);

  StandstillOptions standstill_;
  ImuOptions imu_;
  double gate_;            // χ² gate on the zero velocity (3 dof)
  double gate_zero_rate_;  // and on the zero rotation (kZeroRateGateProbability, 3 dof)
  std::optional<StandstillMeasurement> last_;
  std::map<uint64_t, double> standing_;  // keyframes with an accepted zero velocity: the start of their stop
  MeasurementCounts counts_;
  uint64_t zero_motion_factors_ = 0;
  MeasurementCounts zero_rotation_;  // the zero-motion factors' rotation part: held, or turning (not held)
};

// One attacher per measurement module (core/measurement_module.h), appended to attachers: the module's model
// of the state at its time, gated against the window's prediction, at full weight inside the gate.
void AddModuleAttachers(const SensorOptions& sensors, std::vector<std::unique_ptr<MeasurementAttacher>>* attachers);

}  // namespace gins
