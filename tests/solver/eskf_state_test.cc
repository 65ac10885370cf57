// The ESKF's error-state layout (solver/eskf_state.h) and the embedding of per-block Jacobians into the
// full-width H (solver/eskf_update.h).
#include "solver/eskf_state.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "solver/eskf_update.h"

namespace gins::eskf {
namespace GINS_TEST_FILE {

TEST(EskfState, BlocksAreContiguousAndCoverTheState) {
  int next = 0;
  for (int i = 0; i < kNumBlocks; ++i) {
    const Block b = static_cast<Block>(i);
    EXPECT_EQ(kBlocks[i].block, b) << kBlocks[i].name;
    EXPECT_GT(Dim(b), 0) << kBlocks[i].name;
    EXPECT_EQ(Offset(b), next) << kBlocks[i].name;
    next += Dim(b);
  }
  EXPECT_EQ(next, kDim);
  EXPECT_EQ(Offset(Block::kCount), kDim);
}

TEST(EskfState, NamesAreUnique) {
  std::set<std::string> names;
  for (const BlockInfo& b : kBlocks) EXPECT_TRUE(names.insert(std::string(b.name)).second) << b.name;
}

TEST(EskfState, TodaysLayout) {
  // δp, δv, δθ, δbg, δba, δg, δs, δtd: the NavState tangent first (core/nav_state.h), then gravity, scale and
  // the GNSS time offset.
  EXPECT_EQ(kDim, 20);
  EXPECT_EQ(Offset(Block::kP), nav::kP);
  EXPECT_EQ(Offset(Block::kV), nav::kV);
  EXPECT_EQ(Offset(Block::kTheta), nav::kTheta);
  EXPECT_EQ(Offset(Block::kBg), nav::kBg);
  EXPECT_EQ(Offset(Block::kBa), nav::kBa);
  EXPECT_EQ(kG, 15);
  EXPECT_EQ(kS, 18);
  EXPECT_EQ(Dim(Block::kS), 1);
  EXPECT_EQ(Offset(Block::kTd), 19);
  EXPECT_EQ(kAdditiveDim, 5);
  EXPECT_EQ(kMaxBlockDim, 3);
}

TEST(EskfState, PropagationSplit) {
  // Kinematic (the IMU kernel's A), driving (its B and G), then the rest.
  EXPECT_EQ(kKinematicDim, Dim(Block::kP) + Dim(Block::kV) + Dim(Block::kTheta));
  EXPECT_EQ(kDrivingDim, Dim(Block::kBg) + Dim(Block::kBa) + Dim(Block::kG));
  EXPECT_EQ(kNonKinematicDim, kDim - kKinematicDim);
  EXPECT_LE(kKinematicDim + kDrivingDim, kDim);
}

TEST(EskfState, ViewsSelectTheBlock) {
  Eigen::Matrix<double, kDim, kDim> P;
  for (int i = 0; i < kDim; ++i) {
    for (int j = 0; j < kDim; ++j) P(i, j) = 100 * i + j;
  }
  EXPECT_EQ((BlockOf<Block::kTheta, Block::kS>(P)), (P.block<3, 1>(6, 18)));
  EXPECT_EQ(BlockOf<Block::kBa>(P), (P.block<3, 3>(12, 12)));
  EXPECT_EQ(RowsOf<Block::kG>(P), P.middleRows<3>(15));
  EXPECT_EQ(ColsOf<Block::kV>(P), P.middleCols<3>(3));
  const Eigen::Matrix<double, kDim, 1> v = P.col(0);
  EXPECT_EQ(SegmentOf<Block::kBg>(v), v.segment<3>(9));
}

TEST(EskfEmbedJacobian, ColumnsWhereTheLayoutSays) {
  const Eigen::Matrix<double, 2, 3> H_v = Eigen::Matrix<double, 2, 3>::Random();
  const Eigen::Matrix<double, 2, 3> H_theta = Eigen::Matrix<double, 2, 3>::Random();
  const Eigen::Matrix<double, 2, 1> H_s = Eigen::Matrix<double, 2, 1>::Random();
  // Hand-built at today's offsets: δv at 3, δθ at 6, δs at 18.
  Eigen::Matrix<double, 2, kDim> expected = Eigen::Matrix<double, 2, kDim>::Zero();
  expected.block<2, 3>(0, 3) = H_v;
  expected.block<2, 3>(0, 6) = H_theta;
  expected.block<2, 1>(0, 18) = H_s;
  // The order of the list does not matter.
  const Eigen::Matrix<double, 2, kDim> H =
      EmbedJacobian<2>({{Block::kS, H_s}, {Block::kV, H_v}, {Block::kTheta, H_theta}});
  EXPECT_EQ(H, expected);
}

TEST(EskfEmbedJacobian, OneRowAndIdentityBlocks) {
  const Eigen::Matrix<double, 1, 3> H_theta(0.1, -0.2, 0.3);
  Eigen::Matrix<double, 1, kDim> expected = Eigen::Matrix<double, 1, kDim>::Zero();
  expected.block<1, 3>(0, 6) = H_theta;
  EXPECT_EQ(EmbedJacobian<1>({{Block::kTheta, H_theta}}), expected);

  Eigen::Matrix<double, 3, kDim> expected3 = Eigen::Matrix<double, 3, kDim>::Zero();
  expected3.block<3, 3>(0, 9).setIdentity();
  EXPECT_EQ(EmbedJacobian<3>({{Block::kBg, Mat3::Identity()}}), expected3);
}

TEST(EskfEmbedJacobianDeathTest, WrongWidthOrRepeatedBlock) {
  EXPECT_DEATH(EmbedJacobian<1>({{Block::kS, Eigen::Matrix<double, 1, 3>::Ones()}}), "columns for block s");
  EXPECT_DEATH(EmbedJacobian<3>({{Block::kV, Mat3::Identity()}, {Block::kV, Mat3::Identity()}}),
               "block v listed twice");
}

}  // namespace
}  // namespace gins::eskf
