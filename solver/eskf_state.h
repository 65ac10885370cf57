// The ESKF's error-state layout, declared once: each block's name and dimension in kBlocks, in state order;
// offsets, the total dimension and the propagation's split are derived from it.
//
// The order has three groups, because the IMU kernel (core/imu_kernel.h) propagates by them:
// - kinematic (δp, δv, δθ): the kernel's A;
// - driving (δbg, δba, δg): they enter the kinematics through the kernel's B and G, and random-walk;
// - passive (δs, ...): they do not enter the kinematics; constant or random walks.
// The blocks after the NavState's are additive (Euclidean) in the nominal state too: EskfNominal keeps them
// in one vector in table order, so box-plus, box-minus, packing and the finiteness check loop over the table.
// A new state that does not enter the kinematics (e.g. a barometer bias) is one entry at the end of Block
// and kBlocks (with its nominal start value), plus its own dynamics (Eskf::AddRandomWalks) and its
// measurement's Jacobian.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string_view>

#include "core/nav_state.h"

namespace gins {
namespace eskf {

enum class Block : int { kP, kV, kTheta, kBg, kBa, kG, kS, kTd, kCount };

struct BlockInfo {
  Block block;
  std::string_view name;
  int dim;
  double start = 0.0;  // an additive block's nominal value before any estimate (each component)
};

inline constexpr int kNumBlocks = static_cast<int>(Block::kCount);

inline constexpr std::array<BlockInfo, kNumBlocks> kBlocks = {{
    {Block::kP, "p", 3},          // position in w, m
    {Block::kV, "v", 3},          // velocity in w, m/s
    {Block::kTheta, "theta", 3},  // attitude, right perturbation (core/conventions.h), rad
    {Block::kBg, "bg", 3},        // gyro bias, rad/s
    {Block::kBa, "ba", 3},        // accelerometer bias, m/s²
    {Block::kG, "g", 3},          // gravity in w, m/s²
    {Block::kS, "s", 1, 1.0},     // odometer scale
    {Block::kTd, "td", 1},        // GNSS time offset beyond gnss.time_offset_s's value, s (core/time_shift.h)
}};

// The first block of the driving and of the passive group (see the top of the file).
inline constexpr Block kFirstDriving = Block::kBg;
inline constexpr Block kFirstPassive = Block::kS;

constexpr int Dim(Block b) { return kBlocks[static_cast<int>(b)].dim; }

// Blocks are contiguous in their order: the offset is the sum of the dimensions before. Block::kCount's
// offset is the total dimension.
constexpr int Offset(Block b) {
  int offset = 0;
  for (int i = 0; i < static_cast<int>(b); ++i) offset += kBlocks[i].dim;
  return offset;
}

inline constexpr int kDim = Offset(Block::kCount);
inline constexpr int kKinematicDim = Offset(kFirstDriving);
inline constexpr int kDrivingDim = Offset(kFirstPassive) - kKinematicDim;
inline constexpr int kNonKinematicDim = kDim - kKinematicDim;  // driving and passive: P's "b" part
inline constexpr int kMaxBlockDim = [] {
  int m = 0;
  for (const BlockInfo& b : kBlocks) m = b.dim > m ? b.dim : m;
  return m;
}();

// The former names of two offsets, kept for callers.
inline constexpr int kG = Offset(Block::kG);
inline constexpr int kS = Offset(Block::kS);

constexpr bool TableInEnumOrder() {
  for (int i = 0; i < kNumBlocks; ++i) {
    if (static_cast<int>(kBlocks[i].block) != i || kBlocks[i].dim <= 0) return false;
  }
  return true;
}
static_assert(TableInEnumOrder(), "kBlocks lists every Block once, in enum order, with a positive dimension");
// NavState::Boxplus and the initialiser's P0 use core's layout for the first blocks.
static_assert(Offset(Block::kP) == nav::kP && Offset(Block::kV) == nav::kV &&
                  Offset(Block::kTheta) == nav::kTheta && Offset(Block::kBg) == nav::kBg &&
                  Offset(Block::kBa) == nav::kBa && Offset(Block::kG) == nav::kDim,
              "the NavState blocks come first, in core/nav_state.h's order");
static_assert(kKinematicDim == 9 && kDrivingDim == 9,
              "the IMU kernel (MulA, MulBG) propagates δp, δv, δθ, driven by δbg, δba, δg");

// Views of one block of a state vector or of a covariance (rows r, columns c), sized at compile time.
template <Block b, typename Vector>
auto SegmentOf(Vector& v) {
  return v.template segment<Dim(b)>(Offset(b));
}
template <Block r, Block c = r, typename Matrix>
auto BlockOf(Matrix& m) {
  return m.template block<Dim(r), Dim(c)>(Offset(r), Offset(c));
}
template <Block r, typename Matrix>
auto RowsOf(Matrix& m) {
  return m.template middleRows<Dim(r)>(Offset(r));
}
template <Block c, typename Matrix>
auto ColsOf(Matrix& m) {
  return m.template middleCols<Dim(c)>(Offset(c));
}

// The additive blocks: those after the NavState's, in one vector.
inline constexpr int kAdditiveDim = kDim - nav::kDim;
static_assert(kAdditiveDim > 0, "at least one block after the NavState's");

}  // namespace eskf

// The filter's full nominal state: the NavState and the additive blocks (δg, the odometer scale, ...) in
// table order. Box-plus/box-minus match the error state's layout (eskf::kBlocks).
struct EskfNominal {
  using Vec = Eigen::Matrix<double, eskf::kDim, 1>;
  using Additive = Eigen::Matrix<double, eskf::kAdditiveDim, 1>;
  // The packed form (eskf_rts.h's file): p, v, q (w x y z), bg, ba, then the additive blocks.
  static constexpr int kPackedSize = 16 + eskf::kAdditiveDim;

  NavState x;
  Additive additive = Start();

  // The additive blocks' start values (eskf::BlockInfo::start).
  static Additive Start();

  template <eskf::Block b>
  auto Get() {
    static_assert(eskf::Offset(b) >= nav::kDim, "an additive block");
    return additive.template segment<eskf::Dim(b)>(eskf::Offset(b) - nav::kDim);
  }
  template <eskf::Block b>
  auto Get() const {
    static_assert(eskf::Offset(b) >= nav::kDim, "an additive block");
    return additive.template segment<eskf::Dim(b)>(eskf::Offset(b) - nav::kDim);
  }
  // A one-dimensional additive block's value.
  template <eskf::Block b>
  double& Scalar() {
    static_assert(eskf::Dim(b) == 1, "a scalar block");
    return additive[eskf::Offset(b) - nav::kDim];
  }
  template <eskf::Block b>
  double Scalar() const {
    static_assert(eskf::Dim(b) == 1, "a scalar block");
    return additive[eskf::Offset(b) - nav::kDim];
  }

  // This state moved by d; and this ⊟ a (the error state between them).
  EskfNominal Plus(const Vec& d) const;
  void PlusInPlace(const Vec& d);
  Vec Minus(const EskfNominal& a) const;
  bool AllFinite() const;
  // Each additive block that is not finite back to its start value.
  void ResetNonFinite();
  void Pack(double* out) const;
  static EskfNominal Unpack(const double* in, double t);
};

}  // namespace gins
