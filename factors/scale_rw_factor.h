// Random-walk factor of a scalar block between consecutive keyframes i and j: the odometer scale, and the
// GNSS time offset (σ_rw in s/√s there).
//
// Parameter blocks: scale_i (1, unitless), scale_j (1).
// Residual (1):
//   r = (s_j − s_i) / (σ_rw·√Δt)          (unitless; σ_rw per √s as WheelOptions::scale_rw, Δt in s)
#pragma once

#include <ceres/cost_function.h>

#include <cmath>

namespace gins {

class ScaleRwFactor {
 public:
  static constexpr int kResidualDim = 1;

  ScaleRwFactor(double scale_rw, double dt) : inv_sigma_(1.0 / (scale_rw * std::sqrt(dt))) {}

  template <typename T>
  bool operator()(const T* scale_i, const T* scale_j, T* residual) const {
    residual[0] = (scale_j[0] - scale_i[0]) * T(inv_sigma_);
    return true;
  }

  // AutoDiffCostFunction<ScaleRwFactor, 1, 1, 1>. Requires rw > 0 and dt > 0.
  static ceres::CostFunction* Create(double scale_rw, double dt);

 private:
  double inv_sigma_;
};

}  // namespace gins
