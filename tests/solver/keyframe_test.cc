// The keyframe store: the block table against NavState's tangent, the blocks a keyframe puts in the
// problem, the initial prior, first-estimate wiring and random walks.
#include "solver/keyframe.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <random>
#include <vector>

#include "core/so3.h"
#include "factors/gnss_factor.h"
#include "window_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

const std::vector<BlockType> kNavBlocks = {BlockType::kPose, BlockType::kVelocity, BlockType::kBias};

NavState RandomState(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  auto v = [&](double s) { return Vec3(s * n(rng), s * n(rng), s * n(rng)); };
  NavState x;
  x.t = 12.5;
  x.p_wb = v(10.0);
  x.v_w = v(3.0);
  x.q_wb = ExpQuat<double>(v(1.0));
  x.bg = v(0.01);
  x.ba = v(0.1);
  return x;
}

TEST(KeyframeBlocks, TangentRunsReproduceNavStateOrder) {
  // Pose (δp, δθ), velocity (δv), bias (δbg, δba) -> NavState δp, δv, δθ, δbg, δba.
  const std::vector<int> expected = {0, 1, 2, 6, 7, 8, 3, 4, 5, 9, 10, 11, 12, 13, 14};
  EXPECT_EQ(NavIndexOfTangent(kNavBlocks), expected);
  // The scale and the time offset are outside NavState; every NavState coordinate is some block's, once.
  std::vector<int> all = NavIndexOfTangent(
      {BlockType::kPose, BlockType::kVelocity, BlockType::kBias, BlockType::kScale, BlockType::kTimeOffset});
  ASSERT_EQ(all.size(), 17u);
  EXPECT_EQ(all[15], -1);
  EXPECT_EQ(all[16], -1);
  all.resize(15);
  std::sort(all.begin(), all.end());
  for (int i = 0; i < nav::kDim; ++i) EXPECT_EQ(all[i], i);
  EXPECT_EQ(kKeyframeAmbientSize, 18);
}

TEST(KeyframeBlocks, BlockPerturbationsAreNavStateBoxplus) {
  // Perturbing each block through its manifold by its runs' share of δ is x ⊞ δ: the runs say what the
  // block's tangent coordinates mean, not just where they go.
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 0.3);
  PoseManifold manifold;
  for (int trial = 0; trial < 10; ++trial) {
    const NavState x = RandomState(rng);
    Vec15 delta;
    for (int i = 0; i < nav::kDim; ++i) delta[i] = n(rng);
    Keyframe kf;
    kf.SetState(x);
    Keyframe moved = kf;
    for (BlockType type : kNavBlocks) {
      const BlockSpec& spec = SpecOf(type);
      VecX d = VecX::Zero(spec.tangent_size);
      const std::vector<int> nav = NavIndexOfTangent({type});
      for (int i = 0; i < spec.tangent_size; ++i) d[i] = delta[nav[i]];
      if (spec.kind == BlockKind::kPose) {
        manifold.Plus(kf.block(type), d.data(), moved.block(type));
      } else {
        for (int i = 0; i < spec.ambient_size; ++i) moved.block(type)[i] = kf.block(type)[i] + d[i];
      }
    }
    const NavState got = moved.State(), want = x.Boxplus(delta);
    EXPECT_LT((got.p_wb - want.p_wb).norm(), 1e-12);
    EXPECT_LT((got.v_w - want.v_w).norm(), 1e-12);
    EXPECT_LT(got.q_wb.angularDistance(want.q_wb), 1e-12);
    EXPECT_LT((got.bg - want.bg).norm(), 1e-15);
    EXPECT_LT((got.ba - want.ba).norm(), 1e-15);
  }
}

TEST(KeyframeBlocks, StateRoundTrip) {
  std::mt19937 rng(5);
  const NavState x = RandomState(rng);
  Keyframe kf;
  kf.t = x.t;
  kf.SetState(x);
  const NavState y = kf.State();
  EXPECT_EQ(y.t, x.t);
  EXPECT_EQ(y.p_wb, x.p_wb);
  EXPECT_EQ(y.v_w, x.v_w);
  EXPECT_LT(y.q_wb.angularDistance(x.q_wb), 1e-15);
  EXPECT_EQ(y.bg, x.bg);
  EXPECT_EQ(y.ba, x.ba);
}

TEST(KeyframeStore, ScaleEstimatedOnlyWithWheelsAndEstimateScale) {
  for (bool wheels : {false, true}) {
    for (bool estimate : {false, true}) {
      SensorOptions sensors;
      sensors.wheel.enabled = wheels;
      sensors.wheel.estimate_scale = estimate;
      sensors.gnss.estimate_time_offset = false;  // TimeOffsetEstimatedOnlyWhenAskedForAndListedLast
      KeyframeStore store(sensors);
      const bool scale = wheels && estimate;
      EXPECT_EQ(store.estimated(BlockType::kScale), scale);
      for (BlockType type : kNavBlocks) EXPECT_TRUE(store.estimated(type));

      ceres::Problem problem(test::SmootherProblemOptions());
      store.Reset(&problem);
      std::mt19937 rng(1);
      Keyframe& kf = store.Push(store.Make(1.0, RandomState(rng)));
      EXPECT_EQ(problem.NumParameterBlocks(), kNumBlockTypes);
      for (const BlockSpec& spec : kBlockSpecs) {
        double* b = kf.block(spec.type);
        ASSERT_TRUE(problem.HasParameterBlock(b)) << spec.name;
        EXPECT_EQ(problem.ParameterBlockSize(b), spec.ambient_size) << spec.name;
        EXPECT_EQ(problem.ParameterBlockTangentSize(b), spec.tangent_size) << spec.name;
        EXPECT_EQ(problem.GetManifold(b) != nullptr, spec.kind == BlockKind::kPose) << spec.name;
        EXPECT_EQ(problem.IsParameterBlockConstant(b), !store.estimated(spec.type)) << spec.name;
      }
      EXPECT_EQ(store.EstimatedBlocks(kf).size(), scale ? 4u : 3u);
    }
  }
}

TEST(KeyframeStore, TimeOffsetEstimatedOnlyWhenAskedForAndListedLast) {
  for (bool estimate : {false, true}) {
    SensorOptions sensors = test::WindowSensors(true);
    sensors.gnss.estimate_time_offset = estimate;
    const KeyframeStore store(sensors);
    EXPECT_EQ(store.estimated(BlockType::kTimeOffset), estimate);
    const std::vector<BlockType> types = store.EstimatedTypes();
    EXPECT_EQ(types.back(), estimate ? BlockType::kTimeOffset : BlockType::kScale);
    // Outside NavState: its tangent has no NavState index.
    EXPECT_EQ(NavIndexOfTangent({BlockType::kTimeOffset}), std::vector<int>{-1});
  }
}

TEST(KeyframeStore, KeptValuesStartTheNextWindow) {
  // A watchdog reset keeps what the window learnt of the sensors (scale, time offset) for its first keyframe.
  SensorOptions sensors = test::WindowSensors(true);
  sensors.gnss.estimate_time_offset = true;
  KeyframeStore store(sensors);
  ceres::Problem problem(test::SmootherProblemOptions());
  store.Reset(&problem);
  std::mt19937 rng(3);
  Keyframe& kf = store.Push(store.Make(1.0, RandomState(rng)));
  EXPECT_EQ(kf.block(BlockType::kTimeOffset)[0], 0.0);  // the spec's initial value
  kf.block(BlockType::kScale)[0] = 1.03;
  kf.block(BlockType::kTimeOffset)[0] = 0.093;
  store.KeepValues(kf);
  ceres::Problem fresh(test::SmootherProblemOptions());
  store.Reset(&fresh);
  const std::unique_ptr<Keyframe> next = store.Make(2.0, RandomState(rng));
  EXPECT_EQ(next->block(BlockType::kScale)[0], 1.03);
  EXPECT_EQ(next->block(BlockType::kTimeOffset)[0], 0.093);
  store.ForgetValues();
  const std::unique_ptr<Keyframe> forgotten = store.Make(3.0, RandomState(rng));
  EXPECT_EQ(forgotten->block(BlockType::kScale)[0], 1.0);
  EXPECT_EQ(forgotten->block(BlockType::kTimeOffset)[0], 0.0);
}

TEST(KeyframeStore, MakeCarriesBlocksOutsideNavStateAndListsInTimeThenTableOrder) {
  const SensorOptions sensors = test::WindowSensors(true);
  KeyframeStore store(sensors);
  ceres::Problem problem(test::SmootherProblemOptions());
  store.Reset(&problem);
  std::mt19937 rng(2);
  Keyframe& first = store.Push(store.Make(1.0, RandomState(rng)));
  EXPECT_EQ(first.block(BlockType::kScale)[0], 1.0);  // the spec's initial value
  first.block(BlockType::kScale)[0] = 1.07;
  const NavState x = RandomState(rng);
  Keyframe& second = store.Push(store.Make(2.0, x));
  EXPECT_EQ(second.block(BlockType::kScale)[0], 1.07);  // carried from the newest
  EXPECT_EQ(second.t, 2.0);
  EXPECT_EQ(second.State().p_wb, x.p_wb);
  EXPECT_GT(second.id, first.id);
  const std::vector<double*> expected = {first.block(BlockType::kPose),  first.block(BlockType::kVelocity),
                                         first.block(BlockType::kBias),  first.block(BlockType::kScale),
                                         second.block(BlockType::kPose), second.block(BlockType::kVelocity),
                                         second.block(BlockType::kBias), second.block(BlockType::kScale)};
  EXPECT_EQ(store.EstimatedBlocks(), expected);
}

TEST(KeyframeStore, PriorReproducesTheCovariance) {
  for (bool estimate_scale : {false, true}) {
    SensorOptions sensors = test::WindowSensors(estimate_scale);
    sensors.gnss.estimate_time_offset = true;
    sensors.gnss.time_offset_sigma = 0.05;
    KeyframeStore store(sensors);
    ceres::Problem problem(test::SmootherProblemOptions());
    store.Reset(&problem);
    std::mt19937 rng(4);
    Keyframe& kf = store.Push(store.Make(1.0, RandomState(rng)));
    // A random, well-conditioned, fully correlated covariance.
    std::normal_distribution<double> n(0.0, 1.0);
    Mat15 A;
    for (int i = 0; i < A.size(); ++i) A.data()[i] = n(rng);
    const Mat15 P0 = 0.01 * (A * A.transpose() + 15.0 * Mat15::Identity());
    const ceres::ResidualBlockId id = store.AddPrior(kf, P0);

    VecX r;
    const MatX J = test::DenseJacobian(&problem, store.EstimatedBlocks(kf), {id}, &r);
    EXPECT_LT(r.cwiseAbs().maxCoeff(), 1e-12);  // at its linearisation point
    const MatX P = (J.transpose() * J).inverse();
    const std::vector<int> nav = NavIndexOfTangent(store.EstimatedTypes());
    ASSERT_EQ(P.rows(), static_cast<int>(nav.size()));
    for (int i = 0; i < P.rows(); ++i) {
      for (int j = 0; j < P.cols(); ++j) {
        double want = 0.0;
        if (nav[i] >= 0 && nav[j] >= 0) {
          want = P0(nav[i], nav[j]);
        } else if (i == j) {  // the scale's or the time offset's own σ
          const double sigma = i == P.rows() - 1 ? sensors.gnss.time_offset_sigma : sensors.wheel.scale_sigma;
          want = sigma * sigma;
        }
        EXPECT_NEAR(P(i, j), want, 1e-10) << i << "," << j;
      }
    }
  }
}

TEST(KeyframeStore, FactorsLineariseAtTheFirstEstimatesOnceFrozen) {
  KeyframeStore store(test::WindowSensors(true));
  ceres::Problem problem(test::SmootherProblemOptions());
  store.Reset(&problem);
  std::mt19937 rng(6);
  Keyframe& kf = store.Push(store.Make(1.0, RandomState(rng)));
  const Vec3 z_w(1.0, 2.0, 3.0), sigma_w(0.2, 0.2, 0.4), lever_b(-0.5, 0.7, 0.2);
  const ceres::ResidualBlockId id =
      store.AddFactor(GnssFactor::Create(z_w, sigma_w, lever_b), nullptr, {{&kf, BlockType::kPose}});
  double* pose = kf.block(BlockType::kPose);
  const std::vector<double*> blocks = {pose};
  const MatX J_before = test::DenseJacobian(&problem, blocks, {id});

  kf.FreezeFirstEstimates();
  const std::vector<double> frozen(pose, pose + pose::kAmbient);
  SetPose(Vec3(4.0, -1.0, 0.5), ExpQuat<double>(Vec3(0.2, -0.1, 1.2)), pose);  // the solver moves it
  VecX r;
  const MatX J_after = test::DenseJacobian(&problem, blocks, {id}, &r);
  EXPECT_LT((J_after - J_before).cwiseAbs().maxCoeff(), 1e-12);  // still the first estimate's

  // The residual, though, is at the current value.
  const std::unique_ptr<ceres::CostFunction> gnss(GnssFactor::Create(z_w, sigma_w, lever_b));
  Vec3 r_now;
  const double* params[] = {pose};
  ASSERT_TRUE(gnss->Evaluate(params, r_now.data(), nullptr));
  EXPECT_EQ(r, VecX(r_now));
  // Not frozen, the Jacobian follows the value.
  kf.fej = false;
  EXPECT_GT((test::DenseJacobian(&problem, blocks, {id}) - J_before).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_EQ(std::vector<double>(kf.first_estimate(BlockType::kPose), kf.first_estimate(BlockType::kPose) + 7), frozen);
}

TEST(KeyframeStore, RandomWalksFollowTheTable) {
  for (bool estimate_scale : {false, true}) {
    KeyframeStore store(test::WindowSensors(estimate_scale));
    ceres::Problem problem(test::SmootherProblemOptions());
    store.Reset(&problem);
    std::mt19937 rng(8);
    Keyframe& a = store.Push(store.Make(1.0, RandomState(rng)));
    Keyframe& b = store.Push(store.Make(1.5, RandomState(rng)));
    store.AddRandomWalks(a, b);
    std::vector<ceres::ResidualBlockId> ids;
    problem.GetResidualBlocks(&ids);
    ASSERT_EQ(ids.size(), estimate_scale ? 2u : 1u);
    std::vector<double*> params;
    problem.GetParameterBlocksForResidualBlock(ids[0], &params);
    EXPECT_EQ(params, (std::vector<double*>{a.block(BlockType::kBias), b.block(BlockType::kBias)}));
    if (estimate_scale) {
      problem.GetParameterBlocksForResidualBlock(ids[1], &params);
      EXPECT_EQ(params, (std::vector<double*>{a.block(BlockType::kScale), b.block(BlockType::kScale)}));
    }
  }
}

TEST(KeyframeStore, PopOldestOnlyOnceItsBlocksLeftTheProblem) {
  test::TestWindow w(3, true);
  EXPECT_DEATH(w.store.PopOldest(), "still in the problem");
  std::vector<ceres::ResidualBlockId> ids;
  w.problem->GetResidualBlocks(&ids);
  const size_t before = ids.size();
  // Removing the oldest's blocks (Ceres drops their residuals with them) makes the pop legal.
  for (double* b : w.store.Blocks(w.store.front())) w.problem->RemoveParameterBlock(b);
  const uint64_t second = w.store[1].id;
  w.store.PopOldest();
  EXPECT_EQ(w.store.size(), 2u);
  EXPECT_EQ(w.store.front().id, second);
  EXPECT_EQ(w.problem->NumParameterBlocks(), 2 * kNumBlockTypes);
  w.problem->GetResidualBlocks(&ids);
  EXPECT_LT(ids.size(), before);
  for (auto id : ids) {
    std::vector<double*> params;
    w.problem->GetParameterBlocksForResidualBlock(id, &params);
    for (double* b : params) EXPECT_TRUE(w.problem->HasParameterBlock(b));
  }
}

}  // namespace
}  // namespace gins
