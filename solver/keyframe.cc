#include "solver/keyframe.h"

#include <glog/logging.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <utility>

#include "factors/bias_rw_factor.h"
#include "factors/fej_cost.h"
#include "factors/scale_rw_factor.h"
#include "solver/factor_log.h"

namespace gins {

namespace keyframe_blocks {
namespace {
constexpr double kMinTimeOffsetRandomWalk = 1e-6;  // s/√s
}  // namespace

void PoseToNav(const double* values, NavState* x) {
  x->p_wb = Eigen::Map<const Vec3>(values + pose::kP);
  x->q_wb = Eigen::Map<const Quat>(values + pose::kQ).normalized();
}
void PoseFromNav(const NavState& x, double* values) { SetPose(x.p_wb, x.q_wb, values); }
void VelocityToNav(const double* values, NavState* x) { x->v_w = Eigen::Map<const Vec3>(values); }
void VelocityFromNav(const NavState& x, double* values) {
  Eigen::Map<Vec3> v_w(values);
  v_w = x.v_w;
}
void BiasToNav(const double* values, NavState* x) {
  x->bg = Eigen::Map<const Vec3>(values);
  x->ba = Eigen::Map<const Vec3>(values + 3);
}
void BiasFromNav(const NavState& x, double* values) {
  Eigen::Map<Vec3> bg(values), ba(values + 3);
  bg = x.bg;
  ba = x.ba;
}
double ScalePriorSigma(const SensorOptions& options) { return options.wheel.scale_sigma; }
ceres::CostFunction* BiasRandomWalk(const SensorOptions& options, double dt) {
  return BiasRwFactor::Create(options.imu.gyro_bias_rw, options.imu.acc_bias_rw, dt);
}
ceres::CostFunction* ScaleRandomWalk(const SensorOptions& options, double dt) {
  return ScaleRwFactor::Create(options.wheel.scale_rw, dt);
}
double ScaleRandomWalkSigma(const SensorOptions& options) { return options.wheel.scale_rw; }
bool TimeOffsetEstimated(const SensorOptions& options) { return options.gnss.estimate_time_offset; }
double TimeOffsetPriorSigma(const SensorOptions& options) { return options.gnss.time_offset_sigma; }
// A random walk of 0 (allowed: a constant offset) would make the factor's weight infinite; this floor keeps
// the offset constant to 0.1 ms over an hour.
double TimeOffsetRandomWalkSigma(const SensorOptions& options) {
  return std::max(options.gnss.time_offset_rw, kMinTimeOffsetRandomWalk);
}
ceres::CostFunction* TimeOffsetRandomWalk(const SensorOptions& options, double dt) {
  return ScaleRwFactor::Create(TimeOffsetRandomWalkSigma(options), dt);  // a scalar random walk, as the scale's
}

}  // namespace keyframe_blocks

namespace {

// The table is indexed by BlockType, and the blocks' tangents are what their kinds say.
constexpr bool TableIsConsistent() {
  for (int i = 0; i < kNumBlockTypes; ++i) {
    const BlockSpec& s = kBlockSpecs[i];
    if (static_cast<int>(s.type) != i) return false;
    const int tangent = s.kind == BlockKind::kPose ? pose::kTangent : s.ambient_size;
    if (s.tangent_size != tangent) return false;
    int covered = 0;
    for (int r = 0; r < s.num_runs; ++r) covered += s.runs[r].size;
    if (s.num_runs > 0 && covered != s.tangent_size) return false;
    if ((s.to_nav == nullptr) != (s.num_runs == 0) || (s.from_nav == nullptr) != (s.num_runs == 0)) return false;
    if (s.num_runs == 0 && s.prior_sigma == nullptr) return false;
    // Outside NavState, a random walk states its σ (the predicted covariance's process noise).
    if (s.num_runs == 0 && (s.random_walk == nullptr) != (s.random_walk_sigma == nullptr)) return false;
  }
  return true;
}
static_assert(TableIsConsistent(), "kBlockSpecs: rows out of enum order or inconsistent sizes");

}  // namespace

std::vector<int> NavIndexOfTangent(const std::vector<BlockType>& types) {
  std::vector<int> index;
  for (BlockType type : types) {
    const BlockSpec& spec = SpecOf(type);
    const size_t start = index.size();
    index.resize(start + spec.tangent_size, -1);
    for (int r = 0; r < spec.num_runs; ++r) {
      const NavRun& run = spec.runs[r];
      for (int k = 0; k < run.size; ++k) index[start + run.tangent_offset + k] = run.nav_offset + k;
    }
  }
  return index;
}

void Keyframe::FreezeFirstEstimates() {
  std::copy(values, values + kKeyframeAmbientSize, first_estimates);
  fej = true;
}

NavState Keyframe::State() const {
  NavState x;
  x.t = t;
  for (const BlockSpec& spec : kBlockSpecs) {
    if (spec.to_nav != nullptr) spec.to_nav(block(spec.type), &x);
  }
  return x;
}

void Keyframe::SetState(const NavState& x) {
  for (const BlockSpec& spec : kBlockSpecs) {
    if (spec.from_nav != nullptr) spec.from_nav(x, block(spec.type));
  }
}

std::shared_ptr<Preintegration> ReintegratedIfMoved(const Keyframe& prev, const Preintegration& pre,
                                                    double threshold) {
  const double* bias = prev.block(BlockType::kBias);
  const Vec3 bg = Eigen::Map<const Vec3>(bias), ba = Eigen::Map<const Vec3>(bias + 3);
  // Only the gyro bias counts: Δv and Δp are linear in the accelerometer bias, whose first-order correction
  // is therefore exact (tests/core/preintegration_test.cc).
  if (!((bg - pre.bg_lin()).norm() > threshold)) return nullptr;
  auto fresh = std::make_shared<Preintegration>(pre);
  fresh->Reintegrate(bg, ba);
  return fresh;
}

ceres::Solver::Options ChainSolverOptions(std::shared_ptr<ceres::ParameterBlockOrdering> ordering, int max_iterations,
                                          double function_tolerance, int num_threads) {
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  if (!ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)) {
    so.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  }
  so.linear_solver_ordering = std::move(ordering);
  so.max_num_iterations = max_iterations;
  so.function_tolerance = function_tolerance;
  so.num_threads = num_threads;
  so.logging_type = ceres::SILENT;
  // Start close to Gauss-Newton. Ceres's default radius (1e4) damps every step by 1e-4 of the Jacobi-scaled
  // diagonal, but a navigation-grade IMU factor's information (~1e13) dwarfs what the least-determined
  // directions carry (yaw and the biases: ~1e3 from the fixes), so their scaled curvature is ~1e-10: the
  // damping held those directions still for a dozen iterations, and the window left its fixes behind. Far
  // above that ratio for any IMU grade; a step that does not pay shrinks the radius as usual.
  so.initial_trust_region_radius = 1e12;
  return so;
}

KeyframeStore::KeyframeStore(const SensorOptions& options) : options_(options) {
  for (const BlockSpec& spec : kBlockSpecs) {
    estimated_[static_cast<int>(spec.type)] = spec.estimated == nullptr || spec.estimated(options);
  }
}

void KeyframeStore::Reset(ceres::Problem* problem) {
  Clear();
  problem_ = problem;
}

void KeyframeStore::Clear() {
  if (log_ != nullptr) {
    for (auto& kf : window_) log_->Keep(std::move(kf));
  }
  window_.clear();
}

std::unique_ptr<Keyframe> KeyframeStore::Make(double t, const NavState& x) const {
  auto kf = std::make_unique<Keyframe>();
  kf->id = next_id_;
  kf->t = t;
  kf->SetState(x);
  for (const BlockSpec& spec : kBlockSpecs) {
    if (spec.from_nav != nullptr) continue;
    double* b = kf->block(spec.type);
    if (window_.empty() && have_kept_) {
      const double* kept = kept_ + AmbientOffset(spec.type);
      std::copy(kept, kept + spec.ambient_size, b);
    } else if (window_.empty()) {
      std::fill(b, b + spec.ambient_size, spec.initial_value);
    } else {
      const double* prev = back().block(spec.type);
      std::copy(prev, prev + spec.ambient_size, b);
    }
  }
  return kf;
}

void KeyframeStore::KeepValues(const Keyframe& kf) {
  for (const BlockSpec& spec : kBlockSpecs) {
    if (spec.from_nav != nullptr) continue;
    const double* b = kf.block(spec.type);
    std::copy(b, b + spec.ambient_size, kept_ + AmbientOffset(spec.type));
  }
  have_kept_ = true;
}

ceres::Manifold* KeyframeStore::ManifoldOf(const BlockSpec& spec) {
  return spec.kind == BlockKind::kPose ? &pose_manifold_ : nullptr;
}

Keyframe& KeyframeStore::Push(std::unique_ptr<Keyframe> kf) {
  CHECK(problem_ != nullptr) << "KeyframeStore::Push before Reset";
  CHECK_EQ(kf->id, next_id_) << "a keyframe from Make, pushed once";
  ++next_id_;
  for (const BlockSpec& spec : kBlockSpecs) {
    ceres::Manifold* manifold = ManifoldOf(spec);
    if (manifold != nullptr) {
      problem_->AddParameterBlock(kf->block(spec.type), spec.ambient_size, manifold);
    } else {
      problem_->AddParameterBlock(kf->block(spec.type), spec.ambient_size);
    }
  }
  for (const BlockSpec& spec : kBlockSpecs) {
    if (!estimated(spec.type)) problem_->SetParameterBlockConstant(kf->block(spec.type));
  }
  window_.push_back(std::move(kf));
  return *window_.back();
}

void KeyframeStore::PopOldest() {
  CHECK(!window_.empty());
  for (double* b : Blocks(front())) CHECK(!problem_->HasParameterBlock(b)) << "PopOldest: blocks still in the problem";
  if (log_ != nullptr) log_->Keep(std::move(window_.front()));
  window_.pop_front();
}

std::vector<double*> KeyframeStore::Blocks(Keyframe& kf) const {
  std::vector<double*> blocks;
  for (const BlockSpec& spec : kBlockSpecs) blocks.push_back(kf.block(spec.type));
  return blocks;
}

std::vector<double*> KeyframeStore::EstimatedBlocks(Keyframe& kf) const {
  std::vector<double*> blocks;
  for (const BlockSpec& spec : kBlockSpecs) {
    if (estimated(spec.type)) blocks.push_back(kf.block(spec.type));
  }
  return blocks;
}

std::vector<double*> KeyframeStore::EstimatedBlocks() {
  std::vector<double*> blocks;
  for (auto& kf : window_) {
    for (double* b : EstimatedBlocks(*kf)) blocks.push_back(b);
  }
  return blocks;
}

std::vector<BlockType> KeyframeStore::EstimatedTypes() const {
  std::vector<BlockType> types;
  for (const BlockSpec& spec : kBlockSpecs) {
    if (estimated(spec.type)) types.push_back(spec.type);
  }
  return types;
}

ceres::ResidualBlockId KeyframeStore::AddFactor(ceres::CostFunction* cost, ceres::LossFunction* loss,
                                                const std::vector<BlockRef>& blocks) {
  std::vector<FejCost::Block> fej;
  for (const BlockRef& ref : blocks) {
    fej.push_back({ref.kf->first_estimate(ref.type), &ref.kf->fej, SpecOf(ref.type).kind == BlockKind::kPose});
  }
  std::shared_ptr<ceres::CostFunction> shared(cost);
  return AddLogged(shared, new FejCost(shared, std::move(fej)), loss, blocks);
}

ceres::ResidualBlockId KeyframeStore::AddMeasurement(ceres::CostFunction* cost, ceres::LossFunction* loss,
                                                     const std::vector<BlockRef>& blocks, double gate) {
  const ceres::ResidualBlockId id = AddFactor(cost, loss, blocks);
  if (log_ != nullptr) log_->SetGate(last_logged_, gate);
  return id;
}

void KeyframeStore::LogRejected(ceres::CostFunction* cost, ceres::LossFunction* loss,
                                const std::vector<BlockRef>& blocks, double gate) {
  std::shared_ptr<ceres::CostFunction> owned(cost);
  if (log_ == nullptr) return;
  LoggedFactor f{std::move(owned), loss, blocks, false};
  f.gate = gate;
  log_->Add(std::move(f));
}

ceres::ResidualBlockId KeyframeStore::AddLogged(std::shared_ptr<ceres::CostFunction> cost,
                                                ceres::CostFunction* in_problem, ceres::LossFunction* loss,
                                                const std::vector<BlockRef>& blocks) {
  std::vector<double*> params;
  for (const BlockRef& ref : blocks) params.push_back(ref.kf->block(ref.type));
  if (log_ != nullptr) last_logged_ = log_->Add({std::move(cost), loss, blocks, true});
  return problem_->AddResidualBlock(in_problem, loss, params);
}

MatX KeyframeStore::PriorCovariance(const Mat15& P0) const {
  const std::vector<BlockType> types = EstimatedTypes();
  const std::vector<int> nav = NavIndexOfTangent(types);
  const int n = static_cast<int>(nav.size());
  MatX P = MatX::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (nav[i] >= 0 && nav[j] >= 0) P(i, j) = P0(nav[i], nav[j]);
    }
  }
  int column = 0;
  for (BlockType type : types) {
    const BlockSpec& spec = SpecOf(type);
    if (spec.num_runs == 0) {
      const double sigma = spec.prior_sigma(options_);
      P.diagonal().segment(column, spec.tangent_size).setConstant(sigma * sigma);
    }
    column += spec.tangent_size;
  }
  return P;
}

ceres::ResidualBlockId KeyframeStore::AddPrior(Keyframe& kf, const Mat15& P0) {
  const std::vector<BlockType> types = EstimatedTypes();
  const MatX P = PriorCovariance(P0);
  const int n = static_cast<int>(P.rows());
  const MatX info = P.inverse();
  const Eigen::LLT<MatX> llt(0.5 * (info + info.transpose()));
  const MatX J = llt.matrixU();  // JᵀJ = info
  std::vector<PriorBlock> blocks;
  for (BlockType type : types) {
    const BlockSpec& spec = SpecOf(type);
    PriorBlock b;
    b.kind = spec.kind;
    b.ambient_size = spec.ambient_size;
    b.tangent_size = TangentSizeOf(spec.kind, spec.ambient_size);
    b.x0.assign(kf.block(type), kf.block(type) + spec.ambient_size);
    blocks.push_back(std::move(b));
  }
  // The problem owns what it is given; the log keeps its own copy of the prior.
  std::vector<BlockRef> refs;
  for (BlockType type : types) refs.push_back({&kf, type});
  auto logged = std::make_shared<MarginalizationPrior>(blocks, J, VecX::Zero(n));
  return AddLogged(std::move(logged), new MarginalizationPrior(std::move(blocks), J, VecX::Zero(n)), nullptr, refs);
}

void KeyframeStore::AddRandomWalks(Keyframe& prev, Keyframe& kf) {
  const double dt = kf.t - prev.t;
  for (const BlockSpec& spec : kBlockSpecs) {
    if (spec.random_walk == nullptr || !estimated(spec.type)) continue;
    AddFactor(spec.random_walk(options_, dt), nullptr, {{&prev, spec.type}, {&kf, spec.type}});
  }
}

}  // namespace gins
