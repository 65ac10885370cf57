// A small smoother window for the tests of its parts: keyframes in a KeyframeStore on their own Ceres
// problem, joined by real factors, and the problem's Jacobian as a dense matrix.
#pragma once

#include <ceres/crs_matrix.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "core/preintegration.h"
#include "core/so3.h"
#include "factors/gnss_factor.h"
#include "factors/imu_factor.h"
#include "factors/wheel_factor.h"
#include "solver/keyframe.h"

namespace gins::test {

inline ceres::Problem::Options SmootherProblemOptions() {
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.enable_fast_removal = true;
  return po;
}

inline SensorOptions WindowSensors(bool estimate_scale) {
  SensorOptions sensors;
  sensors.wheel.enabled = true;
  sensors.wheel.estimate_scale = estimate_scale;
  sensors.gnss.estimate_time_offset = false;  // the window's tests of it set it
  return sensors;
}

// Dense Jacobian (tangent columns) of `residuals` (all when empty) over `blocks`, and the residual.
inline MatX DenseJacobian(ceres::Problem* problem, const std::vector<double*>& blocks,
                          const std::vector<ceres::ResidualBlockId>& residuals = {}, VecX* r = nullptr) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = blocks;
  eo.residual_blocks = residuals;
  ceres::CRSMatrix crs;
  std::vector<double> res;
  EXPECT_TRUE(problem->Evaluate(eo, nullptr, &res, nullptr, &crs));
  MatX J = MatX::Zero(crs.num_rows, crs.num_cols);
  for (int i = 0; i < crs.num_rows; ++i) {
    for (int k = crs.rows[i]; k < crs.rows[i + 1]; ++k) J(i, crs.cols[k]) = crs.values[k];
  }
  if (r != nullptr) *r = Eigen::Map<const VecX>(res.data(), static_cast<Eigen::Index>(res.size()));
  return J;
}

// `n` keyframes 0.5 s apart on a gentle turn: the first with a prior, consecutive ones joined by IMU and
// random-walk factors, a GNSS fix on every pose (the last robust), a wheel speed on the second. The values
// are perturbed off the motion so that residuals are not zero.
class TestWindow {
 public:
  TestWindow(int n, bool estimate_scale)
      : sensors(WindowSensors(estimate_scale)),
        problem(std::make_unique<ceres::Problem>(SmootherProblemOptions())),
        store(sensors),
        loss(std::make_unique<ceres::CauchyLoss>(1.0)) {
    store.Reset(problem.get());
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, 1.0);
    auto perturb = [&](double s) { return Vec3(s * noise(rng), s * noise(rng), s * noise(rng)); };
    NavState x;
    x.t = 100.0;
    x.p_wb = Vec3(5.0, -3.0, 1.0);
    x.v_w = Vec3(4.0, 1.0, 0.0);
    x.q_wb = ExpQuat<double>(Vec3(0.01, -0.02, 0.3));
    x.bg = Vec3(0.002, -0.001, 0.003);
    x.ba = Vec3(0.05, -0.03, 0.02);
    Mat15 P0 = Mat15::Zero();
    P0.diagonal() << 0.01, 0.01, 0.04, 0.01, 0.01, 0.01, 1e-4, 1e-4, 4e-4, 1e-6, 1e-6, 1e-6, 1e-3, 1e-3, 1e-3;
    store.AddPrior(store.Push(store.Make(x.t, x)), P0);
    for (int i = 1; i < n; ++i) {
      auto preint = std::make_shared<Preintegration>(x.bg, x.ba, 1e-3, 1e-2);
      for (int k = 0; k < 50; ++k) preint->Integrate(Vec3(0.01, -0.02, 0.1), Vec3(0.5, 0.1, 9.81), 0.01);
      NavState next = preint->Predict(x, g_w);
      next.p_wb += perturb(0.05);
      next.v_w += perturb(0.05);
      next.q_wb = next.q_wb * ExpQuat<double>(perturb(0.01));
      std::unique_ptr<Keyframe> made = store.Make(next.t, next);
      made->preint = preint;
      Keyframe& prev = store.back();
      Keyframe& kf = store.Push(std::move(made));
      kf.block(BlockType::kScale)[0] = 1.0 + 0.01 * i;
      kf.imu_id = store.AddFactor(ImuFactor::Create(preint, g_w), nullptr,
                                  {{&prev, BlockType::kPose},
                                   {&prev, BlockType::kVelocity},
                                   {&prev, BlockType::kBias},
                                   {&kf, BlockType::kPose},
                                   {&kf, BlockType::kVelocity}});
      store.AddRandomWalks(prev, kf);
      x = next;
    }
    for (size_t i = 0; i < store.size(); ++i) {
      Keyframe& kf = store[i];
      const Vec3 fix = kf.State().p_wb + perturb(0.1);
      store.AddFactor(GnssFactor::Create(fix, Vec3(0.1, 0.1, 0.2), Vec3(-0.2, 0.3, 0.1)),
                      i + 1 == store.size() ? loss.get() : nullptr, {{&kf, BlockType::kPose}});
    }
    if (store.size() > 1) {
      store.AddFactor(
          WheelFactor::Create(4.0, 0.1), nullptr,
          {{&store[1], BlockType::kPose}, {&store[1], BlockType::kVelocity}, {&store[1], BlockType::kScale}});
    }
  }

  const Vec3 g_w = GravityWorld(9.81);
  SensorOptions sensors;
  std::unique_ptr<ceres::Problem> problem;
  KeyframeStore store;
  std::unique_ptr<ceres::LossFunction> loss;
};

}  // namespace gins::test
