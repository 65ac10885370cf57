// Cost of one evaluation (residual and Jacobians) of each factor, as Ceres calls it.
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "core/preintegration.h"
#include "core/so3.h"
#include "factors/bias_rw_factor.h"
#include "factors/gnss_factor.h"
#include "factors/heading_factor.h"
#include "factors/imu_factor.h"
#include "factors/wheel_factor.h"

namespace gins {
namespace {

struct Blocks {
  double pose_i[7], vel_i[3], bias_i[6], pose_j[7], vel_j[3], bias_j[6], scale[1] = {1.0};
  Blocks() {
    SetPose(Vec3(1, 2, 3), ExpQuat<double>(Vec3(0.1, -0.05, 0.7)), pose_i);
    SetPose(Vec3(11, 3, 3), ExpQuat<double>(Vec3(0.1, -0.05, 0.8)), pose_j);
    for (int k = 0; k < 3; ++k) vel_i[k] = vel_j[k] = 1.0 + k;
    for (int k = 0; k < 6; ++k) bias_i[k] = bias_j[k] = 1e-3 * (k + 1);
  }
};

void EvaluateLoop(benchmark::State& state, ceres::CostFunction* cost, std::vector<double*> params) {
  std::unique_ptr<ceres::CostFunction> owned(cost);
  std::vector<double> residuals(cost->num_residuals());
  std::vector<std::vector<double>> jac_storage;
  std::vector<double*> jacobians;
  for (int32_t size : cost->parameter_block_sizes()) {
    jac_storage.emplace_back(static_cast<size_t>(size * cost->num_residuals()));
    jacobians.push_back(jac_storage.back().data());
  }
  for (auto _ : state) {
    cost->Evaluate(params.data(), residuals.data(), jacobians.data());
    benchmark::DoNotOptimize(residuals.data());
  }
}

std::shared_ptr<const Preintegration> BenchPreintegration() {
  auto preint = std::make_shared<Preintegration>(Vec3::Zero(), Vec3::Zero(), 1e-4, 1e-3);
  for (int k = 0; k < 100; ++k) preint->Integrate(Vec3(0.01, 0.0, 0.1), Vec3(0.2, 0.0, 9.8), 0.01);
  return preint;
}

// Production: analytic Jacobians (ImuCostFunction).
void BM_ImuFactorAnalytic(benchmark::State& state) {
  Blocks b;
  EvaluateLoop(state, ImuFactor::Create(BenchPreintegration(), Vec3(0, 0, -9.8)),
               {b.pose_i, b.vel_i, b.bias_i, b.pose_j, b.vel_j});
}
BENCHMARK(BM_ImuFactorAnalytic);

// The test oracle: AutoDiffCostFunction of the same residual (Jet<double, 26>).
void BM_ImuFactorAutoDiff(benchmark::State& state) {
  Blocks b;
  EvaluateLoop(state, ImuFactor::CreateAutoDiff(BenchPreintegration(), Vec3(0, 0, -9.8)),
               {b.pose_i, b.vel_i, b.bias_i, b.pose_j, b.vel_j});
}
BENCHMARK(BM_ImuFactorAutoDiff);

void BM_GnssFactor(benchmark::State& state) {
  Blocks b;
  EvaluateLoop(state, GnssFactor::Create(Vec3(1, 2, 3), Vec3(0.02, 0.02, 0.03), Vec3(-0.17, -0.2, 0)), {b.pose_i});
}
BENCHMARK(BM_GnssFactor);

void BM_HeadingFactor(benchmark::State& state) {
  Blocks b;
  EvaluateLoop(state, HeadingFactor::Create(0.3, 0.01, 0.2), {b.pose_i});
}
BENCHMARK(BM_HeadingFactor);

void BM_WheelFactor(benchmark::State& state) {
  Blocks b;
  EvaluateLoop(state, WheelFactor::Create(3.0, 0.1), {b.pose_i, b.vel_i, b.scale});
}
BENCHMARK(BM_WheelFactor);

void BM_BiasRwFactor(benchmark::State& state) {
  Blocks b;
  EvaluateLoop(state, BiasRwFactor::Create(1e-5, 1e-4, 1.0), {b.bias_i, b.bias_j});
}
BENCHMARK(BM_BiasRwFactor);

}  // namespace
}  // namespace gins
