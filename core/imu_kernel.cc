#include "core/imu_kernel.h"

#include "core/so3.h"

namespace gins {

Kinematics ImuStep(const Kinematics& x, const Vec3& omega, const Vec3& acc, const Vec3& g_w, double dt,
                   ImuStepJacobians* J, const Vec3& earth_rate_w) {
  const Mat3 R = x.q.toRotationMatrix();
  const bool rotating = !earth_rate_w.isZero(0.0);
  const Vec3 phi = omega * dt;
  const Quat dq = ExpQuat<double>(phi);
  // The body turns against w by φ_w = (ω − Rᵀω_ie)·dt during the step, so the specific force is rotated by
  // the attitude it has on average (sculling): ∫R(t)·a dt = R·(I + ½[φ_w]×)·a·dt and
  // ∫∫R(t)·a dt² = R·(I + ⅓[φ_w]×)·a·dt²/2, to second order (at rest on the rotating Earth φ_w = 0).
  const Vec3 earth_rate_b = rotating ? Vec3(R.transpose() * earth_rate_w) : Vec3::Zero();
  const Vec3 phi_w = phi - earth_rate_b * dt;
  const Vec3 phi_x_acc = phi_w.cross(acc);
  const Vec3 acc_v = acc + 0.5 * phi_x_acc;
  const Vec3 acc_p = acc + (1.0 / 3.0) * phi_x_acc;
  Vec3 common = g_w;
  if (rotating) common -= 2.0 * earth_rate_w.cross(x.v);
  const Vec3 a_v = R * acc_v + common;
  const Vec3 a_p = R * acc_p + common;

  Kinematics y;
  y.p = x.p + x.v * dt + 0.5 * a_p * dt * dt;
  y.v = x.v + a_v * dt;
  // The left factor turns w under the body; a right perturbation of R passes through it unchanged.
  y.q = rotating ? (ExpQuat<double>(Vec3(-earth_rate_w * dt)) * x.q * dq).normalized() : (x.q * dq).normalized();

  if (J != nullptr) {
    const double dt2 = 0.5 * dt * dt;
    const Mat3 I = Mat3::Identity();
    const Mat3 phi_hat = Hat<double>(phi_w);
    // φ_w = (ω̃ − bg − Rᵀω_ie)·dt, so a gyro-bias error turns the rotated specific force,
    // ∂(φ_w×a)/∂bg = [a]×·dt, and so does an attitude error through Rᵀω_ie: ∂(φ_w×a)/∂δθ = [a]×[Rᵀω_ie]×·dt.
    const Mat3 R_acc_hat_dt = R * Hat<double>(acc) * dt;
    const Mat3 turn = R_acc_hat_dt * Hat<double>(earth_rate_b);  // zero for the flat model
    J->A.setZero();
    J->A.block<3, 3>(0, 0) = I;
    J->A.block<3, 3>(0, 3) = I * dt;
    J->A.block<3, 3>(0, 6) = (-R * Hat<double>(acc_p) + turn / 3.0) * dt2;
    J->A.block<3, 3>(3, 3) = I;
    J->A.block<3, 3>(3, 6) = (-R * Hat<double>(acc_v) + 0.5 * turn) * dt;
    J->A.block<3, 3>(6, 6) = dq.toRotationMatrix().transpose();
    J->B.setZero();
    J->B.block<3, 3>(0, 0) = R_acc_hat_dt * (dt2 / 3.0);
    J->B.block<3, 3>(0, 3) = -R * (I + phi_hat / 3.0) * dt2;
    J->B.block<3, 3>(3, 0) = R_acc_hat_dt * (0.5 * dt);
    J->B.block<3, 3>(3, 3) = -R * (I + 0.5 * phi_hat) * dt;
    J->B.block<3, 3>(6, 0) = -RightJacobian(phi) * dt;
    J->G.setZero();
    J->G.block<3, 3>(0, 0) = I * dt2;
    J->G.block<3, 3>(3, 0) = I * dt;
    J->coriolis = rotating;
    if (rotating) {
      // ∂(−2ω_ie×v)/∂v = −2[ω_ie]×, entering v' over dt and p' over ½dt².
      const Mat3 C = -2.0 * Hat<double>(earth_rate_w);
      J->A.block<3, 3>(0, 3) += C * dt2;
      J->A.block<3, 3>(3, 3) += C * dt;
    }
  }
  return y;
}

Mat6 ImuDiscreteNoise(double gyro_noise_density, double acc_noise_density, double dt) {
  Mat6 Q = Mat6::Zero();
  Q.block<3, 3>(0, 0).diagonal().setConstant(gyro_noise_density * gyro_noise_density / dt);
  Q.block<3, 3>(3, 3).diagonal().setConstant(acc_noise_density * acc_noise_density / dt);
  return Q;
}

}  // namespace gins
