#include "solver/smoother.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/imu_kernel.h"
#include "core/so3.h"
#include "factors/imu_factor.h"
#include "solver/batch_smoother.h"
#include "solver/marginalizer.h"
#include "solver/raw_gnss_attacher.h"
#include "solver/smoother_gate.h"
#include "solver/smoother_output.h"
#include "solver/summary_keys.h"
#include "solver/vehicle_attacher.h"

namespace gins {
namespace {

double Seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

Smoother::Smoother(const SensorOptions& sensors, const EskfOptions& eskf, const SmootherOptions& smoother,
                   const BatchOptions& batch, const StandstillOptions& standstill, const WatchdogOptions& watchdog,
                   StateCallback on_final, StateCallback on_online, StateCallback on_batch)
    : sensors_(sensors),
      eskf_options_(eskf),
      smoother_options_(smoother),
      batch_options_(batch),
      standstill_options_(standstill),
      watchdog_options_(watchdog),
      on_final_(std::move(on_final)),
      on_online_(std::move(on_online)),
      on_batch_(std::move(on_batch)),
      factor_log_(on_batch_ ? std::make_unique<FactorLog>() : nullptr),
      window_(sensors),
      context_{window_,
               earth_,
               last_imu_,
               [this](double t) { return PredictAt(t); },
               [this](double t) { return AnchorAt(t); },
               [this]() -> const MatX* { return newest_two_cov_.size() > 0 ? &newest_two_cov_ : nullptr; },
               [this](double t) { return PartialAt(t); },
               [this](double t) { return PredictStateAt(t); },
               [this](double t) { return AnchorAt(t, /*keyframe=*/true); }},
      watchdog_(watchdog) {
  window_.SetLog(factor_log_.get());
  attachers_.push_back(std::make_unique<VehicleAttacher>(sensors_));
  attachers_.push_back(
      std::make_unique<StandstillAttacher>(standstill_options_, sensors_.imu, sensors_.wheel.gate_probability));
  attachers_.push_back(std::make_unique<GnssVelocityAttacher>(sensors_.gnss));
  attachers_.push_back(std::make_unique<GnssAttacher>(
      sensors_.gnss, [this](double t, bool accepted) { WatchGnss(t, accepted); },
      [this](double factor) { RelievePrior(factor); }));
  attachers_.push_back(std::make_unique<RawGnssAttacher>(
      sensors_.gnss, [this](double t, bool accepted) { WatchGnss(t, accepted); }));
  AddModuleAttachers(sensors_, &attachers_);
  pre_init_.SetBackwardFiller([this](const BackwardSpan& span) {
    return FillBackward(sensors_, eskf_options_, standstill_options_, span);
  });
}

Smoother::~Smoother() = default;

NavState Smoother::NewestState() const { return window_.back().State(); }

void Smoother::AddRestState(const StateEstimate& s) { pre_init_.Add(s, on_final_, on_online_); }

void Smoother::Initialize(const InitResult& init) {
  pre_init_.Start(init, on_final_);  // the online stream is for the newest state: not the late window
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.enable_fast_removal = true;
  problem_ = std::make_unique<ceres::Problem>(po);
  window_.Reset(problem_.get());
  earth_ = init.earth;
  g_w_ = earth_.Gravity(init.x0.p_wb);

  std::unique_ptr<Keyframe> first = window_.Make(init.x0.t, init.x0);
  // The initial covariance as a prior on the first keyframe.
  Keyframe& kf0 = window_.Push(std::move(first));
  prior_id_ = window_.AddPrior(kf0, init.P0);
  // Until the first solve, what the window knows of its keyframe is that prior.
  newest_cov_id_ = kf0.id;
  newest_two_cov_.resize(0, 0);
  newest_cov_ = window_.PriorCovariance(init.P0);
  solve_pending_ = false;

  preint_ = std::make_shared<Preintegration>(init.x0.bg, init.x0.ba, sensors_.imu.gyro_noise_density,
                                             sensors_.imu.acc_noise_density);
  interval_samples_.clear();
  last_imu_.reset();
  last_sample_t_ = init.x0.t;
  t_now_ = init.x0.t;
  pred_ = init.x0;
  initialized_ = true;
  ++keyframes_;
  if (on_online_) on_online_(EstimateOf(window_.back(), nullptr));
}

void Smoother::IntegrateTo(double t, const ImuSample* held) {
  const double dt = t - t_now_;
  if (dt <= 0.0) return;
  if (held == nullptr && last_imu_) held = &*last_imu_;
  ImuStepView step;
  step.dt = dt;
  step.dR_begin = preint_->delta().dq;
  step.v_b_begin = pred_.q_wb.conjugate() * pred_.v_w;
  ImuSample coast;
  // Across an IMU gap (judged from the newest sample, whatever t_now_ is), and over a step no sample covers
  // (a fix after the initialisation, before the first sample): no rotation and no acceleration, from the
  // current estimate, with the uncertainty of an unknown rate and acceleration held over the gap. So the
  // preintegration always reaches t, and no keyframe is made over an empty one.
  if (held == nullptr || t - last_sample_t_ > sensors_.imu.max_gap) {
    coast.t = t_now_;
    coast.gyro = pred_.bg + pred_.q_wb.conjugate() * earth_.rate_w();
    coast.acc = pred_.q_wb.conjugate() * (2.0 * earth_.rate_w().cross(pred_.v_w) - g_w_) + pred_.ba;
    held = &coast;
    // The unknown motion as random walks (kImuGapAccDensity): held over dt, σ = density/√dt.
    const double root_dt = std::sqrt(dt);
    const Vec3 rate_sigma = Vec3(kImuGapTiltDensity, kImuGapTiltDensity, kImuGapYawDensity) / root_dt;
    preint_->IntegrateGuess(coast.gyro, coast.acc, dt, rate_sigma, kImuGapAccDensity / root_dt);
  } else {
    preint_->Integrate(*held, dt);
  }
  interval_samples_.push_back({*held, dt});
  Kinematics k{pred_.q_wb, pred_.v_w, pred_.p_wb};
  k = ImuStep(k, held->gyro - pred_.bg, held->acc - pred_.ba, g_w_, dt, nullptr, earth_.rate_w());
  pred_.q_wb = k.q;
  pred_.v_w = k.v;
  pred_.p_wb = k.p;
  g_w_ = earth_.Gravity(pred_.p_wb);
  pred_.t = t;
  t_now_ = t;
  step.dR_end = preint_->delta().dq;
  step.v_b_end = pred_.q_wb.conjugate() * pred_.v_w;
  step.omega_b = held->gyro - pred_.bg;
  for (auto& attacher : attachers_) attacher->OnImuStep(step);
}

void Smoother::AddImu(const ImuSample& imu) {
  if (!initialized_ || imu.t < t_now_) return;
  // The measurements of the last epoch are all in: solve before the IMU moves on from it.
  SolveIfPending();
  // Before the first sample after the initialisation, its epoch is the newest sample (a dropout right after
  // it is a gap as any other).
  if (imu.t - last_sample_t_ > sensors_.imu.max_gap) imu_gaps_.Add(last_sample_t_, imu.t);
  const ImuSample mid = last_imu_ ? HeldBetween(*last_imu_, imu) : imu;
  IntegrateTo(imu.t, &mid);
  last_imu_ = imu;
  last_sample_t_ = imu.t;
  // Without GNSS a keyframe still comes every max_keyframe_interval, so no preintegration spans an outage.
  // The 10 % grace lets a fix due at that very epoch (often logged just after the IMU sample) make the
  // keyframe itself, instead of a second solve at the same time.
  if (t_now_ - window_.back().t >= 1.1 * smoother_options_.max_keyframe_interval) CreateKeyframe(t_now_);
}

void Smoother::SolveIfPending() {
  if (solve_pending_) SolveAndSlide();
}

Prediction Smoother::PredictAt(double t) {
  IntegrateTo(t);
  const std::vector<BlockType> types = window_.EstimatedTypes();
  Keyframe& newest = window_.back();
  Prediction p;
  // The newest keyframe's covariance: from the last solve, or predicted from the keyframe solved then.
  MatX cov = newest_cov_;
  if (newest.id != newest_cov_id_ && window_.size() >= 2 && newest.preint != nullptr) {
    const Keyframe& solved = window_[window_.size() - 2];
    cov = PredictBlockCovariance(types, newest_cov_, solved.State(), *newest.preint, sensors_);
  }
  if (BeyondNewest(t)) {
    p.x = pred_;
    p.cov = PredictBlockCovariance(types, cov, newest.State(), *preint_, sensors_);
  } else {
    p.x = newest.State();
    p.cov = cov;
  }
  return p;
}

NavState Smoother::PredictStateAt(double t) {
  IntegrateTo(t);
  return BeyondNewest(t) ? pred_ : window_.back().State();
}

bool Smoother::BeyondNewest(double t) const {
  return t - window_.back().t > kSameEpoch && preint_->dt() > 0.0;
}

Anchor Smoother::AnchorAt(double t, bool keyframe) {
  Keyframe& newest = window_.back();
  if (std::abs(t - newest.t) <= kSameEpoch) return {&newest, nullptr};
  IntegrateTo(t);
  if (keyframe || t - newest.t >= smoother_options_.min_keyframe_interval || preint_->dt() <= 0.0) {
    Keyframe& kf = CreateKeyframe(t);
    return {&kf, nullptr};
  }
  // A copy: the live preintegration goes on growing, a factor's must never change.
  return {&newest, std::make_shared<const Preintegration>(*preint_)};
}

Anchor Smoother::PartialAt(double t) {
  Keyframe& newest = window_.back();
  IntegrateTo(t);
  if (std::abs(t - newest.t) <= kSameEpoch || preint_->dt() <= 0.0) return {&newest, nullptr};
  return {&newest, std::make_shared<const Preintegration>(*preint_)};
}

void Smoother::UpdateNewestCovariance(MatX* oldest_cov) {
  const size_t n = window_.size();
  MatX trailing;
  // On failure, the last good ones stay (counted: an ill-conditioned window is never silent).
  if (!WindowCovariances(window_, n >= 2 ? 2 : 1, &trailing, n > 2 ? oldest_cov : nullptr)) {
    CountCovarianceFailure("the two newest keyframes' covariance");
    return;
  }
  const int per = static_cast<int>(trailing.rows()) / (n >= 2 ? 2 : 1);
  newest_cov_ = trailing.bottomRightCorner(per, per);
  newest_cov_id_ = window_.back().id;
  if (n >= 2) {
    newest_two_cov_ = trailing;
  } else {
    newest_two_cov_.resize(0, 0);
  }
}

void Smoother::CountCovarianceFailure(const char* what) {
  if (covariance_failures_++ == 0) {
    LOG(WARNING) << "smoother: " << what << " could not be recovered at t=" << std::fixed << window_.back().t
                 << " (information not positive definite); counted in covariance_failures";
  }
}

ceres::ResidualBlockId Smoother::AddImuFactor(Keyframe& prev, Keyframe& kf) {
  // Gravity held over the interval: the model's at its middle (a metre of error there is 1e-6 m/s²).
  ImuEarthTerms earth;
  earth.g_w = earth_.Gravity(0.5 * (prev.State().p_wb + kf.State().p_wb));
  earth.rate_w = earth_.rate_w();
  return window_.AddFactor(ImuFactor::Create(kf.preint, earth), nullptr,
                           {{&prev, BlockType::kPose},
                            {&prev, BlockType::kVelocity},
                            {&prev, BlockType::kBias},
                            {&kf, BlockType::kPose},
                            {&kf, BlockType::kVelocity}});
}

Keyframe& Smoother::CreateKeyframe(double t) {
  IntegrateTo(t);
  Keyframe& prev = window_.back();
  std::unique_ptr<Keyframe> made = window_.Make(t, pred_);
  made->preint = preint_;
  made->steps_from_prev = interval_samples_;
  Keyframe& kf = window_.Push(std::move(made));
  kf.imu_id = AddImuFactor(prev, kf);
  kf.imu_log_index = window_.last_logged();
  window_.AddRandomWalks(prev, kf);
  preint_ = std::make_shared<Preintegration>(pred_.bg, pred_.ba, sensors_.imu.gyro_noise_density,
                                             sensors_.imu.acc_noise_density);
  interval_samples_.clear();
  ++keyframes_;
  // Every new keyframe is solved before the IMU moves on: a window left unsolved would predict the next
  // measurement from a covariance keyframes old (a burst of rejected fixes made a keyframe per fix for
  // their headings, and none was solved until a fix was accepted).
  solve_pending_ = true;
  for (auto& attacher : attachers_) attacher->OnKeyframeCreated(kf, context_);
  return kf;
}

bool Smoother::Attach(const Measurement& m) {
  bool solve = false;
  for (auto& attacher : attachers_) solve = attacher->OnMeasurement(m, context_) || solve;
  return solve;
}

void Smoother::Use(const StandstillMeasurement& x, const Measurement& m) {
  if (!initialized_ || x.t < window_.back().t) return;
  if (x.t > window_.back().t + kSameEpoch) SolveIfPending();
  Attach(m);
}

void Smoother::Use(const GnssVelocityMeasurement& x, const Measurement& m) {
  if (!initialized_ || x.t < t_now_ - kSameEpoch || x.t < window_.back().t - kSameEpoch) return;
  if (x.t > window_.back().t + kSameEpoch) SolveIfPending();
  if (Attach(m)) solve_pending_ = true;
}

void Smoother::Use(const RawGnssMeasurement& x, const Measurement& m) {
  if (!initialized_ || !x.nav || x.t < t_now_ - kSameEpoch || x.t < window_.back().t - kSameEpoch) return;
  if (x.t > window_.back().t + kSameEpoch) SolveIfPending();
  // The watchdog as for fixes, on the epoch's own single-point fix (the ranges' outcome: RawGnssAttacher).
  if (!x.has_fix) {
    if (Attach(m)) solve_pending_ = true;
    reset_reason_.clear();  // no fix to rebuild from: the run goes on
  } else if (!WatchdogTakes(x.fix)) {
    AttachWatched(x.fix, m);
  }
}

void Smoother::UseModule(double t, const Measurement& m) {
  if (!initialized_ || t < t_now_ - kSameEpoch || t < window_.back().t - kSameEpoch) return;
  if (t > window_.back().t + kSameEpoch) SolveIfPending();
  if (Attach(m)) solve_pending_ = true;
}

void Smoother::Use(const WheelMeasurement& x, const Measurement& m) {
  if (!initialized_ || !sensors_.wheel.enabled) return;
  IntegrateTo(x.t);
  Attach(m);
}

bool Smoother::Solve() {
  ceres::Solver::Options so;
  if (smoother_options_.linear_solver == "sparse_normal_cholesky") {
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    int group = 0;
    for (double* b : window_.EstimatedBlocks()) ordering->AddElementToGroup(b, group++);
    so = ChainSolverOptions(ordering, smoother_options_.max_iterations, smoother_options_.function_tolerance,
                            smoother_options_.num_threads);
  } else {
    so.linear_solver_type = ceres::DENSE_SCHUR;
    so.max_num_iterations = smoother_options_.max_iterations;
    so.function_tolerance = smoother_options_.function_tolerance;
    so.num_threads = smoother_options_.num_threads;
    so.logging_type = ceres::SILENT;
  }
  ceres::Solver::Summary summary;
  ceres::Solve(so, problem_.get(), &summary);
  iterations_ += summary.iterations.size();
  return summary.IsSolutionUsable();
}

void Smoother::SolveAndSlide() {
  solve_pending_ = false;
  const auto t0 = std::chrono::steady_clock::now();
  const bool usable = Solve();
  ReintegrateIfNeeded();
  // One covariance recovery for the gates (the two newest keyframes) and, when the window slides, for the
  // keyframe leaving it.
  const bool slide = static_cast<int>(window_.size()) > smoother_options_.window_size;
  MatX oldest_cov;
  UpdateNewestCovariance(slide ? &oldest_cov : nullptr);
  const double dt = Seconds(std::chrono::steady_clock::now() - t0);
  ++solves_;
  solve_time_ += dt;
  max_solve_time_ = std::max(max_solve_time_, dt);
  if (!usable) ++solver_failures_;

  // The prediction to now starts again from the newest keyframe's solution.
  const Keyframe& newest = window_.back();
  pred_ = newest.State();
  for (const HeldImuSample& step : interval_samples_) {
    Kinematics k{pred_.q_wb, pred_.v_w, pred_.p_wb};
    k = ImuStep(k, step.sample.gyro - pred_.bg, step.sample.acc - pred_.ba, g_w_, step.dt, nullptr, earth_.rate_w());
    pred_.q_wb = k.q;
    pred_.v_w = k.v;
    pred_.p_wb = k.p;
  }
  pred_.t = t_now_;
  if (on_online_) on_online_(EstimateOf(newest, nullptr));
  if (slide) MarginalizeOldest(oldest_cov.size() > 0 ? &oldest_cov : nullptr);
  while (static_cast<int>(window_.size()) > smoother_options_.window_size) MarginalizeOldest(nullptr);
}

void Smoother::ReintegrateIfNeeded() {
  for (size_t i = 1; i < window_.size(); ++i) {
    Keyframe& prev = window_[i - 1];
    Keyframe& kf = window_[i];
    if (kf.imu_id == nullptr) continue;
    auto fresh = ReintegratedIfMoved(prev, *kf.preint, smoother_options_.bias_reintegrate_threshold);
    if (!fresh) continue;
    problem_->RemoveResidualBlock(kf.imu_id);
    if (factor_log_) factor_log_->Deactivate(kf.imu_log_index);
    kf.preint = fresh;
    kf.imu_id = AddImuFactor(prev, kf);
    kf.imu_log_index = window_.last_logged();
    ++reintegrations_;
  }
}

void Smoother::MarginalizeOldest(const MatX* block_cov) {
  const auto t0 = std::chrono::steady_clock::now();
  Keyframe& kf0 = window_.front();
  const Keyframe* kf1 = window_.size() > 1 ? &window_[1] : nullptr;

  // Covariance of the keyframe leaving, from all the information in the window.
  Mat15 cov = Mat15::Zero();
  bool have_cov = false;
  if (block_cov != nullptr) {
    cov = NavCovariance(window_.EstimatedTypes(), *block_cov);
    have_cov = cov.allFinite();
  } else {
    have_cov = OldestCovariance(window_, &cov);
  }
  // Schur complement of every factor touching the oldest keyframe.
  Marginalizer marginalizer(problem_.get(), window_.Blocks(kf0));

  if (have_cov) {
    last_sigma_p_ = std::sqrt(cov.block<3, 3>(nav::kP, nav::kP).diagonal().maxCoeff());
  } else {
    CountCovarianceFailure("the covariance of the keyframe leaving the window");
  }
  OutputFinal(kf0, kf1, have_cov ? &cov : nullptr);
  prior_id_ = marginalizer.Apply();
  for (auto& attacher : attachers_) attacher->OnKeyframeLeaving(kf0);
  window_.PopOldest();
  if (!window_.empty()) {
    window_.front().imu_id = nullptr;  // its IMU factor went with the old keyframe
    window_.front().FreezeFirstEstimates();
  }
  ++marginalizations_;
  marg_time_ += Seconds(std::chrono::steady_clock::now() - t0);
}

void Smoother::OutputFinal(const Keyframe& kf, const Keyframe* next, const Mat15* cov) {
  last_scale_ = kf.block(BlockType::kScale)[0];
  if (on_final_) {
    ImuEarthTerms earth;
    earth.g_w = earth_.Gravity(kf.State().p_wb);
    earth.rate_w = earth_.rate_w();
    EmitFinal(kf, next, interval_samples_, cov, earth, on_final_);
  }
}

void Smoother::Finish() {
  if (!initialized_) return;
  SolveIfPending();
  // The time offset as the last solve left it: the newest keyframe's, with the σ of the last one solved.
  final_time_offset_ = window_.back().block(BlockType::kTimeOffset)[0];
  if (window_.estimated(BlockType::kTimeOffset) && newest_cov_.size() > 0) {
    const MatX var = SubCovariance(window_.EstimatedTypes(), newest_cov_, {BlockType::kTimeOffset});
    final_time_offset_sigma_ = std::sqrt(std::max(var(0, 0), 0.0));
  }
  // Everything still in the window leaves it now, oldest first.
  while (window_.size() > 1) MarginalizeOldest(nullptr);
  Mat15 cov = Mat15::Zero();
  const bool have_cov = OldestCovariance(window_, &cov);
  OutputFinal(window_.front(), nullptr, have_cov ? &cov : nullptr);
  if (factor_log_) factor_log_->SetTail(&window_.front(), interval_samples_);
  window_.Clear();
  initialized_ = false;
  if (on_batch_) {
    BatchSmoother batch(sensors_, batch_options_, smoother_options_, window_.EstimatedTypes());
    batch.Solve(factor_log_.get(), earth_);
    batch.Emit(*factor_log_, earth_, pre_init_.TwoSided(on_batch_));
    batch_stats_ = batch.stats().ToJson();
    batch_stats_["time_offset"] = batch.TimeOffset();
  }
}

nlohmann::json Smoother::Stats() const {
  nlohmann::json j;
  j["keyframes"] = keyframes_;
  j["solves"] = solves_;
  j["iterations"] = iterations_;
  j["solver_failures"] = solver_failures_;
  j["covariance_failures"] = covariance_failures_;
  j["solve_time_s"] = solve_time_;
  j["mean_solve_ms"] = solves_ ? 1e3 * solve_time_ / solves_ : 0.0;
  j["max_solve_ms"] = 1e3 * max_solve_time_;
  j["marginalizations"] = marginalizations_;
  j["marginalization_time_s"] = marg_time_;
  j["mean_marginalization_ms"] = marginalizations_ ? 1e3 * marg_time_ / marginalizations_ : 0.0;
  j["reintegrations"] = reintegrations_;
  j["prior_reliefs"] = prior_reliefs_;
  for (const auto& attacher : attachers_) attacher->AddStats(&j);
  j["final_odom_scale"] = last_scale_;
  j["time_offset"] = TimeOffsetJson(sensors_.gnss, final_time_offset_, final_time_offset_sigma_);
  imu_gaps_.ToJson(&j);
  j[summary_keys::kWatchdog] = watchdog_.ToJson();
  if (on_batch_) j["batch"] = batch_stats_;
  return j;
}

}  // namespace gins
