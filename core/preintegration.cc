#include "core/preintegration.h"

#include <glog/logging.h>

#include <cmath>

#include "core/imu_kernel.h"
#include "core/so3.h"

namespace gins {

Preintegration::Preintegration(const Vec3& bg_lin, const Vec3& ba_lin, double gyro_noise_density,
                               double acc_noise_density)
    : bg_lin_(bg_lin),
      ba_lin_(ba_lin),
      gyro_noise_density_(gyro_noise_density),
      acc_noise_density_(acc_noise_density) {
  CHECK(gyro_noise_density >= 0.0 && acc_noise_density >= 0.0) << "noise densities must be non-negative";
}

void Preintegration::Reset() {
  dt_total_ = 0.0;
  delta_ = Delta();
  cov_.setZero();
  J_bias_.setZero();
}

void Preintegration::Integrate(const Vec3& gyro, const Vec3& acc, double dt) {
  CHECK(std::isfinite(dt) && dt >= 0.0) << "Preintegration::Integrate: bad dt " << dt;
  if (dt == 0.0) return;
  samples_.push_back(Sample{gyro, acc, dt});
  Step(samples_.back());
}

void Preintegration::IntegrateGuess(const Vec3& gyro, const Vec3& acc, double dt, double held_gyro_sigma,
                                    double held_acc_sigma) {
  CHECK(std::isfinite(dt) && dt >= 0.0) << "Preintegration::IntegrateGuess: bad dt " << dt;
  CHECK(held_gyro_sigma >= 0.0 && held_acc_sigma >= 0.0) << "Preintegration::IntegrateGuess: bad sigma";
  if (dt == 0.0) return;
  samples_.push_back(Sample{gyro, acc, dt, held_gyro_sigma, held_acc_sigma});
  Step(samples_.back());
}

void Preintegration::Step(const Sample& s) {
  Kinematics x;
  x.q = delta_.dq;
  x.v = delta_.dv;
  x.p = delta_.dp;
  ImuStepJacobians J;
  const Kinematics y = ImuStep(x, s.gyro - bg_lin_, s.acc - ba_lin_, Vec3::Zero(), s.dt, &J);
  // Covariance and bias Jacobians use A, B at the state before the step (as the kernel defines them).
  Mat6 Q = ImuDiscreteNoise(gyro_noise_density_, acc_noise_density_, s.dt);
  Q.diagonal().head<3>().array() += s.held_gyro_sigma * s.held_gyro_sigma;
  Q.diagonal().tail<3>().array() += s.held_acc_sigma * s.held_acc_sigma;
  // The kernel's structured products (MulA, MulBG): A and B are mostly zero and identity blocks.
  const Mat9 A_cov = MulA<9>(J, cov_);
  const Eigen::Matrix<double, 9, 6> BQ = J.B.lazyProduct(Q);
  cov_ = MulA<9>(J, Mat9(A_cov.transpose())).transpose() + BQ.lazyProduct(J.B.transpose());
  J_bias_ = MulA<6>(J, J_bias_) + J.B;
  delta_.dq = y.q;
  delta_.dv = y.v;
  delta_.dp = y.p;
  dt_total_ += s.dt;
}

void Preintegration::Reintegrate(const Vec3& bg_lin, const Vec3& ba_lin) {
  bg_lin_ = bg_lin;
  ba_lin_ = ba_lin;
  Reset();
  for (const Sample& s : samples_) Step(s);
}

Preintegration::Delta Preintegration::Corrected(const Vec3& bg, const Vec3& ba) const {
  const Vec3 dbg = bg - bg_lin_;
  const Vec3 dba = ba - ba_lin_;
  Delta d;
  d.dq = (delta_.dq * ExpQuat<double>(dR_dbg() * dbg)).normalized();
  d.dv = delta_.dv + dv_dbg() * dbg + dv_dba() * dba;
  d.dp = delta_.dp + dp_dbg() * dbg + dp_dba() * dba;
  return d;
}

Quat ImuEarthTerms::Turn(const Vec3& rate_w, double dt, double fraction) {
  return ExpQuat<double>(Vec3(rate_w * (dt * fraction)));
}

NavState Preintegration::Predict(const NavState& state_i, const ImuEarthTerms& earth) const {
  if (earth.rate_w.isZero(0.0)) return Predict(state_i, earth.g_w);
  const Delta d = Corrected(state_i.bg, state_i.ba);
  const Mat3 R_wi = state_i.R_wb();
  const double T = dt_total_;
  const Vec3& w = earth.rate_w;
  const Vec3& g = earth.g_w;
  NavState state_j = state_i;
  state_j.t = state_i.t + T;
  state_j.q_wb = (ImuEarthTerms::Turn(w, T, 1.0).conjugate() * state_i.q_wb * d.dq).normalized();
  // (I + [ω]×T)·(p_j − p_i) = v_i·T + ½g·T² + Exp(−ωT/3)·R_i·Δp
  const Vec3 rhs = state_i.v_w * T + 0.5 * g * T * T + ImuEarthTerms::Turn(w, T, 1.0 / 3.0).conjugate() * (R_wi * d.dp);
  const Vec3 dp_w = (Mat3::Identity() + Hat<double>(w) * T).inverse() * rhs;
  state_j.p_wb = state_i.p_wb + dp_w;
  state_j.v_w = state_i.v_w + g * T - 2.0 * w.cross(dp_w) + ImuEarthTerms::Turn(w, T, 0.5).conjugate() * (R_wi * d.dv);
  return state_j;
}

NavState Preintegration::Predict(const NavState& state_i, const Vec3& g_w) const {
  const Delta d = Corrected(state_i.bg, state_i.ba);
  const Mat3 R_wi = state_i.R_wb();
  const double T = dt_total_;
  NavState state_j = state_i;
  state_j.t = state_i.t + T;
  state_j.q_wb = (state_i.q_wb * d.dq).normalized();
  state_j.v_w = state_i.v_w + g_w * T + R_wi * d.dv;
  state_j.p_wb = state_i.p_wb + state_i.v_w * T + 0.5 * g_w * T * T + R_wi * d.dp;
  return state_j;
}

}  // namespace gins
