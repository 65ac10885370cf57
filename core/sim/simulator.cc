#include "core/sim/simulator.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <system_error>

#include "core/io/trajectory_writer.h"

namespace gins {
namespace {

// Accelerations and yaw rates move to a segment's values over this time (or the segment, if shorter).
constexpr double kTransitionTime = 1.0;
// Largest quadrature interval between knots (s). 3-point Gauss–Legendre is exact to degree 5, so the
// position error per interval is ~h⁷·|v⁽⁶⁾|·1e-6: round-off level here.
constexpr double kKnotStep = 0.01;
// Breaks closer than this are one break.
constexpr double kBreakTolerance = 1e-9;
// Sample times may exceed the duration by round-off.
constexpr double kTimeTolerance = 1e-9;

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

void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("simulate: " + what);
}

bool FiniteNonNegative(double v) { return std::isfinite(v) && v >= 0.0; }

void ValidateSensors(const SimOptions& sim) {
  Require(std::isfinite(sim.imu_rate) && sim.imu_rate > 0.0, "imu_rate must be > 0");
  Require(FiniteNonNegative(sim.gnss_rate), "gnss_rate must be >= 0 (0 = off)");
  Require(FiniteNonNegative(sim.wheel_rate), "wheel_rate must be >= 0 (0 = off)");
  for (double v : {sim.gyro_noise_density, sim.acc_noise_density, sim.gyro_bias_rw, sim.acc_bias_rw,
                   sim.gyro_turn_on_bias, sim.acc_turn_on_bias, sim.heading_sigma, sim.gnss_outlier_magnitude,
                   sim.wheel_speed_noise, sim.gnss_sigma_enu.x(), sim.gnss_sigma_enu.y(), sim.gnss_sigma_enu.z()}) {
    Require(FiniteNonNegative(v), "noise levels and σ must be finite and >= 0");
  }
  Require(sim.heading_invalid_fraction >= 0.0 && sim.heading_invalid_fraction <= 1.0,
          "heading_invalid_fraction must be in [0, 1]");
  Require(sim.gnss_outlier_probability >= 0.0 && sim.gnss_outlier_probability <= 1.0,
          "gnss_outlier_probability must be in [0, 1]");
  Require(std::isfinite(sim.wheel_radius) && sim.wheel_radius > 0.0, "wheel_radius must be > 0");
  Require(std::isfinite(sim.pulses_per_rev) && sim.pulses_per_rev > 0.0, "pulses_per_rev must be > 0");
  Require(std::isfinite(sim.wheel_scale) && std::isfinite(sim.track_width), "wheel_scale, track_width must be finite");
  Require(sim.lever_b.allFinite() && std::isfinite(sim.mount_yaw), "lever_b, mount_yaw must be finite");
  for (const auto& [start, length] : sim.gnss_outages) {
    Require(std::isfinite(start) && FiniteNonNegative(length), "gnss_outages need finite [start, duration >= 0]");
  }
}

const GeodeticPoint& CheckedOrigin(const GeodeticPoint& o) {
  Require(IsPlausibleGeodetic(o.lat_deg, o.lon_deg, o.alt_m), "origin is not a plausible lat, lon, alt");
  return o;
}

// Number of samples k = first..K with k/rate ≤ duration (round-off tolerant).
uint64_t LastIndex(double rate, double duration) {
  return static_cast<uint64_t>(std::floor(duration * rate + kTimeTolerance));
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// TruthTrajectory

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
  double t0 = 0.0;
  for (unsigned lap = 0; lap < sim.repeat; ++lap) {
    for (const SimSegment& seg : sim.segments) {
      Require(FiniteNonNegative(seg.duration) && std::isfinite(seg.accel) && std::isfinite(seg.yaw_rate) &&
                  std::isfinite(seg.grade) && std::abs(seg.grade) < 0.5 * kPi,
              "segments need finite duration >= 0, accel, yaw_rate and |grade| < 90 deg");
      if (seg.duration == 0.0) continue;  // nothing happens in it
      const double ramp = std::min(kTransitionTime, seg.duration);
      accel_.Add(t0, ramp, seg.accel);
      yaw_rate_.Add(t0, ramp, seg.yaw_rate);
      grade_.Add(t0, seg.duration, seg.grade);
      t0 += seg.duration;
    }
  }
  Require(t0 > 0.0, "segments must have a positive total duration");
  duration_ = t0;
  g_w_ = GravityWorld(NormalGravity(sim.origin.lat_deg, sim.origin.alt_m));

  ComputeSpeedPhases();

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

double TruthTrajectory::Speed(double s) const {
  const SpeedPhase& ph = Phase(s);
  return ph.moving ? std::max(0.0, accel_.Integral(s) - ph.a0) : 0.0;
}

Vec3 TruthTrajectory::Velocity(double s) const {
  const double yaw = Yaw(s), pitch = grade_.Value(s);
  return Speed(s) * Vec3(std::cos(yaw) * std::cos(pitch), std::sin(yaw) * std::cos(pitch), std::sin(pitch));
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

  const Vec3 x_b_w(cy * cp, sy * cp, sp);  // body x axis in w
  const Vec3 dx_dyaw(-sy * cp, cy * cp, 0.0), dx_dpitch(-cy * sp, -sy * sp, cp);

  TruthState x;
  x.t = start_time_ + s;
  const size_t k = KnotIndex(s);
  x.p_wb = knot_p_[k] + GaussLegendre3(knots_[k], s, [this](double u) { return Velocity(u); });
  x.v_w = speed * x_b_w;
  x.q_wb = Quat(Eigen::AngleAxisd(yaw, Vec3::UnitZ())) * Quat(Eigen::AngleAxisd(-pitch, Vec3::UnitY()));
  // ω_w = yaw_rate·e_z − pitch_rate·Rz(yaw)·e_y, expressed in b.
  x.omega_b = Vec3(yaw_rate * sp, -pitch_rate, yaw_rate * cp);
  x.a_w = speed_rate * x_b_w + speed * (yaw_rate * dx_dyaw + pitch_rate * dx_dpitch);
  x.speed = speed;
  return x;
}

Vec2 TruthTrajectory::IntegrateSpeedAndYawRate(double s0, double s1) const {
  CHECK(s0 <= s1);
  s0 = std::clamp(s0, 0.0, duration_);
  s1 = std::clamp(s1, 0.0, duration_);
  const auto f = [this](double s) { return Vec2(Speed(s), yaw_rate_.Value(s) * std::cos(grade_.Value(s))); };
  Vec2 sum = Vec2::Zero();
  // Integrate knot interval by knot interval: the integrand is smooth within each.
  for (size_t k = KnotIndex(s0); k + 1 < knots_.size() && knots_[k] < s1; ++k) {
    const double a = std::max(s0, knots_[k]), b = std::min(s1, knots_[k + 1]);
    if (b > a) sum += GaussLegendre3(a, b, f);
  }
  return sum;
}

// ---------------------------------------------------------------------------------------------------------
// Simulator

double Simulator::Rng::Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

double Simulator::Rng::Normal() {
  // Box–Muller with both uniforms drawn every time, so each normal costs exactly two engine draws.
  const double u1 = 1.0 - Uniform();  // (0, 1]
  const double u2 = Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}

namespace {
// Seed of random source `index`: the index-th draw of the master engine.
uint64_t DerivedSeed(unsigned seed, int index) {
  std::mt19937_64 master(seed);
  master.discard(static_cast<unsigned long long>(index));
  return master();
}
}  // namespace

Simulator::Simulator(const SimOptions& sim)
    : sim_(sim),
      truth_(sim),
      rng_imu_bias_(DerivedSeed(sim.seed, 0)),
      rng_imu_noise_(DerivedSeed(sim.seed, 1)),
      rng_gnss_(DerivedSeed(sim.seed, 2)),
      rng_heading_(DerivedSeed(sim.seed, 3)),
      rng_heading_valid_(DerivedSeed(sim.seed, 4)),
      rng_outlier_(DerivedSeed(sim.seed, 5)),
      rng_wheel_(DerivedSeed(sim.seed, 6)) {
  ValidateSensors(sim);
  const double d = truth_.duration();
  n_imu_ = LastIndex(sim.imu_rate, d) + 1;
  n_gnss_ = sim.gnss_rate > 0.0 ? LastIndex(sim.gnss_rate, d) + 1 : 0;
  n_odom_ = sim.wheel_rate > 0.0 ? LastIndex(sim.wheel_rate, d) + 1 : 1;  // indices 1..last
  bg_ = sim.gyro_turn_on_bias * rng_imu_bias_.Normal3();
  ba_ = sim.acc_turn_on_bias * rng_imu_bias_.Normal3();
}

bool Simulator::Next(SimRecord* record) {
  constexpr double kNever = std::numeric_limits<double>::infinity();
  for (;;) {
    // Elapsed times k/rate: equal rationals give equal doubles, so simultaneous samples tie exactly.
    const double t_imu = i_imu_ < n_imu_ ? static_cast<double>(i_imu_) / sim_.imu_rate : kNever;
    const double t_odom = i_odom_ < n_odom_ ? static_cast<double>(i_odom_) / sim_.wheel_rate : kNever;
    const double t_gnss = i_gnss_ < n_gnss_ ? static_cast<double>(i_gnss_) / sim_.gnss_rate : kNever;
    if (t_imu == kNever && t_odom == kNever && t_gnss == kNever) return false;
    *record = SimRecord();
    if (t_imu <= t_odom && t_imu <= t_gnss) {
      MakeImu(record);
      return true;
    }
    if (t_odom <= t_gnss) {
      MakeOdom(record);
      return true;
    }
    if (MakeGnss(record)) return true;
  }
}

void Simulator::FillTruth(double elapsed, SimRecord* r) const {
  r->truth = truth_.AtElapsed(std::min(elapsed, truth_.duration())).ToNavState();
  r->truth.bg = bg_;
  r->truth.ba = ba_;
}

void Simulator::MakeImu(SimRecord* r) {
  const double rate = sim_.imu_rate;
  const double s = static_cast<double>(i_imu_) / rate;
  if (i_imu_ > 0) {
    const double sqrt_dt = std::sqrt(1.0 / rate);
    bg_ += sim_.gyro_bias_rw * sqrt_dt * rng_imu_bias_.Normal3();
    ba_ += sim_.acc_bias_rw * sqrt_dt * rng_imu_bias_.Normal3();
  }
  const TruthState x = truth_.AtElapsed(std::min(s, truth_.duration()));
  const Vec3 noise_g = sim_.gyro_noise_density * std::sqrt(rate) * rng_imu_noise_.Normal3();
  const Vec3 noise_a = sim_.acc_noise_density * std::sqrt(rate) * rng_imu_noise_.Normal3();
  r->type = SimRecord::Type::kImu;
  r->imu.t = sim_.start_time + s;
  r->imu.gyro = x.omega_b + bg_ + noise_g;
  r->imu.acc = x.q_wb.conjugate() * (x.a_w - truth_.gravity_w()) + ba_ + noise_a;
  r->truth = x.ToNavState();
  r->truth.bg = bg_;
  r->truth.ba = ba_;
  ++i_imu_;
}

void Simulator::MakeOdom(SimRecord* r) {
  const double dt = 1.0 / sim_.wheel_rate;
  const double s1 = std::min(static_cast<double>(i_odom_) / sim_.wheel_rate, truth_.duration());
  const double s0 = static_cast<double>(i_odom_ - 1) / sim_.wheel_rate;
  // Distances of the wheel contact points: body speed ∓ half the track times the body yaw rate.
  const Vec2 integral = truth_.IntegrateSpeedAndYawRate(s0, s1);
  const double half_turn = 0.5 * sim_.track_width * integral.y();
  // A wheel that does not turn counts no pulses: the speed noise (slip, tyre) exists only in motion.
  const bool rolling = std::abs(integral.x()) > 0.0 || std::abs(half_turn) > 0.0;
  const Vec2 noise = (rolling ? sim_.wheel_speed_noise : 0.0) * Vec2(rng_wheel_.Normal(), rng_wheel_.Normal());
  const Vec2 distance = sim_.wheel_scale * Vec2(integral.x() - half_turn, integral.x() + half_turn) + noise * dt;
  const Vec2 counts = distance * sim_.pulses_per_rev / (2.0 * kPi * sim_.wheel_radius) + pulse_carry_;
  const Vec2 pulses(std::round(counts.x()), std::round(counts.y()));
  pulse_carry_ = counts - pulses;
  r->type = SimRecord::Type::kOdom;
  r->odom.t = sim_.start_time + static_cast<double>(i_odom_) / sim_.wheel_rate;
  r->odom.left_pulses = pulses.x();
  r->odom.right_pulses = pulses.y();
  FillTruth(s1, r);
  ++i_odom_;
}

bool Simulator::MakeGnss(SimRecord* r) {
  const double s = static_cast<double>(i_gnss_) / sim_.gnss_rate;
  ++i_gnss_;
  // Every fix draws the same numbers, used or not, so outages and probabilities shift nothing else.
  const Vec3 noise = rng_gnss_.Normal3();
  const double heading_noise = rng_heading_.Normal();
  const bool heading_valid = rng_heading_valid_.Uniform() >= sim_.heading_invalid_fraction;
  const bool outlier = rng_outlier_.Uniform() < sim_.gnss_outlier_probability;
  const double outlier_dir = 2.0 * kPi * rng_outlier_.Uniform();
  for (const auto& [start, length] : sim_.gnss_outages) {
    if (s >= start && s < start + length) return false;
  }

  const TruthState x = truth_.AtElapsed(std::min(s, truth_.duration()));
  Vec3 p_ant_w = x.p_wb + x.q_wb * sim_.lever_b + sim_.gnss_sigma_enu.cwiseProduct(noise);
  if (outlier) p_ant_w += sim_.gnss_outlier_magnitude * Vec3(std::cos(outlier_dir), std::sin(outlier_dir), 0.0);
  const GeodeticPoint geo = truth_.frame().ToGeodetic(p_ant_w);
  const Vec3 x_G_w = x.q_wb * Vec3(std::cos(sim_.mount_yaw), std::sin(sim_.mount_yaw), 0.0);
  const double yaw_G = std::atan2(x_G_w.y(), x_G_w.x()) + sim_.heading_sigma * heading_noise;

  r->type = SimRecord::Type::kGnss;
  r->gnss.t = sim_.start_time + s;
  r->gnss.lat_deg = geo.lat_deg;
  r->gnss.lon_deg = geo.lon_deg;
  r->gnss.alt_m = geo.alt_m;
  r->gnss.heading_valid = heading_valid;
  r->gnss.heading_deg = heading_valid ? EnuYawToCompassDeg(yaw_G) : 0.0;
  r->gnss.has_sigma = sim_.write_gnss_sigma;
  if (sim_.write_gnss_sigma) r->gnss.sigma_enu = sim_.gnss_sigma_enu;
  r->gnss_outlier = outlier;
  FillTruth(s, r);
  return true;
}

// ---------------------------------------------------------------------------------------------------------
// Simulate

namespace {

void CheckedPrintf(AtomicFile* file, int result) {
  if (result < 0) throw std::runtime_error(file->path() + ": write failed");
}

}  // namespace

SimulationResult Simulate(const SimOptions& sim, const std::string& out_dir) {
  Simulator simulator(sim);  // validates before any file is touched
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir)) {
    throw std::runtime_error(out_dir + ": cannot create output directory" + (ec ? ": " + ec.message() : ""));
  }
  const std::string log_path = (std::filesystem::path(out_dir) / "log.txt").string();
  const std::string truth_path = (std::filesystem::path(out_dir) / "truth.csv").string();
  AtomicFile log(log_path);
  AtomicFile truth(truth_path);

  const GeodeticPoint& o = sim.origin;
  CheckedPrintf(&log, std::fprintf(log.stream(),
                                   "# gins simulate seed=%u start_time=%.6f duration=%.6f origin_lla=%.10f %.10f %.4f "
                                   "imu_rate=%g gnss_rate=%g wheel_rate=%g wheel_radius=%g pulses_per_rev=%g\n",
                                   sim.seed, sim.start_time, simulator.truth().duration(), o.lat_deg, o.lon_deg,
                                   o.alt_m, sim.imu_rate, sim.gnss_rate, sim.wheel_rate, sim.wheel_radius,
                                   sim.pulses_per_rev));
  CheckedPrintf(&log, std::fprintf(log.stream(), "# IMU t gx gy gz ax ay az | ODOM t left right | GNSS t lat lon "
                                                 "alt heading valid%s\n",
                                   sim.write_gnss_sigma ? " se sn su" : ""));
  truth.Write("t,lat,lon,alt,qw,qx,qy,qz,ve,vn,vu\n");

  SimulationResult result;
  result.duration = simulator.truth().duration();
  SimRecord r;
  while (simulator.Next(&r)) {
    switch (r.type) {
      case SimRecord::Type::kImu: {
        const ImuSample& m = r.imu;
        CheckedPrintf(&log, std::fprintf(log.stream(), "IMU %.6f %.9e %.9e %.9e %.9e %.9e %.9e\n", m.t, m.gyro.x(),
                                         m.gyro.y(), m.gyro.z(), m.acc.x(), m.acc.y(), m.acc.z()));
        const NavState& x = r.truth;
        const GeodeticPoint g = simulator.truth().frame().ToGeodetic(x.p_wb);
        CheckedPrintf(&truth, std::fprintf(truth.stream(), "%.6f,%.10f,%.10f,%.4f,%.9f,%.9f,%.9f,%.9f,%.6f,%.6f,%.6f\n",
                                           x.t, g.lat_deg, g.lon_deg, g.alt_m, x.q_wb.w(), x.q_wb.x(), x.q_wb.y(),
                                           x.q_wb.z(), x.v_w.x(), x.v_w.y(), x.v_w.z()));
        ++result.imu;
        break;
      }
      case SimRecord::Type::kOdom:
        // Whole pulses, printed as integers (a rounded −0.4 would print as "-0" with %.0f).
        CheckedPrintf(&log, std::fprintf(log.stream(), "ODOM %.6f %lld %lld\n", r.odom.t,
                                         std::llround(r.odom.left_pulses), std::llround(r.odom.right_pulses)));
        ++result.odom;
        break;
      case SimRecord::Type::kGnss: {
        const GnssRecord& g = r.gnss;
        CheckedPrintf(&log, std::fprintf(log.stream(), "GNSS %.6f %.10f %.10f %.4f %.5f %d", g.t, g.lat_deg,
                                         g.lon_deg, g.alt_m, g.heading_deg, g.heading_valid ? 1 : 0));
        if (g.has_sigma) {
          CheckedPrintf(&log, std::fprintf(log.stream(), " %.4f %.4f %.4f", g.sigma_enu.x(), g.sigma_enu.y(),
                                           g.sigma_enu.z()));
        }
        CheckedPrintf(&log, std::fputs("\n", log.stream()));
        ++result.gnss;
        break;
      }
    }
  }
  // Both files or neither: a truth without its log (or the reverse) would mislead.
  truth.Commit();
  try {
    log.Commit();
  } catch (...) {
    std::remove(truth_path.c_str());
    throw;
  }
  return result;
}

}  // namespace gins
