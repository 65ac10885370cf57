#include "factors/fej_cost.h"

#include <glog/logging.h>

#include <array>
#include <utility>

namespace gins {

FejCost::FejCost(ceres::CostFunction* inner, std::vector<Block> blocks)
    : FejCost(std::shared_ptr<ceres::CostFunction>(inner), std::move(blocks)) {}

FejCost::FejCost(std::shared_ptr<ceres::CostFunction> inner, std::vector<Block> blocks)
    : inner_(std::move(inner)), blocks_(std::move(blocks)) {
  CHECK_EQ(blocks_.size(), inner_->parameter_block_sizes().size());
  CHECK_LE(blocks_.size(), static_cast<size_t>(kMaxBlocks));
  CHECK_LE(inner_->num_residuals(), kMaxResiduals);
  set_num_residuals(inner_->num_residuals());
  *mutable_parameter_block_sizes() = inner_->parameter_block_sizes();
}

bool FejCost::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  if (jacobians == nullptr) return inner_->Evaluate(parameters, residuals, nullptr);
  const size_t n = blocks_.size();
  std::array<const double*, kMaxBlocks> at{};
  bool substituted = false;
  for (size_t i = 0; i < n; ++i) {
    at[i] = parameters[i];
    const Block& b = blocks_[i];
    if (b.first_estimate != nullptr && b.active != nullptr && *b.active) {
      at[i] = b.first_estimate;
      substituted = true;
    }
  }
  if (!substituted) return inner_->Evaluate(parameters, residuals, jacobians);
  if (!inner_->Evaluate(parameters, residuals, nullptr)) return false;
  std::array<double, kMaxResiduals> scratch;
  if (!inner_->Evaluate(at.data(), scratch.data(), jacobians)) return false;
  // Ceres turns an ambient pose Jacobian into a tangent one with PlusJacobian at the CURRENT value; the
  // first-estimate Jacobian is tangent at the first estimate. Re-express it so that Ceres's product gives
  // exactly that: J_tan = J_amb(x_fej)·Plus'(x_fej), then J_amb' = J_tan·Minus'(x) (Minus'·Plus' = I).
  for (size_t i = 0; i < n; ++i) {
    if (at[i] == parameters[i] || jacobians[i] == nullptr || !blocks_[i].is_pose) continue;
    using Mat76 = Eigen::Matrix<double, pose::kAmbient, pose::kTangent, Eigen::RowMajor>;
    using Mat67 = Eigen::Matrix<double, pose::kTangent, pose::kAmbient, Eigen::RowMajor>;
    Mat76 plus_fej;
    Mat67 minus_now;
    manifold_.PlusJacobian(at[i], plus_fej.data());
    manifold_.MinusJacobian(parameters[i], minus_now.data());
    using JacobianMap = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, pose::kAmbient, Eigen::RowMajor>>;
    JacobianMap J(jacobians[i], num_residuals(), pose::kAmbient);
    J = (J * plus_fej * minus_now).eval();
  }
  return true;
}

}  // namespace gins
