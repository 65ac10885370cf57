#include "factors/imu_factor.h"

#include <ceres/autodiff_cost_function.h>
#include <glog/logging.h>

#include <Eigen/Eigenvalues>

namespace gins {

Mat9 SqrtInformation(const Mat9& cov) {
  const Eigen::SelfAdjointEigenSolver<Mat9> es(0.5 * (cov + cov.transpose()));
  const Vec9 lambda = es.eigenvalues();
  const double floor = 1e-12 * lambda.maxCoeff();
  if (lambda.minCoeff() > floor) {
    const Mat9 info = cov.inverse();
    const Eigen::LLT<Mat9> llt(0.5 * (info + info.transpose()));
    if (llt.info() == Eigen::Success) return llt.matrixU();  // Uᵀ·U = Σ⁻¹
  }
  // Rank-deficient (or not quite symmetric positive definite): floor the eigenvalues.
  Vec9 inv_sqrt;
  for (int k = 0; k < 9; ++k) inv_sqrt[k] = 1.0 / std::sqrt(std::max(lambda[k], floor));
  return inv_sqrt.asDiagonal() * es.eigenvectors().transpose();
}

ImuFactor::ImuFactor(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth)
    : ImuFactor(std::move(preint), earth.g_w) {
  rotating_ = !earth.rate_w.isZero(0.0);
  if (!rotating_) return;
  rate_w_ = earth.rate_w;
  const double dt = preint_->dt();
  turn_p_ = ImuEarthTerms::Turn(rate_w_, dt, 1.0 / 3.0);
  turn_v_ = ImuEarthTerms::Turn(rate_w_, dt, 0.5);
  turn_r_ = ImuEarthTerms::Turn(rate_w_, dt, 1.0);
}

ImuFactor::ImuFactor(std::shared_ptr<const Preintegration> preint, const Vec3& g_w)
    : preint_(std::move(preint)), g_w_(g_w) {
  // Programmer errors, not data: the smoother's preintegration always reaches a new keyframe's time (it
  // coasts where no sample covers it, Smoother::IntegrateTo) and keyframes are more than kSameEpoch apart;
  // the noise densities are checked > 0 by the config; the reader bounds time stamps (log_limits::kMaxTime),
  // so the coasted covariance stays finite.
  CHECK(preint_ != nullptr);
  CHECK_GT(preint_->dt(), 0.0) << "ImuFactor over an empty preintegration";
  CHECK(preint_->cov().allFinite() && preint_->cov().trace() > 0.0)
      << "ImuFactor needs a non-zero preintegration covariance (noise densities > 0)";
  sqrt_info_ = SqrtInformation(preint_->cov());
}

ceres::CostFunction* ImuFactor::Create(std::shared_ptr<const Preintegration> preint, const Vec3& g_w) {
  return new ImuCostFunction(std::move(preint), g_w);
}

ceres::CostFunction* ImuFactor::Create(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth) {
  return new ImuCostFunction(std::move(preint), earth);
}

ceres::CostFunction* ImuFactor::CreateAutoDiff(std::shared_ptr<const Preintegration> preint, const Vec3& g_w) {
  return new ceres::AutoDiffCostFunction<ImuFactor, 9, pose::kAmbient, 3, 6, pose::kAmbient, 3>(
      new ImuFactor(std::move(preint), g_w));
}

ceres::CostFunction* ImuFactor::CreateAutoDiff(std::shared_ptr<const Preintegration> preint,
                                               const ImuEarthTerms& earth) {
  return new ceres::AutoDiffCostFunction<ImuFactor, 9, pose::kAmbient, 3, 6, pose::kAmbient, 3>(
      new ImuFactor(std::move(preint), earth));
}

namespace {

using Mat93 = Eigen::Matrix<double, 9, 3>;

}  // namespace

bool ImuCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const double* pose_i = parameters[0];
  const double* vel_i = parameters[1];
  const double* bias_i = parameters[2];
  const double* pose_j = parameters[3];
  const double* vel_j = parameters[4];
  ImuResidualTerms<double> t;
  factor_.Terms(pose_i, vel_i, bias_i, pose_j, vel_j, &t);
  const Mat9& S = factor_.sqrt_information();
  Eigen::Map<Vec9> r_w(residuals);
  r_w = S * t.r;
  if (jacobians == nullptr) return true;

  // Whitened Jacobians S·J, formed as Σ over the residual's three row blocks of (columns of S)·(row block
  // of J): J's row blocks are 3×3 matrices, many of them zero.
  const Preintegration& pi = factor_.preintegration();
  const Mat93 S_p = S.middleCols<3>(preint::kP);
  const Mat93 S_v = S.middleCols<3>(preint::kV);
  const Mat93 S_theta = S.middleCols<3>(preint::kTheta);
  const Eigen::Map<const Quat> q_i(pose_i + pose::kQ), q_j(pose_j + pose::kQ);
  const Mat3 R_iw = q_i.conjugate().toRotationMatrix();  // R_iᵀ
  const Vec3 r_theta = t.r.segment<3>(preint::kTheta);
  const Mat93 S_theta_Jr_inv = S_theta * RightJacobianInverse(r_theta);
  // r_p and r_v see the world through R_iᵀ·E (E = I for the flat model), and with Earth rotation they also
  // depend on D = p_j − p_i: ∂r_p/∂D = R_iᵀE_⅓(I + [ω]×Δt), ∂r_v/∂D = 2·R_iᵀE_½[ω]×.
  const bool rotating = factor_.rotating();
  const Mat93 S_p_R_iw = rotating ? Mat93(S_p * (R_iw * factor_.turn_p().toRotationMatrix())) : Mat93(S_p * R_iw);
  const Mat93 S_v_R_iw = rotating ? Mat93(S_v * (R_iw * factor_.turn_v().toRotationMatrix())) : Mat93(S_v * R_iw);
  Mat93 J_D = S_p_R_iw;
  if (rotating) {
    const Mat3 W = Hat<double>(factor_.rate_w());
    J_D += S_p_R_iw * W * pi.dt() + 2.0 * S_v_R_iw * W;
  }

  if (jacobians[0] != nullptr) {  // pose_i
    const Mat3 R_ji = t.q_ij.conjugate().toRotationMatrix();
    const Mat93 J_dtheta = S_p * Hat<double>(t.dp_i) + S_v * Hat<double>(t.dv_i) - S_theta_Jr_inv * R_ji;
    WriteAmbientPoseJacobian<9>(-J_D, J_dtheta, Quat(q_i), jacobians[0]);
  }
  if (jacobians[1] != nullptr) {  // vel_i
    Eigen::Map<Eigen::Matrix<double, 9, 3, Eigen::RowMajor>> J(jacobians[1]);
    J = -(pi.dt() * S_p_R_iw + S_v_R_iw);
  }
  if (jacobians[2] != nullptr) {  // bias_i (bg, ba)
    const Mat96& J_b = pi.bias_jacobian();
    Eigen::Map<Eigen::Matrix<double, 9, 6, Eigen::RowMajor>> J(jacobians[2]);
    J = -(S_p * J_b.middleRows<3>(preint::kP) + S_v * J_b.middleRows<3>(preint::kV));
    // ΔR_corr = ΔR·Exp(φ + ∂ΔR/∂bg·δ) ≈ ΔR_corr·Exp(Jr(φ)·∂ΔR/∂bg·δ), which moves r_θ by −Jr⁻¹·Eᵀ·(that).
    const Mat3 E_T = t.q_err.conjugate().toRotationMatrix();
    J.middleCols<3>(preint::kBg).noalias() -=
        S_theta_Jr_inv * (E_T * RightJacobian(t.phi_bg) * J_b.block<3, 3>(preint::kTheta, preint::kBg));
  }
  if (jacobians[3] != nullptr) {  // pose_j
    WriteAmbientPoseJacobian<9>(J_D, S_theta_Jr_inv, Quat(q_j), jacobians[3]);
  }
  if (jacobians[4] != nullptr) {  // vel_j
    Eigen::Map<Eigen::Matrix<double, 9, 3, Eigen::RowMajor>> J(jacobians[4]);
    J = S_v_R_iw;
  }
  return true;
}

}  // namespace gins
