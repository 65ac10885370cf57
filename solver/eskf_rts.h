// The ESKF's Rauch-Tung-Striebel backward pass (eskf_rts.tum): the forward filter's estimates smoothed
// with every measurement of the log, before and after.
//
// Nodes are the filter's update epochs (every accepted update, several at one time stamp make one node).
// The forward pass records, per node k: the prior x⁻_k, P⁻_k (before its updates), the posterior x⁺_k,
// P⁺_k (after them), the transition Φ_k from the node before (compounded from the IMU steps' Jacobians,
// block-structured as the filter's F), and the IMU steps between them. The records go to an unnamed
// temporary file and are read back in reverse, so memory does not grow with the log (a node is 6 KB on
// disk; in memory only the smoothed state and σ per node, and never a covariance per IMU sample).
//
// Backward (error state, right perturbation as the filter): C_k = P⁺_k Φ_{k+1}ᵀ (P⁻_{k+1})⁻¹,
// δ_k = C_k (x^s_{k+1} ⊟ x⁻_{k+1}), x^s_k = x⁺_k ⊞ δ_k, P^s_k = P⁺_k + C_k (P^s_{k+1} − P⁻_{k+1}) C_kᵀ.
// A watchdog re-initialisation starts a new chain: nothing is smoothed across it.
//
// Output: each node's smoothed state with its smoothed σ, and the IMU-rate states between nodes bridged
// onto both ends (solver/imu_bridge.h).
#pragma once

#include <cstdio>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/imu_kernel.h"
#include "solver/eskf_state.h"
#include "solver/estimator.h"
#include "solver/imu_bridge.h"
#include "solver/keyframe.h"

namespace gins {

// One backward RTS step in N dimensions (the filter's and the tests' linear models alike): given the
// filtered P⁺_k, the transition Φ to k+1, the predicted P⁻_{k+1}, the smoothed correction at k+1
// d = x^s_{k+1} − x⁻_{k+1} and the smoothed P^s_{k+1}, returns the correction at k (δ_k, to add to x⁺_k) and
// P^s_k. False if P⁻_{k+1} is not positive definite.
template <int N>
bool RtsBackwardStep(const Eigen::Matrix<double, N, N>& P_post, const Eigen::Matrix<double, N, N>& Phi,
                     const Eigen::Matrix<double, N, N>& P_prior_next, const Eigen::Matrix<double, N, 1>& d_next,
                     const Eigen::Matrix<double, N, N>& P_smooth_next, Eigen::Matrix<double, N, 1>* delta,
                     Eigen::Matrix<double, N, N>* P_smooth) {
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(P_prior_next);
  if (llt.info() != Eigen::Success) return false;
  // C = P⁺ Φᵀ (P⁻)⁻¹, solved as (P⁻)⁻¹ (Φ P⁺) transposed (P⁻ symmetric).
  const Eigen::Matrix<double, N, N> C = llt.solve(Phi * P_post).transpose();
  *delta = C * d_next;
  *P_smooth = P_post + C * (P_smooth_next - P_prior_next) * C.transpose();
  *P_smooth = 0.5 * (*P_smooth + P_smooth->transpose()).eval();
  return delta->allFinite() && P_smooth->allFinite();
}

class EskfRts {
 public:
  using MatP = Eigen::Matrix<double, eskf::kDim, eskf::kDim>;
  using VecP = Eigen::Matrix<double, eskf::kDim, 1>;

  // noise: the IMU's, for the output bridges between nodes; with_gravity: eskf.estimate_gravity.
  EskfRts(const BridgeNoise& noise, bool with_gravity);
  ~EskfRts();
  EskfRts(const EskfRts&) = delete;
  EskfRts& operator=(const EskfRts&) = delete;

  // A chain starts at x (initialisation, watchdog re-initialisation): a node that is its own prior.
  void StartChain(const EskfNominal& x, const MatP& P);
  // One sample's step of the filter's nominal state (the rate and specific force it used), for the output
  // bridges between nodes.
  void RecordStep(const Vec3& gyro, const Vec3& acc, double t_before, double dt);
  // One step of the filter's covariance (its kernel Jacobians; it may span several samples' steps).
  void Compound(const ImuStepJacobians& J);
  // Before an accepted update at the filter's current time: opens a node there (unless one is open at
  // this time), with the state before the update as its prior.
  void BeforeUpdate(const EskfNominal& x, const MatP& P);
  // After the filter's updates at a time: the open node's posterior (call before it moves on, and at the
  // end). Harmless without an open node.
  void AfterUpdates(const EskfNominal& x, const MatP& P);

  // The backward pass and the output stream (time order); earth: gravity and Earth rate for the bridges.
  void Smooth(const EarthModel& earth, const StateCallback& out);
  nlohmann::json Stats() const;

 private:
  struct Node;
  void Write(const Node& node);
  bool Read(size_t index, Node* node);

  BridgeNoise noise_;
  bool with_gravity_ = false;
  std::FILE* nodes_file_ = nullptr;  // fixed-size node records, in time order
  std::FILE* steps_file_ = nullptr;  // the IMU steps, in time order
  size_t nodes_ = 0, steps_ = 0;
  std::vector<uint64_t> first_step_;  // per node: its first IMU step after it (index into steps_file_)
  // The node being built.
  bool open_ = false;
  bool chain_start_ = false;
  double open_t_ = 0.0;
  EskfNominal prior_x_;
  MatP prior_P_ = MatP::Zero();
  // Φ from the last closed node to now, in the filter's block structure [[Φa, Φc], [0, I]].
  Eigen::Matrix<double, eskf::kKinematicDim, eskf::kKinematicDim> phi_a_;
  Eigen::Matrix<double, eskf::kKinematicDim, eskf::kNonKinematicDim> phi_c_;
  bool failed_ = false;  // a temporary file could not be written: no RTS output
  double smooth_time_s_ = 0.0;
  uint64_t chains_ = 0, singular_ = 0;
};

}  // namespace gins
