#include "core/static_init.h"

#include <cmath>
#include <sstream>

#include "core/heading_model.h"
#include "core/so3.h"

namespace gins {
namespace {

// A vehicle turning at a steady rate has a quiet gyro too; a standstill also has a small mean rate.
constexpr double kMaxStaticMeanRate = 1.0 * kDegToRad;  // rad/s, far above any MEMS turn-on bias
// |mean specific force| must be close to |g| at rest.
constexpr double kMaxStaticAccNormError = 0.3;          // m/s²
// Wheel speed above which the vehicle counts as moving for the motion heading.
constexpr double kMovingSpeed = 0.3;                     // m/s
// A GNSS track this long (and at least 4 horizontal σ) gives the motion heading.
constexpr double kMinTrackLength = 5.0;                  // m

struct WindowStats {
  Vec3 gyro_mean = Vec3::Zero(), acc_mean = Vec3::Zero();
  Vec3 gyro_std = Vec3::Zero(), acc_std = Vec3::Zero();
  double mean_dt = 0.0;
};

WindowStats ComputeStats(const std::deque<ImuSample>& w) {
  WindowStats s;
  const double n = static_cast<double>(w.size());
  for (const auto& m : w) {
    s.gyro_mean += m.gyro;
    s.acc_mean += m.acc;
  }
  s.gyro_mean /= n;
  s.acc_mean /= n;
  for (const auto& m : w) {
    s.gyro_std += (m.gyro - s.gyro_mean).cwiseAbs2();
    s.acc_std += (m.acc - s.acc_mean).cwiseAbs2();
  }
  s.gyro_std = (s.gyro_std / n).cwiseSqrt();
  s.acc_std = (s.acc_std / n).cwiseSqrt();
  s.mean_dt = w.size() > 1 ? (w.back().t - w.front().t) / (n - 1.0) : 0.0;
  return s;
}

}  // namespace

StaticInitializer::StaticInitializer(const InitializerOptions& options, const EarthModel& earth)
    : options_(options), earth_(earth), g_norm_(earth.g_norm()) {}

bool StaticInitializer::WindowIsStatic() const {
  if (window_.size() < 10) return false;
  if (window_.back().t - window_.front().t < 0.98 * options_.init.static_duration) return false;
  if (wheel_seen_) {
    if (wheel_window_.empty()) return false;
    for (const auto& w : wheel_window_) {
      if (!w.standstill) return false;
    }
  }
  const WindowStats s = ComputeStats(window_);
  return s.gyro_std.maxCoeff() < options_.init.max_gyro_std && s.acc_std.maxCoeff() < options_.init.max_acc_std &&
         s.gyro_mean.norm() < kMaxStaticMeanRate && std::abs(s.acc_mean.norm() - g_norm_) < kMaxStaticAccNormError;
}

void StaticInitializer::AddImu(const ImuSample& imu) {
  if (first_time_ < 0.0) first_time_ = imu.t;
  if (!have_standstill_) {
    window_.push_back(imu);
    while (!window_.empty() && imu.t - window_.front().t > options_.init.static_duration) window_.pop_front();
    while (!wheel_window_.empty() && imu.t - wheel_window_.front().t > options_.init.static_duration) {
      wheel_window_.pop_front();
    }
    if (WindowIsStatic()) StartFromStandstill();
    last_imu_ = imu;
    return;
  }
  // Propagate the yaw-free attitude and velocity with the shared kernel (zero-order hold of the last sample).
  const double dt = imu.t - kin_time_;
  if (last_imu_ && dt > 0.0) {
    const Vec3 omega = last_imu_->gyro - partial_.x0.bg;
    const Vec3 acc = last_imu_->acc - partial_.x0.ba;
    const Mat3 R_before = kin_.q.toRotationMatrix();
    kin_ = ImuStep(kin_, omega, acc, GravityWorld(g_norm_), std::min(dt, options_.imu.max_gap));
    if (!moving_) kin_.v.setZero();  // at rest the IMU is not integrated into velocity
    const Vec3 v_dr = wheel_seen_ ? Vec3(R_before * Vec3(last_wheel_speed_, 0.0, 0.0)) : kin_.v;
    dr_p_ += v_dr * dt;
  }
  kin_time_ = imu.t;
  last_imu_ = imu;
}

void StaticInitializer::AddWheel(const WheelMeasurement& wheel) {
  wheel_seen_ = true;
  last_wheel_speed_ = wheel.speed;
  if (!have_standstill_) {
    wheel_window_.push_back(wheel);
  } else if (std::abs(wheel.speed) > kMovingSpeed) {
    moving_ = true;
  }
}

void StaticInitializer::StartFromStandstill() {
  const WindowStats s = ComputeStats(window_);
  InitResult& r = partial_;
  r.static_start = window_.front().t;
  r.static_end = window_.back().t;
  r.g_norm = g_norm_;
  r.earth = earth_;
  r.gyro_std = s.gyro_std;
  r.acc_std = s.acc_std;
  r.gyro_noise_density = s.gyro_std.mean() * std::sqrt(s.mean_dt);
  r.acc_noise_density = s.acc_std.mean() * std::sqrt(s.mean_dt);
  r.x0.bg = s.gyro_mean;
  // At rest the accelerometer measures R_wbᵀ(0, 0, |g|) + ba: its direction gives roll and pitch, its
  // length the bias along gravity. The horizontal bias is indistinguishable from tilt (kept in P0).
  const Vec3 up_b = s.acc_mean.normalized();
  r.x0.ba = s.acc_mean - g_norm_ * up_b;
  kin_.q = Quat::FromTwoVectors(up_b, Vec3::UnitZ());
  q_static_free_ = kin_.q;
  kin_.v.setZero();
  kin_.p.setZero();
  kin_time_ = window_.back().t;
  have_standstill_ = true;
  moving_ = false;
  dr_p_.setZero();

  // Initial covariance of everything but position, velocity and yaw (set when the heading is known).
  const double n = static_cast<double>(window_.size());
  Mat15& P = r.P0;
  P.setZero();
  const double sigma_bg =
      std::max((s.gyro_std / std::sqrt(n)).maxCoeff(), 0.05 * options_.imu.init_gyro_bias_sigma);
  P.block<3, 3>(nav::kBg, nav::kBg).diagonal().setConstant(sigma_bg * sigma_bg);
  // Tilt and horizontal accelerometer bias are one unknown at rest: δba = −[g_b]×·δθ keeps the measured
  // specific force unchanged. Their joint covariance follows from the bias prior.
  const double sigma_tilt = std::hypot(options_.imu.init_acc_bias_sigma / g_norm_, options_.init.sigma_roll_pitch);
  Mat3 P_tilt = Mat3::Zero();
  P_tilt(0, 0) = P_tilt(1, 1) = sigma_tilt * sigma_tilt;
  const Mat3 C = -Hat<double>(Vec3(g_norm_ * up_b));  // δba = C·δθ
  P.block<3, 3>(nav::kTheta, nav::kTheta) = P_tilt;
  P.block<3, 3>(nav::kBa, nav::kTheta) = C * P_tilt;
  P.block<3, 3>(nav::kTheta, nav::kBa) = P_tilt * C.transpose();
  const double sigma_ba_floor = 0.05 * options_.imu.init_acc_bias_sigma;
  const double sigma_ba_z = std::max((s.acc_std / std::sqrt(n)).maxCoeff(), sigma_ba_floor);
  P.block<3, 3>(nav::kBa, nav::kBa) = C * P_tilt * C.transpose();
  P.block<3, 3>(nav::kBa, nav::kBa) += Vec3(sigma_ba_floor, sigma_ba_floor, sigma_ba_z).cwiseAbs2().asDiagonal();
  P.block<3, 3>(nav::kTheta, nav::kTheta) += Mat3::Identity() * 1e-8;
}

void StaticInitializer::AddGnss(const GnssMeasurement& gnss) {
  if (!have_standstill_ || done()) return;
  const bool heading_usable = options_.gnss.use_heading && gnss.heading_valid;
  if (heading_usable) {
    // A left rotation about world z adds its angle to the yaw of every body axis.
    const Mat3 R_wG_free = kin_.q.toRotationMatrix() * ExpMat(Vec3(0, 0, options_.gnss.mount_yaw));
    const double yaw_offset = WrapAngle(gnss.yaw_G - YawOfXAxis<double>(R_wG_free));
    Finish(gnss, yaw_offset, "dual_antenna");
    return;
  }
  if (options_.gnss.use_heading && options_.init.wait_for_heading) {
    last_problem_ = "waiting for a valid dual-antenna heading";
    return;
  }
  if (!moving_) {
    last_problem_ = "waiting for the vehicle to move (heading from motion)";
    return;
  }
  const Vec3 dr_antenna = dr_p_ + kin_.q * options_.gnss.lever_b;
  track_.emplace_back(gnss.p_w, dr_antenna);
  const Vec2 d_gnss = (track_.back().first - track_.front().first).head<2>();
  const double sigma_h = gnss.sigma_w.head<2>().norm();
  if (d_gnss.norm() < std::max(kMinTrackLength, 4.0 * sigma_h)) {
    last_problem_ = "moving, waiting for a GNSS track long enough for the heading";
    return;
  }
  // 2-D Procrustes: the rotation about z that best maps the dead-reckoned track onto the GNSS track.
  Vec2 c_g = Vec2::Zero(), c_d = Vec2::Zero();
  for (const auto& [g, d] : track_) {
    c_g += g.head<2>();
    c_d += d.head<2>();
  }
  c_g /= static_cast<double>(track_.size());
  c_d /= static_cast<double>(track_.size());
  double s_dot = 0.0, s_cross = 0.0;
  for (const auto& [g, d] : track_) {
    const Vec2 a = d.head<2>() - c_d, b = g.head<2>() - c_g;
    s_dot += a.dot(b);
    s_cross += a.x() * b.y() - a.y() * b.x();
  }
  Finish(gnss, std::atan2(s_cross, s_dot), "motion");
}

void StaticInitializer::Finish(const GnssMeasurement& gnss, double yaw_offset, const std::string& source) {
  InitResult r = partial_;
  const Quat q_yaw = QuatFromYaw(yaw_offset);
  r.x0.t = gnss.t;
  r.x0.q_wb = (q_yaw * kin_.q).normalized();
  // At rest the gyro read its bias plus the Earth rate; with the yaw known, the Earth rate is taken out
  // so the bias is the sensor's own.
  r.x0.bg -= (q_yaw * q_static_free_).conjugate() * earth_.rate_w();
  r.x0.p_wb = gnss.p_w - r.x0.q_wb * options_.gnss.lever_b;
  const bool motion = source == "motion";
  if (wheel_seen_) {
    r.x0.v_w = r.x0.q_wb * Vec3(last_wheel_speed_, 0.0, 0.0);
  } else {
    r.x0.v_w = q_yaw * kin_.v;
  }
  r.heading_source = source;
  Mat15& P = r.P0;
  P.block<3, 3>(nav::kP, nav::kP) =
      (gnss.sigma_w.cwiseAbs2() + Vec3::Constant(options_.init.sigma_pos * options_.init.sigma_pos)).asDiagonal();
  const double sigma_v = motion ? std::max(options_.init.sigma_vel, 0.5) : options_.init.sigma_vel;
  P.block<3, 3>(nav::kV, nav::kV) = Mat3::Identity() * sigma_v * sigma_v;
  const double sigma_yaw = motion ? std::max(options_.init.sigma_yaw, 5.0 * kDegToRad)
                                  : std::hypot(gnss.sigma_yaw, options_.init.sigma_yaw);
  // Yaw is about world z; in the right-perturbation tangent that is the body-frame direction R_wbᵀ·e_z.
  const Vec3 z_b = r.x0.q_wb.conjugate() * Vec3::UnitZ();
  P.block<3, 3>(nav::kTheta, nav::kTheta) += sigma_yaw * sigma_yaw * z_b * z_b.transpose();
  result_ = r;
}

std::string StaticInitializer::Diagnosis() const {
  std::ostringstream os;
  if (!have_standstill_) {
    os << "no standstill found: initialisation needs " << options_.init.static_duration
       << " s with the wheels at zero and the IMU quiet (gyro std < " << options_.init.max_gyro_std * kRadToDeg
       << " deg/s, accel std < " << options_.init.max_acc_std << " m/s^2); in-motion initialisation is not "
       << "supported yet";
    if (window_.size() >= 10) {
      const WindowStats s = ComputeStats(window_);
      os << " (last window: gyro std " << s.gyro_std.maxCoeff() * kRadToDeg << " deg/s, accel std "
         << s.acc_std.maxCoeff() << " m/s^2)";
    }
  } else {
    os << "standstill found at t=" << std::fixed << partial_.static_end << " but initialisation did not complete: "
       << (last_problem_.empty() ? "no GNSS fix after it" : last_problem_);
    if (options_.gnss.use_heading && options_.init.wait_for_heading) {
      os << " (set init.wait_for_heading: false to take the heading from the first motion)";
    }
  }
  return os.str();
}

}  // namespace gins
