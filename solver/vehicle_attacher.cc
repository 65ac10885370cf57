#include "solver/vehicle_attacher.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/chi2.h"
#include "core/so3.h"
#include "factors/chord_factor.h"
#include "factors/nhc_factor.h"
#include "factors/odometer_factor.h"
#include "factors/wheel_yaw_factor.h"
#include "solver/smoother_gate.h"

namespace gins {
namespace {

// An interval's records must cover this much of it for its odometer factor: a record or two lost to a
// dropout still leaves the distance known to a few percent, wheels that stopped reporting do not.
constexpr double kMinCoverage = 0.9;

// The joint covariance of (pose_i, pose_j[, scale_i]) out of the two keyframes' joint block covariance; a
// scale held constant gets a zero row and column.
MatX PairCovariance(const std::vector<BlockType>& types, const MatX& joint, bool with_scale) {
  std::vector<int> index;
  int per_keyframe = 0, pose = -1, scale = -1;
  for (BlockType t : types) {
    if (t == BlockType::kPose) pose = per_keyframe;
    if (t == BlockType::kScale) scale = per_keyframe;
    per_keyframe += SpecOf(t).tangent_size;
  }
  for (int k = 0; k < pose::kTangent; ++k) index.push_back(pose + k);
  for (int k = 0; k < pose::kTangent; ++k) index.push_back(per_keyframe + pose + k);
  const int n = static_cast<int>(index.size()) + (with_scale ? 1 : 0);
  MatX out = MatX::Zero(n, n);
  if (with_scale && scale >= 0) index.push_back(scale);
  const int m = static_cast<int>(index.size());
  for (int r = 0; r < m; ++r) {
    for (int c = 0; c < m; ++c) out(r, c) = joint(index[r], index[c]);
  }
  return out;
}

}  // namespace

VehicleAttacher::VehicleAttacher(const SensorOptions& options)
    : options_(options),
      gate_nhc_(Chi2Gate(options.wheel.gate_probability, 2)),
      gate_wheel_(Chi2Gate(options.wheel.gate_probability, 1)),
      gate_yaw_(Chi2Gate(options.wheel.gate_probability, 1)) {}

void VehicleAttacher::Add(Accumulator* acc, const WheelMeasurement& m, double fraction, const Quat& dR_mid) {
  const double dt = m.interval * fraction;
  acc->displacement += dR_mid * Vec3(m.distance * fraction, 0.0, 0.0);
  acc->var_distance += std::pow(m.sigma * dt, 2);
  acc->covered += dt;
  if (m.has_yaw_rate) {
    acc->has_yaw = true;
    acc->yaw += m.yaw_rate * dt;
    acc->var_yaw += std::pow(m.yaw_rate_sigma * dt, 2);
  }
}

bool VehicleAttacher::On(const WheelMeasurement& m, const AttachContext& ctx) {
  if (!options_.wheel.enabled || !open_ || m.interval <= 0.0) return false;
  ++wheel_records_;
  const double a = m.t - m.interval;  // the record counts over (a, m.t]
  double from = std::max(a, open_->t0);
  // The part before the newest keyframe belongs to the interval that keyframe closed.
  if (closing_ && a < *closing_t1_) {
    const double end = std::min(m.t, *closing_t1_);
    const double lo = std::max(a, closing_->t0);
    const Keyframe& newest = ctx.keyframes.back();
    const Quat dR = newest.preint != nullptr ? newest.preint->dq() : Quat::Identity();
    if (end > lo) Add(&*closing_, m, (end - lo) / m.interval, dR);
    from = std::max(from, *closing_t1_);
  }
  if (m.t <= from) return false;
  // The attitude at the middle of this part, relative to the newest keyframe: the IMU's, turned back from
  // now by the body rate.
  const Keyframe& newest = ctx.keyframes.back();
  const NavState x = newest.State();
  const double mid = 0.5 * (from + m.t);
  const NavState now = ctx.predict_state(m.t);
  const Quat dR_now = x.q_wb.conjugate() * now.q_wb;
  const Quat dR_mid = dR_now * ExpQuat<double>(Vec3(-ctx.BodyRate(now) * (m.t - mid)));
  Add(&*open_, m, (m.t - from) / m.interval, dR_mid);
  return false;
}

void VehicleAttacher::OnImuStep(const ImuStepView& step) {
  if (!options_.vehicle.nonholonomic) return;
  // The axle's forward speed at the step's ends, along the body x axis there (trapezoid rule).
  const Vec3& lever = options_.wheel.lever_b;
  const Vec3 turn = step.omega_b.cross(lever);
  path_ += 0.5 * step.dt *
           ((step.v_b_begin + turn).x() * (step.dR_begin * Vec3::UnitX()) +
            (step.v_b_end + turn).x() * (step.dR_end * Vec3::UnitX()));
}

void VehicleAttacher::OnKeyframeCreated(Keyframe& kf, const AttachContext& ctx) {
  const size_t n = ctx.keyframes.size();
  if (n >= 2) {
    // The interval the previous keyframe closed has had its straddling record by now.
    AttachOdometry(ctx);
    if (options_.vehicle.nonholonomic) AttachChord(ctx.keyframes[n - 2], kf, ctx);
  }
  path_.setZero();
  if (options_.vehicle.nonholonomic) AttachNonHolonomic(kf, ctx);
  if (open_) {
    closing_ = open_;
    closing_t1_ = kf.t;
  }
  open_ = Accumulator{kf.id, kf.t};
}

void VehicleAttacher::AttachNonHolonomic(Keyframe& kf, const AttachContext& ctx) {
  const Prediction pred = ctx.predict(kf.t);
  const Vec3 omega_b = ctx.BodyRate(pred.x);
  ceres::CostFunction* cost = NhcFactor::Create(options_.vehicle.nhc_sigma, omega_b, options_.wheel.lever_b);
  const double* pose = kf.block(BlockType::kPose);
  const double* vel = kf.block(BlockType::kVelocity);
  const FactorCheck c =
      CheckFactor(*cost, {pose, vel}, {BlockKind::kPose, BlockKind::kEuclidean},
                  SubCovariance(ctx.keyframes.EstimatedTypes(), pred.cov, {BlockType::kPose, BlockType::kVelocity}));
  if (!c.Passes(gate_nhc_)) {
    delete cost;
    nhc_counts_.Reject(c.evaluated ? "chi2_gate" : "numerical", kf.t);
    return;
  }
  ctx.keyframes.AddFactor(cost, nullptr, {{&kf, BlockType::kPose}, {&kf, BlockType::kVelocity}});
  ++nhc_counts_.used;
}

void VehicleAttacher::AttachChord(Keyframe& prev, Keyframe& kf, const AttachContext& ctx) {
  const MatX* two = ctx.newest_two_cov();
  const double dt = kf.t - prev.t;
  if (two == nullptr || dt <= 0.0 || kf.preint == nullptr) return;
  // prev was the newest keyframe at the last solve: its covariance is the lower-right of the joint one, and
  // kf is predicted from it.
  const std::vector<BlockType> types = ctx.keyframes.EstimatedTypes();
  const int per = static_cast<int>(two->rows()) / 2;
  MatX joint;
  PredictBlockCovariance(types, two->bottomRightCorner(per, per), prev.State(), *kf.preint, options_, &joint);
  // The constraint's noise is white at vehicle.nhc_rate_hz (as the ESKF applies it): over the interval its
  // mean has the σ of rate·Δt samples averaged.
  const double sigma = options_.vehicle.nhc_sigma / std::sqrt(std::max(1.0, options_.vehicle.nhc_rate * dt));
  ceres::CostFunction* cost = ChordFactor::Create(dt, sigma, options_.wheel.lever_b, path_);
  const FactorCheck c = CheckFactor(*cost, {prev.block(BlockType::kPose), kf.block(BlockType::kPose)},
                                    {BlockKind::kPose, BlockKind::kPose}, PairCovariance(types, joint, false));
  if (!c.Passes(gate_nhc_)) {
    delete cost;
    chord_counts_.Reject(c.evaluated ? "chi2_gate" : "numerical", kf.t);
    return;
  }
  ctx.keyframes.AddFactor(cost, nullptr, {{&prev, BlockType::kPose}, {&kf, BlockType::kPose}});
  ++chord_counts_.used;
}

void VehicleAttacher::AttachOdometry(const AttachContext& ctx) {
  if (!closing_ || !closing_t1_) return;
  const Accumulator acc = *closing_;
  const double t1 = *closing_t1_;
  closing_.reset();
  closing_t1_.reset();
  const size_t n = ctx.keyframes.size();
  if (n < 3) return;
  Keyframe& i = ctx.keyframes[n - 3];
  Keyframe& j = ctx.keyframes[n - 2];
  if (i.id != acc.from || std::abs(j.t - t1) > 1e-9 || acc.covered <= 0.0) return;
  if (acc.covered < kMinCoverage * (t1 - acc.t0)) {
    odometer_counts_.Reject("incomplete", t1);
    return;
  }
  const MatX* two = ctx.newest_two_cov();
  if (two == nullptr) return;
  const std::vector<BlockType> types = ctx.keyframes.EstimatedTypes();
  const MatX sigma = PairCovariance(types, *two, true);  // a scale held constant: zero row and column
  // At least a millimetre: a standstill's zero distance is not infinitely certain.
  const double sigma_d = std::max(std::sqrt(acc.var_distance), 1e-3);
  ceres::CostFunction* odo = OdometerFactor::Create(acc.displacement, sigma_d, options_.wheel.lever_b);
  const std::vector<const double*> params = {i.block(BlockType::kPose), j.block(BlockType::kPose),
                                             i.block(BlockType::kScale)};
  const std::vector<BlockKind> kinds = {BlockKind::kPose, BlockKind::kPose, BlockKind::kEuclidean};
  const FactorCheck c = CheckFactor(*odo, params, kinds, sigma);
  if (c.Passes(gate_wheel_)) {
    ctx.keyframes.AddFactor(odo, nullptr, {{&i, BlockType::kPose}, {&j, BlockType::kPose}, {&i, BlockType::kScale}});
    ++odometer_counts_.used;
  } else {
    delete odo;
    odometer_counts_.Reject(c.evaluated ? "chi2_gate" : "numerical", t1);
  }
  if (!acc.has_yaw) return;
  ceres::CostFunction* yaw = WheelYawFactor::Create(acc.yaw, std::max(std::sqrt(acc.var_yaw), 1e-6));
  const FactorCheck cy = CheckFactor(*yaw, params, kinds, sigma);
  if (cy.Passes(gate_yaw_)) {
    ctx.keyframes.AddFactor(yaw, nullptr, {{&i, BlockType::kPose}, {&j, BlockType::kPose}, {&i, BlockType::kScale}});
    ++yaw_counts_.used;
  } else {
    delete yaw;
    yaw_counts_.Reject(cy.evaluated ? "chi2_gate" : "numerical", t1);
  }
}

void VehicleAttacher::OnWindowRebuilt() {
  path_.setZero();
  open_.reset();
  closing_.reset();
  closing_t1_.reset();
}

void VehicleAttacher::AddStats(nlohmann::json* stats) const {
  (*stats)["wheel"] = odometer_counts_.ToJson();
  (*stats)["wheel"]["records"] = wheel_records_;
  (*stats)["wheel_yaw_rate"] = yaw_counts_.ToJson();
  (*stats)["nonholonomic"] = nhc_counts_.ToJson();
  (*stats)["nonholonomic_chord"] = chord_counts_.ToJson();
}

}  // namespace gins
