// Static initialisation (reference §3.5.4): from a standstill (wheels at zero, IMU quiet) estimate the gyro
// bias, the gravity direction (so roll and pitch), the accelerometer bias along gravity (the horizontal
// components are not observable at rest: they stay in the covariance) and the sensor noise levels. Heading
// comes from the first valid dual-antenna heading or, without one, from the first motion (GNSS track
// against the wheel/gyro dead-reckoned track). From the end of the standstill to the GNSS epoch that
// completes the initialisation, the attitude and velocity are propagated with the shared IMU kernel, so the
// estimators start at that epoch with every earlier measurement used.
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "core/sensors.h"
#include "core/earth.h"
#include "core/imu_kernel.h"
#include "core/measurements.h"
#include "core/nav_state.h"

namespace gins {

// init.*
struct InitOptions {
  double static_duration = 2.0;     // init.static_duration_s: standstill needed before starting
  double max_gyro_std = 0.5 * kDegToRad;  // init.max_gyro_std_deg_s: "IMU quiet" thresholds
  double max_acc_std = 0.1;         // init.max_acc_std_m_s2
  double max_wait = 300.0;          // init.max_wait_s: give up if no standstill was found by then
  bool wait_for_heading = true;     // init.wait_for_heading: take yaw from the first valid heading
  double sigma_pos = 0.1;           // init.sigma_pos_m   (added to the first fix's σ)
  double sigma_vel = 0.05;          // init.sigma_vel_m_s
  double sigma_roll_pitch = 0.5 * kDegToRad;  // init.sigma_roll_pitch_deg
  double sigma_yaw = 2.0 * kDegToRad;         // init.sigma_yaw_deg (no heading: 180)
};

// What the initialisation needs: the sensors and its own settings.
struct InitializerOptions : SensorOptions {
  InitOptions init;
};

struct InitResult {
  NavState x0;                    // at x0.t, the GNSS epoch that completed the initialisation
  Mat15 P0 = Mat15::Identity();   // covariance in the NavState tangent (δp, δv, δθ, δbg, δba)
  double g_norm = kStandardGravity;
  EarthModel earth;               // the Earth the estimators start in (gravity.*)
  double static_start = 0.0, static_end = 0.0;
  Vec3 gyro_std = Vec3::Zero();   // per-sample standard deviation at rest, rad/s
  Vec3 acc_std = Vec3::Zero();    // m/s²
  double gyro_noise_density = 0.0;  // estimated from gyro_std and the IMU rate, rad/s/√Hz
  double acc_noise_density = 0.0;   // m/s²/√Hz
  std::string heading_source;     // "dual_antenna" | "motion"
};

class StaticInitializer {
 public:
  StaticInitializer(const InitializerOptions& options, const EarthModel& earth);
  // The flat Earth with constant gravity of magnitude g_norm.
  StaticInitializer(const InitializerOptions& options, double g_norm)
      : StaticInitializer(options, EarthModel(g_norm)) {}

  void AddImu(const ImuSample& imu);
  void AddWheel(const WheelMeasurement& wheel);
  void AddGnss(const GnssMeasurement& gnss);

  bool done() const { return result_.has_value(); }
  const InitResult& result() const { return *result_; }
  // Why initialisation has not completed, for the error message at the end of a log.
  std::string Diagnosis() const;

 private:
  bool WindowIsStatic() const;
  void StartFromStandstill();
  void Finish(const GnssMeasurement& gnss, double yaw_offset, const std::string& source);

  InitializerOptions options_;
  EarthModel earth_;
  double g_norm_;
  Quat q_static_free_ = Quat::Identity();  // attitude at the standstill in the yaw-free frame
  std::deque<ImuSample> window_;   // IMU samples of the current candidate standstill
  std::deque<WheelMeasurement> wheel_window_;
  bool wheel_seen_ = false;
  double first_time_ = -1.0;
  std::optional<ImuSample> last_imu_;

  // After a standstill was found: attitude/velocity propagated with an arbitrary yaw.
  bool have_standstill_ = false;
  InitResult partial_;
  Kinematics kin_;                 // yaw-free frame: z is up, yaw arbitrary
  double kin_time_ = 0.0;
  double last_wheel_speed_ = 0.0;
  bool moving_ = false;
  // Motion heading: GNSS fixes and dead-reckoned positions at the same epochs.
  std::vector<std::pair<Vec3, Vec3>> track_;  // (antenna p_w from GNSS, dead-reckoned antenna in yaw-free frame)
  Vec3 dr_p_ = Vec3::Zero();
  std::string last_problem_;
  std::optional<InitResult> result_;
};

}  // namespace gins
