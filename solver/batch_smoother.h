// Whole-log smoothing (--mode batch, reference ch. 4 with the window removed): every keyframe and every
// factor the sliding window built over the log (solver/factor_log.h), in one Ceres problem, solved from the
// window's final estimates. No marginalisation and no first-estimate Jacobians: each keyframe sees the
// whole log on both sides, so an outage is bridged from both of its ends.
//
// Linear algebra: sparse normal Cholesky with SuiteSparse's CHOLMOD (Eigen's sparse Cholesky when Ceres
// lacks it), blocks eliminated in time order. The problem is a chain (each factor spans at most a few
// neighbouring keyframes), so its normal equations are banded and a time-ordered supernodal Cholesky
// factors them with no fill beyond the band; a Schur ordering would only add a dense reduced system.
//
// Marginal covariances (the 1-σ of the output) come from the same banded structure: the information matrix
// is block-tridiagonal over groups of w consecutive keyframes (w the widest factor's span), inverted on
// its diagonal blocks by a forward Schur sweep and a backward (Rauch-Tung-Striebel-like) one, O(n) and
// never a dense inverse.
//
// Outputs: each keyframe with its σ, and the IMU-rate states between keyframes bridged so that there is no
// jump at either end (solver/imu_bridge.h).
#pragma once

#include <ceres/ordered_groups.h>
#include <ceres/problem.h>

#include <nlohmann/json.hpp>

#include <memory>
#include <vector>

#include "core/preintegration.h"
#include "factors/pose_manifold.h"
#include "solver/estimator.h"
#include "solver/estimator_options.h"
#include "solver/factor_log.h"
#include "solver/keyframe.h"

namespace gins {

struct BatchStats {
  int keyframes = 0;
  int factors = 0;
  int keyframes_dropped = 0;  // not finite
  int segments = 0;
  int marginalization_failures = 0;  // at segment seams
  int revisit_dropped = 0;   // fixes the window used that the two-sided solution rejects
  int revisit_restored = 0;  // fixes the window rejected that the two-sided solution accepts
  int iterations = 0;
  int solves = 0;          // re-linearisation rounds
  int reintegrations = 0;  // IMU factors integrated again at the batch's biases
  bool converged = false;
  bool usable = false;
  double initial_cost = 0.0, final_cost = 0.0;
  double solve_time_s = 0.0, covariance_time_s = 0.0;
  int band_keyframes = 0;  // w: the widest factor's span in keyframes
  bool covariance_ok = false;
  nlohmann::json ToJson() const;
};

class BatchSmoother {
 public:
  // types: the estimated blocks (KeyframeStore::EstimatedTypes), in keyframe order.
  // Its sections: imu.* (the bridges' noise), gnss.* (the time offset), batch.*, smoother.* (threads and the
  // reintegration threshold).
  BatchSmoother(const SensorOptions& sensors, const BatchOptions& batch, const SmootherOptions& smoother,
                std::vector<BlockType> estimated_types);

  // Solves the logged problem in place: the keyframes' blocks end at the batch solution. IMU factors whose
  // bias moved are integrated again at the solution (replaced in the log) and the problem solved again.
  void Solve(FactorLog* log, const EarthModel& earth);
  // The keyframes and the IMU-rate states between them, oldest first.
  void Emit(const FactorLog& log, const EarthModel& earth, const StateCallback& out) const;

  const BatchStats& stats() const { return stats_; }
  // summary.json's "time_offset" (solver/estimator_common.h): the newest keyframe's, with its σ from the solution.
  nlohmann::json TimeOffset() const;

 private:
  // A logged factor and the keyframes (indices into kfs_) it spans.
  struct FactorSpan {
    size_t log_index;
    int lo, hi;
  };
  // What a segment hands the next: everything before its seam, marginalised.
  struct Prior {
    std::shared_ptr<ceres::CostFunction> cost;
    std::vector<BlockRef> blocks;
    int lo = 0, hi = 0;
    std::vector<double*> Params() const;
  };
  void AddKeyframeBlocks(ceres::Problem* problem, Keyframe* kf, ceres::ParameterBlockOrdering* ordering, int* group);
  // Solves keyframes [first, last) (with prior on `first`); returns the seam it chose in [seam_from, seam_to]
  // (last when seam_from is last: the final segment) and keeps the covariances of [first, seam).
  int SolveSegment(FactorLog* log, const EarthModel& earth, int first, int last, int seam_from, int seam_to,
                   const Prior& prior);
  // Checks every revisitable measurement of [first, last) against the solution and its covariance (per
  // keyframe, block order); true if one changed sides.
  bool Revisit(FactorLog* log, int first, int last, const std::vector<MatX>& cov);
  // Solves keyframes [first, seam) again with those from the seam on held where the later segment put them.
  void SolveBeforeSeam(const FactorLog& log, int first, int seam, const Prior& prior);
  Prior MarginalPrior(const FactorLog& log, int first, int seam, const Prior& previous);
  // The marginal covariance of each keyframe of [first, last) (its estimated blocks' tangents, block order);
  // false if H is not positive definite or not banded.
  bool RecoverCovariances(ceres::Problem* problem, const std::vector<FactorSpan>& spans, int first, int last,
                          std::vector<MatX>* cov);

  const SensorOptions sensors_;
  const BatchOptions batch_;
  const SmootherOptions smoother_;
  std::vector<BlockType> types_;
  bool estimated_[kNumBlockTypes] = {};
  PoseManifold pose_manifold_;
  // The logged keyframes with finite values (a non-finite one, which only a failed window leaves, is left
  // out with every factor on it), in time order, and the factors on them.
  std::vector<Keyframe*> kfs_;
  std::vector<FactorSpan> factors_;
  std::vector<size_t> imu_factor_;  // per keyframe: its IMU factor's log index (SIZE_MAX: none)
  std::vector<Mat15> covariances_;
  MatX last_block_cov_;  // the newest keyframe's, block order (empty: none)
  std::vector<bool> have_cov_;
  BatchStats stats_;
};

}  // namespace gins
