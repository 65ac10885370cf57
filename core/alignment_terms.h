// The residuals of the alignment fit (core/alignment.h), each written once as a template on the scalar, from
// the shared measurement models. All of them take the one 15-vector the fit estimates, the navigation state
// at the window's first epoch t0 in NavState tangent order,
//   x = (p_wb, v_w, δθ, bg, ba),   R_wb(t0) = R_ref·Exp(δθ)   (right perturbation, core/conventions.h),
// and predict the state at a measurement's epoch through the preintegrated IMU from t0 (PreintSnapshot,
// PredictKinematics with the Earth terms). Residuals are whitened (divided by their 1-σ).
#pragma once

#include "core/conventions.h"
#include "core/gnss_model.h"
#include "core/gnss_velocity_model.h"
#include "core/heading_model.h"
#include "core/nav_state.h"
#include "core/preintegration.h"
#include "core/so3.h"
#include "core/wheel_model.h"

namespace gins {

// The preintegrated IMU from t0 to one epoch: the deltas, their bias Jacobians and noise covariance, as a
// Preintegration held them then (PredictKinematics reads the same accessors).
class PreintSnapshot {
 public:
  PreintSnapshot() = default;
  // Nothing integrated: the epoch is t0 itself (or the vehicle stood still from it to t0).
  PreintSnapshot(const Vec3& bg_lin, const Vec3& ba_lin) : bg_lin_(bg_lin), ba_lin_(ba_lin) {}
  explicit PreintSnapshot(const Preintegration& pre)
      : dt_(pre.dt()), delta_(pre.delta()), J_(pre.bias_jacobian()), cov_(pre.cov()), bg_lin_(pre.bg_lin()),
        ba_lin_(pre.ba_lin()) {}

  double dt() const { return dt_; }
  const Quat& dq() const { return delta_.dq; }
  const Vec3& dv() const { return delta_.dv; }
  const Vec3& dp() const { return delta_.dp; }
  const Vec3& bg_lin() const { return bg_lin_; }
  const Vec3& ba_lin() const { return ba_lin_; }
  const Mat9& cov() const { return cov_; }
  Mat3 dp_dbg() const { return J_.block<3, 3>(preint::kP, preint::kBg); }
  Mat3 dp_dba() const { return J_.block<3, 3>(preint::kP, preint::kBa); }
  Mat3 dv_dbg() const { return J_.block<3, 3>(preint::kV, preint::kBg); }
  Mat3 dv_dba() const { return J_.block<3, 3>(preint::kV, preint::kBa); }
  Mat3 dR_dbg() const { return J_.block<3, 3>(preint::kTheta, preint::kBg); }

 private:
  double dt_ = 0.0;
  Preintegration::Delta delta_;
  Mat96 J_ = Mat96::Zero();
  Mat9 cov_ = Mat9::Zero();
  Vec3 bg_lin_ = Vec3::Zero(), ba_lin_ = Vec3::Zero();
};

namespace align {

template <typename T>
using Vec3T = Eigen::Matrix<T, 3, 1>;

template <typename T>
struct State {
  Vec3T<T> p, v, bg, ba;
  Eigen::Quaternion<T> q;
};

// The state at t0 from the fit's 15-vector.
template <typename T>
State<T> Unpack(const T* x, const Quat& q_ref) {
  State<T> s;
  s.p = Eigen::Map<const Vec3T<T>>(x + nav::kP);
  s.v = Eigen::Map<const Vec3T<T>>(x + nav::kV);
  s.q = q_ref.cast<T>() * ExpQuat<T>(Vec3T<T>(Eigen::Map<const Vec3T<T>>(x + nav::kTheta)));
  s.bg = Eigen::Map<const Vec3T<T>>(x + nav::kBg);
  s.ba = Eigen::Map<const Vec3T<T>>(x + nav::kBa);
  return s;
}

// What every term that looks at a later epoch shares: the preintegration to it and the Earth.
struct Epoch {
  PreintSnapshot pre;
  ImuEarthTerms earth;
  EarthTurns turns;
  Quat q_ref = Quat::Identity();

  Epoch() = default;
  Epoch(const PreintSnapshot& p, const ImuEarthTerms& e, const Quat& q) : pre(p), earth(e), turns(e, p.dt()), q_ref(q) {}

  template <typename T>
  PredictedKinematics<T> Predict(const T* x) const {
    const State<T> s = Unpack(x, q_ref);
    return PredictKinematics<T>(pre, earth, turns, s.p, s.q, s.v, s.bg, s.ba);
  }
};

// GNSS antenna position (core/gnss_model.h): 3 residuals.
struct GnssTerm {
  Epoch epoch;
  Vec3 lever_b, z_w, inv_sigma;
  template <typename T>
  bool operator()(const T* x, T* r) const {
    const PredictedKinematics<T> k = epoch.Predict(x);
    Eigen::Map<Vec3T<T>>{r} =
        GnssPositionModel::Residual<T>(k.p, k.q, lever_b, z_w).cwiseProduct(inv_sigma.cast<T>());
    return true;
  }
};

// GNSS (Doppler) antenna velocity (core/gnss_velocity_model.h): 3 residuals. omega_b: body rate at the epoch.
struct GvelTerm {
  Epoch epoch;
  Vec3 omega_b, lever_b, z_w, inv_sigma;
  template <typename T>
  bool operator()(const T* x, T* r) const {
    const PredictedKinematics<T> k = epoch.Predict(x);
    Eigen::Map<Vec3T<T>>{r} =
        GnssVelocityModel::Residual<T>(k.q, k.v, omega_b, lever_b, z_w).cwiseProduct(inv_sigma.cast<T>());
    return true;
  }
};

// Dual-antenna heading (core/heading_model.h): 1 residual.
struct HeadingTerm {
  Epoch epoch;
  double mount_yaw = 0.0, yaw_meas = 0.0, inv_sigma = 1.0;
  template <typename T>
  bool operator()(const T* x, T* r) const {
    const PredictedKinematics<T> k = epoch.Predict(x);
    r[0] = HeadingModel::Residual<T>(k.q, mount_yaw, yaw_meas) * T(inv_sigma);
    return true;
  }
};

// Forward speed from the wheels (core/wheel_model.h, scale 1; its uncertainty is in the σ): 1 residual.
struct WheelTerm {
  Epoch epoch;
  double speed = 0.0, inv_sigma = 1.0;
  template <typename T>
  bool operator()(const T* x, T* r) const {
    const PredictedKinematics<T> k = epoch.Predict(x);
    r[0] = WheelSpeedModel::Residual<T>(k.q, k.v, T(1), speed) * T(inv_sigma);
    return true;
  }
};

// A car's non-holonomic constraint at the rear-axle centre (core/wheel_model.h): no lateral and no vertical
// speed there; omega_b is the body rate at the epoch. 2 residuals.
struct NhcTerm {
  Epoch epoch;
  Vec3 omega_b, lever_b;
  double inv_sigma = 1.0;
  template <typename T>
  bool operator()(const T* x, T* r) const {
    const PredictedKinematics<T> k = epoch.Predict(x);
    const Vec3T<T> v_a = AxleVelocity<T>(k.q, k.v, omega_b, lever_b);
    Eigen::Map<Eigen::Matrix<T, 2, 1>>{r} = v_a.template tail<2>() * T(inv_sigma);
    return true;
  }
};

// A standstill that ended at t0, summarised by its mean IMU readings: at rest the accelerometer reads
// R_wbᵀ·(−g_w) + ba and the gyro R_wbᵀ·ω_ie + bg (the Earth rate is not the bias), and the velocity is zero.
// 9 residuals: specific force, rate, velocity.
struct StaticTerm {
  Quat q_ref = Quat::Identity();
  Vec3 g_w, rate_w, acc_mean, gyro_mean;
  double inv_sigma_acc = 1.0, inv_sigma_gyro = 1.0, inv_sigma_v = 1.0;
  template <typename T>
  bool operator()(const T* x, T* r) const {
    const State<T> s = Unpack(x, q_ref);
    const Eigen::Quaternion<T> q_bw = s.q.conjugate();
    Eigen::Map<Vec3T<T>>{r} = (q_bw * Vec3T<T>(-g_w.cast<T>()) + s.ba - acc_mean.cast<T>()) * T(inv_sigma_acc);
    Eigen::Map<Vec3T<T>>{r + 3} = (q_bw * rate_w.cast<T>() + s.bg - gyro_mean.cast<T>()) * T(inv_sigma_gyro);
    Eigen::Map<Vec3T<T>>{r + 6} = s.v * T(inv_sigma_v);
    return true;
  }
};

// The sensors' stated bias priors (imu.init_*_bias_sigma): 6 residuals.
struct BiasPriorTerm {
  Vec3 bg_prior = Vec3::Zero(), ba_prior = Vec3::Zero();
  double inv_sigma_bg = 1.0, inv_sigma_ba = 1.0;
  template <typename T>
  bool operator()(const T* x, T* r) const {
    for (int i = 0; i < 3; ++i) {
      r[i] = (x[nav::kBg + i] - T(bg_prior[i])) * T(inv_sigma_bg);
      r[3 + i] = (x[nav::kBa + i] - T(ba_prior[i])) * T(inv_sigma_ba);
    }
    return true;
  }
};

}  // namespace align
}  // namespace gins
