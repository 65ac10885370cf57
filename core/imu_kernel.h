// The one IMU propagation kernel. The ESKF (with gravity), the preintegration (gravity zero, from the
// identity) and the simulator's consistency tests all step through it.
//
// Over one interval dt with bias-corrected rate ω and specific force a held constant, φ = ω·dt, and the
// specific force rotated by the attitude the body has on average over the step (second order in φ; the
// first-order R·a lags a turning body and, with a navigation-grade IMU, is thousands of σ off in a turn):
//   p' = p + v·dt + ½(R·(I + ⅓[φ]×)·a + g)·dt²,   v' = v + (R·(I + ½[φ]×)·a + g)·dt,   R' = R·Exp(φ).
// With Earth rotation (core/earth.h: w is Earth-fixed, ω = ω_ib is measured against inertial space and
// ω_ie is constant in w), the acceleration gains the Coriolis term and w turns under the body:
//   both accelerations gain −2·ω_ie×v, φ is the turn against w, (ω − Rᵀω_ie)·dt, in the rotated specific
//   force (not in R'), and R' = Exp(−ω_ie·dt)·R·Exp(ω·dt).
// Error state (right perturbation, core/conventions.h), order δp, δv, δθ:
//   δx' = A·δx + B·[δbg; δba] + B·[ηg; ηa] + G·δg
// where ηg, ηa are the sensor white noises over the interval (rad/s, m/s²; discrete variance σ²/dt for
// continuous densities σ), which enter exactly where the biases do.
#pragma once

#include "core/conventions.h"
#include "core/measurements.h"

namespace gins {

struct ImuStepJacobians {
  Mat9 A;                          // ∂δx'/∂δx
  Eigen::Matrix<double, 9, 6> B;   // ∂δx'/∂[δbg, δba]  (also the noise Jacobian)
  Eigen::Matrix<double, 9, 3> G;   // ∂δx'/∂δg
  bool coriolis = false;           // A's δv columns carry the Coriolis terms (else they are I·dt and I)
};

// Kinematic part of the state that the kernel propagates.
struct Kinematics {
  Quat q = Quat::Identity();
  Vec3 v = Vec3::Zero();
  Vec3 p = Vec3::Zero();
};

// One step. omega and acc are already bias-corrected. J may be null. earth_rate_w: ω_ie in w (zero: the
// flat, non-rotating model).
Kinematics ImuStep(const Kinematics& x, const Vec3& omega, const Vec3& acc, const Vec3& g_w, double dt,
                   ImuStepJacobians* J = nullptr, const Vec3& earth_rate_w = Vec3::Zero());

// Products with the step Jacobians that skip their zero and identity blocks (as ImuStep fills them): the
// preintegration's covariance and the RTS pass's transitions are made of these (the ESKF's propagation of
// their transposes, below). X has the rows δp, δv, δθ; Y has the rows δbg, δba, δg. MulA(J, X) = A·X;
// MulBG(J, Y, with_gravity) = [B G]·Y (G's part only if with_gravity). X and Y may be blocks of a larger
// matrix (no copy is made).
template <int N, typename Derived>
Eigen::Matrix<double, 9, N> MulA(const ImuStepJacobians& J, const Eigen::MatrixBase<Derived>& X) {
  const auto Xv = X.template middleRows<3>(3);
  const auto Xt = X.template middleRows<3>(6);
  Eigen::Matrix<double, 9, N> out;
  if (J.coriolis) {
    out.template middleRows<3>(0) = X.template middleRows<3>(0) + J.A.template block<3, 3>(0, 3).lazyProduct(Xv) +
                                    J.A.template block<3, 3>(0, 6).lazyProduct(Xt);
    out.template middleRows<3>(3) =
        J.A.template block<3, 3>(3, 3).lazyProduct(Xv) + J.A.template block<3, 3>(3, 6).lazyProduct(Xt);
  } else {
    const double dt = J.A(0, 3);
    out.template middleRows<3>(0) =
        X.template middleRows<3>(0) + dt * Xv + J.A.template block<3, 3>(0, 6).lazyProduct(Xt);
    out.template middleRows<3>(3) = Xv + J.A.template block<3, 3>(3, 6).lazyProduct(Xt);
  }
  out.template middleRows<3>(6) = J.A.template block<3, 3>(6, 6).lazyProduct(Xt);
  return out;
}

template <int N, typename Derived>
Eigen::Matrix<double, 9, N> MulBG(const ImuStepJacobians& J, const Eigen::MatrixBase<Derived>& Y, bool with_gravity) {
  const auto Ybg = Y.template middleRows<3>(0);
  const auto Yba = Y.template middleRows<3>(3);
  Eigen::Matrix<double, 9, N> out;
  out.template middleRows<3>(0) =
      J.B.template block<3, 3>(0, 0).lazyProduct(Ybg) + J.B.template block<3, 3>(0, 3).lazyProduct(Yba);
  out.template middleRows<3>(3) =
      J.B.template block<3, 3>(3, 0).lazyProduct(Ybg) + J.B.template block<3, 3>(3, 3).lazyProduct(Yba);
  out.template middleRows<3>(6) = J.B.template block<3, 3>(6, 0).lazyProduct(Ybg);
  if (with_gravity) {
    out.template middleRows<3>(0) += J.G(0, 0) * Y.template middleRows<3>(6);
    out.template middleRows<3>(3) += J.G(3, 0) * Y.template middleRows<3>(6);
  }
  return out;
}

// The same products transposed: MulAT(J, XT) = XT·Aᵀ = (A·X)ᵀ and MulBGT(J, YT, with_gravity) = YT·[B G]ᵀ,
// with XT's columns δp, δv, δθ and YT's δbg, δba, δg. Each output column is a weighted sum of a few of XT's
// columns, which Eigen vectorises down the rows (A·X's 3-row blocks do not vectorise). For a symmetric
// covariance XT is its own block: the ESKF's propagation uses these. Same sums in the same order as MulA.
template <int N, typename Derived>
Eigen::Matrix<double, N, 9> MulAT(const ImuStepJacobians& J, const Eigen::MatrixBase<Derived>& XT) {
  const Mat9& A = J.A;
  Eigen::Matrix<double, N, 9> out;
  for (int c = 0; c < 3; ++c) {
    const auto t_sum = [&](int row) {
      return A(row, 6) * XT.col(6) + A(row, 7) * XT.col(7) + A(row, 8) * XT.col(8);
    };
    if (J.coriolis) {
      out.col(c) = XT.col(c) + (A(c, 3) * XT.col(3) + A(c, 4) * XT.col(4) + A(c, 5) * XT.col(5)) + t_sum(c);
      out.col(3 + c) = (A(3 + c, 3) * XT.col(3) + A(3 + c, 4) * XT.col(4) + A(3 + c, 5) * XT.col(5)) + t_sum(3 + c);
    } else {  // A's δv blocks are I·dt and I
      out.col(c) = XT.col(c) + A(0, 3) * XT.col(3 + c) + t_sum(c);
      out.col(3 + c) = XT.col(3 + c) + t_sum(3 + c);
    }
    out.col(6 + c) = t_sum(6 + c);
  }
  return out;
}

template <int N, typename Derived>
Eigen::Matrix<double, N, 9> MulBGT(const ImuStepJacobians& J, const Eigen::MatrixBase<Derived>& YT,
                                   bool with_gravity) {
  const auto& B = J.B;
  Eigen::Matrix<double, N, 9> out;
  for (int c = 0; c < 3; ++c) {
    out.col(c) = (B(c, 0) * YT.col(0) + B(c, 1) * YT.col(1) + B(c, 2) * YT.col(2)) +
                 (B(c, 3) * YT.col(3) + B(c, 4) * YT.col(4) + B(c, 5) * YT.col(5));
    out.col(3 + c) = (B(3 + c, 0) * YT.col(0) + B(3 + c, 1) * YT.col(1) + B(3 + c, 2) * YT.col(2)) +
                     (B(3 + c, 3) * YT.col(3) + B(3 + c, 4) * YT.col(4) + B(3 + c, 5) * YT.col(5));
    out.col(6 + c) = B(6 + c, 0) * YT.col(0) + B(6 + c, 1) * YT.col(1) + B(6 + c, 2) * YT.col(2);
    if (with_gravity) {
      out.col(c) += J.G(0, 0) * YT.col(6 + c);
      out.col(3 + c) += J.G(3, 0) * YT.col(6 + c);
    }
  }
  return out;
}

// P += B·diag(q)·Bᵀ, the sensor noise over the step (q: the variances of [ηg; ηa], e.g. ImuDiscreteNoise's
// diagonal), from B's five non-zero blocks: the δp and δv rows take ηa and (through the sculling term) ηg,
// the δθ rows ηg. P: 9×9, rows and columns δp, δv, δθ (a block of a larger matrix is fine).
template <typename Derived>
void AddDrivingNoise(const ImuStepJacobians& J, const Vec6& q, const Eigen::MatrixBase<Derived>& P_out) {
  auto& P = const_cast<Eigen::MatrixBase<Derived>&>(P_out);  // Eigen's idiom for writable block arguments
  const auto Bpg = J.B.template block<3, 3>(0, 0), Bpa = J.B.template block<3, 3>(0, 3);
  const auto Bvg = J.B.template block<3, 3>(3, 0), Bva = J.B.template block<3, 3>(3, 3);
  const auto Btg = J.B.template block<3, 3>(6, 0);
  const Mat3 BpaQ = Bpa * q.tail<3>().asDiagonal(), BvaQ = Bva * q.tail<3>().asDiagonal();
  const Mat3 BpgQ = Bpg * q.head<3>().asDiagonal(), BvgQ = Bvg * q.head<3>().asDiagonal();
  const Mat3 Qpv = BpaQ.lazyProduct(Bva.transpose()) + BpgQ.lazyProduct(Bvg.transpose());
  const Mat3 Qpt = BpgQ.lazyProduct(Btg.transpose()), Qvt = BvgQ.lazyProduct(Btg.transpose());
  P.template block<3, 3>(0, 0) += BpaQ.lazyProduct(Bpa.transpose()) + BpgQ.lazyProduct(Bpg.transpose());
  P.template block<3, 3>(0, 3) += Qpv;
  P.template block<3, 3>(3, 0) += Qpv.transpose();
  P.template block<3, 3>(3, 3) += BvaQ.lazyProduct(Bva.transpose()) + BvgQ.lazyProduct(Bvg.transpose());
  P.template block<3, 3>(0, 6) += Qpt;
  P.template block<3, 3>(6, 0) += Qpt.transpose();
  P.template block<3, 3>(3, 6) += Qvt;
  P.template block<3, 3>(6, 3) += Qvt.transpose();
  P.template block<3, 3>(6, 6) += (Btg * q.head<3>().asDiagonal()).lazyProduct(Btg.transpose());
}

// The rate and specific force to hold between two consecutive samples: their mean. Second-order accurate
// for sampled (not interval-averaged) IMU data, where holding the first sample lags the attitude by half a
// step of the rate change. Time stamp: the later sample's.
inline ImuSample HeldBetween(const ImuSample& earlier, const ImuSample& later) {
  ImuSample mid = later;
  mid.gyro = 0.5 * (earlier.gyro + later.gyro);
  mid.acc = 0.5 * (earlier.acc + later.acc);
  return mid;
}

// Discrete noise covariance of [ηg; ηa] over dt for continuous white-noise densities
// (gyro rad/s/√Hz, accel m/s²/√Hz).
Mat6 ImuDiscreteNoise(double gyro_noise_density, double acc_noise_density, double dt);

}  // namespace gins
