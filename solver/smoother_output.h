// What leaves the smoother: a keyframe's estimate with its 1-σ, the covariance of the oldest keyframe from
// the information of the whole window, and the final stream (each keyframe as it leaves the window, with
// IMU-rate states to the next one).
#pragma once

#include <vector>

#include "solver/estimator.h"
#include "solver/keyframe.h"

namespace gins {

// The keyframe's state and odometer scale, with the 1-σ of cov (NavState tangent order) when given.
StateEstimate EstimateOf(const Keyframe& kf, const Mat15* cov);

// Covariance (NavState tangent order) of the columns `nav_index` says are NavState coordinates among the
// first nav_index.size() tangent columns of `blocks`, from the full information H = JᵀJ of the problem over
// `blocks`. False if the problem cannot be evaluated or H is not positive definite.
bool LeadingCovariance(ceres::Problem* problem, const std::vector<double*>& blocks, const std::vector<int>& nav_index,
                       Mat15* cov);

// Covariance of the oldest keyframe of the window, from all the information in the window.
bool OldestCovariance(KeyframeStore& store, Mat15* cov);

// Covariances of the estimated blocks (KeyframeStore::EstimatedTypes order) from all the information in the
// window: of the newest `trailing` keyframes jointly (keyframe after keyframe), and, when oldest_cov is not
// null, of the oldest keyframe. False if the problem cannot be evaluated or H is not finite.
bool WindowCovariances(KeyframeStore& store, int trailing, MatX* trailing_cov, MatX* oldest_cov);
// The same in NavState tangent order (15) for one keyframe's block-order covariance (scale left out).
Mat15 NavCovariance(const std::vector<BlockType>& types, const MatX& block_cov);

// The final stream of one keyframe: its estimate, then the IMU-rate states up to the next keyframe
// (excluded: it emits itself), propagated from this keyframe's final estimate through next's
// steps_from_prev; without a next keyframe, through all of `tail` (the steps after the newest keyframe).
void EmitFinal(const Keyframe& kf, const Keyframe* next, const std::vector<HeldImuSample>& tail, const Mat15* cov,
               const ImuEarthTerms& earth, const StateCallback& on_final);
// On the flat Earth with gravity g_w.
inline void EmitFinal(const Keyframe& kf, const Keyframe* next, const std::vector<HeldImuSample>& tail,
                      const Mat15* cov, const Vec3& g_w, const StateCallback& on_final) {
  ImuEarthTerms earth;
  earth.g_w = g_w;
  EmitFinal(kf, next, tail, cov, earth, on_final);
}

}  // namespace gins
