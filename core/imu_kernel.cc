#include "core/imu_kernel.h"

#include "core/so3.h"

namespace gins {

Kinematics ImuStep(const Kinematics& x, const Vec3& omega, const Vec3& acc, const Vec3& g_w, double dt,
                   ImuStepJacobians* J, const Vec3& earth_rate_w) {
  const Mat3 R = x.q.toRotationMatrix();
  const bool rotating = !earth_rate_w.isZero(0.0);
  Vec3 a_w = R * acc + g_w;
  if (rotating) a_w -= 2.0 * earth_rate_w.cross(x.v);
  const Vec3 phi = omega * dt;
  const Quat dq = ExpQuat<double>(phi);

  Kinematics y;
  y.p = x.p + x.v * dt + 0.5 * a_w * dt * dt;
  y.v = x.v + a_w * dt;
  // The left factor turns w under the body; a right perturbation of R passes through it unchanged.
  y.q = rotating ? (ExpQuat<double>(Vec3(-earth_rate_w * dt)) * x.q * dq).normalized() : (x.q * dq).normalized();

  if (J != nullptr) {
    const double dt2 = 0.5 * dt * dt;
    const Mat3 R_acc_hat = R * Hat<double>(acc);
    const Mat3 I = Mat3::Identity();
    J->A.setZero();
    J->A.block<3, 3>(0, 0) = I;
    J->A.block<3, 3>(0, 3) = I * dt;
    J->A.block<3, 3>(0, 6) = -R_acc_hat * dt2;
    J->A.block<3, 3>(3, 3) = I;
    J->A.block<3, 3>(3, 6) = -R_acc_hat * dt;
    J->A.block<3, 3>(6, 6) = dq.toRotationMatrix().transpose();
    J->B.setZero();
    J->B.block<3, 3>(0, 3) = -R * dt2;
    J->B.block<3, 3>(3, 3) = -R * dt;
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
