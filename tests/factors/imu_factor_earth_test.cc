// The IMU factor with the Earth's rotation (ImuEarthTerms): zero at a truth stepped through the kernel with
// Earth rate and Coriolis, consistent with Preintegration::Predict, and analytic Jacobians equal to autodiff
// and to numeric differences. An exaggerated Earth rate (0.05 rad/s, ~700× Ω) makes its terms visible.
#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "core/earth.h"
#include "core/imu_kernel.h"
#include "core/preintegration.h"
#include "factor_test_util.h"
#include "factors/imu_factor.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kG = 9.81;

struct EarthScenario {
  NavState x_i, x_j;
  ImuEarthTerms earth;
  std::shared_ptr<Preintegration> preint;
};

// Truth stepped through the kernel (with Earth rate and Coriolis) at 1 ms for `seconds`; the preintegration
// sees the same rates (against inertial space), so the only residual left is the factor's closed-form
// approximation of the Earth terms.
EarthScenario MakeScenario(const Vec3& rate_w, double seconds) {
  EarthScenario s;
  s.earth.g_w = GravityWorld(kG);
  s.earth.rate_w = rate_w;
  s.x_i.p_wb = Vec3(10.0, -4.0, 2.0);
  s.x_i.v_w = Vec3(15.0, 5.0, -0.2);
  s.x_i.q_wb = ExpQuat<double>(Vec3(0.1, -0.3, 2.0));
  s.preint = std::make_shared<Preintegration>(Vec3::Zero(), Vec3::Zero(), 2e-3, 2e-2);
  Kinematics x{s.x_i.q_wb, s.x_i.v_w, s.x_i.p_wb};
  const double dt = 1e-3;
  const int n = static_cast<int>(seconds / dt + 0.5);
  for (int k = 0; k < n; ++k) {
    const double t = k * dt;
    const Vec3 omega(0.3 * std::sin(2.0 * t), -0.2 + 0.1 * std::cos(3.0 * t), 0.5 * std::sin(0.7 * t + 1.0));
    const Vec3 acc(1.0 + 0.5 * std::cos(1.3 * t), 0.4 * std::sin(2.1 * t), kG + 0.3 * std::sin(t));
    s.preint->Integrate(omega, acc, dt);
    x = ImuStep(x, omega, acc, s.earth.g_w, dt, nullptr, rate_w);
  }
  s.x_j = s.x_i;
  s.x_j.t = s.x_i.t + n * dt;
  s.x_j.p_wb = x.p;
  s.x_j.v_w = x.v;
  s.x_j.q_wb = x.q;
  return s;
}

Vec9 RawResidual(const ImuFactor& f, const EarthScenario& s) {
  const test::PoseBlock pi = test::MakePose(s.x_i.p_wb, s.x_i.q_wb), pj = test::MakePose(s.x_j.p_wb, s.x_j.q_wb);
  Vec6 bias = Vec6::Zero();
  Vec9 r;
  f(pi.data(), s.x_i.v_w.data(), bias.data(), pj.data(), s.x_j.v_w.data(), r.data());
  return f.sqrt_information().inverse() * r;
}

TEST(ImuFactorEarthTest, ResidualAtKernelTruthIsSmall) {
  // Real Earth rate over 1 s at 16 m/s while turning: what is left is the midpoint rule's second-order term
  // (ω times the first moment of the specific force's change, ~1e-5 m/s), far below the IMU noise over the
  // same second (a tactical IMU's velocity random walk is ~2e-4 m/s there).
  const Vec3 omega_ie = kEarthRate * Vec3(0.0, std::cos(0.55), std::sin(0.55));
  const EarthScenario real = MakeScenario(omega_ie, 1.0);
  const Vec9 r = RawResidual(ImuFactor(real.preint, real.earth), real);
  EXPECT_LT(r.segment<3>(preint::kP).norm(), 5e-5);
  EXPECT_LT(r.segment<3>(preint::kV).norm(), 5e-5);
  EXPECT_LT(r.segment<3>(preint::kTheta).norm(), 1e-9);
  // Without the Earth terms the same truth leaves the Coriolis and Earth-rate errors.
  const Vec9 r_flat = RawResidual(ImuFactor(real.preint, real.earth.g_w), real);
  EXPECT_GT(r_flat.segment<3>(preint::kV).norm(), 1e-3);
  EXPECT_GT(r_flat.segment<3>(preint::kTheta).norm(), 5e-5);
  // An exaggerated rate: the approximation error is second order in ω·Δt.
  const EarthScenario big = MakeScenario(Vec3(0.01, 0.03, 0.04), 1.0);
  const Vec9 r_big = RawResidual(ImuFactor(big.preint, big.earth), big);
  EXPECT_LT(r_big.segment<3>(preint::kP).norm(), 5e-2);
  EXPECT_LT(r_big.segment<3>(preint::kV).norm(), 5e-2);
  EXPECT_LT(r_big.segment<3>(preint::kTheta).norm(), 1e-9);  // the rotation part is exact
}

TEST(ImuFactorEarthTest, PredictSolvesTheResidual) {
  // Predict solves the factor's equations: the residual at its prediction is zero (exaggerated rate).
  const EarthScenario s = MakeScenario(Vec3(0.01, 0.03, 0.04), 2.0);
  EarthScenario predicted = s;
  predicted.x_j = s.preint->Predict(s.x_i, s.earth);
  EXPECT_LT(RawResidual(ImuFactor(s.preint, s.earth), predicted).norm(), 1e-10);
  // With the real Earth rate the prediction hits the kernel's truth to the closed form's second-order terms
  // (over 2 s of turning at 16 m/s: 1e-4 m from the straight-path Coriolis term, aT³/12·2ω); the flat
  // prediction misses it by the whole Coriolis drift (2ω×v·T²/2, millimetres).
  const EarthScenario real = MakeScenario(kEarthRate * Vec3(0.0, 0.8, 0.6), 2.0);
  const NavState x_j = real.preint->Predict(real.x_i, real.earth);
  EXPECT_LT((x_j.p_wb - real.x_j.p_wb).norm(), 3e-4);
  EXPECT_LT((x_j.v_w - real.x_j.v_w).norm(), 3e-4);
  EXPECT_LT(LogQuat<double>(x_j.q_wb.conjugate() * real.x_j.q_wb).norm(), 1e-9);
  EXPECT_GT((real.preint->Predict(real.x_i, real.earth.g_w).p_wb - real.x_j.p_wb).norm(), 1e-3);
}

TEST(ImuFactorEarthTest, AnalyticJacobiansMatchAutoDiffAndNumeric) {
  const EarthScenario s = MakeScenario(Vec3(0.01, 0.03, 0.04), 1.0);
  const std::unique_ptr<ceres::CostFunction> analytic(ImuFactor::Create(s.preint, s.earth));
  const std::unique_ptr<ceres::CostFunction> autodiff(ImuFactor::CreateAutoDiff(s.preint, s.earth));
  const PoseManifold manifold;
  const std::vector<const ceres::Manifold*> manifolds = {&manifold, nullptr, nullptr, &manifold, nullptr};
  std::mt19937 rng(5);
  for (int trial = 0; trial < 6; ++trial) {
    Vec6 d_i, d_j;
    d_i << test::RandomVec3(rng, 1.0), test::RandomVec3(rng, 0.3);
    d_j << test::RandomVec3(rng, 1.0), test::RandomVec3(rng, 0.3);
    const test::PoseBlock pose_i = test::PosePlus(test::MakePose(s.x_i.p_wb, s.x_i.q_wb), d_i);
    const test::PoseBlock pose_j = test::PosePlus(test::MakePose(s.x_j.p_wb, s.x_j.q_wb), d_j);
    const Vec3 vel_i = s.x_i.v_w + test::RandomVec3(rng, 1.0), vel_j = s.x_j.v_w + test::RandomVec3(rng, 1.0);
    Vec6 bias;
    bias << test::RandomVec3(rng, 0.02), test::RandomVec3(rng, 0.2);
    const std::vector<const double*> params = {pose_i.data(), vel_i.data(), bias.data(), pose_j.data(),
                                               vel_j.data()};
    // Tangent Jacobians of the analytic and the autodiff cost functions agree.
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    const std::vector<int32_t>& sizes = analytic->parameter_block_sizes();
    std::vector<RowMajor> Ja(5), Jb(5);
    std::vector<double*> pa, pb;
    for (int k = 0; k < 5; ++k) {
      Ja[k].resize(9, sizes[k]);
      Jb[k].resize(9, sizes[k]);
      pa.push_back(Ja[k].data());
      pb.push_back(Jb[k].data());
    }
    Vec9 ra, rb;
    ASSERT_TRUE(analytic->Evaluate(params.data(), ra.data(), pa.data()));
    ASSERT_TRUE(autodiff->Evaluate(params.data(), rb.data(), pb.data()));
    EXPECT_LT((ra - rb).cwiseAbs().maxCoeff(), 1e-9 * std::max(1.0, rb.cwiseAbs().maxCoeff()));
    for (int k = 0; k < 5; ++k) {
      MatX ta = Ja[k], tb = Jb[k];
      if (sizes[k] == pose::kAmbient) {
        Eigen::Matrix<double, 7, 6, Eigen::RowMajor> P;
        manifold.PlusJacobian(params[k], P.data());
        ta = Ja[k] * P;
        tb = Jb[k] * P;
      }
      const double scale = std::max(tb.cwiseAbs().maxCoeff(), 1e-300);
      EXPECT_LE((ta - tb).cwiseAbs().maxCoeff() / scale, 1e-9) << "trial " << trial << " block " << k;
    }
    EXPECT_LT(test::CheckJacobians(*analytic, manifolds, params, 1e-6, "earth trial " + std::to_string(trial)),
              1e-5);
  }
}

}  // namespace
}  // namespace gins
