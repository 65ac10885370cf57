// A measurement module's factors (factors/module_factor.h), with the barometer's model: the residual at a
// keyframe is the model's of its state, and both factors' autodiff Jacobians match numeric differences
// through the pose manifold.
#include "factors/module_factor.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "core/barometer.h"
#include "factor_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

BarometerModule::Model BaroModel(double height, double sigma) {
  BarometerModule::Measurement m;
  m.height = height;
  m.sigma = sigma;
  m.half_inv_radius_e = 0.5 / 6.38e6;
  m.half_inv_radius_n = 0.5 / 6.35e6;
  return BarometerModule::Model{m};
}

TEST(ModuleFactor, AtAKeyframeIsTheModelOfItsState) {
  std::mt19937 rng(5);
  const test::PoseBlock pose = test::RandomPose(rng);
  const Vec3 vel(1.0, 2.0, 3.0);
  const Vec3 p = PosePosition(pose.data());
  const BarometerModule::Model model = BaroModel(p.z() - 0.3, 0.5);
  std::unique_ptr<ceres::CostFunction> cost(ModuleFactorAtKeyframe(model));
  const double* params[] = {pose.data(), vel.data()};
  double r = 0.0;
  ASSERT_TRUE(cost->Evaluate(params, &r, nullptr));
  const double curvature = p.x() * p.x() * 0.5 / 6.38e6 + p.y() * p.y() * 0.5 / 6.35e6;
  EXPECT_NEAR(r, (0.3 + curvature) / 0.5, 1e-12);
}

TEST(ModuleFactor, JacobiansMatchNumeric) {
  std::mt19937 rng(6);
  const PoseManifold manifold;
  double worst = 0.0;
  for (int trial = 0; trial < 4; ++trial) {
    const test::PoseBlock pose = test::RandomPose(rng);
    const Vec3 vel = test::RandomVec3(rng, 3.0);
    const BarometerModule::Model model = BaroModel(PosePosition(pose.data()).z() + 0.4, 0.3);
    std::unique_ptr<ceres::CostFunction> at(ModuleFactorAtKeyframe(model));
    worst = std::max(worst, test::CheckJacobians(*at, {&manifold, nullptr}, {pose.data(), vel.data()}, 1e-6,
                                                 "at keyframe"));
    const test::AttachedInterval s = test::MakeAttachedInterval(Vec3(0.0, 4e-5, 6e-5));
    const test::AttachedBlocks b = test::PerturbedBlocks(rng, s.pose_i, s.vel_i, s.bias);
    std::unique_ptr<ceres::CostFunction> preint(ModuleFactorPreint(s.preint, s.earth, model));
    worst = std::max(worst, test::CheckJacobians(*preint, {&manifold, nullptr, nullptr},
                                                 {b.pose.data(), b.vel.data(), b.bias.data()}, 1e-6, "preint"));
  }
  std::printf("[ module factor jac ] worst relative error: %.2g\n", worst);
}

}  // namespace GINS_TEST_FILE
}  // namespace gins
