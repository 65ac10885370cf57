// Error-state Kalman filter (reference ch. 3). Nominal state: NavState, gravity g_w, odometer scale s, GNSS
// time offset td. Error state (20): δp, δv, δθ, δbg, δba, δg, δs, δtd — right perturbation (core/conventions.h), so
// the first 15 are the NavState tangent; the layout is declared once in solver/eskf_state.h. Prediction at
// IMU rate through the shared kernel (core/imu_kernel.h); updates linearise the shared measurement models
// (core/*_model.h) with core/linearize.h and all go through one update (Eskf::Update, solver/eskf_update.h):
// Jacobians per block, a χ² innovation gate, an iterated update on the manifold (eskf.iterations, the IKFoM
// form: the model is re-linearised at each iterate, the prior carried into its tangent), Joseph-form
// covariance, then the reset with covariance projection.
//
// Measurements (solver/eskf_measurements.cc): GNSS position (lever arm) and dual-antenna heading, GNSS
// velocity (each compared with the state at its stamp less td, core/time_shift.h; td is held at 0 unless
// gnss.time_offset_s: estimate), wheel speed of the rear-axle centre at the middle of each record's interval
// (lever arm, every record) and the left/right difference as a yaw-rate aid (wheel.track_m), the
// non-holonomic constraint at vehicle.nhc_rate_hz whether or not the log has wheels, standstill updates. A
// run of rejected GNSS fixes that agree with one another inflates the gate and, when a fix is accepted under
// it, the covariance it updates (GateInflation, solver/estimator_common.h): re-acquisition after an outage by design.
// Fixes that disagree with the prediction by more than stated on most fixes scale the position gate
// (GateConsistency, the same file).
//
// Standstills, IMU gaps and the watchdog behave as docs/robustness.md ("Field robustness") describes, in
// both estimators alike (solver/estimator_common.h). Here: the zero-rate update takes the mean gyro reading
// since the last standstill update (it observes the gyro bias); a standstill is ignored while the estimated
// speed is above standstill.max_speed_m_s; a reset re-initialises from the current fix (ResetPositionFromFix).
#pragma once

#include <array>
#include <functional>
#include <map>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "core/imu_kernel.h"
#include "solver/eskf_rts.h"
#include "solver/eskf_state.h"
#include "solver/eskf_update.h"
#include "solver/estimator.h"
#include "solver/estimator_common.h"
#include "solver/estimator_options.h"
#include "solver/pre_init_output.h"

namespace gins {

class Eskf : public Estimator {
 public:
  using MatP = Eigen::Matrix<double, eskf::kDim, eskf::kDim>;
  using VecP = Eigen::Matrix<double, eskf::kDim, 1>;

  // The sections it reads: the sensors, eskf.*, standstill.* (its updates) and watchdog.*.
  // on_rts (optional): the Rauch-Tung-Striebel smoothed stream (solver/eskf_rts.h), emitted at Finish.
  Eskf(const SensorOptions& sensors, const EskfOptions& eskf, const StandstillOptions& standstill,
       const WatchdogOptions& watchdog, StateCallback on_state, StateCallback on_rts = nullptr);
  ~Eskf() override;

  std::string name() const override { return "eskf"; }
  void Initialize(const InitResult& init) override;
  void AddImu(const ImuSample& imu) override;
  void Add(const Measurement& m) override {
    std::visit(
        [&](const auto& x) {
          if constexpr (MeasurementModules::kHasMeasurement<std::decay_t<decltype(x)>>) {
            UseModule(m);
          } else {
            Use(x);
          }
        },
        m);
  }
  void AddRestState(const StateEstimate& s) override;
  void Finish() override;
  nlohmann::json Stats() const override;

  const NavState& state() const { return nom_.x; }
  // The covariance at the current time (a pending covariance interval is stepped first).
  const MatP& covariance() {
    FlushCovariance();
    return P_;
  }
  // Gravity in w at the current position: the Earth model's, plus the estimated correction (δg).
  Vec3 gravity() const { return earth_.Gravity(nom_.x.p_wb) + nom_.Get<eskf::Block::kG>(); }
  // The body's rate against w (rad/s) from the last IMU sample: gyro less bias less the Earth rate.
  Vec3 BodyRate() const {
    return last_imu_ ? Vec3(last_imu_->gyro - nom_.x.bg - nom_.x.q_wb.conjugate() * earth_.rate_w()) : Vec3::Zero();
  }
  double odom_scale() const { return nom_.Scalar<eskf::Block::kS>(); }
  StateEstimate Estimate() const;

 private:
  // Whether t lies beyond an IMU gap from the newest sample (imu.max_gap_s): there the state coasts.
  bool PastImuGap(double t) const { return t - last_sample_t_ > sensors_.imu.max_gap; }
  // Propagates nominal state and covariance to time t with the given rate and specific force held
  // (default: the last IMU sample).
  void Propagate(double t, const ImuSample* held = nullptr);
  // P through one kernel step (J) of dt; gap: the step coasted over an IMU gap.
  void PropagateCovariance(const ImuStepJacobians& J, double dt);
  // Steps the covariance over the pending interval (nothing pending: no change). P_ is current only after
  // this: every update and reset calls it first.
  void FlushCovariance();
  // The covariance over a step no IMU sample covers (an IMU gap): see kImuGapAccDensity.
  void CoastCovariance(double dt);
  // The prior variances of the additive blocks (δg, s, td) that are estimated; and their random walks, with
  // the biases', over dt.
  void SetAdditivePriors();
  void AddRandomWalks(double dt);
  // The measurements, one overload per type of Measurement (eskf_measurements.cc; raw GNSS: eskf_raw_gnss.cc).
  void Use(const GnssMeasurement& m);
  void Use(const GnssVelocityMeasurement& m);
  void Use(const WheelMeasurement& m);
  void Use(const StandstillMeasurement& m);
  void Use(const RawGnssMeasurement& m);
  // A measurement module's (core/measurement_module.h; eskf_modules.cc): its model linearised at the nominal
  // state, gated by the module's gate_probability. Its gates are set at construction (SetModuleGates).
  void UseModule(const Measurement& m);
  void SetModuleGates();
  void AddModuleStats(nlohmann::json* stats) const;
  // A measurement model linearised at the filter's current nominal state: its residual r = h(x) − z and
  // full-width Jacobian (from the blocks it touches, eskf::EmbedJacobian).
  template <int M>
  struct Linearized {
    Eigen::Matrix<double, M, 1> r;
    Eigen::Matrix<double, M, eskf::kDim> H;
  };
  template <int M>
  using Model = std::function<Linearized<M>()>;
  // Gated, iterated update with noise R; inflation (≥ 1) multiplies the kinematic block of the prior
  // covariance (GateInflation). Injects and returns true when accepted; false when rejected (counted).
  // innovation_out/S_out, if given, receive the prior innovation −r and HPHᵀ + R (uninflated: for
  // GateInflation when the fix was rejected).
  template <int M>
  bool Update(const Model<M>& model, const Eigen::Matrix<double, M, M>& R, double gate, MeasurementCounts* counts,
              double t, double inflation = 1.0, Eigen::Matrix<double, M, 1>* innovation_out = nullptr,
              Eigen::Matrix<double, M, M>* S_out = nullptr);
  // The covariance's reset for a step δx of the nominal state.
  void ResetCovariance(const VecP& dx);
  // The measurement updates (eskf_measurements.cc).
  bool UpdateGnssPosition(const GnssMeasurement& m);
  void UpdateHeading(const GnssMeasurement& m);
  void UpdateWheelSpeed(const WheelMeasurement& m);
  void UpdateWheelYawRate(const WheelMeasurement& m);
  void UpdateNonHolonomic(double t);
  // The tightly coupled updates (eskf_raw_gnss.cc): the epoch's pseudoranges, or its range rates. True if
  // used, false if rejected (by the gate, or every difference screened away), none if there was nothing to
  // difference.
  std::optional<bool> UpdateRawGnss(const RawGnssMeasurement& m, const std::vector<RawSatellite>& sats, bool rates);
  // The carrier phases' time differences since the previous epoch; then that epoch becomes this one.
  void UpdateRawPhase(const RawGnssMeasurement& m, const std::vector<RawSatellite>& sats);
  // Watchdog: before a fix is used, true if its verdict took the fix (held for a course, or re-initialised
  // from it); after a GNSS position update or a raw epoch's ranges (accepted or not), true if it
  // re-initialised.
  bool WatchdogTakes(const GnssMeasurement& m);
  bool WatchGnss(const GnssMeasurement& m, bool accepted);
  void ResetFromGnss(const GnssMeasurement& m, const std::string& reason);

  const EskfNominal& Nominal() const { return nom_; }

  SensorOptions sensors_;
  EskfOptions eskf_options_;
  StandstillOptions standstill_options_;
  WatchdogOptions watchdog_options_;
  StateCallback on_state_;
  StateCallback on_rts_;
  PreInitOutput pre_init_{BridgeNoise{sensors_.imu.gyro_noise_density, sensors_.imu.acc_noise_density}};
  std::unique_ptr<EskfRts> rts_;  // with on_rts_
  bool initialized_ = false;
  EskfNominal nom_;  // the nominal state: nom_.x the NavState, then δg, the odometer scale, td (eskf_state.h)
  EarthModel earth_;
  MatP P_ = MatP::Identity();
  // The samples' steps since the covariance's last step (eskf.covariance_interval_s): P_ is as of their
  // start. Estimate() reports its σ from P_ as it is.
  struct PendingCovariance {
    Kinematics start;    // the state at the interval's start
    Vec3 g_w = Vec3::Zero();  // gravity there
    Vec3 omega_dt = Vec3::Zero(), acc_dt = Vec3::Zero();  // ∫ω dt, ∫a dt of the bias-corrected samples
    Vec3 omega = Vec3::Zero(), acc = Vec3::Zero();        // the last step's ω and a
    double dt = 0.0;
    int steps = 0;
  };
  PendingCovariance pending_;
  std::optional<ImuSample> last_imu_;
  double last_sample_t_ = 0.0;  // the newest sample's time; the initialisation's epoch before the first one
  Vec3 a_w_ = Vec3::Zero();  // acceleration in w over the last IMU step
  // Gyro readings since the last standstill update, for the zero-rate update.
  Vec3 gyro_sum_ = Vec3::Zero();
  int gyro_count_ = 0;
  double gyro_sum_start_ = 0.0;
  // Gyro readings since the last wheel record, for the wheels' yaw-rate aid over the same interval.
  Vec3 wheel_gyro_sum_ = Vec3::Zero();
  int wheel_gyro_count_ = 0;
  double last_nhc_t_ = -1e300;
  GateInflation gnss_inflation_;
  GateConsistency gnss_consistency_;

  // χ² gates, computed once (the quantile is an iterative inversion).
  double gate_gnss_ = 0.0, gate_heading_ = 0.0, gate_wheel_ = 0.0, gate_nhc_ = 0.0, gate_wheel_yaw_ = 0.0,
         gate_zupt_ = 0.0, gate_zero_rate_ = 0.0;
  uint64_t imu_steps_ = 0;
  ImuGapLog imu_gaps_;
  MeasurementCounts gnss_counts_, heading_counts_, gnss_velocity_counts_, wheel_counts_, wheel_yaw_counts_, nhc_counts_,
      zupt_counts_;
  std::array<MeasurementCounts, MeasurementModules::kSize> module_counts_;  // by module
  std::array<double, MeasurementModules::kSize> module_gates_{};

  // Raw GNSS (eskf_raw_gnss.cc): the epochs' updates, and each satellite's fate.
  struct RawGnssCounts {
    uint64_t epochs = 0, satellites_used = 0, unusable = 0, epochs_without_differences = 0;
    MeasurementCounts ranges, rates, phases;
    uint64_t phase_slips = 0;  // satellites left out of a difference: lost lock, or a jump against the Doppler
    std::map<std::string, uint64_t> satellite_rejected;  // "G05" -> epochs its own test rejected it
    double w_max = 0.0;  // the standardised residual's bound: √χ²(gnss.gate_probability, 1)
    nlohmann::json ToJson() const;
  };
  RawGnssCounts raw_;
  // The previous epoch for the phases' time differences: its satellites, the nominal antenna then, and the
  // updates' corrections of the nominal position since (the propagation alone gives the displacement).
  struct PhaseEpoch {
    bool valid = false;
    double t = 0.0;
    Vec3 p_wb = Vec3::Zero();
    Quat q_wb = Quat::Identity();
    std::map<std::string, RawSatellite> sats;  // by "G05"
  };
  PhaseEpoch phase_epoch_;
  Vec3 position_corrections_ = Vec3::Zero();

  GnssWatchdog watchdog_;
  std::optional<GnssMeasurement> prev_fix_;  // the fix before the current one, accepted or not
  CourseWait course_wait_;                    // a re-initialisation waiting for a later fix's course
};

}  // namespace gins
