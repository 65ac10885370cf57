#include "solver/smoother_attachers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/chi2.h"
#include "factors/gnss_factor.h"
#include "factors/gvel_factor.h"
#include "factors/heading_factor.h"
#include "factors/nhc_factor.h"
#include "factors/wheel_factor.h"
#include "factors/zero_motion_factor.h"
#include "factors/zero_velocity_factor.h"

namespace gins {
namespace {

// Standstill: displacement 1-σ between two keyframes of one standstill, and how far a keyframe may lie after
// the last standstill detection (sent every 0.1 s) and still count as standing.
constexpr double kStandstillPositionSigma = 1e-4;  // m
constexpr double kStandstillReach = 0.15;          // s
constexpr double kStandstillLossScale = 3.0;       // Cauchy loss scale on the whitened standstill residuals
constexpr double kSameEpoch = 1e-6;                // s: a measurement at a keyframe's time belongs to it

// Squared norm of a 3-dimensional residual block's residual, without its loss.
double SquaredResidual(ceres::Problem* problem, ceres::ResidualBlockId id) {
  double cost = 0.0;
  Vec3 r;
  problem->EvaluateResidualBlock(id, /*apply_loss_function=*/false, &cost, r.data(), nullptr);
  return r.squaredNorm();
}

}  // namespace

// --- GNSS velocity -------------------------------------------------------------------------------------------

void GvelAttacher::OnGvel(const GvelMeasurement& m, const AttachContext& ctx) {
  Keyframe& kf = ctx.keyframes.back();
  if (std::abs(m.t - kf.t) > kSameEpoch) {
    counts_.Reject("no_keyframe", m.t);
    return;
  }
  const NavState x = kf.State();
  const Vec3 omega_b = ctx.last_imu ? Vec3(ctx.last_imu->gyro - x.bg) : Vec3::Zero();
  ctx.keyframes.AddFactor(GvelFactor::Create(m.v_w, m.sigma_w, omega_b, options_.gnss.lever_b), nullptr,
                          {{&kf, BlockType::kPose}, {&kf, BlockType::kVelocity}});
  ++counts_.used;
}

// --- GNSS -------------------------------------------------------------------------------------------------

GnssAttacher::GnssAttacher(const EstimatorOptions& options, std::function<void(double, bool)> on_checked)
    : options_(options),
      on_checked_(std::move(on_checked)),
      gate_(Chi2Gate(options.gnss.gate_probability, 3)),
      loss_(std::make_unique<ceres::CauchyLoss>(options.smoother.gnss_loss_scale)) {}

bool GnssAttacher::OnGnss(const GnssMeasurement& m, const AttachContext& ctx) {
  Keyframe& kf = ctx.keyframes.back();
  Record& record = records_[kf.id];
  if (record.position_id != nullptr) return false;  // one fix per epoch
  record.position_id = ctx.keyframes.AddFactor(GnssFactor::Create(m.p_w, m.sigma_w, options_.gnss.lever_b), loss_.get(),
                                               {{&kf, BlockType::kPose}});
  if (m.heading_valid && options_.gnss.use_heading) {
    ctx.keyframes.AddFactor(HeadingFactor::Create(m.yaw_G, m.sigma_yaw, options_.gnss.mount_yaw), loss_.get(),
                            {{&kf, BlockType::kPose}});
    ++heading_counts_.used;
  }
  return true;
}

bool GnssAttacher::AfterSolve(const AttachContext& ctx) {
  const Keyframe& kf = ctx.keyframes.back();
  auto it = records_.find(kf.id);
  if (it == records_.end()) return false;
  Record& record = it->second;
  if (record.position_id == nullptr || record.checked) return false;
  record.checked = true;
  if (SquaredResidual(ctx.keyframes.problem(), record.position_id) > gate_) {
    // An outlier the robust loss only damped: take it out and solve again without it.
    ctx.keyframes.problem()->RemoveResidualBlock(record.position_id);
    record.position_id = nullptr;
    position_counts_.Reject("chi2_gate", kf.t);
    on_checked_(kf.t, false);
    return true;
  }
  ++position_counts_.used;
  on_checked_(kf.t, true);
  return false;
}

void GnssAttacher::AddStats(nlohmann::json* stats) const {
  (*stats)["gnss_position"] = position_counts_.ToJson();
  (*stats)["gnss_heading"] = heading_counts_.ToJson();
}

// --- Wheel ------------------------------------------------------------------------------------------------

void WheelAttacher::OnWheel(const WheelMeasurement& m, const AttachContext& ctx) {
  if (!options_.wheel.enabled) return;
  last_wheel_ = m;
  Attach(ctx.keyframes.back(), ctx);
}

void WheelAttacher::Attach(Keyframe& kf, const AttachContext& ctx) {
  if (!options_.wheel.enabled || attached_to_ == kf.id || !last_wheel_) return;
  const WheelMeasurement& w = *last_wheel_;
  const double t_mid = w.t - 0.5 * w.interval;
  const double offset = kf.t - t_mid;
  if (std::abs(offset) > std::max(w.interval, 1e-3)) return;
  attached_to_ = kf.id;
  // The encoders give the mean speed over their interval; move it to the keyframe's time with the
  // forward acceleration from the IMU.
  double speed = w.speed;
  if (ctx.last_imu) {
    const NavState x = kf.State();
    const Vec3 a_b = (ctx.last_imu->acc - x.ba) + x.q_wb.conjugate() * ctx.g_w;
    speed += a_b.x() * offset;
  }
  ctx.keyframes.AddFactor(WheelFactor::Create(speed, w.sigma), nullptr,
                          {{&kf, BlockType::kPose}, {&kf, BlockType::kVelocity}, {&kf, BlockType::kScale}});
  if (options_.wheel.nonholonomic) {
    ctx.keyframes.AddFactor(NhcFactor::Create(options_.wheel.nhc_sigma), nullptr,
                            {{&kf, BlockType::kPose}, {&kf, BlockType::kVelocity}});
  }
  ++counts_.used;
}

void WheelAttacher::AddStats(nlohmann::json* stats) const { (*stats)["wheel"] = counts_.ToJson(); }

// --- Standstill -------------------------------------------------------------------------------------------

StandstillAttacher::StandstillAttacher(const EstimatorOptions& options)
    : options_(options),
      gate_(Chi2Gate(options.wheel.gate_probability, 3)),  // standstill.* has no gate of its own: the wheel's
      loss_(std::make_unique<ceres::CauchyLoss>(kStandstillLossScale)) {}

const StandstillAttacher::Record* StandstillAttacher::Find(uint64_t id) const {
  auto it = records_.find(id);
  return it != records_.end() ? &it->second : nullptr;
}

void StandstillAttacher::OnStandstill(const StandstillMeasurement& m, const AttachContext& ctx) {
  last_ = m;
  Attach(ctx.keyframes.back(), ctx);
}

void StandstillAttacher::Attach(Keyframe& kf, const AttachContext& ctx) {
  const Record* existing = Find(kf.id);
  if (!last_ || (existing != nullptr && existing->standstill) || &kf != &ctx.keyframes.back()) return;
  const StandstillMeasurement& s = *last_;
  if (kf.t < s.since || kf.t > s.t + kStandstillReach) return;
  if (!StandstillPlausible(kf.State().v_w, options_.standstill)) {
    counts_.Reject("moving", kf.t);  // a quiet IMU at speed: not a stop
    return;
  }
  Record& record = records_[kf.id];
  record.standstill = true;
  record.since = s.since;
  // Robust like the GNSS factors, so that a wrong detection cannot bend the window to itself before the χ²
  // check (AfterSolve) takes it out.
  record.zupt_id = ctx.keyframes.AddFactor(new ZeroVelocityFactor(options_.standstill.velocity_sigma), loss_.get(),
                                           {{&kf, BlockType::kVelocity}});
}

bool StandstillAttacher::AfterSolve(const AttachContext& ctx) {
  // A quiet IMU during a smooth start or a constant acceleration can look like a stop: a zero velocity the
  // other measurements disagree with (χ² on its whitened residual after the solve) is taken out again, and
  // the window solved without it. (No zero-motion factor can be on it: those join confirmed ones only.)
  KeyframeStore& keyframes = ctx.keyframes;
  bool removed = false;
  for (size_t i = 0; i < keyframes.size(); ++i) {
    Keyframe& kf = keyframes[i];
    auto it = records_.find(kf.id);
    if (it == records_.end()) continue;
    Record& record = it->second;
    if (record.zupt_id == nullptr || record.checked) continue;
    record.checked = true;
    if (SquaredResidual(keyframes.problem(), record.zupt_id) <= gate_) {
      ++counts_.used;
      record.ok = true;
      // Two confirmed keyframes of one standstill: no translation, no rotation in between. Not robust (its
      // 0.1 mm would put any IMU disagreement in the flat part of a robust loss), so only between confirmed
      // zero velocities; it joins at the next solve.
      Keyframe* prev = i > 0 ? &keyframes[i - 1] : nullptr;
      const Record* prev_record = prev != nullptr ? Find(prev->id) : nullptr;
      if (prev_record != nullptr && prev_record->ok && prev->t >= record.since && !kf.still_from_prev) {
        const double sigma_theta = std::max(2.0 * options_.imu.gyro_noise_density * std::sqrt(kf.t - prev->t), 1e-6);
        ++zero_motion_factors_;
        keyframes.AddFactor(ZeroMotionFactor::Create(kStandstillPositionSigma, sigma_theta), nullptr,
                            {{prev, BlockType::kPose}, {&kf, BlockType::kPose}});
        kf.still_from_prev = true;
      }
      continue;
    }
    counts_.Reject("chi2_gate", kf.t);
    keyframes.problem()->RemoveResidualBlock(record.zupt_id);
    record.zupt_id = nullptr;
    record.standstill = false;
    removed = true;
  }
  return removed;
}

void StandstillAttacher::OnWindowRebuilt() {
  last_.reset();
  records_.clear();
}

void StandstillAttacher::AddStats(nlohmann::json* stats) const {
  (*stats)["zero_velocity"] = counts_.ToJson();
  (*stats)["zero_motion_factors"] = zero_motion_factors_;
}

}  // namespace gins
