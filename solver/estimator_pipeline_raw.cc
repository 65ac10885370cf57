// The estimator pipeline's raw GNSS epochs (solver/estimator_pipeline.h, solver/raw_gnss_feed.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/chi2.h"
#include "core/gnss_atmosphere.h"
#include "solver/estimator_pipeline.h"

namespace gins {

namespace {

// An epoch this long before the log's first record is not of the log: skipped (a receiver's file often
// starts long before the log).
constexpr double kBeforeLog = 1.0;  // s
// Receiver clocks are within this of GPS time (receivers steer theirs to within a millisecond or so).
constexpr double kClockLookAhead = 1.0;  // s
// An inter-system bias is used once this many fixes averaged it; its σ is the mean's, with a floor for what
// drifts (the systems' time offsets, a receiver's delays with temperature).
constexpr uint64_t kMinBiasFixes = 10;
constexpr double kBiasSigmaFloor = 0.1;  // m

// The single-point fix of an epoch as a logged fix: geodetic, σ from its covariance in the local ENU frame.
GnssRecord FixRecord(const SppSolution& sol, double t) {
  const GeodeticRad g = EcefToGeodeticRad(sol.position_ecef_m);
  GnssRecord r;
  r.t = t;
  r.lat_deg = g.lat * kRadToDeg;
  r.lon_deg = g.lon * kRadToDeg;
  r.alt_m = g.h;
  const double sl = std::sin(g.lat), cl = std::cos(g.lat), so = std::sin(g.lon), co = std::cos(g.lon);
  Mat3 R_enu_ecef;
  R_enu_ecef << -so, co, 0.0, -sl * co, -sl * so, cl, cl * co, cl * so, sl;
  const Mat3 C = R_enu_ecef * sol.covariance.topLeftCorner<3, 3>() * R_enu_ecef.transpose();
  r.has_sigma = true;
  r.sigma_enu = C.diagonal().cwiseMax(0.0).cwiseSqrt();
  return r;
}

}  // namespace

void EstimatorPipeline::SetRawGnssFeed(std::unique_ptr<RawGnssFeed> feed) { raw_feed_ = std::move(feed); }

void EstimatorPipeline::DrainRawFeed(double t) {
  draining_raw_ = true;
  // Epochs are tagged on the receiver's clock: each is read up to kClockLookAhead early (and a stated GNSS
  // time offset more), dated on GPS time by its fix's clock and then on the IMU's clock by that offset, and
  // used once the records reach that time, so it takes its place in time order.
  RawGnssMeasurement m;
  while (raw_feed_->NextBefore(t + kClockLookAhead + std::max(sensors_.gnss.time_offset, 0.0), &m)) {
    const double first = first_t_ >= 0.0 ? first_t_ : t;  // before the first record: the one coming
    if (m.rx_gps_s - sensors_.gnss.time_offset < first - kBeforeLog) {
      ++raw_.before_log;
      continue;
    }
    PreparedRawGnss p = PrepareRawGnss(std::move(m));
    auto at = raw_queue_.end();
    while (at != raw_queue_.begin() && std::prev(at)->m.t > p.m.t) --at;
    raw_queue_.insert(at, std::move(p));
  }
  while (!raw_queue_.empty() && raw_queue_.front().m.t <= t) {
    PreparedRawGnss p = std::move(raw_queue_.front());
    raw_queue_.pop_front();
    UseRawGnss(std::move(p));
  }
  draining_raw_ = false;
}

void EstimatorPipeline::FinishRawGnss() {
  if (!raw_feed_) return;
  const std::optional<double> next = raw_feed_->PeekTime();
  const double end = std::numeric_limits<double>::infinity();
  DrainRawGnss(end);
  if (raw_.epochs == 0 && first_t_ >= 0.0) {
    // Nothing overlapped the log: almost always a log not stamped in GPS seconds.
    std::ostringstream why;
    why.precision(15);
    why << "no raw GNSS epoch of " << raw_feed_->Stats()["obs_file"].get<std::string>()
        << " lies within the log (t " << first_t_ << " .. " << last_t_ << ")";
    if (raw_.before_log > 0) why << "; " << raw_.before_log << " epochs are before it";
    if (next) why << "; the first one after it is at " << *next;
    why << ": with raw_gnss the log's time must be GPS seconds (RINEX epochs are receiver time, GPS)";
    throw RunError(why.str());
  }
}

void EstimatorPipeline::AddRawGnss(RawGnssMeasurement m) { UseRawGnss(PrepareRawGnss(std::move(m))); }

EstimatorPipeline::PreparedRawGnss EstimatorPipeline::PrepareRawGnss(RawGnssMeasurement m) {
  PreparedRawGnss p;
  std::vector<SppObservation> code;
  code.reserve(m.satellites.size());
  for (const RawGnssObservation& o : m.satellites) code.push_back(o.code);
  p.sol = SolveSpp(m.rx_gps_s, code, m.nav->ephemerides, m.nav->spp, last_spp_ecef_.value_or(Vec3::Zero()));
  TrackInterSystemBias(p.sol, &m);
  if (p.sol.ok) {
    last_spp_ecef_ = p.sol.position_ecef_m;
    // The reception on GPS time: the tag less the receiver clock (GPS's, else the first system's).
    const auto gps = p.sol.clock_m.find(GnssSystem::kGps);
    last_clock_m_ = gps != p.sol.clock_m.end() ? gps->second : p.sol.clock_m.begin()->second;
  }
  // Without a fix, the last one's clock (a receiver clock drifts by microseconds per second). GPS time is
  // then put on the IMU's clock as for every GNSS record: gnss.time_offset_s says how much later than the
  // IMU time of their measurement the GNSS times are (the estimated part of it is not applied to raw epochs).
  m.t = m.rx_gps_s - last_clock_m_.value_or(0.0) / kSpeedOfLight - sensors_.gnss.time_offset;
  p.m = std::move(m);
  return p;
}

void EstimatorPipeline::UseRawGnss(PreparedRawGnss p) {
  RawGnssMeasurement& m = p.m;
  const SppSolution& sol = p.sol;
  Touch(m.t);
  if (DropForSimulatedOutage(m.t)) {
    ++raw_.in_outage;
    return;
  }
  ++raw_.epochs;
  if (!sol.ok) {
    ++raw_.without_fix;
    ++raw_.fix_failures[sol.why.substr(0, sol.why.find(':'))];
  }
  if (frame_) {
    m.origin_ecef = frame_->OriginEcef();
    m.R_ecef_w = frame_->R_ecef_w();
  }
  if (!sol.ok) {
    if (initialized_ && frame_) Dispatch(&Estimator::Add, Measurement(m));
    return;
  }
  const GnssRecord fix = FixRecord(sol, m.t);
  if (!frame_) {
    frame_.emplace(GeodeticPoint{fix.lat_deg, fix.lon_deg, fix.alt_m});
    m.origin_ecef = frame_->OriginEcef();
    m.R_ecef_w = frame_->R_ecef_w();
  }
  // The Doppler velocity at the fix, in w (whose axes are fixed ECEF directions: v_w = R_ecef_wᵀ·v_ecef).
  if (m.nav->use_doppler) {
    const std::vector<RawSatellite> sats = PrepareSatellites(m, sol.position_ecef_m);
    Vec3 v_ecef;
    Mat3 cov;
    if (SolveDopplerVelocity(sats, sol.position_ecef_m, std::sqrt(Chi2Gate(sensors_.gnss.gate_probability, 1)),
                             &v_ecef, &cov)) {
      m.has_velocity = true;
      m.velocity.t = m.t;
      m.velocity.v_w = m.R_ecef_w.transpose() * v_ecef;
      const Mat3 cov_w = m.R_ecef_w.transpose() * cov * m.R_ecef_w;
      m.velocity.sigma_w = cov_w.diagonal().cwiseMax(0.0).cwiseSqrt().cwiseMax(sensors_.gnss.min_velocity_sigma);
    } else {
      ++raw_.without_velocity;
    }
  }
  if (!initialized_) ++raw_.used_before_init;
  UseFix(fix, &m);
  if (m.has_velocity && sensors_.gnss.use_velocity) {
    if (standstill_) standstill_->AddGnssVelocity(m.velocity);
    if (!initialized_ && init_) init_->AddGnssVelocity(m.velocity);
  }
}

void EstimatorPipeline::TrackInterSystemBias(const SppSolution& sol, RawGnssMeasurement* m) {
  if (sol.ok && !isb_reference_) {
    isb_reference_ = sol.clock_m.count(GnssSystem::kGps) ? GnssSystem::kGps : sol.clock_m.begin()->first;
  }
  if (!isb_reference_) return;
  const auto ref = sol.clock_m.find(*isb_reference_);
  if (sol.ok && ref != sol.clock_m.end()) {
    for (const auto& [system, clock_m] : sol.clock_m) {
      if (system == *isb_reference_) continue;
      BiasMean& b = isb_[system];
      const double d = clock_m - ref->second;
      ++b.n;
      const double delta = d - b.mean;
      b.mean += delta / static_cast<double>(b.n);
      b.m2 += delta * (d - b.mean);
    }
  }
  m->clock_reference = *isb_reference_;
  for (const auto& [system, b] : isb_) {
    if (b.n < kMinBiasFixes) continue;
    const double var = b.m2 / static_cast<double>(b.n - 1);
    m->inter_system_bias[system] = {b.mean, std::sqrt(var / static_cast<double>(b.n) + kBiasSigmaFloor * kBiasSigmaFloor)};
  }
}

nlohmann::json EstimatorPipeline::RawGnssStats() const {
  nlohmann::json j = raw_feed_ ? raw_feed_->Stats() : nlohmann::json::object();
  j["epochs_used"] = raw_.epochs;
  j["epochs_before_log"] = raw_.before_log;
  j["epochs_in_simulated_outages"] = raw_.in_outage;
  j["epochs_without_fix"] = raw_.without_fix;
  j["epochs_without_velocity"] = raw_.without_velocity;
  j["epochs_to_initialization"] = raw_.used_before_init;
  j["fix_failures"] = raw_.fix_failures;
  for (const auto& [system, b] : isb_) {
    const std::string name(1, static_cast<char>(system));
    j["inter_system_bias_m"][name] = {{"mean", b.mean}, {"fixes", b.n}};
  }
  return j;
}

}  // namespace gins
