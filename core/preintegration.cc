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
  IntegrateGuess(gyro, acc, dt, Vec3::Constant(held_gyro_sigma), held_acc_sigma);
}

void Preintegration::IntegrateGuess(const Vec3& gyro, const Vec3& acc, double dt, const Vec3& held_gyro_sigma,
                                    double held_acc_sigma) {
  // Programmer errors: the smoother coasts only forward in time (dt > 0, bounded by the reader's time limit)
  // with σ from constants.
  CHECK(std::isfinite(dt) && dt >= 0.0) << "Preintegration::IntegrateGuess: bad dt " << dt;
  CHECK((held_gyro_sigma.array() >= 0.0).all() && held_acc_sigma >= 0.0) << "Preintegration::IntegrateGuess: bad sigma";
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
  // A guessed step's held rate is not a sensor's reading: its error is the coast's own (held σ, white
  // acceleration), not a turn of the specific force by the sculling term.
  if (s.held_acc_sigma > 0.0 || !s.held_gyro_sigma.isZero(0.0)) {
    J.B.block<3, 3>(preint::kP, preint::kBg).setZero();
    J.B.block<3, 3>(preint::kV, preint::kBg).setZero();
  }
  Mat6 Q = ImuDiscreteNoise(gyro_noise_density_, acc_noise_density_, s.dt);
  Q.diagonal().head<3>() += s.held_gyro_sigma.cwiseAbs2();
  Q.diagonal().tail<3>().array() += s.held_acc_sigma * s.held_acc_sigma;
  // The kernel's structured products (MulA, MulBG): A and B are mostly zero and identity blocks.
  const Mat9 A_cov = MulA<9>(J, cov_);
  cov_ = MulA<9>(J, A_cov.transpose()).transpose();
  AddDrivingNoise(J, Q.diagonal(), cov_);
  if (s.held_acc_sigma > 0.0) AddWhiteAcceleration(s.held_acc_sigma, s.dt);
  J_bias_ = MulA<6>(J, J_bias_) + J.B;
  delta_.dq = y.q;
  delta_.dv = y.v;
  delta_.dp = y.p;
  dt_total_ += s.dt;
}

void Preintegration::AddWhiteAcceleration(double sigma, double dt) {
  // An acceleration of white noise with PSD q = σ²·dt over dt (the held part's velocity variance σ²·dt²):
  // δv = ∫a, δp = ∫∫a, per axis [[dt³/3, dt²/2], [dt²/2, dt]]·q, isotropic so in any frame.
  const double q = sigma * sigma * dt;
  cov_.block<3, 3>(preint::kP, preint::kP).diagonal().array() += q * dt * dt * dt / 3.0;
  cov_.block<3, 3>(preint::kP, preint::kV).diagonal().array() += q * dt * dt / 2.0;
  cov_.block<3, 3>(preint::kV, preint::kP).diagonal().array() += q * dt * dt / 2.0;
  cov_.block<3, 3>(preint::kV, preint::kV).diagonal().array() += q * dt;
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

EarthTurns::EarthTurns(const ImuEarthTerms& earth, double dt) : rotating(!earth.rate_w.isZero(0.0)) {
  if (!rotating) return;
  back_r = ImuEarthTerms::Turn(earth.rate_w, dt, 1.0).conjugate();
  back_v = ImuEarthTerms::Turn(earth.rate_w, dt, 0.5).conjugate();
  back_p = ImuEarthTerms::Turn(earth.rate_w, dt, 1.0 / 3.0).conjugate();
  m_inv = (Mat3::Identity() + Hat<double>(earth.rate_w) * dt).inverse();
}

NavState Preintegration::Predict(const NavState& state_i, const ImuEarthTerms& earth) const {
  if (earth.rate_w.isZero(0.0)) return Predict(state_i, earth.g_w);
  const PredictedKinematics<double> k =
      PredictKinematics<double>(*this, earth, EarthTurns(earth, dt_total_), state_i.p_wb, state_i.q_wb,
                                state_i.v_w, state_i.bg, state_i.ba);
  NavState state_j = state_i;
  state_j.t = state_i.t + dt_total_;
  state_j.q_wb = k.q.normalized();
  state_j.v_w = k.v;
  state_j.p_wb = k.p;
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

void PredictedTransition(const NavState& x_i, const Preintegration& pre, double gyro_bias_rw, double acc_bias_rw,
                         Mat15* Phi_out, Mat15* Q_out) {
  const Preintegration::Delta d = pre.Corrected(x_i.bg, x_i.ba);
  const Mat3 R_i = x_i.R_wb();
  const double T = pre.dt();
  const Mat96& J = pre.bias_jacobian();
  Mat15& Phi = *Phi_out;
  Phi.setIdentity();
  Phi.block<3, 3>(nav::kP, nav::kV) = Mat3::Identity() * T;
  Phi.block<3, 3>(nav::kP, nav::kTheta) = -R_i * Hat<double>(d.dp);
  Phi.block<3, 3>(nav::kV, nav::kTheta) = -R_i * Hat<double>(d.dv);
  Phi.block<3, 3>(nav::kTheta, nav::kTheta) = d.dq.toRotationMatrix().transpose();
  Phi.block<3, 6>(nav::kP, nav::kBg) = R_i * J.middleRows<3>(preint::kP);
  Phi.block<3, 6>(nav::kV, nav::kBg) = R_i * J.middleRows<3>(preint::kV);
  Phi.block<3, 3>(nav::kTheta, nav::kBg) = J.block<3, 3>(preint::kTheta, preint::kBg);
  // The deltas' noise: δp and δv rotate into w, δθ is already the right perturbation of R_j.
  Mat9 Rot = Mat9::Identity();
  Rot.block<3, 3>(preint::kP, preint::kP) = R_i;
  Rot.block<3, 3>(preint::kV, preint::kV) = R_i;
  Mat15& Q = *Q_out;
  Q.setZero();
  // Preintegration order (δp, δv, δθ) is NavState's first nine.
  Q.topLeftCorner<9, 9>() = Rot * pre.cov() * Rot.transpose();
  Q.block<3, 3>(nav::kBg, nav::kBg).diagonal().setConstant(gyro_bias_rw * gyro_bias_rw * T);
  Q.block<3, 3>(nav::kBa, nav::kBa).diagonal().setConstant(acc_bias_rw * acc_bias_rw * T);
}

Mat15 PredictedCovariance(const NavState& x_i, const Mat15& P_i, const Preintegration& pre, double gyro_bias_rw,
                          double acc_bias_rw) {
  Mat15 Phi, Q;
  PredictedTransition(x_i, pre, gyro_bias_rw, acc_bias_rw, &Phi, &Q);
  const Mat15 P = Phi * P_i * Phi.transpose() + Q;
  return 0.5 * (P + P.transpose());
}

}  // namespace gins
