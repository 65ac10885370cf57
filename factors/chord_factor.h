// Chord factor: the non-holonomic constraint between keyframes i and j (core/odometry_model.h): the rear-axle
// centre's chord points along the path its body x axis traced over the interval.
//
// Parameter blocks: pose_i (7), pose_j (7) (factors/pose_manifold.h).
// Residual (2):
//   r = N_i·R_iᵀ·(a_j − a_i) / (Δt·σ)   (unitless; N_i the two directions across the path, σ in m/s, the mean
//                                        lateral and vertical speed's 1-σ over the interval)
// The raw residual is ChordModel::Residual. Jacobians (ChordCostFunction, analytic; autodiff is the test
// oracle), with d = R_iᵀ·(a_j − a_i), w = R_iᵀ·(p_j + R_j·l − p_i) = d + l and A = N_i/(Δt·σ):
//   ∂r/∂δp_i = −A·R_iᵀ   ∂r/∂δθ_i = A·[w]×   ∂r/∂δp_j = A·R_iᵀ   ∂r/∂δθ_j = −A·R_iᵀ·R_j·[l]×
#pragma once

#include <ceres/cost_function.h>
#include <ceres/sized_cost_function.h>

#include "core/conventions.h"
#include "core/odometry_model.h"
#include "factors/pose_manifold.h"

namespace gins {

class ChordFactor {
 public:
  static constexpr int kResidualDim = ChordModel::kResidualDim;

  // dt: t_j − t_i (s, > 0); sigma (m/s, > 0); lever_b: rear-axle centre in b; path_i: the axle's path P_i
  // in the body frame at i (m; only its direction counts).
  ChordFactor(double dt, double sigma, const Vec3& lever_b, const Vec3& path_i)
      : dt_(dt), inv_sigma_(1.0 / sigma), lever_b_(lever_b), across_i_(ChordModel::Basis(path_i)) {}

  template <typename T>
  bool operator()(const T* pose_i, const T* pose_j, T* residual) const {
    Eigen::Map<Eigen::Matrix<T, 2, 1>> out(residual);
    out = ChordModel::Residual<T>(Eigen::Matrix<T, 3, 1>(PosePosition(pose_i)),
                                  Eigen::Quaternion<T>(PoseRotation(pose_i)),
                                  Eigen::Matrix<T, 3, 1>(PosePosition(pose_j)),
                                  Eigen::Quaternion<T>(PoseRotation(pose_j)), lever_b_, across_i_, dt_) *
          T(inv_sigma_);
    return true;
  }

  // ChordCostFunction (analytic Jacobians).
  static ceres::CostFunction* Create(double dt, double sigma, const Vec3& lever_b, const Vec3& path_i);
  // AutoDiffCostFunction<ChordFactor, 2, 7, 7> of the same residual: the test oracle.
  static ceres::CostFunction* CreateAutoDiff(double dt, double sigma, const Vec3& lever_b, const Vec3& path_i);

  double dt() const { return dt_; }
  double inv_sigma() const { return inv_sigma_; }
  const Vec3& lever_b() const { return lever_b_; }
  const Eigen::Matrix<double, 2, 3>& across_i() const { return across_i_; }

 private:
  double dt_, inv_sigma_;
  Vec3 lever_b_;
  Eigen::Matrix<double, 2, 3> across_i_;
};

class ChordCostFunction final : public ceres::SizedCostFunction<2, pose::kAmbient, pose::kAmbient> {
 public:
  explicit ChordCostFunction(const ChordFactor& factor) : factor_(factor) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  ChordFactor factor_;
};

}  // namespace gins
