// Analytic Jacobians of the odometer and chord factors (their headers give the formulas); the residuals are
// the factors' own (core/odometry_model.h). Autodiff of the same residuals is their test oracle.
#include <glog/logging.h>

#include "core/so3.h"
#include "factors/chord_factor.h"
#include "factors/odometer_factor.h"

namespace gins {
namespace {

// The pieces both factors' Jacobians share: R_iᵀ, w = R_iᵀ·(p_j + R_j·l − p_i) and R_iᵀ·R_j·[l]×.
struct AxleTerms {
  Mat3 R_iT;
  Vec3 w;
  Mat3 R_ij_l;
};

AxleTerms Terms(const double* pose_i, const double* pose_j, const Vec3& lever_b) {
  const Mat3 R_i = Quat(PoseRotation(pose_i)).toRotationMatrix();
  const Mat3 R_j = Quat(PoseRotation(pose_j)).toRotationMatrix();
  AxleTerms t;
  t.R_iT = R_i.transpose();
  t.w = t.R_iT * (Vec3(PosePosition(pose_j)) + R_j * lever_b - Vec3(PosePosition(pose_i)));
  t.R_ij_l = t.R_iT * R_j * Hat<double>(lever_b);
  return t;
}

// Both poses' ambient Jacobians of r = A·d (A: M×3).
template <int M>
void WritePoseJacobians(const Eigen::Matrix<double, M, 3>& A, const AxleTerms& t, const double* pose_i,
                        const double* pose_j, double** jacobians) {
  const Eigen::Matrix<double, M, 3> A_R = A * t.R_iT;
  if (jacobians[0] != nullptr) {
    WriteAmbientPoseJacobian<M>(-A_R, A * Hat<double>(t.w), Quat(PoseRotation(pose_i)), jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    WriteAmbientPoseJacobian<M>(A_R, -A * t.R_ij_l, Quat(PoseRotation(pose_j)), jacobians[1]);
  }
}

}  // namespace

ceres::CostFunction* ChordFactor::Create(double dt, double sigma, const Vec3& lever_b, const Vec3& path_i) {
  CHECK(dt > 0.0 && sigma > 0.0) << "ChordFactor: dt and σ must be > 0";
  return new ChordCostFunction(ChordFactor(dt, sigma, lever_b, path_i));
}

bool ChordCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  factor_(parameters[0], parameters[1], residuals);
  if (jacobians == nullptr || (jacobians[0] == nullptr && jacobians[1] == nullptr)) return true;
  const AxleTerms t = Terms(parameters[0], parameters[1], factor_.lever_b());
  const Eigen::Matrix<double, 2, 3> A = factor_.across_i() * (factor_.inv_sigma() / factor_.dt());
  WritePoseJacobians<2>(A, t, parameters[0], parameters[1], jacobians);
  return true;
}

ceres::CostFunction* OdometerFactor::Create(const Vec3& displacement_i, double sigma, const Vec3& lever_b) {
  CHECK_GT(sigma, 0.0) << "OdometerFactor: σ must be > 0";
  return new OdometerCostFunction(OdometerFactor(displacement_i, sigma, lever_b));
}

bool OdometerCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  factor_(parameters[0], parameters[1], parameters[2], residuals);
  if (jacobians == nullptr) return true;
  const AxleTerms t = Terms(parameters[0], parameters[1], factor_.lever_b());
  const double scale = parameters[2][0];
  const Eigen::Matrix<double, 1, 3> a = (scale * factor_.inv_sigma()) * factor_.u_i().transpose();
  WritePoseJacobians<1>(a, t, parameters[0], parameters[1], jacobians);
  if (jacobians[2] != nullptr) {
    jacobians[2][0] = factor_.u_i().dot(t.w - factor_.lever_b()) * factor_.inv_sigma();
  }
  return true;
}

}  // namespace gins
