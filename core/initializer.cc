#include "core/initializer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "core/chi2.h"
#include "core/so3.h"

namespace gins {
namespace {

// Bounds of the fit's window (ImuWindowForSigma between them).
constexpr double kMinWindow = 5.0;   // s
constexpr double kMaxWindow = 60.0;  // s
// At most one fit per this much log time (each is a few small Ceres solves).
constexpr double kAttemptInterval = 1.0;  // s
// A standstill's fixes kept for the fit (the antenna stands: more say little).
constexpr size_t kMaxStandstillFixes = 50;
// At most this many of each measurement in motion enter a fit, evenly spread over the window: a 60 s window
// of 20 Hz fixes or 100 Hz wheels would make every attempt cost seconds (slower than the log on a stream),
// while neighbouring metre-level fixes share most of their error and add little.
constexpr size_t kMaxFitMeasurements = 200;

// The measurements of `all` in [t0, t1] (TimeOf(m) their epoch), at most kMaxFitMeasurements of them evenly
// spread by index, the newest always kept, appended to *out.
template <class M, class TimeOf>
void AppendThinned(const std::deque<M>& all, double t0, double t1, TimeOf time_of, std::vector<M>* out) {
  std::vector<const M*> in;
  for (const M& m : all) {
    if (time_of(m) >= t0 && m.t <= t1) in.push_back(&m);
  }
  const size_t n = in.size(), keep = std::min(n, kMaxFitMeasurements);
  for (size_t k = 0; k < keep; ++k) {
    // Index k·(n−1)/(keep−1) rounded: the first and the last are kept.
    const size_t i = keep == 1 ? n - 1 : (k * (n - 1) + (keep - 1) / 2) / (keep - 1);
    out->push_back(*in[i]);
  }
}
// Another yaw must explain the window worse by this χ²(1) quantile to rule it out.
constexpr double kAmbiguityProbability = 0.9999;
// The GNSS must rule out a zero speed at this probability before a fit is tried.
constexpr double kMotionProbability = 0.999;
// Over a full window a fit is accepted with a yaw 1-σ up to this: the iterated updates converge from tens of
// degrees; far beyond, the linearised estimators would not.
constexpr double kMaxSettledYawSigma = 30.0 * kDegToRad;
// ... and roll and pitch 1-σ up to this: gravity observes them within seconds once the estimators run, and
// at 3 σ (15°) the linearised gravity is off by 1 − cos 15° ≈ 3 % of g, which the iterated update absorbs.
constexpr double kMaxSettledTiltSigma = 5.0 * kDegToRad;
// Gyrocompassing at rest gives a yaw when its 1-σ is at most this (rad); beyond, the linearised σ means
// little and the yaw is taken as unknown.
constexpr double kMaxGyrocompassSigma = 15.0 * kDegToRad;
// Floors of the initial covariance (1-σ): the estimators invert it.
constexpr double kFloorPos = 1e-3, kFloorVel = 1e-3, kFloorAtt = 1e-5, kFloorBg = 1e-7, kFloorBa = 1e-5;

std::string Deg(double rad) {
  std::ostringstream os;
  os.precision(2);
  os << std::fixed << rad * kRadToDeg;
  return os.str();
}

}  // namespace

Initializer::Initializer(const SensorOptions& sensors, const InitOptions& init, const StandstillOptions& standstill,
                         const EarthModel& earth)
    : sensors_(sensors),
      init_options_(init),
      standstill_options_(standstill),
      earth_(earth),
      detector_(
          [&] {
            StandstillOptions o = standstill;
            o.enabled = true;  // the estimators' updates may be off; the static path still needs to know
            o.window = init.static_duration;
            return o;
          }(),
          earth.g_norm(), sensors.wheel.interval) {
  align_options_.sensors = sensors;
  align_options_.zero_velocity_sigma = standstill.velocity_sigma;
}

void Initializer::AddImu(const ImuSample& imu) {
  if (done()) return;
  if (first_time_ < 0.0) first_time_ = imu.t;
  if (!imu_.empty() && imu.t - imu_.back().t > sensors_.imu.max_gap) {
    // Nothing is integrated across an IMU gap: the window starts again after it.
    imu_.clear();
    standing_.reset();
    last_standstill_.reset();
  }
  imu_.push_back(imu);
  history_imu_.push_back(imu);
  detector_.AddImu(imu);
  TrackStandstill(imu);
  Prune(imu.t);
}

void Initializer::AddWheel(const WheelMeasurement& wheel) {
  if (done() || !sensors_.wheel.enabled) return;
  wheels_.push_back(wheel);
  detector_.AddWheel(wheel);
}

void Initializer::AddGnssVelocity(const GnssVelocityMeasurement& gnss_velocity) {
  if (done()) return;
  gnss_velocities_.push_back(gnss_velocity);
  detector_.AddGnssVelocity(gnss_velocity);
}

void Initializer::Prune(double t) {
  const double keep = kMaxWindow + 1.0;
  while (!imu_.empty() && t - imu_.front().t > keep) imu_.pop_front();
  while (!fixes_.empty() && t - fixes_.front().t > keep) fixes_.pop_front();
  while (!gnss_velocities_.empty() && t - gnss_velocities_.front().t > keep) gnss_velocities_.pop_front();
  while (!wheels_.empty() && t - wheels_.front().t > keep) wheels_.pop_front();
  const double keep_history = init_options_.max_wait + kMaxWindow;
  while (!history_imu_.empty() && t - history_imu_.front().t > keep_history) history_imu_.pop_front();
  while (!history_fixes_.empty() && t - history_fixes_.front().t > keep_history) history_fixes_.pop_front();
}

void Initializer::Summarize(Standstill* st) {
  StaticSummary& m = st->summary;
  const double n = std::max(1, m.n);
  m.gyro_mean = st->gyro_sum / n;
  m.acc_mean = st->acc_sum / n;
  // Sums of squares are accurate enough here: the spreads only weigh the means (σ/√n), and at rest the
  // accelerometer's spread is far above the rounding of g² (1e-15 relative).
  m.gyro_std = (st->gyro_sq / n - m.gyro_mean.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
  m.acc_std = (st->acc_sq / n - m.acc_mean.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt();
  m.mean_dt = n > 1 ? (m.t_end - m.t_start) / (n - 1.0) : 0.0;
}

void Initializer::Accumulate(const ImuSample& s, double sign) {
  Standstill& st = *standing_;
  st.gyro_sum += sign * s.gyro;
  st.acc_sum += sign * s.acc;
  st.gyro_sq += sign * s.gyro.cwiseAbs2();
  st.acc_sq += sign * s.acc.cwiseAbs2();
  st.summary.n += sign > 0.0 ? 1 : -1;
}

void Initializer::TrackStandstill(const ImuSample& imu) {
  const bool standing = detector_.Decide() == StandstillDetector::State::kStanding;
  if (standing && !standing_) {
    // The quiet stretch the witness vouches for, from its start (its samples are still buffered).
    standing_.emplace(Standstill{});  // (not emplace(): clang rejects the nested type's defaults there)
    standing_->summary.t_start = std::max(detector_.quiet_since(), imu_.front().t);
    standing_->witness = detector_.witness();
    for (const ImuSample& s : imu_) {
      if (s.t >= standing_->summary.t_start) Accumulate(s, 1.0);
    }
    standing_->summary.t_end = imu.t;
    Summarize(&*standing_);
    for (const GnssMeasurement& f : fixes_) {
      if (f.t >= standing_->summary.t_start && standing_->fixes.size() < kMaxStandstillFixes) {
        standing_->fixes.push_back(f);
      }
    }
    return;
  }
  if (standing) {
    Accumulate(imu, 1.0);
    standing_->summary.t_end = imu.t;
    Summarize(&*standing_);
  } else if (standing_) {
    CloseStandstill();
  }
}

void Initializer::CloseStandstill() {
  // A gentle start hides in the newest fifth of the detector's window for a while: leave that part out.
  const double t_cut = standing_->summary.t_end - 0.2 * init_options_.static_duration;
  double t_end = standing_->summary.t_start;
  for (const ImuSample& s : imu_) {
    if (s.t > t_cut && s.t <= standing_->summary.t_end) Accumulate(s, -1.0);
    if (s.t <= t_cut) t_end = s.t;
  }
  Standstill st = std::move(*standing_);
  standing_.reset();
  if (t_end - st.summary.t_start < 0.5 * init_options_.static_duration || st.summary.n < 2) return;
  st.summary.t_end = t_end;
  Summarize(&st);
  while (!st.fixes.empty() && st.fixes.back().t > t_end) st.fixes.pop_back();
  last_standstill_ = std::move(st);
}

void Initializer::AddGnss(const GnssMeasurement& fix) {
  if (done()) return;
  fixes_.push_back(fix);
  history_fixes_.push_back(fix);
  detector_.AddGnss(fix);
  if (imu_.empty()) {
    last_problem_ = "no IMU sample yet";
    return;
  }
  if (standing_ && standing_->fixes.size() < kMaxStandstillFixes) standing_->fixes.push_back(fix);
  const bool heading = sensors_.gnss.use_heading && fix.heading_valid;
  if (standing_) {
    if (heading) {
      TryStandingWithHeading(fix);
    } else {
      last_problem_ = "standing still: yaw is not observable at rest; waiting for a valid dual-antenna heading "
                      "or for the vehicle to move";
    }
    return;
  }
  if (init_options_.wait_for_heading && !heading) {
    last_problem_ = "waiting for a valid dual-antenna heading (init.wait_for_heading: true)";
    return;
  }
  if (!heading && fix.t - last_attempt_ < kAttemptInterval - 1e-6) return;
  TryFit(fix);
}

void Initializer::TryStandingWithHeading(const GnssMeasurement& fix) {
  AlignmentInput in;
  in.imu = {imu_.back()};
  in.fixes = standing_->fixes;
  in.standstill = standing_->summary;
  const AlignmentFit a = Align(in, align_options_, earth_);
  if (!a.solved) {
    last_problem_ = "standing still with a heading, but the fit failed: " + a.problem;
    return;
  }
  Finish(a, fix, standing_, {});
}

bool Initializer::Moved(const AlignmentInput& in) const {
  // Yaw needs motion: a speed that the GNSS velocities or a line through the fixes show to be non-zero
  // (a slow rover on metre-level fixes needs a few seconds; a track longer than the fixes' σ, far more).
  const double t0 = in.imu.front().t;
  if (const std::optional<GnssSpeed> v = MeanGnssVelocity(in.gnss_velocities, t0)) {
    if (GnssShowsMotion(*v, kMotionProbability)) return true;
  }
  const std::optional<GnssSpeed> line = LineThroughFixes(in.fixes, t0);
  return line && GnssShowsMotion(*line, kMotionProbability);
}

bool Initializer::BuildWindow(const GnssMeasurement& fix, AlignmentInput* in, bool* from_standstill,
                              bool* full) {
  // The longest window the IMU's noise allows for these fixes' σ (their median horizontal σ).
  std::vector<double> sigmas;
  for (const GnssMeasurement& f : fixes_) sigmas.push_back(f.sigma_w.head<2>().norm() / std::sqrt(2.0));
  std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
  const double length =
      ImuWindowForSigma(sensors_.imu, earth_.g_norm(), sigmas[sigmas.size() / 2], kMinWindow, kMaxWindow);
  double t0 = std::max(imu_.front().t, fix.t - length);
  *from_standstill = last_standstill_ && last_standstill_->summary.t_end >= t0;
  if (*from_standstill) {
    t0 = last_standstill_->summary.t_end;
    in->standstill = last_standstill_->summary;
    in->fixes = last_standstill_->fixes;
  }
  for (const ImuSample& s : imu_) {
    if (s.t >= t0 && s.t <= fix.t) in->imu.push_back(s);
  }
  if (in->imu.size() < 2) {
    last_problem_ = "too few IMU samples before the fix";
    return false;
  }
  t0 = in->imu.front().t;
  // The window of motion is as long as it gets: from now on it slides, and the fit gets no better by
  // waiting.
  *full = fix.t - t0 >= length - kAttemptInterval;
  const auto at = [](const auto& m) { return m.t; };
  AppendThinned(fixes_, t0, fix.t, at, &in->fixes);
  AppendThinned(gnss_velocities_, t0, fix.t, at, &in->gnss_velocities);
  AppendThinned(wheels_, t0, fix.t, [](const WheelMeasurement& w) { return w.t - 0.5 * w.interval; }, &in->wheels);
  if (in->fixes.size() < 3) {
    last_problem_ = "waiting for more GNSS fixes";
    return false;
  }
  // Without motion the fit knows no more than a standstill would (and a quiet IMU may become one).
  if (!Moved(*in)) {
    last_problem_ = "the GNSS shows no motion and no standstill is confirmed yet (IMU quiet for " +
                    std::to_string(init_options_.static_duration) + " s and a witness)";
    return false;
  }
  return true;
}

void Initializer::TryFit(const GnssMeasurement& fix) {
  AlignmentInput in;
  bool from_standstill = false, full = false;
  if (!BuildWindow(fix, &in, &from_standstill, &full)) return;
  last_attempt_ = fix.t;
  const AlignmentFit a = Align(in, align_options_, earth_);
  if (!a.solved) {
    last_problem_ = "moving, but the fit failed: " + a.problem;
    return;
  }
  if (!Acceptable(a, full)) return;
  Finish(a, fix, from_standstill ? last_standstill_ : std::nullopt, std::move(in.imu));
}

bool FitStartsEstimators(const AlignmentFit& a, bool window_full, double max_attitude_sigma, double max_tilt_sigma) {
  const double chi2_1 = Chi2Quantile(kAmbiguityProbability, 1);
  if (a.yaw_sigma <= max_attitude_sigma && a.tilt_sigma <= max_tilt_sigma &&
      a.runner_up_delta_chi2 > chi2_1 * a.inflation) {
    return true;
  }
  // A slow vehicle on metre-level fixes may never give a precise yaw, nor (its residuals correlated) a
  // precise roll and pitch. Once the window is as long as it gets, the fit is as good as it will be: the
  // estimators start from it with its σ, unless another yaw fits about as well (its χ² not inflated by the
  // residuals' correlation here: the fit's σ covers that).
  return window_full && a.yaw_sigma <= kMaxSettledYawSigma && a.tilt_sigma <= kMaxSettledTiltSigma &&
         a.runner_up_delta_chi2 > chi2_1;
}

bool Initializer::Acceptable(const AlignmentFit& a, bool window_full) {
  const double max_att = init_options_.max_attitude_sigma;
  const double max_tilt = std::hypot(max_att, sensors_.imu.init_acc_bias_sigma / earth_.g_norm());
  const double chi2_1 = Chi2Quantile(kAmbiguityProbability, 1);
  std::ostringstream os;
  os << "moving; the last fit (" << a.fixes_used << " fixes) gives yaw σ " << Deg(a.yaw_sigma) << " deg (needs ≤ "
     << Deg(max_att) << ", or ≤ " << Deg(kMaxSettledYawSigma) << " over a full window), roll/pitch σ "
     << Deg(a.tilt_sigma) << " deg (needs ≤ " << Deg(max_tilt) << ", or ≤ " << Deg(kMaxSettledTiltSigma)
     << " over a full window)";
  if (std::isfinite(a.runner_up_delta_chi2)) {
    os << ", another yaw " << Deg(a.runner_up_yaw) << " deg is worse by χ² " << a.runner_up_delta_chi2
       << " (needs > " << chi2_1 * a.inflation << ", or > " << chi2_1 << " over a full window)";
  }
  last_problem_ = os.str();
  return FitStartsEstimators(a, window_full, max_att, max_tilt);
}

void Initializer::Finish(const AlignmentFit& a, const GnssMeasurement& fix, const std::optional<Standstill>& standstill,
                         std::vector<ImuSample> fit_imu) {
  InitResult r;
  r.x0 = a.x;
  r.x0.t = fix.t;
  Mat15 P = 0.5 * (a.P + a.P.transpose());
  const double floors[] = {kFloorPos, kFloorVel, kFloorAtt, kFloorBg, kFloorBa};
  for (int b = 0; b < 5; ++b) P.block<3, 3>(3 * b, 3 * b).diagonal().array() += floors[b] * floors[b];
  r.P0 = P;
  r.g_norm = earth_.g_norm();
  r.earth = earth_;
  r.heading_source = a.heading_used ? "dual_antenna" : "motion";
  r.nonholonomic_fit = a.nhc_used;
  r.start = standstill ? "standstill" : "moving";
  if (standstill) {
    const StaticSummary& s = standstill->summary;
    r.static_start = s.t_start;
    r.static_end = s.t_end;
    r.gyro_std = s.gyro_std;
    r.acc_std = s.acc_std;
    r.gyro_noise_density = s.gyro_std.mean() * std::sqrt(s.mean_dt);
    r.acc_noise_density = s.acc_std.mean() * std::sqrt(s.mean_dt);
    r.standstill_witness = WitnessName(standstill->witness);
  }
  r.yaw_sigma = a.yaw_sigma;
  r.tilt_sigma = a.tilt_sigma;
  r.window_start = a.x0.t;
  r.fit_start = a.x0;
  r.fit_start_P = 0.5 * (a.P0 + a.P0.transpose());
  for (int b = 0; b < 5; ++b) r.fit_start_P.block<3, 3>(3 * b, 3 * b).diagonal().array() += floors[b] * floors[b];
  r.fit_imu = std::move(fit_imu);
  const double first_fix = history_fixes_.empty() ? r.x0.t : history_fixes_.front().t;
  for (const ImuSample& sample : history_imu_) {
    if (sample.t >= first_fix - 1e-6 && sample.t < r.x0.t) r.pre_init_imu.push_back(sample);
  }
  for (const GnssMeasurement& f : history_fixes_) {
    if (f.t < r.x0.t) r.pre_init_fixes.push_back(f);
  }
  history_imu_.clear();
  history_fixes_.clear();
  r.chi2_per_dof = a.chi2 / std::max(1, a.dof);
  r.inflation = a.inflation;
  r.runner_up_delta_chi2 = a.runner_up_delta_chi2;
  result_ = r;
}

void Initializer::RestStates(double after, std::vector<RestState>* out) const {
  if (done() || !standing_ || standing_->fixes.empty() || imu_.empty()) return;
  const StaticSummary& st = standing_->summary;
  if (!(st.acc_mean.norm() > 0.0)) return;
  const double from = std::max(st.t_start, standing_->fixes.front().t);
  RestState r;
  // Level from gravity; an accelerometer bias tilts the measured gravity by up to its σ over g.
  const double g = earth_.g_norm();
  const double tilt = std::hypot(sensors_.imu.init_acc_bias_sigma / g,
                                 st.acc_std.mean() / std::sqrt(std::max(1, st.n)) / g);
  const Quat q_level = Quat::FromTwoVectors(st.acc_mean.normalized(), Vec3::UnitZ());
  const Quat q0 = (QuatFromYaw(-YawOfXAxis<double>(q_level.toRotationMatrix())) * q_level).normalized();
  // The yaw from the Earth's rotation (gyrocompassing): the mean rate, levelled, points its horizontal part
  // north, off by the gyro bias and the mean's noise over the rotation's horizontal part. A tactical or
  // navigation-grade IMU resolves it to degrees; a MEMS gyro's bias is far larger than the Earth's rate:
  // then any yaw is as likely (0, with the σ of a uniform angle).
  double yaw = 0.0, yaw_sigma = kUnknownYawSigma;
  const Vec3 rate_w = earth_.rate_w();
  const double rate_h = rate_w.head<2>().norm();
  if (rate_h > 0.0 && st.t_end > st.t_start) {
    const Vec3 u = q0 * st.gyro_mean;
    const double noise = sensors_.imu.gyro_noise_density / std::sqrt(st.t_end - st.t_start);
    const double sigma_h = std::sqrt(std::pow(sensors_.imu.init_gyro_bias_sigma, 2) + noise * noise +
                                     std::pow(tilt * rate_w.z(), 2));
    if (sigma_h / rate_h <= kMaxGyrocompassSigma) {
      yaw = WrapAngle(std::atan2(rate_w.y(), rate_w.x()) - std::atan2(u.y(), u.x()));
      yaw_sigma = sigma_h / rate_h;
    }
  }
  // A dual-antenna heading at this standstill (the newest valid one) is better still.
  if (sensors_.gnss.use_heading) {
    for (auto f = standing_->fixes.rbegin(); f != standing_->fixes.rend(); ++f) {
      if (!f->heading_valid) continue;
      const double m = sensors_.gnss.mount_yaw;
      const Vec3 x_G = q0 * Vec3(std::cos(m), std::sin(m), 0.0);  // the antennas' baseline, level, yaw 0
      yaw = WrapAngle(f->yaw_G - std::atan2(x_G.y(), x_G.x()));
      yaw_sigma = f->sigma_yaw;
      break;
    }
  }
  r.x.q_wb = (QuatFromYaw(yaw) * q0).normalized();
  // The antenna: the fixes' weighted mean (each σ already covers the fixes' correlation, gnss_noise.h),
  // without the outliers: a fix whose offset from the fixes' median, over its σ, is beyond the fix gate's
  // χ²(3) quantile (gnss.gate_probability) does not stand where the others do.
  const std::vector<GnssMeasurement>& fixes = standing_->fixes;
  Vec3 median;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> v;
    for (const GnssMeasurement& f : fixes) v.push_back(f.p_w[k]);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    median[k] = v[v.size() / 2];
  }
  const double gate = sensors_.gnss.gate_probability > 0.0 ? Chi2Quantile(sensors_.gnss.gate_probability, 3)
                                                            : std::numeric_limits<double>::infinity();
  Vec3 info = Vec3::Zero(), sum = Vec3::Zero();
  for (const GnssMeasurement& f : fixes) {
    if (fixes.size() >= 3 && (f.p_w - median).cwiseQuotient(f.sigma_w).squaredNorm() > gate) continue;
    const Vec3 w = f.sigma_w.cwiseAbs2().cwiseInverse();
    info += w;
    sum += w.cwiseProduct(f.p_w);
  }
  if (!(info.minCoeff() > 0.0)) return;
  const Vec3 p_antenna = sum.cwiseQuotient(info);
  // The IMU point: the lever arm's vertical part is known from the tilt; its horizontal part turns with the
  // yaw (for an unknown yaw a circle about the antenna: a mean of zero, a variance of half its squared
  // radius; else its arc over the yaw's σ).
  const Vec3 lever_w = r.x.q_wb * sensors_.gnss.lever_b;
  const bool yaw_known = yaw_sigma < kUnknownYawSigma;
  r.x.p_wb = p_antenna - (yaw_known ? lever_w : Vec3(0.0, 0.0, lever_w.z()));
  const double lever_var = lever_w.head<2>().squaredNorm() * (yaw_known ? yaw_sigma * yaw_sigma : 0.5);
  r.sigma_p = (info.cwiseInverse() + Vec3(lever_var, lever_var, 0.0)).cwiseSqrt();
  r.sigma_v.setConstant(standstill_options_.velocity_sigma);
  r.sigma_att = Vec3(tilt, tilt, yaw_sigma);
  const size_t first = out->size();
  for (auto it = imu_.rbegin(); it != imu_.rend() && it->t > after; ++it) {
    if (it->t < from) break;
    r.x.t = it->t;
    out->push_back(r);
  }
  std::reverse(out->begin() + static_cast<std::ptrdiff_t>(first), out->end());
}

std::string Initializer::Diagnosis() const {
  std::ostringstream os;
  if (imu_.empty()) return "no IMU samples";
  if (fixes_.empty()) return "no GNSS fix";
  if (standing_) {
    os << "standstill found at t=" << std::fixed << standing_->summary.t_start << " (witness "
       << WitnessName(standing_->witness) << "), ";
  } else if (last_standstill_) {
    os << "standstill found at t=" << std::fixed << last_standstill_->summary.t_start << "-"
       << last_standstill_->summary.t_end << ", ";
  }
  os << "initialisation did not complete: " << (last_problem_.empty() ? "no GNSS fix after it" : last_problem_);
  if (init_options_.wait_for_heading) os << " (set init.wait_for_heading: false to take the yaw from the motion)";
  return os.str();
}

}  // namespace gins
