#include "solver/smoother_attachers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "core/chi2.h"
#include "factors/delayed_factor.h"
#include "factors/gnss_factor.h"
#include "factors/gnss_velocity_factor.h"
#include "factors/heading_factor.h"
#include "factors/preint_attached_factor.h"
#include "factors/module_factor.h"
#include "factors/zero_motion_factor.h"
#include "factors/zero_velocity_factor.h"
#include "solver/smoother_gate.h"

namespace gins {
namespace {

// Standstill: displacement 1-σ between two keyframes of one standstill, and how far a keyframe may lie after
// the last standstill detection (sent every 0.1 s) and still count as standing.
constexpr double kStandstillPositionSigma = 1e-4;  // m
constexpr double kStandstillReach = 0.15;          // s

// A state's blocks as values, to evaluate a factor at a predicted state before any keyframe holds it; the
// time offset is the newest keyframe's.
struct StateBlocks {
  std::array<double, pose::kAmbient> pose;
  Vec3 vel;
  Vec6 bias;
  double td;
  StateBlocks(const NavState& x, const KeyframeStore& keyframes)
      : vel(x.v_w), td(keyframes.back().block(BlockType::kTimeOffset)[0]) {
    SetPose(x.p_wb, x.q_wb, pose.data());
    bias << x.bg, x.ba;
  }
};

bool TimeOffsetEstimated(const AttachContext& ctx) { return ctx.keyframes.estimated(BlockType::kTimeOffset); }

// A GNSS record's factor at t − td (the time offset estimated): the model M at the state the anchor predicts
// for the stamp, taken back by the anchor keyframe's offset block (factors/delayed_factor.h).
template <class M>
ceres::CostFunction* DelayedFactor(const M& model, const Anchor& a, const Prediction& pred, const AttachContext& ctx,
                                   std::vector<BlockRef>* blocks) {
  const Delayed<M> delayed{model, ctx.Acceleration(pred.x), ctx.BodyRate(pred.x)};
  if (a.partial == nullptr) {
    *blocks = {{a.kf, BlockType::kPose}, {a.kf, BlockType::kVelocity}, {a.kf, BlockType::kTimeOffset}};
    return DelayedAtKeyframeFactor<M>::Create(delayed);
  }
  *blocks = {{a.kf, BlockType::kPose}, {a.kf, BlockType::kVelocity}, {a.kf, BlockType::kBias},
             {a.kf, BlockType::kTimeOffset}};
  return DelayedAttachedCostFunction<M>::Create(a.partial, ctx.EarthTermsAt(pred.x.p_wb), delayed);
}

// A measurement's check against the prediction (smoother_gate.h): its factor at the predicted blocks, with
// their covariance; with the offset estimated, the delayed factor on pose, velocity and offset, so the
// offset's σ widens the gate as the ESKF's H·P·Hᵀ does.
struct GateCheck {
  std::unique_ptr<ceres::CostFunction> cost;
  std::vector<const double*> params;
  std::vector<BlockKind> kinds;
  MatX sigma;
  FactorCheck Run(double inflation = 1.0) const {
    return CheckFactor(*cost, params, kinds, inflation == 1.0 ? sigma : MatX(inflation * sigma));
  }
};

// The check at the stamp (the offset held): cost on the predicted pose, and velocity if it takes one.
GateCheck StampCheck(ceres::CostFunction* cost, const StateBlocks& at, bool with_velocity, const Prediction& pred,
                     const AttachContext& ctx) {
  GateCheck g;
  g.cost.reset(cost);
  g.params = {at.pose.data()};
  g.kinds = {BlockKind::kPose};
  std::vector<BlockType> blocks = {BlockType::kPose};
  if (with_velocity) {
    g.params.push_back(at.vel.data());
    g.kinds.push_back(BlockKind::kEuclidean);
    blocks.push_back(BlockType::kVelocity);
  }
  g.sigma = SubCovariance(ctx.keyframes.EstimatedTypes(), pred.cov, blocks);
  return g;
}

template <class M>
GateCheck DelayedCheck(const M& model, const Prediction& pred, const StateBlocks& at, const AttachContext& ctx) {
  GateCheck g;
  g.cost.reset(DelayedAtKeyframeFactor<M>::Create(Delayed<M>{model, ctx.Acceleration(pred.x), ctx.BodyRate(pred.x)}));
  g.params = {at.pose.data(), at.vel.data(), &at.td};
  g.kinds = {BlockKind::kPose, BlockKind::kEuclidean, BlockKind::kEuclidean};
  g.sigma = SubCovariance(ctx.keyframes.EstimatedTypes(), pred.cov,
                          {BlockType::kPose, BlockType::kVelocity, BlockType::kTimeOffset});
  return g;
}

// The whitened innovation and its covariance back in the measurement's units, for GateInflation.
void Unwhiten(const FactorCheck& c, const Vec3& sigma, Vec3* innovation, Mat3* S) {
  *innovation = -c.residual.head<3>().cwiseProduct(sigma);
  *S = sigma.asDiagonal() * Mat3(c.S.topLeftCorner<3, 3>()) * sigma.asDiagonal();
}

}  // namespace

ImuEarthTerms AttachContext::EarthTermsAt(const Vec3& p_w) const {
  ImuEarthTerms e;
  e.g_w = earth.Gravity(p_w);
  e.rate_w = earth.rate_w();
  return e;
}

Vec3 AttachContext::BodyRate(const NavState& x) const {
  return last_imu ? Vec3(last_imu->gyro - x.bg - x.q_wb.conjugate() * earth.rate_w()) : Vec3::Zero();
}

Vec3 AttachContext::Acceleration(const NavState& x) const {
  if (!last_imu) return Vec3::Zero();
  return x.q_wb * (last_imu->acc - x.ba) + earth.Gravity(x.p_wb) - 2.0 * earth.rate_w().cross(x.v_w);
}

// --- GNSS -------------------------------------------------------------------------------------------------

GnssAttacher::GnssAttacher(const GnssOptions& gnss, std::function<void(double, bool)> on_checked,
                           std::function<void(double)> on_reacquired)
    : gnss_(gnss),
      on_checked_(std::move(on_checked)),
      on_reacquired_(std::move(on_reacquired)),
      gate_position_(Chi2Gate(gnss.gate_probability, 3)),
      gate_heading_(Chi2Gate(gnss.gate_probability, 1)),
      // A gate of +∞ (probability 0) leaves no corner: then no loss, as the ESKF has none.
      loss_position_(std::isfinite(gate_position_) ? new ceres::HuberLoss(std::sqrt(gate_position_)) : nullptr),
      loss_heading_(std::isfinite(gate_heading_) ? new ceres::HuberLoss(std::sqrt(gate_heading_)) : nullptr),
      consistency_(gnss.gate_probability, 3) {}

// The loss of a position factor accepted under the gate scaled by `scale`: a Huber loss whose corner is that
// gate, so every residual it accepts is inside the quadratic part as at scale 1. One per scale in steps of
// 2^(1/8) (the window's factors keep theirs).
ceres::LossFunction* GnssAttacher::PositionLoss(double scale) {
  if (!(scale > 1.0) || loss_position_ == nullptr) return loss_position_.get();
  const int step = static_cast<int>(std::ceil(8.0 * std::log2(scale)));
  std::unique_ptr<ceres::LossFunction>& loss = scaled_losses_[step];
  if (loss == nullptr) loss.reset(new ceres::HuberLoss(std::sqrt(gate_position_ * std::exp2(step / 8.0))));
  return loss.get();
}

bool GnssAttacher::On(const GnssMeasurement& m, const AttachContext& ctx) {
  const Prediction pred = ctx.predict(m.t);
  const bool position = AttachPosition(m, pred, ctx);
  // A heading attached beside a rejected fix is a measurement too: the window must be solved for it.
  const bool heading = m.heading_valid && gnss_.use_heading && AttachHeading(m, ctx.predict(m.t), ctx);
  return position || heading;
}

ceres::CostFunction* GnssAttacher::PositionFactor(const GnssMeasurement& m, const Prediction& pred, const Anchor& a,
                                                  const AttachContext& ctx, std::vector<BlockRef>* blocks) const {
  if (TimeOffsetEstimated(ctx)) {
    return DelayedFactor(GnssAtTime{m.p_w, m.sigma_w.cwiseInverse(), gnss_.lever_b}, a, pred, ctx, blocks);
  }
  if (a.partial == nullptr) {
    *blocks = {{a.kf, BlockType::kPose}};
    return GnssFactor::Create(m.p_w, m.sigma_w, gnss_.lever_b);
  }
  *blocks = {{a.kf, BlockType::kPose}, {a.kf, BlockType::kVelocity}, {a.kf, BlockType::kBias}};
  return PreintAttachedFactor<GnssAtTime>::Create(a.partial, ctx.EarthTermsAt(pred.x.p_wb),
                                                  GnssAtTime{m.p_w, m.sigma_w.cwiseInverse(), gnss_.lever_b});
}

bool GnssAttacher::AttachPosition(const GnssMeasurement& m, const Prediction& pred, const AttachContext& ctx) {
  const StateBlocks at(pred.x, ctx.keyframes);
  const GateCheck gate =
      TimeOffsetEstimated(ctx)
          ? DelayedCheck(GnssAtTime{m.p_w, m.sigma_w.cwiseInverse(), gnss_.lever_b}, pred, at, ctx)
          : StampCheck(GnssFactor::Create(m.p_w, m.sigma_w, gnss_.lever_b), at, false, pred, ctx);
  const double inflation = inflation_.factor();
  const double scale = consistency_.scale();
  const double bound = gate_position_ * scale;
  const FactorCheck plain = gate.Run();
  const FactorCheck check = inflation > 1.0 ? gate.Run(inflation) : plain;
  if (!check.Passes(bound)) {
    position_counts_.Reject(check.evaluated ? "chi2_gate" : "numerical", m.t);
    if (ctx.keyframes.log() != nullptr && check.evaluated) {
      const Anchor a = ctx.partial(m.t);
      std::vector<BlockRef> blocks;
      ceres::CostFunction* cost = PositionFactor(m, pred, a, ctx, &blocks);
      ctx.keyframes.LogRejected(cost, PositionLoss(scale), blocks, bound);
    }
    if (plain.evaluated) {
      Vec3 innovation;
      Mat3 S;
      Unwhiten(plain, m.sigma_w, &innovation, &S);
      inflation_.Rejected(m.t, innovation, S, bound);
    }
    on_checked_(m.t, false);
    return false;
  }
  if (inflation > 1.0) {
    inflation_.CountReacquired();
    on_reacquired_(inflation);
  } else {
    consistency_.Add(plain.chi2);
  }
  inflation_.Accepted();
  const Anchor a = ctx.anchor(m.t);
  std::vector<BlockRef> blocks;
  ceres::CostFunction* cost = PositionFactor(m, pred, a, ctx, &blocks);
  // A fix that passed only the widened gate is far from the window in R's units: under the Huber loss it
  // would pull with the weight of an outlier and the window could not follow it. It passed the gate: no loss.
  ctx.keyframes.AddMeasurement(cost, inflation > 1.0 ? nullptr : PositionLoss(scale), blocks, bound);
  ++position_counts_.used;
  on_checked_(m.t, true);
  return true;
}

bool GnssAttacher::AttachHeading(const GnssMeasurement& m, const Prediction& pred, const AttachContext& ctx) {
  const StateBlocks at(pred.x, ctx.keyframes);
  const HeadingAtTime model{m.yaw_G, 1.0 / m.sigma_yaw, gnss_.mount_yaw};
  const GateCheck gate =
      TimeOffsetEstimated(ctx)
          ? DelayedCheck(model, pred, at, ctx)
          : StampCheck(HeadingFactor::Create(m.yaw_G, m.sigma_yaw, gnss_.mount_yaw), at, false, pred, ctx);
  const FactorCheck check = gate.Run();
  const auto factor = [&](const Anchor& a, std::vector<BlockRef>* blocks) -> ceres::CostFunction* {
    if (TimeOffsetEstimated(ctx)) return DelayedFactor(model, a, pred, ctx, blocks);
    if (a.partial == nullptr) {
      *blocks = {{a.kf, BlockType::kPose}};
      return HeadingFactor::Create(m.yaw_G, m.sigma_yaw, gnss_.mount_yaw);
    }
    *blocks = {{a.kf, BlockType::kPose}, {a.kf, BlockType::kVelocity}, {a.kf, BlockType::kBias}};
    return PreintAttachedFactor<HeadingAtTime>::Create(a.partial, ctx.EarthTermsAt(pred.x.p_wb), model);
  };
  std::vector<BlockRef> blocks;
  if (!check.Passes(gate_heading_)) {
    heading_counts_.Reject(check.evaluated ? "chi2_gate" : "numerical", m.t);
    if (ctx.keyframes.log() != nullptr && check.evaluated) {
      ceres::CostFunction* cost = factor(ctx.partial(m.t), &blocks);
      ctx.keyframes.LogRejected(cost, loss_heading_.get(), blocks, gate_heading_);
    }
    return false;
  }
  ceres::CostFunction* cost = factor(ctx.anchor(m.t), &blocks);
  ctx.keyframes.AddMeasurement(cost, loss_heading_.get(), blocks, gate_heading_);
  ++heading_counts_.used;
  return true;
}

void GnssAttacher::AddStats(nlohmann::json* stats) const {
  (*stats)["gnss_position"] = position_counts_.ToJson();
  (*stats)["gnss_heading"] = heading_counts_.ToJson();
  (*stats)["gnss_reacquired"] = inflation_.reacquired();
  (*stats)["gnss_gate_scale"] = {{"final", consistency_.scale()}, {"max", consistency_.max_scale()}};
}

// --- GNSS velocity ----------------------------------------------------------------------------------------

GnssVelocityAttacher::GnssVelocityAttacher(const GnssOptions& gnss)
    : lever_b_(gnss.lever_b),
      gate_(Chi2Gate(gnss.gate_probability, 3)),
      loss_(std::isfinite(gate_) ? new ceres::HuberLoss(std::sqrt(gate_)) : nullptr) {}

bool GnssVelocityAttacher::On(const GnssVelocityMeasurement& m, const AttachContext& ctx) {
  const Prediction pred = ctx.predict(m.t);
  const StateBlocks at(pred.x, ctx.keyframes);
  const Vec3 omega_b = ctx.BodyRate(pred.x);
  const GnssVelocityAtTime model{m.v_w, m.sigma_w.cwiseInverse(), omega_b, lever_b_};
  const GateCheck gate =
      TimeOffsetEstimated(ctx)
          ? DelayedCheck(model, pred, at, ctx)
          : StampCheck(GnssVelocityFactor::Create(m.v_w, m.sigma_w, omega_b, lever_b_), at, true, pred, ctx);
  const FactorCheck check = gate.Run();
  if (!check.Passes(gate_)) {
    counts_.Reject(check.evaluated ? "chi2_gate" : "numerical", m.t);
    return false;
  }
  const Anchor a = ctx.anchor(m.t);
  if (TimeOffsetEstimated(ctx)) {
    std::vector<BlockRef> blocks;
    ceres::CostFunction* cost = DelayedFactor(model, a, pred, ctx, &blocks);
    ctx.keyframes.AddFactor(cost, loss_.get(), blocks);
  } else if (a.partial == nullptr) {
    ctx.keyframes.AddFactor(GnssVelocityFactor::Create(m.v_w, m.sigma_w, omega_b, lever_b_), loss_.get(),
                            {{a.kf, BlockType::kPose}, {a.kf, BlockType::kVelocity}});
  } else {
    ctx.keyframes.AddFactor(
        PreintAttachedFactor<GnssVelocityAtTime>::Create(a.partial, ctx.EarthTermsAt(pred.x.p_wb), model),
        loss_.get(), {{a.kf, BlockType::kPose}, {a.kf, BlockType::kVelocity}, {a.kf, BlockType::kBias}});
  }
  ++counts_.used;
  return true;
}

// --- Standstill -------------------------------------------------------------------------------------------

StandstillAttacher::StandstillAttacher(const StandstillOptions& standstill, const ImuOptions& imu,
                                       double gate_probability)
    : standstill_(standstill),
      imu_(imu),
      gate_(Chi2Gate(gate_probability, 3)),
      gate_zero_rate_(Chi2Gate(kZeroRateGateProbability, 3)) {}

bool StandstillAttacher::On(const StandstillMeasurement& m, const AttachContext& ctx) {
  last_ = m;
  Attach(ctx.keyframes.back(), ctx);
  return false;
}

void StandstillAttacher::Attach(Keyframe& kf, const AttachContext& ctx) {
  if (!last_ || standing_.count(kf.id) > 0 || &kf != &ctx.keyframes.back()) return;
  const StandstillMeasurement& s = *last_;
  if (kf.t < s.since || kf.t > s.t + kStandstillReach) return;
  const Prediction pred = ctx.predict(kf.t);
  if (!StandstillPlausible(pred.x.v_w, standstill_)) {
    counts_.Reject("moving", kf.t);  // a quiet IMU at speed: not a stop
    return;
  }
  // Nothing witnesses the stop (an outage without wheels): not while the estimate brakes (estimator_common.h).
  {
    const std::vector<BlockType> types = ctx.keyframes.EstimatedTypes();
    const MatX pose = SubCovariance(types, pred.cov, {BlockType::kPose});
    const Mat3 R_wb = pred.x.R_wb();
    const Mat3 att_w = R_wb * pose.block<3, 3>(pose::kTheta, pose::kTheta) * R_wb.transpose();
    const double sigma_tilt = std::sqrt(std::max(att_w(0, 0), att_w(1, 1)));
    const double sigma_ba = std::sqrt(SubCovariance(types, pred.cov, {BlockType::kBias}).diagonal().tail<3>().maxCoeff());
    if (AcceleratingWithoutWitness(s, pred.x, ctx.earth.Gravity(pred.x.p_wb), sigma_tilt, sigma_ba,
                                   imu_.acc_noise_density)) {
      counts_.Reject("accelerating", kf.t);  // braking smoothly, nothing to say it stopped
      return;
    }
  }
  // A quiet IMU during a smooth start or a constant acceleration can look like a stop: a zero velocity
  // the predicted velocity disagrees with is not taken.
  ZeroVelocityFactor check(standstill_.velocity_sigma);
  const Vec3 v = pred.x.v_w;
  const FactorCheck c = CheckFactor(check, {v.data()}, {BlockKind::kEuclidean},
                                    SubCovariance(ctx.keyframes.EstimatedTypes(), pred.cov, {BlockType::kVelocity}));
  if (!c.Passes(gate_)) {
    counts_.Reject("chi2_gate", kf.t);
    return;
  }
  ctx.keyframes.AddFactor(new ZeroVelocityFactor(standstill_.velocity_sigma), nullptr,
                          {{&kf, BlockType::kVelocity}});
  ++counts_.used;
  standing_[kf.id] = s.since;
  // Two keyframes of one standstill: no translation, and no rotation where the gyro agrees (its 0.1 mm
  // would put any IMU disagreement in the flat part of a robust loss, so only between accepted zero
  // velocities).
  if (ctx.keyframes.size() < 2) return;
  Keyframe& prev = ctx.keyframes[ctx.keyframes.size() - 2];
  if (standing_.count(prev.id) == 0 || prev.t < s.since) return;  // (kf's zero velocity is new: joined once)
  // The rotation stands only where the gyro agrees (estimator_common.h, kZeroRateGateProbability): its mean over
  // the interval, less the bias and the Earth's rate, within its noise and the bias's σ.
  Vec3 integral = Vec3::Zero();
  double span = 0.0;
  for (const HeldImuSample& step : kf.steps_from_prev) {
    integral += step.sample.gyro * step.dt;
    span += step.dt;
  }
  bool turning = true;
  if (span > 0.0) {
    const double sigma = ZeroRateSigma(imu_.gyro_noise_density, span);
    const Vec3 r = pred.x.bg + pred.x.q_wb.conjugate() * ctx.earth.rate_w() - integral / span;
    const Mat3 S = SubCovariance(ctx.keyframes.EstimatedTypes(), pred.cov, {BlockType::kBias}).topLeftCorner<3, 3>() +
                   sigma * sigma * Mat3::Identity();
    const double chi2 = r.dot(S.ldlt().solve(r));
    turning = !(chi2 <= gate_zero_rate_);
  }
  if (turning) {
    zero_rotation_.Reject("chi2_gate", kf.t);
  } else {
    ++zero_rotation_.used;
  }
  const double sigma_theta = turning ? std::numeric_limits<double>::infinity()
                                     : std::max(2.0 * imu_.gyro_noise_density * std::sqrt(kf.t - prev.t), 1e-6);
  ++zero_motion_factors_;
  ctx.keyframes.AddFactor(ZeroMotionFactor::Create(kStandstillPositionSigma, sigma_theta), nullptr,
                          {{&prev, BlockType::kPose}, {&kf, BlockType::kPose}});
  kf.still_from_prev = !turning;  // the outputs between them hold still (zero velocity, no IMU wobble)
}

void StandstillAttacher::OnWindowRebuilt() {
  standing_.clear();
  last_.reset();
}

void StandstillAttacher::AddStats(nlohmann::json* stats) const {
  (*stats)["zero_velocity"] = counts_.ToJson();
  (*stats)["zero_motion_factors"] = zero_motion_factors_;
  (*stats)["zero_rotation"] = zero_rotation_.ToJson();
}

// --- Measurement modules (core/measurement_module.h) ----------------------------------------------------

namespace {

// Module Mod's measurements: the model at the predicted state through the gate, then at its keyframe (pose,
// velocity) or through the IMU preintegrated from it (pose, velocity, biases), with a Huber loss whose corner
// is the gate. The module's measurements are on the IMU's clock: no time offset.
template <class Mod>
class ModuleAttacher final : public AttacherOf<typename Mod::Measurement> {
 public:
  using Model = typename Mod::Model;
  static constexpr int kDim = Model::kResidualDim;

  explicit ModuleAttacher(const typename Mod::Options& options)
      : options_(options),
        gate_(Chi2Gate(options.gate_probability, kDim)),
        loss_(std::isfinite(gate_) ? new ceres::HuberLoss(std::sqrt(gate_)) : nullptr) {}

  bool On(const typename Mod::Measurement& m, const AttachContext& ctx) override {
    const Prediction pred = ctx.predict(m.t);
    const StateBlocks at(pred.x, ctx.keyframes);
    const Model model = Mod::ModelOf(m, options_);
    const FactorCheck check = StampCheck(ModuleFactorAtKeyframe(model), at, true, pred, ctx).Run();
    if (!check.Passes(gate_)) {
      counts_.Reject(check.evaluated ? "chi2_gate" : "numerical", m.t);
      return false;
    }
    const Anchor a = ctx.anchor(m.t);
    if (a.partial == nullptr) {
      ctx.keyframes.AddFactor(ModuleFactorAtKeyframe(model), loss_.get(),
                              {{a.kf, BlockType::kPose}, {a.kf, BlockType::kVelocity}});
    } else {
      ctx.keyframes.AddFactor(ModuleFactorPreint(a.partial, ctx.EarthTermsAt(pred.x.p_wb), model), loss_.get(),
                              {{a.kf, BlockType::kPose}, {a.kf, BlockType::kVelocity}, {a.kf, BlockType::kBias}});
    }
    ++counts_.used;
    return true;
  }
  void AddStats(nlohmann::json* stats) const override { (*stats)[Mod::kName] = counts_.ToJson(); }

 private:
  typename Mod::Options options_;
  double gate_;
  std::unique_ptr<ceres::LossFunction> loss_;
  MeasurementCounts counts_;
};

}  // namespace

void AddModuleAttachers(const SensorOptions& sensors, std::vector<std::unique_ptr<MeasurementAttacher>>* attachers) {
  MeasurementModules::ForEach([&](auto tag) {
    using Mod = typename decltype(tag)::type;
    attachers->push_back(std::make_unique<ModuleAttacher<Mod>>(std::get<typename Mod::Options>(sensors.modules)));
  });
}

}  // namespace gins
