// Alignment: the joint fit of a short window of GNSS and preintegrated IMU that gives the initial attitude
// (roll, pitch, yaw), velocity, position and biases with their covariance, the way visual-inertial systems
// align. A small Ceres problem over one 15-vector, the state at the window's first epoch t0
// (core/alignment_terms.h), with every measurement of the window predicted through the IMU preintegrated
// from t0: GNSS positions and velocities, dual-antenna headings, wheel speeds, a car's non-holonomic
// constraint (vehicle.nonholonomic, at the rear axle), a standstill that ended at t0 (its mean IMU readings
// and zero velocity), and the sensors' stated bias priors.
//
// Roll and pitch come from gravity, compensated by the acceleration the GNSS track shows; yaw from the
// headings, or from the horizontal accelerations the IMU and the GNSS track both see (and, for a car, from
// the course through the non-holonomic constraint). The cost is not convex in yaw: the fit starts from four yaws 90° apart about the GNSS course
// and keeps the best; the best other solution (forward against backward, a mirror image) tells how
// ambiguous it is. σ's come from the fit's information (with the sensors' stated noise and bias priors),
// inflated when the residuals are larger or more correlated in time than stated.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/earth.h"
#include "core/measurements.h"
#include "core/nav_state.h"
#include "core/sensors.h"

namespace gins {

// The mean IMU readings of a standstill (gyro and accelerometer), with their spread.
struct StaticSummary {
  double t_start = 0.0, t_end = 0.0;
  int n = 0;
  Vec3 gyro_mean = Vec3::Zero(), acc_mean = Vec3::Zero();
  Vec3 gyro_std = Vec3::Zero(), acc_std = Vec3::Zero();  // per sample
  double mean_dt = 0.0;
  // The standstill's GNSS fixes (the antenna did not move) are in AlignmentInput::fixes.
};

struct AlignmentInput {
  std::vector<ImuSample> imu;  // body axes, time order; imu.front().t is t0
  // Measurements with t in [t0, imu.back().t] (GNSS fixes also from the standstill before t0, if any).
  std::vector<GnssMeasurement> fixes;
  std::vector<GnssVelocityMeasurement> gnss_velocities;
  std::vector<WheelMeasurement> wheels;
  std::optional<StaticSummary> standstill;  // the vehicle stood still until t0
};

struct AlignmentOptions {
  SensorOptions sensors;
  double zero_velocity_sigma = 0.01;  // m/s, a standstill's velocity (standstill.velocity_sigma_m_s)
};

struct AlignmentFit {
  bool solved = false;
  std::string problem;  // why not solved
  NavState x0;          // at t0
  Mat15 P0 = Mat15::Zero();
  NavState x;           // at the window's last measurement, where the estimators start
  Mat15 P = Mat15::Zero();
  double yaw_sigma = kPi, tilt_sigma = kPi;  // rad, of x: about world z, and the larger about E and N
  double chi2 = 0.0;                          // 2·cost of the best solution
  int dof = 0;
  double inflation = 1.0;             // covariance inflation from the residuals (size and correlation)
  double runner_up_delta_chi2 = 0.0;  // best other solution's χ² minus the best's (+∞: none found)
  double runner_up_yaw = 0.0;         // its yaw at t0 (rad)
  bool heading_used = false;
  bool nhc_used = false;  // the fit assumed motion along body x (a land vehicle)
  int fixes_used = 0;
};

// The fit over the window. Needs at least two IMU samples and two GNSS fixes (or a standstill and a heading).
AlignmentFit Align(const AlignmentInput& in, const AlignmentOptions& options, const EarthModel& earth);

// The longest window over which the IMU's stated white noise alone moves the predicted position by less
// than sigma_m (m): g²·N_g²·T⁵/20 + N_a²·T³/3 ≤ σ² (angle random walk tilting the platform, velocity
// random walk), within [min_s, max_s].
double ImuWindowForSigma(const ImuOptions& imu, double g_norm, double sigma_m, double min_s, double max_s);

}  // namespace gins
