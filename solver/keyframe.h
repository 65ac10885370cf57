// The smoother's keyframes and their state blocks, as data. One row per block type (kBlockSpecs) gives its
// sizes, its manifold, where its tangent sits in the NavState tangent (δp, δv, δθ, δbg, δba) and whether the
// options estimate it; the keyframe store adds a keyframe's blocks to the problem, lists them, builds the
// initial prior and wraps factors for first-estimate Jacobians by iterating that table. Adding a state to
// the keyframes is one row (and its enum value), not an edit wherever the blocks are listed.
#pragma once

#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "core/nav_state.h"
#include "core/preintegration.h"
#include "factors/marginalization_prior.h"
#include "factors/pose_manifold.h"
#include "solver/estimator_options.h"

namespace gins {

// The state blocks of one keyframe, in table order (the order of kBlockSpecs, of Keyframe::values, of every
// list of a keyframe's blocks, and so of the solver's elimination order).
enum class BlockType { kPose, kVelocity, kBias, kScale, kTimeOffset };
inline constexpr int kNumBlockTypes = 5;

// Coordinates [tangent_offset, tangent_offset + size) of a block's tangent sit at
// [nav_offset, nav_offset + size) of the NavState tangent.
struct NavRun {
  int tangent_offset = 0;
  int nav_offset = 0;
  int size = 0;
};

struct BlockSpec {
  BlockType type;
  const char* name;
  int ambient_size;
  int tangent_size;
  BlockKind kind;  // kPose: PoseManifold; kEuclidean: no manifold
  // Where the tangent sits in NavState: the pose block is (δp, δθ), so two runs; none (num_runs 0) for a
  // block outside NavState.
  int num_runs;
  std::array<NavRun, 2> runs;
  // NavState <-> block values; null for a block outside NavState.
  void (*to_nav)(const double* values, NavState* x);
  void (*from_nav)(const NavState& x, double* values);
  // Whether the options estimate the block; one that is not is held constant in the problem and left out
  // of priors, orderings and covariances. Null: always estimated.
  bool (*estimated)(const SensorOptions& options);
  // For a block outside NavState: its value on a first keyframe (later keyframes start from the previous
  // keyframe's, a random walk's mean) and its 1-σ in the initial prior.
  double initial_value;
  double (*prior_sigma)(const SensorOptions& options);
  // The factor between this block of two consecutive keyframes dt apart, when it is a random walk; null
  // for a block the IMU factor links (pose, velocity).
  ceres::CostFunction* (*random_walk)(const SensorOptions& options, double dt);
  // For a random walk outside NavState: its 1-σ per √s, for the window's predicted covariance.
  double (*random_walk_sigma)(const SensorOptions& options);
};

namespace keyframe_blocks {
void PoseToNav(const double* values, NavState* x);
void PoseFromNav(const NavState& x, double* values);
void VelocityToNav(const double* values, NavState* x);
void VelocityFromNav(const NavState& x, double* values);
void BiasToNav(const double* values, NavState* x);
void BiasFromNav(const NavState& x, double* values);
double ScalePriorSigma(const SensorOptions& options);
double ScaleRandomWalkSigma(const SensorOptions& options);
ceres::CostFunction* BiasRandomWalk(const SensorOptions& options, double dt);
ceres::CostFunction* ScaleRandomWalk(const SensorOptions& options, double dt);
// The GNSS time offset beyond gnss.time_offset_s (s; factors/delayed_factor.h), with `estimate` only.
bool TimeOffsetEstimated(const SensorOptions& options);
double TimeOffsetPriorSigma(const SensorOptions& options);
double TimeOffsetRandomWalkSigma(const SensorOptions& options);
ceres::CostFunction* TimeOffsetRandomWalk(const SensorOptions& options, double dt);
}  // namespace keyframe_blocks

// clang-format off
inline constexpr std::array<BlockSpec, kNumBlockTypes> kBlockSpecs = {{
    {BlockType::kPose, "pose", pose::kAmbient, pose::kTangent, BlockKind::kPose,
     2, {{{pose::kP, nav::kP, 3}, {pose::kTheta, nav::kTheta, 3}}},
     &keyframe_blocks::PoseToNav, &keyframe_blocks::PoseFromNav,
     nullptr, 0.0, nullptr, nullptr, nullptr},
    {BlockType::kVelocity, "velocity", 3, 3, BlockKind::kEuclidean,
     1, {{{0, nav::kV, 3}, {}}},
     &keyframe_blocks::VelocityToNav, &keyframe_blocks::VelocityFromNav,
     nullptr, 0.0, nullptr, nullptr, nullptr},
    {BlockType::kBias, "bias", 6, 6, BlockKind::kEuclidean,
     1, {{{0, nav::kBg, 6}, {}}},  // (bg, ba): contiguous in NavState too
     &keyframe_blocks::BiasToNav, &keyframe_blocks::BiasFromNav,
     nullptr, 0.0, nullptr, &keyframe_blocks::BiasRandomWalk, nullptr},
    {BlockType::kScale, "scale", 1, 1, BlockKind::kEuclidean,
     0, {},
     nullptr, nullptr,
     &OdometerScaleEstimated, 1.0, &keyframe_blocks::ScalePriorSigma, &keyframe_blocks::ScaleRandomWalk,
     &keyframe_blocks::ScaleRandomWalkSigma},
    {BlockType::kTimeOffset, "time_offset", 1, 1, BlockKind::kEuclidean,
     0, {},
     nullptr, nullptr,
     &keyframe_blocks::TimeOffsetEstimated, 0.0, &keyframe_blocks::TimeOffsetPriorSigma,
     &keyframe_blocks::TimeOffsetRandomWalk, &keyframe_blocks::TimeOffsetRandomWalkSigma},
}};
// clang-format on

constexpr const BlockSpec& SpecOf(BlockType type) { return kBlockSpecs[static_cast<int>(type)]; }

// Offset of a block in a keyframe's values (blocks back to back in table order), and their total size.
constexpr int AmbientOffsetOfRow(int row) {
  int offset = 0;
  for (int i = 0; i < row; ++i) offset += kBlockSpecs[i].ambient_size;
  return offset;
}
constexpr int AmbientOffset(BlockType type) { return AmbientOffsetOfRow(static_cast<int>(type)); }
inline constexpr int kKeyframeAmbientSize = AmbientOffsetOfRow(kNumBlockTypes);

// The NavState index of each tangent coordinate of the given blocks, concatenated in their order (-1 for a
// coordinate outside NavState).
std::vector<int> NavIndexOfTangent(const std::vector<BlockType>& types);

// One IMU step: the rate and specific force held over dt.
struct HeldImuSample {
  ImuSample sample;
  double dt;
};

struct Keyframe {
  uint64_t id = 0;  // from the store: increasing, never reused (attachers key their records on it)
  double t = 0.0;
  double values[kKeyframeAmbientSize] = {};  // the blocks, back to back in table order: the parameter memory
  // First estimates: once a marginalisation prior is built on this keyframe, every other factor on it
  // evaluates its Jacobians here, at the prior's linearisation point, so the prior and the factors agree
  // on what is observable (no spurious information in yaw or position).
  bool fej = false;
  double first_estimates[kKeyframeAmbientSize] = {};

  std::shared_ptr<const Preintegration> preint;  // previous keyframe -> this one
  std::vector<HeldImuSample> steps_from_prev;    // for the IMU-rate output between keyframes
  ceres::ResidualBlockId imu_id = nullptr;       // the IMU factor from the previous keyframe
  size_t imu_log_index = 0;                      // and its entry in the factor log, when one is kept
  // Stood still since the previous keyframe, turning neither (a zero-motion factor with its rotation joins
  // them): the outputs between them hold still.
  bool still_from_prev = false;

  double* block(BlockType type) { return values + AmbientOffset(type); }
  const double* block(BlockType type) const { return values + AmbientOffset(type); }
  const double* first_estimate(BlockType type) const { return first_estimates + AmbientOffset(type); }
  void FreezeFirstEstimates();
  NavState State() const;            // t and the NavState blocks (quaternion normalised)
  void SetState(const NavState& x);  // the NavState blocks (not t)
};

// Solver options for a chain of keyframes: sparse normal Cholesky on SuiteSparse (Eigen's sparse Cholesky
// when Ceres lacks it), eliminating in `ordering` (time order, one block after the other: no fill-in along
// the chain, and the same order every run; Ceres's default ordering is a set of block addresses, so the
// last bits of the solution would follow the heap's layout).
ceres::Solver::Options ChainSolverOptions(std::shared_ptr<ceres::ParameterBlockOrdering> ordering, int max_iterations,
                                          double function_tolerance, int num_threads);

// One block of one keyframe, as a factor's parameter.
struct BlockRef {
  Keyframe* kf;
  BlockType type;
};

class FactorLog;

// The IMU from prev to a keyframe integrated again at prev's bias estimate, when its gyro bias moved further
// than threshold (rad/s) from where `pre` was integrated; null otherwise (the factor's first-order bias
// Jacobians cover the rest, exactly for the accelerometer bias). A new object: live factors never see theirs
// change.
std::shared_ptr<Preintegration> ReintegratedIfMoved(const Keyframe& prev, const Preintegration& pre,
                                                    double threshold);


// The window's keyframes, oldest first, and their blocks in a Ceres problem.
class KeyframeStore {
 public:
  explicit KeyframeStore(const SensorOptions& options);

  // Empties the window; the blocks of the keyframes pushed from now on go to `problem` (not owned).
  void Reset(ceres::Problem* problem);
  // From now on every factor and prior added, and every keyframe leaving the window, also goes to `log`
  // (not owned; null: none, the default).
  void SetLog(FactorLog* log) { log_ = log; }
  FactorLog* log() const { return log_; }
  // The log index of the factor or prior added last (with a log).
  size_t last_logged() const { return last_logged_; }
  ceres::Problem* problem() const { return problem_; }
  bool estimated(BlockType type) const { return estimated_[static_cast<int>(type)]; }

  // A keyframe at t with the NavState blocks from x, and the others from the newest keyframe (in an empty
  // window: the values kept by KeepValues, or their initial value); not in the window yet.
  std::unique_ptr<Keyframe> Make(double t, const NavState& x) const;
  // kf's blocks outside NavState (scale, time offset) as the start of the next empty window's first keyframe
  // (a reset keeps what was learnt of the sensors); ForgetValues returns to the initial values.
  void KeepValues(const Keyframe& kf);
  void ForgetValues() { have_kept_ = false; }
  // Appends kf as the newest keyframe and adds its blocks to the problem in table order (those not
  // estimated held constant).
  Keyframe& Push(std::unique_ptr<Keyframe> kf);
  // Drops the oldest keyframe; its residuals and blocks must be out of the problem already (Marginalizer:
  // residuals first, in program order, for determinism).
  void PopOldest();
  void Clear();

  size_t size() const { return window_.size(); }
  bool empty() const { return window_.empty(); }
  Keyframe& operator[](size_t i) { return *window_[i]; }
  const Keyframe& operator[](size_t i) const { return *window_[i]; }
  Keyframe& front() { return *window_.front(); }
  const Keyframe& front() const { return *window_.front(); }
  Keyframe& back() { return *window_.back(); }
  const Keyframe& back() const { return *window_.back(); }

  // A keyframe's blocks in table order: all of them, or the estimated ones.
  std::vector<double*> Blocks(Keyframe& kf) const;
  std::vector<double*> EstimatedBlocks(Keyframe& kf) const;
  // The estimated blocks of the whole window, oldest keyframe first: the elimination order, and the
  // columns of a covariance recovery.
  std::vector<double*> EstimatedBlocks();
  // The block types EstimatedBlocks(kf) lists, in its order.
  std::vector<BlockType> EstimatedTypes() const;

  // Adds a factor on the given blocks, wrapped for first-estimate Jacobians (factors/fej_cost.h): each
  // block linearises at its keyframe's first estimate once the keyframe has one.
  ceres::ResidualBlockId AddFactor(ceres::CostFunction* cost, ceres::LossFunction* loss,
                                   const std::vector<BlockRef>& blocks);
  // A measurement's factor, as AddFactor, that the whole-log smoother re-checks with gate (χ²).
  ceres::ResidualBlockId AddMeasurement(ceres::CostFunction* cost, ceres::LossFunction* loss,
                                        const std::vector<BlockRef>& blocks, double gate);
  // A measurement the window rejected: kept in the log (inactive) for the whole-log smoother to re-check,
  // nothing added to the problem. Takes ownership of cost; without a log it is deleted.
  void LogRejected(ceres::CostFunction* cost, ceres::LossFunction* loss, const std::vector<BlockRef>& blocks,
                   double gate);
  // The covariance P0 (NavState tangent order) in the estimated blocks' tangent order; a block outside
  // NavState gets its spec's prior_sigma, uncorrelated.
  MatX PriorCovariance(const Mat15& P0) const;
  // PriorCovariance(P0) as a prior on kf's estimated blocks.
  ceres::ResidualBlockId AddPrior(Keyframe& kf, const Mat15& P0);
  // The random-walk factors from prev to kf of the estimated blocks that have one, in table order.
  void AddRandomWalks(Keyframe& prev, Keyframe& kf);

 private:
  ceres::Manifold* ManifoldOf(const BlockSpec& spec);

  SensorOptions options_;  // its blocks read imu.*, wheel.* and gnss.* only
  std::array<bool, kNumBlockTypes> estimated_{};
  ceres::Problem* problem_ = nullptr;
  PoseManifold pose_manifold_;
  std::deque<std::unique_ptr<Keyframe>> window_;
  bool have_kept_ = false;
  double kept_[kKeyframeAmbientSize] = {};  // KeepValues's blocks (those outside NavState)
  uint64_t next_id_ = 0;
  FactorLog* log_ = nullptr;
  size_t last_logged_ = 0;
  // Adds to the problem and, with a log, records.
  ceres::ResidualBlockId AddLogged(std::shared_ptr<ceres::CostFunction> cost, ceres::CostFunction* in_problem,
                                   ceres::LossFunction* loss, const std::vector<BlockRef>& blocks);
};

}  // namespace gins
