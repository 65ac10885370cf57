// Manifold of a pose parameter block, with the right perturbation of core/conventions.h.
//
// Block layout (7 doubles):  [ p_wb.x, p_wb.y, p_wb.z,  q_wb.x, q_wb.y, q_wb.z, q_wb.w ]
//   p_wb: body origin in w (m);  q_wb: Hamilton unit quaternion in Eigen storage order (x, y, z, w).
// Tangent (6):  [ δp (m, world axes),  δθ (rad, full angle, body axes) ]
//   Plus(x, δ)  = ( p + δp,  q·Exp(δθ) )
//   Minus(y, x) = ( p_y − p_x,  Log(q_x⁻¹·q_y) )        (shortest rotation: angle in [0, π])
// q and −q are the same pose: Minus does not distinguish them, so Plus(x, Minus(y, x)) returns y's rotation
// possibly as −q_y. This is NOT Ceres's QuaternionManifold / EigenQuaternionManifold (left perturbation,
// half-angle delta); do not mix them.
#pragma once

#include <ceres/manifold.h>

#include "core/conventions.h"

namespace gins {

namespace pose {
constexpr int kAmbient = 7;
constexpr int kTangent = 6;
constexpr int kP = 0;      // position offset, ambient and tangent
constexpr int kQ = 3;      // quaternion offset (ambient)
constexpr int kTheta = 3;  // δθ offset (tangent)
}  // namespace pose

// Views of a pose block as Eigen types; templated for autodiff.
template <typename T>
Eigen::Map<const Eigen::Matrix<T, 3, 1>> PosePosition(const T* pose) {
  return Eigen::Map<const Eigen::Matrix<T, 3, 1>>(pose + pose::kP);
}
template <typename T>
Eigen::Map<const Eigen::Quaternion<T>> PoseRotation(const T* pose) {
  return Eigen::Map<const Eigen::Quaternion<T>>(pose + pose::kQ);
}
// Writes (p_wb, q_wb) into a 7-double block.
inline void SetPose(const Vec3& p_wb, const Quat& q_wb, double* pose) {
  Eigen::Map<Vec3>(pose + pose::kP) = p_wb;
  Eigen::Map<Quat>(pose + pose::kQ) = q_wb;
}

class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return pose::kAmbient; }
  int TangentSize() const override { return pose::kTangent; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  // ∂Plus(x, δ)/∂δ at δ = 0, row-major 7×6.
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  // ∂Minus(y, x)/∂y at y = x, row-major 6×7.
  bool MinusJacobian(const double* x, double* jacobian) const override;

  // ∂Minus(y, x)/∂y at any y (row-major 6×7): what a prior r(y) = f(Minus(y, x0)) needs away from x0.
  // Rotation part: Jr⁻¹(Log(q_x⁻¹q_y))·M(q_y), with M(q) the 3×4 map of MinusJacobian at q; it vanishes along
  // the radial direction q_y, like Minus itself.
  static void MinusJacobianAt(const double* y, const double* x, double* jacobian);
};

// ∂Log(q⁻¹·q')/∂q' at q' = q, columns (x, y, z, w): 2·[w·I − [v]×, −v] (PoseManifold::MinusJacobian's rotation
// part). It maps the tangent direction q·(δθ/2, 0) to δθ and the radial direction q to 0.
Eigen::Matrix<double, 3, 4> QuaternionLift(const Quat& q);

// Writes an M-row Jacobian of a pose block given in the tangent (columns δp, δθ) as the ambient one Ceres
// wants, J_tan·M(q): the p columns as they are, the q columns J_θ·QuaternionLift(q). Any J_amb with
// J_amb·PlusJacobian = J_tan is equivalent to Ceres (factors/imu_factor.h, ImuCostFunction, says why); this
// one has no component along the radial direction q. out: M×7, row-major.
template <int M, typename DerivedP, typename DerivedTheta>
void WriteAmbientPoseJacobian(const Eigen::MatrixBase<DerivedP>& J_dp, const Eigen::MatrixBase<DerivedTheta>& J_dtheta,
                              const Quat& q, double* out) {
  Eigen::Map<Eigen::Matrix<double, M, pose::kAmbient, Eigen::RowMajor>> J(out);
  J.template middleCols<3>(pose::kP) = J_dp;
  J.template middleCols<4>(pose::kQ) = J_dtheta * QuaternionLift(q);
}

}  // namespace gins
