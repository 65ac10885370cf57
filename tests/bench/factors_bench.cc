// Cost of one evaluation (residual and Jacobians) of each factor, as Ceres calls it; and of the
// marginalisation of one keyframe (Schur complement) with the prior it leaves.
#include <benchmark/benchmark.h>
#include <ceres/loss_function.h>
#include <glog/logging.h>

#include <memory>
#include <random>
#include <vector>

#include "core/imu_kernel.h"
#include "core/preintegration.h"
#include "core/sensors.h"
#include "core/so3.h"
#include "factors/bias_rw_factor.h"
#include "factors/gnss_factor.h"
#include "factors/heading_factor.h"
#include "factors/imu_factor.h"
#include "factors/marginalization_prior.h"
#include "factors/nhc_factor.h"
#include "factors/scale_rw_factor.h"
#include "factors/wheel_factor.h"
#include "factors/zero_motion_factor.h"
#include "factors/zero_velocity_factor.h"

namespace gins {
namespace {

struct Blocks {
  double pose_i[7], vel_i[3], bias_i[6], pose_j[7], vel_j[3], bias_j[6], scale[1] = {1.0}, scale_j[1] = {1.002};
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

// Non-holonomic constraint (lateral and vertical body speed), autodiff.
void BM_NhcFactor(benchmark::State& state) {
  Blocks b;
  EvaluateLoop(state, NhcFactor::Create(0.1), {b.pose_i, b.vel_i});
}
BENCHMARK(BM_NhcFactor);

// Odometer scale random walk between two keyframes, autodiff.
void BM_ScaleRwFactor(benchmark::State& state) {
  Blocks b;
  EvaluateLoop(state, ScaleRwFactor::Create(1e-4, 1.0), {b.scale, b.scale_j});
}
BENCHMARK(BM_ScaleRwFactor);

// Zero velocity at a standstill (analytic Jacobian).
void BM_ZeroVelocityFactor(benchmark::State& state) {
  Blocks b;
  EvaluateLoop(state, new ZeroVelocityFactor(0.01), {b.vel_i});
}
BENCHMARK(BM_ZeroVelocityFactor);

// Zero motion (translation and rotation) between two keyframes of one standstill, autodiff.
void BM_ZeroMotionFactor(benchmark::State& state) {
  Blocks b;
  EvaluateLoop(state, ZeroMotionFactor::Create(1e-4, 1e-4), {b.pose_i, b.pose_j});
}
BENCHMARK(BM_ZeroMotionFactor);

// ---------------------------------------------------------------------------------------------------------
// Marginalisation.

// A chain of keyframes 1 s apart on a turning drive, with the factors the smoother attaches at the default
// options: IMU, bias and scale random walks to the next keyframe; GNSS and heading (Cauchy loss) and wheel
// speed on each. States are perturbed off the truth so that residuals are not zero. Keyframe 0 starts with
// a diagonal prior; Marginalize(i) drops keyframe i, as Smoother::MarginalizeOldest does, and leaves the
// prior on keyframe i + 1.
class KeyframeChain {
 public:
  static constexpr int kNumKf = 5;
  struct Kf {
    double pose[7], vel[3], bias[6], scale[1];
  };

  KeyframeChain() {
    const SensorOptions sensors;
    const Vec3 g_w = GravityWorld(kStandardGravity), lever_b(-0.17, -0.2, 0.0);
    const double mount_yaw = 0.21, true_scale = 0.99;
    Vec6 bias_true;
    bias_true << 2e-4, -3e-4, 1e-4, 0.02, -0.01, 0.03;
    std::mt19937 rng(7);
    std::normal_distribution<double> n01;
    auto noise = [&](double sigma) {
      Vec3 v;
      for (int k = 0; k < 3; ++k) v[k] = sigma * n01(rng);
      return v;
    };
    Kinematics x{ExpQuat<double>(Vec3(0.01, -0.02, 0.3)), Vec3(8.0, 3.0, 0.0), Vec3(100.0, 50.0, 10.0)};
    for (int i = 0; i < kNumKf; ++i) {
      Kf& kf = kf_[i];
      SetPose(x.p + noise(0.05), x.q * ExpQuat<double>(noise(0.005)), kf.pose);
      Eigen::Map<Vec3>(kf.vel) = x.v + noise(0.02);
      Eigen::Map<Vec6>(kf.bias) = bias_true + Vec6::Constant(1e-4);
      kf.scale[0] = true_scale + 0.003;
      gnss_.emplace_back(GnssFactor::Create(x.p + x.q * lever_b + noise(0.02), Vec3(0.02, 0.02, 0.03), lever_b));
      const Mat3 R_wG = x.q.toRotationMatrix() * QuatFromYaw(mount_yaw).toRotationMatrix();
      heading_.emplace_back(HeadingFactor::Create(YawOfXAxis<double>(R_wG) + 0.002, 0.0035, mount_yaw));
      wheel_.emplace_back(WheelFactor::Create(true_scale * (x.q.conjugate() * x.v).x() + 0.01, 0.05));
      if (i + 1 == kNumKf) break;
      auto pre = std::make_shared<Preintegration>(bias_true.head<3>(), bias_true.tail<3>(),
                                                  sensors.imu.gyro_noise_density, sensors.imu.acc_noise_density);
      for (int k = 0; k < 100; ++k) {
        const double t = i + 0.01 * k;
        const Vec3 omega(0.01 * std::sin(t), 0.02 * std::cos(t), 0.1);
        const Vec3 acc(0.3 * std::cos(t), 0.85, kStandardGravity + 0.05 * std::sin(2.0 * t));
        pre->Integrate(omega + bias_true.head<3>(), acc + bias_true.tail<3>(), 0.01);
        x = ImuStep(x, omega, acc, g_w, 0.01);
      }
      imu_.emplace_back(ImuFactor::Create(pre, g_w));
      bias_rw_.emplace_back(BiasRwFactor::Create(sensors.imu.gyro_bias_rw, sensors.imu.acc_bias_rw, 1.0));
      scale_rw_.emplace_back(ScaleRwFactor::Create(sensors.wheel.scale_rw, 1.0));
    }
    // Initial prior on keyframe 0: diagonal, as from an initialisation covariance.
    Eigen::Matrix<double, 16, 1> sigma;  // tangent order: δp, δθ (pose), v, bg, ba, s
    sigma << 0.05, 0.05, 0.1, 0.01, 0.01, 0.035, 0.1, 0.1, 0.1, 1e-3, 1e-3, 1e-3, 0.05, 0.05, 0.05, 0.01;
    std::vector<PriorBlock> blocks;
    const std::pair<BlockKind, double*> kinds[] = {{BlockKind::kPose, kf_[0].pose},
                                                   {BlockKind::kEuclidean, kf_[0].vel},
                                                   {BlockKind::kEuclidean, kf_[0].bias},
                                                   {BlockKind::kEuclidean, kf_[0].scale}};
    const int sizes[] = {7, 3, 6, 1};
    for (int k = 0; k < 4; ++k) {
      blocks.push_back(PriorBlock{kinds[k].first, sizes[k], TangentSizeOf(kinds[k].first, sizes[k]),
                                  std::vector<double>(kinds[k].second, kinds[k].second + sizes[k])});
      prior_blocks_.push_back(kinds[k].second);
    }
    prior_ = std::make_unique<MarginalizationPrior>(std::move(blocks), MatX(sigma.cwiseInverse().asDiagonal()),
                                                    VecX::Zero(16));
  }

  // Declares keyframe i's blocks (marginalised), keyframe i + 1's (kept) and every residual touching
  // keyframe i: its prior, IMU, bias and scale random walks to i + 1, GNSS, heading and wheel.
  void Declare(int i, MarginalizationInfo* info) {
    using Role = MarginalizationInfo::Role;
    for (int k : {i, i + 1}) {
      const Role role = k == i ? Role::kMarginalize : Role::kKeep;
      info->AddParameterBlock(kf_[k].pose, BlockKind::kPose, 7, role);
      info->AddParameterBlock(kf_[k].vel, BlockKind::kEuclidean, 3, role);
      info->AddParameterBlock(kf_[k].bias, BlockKind::kEuclidean, 6, role);
      info->AddParameterBlock(kf_[k].scale, BlockKind::kEuclidean, 1, role);
    }
    Kf &a = kf_[i], &b = kf_[i + 1];
    info->AddResidualBlock(prior_.get(), nullptr, prior_blocks_);
    info->AddResidualBlock(imu_[i].get(), nullptr, {a.pose, a.vel, a.bias, b.pose, b.vel});
    info->AddResidualBlock(bias_rw_[i].get(), nullptr, {a.bias, b.bias});
    info->AddResidualBlock(scale_rw_[i].get(), nullptr, {a.scale, b.scale});
    info->AddResidualBlock(gnss_[i].get(), &cauchy_, {a.pose});
    info->AddResidualBlock(heading_[i].get(), &cauchy_, {a.pose});
    info->AddResidualBlock(wheel_[i].get(), nullptr, {a.pose, a.vel, a.scale});
  }

  // Marginalises keyframe i (whose prior this chain holds) and keeps the prior it leaves on i + 1.
  void Marginalize(int i) {
    MarginalizationInfo info;
    Declare(i, &info);
    CHECK(info.Marginalize());
    prior_ = info.CreatePrior();
    CHECK(prior_ != nullptr);
    prior_blocks_ = info.kept_parameter_blocks();
  }

  Kf& kf(int i) { return kf_[i]; }
  std::unique_ptr<MarginalizationPrior> TakePrior() { return std::move(prior_); }
  const std::vector<double*>& prior_blocks() const { return prior_blocks_; }

 private:
  Kf kf_[kNumKf];
  std::vector<std::unique_ptr<ceres::CostFunction>> imu_, bias_rw_, scale_rw_, gnss_, heading_, wheel_;
  ceres::CauchyLoss cauchy_{3.0};
  std::unique_ptr<MarginalizationPrior> prior_;
  std::vector<double*> prior_blocks_;
};

// MarginalizationInfo::Marginalize for the factors touching the oldest keyframe of a window (prior from the
// previous marginalisation, IMU to the next keyframe, GNSS, heading, wheel, bias and scale random walks):
// evaluation, tangent-space H and b, Schur complement and the prior's eigen-factorisation (16 + 16 tangent).
void BM_Marginalize(benchmark::State& state) {
  KeyframeChain chain;
  const int oldest = KeyframeChain::kNumKf - 2;
  for (int i = 0; i < oldest; ++i) chain.Marginalize(i);  // priors as in a running window
  MarginalizationInfo info;
  chain.Declare(oldest, &info);
  for (auto _ : state) {
    benchmark::DoNotOptimize(info.Marginalize());
    benchmark::DoNotOptimize(info.marginal_information().data());
  }
  state.counters["prior_rows"] = static_cast<double>(info.CreatePrior()->num_residuals());
}
BENCHMARK(BM_Marginalize);

// The marginalisation prior left on a keyframe (pose, velocity, biases, scale) by BM_Marginalize's
// marginalisation, evaluated slightly away from its linearisation point.
void BM_MarginalizationPrior(benchmark::State& state) {
  KeyframeChain chain;
  const int oldest = KeyframeChain::kNumKf - 2;
  for (int i = 0; i <= oldest; ++i) chain.Marginalize(i);
  KeyframeChain::Kf& kf = chain.kf(oldest + 1);
  const Vec3 p = PosePosition(kf.pose) + Vec3(0.01, -0.02, 0.01);
  const Quat q = Quat(PoseRotation(kf.pose)) * ExpQuat<double>(Vec3(1e-3, -2e-3, 3e-3));
  SetPose(p, q, kf.pose);
  for (double& v : kf.vel) v += 0.01;
  std::unique_ptr<MarginalizationPrior> prior = chain.TakePrior();
  state.counters["prior_rows"] = static_cast<double>(prior->num_residuals());
  EvaluateLoop(state, prior.release(), chain.prior_blocks());
}
BENCHMARK(BM_MarginalizationPrior);

}  // namespace
}  // namespace gins
