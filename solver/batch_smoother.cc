#include "solver/batch_smoother.h"

#include <ceres/solver.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdint>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "factors/imu_factor.h"
#include "factors/pose_manifold.h"
#include "solver/imu_bridge.h"
#include "solver/marginalizer.h"
#include "solver/smoother_output.h"

namespace gins {
namespace {

double Seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

nlohmann::json BatchStats::ToJson() const {
  return {{"keyframes", keyframes},           {"factors", factors},
          {"iterations", iterations},         {"converged", converged},
          {"solution_usable", usable},        {"initial_cost", initial_cost},
          {"final_cost", final_cost},         {"solve_time_s", solve_time_s},
          {"covariance_time_s", covariance_time_s}, {"band_keyframes", band_keyframes},
          {"covariance_ok", covariance_ok}, {"solves", solves}, {"reintegrations", reintegrations},
          {"keyframes_dropped", keyframes_dropped}, {"segments", segments},
          {"marginalization_failures", marginalization_failures}, {"revisit_dropped", revisit_dropped},
          {"revisit_restored", revisit_restored}};
}

BatchSmoother::BatchSmoother(const SensorOptions& sensors, const BatchOptions& batch, const SmootherOptions& smoother,
                             std::vector<BlockType> estimated_types)
    : sensors_(sensors), batch_(batch), smoother_(smoother), types_(std::move(estimated_types)) {
  for (BlockType t : types_) estimated_[static_cast<int>(t)] = true;
}

namespace {

// A problem over the log's keyframes and factors: it owns none of them (the costs are the log's and the
// priors', the losses the attachers').
ceres::Problem::Options BorrowingProblemOptions() {
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return po;
}

std::vector<double*> ParamsOf(const std::vector<BlockRef>& refs) {
  std::vector<double*> params;
  params.reserve(refs.size());
  for (const BlockRef& ref : refs) params.push_back(ref.kf->block(ref.type));
  return params;
}

// Adds a logged factor to a problem that borrows it.
void AddBorrowed(ceres::Problem* problem, const LoggedFactor& f) {
  problem->AddResidualBlock(f.cost.get(), const_cast<ceres::LossFunction*>(f.loss), ParamsOf(f.blocks));
}

// A cost the log (or a segment's prior) keeps, lent to a problem that owns what it is given.
class SharedCost final : public ceres::CostFunction {
 public:
  explicit SharedCost(std::shared_ptr<ceres::CostFunction> cost) : cost_(std::move(cost)) {
    set_num_residuals(cost_->num_residuals());
    *mutable_parameter_block_sizes() = cost_->parameter_block_sizes();
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    return cost_->Evaluate(parameters, residuals, jacobians);
  }

 private:
  std::shared_ptr<ceres::CostFunction> cost_;
};

}  // namespace

void BatchSmoother::AddKeyframeBlocks(ceres::Problem* problem, Keyframe* kf, ceres::ParameterBlockOrdering* ordering,
                                      int* group) {
  for (const BlockSpec& spec : kBlockSpecs) {
    double* b = kf->block(spec.type);
    if (problem->HasParameterBlock(b)) continue;
    if (spec.kind == BlockKind::kPose) {
      problem->AddParameterBlock(b, spec.ambient_size, &pose_manifold_);
    } else {
      problem->AddParameterBlock(b, spec.ambient_size);
    }
    if (!estimated_[static_cast<int>(spec.type)]) {
      problem->SetParameterBlockConstant(b);
    } else if (ordering != nullptr) {
      ordering->AddElementToGroup(b, (*group)++);  // time order: no fill-in along the chain
    }
  }
}

void BatchSmoother::Solve(FactorLog* log, const EarthModel& earth) {
  const auto t0 = std::chrono::steady_clock::now();
  kfs_.clear();
  std::map<const Keyframe*, int> index;
  for (const auto& kf : log->keyframes()) {
    if (std::all_of(kf->values, kf->values + kKeyframeAmbientSize, [](double v) { return std::isfinite(v); })) {
      index[kf.get()] = static_cast<int>(kfs_.size());
      kfs_.push_back(kf.get());
    } else {
      ++stats_.keyframes_dropped;
    }
  }
  const int n = static_cast<int>(kfs_.size());
  stats_.keyframes = n;
  if (n == 0) return;
  // The factors on usable keyframes, with the span of keyframes each touches.
  factors_.clear();
  int w = 1;
  for (size_t i = 0; i < log->factors().size(); ++i) {
    const LoggedFactor& f = log->factors()[i];
    if (!f.active && !f.revisitable()) continue;
    FactorSpan span{i, n, -1};
    bool usable = true;
    for (const BlockRef& ref : f.blocks) {
      const auto it = index.find(ref.kf);
      if (it == index.end()) {
        usable = false;
        break;
      }
      span.lo = std::min(span.lo, it->second);
      span.hi = std::max(span.hi, it->second);
    }
    if (!usable) continue;
    w = std::max(w, span.hi - span.lo);
    factors_.push_back(span);
  }
  stats_.band_keyframes = w;
  // Each keyframe's IMU factor from the keyframe before it (to re-integrate at the batch's biases).
  imu_factor_.assign(n, SIZE_MAX);
  for (int k = 1; k < n; ++k) {
    const Keyframe& kf = *kfs_[k];
    if (kf.preint == nullptr || kf.imu_log_index >= log->factors().size()) continue;
    const LoggedFactor& f = log->factors()[kf.imu_log_index];
    if (f.active && f.blocks.size() == 5 && f.blocks.front().kf == kfs_[k - 1] && f.blocks.back().kf == &kf) {
      imu_factor_[k] = kf.imu_log_index;
    }
  }
  covariances_.assign(n, Mat15::Zero());
  have_cov_.assign(n, false);

  // Segments of at most L keyframes overlapping by O; each keeps its estimates up to a seam in the middle
  // half of the overlap, and hands the next one a prior: everything before the seam, marginalised at its
  // solution. The seam goes where this segment knows the position best (smallest marginal position σ): a
  // keyframe amid GNSS fixes, whose estimate the data beyond the segment would not move, never one inside
  // an outage.
  const int L = std::max(batch_.max_segment_keyframes, 4 * w + 4);
  const int O = std::clamp(batch_.segment_overlap_keyframes, 2 * w + 2, L / 2);
  struct Segment {
    int first, seam;
    Prior prior;
  };
  std::vector<Segment> segments;
  Prior prior;
  for (int first = 0;;) {
    const int last = n - first <= L ? n : first + L;
    const int seam = SolveSegment(log, earth, first, last, last == n ? n : last - (3 * O) / 4, last - O / 4, prior);
    ++stats_.segments;
    if (last == n) break;
    segments.push_back({first, seam, prior});
    prior = MarginalPrior(*log, first, seam, prior);
    first = seam;
  }
  // Backward: the last segment's solution has all the data (the past through its prior); each earlier one is
  // solved again with the keyframes from its seam on held at the later solution. In a chain the state beyond
  // the seam carries everything the later data say about the earlier states, so this is the two-sided
  // solution, as an RTS pass is for a filter: the seams do not show.
  for (auto it = segments.rbegin(); it != segments.rend(); ++it) SolveBeforeSeam(*log, it->first, it->seam, it->prior);
  stats_.covariance_ok = std::all_of(have_cov_.begin(), have_cov_.end(), [](bool b) { return b; });
  stats_.solve_time_s = Seconds(std::chrono::steady_clock::now() - t0) - stats_.covariance_time_s;
}

int BatchSmoother::SolveSegment(FactorLog* log, const EarthModel& earth, int first, int last, int seam_from,
                                int seam_to, const Prior& prior) {
  const auto inside = [&](const FactorSpan& f) {
    return f.lo >= first && f.hi < last && log->factors()[f.log_index].active;
  };
  bool revisited = false;
  for (int round = 0;; ++round) {
    ceres::Problem problem(BorrowingProblemOptions());
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    int group = 0;
    for (int k = first; k < last; ++k) AddKeyframeBlocks(&problem, kfs_[k], ordering.get(), &group);
    for (const FactorSpan& f : factors_) {
      if (!inside(f)) continue;
      AddBorrowed(&problem, log->factors()[f.log_index]);
    }
    if (prior.cost) problem.AddResidualBlock(prior.cost.get(), nullptr, prior.Params());

    const ceres::Solver::Options so = ChainSolverOptions(ordering, batch_.max_iterations,
                                                         batch_.function_tolerance, smoother_.num_threads);
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    stats_.iterations += static_cast<int>(summary.iterations.size());
    stats_.converged = (first == 0 || stats_.converged) && summary.termination_type == ceres::CONVERGENCE;
    stats_.usable = (first == 0 || stats_.usable) && summary.IsSolutionUsable();
    if (round == 0) stats_.initial_cost += summary.initial_cost;
    ++stats_.solves;

    // The IMU factors are linear in the bias about where they were integrated; where the solution moved
    // the bias further than the window allows, integrate again there and solve once more.
    int reintegrated = 0;
    if (round < batch_.max_relinearizations && summary.IsSolutionUsable()) {
      for (int k = first + 1; k < last; ++k) {
        if (imu_factor_[k] == SIZE_MAX) continue;
        Keyframe& kf = *kfs_[k];
        auto fresh = ReintegratedIfMoved(*kfs_[k - 1], *kf.preint, smoother_.bias_reintegrate_threshold);
        if (!fresh) continue;
        ImuEarthTerms terms;
        terms.g_w = earth.Gravity(0.5 * (kfs_[k - 1]->State().p_wb + kf.State().p_wb));
        terms.rate_w = earth.rate_w();
        log->Replace(imu_factor_[k], std::shared_ptr<ceres::CostFunction>(ImuFactor::Create(fresh, terms)));
        kf.preint = fresh;  // the keyframe left the window: nothing else reads it
        ++reintegrated;
      }
    }
    stats_.reintegrations += reintegrated;
    if (reintegrated == 0) {
      const auto t1 = std::chrono::steady_clock::now();
      std::vector<FactorSpan> spans;
      for (const FactorSpan& f : factors_) {
        if (inside(f)) spans.push_back(f);
      }
      if (prior.cost) spans.push_back({SIZE_MAX, prior.lo, prior.hi});
      std::vector<MatX> cov;  // block order
      const bool ok = RecoverCovariances(&problem, spans, first, last, &cov);
      std::vector<Mat15> nav_cov;
      for (const MatX& c : cov) nav_cov.push_back(NavCovariance(types_, c));
      stats_.covariance_time_s += Seconds(std::chrono::steady_clock::now() - t1);
      // The window decided on each fix from one side; check them all again on the two-sided solution and
      // its covariance, and solve once more if a decision changed.
      if (ok && !revisited && batch_.revisit_fixes && Revisit(log, first, last, cov)) {
        revisited = true;
        continue;
      }
      revisited = true;
      stats_.final_cost += summary.final_cost;  // summed over the segments (their overlaps counted twice)
      stats_.factors += static_cast<int>(spans.size());
      int seam = last;
      if (seam_from < last) {
        // Among the keyframes whose position variance is within 25 % of the best, the one nearest the middle
        // of the overlap (the most data on both sides).
        const auto var = [&](int k) { return nav_cov[k - first].block<3, 3>(nav::kP, nav::kP).trace(); };
        const int middle = (seam_from + seam_to) / 2;
        seam = middle;
        if (ok) {
          double best = var(seam_from);
          for (int k = seam_from; k <= seam_to; ++k) best = std::min(best, var(k));
          for (int k = seam_from; k <= seam_to; ++k) {
            if (var(k) <= 1.25 * best && (std::abs(k - middle) < std::abs(seam - middle) || var(seam) > 1.25 * best)) {
              seam = k;
            }
          }
        }
      }
      for (int k = first; ok && k < seam; ++k) {
        covariances_[k] = nav_cov[k - first];
        have_cov_[k] = true;
        if (k + 1 == static_cast<int>(kfs_.size())) last_block_cov_ = cov[k - first];
      }
      return seam;
    }
  }
}

void BatchSmoother::SolveBeforeSeam(const FactorLog& log, int first, int seam, const Prior& prior) {
  const int w = stats_.band_keyframes;
  const int end = std::min<int>(kfs_.size(), seam + w);
  ceres::Problem problem(BorrowingProblemOptions());
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  int group = 0;
  for (int k = first; k < end; ++k) AddKeyframeBlocks(&problem, kfs_[k], ordering.get(), &group);
  for (int k = seam; k < end; ++k) {
    for (const BlockSpec& spec : kBlockSpecs) {
      double* b = kfs_[k]->block(spec.type);
      problem.SetParameterBlockConstant(b);
      if (ordering->IsMember(b)) ordering->Remove(b);
    }
  }
  for (const FactorSpan& f : factors_) {
    if (f.lo < first || f.lo >= seam || f.hi >= end) continue;
    const LoggedFactor& lf = log.factors()[f.log_index];
    if (!lf.active) continue;
    AddBorrowed(&problem, lf);
  }
  if (prior.cost) problem.AddResidualBlock(prior.cost.get(), nullptr, prior.Params());
  const ceres::Solver::Options so = ChainSolverOptions(ordering, batch_.max_iterations,
                                                       batch_.function_tolerance, smoother_.num_threads);
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  stats_.iterations += static_cast<int>(summary.iterations.size());
  stats_.usable = stats_.usable && summary.IsSolutionUsable();
  ++stats_.solves;
}

std::vector<double*> BatchSmoother::Prior::Params() const { return ParamsOf(blocks); }

BatchSmoother::Prior BatchSmoother::MarginalPrior(const FactorLog& log, int first, int seam, const Prior& previous) {
  // The window's marginalisation, keyframe after keyframe from `first` up to the seam, at this segment's
  // solution: each step holds only the running prior and the factors on the next few keyframes.
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;  // SharedCost wrappers and the Marginalizer's priors
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.enable_fast_removal = true;
  ceres::Problem problem(po);
  std::map<const double*, BlockRef> ref_of;
  const auto add_blocks = [&](const std::vector<BlockRef>& refs) {
    for (const BlockRef& r : refs) {
      AddKeyframeBlocks(&problem, r.kf, nullptr, nullptr);
      ref_of[r.kf->block(r.type)] = r;
    }
  };
  if (previous.cost) {
    add_blocks(previous.blocks);
    problem.AddResidualBlock(new SharedCost(previous.cost), nullptr, previous.Params());
  }
  // The factors by their first keyframe.
  std::vector<const FactorSpan*> by_lo;
  for (const FactorSpan& f : factors_) {
    if (f.lo >= first && f.lo < seam && log.factors()[f.log_index].active) by_lo.push_back(&f);
  }
  std::stable_sort(by_lo.begin(), by_lo.end(), [](const FactorSpan* a, const FactorSpan* b) { return a->lo < b->lo; });
  size_t next = 0;
  const MarginalizationPrior* last_prior = nullptr;
  std::unique_ptr<Marginalizer> marg;
  for (int k = first; k < seam; ++k) {
    for (; next < by_lo.size() && by_lo[next]->lo == k; ++next) {
      const LoggedFactor& lf = log.factors()[by_lo[next]->log_index];
      add_blocks(lf.blocks);
      problem.AddResidualBlock(new SharedCost(lf.cost), const_cast<ceres::LossFunction*>(lf.loss), ParamsOf(lf.blocks));
    }
    AddKeyframeBlocks(&problem, kfs_[k], nullptr, nullptr);
    std::vector<double*> blocks;
    for (const BlockSpec& spec : kBlockSpecs) blocks.push_back(kfs_[k]->block(spec.type));
    marg = std::make_unique<Marginalizer>(&problem, blocks);
    last_prior = marg->prior();
    if (!marg->ok()) ++stats_.marginalization_failures;
    marg->Apply();
  }
  Prior prior;
  if (last_prior == nullptr || !marg->ok()) return prior;
  // The prior Apply left in the problem is the last one: copy it out with its blocks.
  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  if (ids.size() != 1) {
    LOG(WARNING) << "batch: " << ids.size() << " residuals left at a segment's seam; no prior";
    return prior;
  }
  const auto* p = dynamic_cast<const MarginalizationPrior*>(problem.GetCostFunctionForResidualBlock(ids[0]));
  if (p == nullptr) return prior;
  std::vector<double*> params;
  problem.GetParameterBlocksForResidualBlock(ids[0], &params);
  prior.cost = std::make_shared<MarginalizationPrior>(p->blocks(), p->J(), p->r0());
  prior.lo = static_cast<int>(kfs_.size());
  prior.hi = -1;
  std::map<const Keyframe*, int> index;
  for (int k = seam; k < std::min<int>(kfs_.size(), seam + 64); ++k) index[kfs_[k]] = k;
  for (double* b : params) {
    const BlockRef r = ref_of.at(b);
    prior.blocks.push_back(r);
    prior.lo = std::min(prior.lo, index.at(r.kf));
    prior.hi = std::max(prior.hi, index.at(r.kf));
  }
  return prior;
}

void BatchSmoother::Emit(const FactorLog& log, const EarthModel& earth, const StateCallback& out) const {
  const BridgeNoise noise{sensors_.imu.gyro_noise_density, sensors_.imu.acc_noise_density};
  static const std::vector<HeldImuSample> kNone;
  for (size_t k = 0; k < kfs_.size(); ++k) {
    const Keyframe& kf = *kfs_[k];
    const StateEstimate a = EstimateOf(kf, have_cov_[k] ? &covariances_[k] : nullptr);
    ImuEarthTerms terms;
    terms.g_w = earth.Gravity(a.x.p_wb);
    terms.rate_w = earth.rate_w();
    const std::vector<HeldImuSample>* tail = log.TailOf(&kf);
    const Keyframe* next = k + 1 < kfs_.size() ? kfs_[k + 1] : nullptr;
    // The next keyframe continues the chain when its IMU steps start here.
    if (tail == nullptr && next != nullptr) {
      double span = 0.0;
      for (const HeldImuSample& step : next->steps_from_prev) span += step.dt;
      if (next->steps_from_prev.empty() || std::abs(kf.t + span - next->t) > 1e-6) next = nullptr;
    }
    if (next == nullptr) {
      // The end of a chain (the window was rebuilt after it, or the log ends): propagated from it alone.
      EmitBridge(a, nullptr, tail != nullptr ? *tail : kNone, terms, noise, false, out);
      continue;
    }
    const StateEstimate b = EstimateOf(*next, have_cov_[k + 1] ? &covariances_[k + 1] : nullptr);
    EmitBridge(a, &b, next->steps_from_prev, terms, noise, next->still_from_prev, out);
  }
}

}  // namespace gins
