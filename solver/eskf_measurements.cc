// The ESKF's measurement updates: each linearises its model from core/*_model.h at the current nominal
// state (with Jets, core/linearize.h), in the blocks it touches, and hands it to Eskf::Update.
#include <cmath>

#include "core/gnss_model.h"
#include "core/gnss_velocity_model.h"
#include "core/heading_model.h"
#include "core/linearize.h"
#include "core/so3.h"
#include "core/time_shift.h"
#include "core/wheel_model.h"
#include "solver/eskf.h"

namespace gins {

using eskf::Block;
using eskf::BlockOf;
using eskf::EmbedJacobian;

namespace {

// The state the models see: the nominal state perturbed by the first N coordinates of a Jet vector, taken
// as (δp, δθ), (δv, δθ) or (δv, δθ, δs) as each model needs.
template <typename T>
Eigen::Quaternion<T> Rotated(const NavState& x, const Eigen::Matrix<T, 3, 1>& d_theta) {
  return x.q_wb.cast<T>() * ExpQuat<T>(d_theta);
}

// The state at the GNSS record's measurement time, t − td (core/time_shift.h), perturbed by (δp, δθ, δv, δtd).
template <typename T>
ShiftedKinematics<T> ShiftedState(const NavState& x, double td, const Vec3& a_w, const Vec3& omega_b,
                                  const Eigen::Matrix<T, 3, 1>& dp, const Eigen::Matrix<T, 3, 1>& d_theta,
                                  const Eigen::Matrix<T, 3, 1>& dv, const T& d_td) {
  return ShiftBack<T>(x.p_wb.cast<T>() + dp, x.v_w.cast<T>() + dv, Rotated<T>(x, d_theta), a_w, omega_b,
                      T(td) + d_td);
}

}  // namespace

void Eskf::Use(const GnssMeasurement& m) {
  if (!initialized_ || m.t < nom_.x.t) return;
  Propagate(m.t);
  if (WatchdogTakes(m)) {
    ++gnss_counts_.used;  // the re-initialisation's fix (or one held for its course): offered stays every fix
    return;
  }
  const bool accepted = UpdateGnssPosition(m);
  const bool reset = WatchGnss(m, accepted);
  prev_fix_ = m;
  if (reset) return;
  if (m.heading_valid && sensors_.gnss.use_heading) UpdateHeading(m);
}

bool Eskf::WatchdogTakes(const GnssMeasurement& m) {
  if (!watchdog_options_.enabled) return false;
  FlushCovariance();
  const bool finite = nom_.AllFinite() && P_.allFinite();
  const double sigma_p = std::sqrt(BlockOf<Block::kP>(P_).diagonal().maxCoeff());
  const FixVerdict verdict = WatchdogVerdict(m, finite, sigma_p, sensors_, watchdog_options_, nom_.x, P_, &course_wait_, &prev_fix_);
  if (verdict == FixVerdict::kUse) return false;
  if (verdict == FixVerdict::kReset) {
    ResetFromGnss(m, finite ? "covariance" : "non_finite");
    prev_fix_ = m;
  }
  return true;
}

bool Eskf::UpdateGnssPosition(const GnssMeasurement& m) {
  const Vec3 omega_b = BodyRate();
  const Model<3> model = [&] {
    Eigen::Matrix<double, 3, 1> r;
    Eigen::Matrix<double, 3, 10> H;  // (δp, δθ, δv, δtd)
    Linearize<3, 10>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          const ShiftedKinematics<T> k =
              ShiftedState<T>(nom_.x, nom_.Scalar<Block::kTd>(), a_w_, omega_b, d.template head<3>(),
                              d.template segment<3>(3), d.template segment<3>(6), d[9]);
          return GnssPositionModel::Residual<T>(k.p_wb, k.q_wb, sensors_.gnss.lever_b, m.p_w);
        },
        &r, &H);
    if (PastImuGap(nom_.x.t)) H.rightCols<1>().setZero();  // a coast says nothing of the offset
    return Linearized<3>{r, EmbedJacobian<3>({{Block::kP, H.leftCols<3>()},
                                              {Block::kTheta, H.middleCols<3>(3)},
                                              {Block::kV, H.middleCols<3>(6)},
                                              {Block::kTd, H.rightCols<1>()}})};
  };
  const Mat3 R = m.sigma_w.cwiseAbs2().asDiagonal();
  const double inflation = gnss_inflation_.factor();
  const double gate = gate_gnss_ * gnss_consistency_.scale();
  Vec3 innovation;
  Mat3 S;
  const bool accepted = Update<3>(model, R, gate, &gnss_counts_, m.t, inflation, &innovation, &S);
  if (accepted) {
    if (inflation > 1.0) {
      gnss_inflation_.CountReacquired();
    } else {
      gnss_consistency_.Add(innovation.dot(S.ldlt().solve(innovation)));
    }
    gnss_inflation_.Accepted();
  } else {
    gnss_inflation_.Rejected(m.t, innovation, S, gate);
  }
  return accepted;
}

void Eskf::UpdateHeading(const GnssMeasurement& m) {
  const Vec3 omega_b = BodyRate();
  const Model<1> model = [&] {
    Eigen::Matrix<double, 1, 1> r;
    Eigen::Matrix<double, 1, 4> H;  // (δθ, δtd)
    Linearize<1, 4>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          const Eigen::Matrix<T, 3, 1> zero = Eigen::Matrix<T, 3, 1>::Zero();
          const ShiftedKinematics<T> k =
              ShiftedState<T>(nom_.x, nom_.Scalar<Block::kTd>(), a_w_, omega_b, zero, d.template head<3>(), zero, d[3]);
          return Eigen::Matrix<T, 1, 1>(HeadingModel::Residual<T>(k.q_wb, sensors_.gnss.mount_yaw, m.yaw_G));
        },
        &r, &H);
    if (PastImuGap(nom_.x.t)) H.rightCols<1>().setZero();  // a coast says nothing of the offset
    return Linearized<1>{r, EmbedJacobian<1>({{Block::kTheta, H.leftCols<3>()}, {Block::kTd, H.rightCols<1>()}})};
  };
  Update<1>(model, Eigen::Matrix<double, 1, 1>(m.sigma_yaw * m.sigma_yaw), gate_heading_, &heading_counts_, m.t);
}

void Eskf::Use(const GnssVelocityMeasurement& m) {
  if (!initialized_ || m.t < nom_.x.t) return;
  Propagate(m.t);
  // The antenna's velocity includes the lever arm's turn: the body rate from the last IMU sample.
  const Vec3 omega_b = BodyRate();
  const Model<3> model = [&] {
    Eigen::Matrix<double, 3, 1> r;
    Eigen::Matrix<double, 3, 7> H;  // (δv, δθ, δtd)
    Linearize<3, 7>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          const ShiftedKinematics<T> k =
              ShiftedState<T>(nom_.x, nom_.Scalar<Block::kTd>(), a_w_, omega_b, Eigen::Matrix<T, 3, 1>::Zero(),
                              d.template segment<3>(3), d.template head<3>(), d[6]);
          return GnssVelocityModel::Residual<T>(k.q_wb, k.v_w, omega_b, sensors_.gnss.lever_b, m.v_w);
        },
        &r, &H);
    if (PastImuGap(nom_.x.t)) H.rightCols<1>().setZero();  // a coast says nothing of the offset
    return Linearized<3>{r, EmbedJacobian<3>({{Block::kV, H.leftCols<3>()},
                                              {Block::kTheta, H.middleCols<3>(3)},
                                              {Block::kTd, H.rightCols<1>()}})};
  };
  Update<3>(model, Mat3(m.sigma_w.cwiseAbs2().asDiagonal()), gate_gnss_, &gnss_velocity_counts_, m.t);
}

void Eskf::Use(const WheelMeasurement& m) {
  if (!initialized_ || m.t < nom_.x.t || !sensors_.wheel.enabled) return;
  Propagate(m.t);
  // At zero pulses this is a zero-speed measurement; the standstill updates (StandstillMeasurement) come from the
  // session's detector, which also wants the IMU quiet.
  UpdateWheelSpeed(m);
  if (m.has_yaw_rate) UpdateWheelYawRate(m);
  wheel_gyro_sum_.setZero();
  wheel_gyro_count_ = 0;
}

void Eskf::UpdateWheelSpeed(const WheelMeasurement& m) {
  // The encoders report the mean speed over their interval: compare with the velocity at its middle (at
  // 1 m/s² and 0.1 s this is a 5 cm/s difference), at the rear-axle centre.
  const Vec3 omega_b = BodyRate();
  const Model<1> model = [&] {
    Eigen::Matrix<double, 1, 1> r;
    Eigen::Matrix<double, 1, 7> H7;  // (δv, δθ, δs)
    const Vec3 v_mid = nom_.x.v_w - a_w_ * (0.5 * m.interval);
    const double s0 = nom_.Scalar<Block::kS>();
    Linearize<1, 7>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          const Eigen::Matrix<T, 3, 1> v = v_mid.cast<T>() + d.template head<3>();
          const T s = T(s0) + d[6];
          return Eigen::Matrix<T, 1, 1>(AxleSpeedModel::Residual<T>(
              Rotated<T>(nom_.x, Eigen::Matrix<T, 3, 1>(d.template segment<3>(3))), v, s, omega_b,
              sensors_.wheel.lever_b, m.speed));
        },
        &r, &H7);
    if (!sensors_.wheel.estimate_scale) H7(0, 6) = 0.0;  // a scale held fixed takes no correction
    return Linearized<1>{r, EmbedJacobian<1>({{Block::kV, H7.leftCols<3>()},
                                              {Block::kTheta, H7.middleCols<3>(3)},
                                              {Block::kS, H7.rightCols<1>()}})};
  };
  Update<1>(model, Eigen::Matrix<double, 1, 1>(m.sigma * m.sigma), gate_wheel_, &wheel_counts_, m.t);
}

void Eskf::UpdateWheelYawRate(const WheelMeasurement& m) {
  if (wheel_gyro_count_ == 0 || m.interval <= 0.0) return;
  // The wheels' turn rate (read with the odometer scale, as their speeds are) against the gyro's mean
  // over the same interval: it observes the gyro's z bias (and the scale, weakly).
  const Vec3 mean_gyro = wheel_gyro_sum_ / wheel_gyro_count_;
  const Model<1> model = [&] {
    const double omega_z = (mean_gyro - nom_.x.bg - nom_.x.q_wb.conjugate() * earth_.rate_w()).z();
    Eigen::Matrix<double, 1, eskf::kDim> H = Eigen::Matrix<double, 1, eskf::kDim>::Zero();
    H(0, eskf::Offset(Block::kBg) + 2) = -nom_.Scalar<Block::kS>();
    if (sensors_.wheel.estimate_scale) H(0, eskf::kS) = omega_z;
    return Linearized<1>{Eigen::Matrix<double, 1, 1>(nom_.Scalar<Block::kS>() * omega_z - m.yaw_rate), H};
  };
  // The gyro's own noise over the interval adds to the wheels'.
  const double gyro_var = std::pow(sensors_.imu.gyro_noise_density, 2) / m.interval;
  const double var =
      m.yaw_rate_sigma * m.yaw_rate_sigma + nom_.Scalar<Block::kS>() * nom_.Scalar<Block::kS>() * gyro_var;
  Update<1>(model, Eigen::Matrix<double, 1, 1>(var), gate_wheel_yaw_, &wheel_yaw_counts_, m.t);
}

void Eskf::UpdateNonHolonomic(double t) {
  const Vec3 omega_b = BodyRate();
  const Model<2> model = [&] {
    Eigen::Matrix<double, 2, 1> r;
    Eigen::Matrix<double, 2, 6> H6;  // (δv, δθ)
    Linearize<2, 6>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          const Eigen::Matrix<T, 3, 1> v = nom_.x.v_w.cast<T>() + d.template head<3>();
          return AxleNhcModel::Residual<T>(Rotated<T>(nom_.x, Eigen::Matrix<T, 3, 1>(d.template tail<3>())), v, omega_b,
                                           sensors_.wheel.lever_b);
        },
        &r, &H6);
    return Linearized<2>{r, EmbedJacobian<2>({{Block::kV, H6.leftCols<3>()}, {Block::kTheta, H6.rightCols<3>()}})};
  };
  const double s2 = sensors_.vehicle.nhc_sigma * sensors_.vehicle.nhc_sigma;
  Update<2>(model, Eigen::Matrix2d::Identity() * s2, gate_nhc_, &nhc_counts_, t);
}

void Eskf::Use(const StandstillMeasurement& m) {
  if (!initialized_ || m.t < nom_.x.t) return;
  Propagate(m.t);
  // The gyro mean since the last update observes the bias only if the whole interval was standing.
  const bool rate_usable = gyro_count_ > 0 && gyro_sum_start_ >= m.since && m.t > gyro_sum_start_;
  const Vec3 mean_gyro = gyro_count_ > 0 ? Vec3(gyro_sum_ / gyro_count_) : Vec3::Zero();
  const double T = m.t - gyro_sum_start_;
  gyro_sum_.setZero();
  gyro_count_ = 0;
  gyro_sum_start_ = m.t;
  if (!StandstillPlausible(nom_.x.v_w, standstill_options_)) {
    zupt_counts_.Reject("moving", m.t);  // a quiet IMU at speed: not a stop
    return;
  }
  {
    const StateEstimate e = Estimate();
    const double sigma_tilt = e.sigma_att.head<2>().maxCoeff();
    const double sigma_ba = std::sqrt(BlockOf<Block::kBa>(P_).diagonal().maxCoeff());
    if (AcceleratingWithoutWitness(m, nom_.x, earth_.Gravity(nom_.x.p_wb) + nom_.Get<Block::kG>(), sigma_tilt, sigma_ba,
                                   sensors_.imu.acc_noise_density)) {
      zupt_counts_.Reject("accelerating", m.t);  // braking smoothly, nothing to say it stopped
      return;
    }
  }
  // Standing: zero velocity, and the gyro reads its bias (zero-rate update), so nothing wanders.
  const double sv = standstill_options_.velocity_sigma;
  Update<3>([&] { return Linearized<3>{nom_.x.v_w, EmbedJacobian<3>({{Block::kV, Mat3::Identity()}})}; },
            Mat3::Identity() * sv * sv, gate_zupt_, &zupt_counts_, m.t);
  if (rate_usable) {
    // Standing on the rotating Earth, the gyro reads its bias plus the Earth rate.
    const double sigma = ZeroRateSigma(sensors_.imu.gyro_noise_density, T);
    Update<3>(
        [&] {
          return Linearized<3>{Vec3(nom_.x.bg + nom_.x.q_wb.conjugate() * earth_.rate_w() - mean_gyro),
                               EmbedJacobian<3>({{Block::kBg, Mat3::Identity()}})};
        },
        Mat3::Identity() * sigma * sigma, gate_zero_rate_, &zupt_counts_, m.t);
  }
}

}  // namespace gins
