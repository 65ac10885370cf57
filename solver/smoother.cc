#include "solver/smoother.h"

#include <glog/logging.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "core/chi2.h"
#include "core/imu_kernel.h"
#include "core/so3.h"
#include "factors/bias_rw_factor.h"
#include "factors/gnss_factor.h"
#include "factors/heading_factor.h"
#include "factors/imu_factor.h"
#include "factors/marginalization_prior.h"
#include "factors/nhc_factor.h"
#include "factors/scale_rw_factor.h"
#include "factors/wheel_factor.h"
#include "factors/zero_motion_factor.h"
#include "factors/zero_velocity_factor.h"

namespace gins {
namespace {

constexpr double kSameEpoch = 1e-6;          // s: a fix at a keyframe's time belongs to it
// Standstill: displacement 1-σ between two keyframes of one standstill, and how far a keyframe may lie after
// the last standstill detection (sent every 0.1 s) and still count as standing.
constexpr double kStandstillPositionSigma = 1e-4;  // m
constexpr double kStandstillReach = 0.15;          // s
constexpr double kStandstillLossScale = 3.0;       // Cauchy loss scale on the whitened standstill residuals
// IMU gap coasting, as in the ESKF.
constexpr double kGapAccSigma = 2.0;                // m/s²
constexpr double kGapRateSigma = 10.0 * kDegToRad;  // rad/s
constexpr size_t kMaxListed = 100;
// Watchdog re-initialisation, as in the ESKF.

// Tangent layout of one keyframe in covariance blocks: pose (δp, δθ), vel (δv), bias (δbg, δba).
// NavState tangent order is δp, δv, δθ, δbg, δba; this maps keyframe-tangent index -> NavState index.
constexpr int kKfToNav[15] = {0, 1, 2, 6, 7, 8, 3, 4, 5, 9, 10, 11, 12, 13, 14};

double Seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

bool OldestCovariance(ceres::Problem* problem, const std::vector<double*>& blocks, Mat15* cov);

}  // namespace

struct Smoother::Keyframe {
  double t = 0.0;
  double pose[pose::kAmbient];
  double vel[3];
  double bias[6];
  double scale[1];
  // First estimates: once a marginalisation prior is built on this keyframe, every other factor on it
  // evaluates its Jacobians here, at the prior's linearisation point, so the prior and the factors agree
  // on what is observable (no spurious information in yaw or position).
  bool fej = false;
  double fej_pose[pose::kAmbient];
  double fej_vel[3];
  double fej_bias[6];
  double fej_scale[1];
  void FreezeFirstEstimates() {
    std::copy(pose, pose + pose::kAmbient, fej_pose);
    std::copy(vel, vel + 3, fej_vel);
    std::copy(bias, bias + 6, fej_bias);
    fej_scale[0] = scale[0];
    fej = true;
  }
  // The first estimate of one of this keyframe's blocks (null if the block is not this keyframe's).
  const double* FirstEstimate(const double* block) const {
    if (block == pose) return fej_pose;
    if (block == vel) return fej_vel;
    if (block == bias) return fej_bias;
    if (block == scale) return fej_scale;
    return nullptr;
  }
  std::shared_ptr<const Preintegration> preint;  // previous keyframe -> this one
  std::vector<HeldSample> steps_from_prev;  // for the IMU-rate output between keyframes
  ceres::ResidualBlockId imu_id = nullptr;
  ceres::ResidualBlockId gnss_id = nullptr;
  bool gnss_checked = false;
  bool has_wheel = false;
  bool standstill = false;  // has a zero-velocity factor
  double standstill_since = 0.0;
  ceres::ResidualBlockId zupt_id = nullptr;
  ceres::ResidualBlockId zero_motion_id = nullptr;  // to the previous keyframe
  bool zupt_checked = false;
  bool zupt_ok = false;  // its zero velocity passed the χ² check
};

// Wraps a factor so that its Jacobians are evaluated at the first estimates of the keyframes that have
// them; the residual is always evaluated at the current values. The keyframes' first estimates change
// only between solves (in MarginalizeOldest), never while Ceres evaluates.
class Smoother::FejCost final : public ceres::CostFunction {
 public:
  // owners[i]: parameter block i's keyframe and first-estimate storage. (Ceres passes its own copies of the
  // parameters to Evaluate, so blocks cannot be recognised by address there.)
  struct Owner {
    const Keyframe* kf = nullptr;
    const double* first_estimate = nullptr;
    bool is_pose = false;
  };
  FejCost(ceres::CostFunction* inner, std::vector<Owner> owners)
      : inner_(inner), owners_(std::move(owners)) {
    set_num_residuals(inner_->num_residuals());
    *mutable_parameter_block_sizes() = inner_->parameter_block_sizes();
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    if (jacobians == nullptr) return inner_->Evaluate(parameters, residuals, nullptr);
    const size_t n = owners_.size();
    std::array<const double*, 8> at{};
    bool substituted = false;
    for (size_t i = 0; i < n; ++i) {
      at[i] = parameters[i];
      if (owners_[i].kf != nullptr && owners_[i].kf->fej) {
        at[i] = owners_[i].first_estimate;
        substituted = true;
      }
    }
    if (!substituted) return inner_->Evaluate(parameters, residuals, jacobians);
    if (!inner_->Evaluate(parameters, residuals, nullptr)) return false;
    std::array<double, 16> scratch;
    if (!inner_->Evaluate(at.data(), scratch.data(), jacobians)) return false;
    // Ceres turns an ambient pose Jacobian into a tangent one with PlusJacobian at the CURRENT value; the
    // first-estimate Jacobian is tangent at the first estimate. Re-express it so that Ceres's product gives
    // exactly that: J_tan = J_amb(x_fej)·Plus'(x_fej), then J_amb' = J_tan·Minus'(x) (Minus'·Plus' = I).
    for (size_t i = 0; i < n; ++i) {
      if (at[i] == parameters[i] || jacobians[i] == nullptr || !owners_[i].is_pose) continue;
      using Mat76 = Eigen::Matrix<double, pose::kAmbient, pose::kTangent, Eigen::RowMajor>;
      using Mat67 = Eigen::Matrix<double, pose::kTangent, pose::kAmbient, Eigen::RowMajor>;
      Mat76 plus_fej;
      Mat67 minus_now;
      manifold_.PlusJacobian(at[i], plus_fej.data());
      manifold_.MinusJacobian(parameters[i], minus_now.data());
      using JacobianMap = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, pose::kAmbient, Eigen::RowMajor>>;
      JacobianMap J(jacobians[i], num_residuals(), pose::kAmbient);
      J = (J * plus_fej * minus_now).eval();
    }
    return true;
  }

 private:
  std::unique_ptr<ceres::CostFunction> inner_;
  std::vector<Owner> owners_;
  PoseManifold manifold_;
};

ceres::ResidualBlockId Smoother::AddFactor(ceres::CostFunction* cost, ceres::LossFunction* loss,
                                           const std::vector<std::pair<const Keyframe*, double*>>& blocks) {
  std::vector<FejCost::Owner> owners;
  std::vector<double*> params;
  for (const auto& [kf, block] : blocks) {
    owners.push_back({kf, kf->FirstEstimate(block), block == kf->pose});
    params.push_back(block);
  }
  CHECK_LE(owners.size(), 8u);
  CHECK_LE(cost->num_residuals(), 16);
  return problem_->AddResidualBlock(new FejCost(cost, std::move(owners)), loss, params);
}

Smoother::Smoother(const EstimatorOptions& options, StateCallback on_final, StateCallback on_online)
    : options_(options), on_final_(std::move(on_final)), on_online_(std::move(on_online)),
      watchdog_(options.watchdog) {
  gnss_gate_ = options_.gnss.gate_probability > 0.0 ? Chi2Quantile(options_.gnss.gate_probability, 3)
                                                    : std::numeric_limits<double>::infinity();
  zupt_gate_ = options_.wheel.gate_probability > 0.0 ? Chi2Quantile(options_.wheel.gate_probability, 3)
                                                     : std::numeric_limits<double>::infinity();
}

Smoother::~Smoother() = default;

NavState Smoother::StateOf(const Keyframe& kf) const {
  NavState x;
  x.t = kf.t;
  x.p_wb = Eigen::Map<const Vec3>(kf.pose + pose::kP);
  x.q_wb = Eigen::Map<const Quat>(kf.pose + pose::kQ).normalized();
  x.v_w = Eigen::Map<const Vec3>(kf.vel);
  x.bg = Eigen::Map<const Vec3>(kf.bias);
  x.ba = Eigen::Map<const Vec3>(kf.bias + 3);
  return x;
}

NavState Smoother::NewestState() const { return StateOf(*window_.back()); }

StateEstimate Smoother::EstimateOf(const Keyframe& kf, const Mat15* cov) const {
  StateEstimate e;
  e.x = StateOf(kf);
  e.odom_scale = kf.scale[0];
  if (cov != nullptr) {
    e.sigma_p = cov->block<3, 3>(nav::kP, nav::kP).diagonal().cwiseSqrt();
    e.sigma_v = cov->block<3, 3>(nav::kV, nav::kV).diagonal().cwiseSqrt();
    const Mat3 R = e.x.R_wb();
    e.sigma_att = (R * cov->block<3, 3>(nav::kTheta, nav::kTheta) * R.transpose()).diagonal().cwiseSqrt();
  }
  return e;
}

void Smoother::Initialize(const InitResult& init) {
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.enable_fast_removal = true;
  problem_ = std::make_unique<ceres::Problem>(po);
  gnss_loss_ = std::make_unique<ceres::CauchyLoss>(options_.smoother.gnss_loss_scale);
  standstill_loss_ = std::make_unique<ceres::CauchyLoss>(kStandstillLossScale);
  window_.clear();
  g_w_ = GravityWorld(init.g_norm);

  auto kf = std::make_unique<Keyframe>();
  kf->t = init.x0.t;
  SetPose(init.x0.p_wb, init.x0.q_wb, kf->pose);
  Eigen::Map<Vec3>(kf->vel) = init.x0.v_w;
  Eigen::Map<Vec3>(kf->bias) = init.x0.bg;
  Eigen::Map<Vec3>(kf->bias + 3) = init.x0.ba;
  kf->scale[0] = initial_scale_;
  problem_->AddParameterBlock(kf->pose, pose::kAmbient, &pose_manifold_);
  problem_->AddParameterBlock(kf->vel, 3);
  problem_->AddParameterBlock(kf->bias, 6);
  problem_->AddParameterBlock(kf->scale, 1);
  const bool scale_estimated = options_.wheel.enabled && options_.wheel.estimate_scale;
  if (!scale_estimated) problem_->SetParameterBlockConstant(kf->scale);
  window_.push_back(std::move(kf));
  AddPrior(*window_.back(), init.P0);

  preint_ = std::make_shared<Preintegration>(init.x0.bg, init.x0.ba, options_.imu.gyro_noise_density,
                                             options_.imu.acc_noise_density);
  interval_samples_.clear();
  last_imu_.reset();
  t_now_ = init.x0.t;
  pred_ = init.x0;
  initialized_ = true;
  ++keyframes_;
  if (on_online_) on_online_(EstimateOf(*window_.back(), nullptr));
}

void Smoother::AddPrior(const Keyframe& kf, const Mat15& P0) {
  // The initial covariance as a prior on the first keyframe, in its block tangent order.
  const bool scale_estimated = options_.wheel.enabled && options_.wheel.estimate_scale;
  const int n = scale_estimated ? 16 : 15;
  MatX P = MatX::Zero(n, n);
  for (int i = 0; i < 15; ++i) {
    for (int j = 0; j < 15; ++j) P(i, j) = P0(kKfToNav[i], kKfToNav[j]);
  }
  if (scale_estimated) P(15, 15) = options_.wheel.scale_sigma * options_.wheel.scale_sigma;
  const MatX info = P.inverse();
  const Eigen::LLT<MatX> llt(0.5 * (info + info.transpose()));
  const MatX J = llt.matrixU();  // JᵀJ = info
  std::vector<PriorBlock> blocks;
  auto block = [](BlockKind kind, int ambient, const double* values) {
    PriorBlock b;
    b.kind = kind;
    b.ambient_size = ambient;
    b.tangent_size = TangentSizeOf(kind, ambient);
    b.x0.assign(values, values + ambient);
    return b;
  };
  blocks.push_back(block(BlockKind::kPose, pose::kAmbient, kf.pose));
  blocks.push_back(block(BlockKind::kEuclidean, 3, kf.vel));
  blocks.push_back(block(BlockKind::kEuclidean, 6, kf.bias));
  std::vector<double*> params = {const_cast<double*>(kf.pose), const_cast<double*>(kf.vel),
                                 const_cast<double*>(kf.bias)};
  if (scale_estimated) {
    blocks.push_back(block(BlockKind::kEuclidean, 1, kf.scale));
    params.push_back(const_cast<double*>(kf.scale));
  }
  prior_id_ = problem_->AddResidualBlock(new MarginalizationPrior(std::move(blocks), J, VecX::Zero(n)), nullptr,
                                         params);
}

void Smoother::IntegrateTo(double t, const ImuSample* held) {
  const double dt = t - t_now_;
  if (dt <= 0.0) return;
  if (last_imu_) {
    if (held == nullptr) held = &*last_imu_;
    ImuSample coast;
    if (t - last_imu_->t > options_.imu.max_gap) {
      // Across an IMU gap: no rotation and no acceleration, from the current estimate, with the
      // uncertainty of an unknown rate and acceleration held over the gap.
      coast.t = held->t;
      coast.gyro = pred_.bg;
      coast.acc = pred_.q_wb.conjugate() * -g_w_ + pred_.ba;
      held = &coast;
      preint_->IntegrateGuess(coast.gyro, coast.acc, dt, kGapRateSigma, kGapAccSigma);
    } else {
      preint_->Integrate(*held, dt);
    }
    interval_samples_.push_back({*held, dt});
    Kinematics k{pred_.q_wb, pred_.v_w, pred_.p_wb};
    k = ImuStep(k, held->gyro - pred_.bg, held->acc - pred_.ba, g_w_, dt);
    pred_.q_wb = k.q;
    pred_.v_w = k.v;
    pred_.p_wb = k.p;
  }
  pred_.t = t;
  t_now_ = t;
}

void Smoother::AddImu(const ImuSample& imu) {
  if (!initialized_ || imu.t < t_now_) return;
  if (last_imu_ && imu.t - last_imu_->t > options_.imu.max_gap) {
    ++imu_gaps_;
    if (gap_times_.size() < kMaxListed) gap_times_.emplace_back(last_imu_->t, imu.t);
  }
  if (last_imu_) {
    const ImuSample mid = HeldBetween(*last_imu_, imu);
    IntegrateTo(imu.t, &mid);
  }
  last_imu_ = imu;
  // Without GNSS a keyframe still comes every max_keyframe_interval, so no preintegration spans an outage.
  // The 10 % grace lets a fix due at that very epoch (often logged just after the IMU sample) make the
  // keyframe itself, instead of a second solve at the same time.
  if (t_now_ - window_.back()->t >= 1.1 * options_.smoother.max_keyframe_interval) {
    CreateKeyframe(t_now_);
    SolveAndSlide();
  }
}

Smoother::Keyframe* Smoother::CreateKeyframe(double t) {
  IntegrateTo(t);
  Keyframe& prev = *window_.back();
  auto kf = std::make_unique<Keyframe>();
  kf->t = t;
  SetPose(pred_.p_wb, pred_.q_wb, kf->pose);
  Eigen::Map<Vec3>(kf->vel) = pred_.v_w;
  Eigen::Map<Vec3>(kf->bias) = pred_.bg;
  Eigen::Map<Vec3>(kf->bias + 3) = pred_.ba;
  kf->scale[0] = prev.scale[0];
  kf->preint = preint_;
  kf->steps_from_prev = interval_samples_;
  problem_->AddParameterBlock(kf->pose, pose::kAmbient, &pose_manifold_);
  problem_->AddParameterBlock(kf->vel, 3);
  problem_->AddParameterBlock(kf->bias, 6);
  problem_->AddParameterBlock(kf->scale, 1);
  if (problem_->IsParameterBlockConstant(prev.scale)) problem_->SetParameterBlockConstant(kf->scale);

  const double dt = kf->t - prev.t;
  const Keyframe* k = kf.get();
  kf->imu_id = AddFactor(ImuFactor::Create(kf->preint, g_w_), nullptr,
                         {{&prev, prev.pose}, {&prev, prev.vel}, {&prev, prev.bias}, {k, kf->pose}, {k, kf->vel}});
  AddFactor(BiasRwFactor::Create(options_.imu.gyro_bias_rw, options_.imu.acc_bias_rw, dt), nullptr,
            {{&prev, prev.bias}, {k, kf->bias}});
  if (!problem_->IsParameterBlockConstant(kf->scale)) {
    AddFactor(ScaleRwFactor::Create(options_.wheel.scale_rw, dt), nullptr, {{&prev, prev.scale}, {k, kf->scale}});
  }
  preint_ = std::make_shared<Preintegration>(pred_.bg, pred_.ba, options_.imu.gyro_noise_density,
                                             options_.imu.acc_noise_density);
  interval_samples_.clear();
  window_.push_back(std::move(kf));
  ++keyframes_;
  AttachWheel(window_.back().get());
  AttachStandstill(window_.back().get());
  return window_.back().get();
}

void Smoother::AttachStandstill(Keyframe* kf) {
  if (!last_standstill_ || kf->standstill || kf != window_.back().get()) return;
  const StandstillMeasurement& s = *last_standstill_;
  if (kf->t < s.since || kf->t > s.t + kStandstillReach) return;
  if (StateOf(*kf).v_w.norm() > options_.standstill.max_speed) {
    zupt_counts_.Reject("moving", kf->t);  // a quiet IMU at speed: not a stop
    return;
  }
  kf->standstill = true;
  kf->standstill_since = s.since;
  // Robust like the GNSS factors, so that a wrong detection cannot bend the window to itself before the χ²
  // check (CheckStandstillResiduals) takes it out.
  kf->zupt_id = AddFactor(new ZeroVelocityFactor(options_.standstill.velocity_sigma), standstill_loss_.get(),
                          {{kf, kf->vel}});
}

void Smoother::CheckStandstillResiduals() {
  // A quiet IMU during a smooth start or a constant acceleration can look like a stop: a zero velocity the
  // other measurements disagree with (χ² on its whitened residual after the solve) is taken out again, with
  // the zero-motion factors on that keyframe, and the window solved without it.
  bool removed = false;
  for (size_t i = 0; i < window_.size(); ++i) {
    Keyframe& kf = *window_[i];
    if (kf.zupt_id == nullptr || kf.zupt_checked) continue;
    kf.zupt_checked = true;
    double cost = 0.0;
    Vec3 r;
    problem_->EvaluateResidualBlock(kf.zupt_id, /*apply_loss_function=*/false, &cost, r.data(), nullptr);
    if (r.squaredNorm() <= zupt_gate_) {
      ++zupt_counts_.used;
      kf.zupt_ok = true;
      // Two confirmed keyframes of one standstill: no translation, no rotation in between. Not robust (its
      // 0.1 mm would put any IMU disagreement in the flat part of a robust loss), so only between confirmed
      // zero velocities; it joins at the next solve.
      Keyframe* prev = i > 0 ? window_[i - 1].get() : nullptr;
      if (prev != nullptr && prev->zupt_ok && prev->t >= kf.standstill_since && kf.zero_motion_id == nullptr) {
        const double sigma_theta =
            std::max(2.0 * options_.imu.gyro_noise_density * std::sqrt(kf.t - prev->t), 1e-6);
        ++zero_motion_factors_;
        kf.zero_motion_id = AddFactor(ZeroMotionFactor::Create(kStandstillPositionSigma, sigma_theta), nullptr,
                                      {{prev, prev->pose}, {&kf, kf.pose}});
      }
      continue;
    }
    zupt_counts_.Reject("chi2_gate", kf.t);
    problem_->RemoveResidualBlock(kf.zupt_id);
    kf.zupt_id = nullptr;
    kf.standstill = false;
    removed = true;
  }
  if (!removed) return;
  Solve();
}

void Smoother::AddStandstill(const StandstillMeasurement& m) {
  if (!initialized_) return;
  last_standstill_ = m;
  AttachStandstill(window_.back().get());
}

void Smoother::AttachWheel(Keyframe* kf) {
  if (!options_.wheel.enabled || kf->has_wheel || !last_wheel_) return;
  const WheelMeasurement& w = *last_wheel_;
  const double t_mid = w.t - 0.5 * w.interval;
  const double offset = kf->t - t_mid;
  if (std::abs(offset) > std::max(w.interval, 1e-3)) return;
  kf->has_wheel = true;
  // The encoders give the mean speed over their interval; move it to the keyframe's time with the
  // forward acceleration from the IMU.
  double speed = w.speed;
  if (last_imu_) {
    const NavState x = StateOf(*kf);
    const Vec3 a_b = (last_imu_->acc - x.ba) + x.q_wb.conjugate() * g_w_;
    speed += a_b.x() * offset;
  }
  AddFactor(WheelFactor::Create(speed, w.sigma), nullptr, {{kf, kf->pose}, {kf, kf->vel}, {kf, kf->scale}});
  if (options_.wheel.nonholonomic) {
    AddFactor(NhcFactor::Create(options_.wheel.nhc_sigma), nullptr, {{kf, kf->pose}, {kf, kf->vel}});
  }
  ++wheel_counts_.used;
}

void Smoother::AddWheel(const WheelMeasurement& w) {
  if (!initialized_ || !options_.wheel.enabled) return;
  last_wheel_ = w;
  AttachWheel(window_.back().get());
}

void Smoother::AddGnss(const GnssMeasurement& m) {
  if (!initialized_ || m.t < t_now_ - kSameEpoch) return;
  if (options_.watchdog.enabled) {
    const double max_sigma = options_.watchdog.max_position_sigma;
    const bool finite = StateOf(*window_.back()).AllFinite() && pred_.AllFinite();
    if (!finite || last_sigma_p_ > max_sigma) {
      ResetFromGnss(m, finite ? "covariance" : "non_finite");
      prev_fix_ = m;
      return;
    }
  }
  reset_reason_.clear();
  const std::optional<GnssMeasurement> prev_fix = prev_fix_;
  prev_fix_ = m;
  Keyframe* kf = window_.back().get();
  if (std::abs(m.t - kf->t) <= kSameEpoch) {
    if (kf->gnss_id != nullptr) return;  // one fix per epoch
  } else if (m.t - kf->t < options_.smoother.min_keyframe_interval) {
    ++gnss_decimated_;
    return;
  } else {
    kf = CreateKeyframe(m.t);
  }
  kf->gnss_id =
      AddFactor(GnssFactor::Create(m.p_w, m.sigma_w, options_.gnss.lever_b), gnss_loss_.get(), {{kf, kf->pose}});
  if (m.heading_valid && options_.gnss.use_heading) {
    AddFactor(HeadingFactor::Create(m.yaw_G, m.sigma_yaw, options_.gnss.mount_yaw), gnss_loss_.get(),
              {{kf, kf->pose}});
    ++heading_counts_.used;
  }
  SolveAndSlide();
  if (!reset_reason_.empty()) {
    prev_fix_ = prev_fix;  // the fix before this one, for the velocity
    ResetFromGnss(m, reset_reason_);
    prev_fix_ = m;
  }
}

void Smoother::WatchGnss(double t, bool accepted) {
  if (watchdog_.Watch(t, accepted)) reset_reason_ = "gnss_rejected";
}

void Smoother::ResetFromGnss(const GnssMeasurement& m, const std::string& reason_in) {
  const std::string reason = reason_in;  // may be reset_reason_, which is cleared below
  IntegrateTo(m.t);  // attitude and biases at the fix's time (pred_), from the newest keyframe
  const NavState at_fix = pred_;
  // What the window knows of the newest keyframe: its state, and its covariance from the whole window.
  InitResult init;
  Mat15 cov = Mat15::Zero();
  bool have_cov = false;
  const bool finite = StateOf(*window_.back()).AllFinite();
  if (finite) {
    // The older keyframes leave the window as usual (final output); the newest is replaced by the prior.
    while (window_.size() > 1) MarginalizeOldest();
    std::vector<double*> blocks;
    for (double* b : {window_.front()->pose, window_.front()->vel, window_.front()->bias, window_.front()->scale}) {
      if (!problem_->IsParameterBlockConstant(b)) blocks.push_back(b);
    }
    have_cov = OldestCovariance(problem_.get(), blocks, &cov);
    init.x0 = at_fix.AllFinite() ? at_fix : StateOf(*window_.front());
    initial_scale_ = window_.front()->scale[0];
  } else {
    // Nothing is left to keep: attitude from the dual-antenna heading if there is one, level otherwise.
    init.x0.q_wb = QuatFromYaw(m.heading_valid ? m.yaw_G - options_.gnss.mount_yaw : 0.0);
    initial_scale_ = 1.0;
  }
  if (!have_cov) {
    cov.setZero();
    cov.block<3, 3>(nav::kTheta, nav::kTheta).diagonal() << 0.05, 0.05, 1.0;
    cov.block<3, 3>(nav::kBg, nav::kBg).diagonal().setConstant(std::pow(options_.imu.init_gyro_bias_sigma, 2));
    cov.block<3, 3>(nav::kBa, nav::kBa).diagonal().setConstant(std::pow(options_.imu.init_acc_bias_sigma, 2));
  }
  init.g_norm = g_w_.norm();
  const bool have_velocity = ResetPositionFromFix(m, prev_fix_, options_, &init.x0, cov);
  // Tiny floors keep the prior invertible whatever the window's covariance was.
  cov = 0.5 * (cov + cov.transpose());
  cov.diagonal() = cov.diagonal().cwiseMax(1e-12);
  init.P0 = cov;

  const std::optional<ImuSample> last_imu = last_imu_;
  const std::optional<WheelMeasurement> last_wheel = last_wheel_;
  Initialize(init);  // a fresh problem and window; emits the new keyframe on the online stream
  last_imu_ = last_imu;
  last_wheel_ = last_wheel;
  last_standstill_.reset();
  last_sigma_p_ = 0.0;
  reset_reason_.clear();
  watchdog_.Reset(m.t, reason);
  LOG(WARNING) << "smoother watchdog: window rebuilt from GNSS at t=" << std::fixed << m.t << " (" << reason
               << (have_velocity ? "; velocity from the last two fixes" : "; velocity kept") << ")";
}

bool Smoother::Solve() {
  ceres::Solver::Options so;
  so.linear_solver_type = options_.smoother.linear_solver == "sparse_normal_cholesky" ? ceres::SPARSE_NORMAL_CHOLESKY
                                                                                      : ceres::DENSE_SCHUR;
  if (so.linear_solver_type == ceres::SPARSE_NORMAL_CHOLESKY) {
    // SuiteSparse when Ceres has it (Debian's does), Eigen's sparse Cholesky otherwise.
    if (!ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE)) {
      so.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
    }
    // Eliminate in time order, one block after the other: no fill-in along the chain, and the same order
    // every run. Ceres's default ordering is a set of block addresses, so the last bits of the solution
    // would follow the heap's layout.
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    int group = 0;
    for (const auto& kf : window_) {
      for (double* b : {kf->pose, kf->vel, kf->bias, kf->scale}) {
        if (problem_->HasParameterBlock(b) && !problem_->IsParameterBlockConstant(b)) {
          ordering->AddElementToGroup(b, group++);
        }
      }
    }
    so.linear_solver_ordering = ordering;
  }
  so.max_num_iterations = options_.smoother.max_iterations;
  so.function_tolerance = options_.smoother.function_tolerance;
  so.num_threads = options_.smoother.num_threads;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, problem_.get(), &summary);
  iterations_ += summary.iterations.size();
  return summary.IsSolutionUsable();
}

void Smoother::SolveAndSlide() {
  const auto t0 = std::chrono::steady_clock::now();
  const bool usable = Solve();
  // A wrong zero velocity (a constant acceleration looks as quiet as a stop) goes first: with it in, the
  // fix that contradicts it would be the one to fail.
  CheckStandstillResiduals();
  CheckGnssResiduals();
  ReintegrateIfNeeded();
  const double dt = Seconds(std::chrono::steady_clock::now() - t0);
  ++solves_;
  solve_time_ += dt;
  max_solve_time_ = std::max(max_solve_time_, dt);
  if (!usable) ++solver_failures_;

  pred_ = StateOf(*window_.back());
  if (on_online_) on_online_(EstimateOf(*window_.back(), nullptr));
  while (static_cast<int>(window_.size()) > options_.smoother.window_size) MarginalizeOldest();
}

void Smoother::CheckGnssResiduals() {
  Keyframe& kf = *window_.back();
  if (kf.gnss_id == nullptr || kf.gnss_checked) return;
  kf.gnss_checked = true;
  double cost = 0.0;
  Vec3 r;
  problem_->EvaluateResidualBlock(kf.gnss_id, /*apply_loss_function=*/false, &cost, r.data(), nullptr);
  if (r.squaredNorm() > gnss_gate_) {
    // An outlier the robust loss only damped: take it out and solve again without it.
    problem_->RemoveResidualBlock(kf.gnss_id);
    kf.gnss_id = nullptr;
    gnss_counts_.Reject("chi2_gate", kf.t);
    WatchGnss(kf.t, false);
    Solve();
  } else {
    ++gnss_counts_.used;
    WatchGnss(kf.t, true);
  }
}

void Smoother::ReintegrateIfNeeded() {
  for (size_t i = 1; i < window_.size(); ++i) {
    Keyframe& prev = *window_[i - 1];
    Keyframe& kf = *window_[i];
    if (kf.imu_id == nullptr) continue;
    const Vec3 bg = Eigen::Map<const Vec3>(prev.bias), ba = Eigen::Map<const Vec3>(prev.bias + 3);
    const double moved = std::sqrt((bg - kf.preint->bg_lin()).squaredNorm() + (ba - kf.preint->ba_lin()).squaredNorm());
    if (moved <= options_.smoother.bias_reintegrate_threshold) continue;
    // A new preintegration (live factors must never see theirs change).
    auto fresh = std::make_shared<Preintegration>(*kf.preint);
    fresh->Reintegrate(bg, ba);
    problem_->RemoveResidualBlock(kf.imu_id);
    kf.preint = fresh;
    kf.imu_id = AddFactor(ImuFactor::Create(kf.preint, g_w_), nullptr,
                          {{&prev, prev.pose}, {&prev, prev.vel}, {&prev, prev.bias}, {&kf, kf.pose}, {&kf, kf.vel}});
    ++reintegrations_;
  }
}

namespace {

// Covariance (NavState tangent order) of the first keyframe's blocks (pose, vel, bias: the first 15
// tangent columns of `blocks`) from the window's full information H = JᵀJ. The window is a chain, so H is
// banded: a sparse product and a sparse LDLᵀ in the natural (time) order cost a few hundred µs where dense
// ones cost milliseconds per keyframe.
bool OldestCovariance(ceres::Problem* problem, const std::vector<double*>& blocks, Mat15* cov) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = blocks;
  ceres::CRSMatrix J;
  if (!problem->Evaluate(eo, nullptr, nullptr, nullptr, &J)) return false;
  if (J.num_cols < 15) return false;
  using SpMat = Eigen::SparseMatrix<double>;
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor, int>> Js(
      J.num_rows, J.num_cols, static_cast<Eigen::Index>(J.values.size()), J.rows.data(), J.cols.data(),
      J.values.data());
  const SpMat H = SpMat(Js.transpose()) * Js;
  const Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt(H);
  if (ldlt.info() != Eigen::Success) return false;
  MatX E = MatX::Zero(H.rows(), 15);
  E.topRows<15>().setIdentity();
  const MatX C = ldlt.solve(E).topRows<15>();
  if (ldlt.info() != Eigen::Success) return false;
  for (int i = 0; i < 15; ++i) {
    for (int j = 0; j < 15; ++j) (*cov)(kKfToNav[i], kKfToNav[j]) = C(i, j);
  }
  return cov->allFinite();
}

}  // namespace

void Smoother::MarginalizeOldest() {
  const auto t0 = std::chrono::steady_clock::now();
  Keyframe& kf0 = *window_.front();
  const Keyframe* kf1 = window_.size() > 1 ? window_[1].get() : nullptr;

  // Covariance of the keyframe leaving, from all the information in the window.
  std::vector<double*> all_blocks;
  for (const auto& kf : window_) {
    for (double* b : {kf->pose, kf->vel, kf->bias, kf->scale}) {
      if (!problem_->IsParameterBlockConstant(b)) all_blocks.push_back(b);
    }
  }
  Mat15 cov = Mat15::Zero();
  const bool have_cov = OldestCovariance(problem_.get(), all_blocks, &cov);

  // Schur complement of every factor touching the oldest keyframe.
  MarginalizationInfo info;
  std::vector<double*> marg_blocks = {kf0.pose, kf0.vel, kf0.bias, kf0.scale};
  // In the problem's own (insertion) order, not GetResidualBlocksForParameterBlock's, which follows a hash
  // of addresses: the sums of the Schur complement, and so the last bits of every later estimate, would
  // then change from run to run with the heap's layout.
  std::vector<ceres::ResidualBlockId> all_ids, ids;
  problem_->GetResidualBlocks(&all_ids);
  for (auto id : all_ids) {
    std::vector<double*> params;
    problem_->GetParameterBlocksForResidualBlock(id, &params);
    const bool touches = std::any_of(params.begin(), params.end(), [&](double* b) {
      return std::find(marg_blocks.begin(), marg_blocks.end(), b) != marg_blocks.end();
    });
    if (touches) ids.push_back(id);
  }
  std::vector<double*> declared;
  auto declare = [&](double* b) {
    if (std::find(declared.begin(), declared.end(), b) != declared.end()) return;
    declared.push_back(b);
    const bool is_marg = std::find(marg_blocks.begin(), marg_blocks.end(), b) != marg_blocks.end();
    const bool is_const = problem_->IsParameterBlockConstant(b);
    const MarginalizationInfo::Role role = is_const  ? MarginalizationInfo::Role::kConstant
                                           : is_marg ? MarginalizationInfo::Role::kMarginalize
                                                     : MarginalizationInfo::Role::kKeep;
    const BlockKind kind = problem_->GetManifold(b) != nullptr ? BlockKind::kPose : BlockKind::kEuclidean;
    info.AddParameterBlock(b, kind, problem_->ParameterBlockSize(b), role);
  };
  for (auto id : ids) {
    std::vector<double*> params;
    problem_->GetParameterBlocksForResidualBlock(id, &params);
    for (double* b : params) declare(b);
    info.AddResidualBlock(problem_->GetCostFunctionForResidualBlock(id), problem_->GetLossFunctionForResidualBlock(id),
                          params);
  }
  const bool ok = info.Marginalize();
  std::unique_ptr<MarginalizationPrior> prior = ok ? info.CreatePrior() : nullptr;
  const std::vector<double*> kept = info.kept_parameter_blocks();

  if (have_cov) last_sigma_p_ = std::sqrt(cov.block<3, 3>(nav::kP, nav::kP).diagonal().maxCoeff());
  EmitFinal(kf0, kf1, have_cov ? &cov : nullptr);
  // Residuals first, in program order: RemoveParameterBlock would remove them in the order of a hash set of
  // addresses, and each removal moves the problem's last residual into the hole, so the residual order (and
  // the last bits of every later solve) would follow the heap's layout.
  for (auto id : ids) problem_->RemoveResidualBlock(id);
  for (double* b : marg_blocks) problem_->RemoveParameterBlock(b);
  prior_id_ = nullptr;
  if (prior) prior_id_ = problem_->AddResidualBlock(prior.release(), nullptr, kept);
  window_.pop_front();
  if (!window_.empty()) {
    window_.front()->imu_id = nullptr;  // its IMU factor went with the old keyframe
    window_.front()->FreezeFirstEstimates();
  }
  ++marginalizations_;
  marg_time_ += Seconds(std::chrono::steady_clock::now() - t0);
}

void Smoother::EmitFinal(const Keyframe& kf, const Keyframe* next, const Mat15* cov) {
  last_scale_ = kf.scale[0];
  if (!on_final_) return;
  StateEstimate e = EstimateOf(kf, cov);
  last_scale_ = kf.scale[0];
  on_final_(e);
  // IMU-rate states to the next keyframe, propagated from this keyframe's final estimate.
  const std::vector<HeldSample>* steps = next != nullptr ? &next->steps_from_prev : nullptr;
  std::vector<HeldSample> tail;
  if (next == nullptr) {
    tail = interval_samples_;
    steps = &tail;
  }
  Kinematics k{e.x.q_wb, e.x.v_w, e.x.p_wb};
  // Between two keyframes of one standstill the vehicle stands: no IMU wobble in the output either.
  const bool standing = next != nullptr && next->zero_motion_id != nullptr;
  if (standing) k.v.setZero();
  double t = e.x.t;
  for (size_t i = 0; i < steps->size(); ++i) {
    const auto& st = (*steps)[i];
    if (!standing) k = ImuStep(k, st.sample.gyro - e.x.bg, st.sample.acc - e.x.ba, g_w_, st.dt);
    t += st.dt;
    if (next != nullptr && i + 1 == steps->size()) break;  // the next keyframe emits itself
    StateEstimate m = e;
    m.x.t = t;
    m.x.q_wb = k.q;
    m.x.v_w = k.v;
    m.x.p_wb = k.p;
    on_final_(m);
  }
}

void Smoother::Finish() {
  if (!initialized_) return;
  // Everything still in the window leaves it now, oldest first.
  while (window_.size() > 1) MarginalizeOldest();
  std::vector<double*> blocks;
  for (double* b : {window_.front()->pose, window_.front()->vel, window_.front()->bias, window_.front()->scale}) {
    if (!problem_->IsParameterBlockConstant(b)) blocks.push_back(b);
  }
  Mat15 cov = Mat15::Zero();
  const bool have_cov = OldestCovariance(problem_.get(), blocks, &cov);
  EmitFinal(*window_.front(), nullptr, have_cov ? &cov : nullptr);
  window_.clear();
  initialized_ = false;
}

nlohmann::json Smoother::Stats() const {
  nlohmann::json j;
  j["keyframes"] = keyframes_;
  j["solves"] = solves_;
  j["iterations"] = iterations_;
  j["solver_failures"] = solver_failures_;
  j["solve_time_s"] = solve_time_;
  j["mean_solve_ms"] = solves_ ? 1e3 * solve_time_ / solves_ : 0.0;
  j["max_solve_ms"] = 1e3 * max_solve_time_;
  j["marginalizations"] = marginalizations_;
  j["marginalization_time_s"] = marg_time_;
  j["mean_marginalization_ms"] = marginalizations_ ? 1e3 * marg_time_ / marginalizations_ : 0.0;
  j["reintegrations"] = reintegrations_;
  j["gnss_decimated"] = gnss_decimated_;
  j["gnss_position"] = gnss_counts_.ToJson();
  j["gnss_heading"] = heading_counts_.ToJson();
  j["wheel"] = wheel_counts_.ToJson();
  j["zero_velocity"] = zupt_counts_.ToJson();
  j["zero_motion_factors"] = zero_motion_factors_;
  j["final_odom_scale"] = last_scale_;
  j["imu_gaps"] = imu_gaps_;
  j["imu_gap_times"] = nlohmann::json::array();
  for (const auto& [a, b] : gap_times_) j["imu_gap_times"].push_back({a, b});
  j["watchdog"] = watchdog_.ToJson();
  return j;
}

}  // namespace gins
