// Odometer factor: every encoder record between keyframes i and j, integrated (core/odometry_model.h).
//
// Parameter blocks: pose_i (7), pose_j (7) (factors/pose_manifold.h), scale_i (1: odometer scale s).
// Residual (1):
//   r = (s·uᵀ·R_iᵀ·(a_j − a_i) − |D_i|) / σ      (unitless; a = rear-axle centre, D_i the encoders'
//                                                   displacement in the body frame at i, u its direction)
// The raw residual is OdometerModel::Residual. Jacobians (OdometerCostFunction, analytic; autodiff is the
// test oracle), with d = R_iᵀ·(a_j − a_i), w = R_iᵀ·(p_j + R_j·l − p_i) = d + l and a = s·uᵀ/σ:
//   ∂r/∂δp_i = −a·R_iᵀ   ∂r/∂δθ_i = a·[w]×   ∂r/∂δp_j = a·R_iᵀ   ∂r/∂δθ_j = −a·R_iᵀ·R_j·[l]×   ∂r/∂s = uᵀ·d/σ
#pragma once

#include <ceres/cost_function.h>
#include <ceres/sized_cost_function.h>

#include "core/conventions.h"
#include "core/odometry_model.h"
#include "factors/pose_manifold.h"

namespace gins {

class OdometerFactor {
 public:
  static constexpr int kResidualDim = OdometerModel::kResidualDim;

  // displacement_i: D_i (m, body frame at i); sigma: 1-σ of |D_i| (m, > 0); lever_b: rear-axle centre in b.
  OdometerFactor(const Vec3& displacement_i, double sigma, const Vec3& lever_b)
      : distance_(displacement_i.norm()),
        u_i_(distance_ > 1e-9 ? Vec3(displacement_i / distance_) : Vec3::UnitX()),
        inv_sigma_(1.0 / sigma),
        lever_b_(lever_b) {}

  template <typename T>
  bool operator()(const T* pose_i, const T* pose_j, const T* scale_i, T* residual) const {
    residual[0] = OdometerModel::Residual<T>(Eigen::Matrix<T, 3, 1>(PosePosition(pose_i)),
                                             Eigen::Quaternion<T>(PoseRotation(pose_i)),
                                             Eigen::Matrix<T, 3, 1>(PosePosition(pose_j)),
                                             Eigen::Quaternion<T>(PoseRotation(pose_j)), scale_i[0], lever_b_, u_i_,
                                             distance_) *
                  T(inv_sigma_);
    return true;
  }

  // OdometerCostFunction (analytic Jacobians).
  static ceres::CostFunction* Create(const Vec3& displacement_i, double sigma, const Vec3& lever_b);
  // AutoDiffCostFunction<OdometerFactor, 1, 7, 7, 1> of the same residual: the test oracle.
  static ceres::CostFunction* CreateAutoDiff(const Vec3& displacement_i, double sigma, const Vec3& lever_b);

  const Vec3& u_i() const { return u_i_; }
  double inv_sigma() const { return inv_sigma_; }
  const Vec3& lever_b() const { return lever_b_; }

 private:
  double distance_;
  Vec3 u_i_;
  double inv_sigma_;
  Vec3 lever_b_;
};

class OdometerCostFunction final : public ceres::SizedCostFunction<1, pose::kAmbient, pose::kAmbient, 1> {
 public:
  explicit OdometerCostFunction(const OdometerFactor& factor) : factor_(factor) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  OdometerFactor factor_;
};

}  // namespace gins
