// The marginaliser on a small window: the prior's information and gradient are the dense Schur complement,
// the residuals are selected and removed in program order, and the window stays consistent.
#include "solver/marginalizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <vector>

#include "window_test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

// Tangent column of each block in `blocks`.
std::map<const double*, int> ColumnsOf(ceres::Problem* problem, const std::vector<double*>& blocks) {
  std::map<const double*, int> columns;
  int c = 0;
  for (double* b : blocks) {
    columns[b] = c;
    c += problem->ParameterBlockTangentSize(b);
  }
  return columns;
}

TEST(Marginalizer, PriorIsTheDenseSchurComplement) {
  for (bool estimate_scale : {false, true}) {
    test::TestWindow w(4, estimate_scale);
    ceres::Problem* problem = w.problem.get();
    Keyframe& oldest = w.store.front();
    Marginalizer marginalizer(problem, w.store.Blocks(oldest));
    ASSERT_TRUE(marginalizer.ok());

    // Dense: J and r of the selected residuals over every estimated block, the oldest's columns first.
    const std::vector<double*> all = w.store.EstimatedBlocks();
    VecX r;
    const MatX J = test::DenseJacobian(problem, all, marginalizer.residuals(), &r);
    const int m = static_cast<int>(NavIndexOfTangent(w.store.EstimatedTypes()).size());
    const int k = static_cast<int>(J.cols()) - m;
    const MatX H = J.transpose() * J;
    const VecX b = J.transpose() * r;
    const MatX Hmm_inv = H.topLeftCorner(m, m).inverse();
    const MatX H_schur = H.bottomRightCorner(k, k) - H.bottomLeftCorner(k, m) * Hmm_inv * H.topRightCorner(m, k);
    const VecX b_schur = b.tail(k) - H.bottomLeftCorner(k, m) * Hmm_inv * b.head(m);

    const auto all_columns = ColumnsOf(problem, all);

    // The prior, as the problem sees it, over its kept blocks.
    const std::vector<double*> kept = marginalizer.info().kept_parameter_blocks();
    ASSERT_FALSE(kept.empty());
    const ceres::ResidualBlockId prior_id = marginalizer.Apply();
    ASSERT_NE(prior_id, nullptr);
    VecX r_prior;
    const MatX J_prior = test::DenseJacobian(problem, kept, {prior_id}, &r_prior);
    const MatX H_prior = J_prior.transpose() * J_prior;
    const VecX b_prior = J_prior.transpose() * r_prior;

    // Compare on the kept blocks' columns (the Schur complement is zero elsewhere: no residual there).
    const auto kept_columns = ColumnsOf(problem, kept);
    std::vector<std::pair<int, int>> index;  // (column in H_schur, column in H_prior)
    for (double* block : kept) {
      for (int c = 0; c < problem->ParameterBlockTangentSize(block); ++c) {
        index.emplace_back(all_columns.at(block) - m + c, kept_columns.at(block) + c);
      }
    }
    ASSERT_EQ(static_cast<int>(index.size()), H_prior.rows());
    const double scale = H_schur.cwiseAbs().maxCoeff();
    for (const auto& [si, pi] : index) {
      for (const auto& [sj, pj] : index) {
        EXPECT_NEAR(H_prior(pi, pj), H_schur(si, sj), 1e-9 * scale) << si << "," << sj;
      }
      // H_mm spans ~10 orders of magnitude (bias random walks against positions): the gradient, through
      // H_mm⁻¹, agrees to round-off of that conditioning.
      EXPECT_NEAR(b_prior(pi), b_schur(si), 1e-7 * b_schur.cwiseAbs().maxCoeff());
    }
    double outside = 0.0;  // what the selected residuals say of blocks the prior leaves out
    for (int i = 0; i < k; ++i) {
      const bool is_kept = std::any_of(index.begin(), index.end(), [&](const auto& p) { return p.first == i; });
      if (!is_kept) outside = std::max(outside, H_schur.row(i).cwiseAbs().maxCoeff());
    }
    EXPECT_EQ(outside, 0.0);
  }
}

TEST(Marginalizer, SelectsAndRemovesInProgramOrderThenAddsThePriorLast) {
  test::TestWindow w(3, true);
  ceres::Problem* problem = w.problem.get();
  const std::vector<double*> oldest = w.store.Blocks(w.store.front());
  std::vector<ceres::ResidualBlockId> before;
  problem->GetResidualBlocks(&before);

  Marginalizer marginalizer(problem, oldest);
  std::vector<ceres::ResidualBlockId> touching;
  for (auto id : before) {
    std::vector<double*> params;
    problem->GetParameterBlocksForResidualBlock(id, &params);
    const bool touches = std::any_of(params.begin(), params.end(), [&](double* b) {
      return std::find(oldest.begin(), oldest.end(), b) != oldest.end();
    });
    if (touches) touching.push_back(id);
  }
  EXPECT_EQ(marginalizer.residuals(), touching);  // all of them, in program order
  ASSERT_GE(touching.size(), 3u);
  EXPECT_EQ(problem->NumResidualBlocks(), static_cast<int>(before.size()));  // nothing changed yet

  // Ceres removes a residual by moving its last one into the hole: removing in program order leaves this
  // order, whatever the addresses.
  std::vector<ceres::ResidualBlockId> expected = before;
  for (auto id : touching) {
    auto it = std::find(expected.begin(), expected.end(), id);
    *it = expected.back();
    expected.pop_back();
  }
  const ceres::ResidualBlockId prior = marginalizer.Apply();
  ASSERT_NE(prior, nullptr);
  expected.push_back(prior);
  std::vector<ceres::ResidualBlockId> after;
  problem->GetResidualBlocks(&after);
  EXPECT_EQ(after, expected);
  for (double* b : oldest) EXPECT_FALSE(problem->HasParameterBlock(b));

  // The store's window then drops the keyframe, and its blocks are those of the problem.
  w.store.PopOldest();
  EXPECT_EQ(w.store.size(), 2u);
  std::vector<double*> in_problem;
  problem->GetParameterBlocks(&in_problem);
  std::vector<double*> in_store;
  for (size_t i = 0; i < w.store.size(); ++i) {
    for (double* b : w.store.Blocks(w.store[i])) in_store.push_back(b);
  }
  std::sort(in_problem.begin(), in_problem.end());
  std::sort(in_store.begin(), in_store.end());
  EXPECT_EQ(in_problem, in_store);
  std::vector<double*> prior_blocks;
  problem->GetParameterBlocksForResidualBlock(prior, &prior_blocks);
  EXPECT_EQ(prior_blocks, w.store.EstimatedBlocks(w.store.front()));  // the next keyframe, table order
}

TEST(Marginalizer, ConstantBlocksGetNoPriorColumn) {
  test::TestWindow w(2, /*estimate_scale=*/false);
  Marginalizer marginalizer(w.problem.get(), w.store.Blocks(w.store.front()));
  ASSERT_TRUE(marginalizer.ok());
  const std::vector<double*>& kept = marginalizer.info().kept_parameter_blocks();
  EXPECT_EQ(std::find(kept.begin(), kept.end(), w.store[1].block(BlockType::kScale)), kept.end());
  EXPECT_EQ(kept, w.store.EstimatedBlocks(w.store[1]));
}

}  // namespace
}  // namespace gins
