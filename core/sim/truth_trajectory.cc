// TruthTrajectory: the exact motion of a simulated drive (core/sim/simulator.h).
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/sim/sim_internal.h"
#include "core/sim/simulator.h"

namespace gins {
namespace {

using sim_internal::FiniteNonNegative;
using sim_internal::kTimeTolerance;
using sim_internal::Require;

// Accelerations and yaw rates move to a segment's values over this time (or the segment, if shorter).
constexpr double kTransitionTime = 1.0;
// Largest quadrature interval between knots (s). 3-point Gauss–Legendre is exact to degree 5, so the
// position error per interval is ~h⁷·|v⁽⁶⁾|·1e-6: round-off level here.
constexpr double kKnotStep = 0.01;
// Breaks closer than this are one break.
constexpr double kBreakTolerance = 1e-9;
// Below this speed (m/s) a vehicle counts as stopped for a change of gear: a stop reached exactly at a
// ramp's end leaves round-off, not motion.
constexpr double kStoppedSpeed = 1e-6;

// ∫_a^b f(s) ds by 3-point Gauss–Legendre; f smooth on [a, b].
template <typename F>
auto GaussLegendre3(double a, double b, const F& f) -> decltype(f(a)) {
  static const double kNode = std::sqrt(0.6);
  const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
  return half * ((5.0 / 9.0) * f(mid - half * kNode) + (8.0 / 9.0) * f(mid) + (5.0 / 9.0) * f(mid + half * kNode));
}

// First s in (lo, hi] where pred(s) holds, for pred false at lo and true at hi and monotone between.
template <typename P>
double FirstTrue(double lo, double hi, const P& pred) {
  for (int i = 0; i < 200 && hi - lo > 1e-13 * std::max(1.0, std::abs(hi)); ++i) {
    const double mid = 0.5 * (lo + hi);
    (pred(mid) ? hi : lo) = mid;
  }
  return hi;
}

const GeodeticPoint& CheckedOrigin(const GeodeticPoint& o) {
  Require(IsPlausibleGeodetic(o.lat_deg, o.lon_deg, o.alt_m), "origin is not a plausible lat, lon, alt");
  return o;
}

}  // namespace

NavState TruthState::ToNavState() const {
  NavState x;
  x.t = t;
  x.p_wb = p_wb;
  x.v_w = v_w;
  x.q_wb = q_wb;
  return x;
}

void TruthTrajectory::Profile::Add(double t0, double ramp, double value) {
  Piece p{t0, ramp, 0.0, value, 0.0};
  if (!pieces_.empty()) {
    p.from = pieces_.back().to;
    p.integral0 = Integral(t0);
  }
  pieces_.push_back(p);
}

const TruthTrajectory::Profile::Piece& TruthTrajectory::Profile::Find(double s) const {
  auto it = std::upper_bound(pieces_.begin(), pieces_.end(), s,
                             [](double v, const Piece& p) { return v < p.t0; });
  return it == pieces_.begin() ? *it : *(it - 1);
}

double TruthTrajectory::Profile::Value(double s) const {
  const Piece& p = Find(s);
  const double d = std::max(0.0, s - p.t0);
  if (d >= p.ramp) return p.to;
  return p.from + (p.to - p.from) * 0.5 * (1.0 - std::cos(kPi * d / p.ramp));
}

double TruthTrajectory::Profile::Rate(double s) const {
  const Piece& p = Find(s);
  const double d = std::max(0.0, s - p.t0);
  if (d >= p.ramp) return 0.0;
  return (p.to - p.from) * 0.5 * kPi / p.ramp * std::sin(kPi * d / p.ramp);
}

double TruthTrajectory::Profile::RateOfRate(double s) const {
  const Piece& p = Find(s);
  const double d = std::max(0.0, s - p.t0);
  if (d >= p.ramp) return 0.0;
  return (p.to - p.from) * 0.5 * (kPi / p.ramp) * (kPi / p.ramp) * std::cos(kPi * d / p.ramp);
}

double TruthTrajectory::Profile::Integral(double s) const {
  const Piece& p = Find(s);
  const double d = std::max(0.0, s - p.t0);
  const double delta = p.to - p.from;
  if (d < p.ramp) return p.integral0 + p.from * d + 0.5 * delta * (d - p.ramp / kPi * std::sin(kPi * d / p.ramp));
  return p.integral0 + p.from * p.ramp + 0.5 * delta * p.ramp + p.to * (d - p.ramp);
}

std::vector<double> TruthTrajectory::Profile::Breaks() const {
  std::vector<double> b;
  for (const Piece& p : pieces_) {
    b.push_back(p.t0);
    b.push_back(p.t0 + p.ramp);
  }
  return b;
}

TruthTrajectory::TruthTrajectory(const SimOptions& sim)
    : start_time_(sim.start_time), initial_yaw_(sim.initial_yaw), frame_(CheckedOrigin(sim.origin)) {
  Require(std::isfinite(sim.start_time) && std::isfinite(sim.initial_yaw), "start_time, initial_yaw must be finite");
  Require(sim.wheel_lever_b.allFinite(), "wheel_lever_b must be finite");
  imu_from_axle_b_ = -sim.wheel_lever_b;
  double t0 = 0.0;
  std::vector<std::string> names;  // of the segments in gears_, for error messages
  for (unsigned lap = 0; lap < sim.repeat; ++lap) {
    for (size_t i = 0; i < sim.segments.size(); ++i) {
      const SimSegment& seg = sim.segments[i];
      Require(FiniteNonNegative(seg.duration) && std::isfinite(seg.accel) && std::isfinite(seg.yaw_rate) &&
                  std::isfinite(seg.grade) && std::abs(seg.grade) < 0.5 * kPi,
              "segments need finite duration >= 0, accel, yaw_rate and |grade| < 90 deg");
      if (seg.duration == 0.0) continue;  // nothing happens in it
      const double ramp = std::min(kTransitionTime, seg.duration);
      accel_.Add(t0, ramp, seg.accel);
      yaw_rate_.Add(t0, ramp, seg.yaw_rate);
      grade_.Add(t0, seg.duration, seg.grade);
      gears_.push_back(Gear{t0, seg.reverse});
      const std::string lap_name = lap > 0 ? " (lap " + std::to_string(lap + 1) + ")" : "";
      names.push_back("segments[" + std::to_string(i) + "]" + lap_name);
      t0 += seg.duration;
    }
  }
  Require(t0 > 0.0, "segments must have a positive total duration");
  duration_ = t0;
  g_w_ = GravityWorld(NormalGravity(sim.origin.lat_deg, sim.origin.alt_m));

  ComputeSpeedPhases();
  CheckGearChanges(names);

  // Knots: every break of smoothness, then at most kKnotStep apart.
  std::vector<double> breaks = {0.0, duration_};
  for (const Profile* p : {&accel_, &yaw_rate_, &grade_}) {
    const std::vector<double> b = p->Breaks();
    breaks.insert(breaks.end(), b.begin(), b.end());
  }
  for (const SpeedPhase& ph : phases_) breaks.push_back(ph.t0);
  std::sort(breaks.begin(), breaks.end());
  std::vector<double> unique;
  for (double b : breaks) {
    if (b < 0.0 || b > duration_) continue;
    if (unique.empty() || b - unique.back() > kBreakTolerance) unique.push_back(b);
  }
  unique.back() = duration_;
  knots_.push_back(0.0);
  for (size_t i = 1; i < unique.size(); ++i) {
    const double a = unique[i - 1], b = unique[i];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a) / kKnotStep)));
    for (int k = 1; k < n; ++k) knots_.push_back(a + (b - a) * k / n);
    knots_.push_back(b);
  }
  knot_p_.assign(knots_.size(), Vec3::Zero());
  const auto vel = [this](double s) { return Velocity(s); };
  for (size_t i = 1; i < knots_.size(); ++i) {
    knot_p_[i] = knot_p_[i - 1] + GaussLegendre3(knots_[i - 1], knots_[i], vel);
  }
}

// The speed integrates the commanded acceleration, reflected at zero. Between the accel profile's breaks
// the acceleration is monotone, which makes each stop and go time a bracketed root.
void TruthTrajectory::ComputeSpeedPhases() {
  const auto accel = [this](double s) { return accel_.Value(s); };
  phases_ = {SpeedPhase{0.0, false, 0.0}};
  std::vector<double> breaks = accel_.Breaks();
  breaks.push_back(duration_);
  std::sort(breaks.begin(), breaks.end());
  for (size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double lo = breaks[i], hi = std::min(breaks[i + 1], duration_);
    if (hi <= lo) continue;
    double c = lo;
    // At most a go, a stop and a go per monotone piece; the bound guards against round-off cycling.
    for (int iter = 0; iter < 4; ++iter) {
      const double a_c = accel(c), a_hi = accel(hi);
      if (!phases_.back().moving) {
        if (a_c <= 0.0 && a_hi <= 0.0) break;  // stays stopped
        const double t_go = a_c > 0.0 ? c : FirstTrue(c, hi, [&](double s) { return accel(s) > 0.0; });
        phases_.push_back(SpeedPhase{t_go, true, accel_.Integral(t_go)});
        c = t_go;
      } else {
        if (a_c >= 0.0 && a_hi >= 0.0) break;  // speed does not decrease
        const double a0 = phases_.back().a0;
        const auto speed = [&](double s) { return accel_.Integral(s) - a0; };
        // Speed is lowest where the (increasing) acceleration crosses zero, or at the end of the piece.
        const double t_min =
            (a_c < 0.0 && a_hi > 0.0) ? FirstTrue(c, hi, [&](double s) { return accel(s) > 0.0; }) : hi;
        if (speed(t_min) >= 0.0) break;
        const double t_stop = FirstTrue(c, t_min, [&](double s) { return speed(s) < 0.0; });
        phases_.push_back(SpeedPhase{t_stop, false, 0.0});
        c = t_stop;
      }
    }
  }
}

const TruthTrajectory::SpeedPhase& TruthTrajectory::Phase(double s) const {
  auto it = std::upper_bound(phases_.begin(), phases_.end(), s,
                             [](double v, const SpeedPhase& p) { return v < p.t0; });
  return *(it - 1);  // phases_[0].t0 == 0 and s ≥ 0
}

void TruthTrajectory::CheckGearChanges(const std::vector<std::string>& names) const {
  for (size_t i = 1; i < gears_.size(); ++i) {
    if (gears_[i].reverse == gears_[i - 1].reverse) continue;
    const double speed = Speed(gears_[i].t0);
    if (speed <= kStoppedSpeed) continue;
    char what[160];
    std::snprintf(what, sizeof(what), " (reverse: %s) changes gear at %.3f s while moving at %.3f m/s",
                  gears_[i].reverse ? "true" : "false", gears_[i].t0, speed);
    Require(false, names[i] + what + ": the gear changes only at a standstill (brake to a stop before it)");
  }
}

bool TruthTrajectory::Reverse(double s) const {
  auto it = std::upper_bound(gears_.begin(), gears_.end(), s, [](double v, const Gear& g) { return v < g.t0; });
  return it == gears_.begin() ? gears_.front().reverse : (it - 1)->reverse;
}

double TruthTrajectory::Speed(double s) const {
  const SpeedPhase& ph = Phase(s);
  return ph.moving ? std::max(0.0, accel_.Integral(s) - ph.a0) : 0.0;
}

Vec3 TruthTrajectory::Velocity(double s) const {
  const double yaw = Yaw(s), pitch = grade_.Value(s);
  const double v = Reverse(s) ? -Speed(s) : Speed(s);  // along the body x axis
  return v * Vec3(std::cos(yaw) * std::cos(pitch), std::sin(yaw) * std::cos(pitch), std::sin(pitch));
}

size_t TruthTrajectory::KnotIndex(double s) const {
  const auto it = std::upper_bound(knots_.begin(), knots_.end(), s);
  const size_t i = it == knots_.begin() ? 0 : static_cast<size_t>(it - knots_.begin()) - 1;
  return std::min(i, knots_.size() - 2);
}

TruthState TruthTrajectory::AtElapsed(double s) const {
  CHECK(s >= -kTimeTolerance && s <= duration_ + kTimeTolerance)
      << "truth queried at " << s << " s, outside [0, " << duration_ << "]";
  s = std::clamp(s, 0.0, duration_);
  const double yaw = Yaw(s), yaw_rate = yaw_rate_.Value(s);
  const double pitch = grade_.Value(s), pitch_rate = grade_.Rate(s);
  const double cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch), sp = std::sin(pitch);
  const SpeedPhase& ph = Phase(s);
  const double speed = Speed(s);
  const double speed_rate = ph.moving ? accel_.Value(s) : 0.0;
  // Velocity along the body x axis and its rate: backwards in reverse.
  const bool reverse = Reverse(s);
  const double v_x = reverse ? -speed : speed, a_x = reverse ? -speed_rate : speed_rate;

  const Vec3 x_b_w(cy * cp, sy * cp, sp);  // body x axis in w
  const Vec3 dx_dyaw(-sy * cp, cy * cp, 0.0), dx_dpitch(-cy * sp, -sy * sp, cp);

  TruthState x;
  x.t = start_time_ + s;
  const size_t k = KnotIndex(s);
  x.p_wb = knot_p_[k] + GaussLegendre3(knots_[k], s, [this](double u) { return Velocity(u); });
  x.v_w = v_x * x_b_w;
  x.q_wb = Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ())) * Quat(Eigen::AngleAxisd(-pitch, Vec3::UnitY()));
  // ω_w = yaw_rate·e_z − pitch_rate·Rz(yaw)·e_y, expressed in b.
  x.omega_b = Vec3(yaw_rate * sp, -pitch_rate, yaw_rate * cp);
  x.a_w = a_x * x_b_w + v_x * (yaw_rate * dx_dyaw + pitch_rate * dx_dpitch);
  x.speed = speed;
  x.reverse = reverse;
  if (!imu_from_axle_b_.isZero()) {
    // The path is the axle's; the IMU is the rigid point l = imu_from_axle_b_ from it:
    // p + R·l, v + R·(ω × l), a + R·(ω̇ × l + ω × (ω × l)), with ω̇ the derivative of ω_b above.
    const Vec3& l = imu_from_axle_b_;
    const double yaw_acc = yaw_rate_.Rate(s), pitch_acc = grade_.RateOfRate(s);
    const Vec3 omega_dot_b(yaw_acc * sp + yaw_rate * cp * pitch_rate, -pitch_acc,
                           yaw_acc * cp - yaw_rate * sp * pitch_rate);
    x.p_wb += x.q_wb * l;
    x.v_w += x.q_wb * x.omega_b.cross(l);
    x.a_w += x.q_wb * (omega_dot_b.cross(l) + x.omega_b.cross(x.omega_b.cross(l)));
  }
  return x;
}

Vec2 TruthTrajectory::IntegrateSpeedAndYawRate(double s0, double s1) const {
  CHECK(s0 <= s1);
  s0 = std::clamp(s0, 0.0, duration_);
  s1 = std::clamp(s1, 0.0, duration_);
  const auto f = [this](double s) {
    return Vec2(Reverse(s) ? -Speed(s) : Speed(s), yaw_rate_.Value(s) * std::cos(grade_.Value(s)));
  };
  Vec2 sum = Vec2::Zero();
  // Integrate knot interval by knot interval: the integrand is smooth within each.
  for (size_t k = KnotIndex(s0); k + 1 < knots_.size() && knots_[k] < s1; ++k) {
    const double a = std::max(s0, knots_[k]), b = std::min(s1, knots_[k + 1]);
    if (b > a) sum += GaussLegendre3(a, b, f);
  }
  return sum;
}

}  // namespace gins
