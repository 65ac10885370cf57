#include "solver/eskf.h"

#include <glog/logging.h>

#include <cmath>

#include "core/chi2.h"
#include "core/gnss_model.h"
#include "core/gvel_model.h"
#include "core/heading_model.h"
#include "core/imu_kernel.h"
#include "core/linearize.h"
#include "core/so3.h"
#include "core/wheel_model.h"

namespace gins {

using eskf::Block;
using eskf::BlockOf;

namespace {

constexpr double kZeroRateGateProbability = 0.9999;  // the gyro-reads-its-bias update at standstills

}  // namespace

Eskf::Eskf(const EstimatorOptions& options, StateCallback on_state)
    : options_(options), on_state_(std::move(on_state)), watchdog_(options.watchdog) {
  gate_gnss_ = Chi2Gate(options_.gnss.gate_probability, 3);
  gate_heading_ = Chi2Gate(options_.gnss.gate_probability, 1);
  gate_wheel_ = Chi2Gate(options_.wheel.gate_probability, 1);
  gate_nhc_ = Chi2Gate(options_.wheel.gate_probability, 2);
  gate_zupt_ = Chi2Gate(options_.wheel.gate_probability, 3);
  gate_zero_rate_ = Chi2Gate(kZeroRateGateProbability, 3);
}

void Eskf::Initialize(const InitResult& init) {
  x_ = init.x0;
  earth_ = init.earth;
  dg_w_.setZero();
  scale_ = 1.0;
  P_.setZero();
  P_.topLeftCorner<nav::kDim, nav::kDim>() = init.P0;
  if (options_.eskf.estimate_gravity) {
    BlockOf<Block::kG>(P_).diagonal().setConstant(options_.eskf.gravity_sigma * options_.eskf.gravity_sigma);
  }
  if (options_.wheel.enabled && options_.wheel.estimate_scale) {
    P_(eskf::kS, eskf::kS) = options_.wheel.scale_sigma * options_.wheel.scale_sigma;
  }
  last_imu_.reset();
  gyro_sum_.setZero();
  gyro_count_ = 0;
  gyro_sum_start_ = x_.t;
  watchdog_.Clear();
  initialized_ = true;
  if (on_state_) on_state_(Estimate());
}

void Eskf::Propagate(double t, const ImuSample* held) {
  const double dt = t - x_.t;
  if (dt <= 0.0 || !last_imu_) return;
  if (held == nullptr) held = &*last_imu_;
  // Across an IMU gap, coast: no rotation, no acceleration (the held sample says nothing about the gap).
  const bool gap = t - last_imu_->t > options_.imu.max_gap;
  const Vec3 g_w = gravity();
  const Vec3& rate_w = earth_.rate_w();
  const Vec3 omega = gap ? Vec3(x_.q_wb.conjugate() * rate_w) : Vec3(held->gyro - x_.bg);
  const Vec3 acc = gap ? Vec3(x_.q_wb.conjugate() * (2.0 * rate_w.cross(x_.v_w) - g_w)) : Vec3(held->acc - x_.ba);
  Kinematics k{x_.q_wb, x_.v_w, x_.p_wb};
  ImuStepJacobians J;
  k = ImuStep(k, omega, acc, g_w, dt, &J, rate_w);
  a_w_ = (k.v - x_.v_w) / dt;
  x_.q_wb = k.q;
  x_.v_w = k.v;
  x_.p_wb = k.p;
  x_.t = t;
  ++imu_steps_;
  PropagateCovariance(J, dt, gap);
}

void Eskf::PropagateCovariance(const ImuStepJacobians& J, double dt, bool gap) {
  // F = [[A, C], [0, I]] with the kinematic block a = (δp, δv, δθ) and b = (δbg, δba, δg, δs), C = [B G 0]:
  // P'aa = A·Paa·Aᵀ + A·Pab·Cᵀ + C·Pba·Aᵀ + C·Pbb·Cᵀ = (A·M1ᵀ + C·Mᵀ)ᵀ with M1 = A·Paa + C·Pba and
  // M = P'ab = A·Pab + C·Pbb. The products skip A's and C's zero and identity blocks (MulA, MulBG). C has
  // columns for the driving blocks (δbg, δba, δg) only, so Pba and Pbb enter through their driving rows.
  constexpr int kA = eskf::kKinematicDim, kB = eskf::kNonKinematicDim, kD = eskf::kDrivingDim;
  using MatAA = Eigen::Matrix<double, kA, kA>;
  using MatAB = Eigen::Matrix<double, kA, kB>;
  const bool with_g = options_.eskf.estimate_gravity;
  const MatAA Paa = P_.topLeftCorner<kA, kA>();
  const MatAB Pab = P_.topRightCorner<kA, kB>();
  const Eigen::Matrix<double, kD, kA> PbaD = P_.block<kD, kA>(kA, 0);
  const Eigen::Matrix<double, kD, kB> PbbD = P_.block<kD, kB>(kA, kA);
  const MatAB M = MulA<kB>(J, Pab) + MulBG<kB>(J, PbbD, with_g);
  const MatAA M1 = MulA<kA>(J, Paa) + MulBG<kA>(J, PbaD, with_g);
  const Eigen::Matrix<double, kD, kA> MtC = M.leftCols<kD>().transpose();  // driving rows of Mᵀ
  P_.topLeftCorner<kA, kA>() = (MulA<kA>(J, MatAA(M1.transpose())) + MulBG<kA>(J, MtC, with_g)).transpose();
  P_.topRightCorner<kA, kB>() = M;
  P_.bottomLeftCorner<kB, kA>() = M.transpose();

  // Process noise: sensor white noise through B, bias and scale random walks.
  Mat6 Qn = ImuDiscreteNoise(options_.imu.gyro_noise_density, options_.imu.acc_noise_density, dt);
  if (gap) {
    // An unknown rate and acceleration held over the step enter where the held sample does.
    Qn.diagonal() += (Vec6() << Vec3::Constant(kImuGapRateSigma * kImuGapRateSigma),
                      Vec3::Constant(kImuGapAccSigma * kImuGapAccSigma))
                         .finished();
  }
  const Eigen::Matrix<double, kA, 6> BQ = J.B.lazyProduct(Qn);
  P_.topLeftCorner<kA, kA>() += BQ.lazyProduct(J.B.transpose());
  AddRandomWalks(dt);
}

void Eskf::AddRandomWalks(double dt) {
  const double qbg = options_.imu.gyro_bias_rw * options_.imu.gyro_bias_rw * dt;
  const double qba = options_.imu.acc_bias_rw * options_.imu.acc_bias_rw * dt;
  BlockOf<Block::kBg>(P_).diagonal().array() += qbg;
  BlockOf<Block::kBa>(P_).diagonal().array() += qba;
  if (options_.wheel.enabled && options_.wheel.estimate_scale) {
    P_(eskf::kS, eskf::kS) += options_.wheel.scale_rw * options_.wheel.scale_rw * dt;
  }
}

void Eskf::AddImu(const ImuSample& imu) {
  if (!initialized_) return;
  if (imu.t < x_.t) return;  // samples before the initialisation epoch were used by the initialiser
  if (last_imu_ && imu.t - last_imu_->t > options_.imu.max_gap) {
    imu_gaps_.Add(last_imu_->t, imu.t);
  }
  if (last_imu_) {
    const ImuSample mid = HeldBetween(*last_imu_, imu);
    Propagate(imu.t, &mid);
  }
  last_imu_ = imu;
  gyro_sum_ += imu.gyro;
  ++gyro_count_;
  if (on_state_) on_state_(Estimate());
}

template <int M>
bool Eskf::Update(const Eigen::Matrix<double, M, 1>& r, std::initializer_list<eskf::BlockJacobian<M>> H,
                  const Eigen::Matrix<double, M, M>& R, double gate, MeasurementCounts* counts, double t) {
  VecP dx;
  if (!eskf::GatedUpdate<M, eskf::kDim>(r, eskf::EmbedJacobian<M>(H), R, gate, t, counts, &P_, &dx)) {
    return false;
  }
  Inject(dx);
  return true;
}

void Eskf::Inject(const VecP& dx) {
  x_ = x_.Boxplus(dx.head<nav::kDim>());
  dg_w_ += eskf::SegmentOf<Block::kG>(dx);
  scale_ += dx[eskf::kS];
  // Reset: the error is now zero about the corrected rotation; project the covariance accordingly
  // (right perturbation: ∂δθ⁺/∂δθ = I − ½[δθ]×).
  // Jr is the identity but for its δθ block, so only the δθ rows and columns of P change.
  const Mat3 Jt = Mat3::Identity() - 0.5 * Hat<double>(Vec3(eskf::SegmentOf<Block::kTheta>(dx)));
  const Eigen::Matrix<double, 3, eskf::kDim> rows = Jt.lazyProduct(eskf::RowsOf<Block::kTheta>(P_));
  eskf::RowsOf<Block::kTheta>(P_) = rows;
  const Eigen::Matrix<double, eskf::kDim, 3> cols = eskf::ColsOf<Block::kTheta>(P_).lazyProduct(Jt.transpose());
  eskf::ColsOf<Block::kTheta>(P_) = cols;
  P_ = 0.5 * (P_ + P_.transpose()).eval();
}

void Eskf::AddGnss(const GnssMeasurement& m) {
  if (!initialized_ || m.t < x_.t) return;
  Propagate(m.t);
  if (options_.watchdog.enabled) {
    const double max_sigma = options_.watchdog.max_position_sigma;
    const bool finite = x_.AllFinite() && P_.allFinite() && dg_w_.allFinite() && std::isfinite(scale_);
    if (!finite || BlockOf<Block::kP>(P_).diagonal().maxCoeff() > max_sigma * max_sigma) {
      ResetFromGnss(m, finite ? "covariance" : "non_finite");
      prev_fix_ = m;
      return;
    }
  }
  bool accepted = false;
  {
    Eigen::Matrix<double, 3, 1> r;
    Eigen::Matrix<double, 3, 6> H6;  // (δp, δθ)
    const NavState& x = x_;
    Linearize<3, 6>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          const Eigen::Matrix<T, 3, 1> p = x.p_wb.cast<T>() + d.template head<3>();
          const Eigen::Quaternion<T> q = x.q_wb.cast<T>() * ExpQuat<T>(d.template tail<3>());
          return GnssPositionModel::Residual<T>(p, q, options_.gnss.lever_b, m.p_w);
        },
        &r, &H6);
    const Mat3 R = m.sigma_w.cwiseAbs2().asDiagonal();
    accepted = Update<3>(r, {{Block::kP, H6.leftCols<3>()}, {Block::kTheta, H6.rightCols<3>()}}, R, gate_gnss_,
                         &gnss_counts_, m.t);
  }
  const bool reset = WatchGnss(m, accepted);
  prev_fix_ = m;
  if (reset) return;
  if (m.heading_valid && options_.gnss.use_heading) {
    Eigen::Matrix<double, 1, 1> r;
    Eigen::Matrix<double, 1, 3> H3;
    const NavState& x = x_;
    Linearize<1, 3>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          const Eigen::Quaternion<T> q = x.q_wb.cast<T>() * ExpQuat<T>(d);
          return Eigen::Matrix<T, 1, 1>(HeadingModel::Residual<T>(q, options_.gnss.mount_yaw, m.yaw_G));
        },
        &r, &H3);
    Eigen::Matrix<double, 1, 1> R;
    R(0, 0) = m.sigma_yaw * m.sigma_yaw;
    Update<1>(r, {{Block::kTheta, H3}}, R, gate_heading_, &heading_counts_, m.t);
  }
}

void Eskf::AddGvel(const GvelMeasurement& m) {
  if (!initialized_ || m.t < x_.t) return;
  Propagate(m.t);
  // The antenna's velocity includes the lever arm's turn: the body rate from the last IMU sample.
  const Vec3 omega_b = BodyRate();
  Eigen::Matrix<double, 3, 1> r;
  Eigen::Matrix<double, 3, 6> H6;  // (δv, δθ)
  const NavState& x = x_;
  Linearize<3, 6>(
      [&](const auto& d) {
        using T = typename std::decay_t<decltype(d)>::Scalar;
        const Eigen::Matrix<T, 3, 1> v = x.v_w.cast<T>() + d.template head<3>();
        const Eigen::Quaternion<T> q = x.q_wb.cast<T>() * ExpQuat<T>(d.template tail<3>());
        return GnssVelocityModel::Residual<T>(q, v, omega_b, options_.gnss.lever_b, m.v_w);
      },
      &r, &H6);
  const Mat3 R = m.sigma_w.cwiseAbs2().asDiagonal();
  Update<3>(r, {{Block::kV, H6.leftCols<3>()}, {Block::kTheta, H6.rightCols<3>()}}, R, gate_gnss_, &gvel_counts_,
            m.t);
}

void Eskf::AddWheel(const WheelMeasurement& m) {
  if (!initialized_ || m.t < x_.t || !options_.wheel.enabled) return;
  Propagate(m.t);
  // At zero pulses this is a zero-speed measurement; the standstill updates (AddStandstill) come from the
  // session's detector, which also wants the IMU quiet.
  {
    Eigen::Matrix<double, 1, 1> r;
    Eigen::Matrix<double, 1, 7> H7;  // (δv, δθ, δs)
    const NavState& x = x_;
    const double s0 = scale_;
    // The encoders report the mean speed over the counting interval: compare with the velocity at its
    // middle (at 1 m/s² and 0.1 s this is a 5 cm/s difference).
    const Vec3 v_mid = x.v_w - a_w_ * (0.5 * m.interval);
    Linearize<1, 7>(
        [&](const auto& d) {
          using T = typename std::decay_t<decltype(d)>::Scalar;
          const Eigen::Matrix<T, 3, 1> v = v_mid.cast<T>() + d.template head<3>();
          const Eigen::Quaternion<T> q = x.q_wb.cast<T>() * ExpQuat<T>(Eigen::Matrix<T, 3, 1>(d.template segment<3>(3)));
          const T s = T(s0) + d[6];
          return Eigen::Matrix<T, 1, 1>(WheelSpeedModel::Residual<T>(q, v, s, m.speed));
        },
        &r, &H7);
    if (!options_.wheel.estimate_scale) H7(0, 6) = 0.0;  // a scale held fixed takes no correction
    Eigen::Matrix<double, 1, 1> R;
    R(0, 0) = m.sigma * m.sigma;
    Update<1>(r,
              {{Block::kV, H7.leftCols<3>()}, {Block::kTheta, H7.middleCols<3>(3)},
               {Block::kS, H7.rightCols<1>()}},
              R, gate_wheel_, &wheel_counts_, m.t);
    if (options_.wheel.nonholonomic) {
      Eigen::Matrix<double, 2, 1> rn;
      Eigen::Matrix<double, 2, 6> H6;
      Linearize<2, 6>(
          [&](const auto& d) {
            using T = typename std::decay_t<decltype(d)>::Scalar;
            const Eigen::Matrix<T, 3, 1> v = x.v_w.cast<T>() + d.template head<3>();
            const Eigen::Quaternion<T> q = x.q_wb.cast<T>() * ExpQuat<T>(Eigen::Matrix<T, 3, 1>(d.template tail<3>()));
            return NonHolonomicModel::Residual<T>(q, v);
          },
          &rn, &H6);
      const double s2 = options_.wheel.nhc_sigma * options_.wheel.nhc_sigma;
      Update<2>(rn, {{Block::kV, H6.leftCols<3>()}, {Block::kTheta, H6.rightCols<3>()}},
                Eigen::Matrix2d::Identity() * s2, gate_nhc_, &wheel_counts_, m.t);
    }
  }
}

void Eskf::AddStandstill(const StandstillMeasurement& m) {
  if (!initialized_ || m.t < x_.t) return;
  Propagate(m.t);
  // The gyro mean since the last update observes the bias only if the whole interval was standing.
  const bool rate_usable = gyro_count_ > 0 && gyro_sum_start_ >= m.since && m.t > gyro_sum_start_;
  const Vec3 mean_gyro = gyro_count_ > 0 ? Vec3(gyro_sum_ / gyro_count_) : Vec3::Zero();
  const double T = m.t - gyro_sum_start_;
  gyro_sum_.setZero();
  gyro_count_ = 0;
  gyro_sum_start_ = m.t;
  if (!StandstillPlausible(x_.v_w, options_.standstill)) {
    zupt_counts_.Reject("moving", m.t);  // a quiet IMU at speed: not a stop
    return;
  }
  // Standing: zero velocity, and the gyro reads its bias (zero-rate update), so nothing wanders.
  const Eigen::Matrix<double, 3, 1> r = x_.v_w;
  const double sv = options_.standstill.velocity_sigma;
  Update<3>(r, {{Block::kV, Mat3::Identity()}}, Mat3::Identity() * sv * sv, gate_zupt_, &zupt_counts_, m.t);
  if (rate_usable) {
    // Standing on the rotating Earth, the gyro reads its bias plus the Earth rate.
    const Eigen::Matrix<double, 3, 1> rg = x_.bg + x_.q_wb.conjugate() * earth_.rate_w() - mean_gyro;
    const double sigma = 2.0 * options_.imu.gyro_noise_density / std::sqrt(T);
    Update<3>(rg, {{Block::kBg, Mat3::Identity()}}, Mat3::Identity() * sigma * sigma, gate_zero_rate_,
              &zupt_counts_, m.t);
  }
}

bool Eskf::WatchGnss(const GnssMeasurement& m, bool accepted) {
  if (!watchdog_.Watch(m.t, accepted)) return false;
  ResetFromGnss(m, "gnss_rejected");
  return true;
}

void Eskf::ResetFromGnss(const GnssMeasurement& m, const std::string& reason) {
  const bool finite = x_.AllFinite() && P_.allFinite();
  if (!finite) {
    x_.q_wb = FallbackAttitude(m, options_);
    x_.bg.setZero();
    x_.ba.setZero();
    x_.v_w.setZero();
    if (!dg_w_.allFinite()) dg_w_.setZero();
    if (!std::isfinite(scale_)) scale_ = 1.0;
    P_.setZero();
    P_.topLeftCorner<nav::kDim, nav::kDim>() = FallbackCovariance(options_);
    if (options_.eskf.estimate_gravity) {
      BlockOf<Block::kG>(P_).diagonal().setConstant(std::pow(options_.eskf.gravity_sigma, 2));
    }
    if (options_.wheel.enabled && options_.wheel.estimate_scale) P_(eskf::kS, eskf::kS) = std::pow(options_.wheel.scale_sigma, 2);
  }
  const bool have_velocity = ResetPositionFromFix(m, prev_fix_, options_, &x_, P_);
  P_ = 0.5 * (P_ + P_.transpose());
  gyro_sum_.setZero();
  gyro_count_ = 0;
  gyro_sum_start_ = m.t;
  watchdog_.Reset(m.t, reason);
  LOG(WARNING) << "eskf watchdog: re-initialised from GNSS at t=" << std::fixed << m.t << " (" << reason
               << (have_velocity ? "; velocity from the last two fixes" : "; velocity kept") << ")";
  if (on_state_) on_state_(Estimate());
}

StateEstimate Eskf::Estimate() const {
  StateEstimate e;
  e.x = x_;
  e.sigma_p = BlockOf<Block::kP>(P_).diagonal().cwiseSqrt();
  e.sigma_v = BlockOf<Block::kV>(P_).diagonal().cwiseSqrt();
  const Mat3 R = x_.R_wb();
  e.sigma_att = (R * BlockOf<Block::kTheta>(P_) * R.transpose()).diagonal().cwiseSqrt();
  e.odom_scale = scale_;
  return e;
}

nlohmann::json Eskf::Stats() const {
  nlohmann::json j;
  j["imu_steps"] = imu_steps_;
  imu_gaps_.ToJson(&j);
  j["watchdog"] = watchdog_.ToJson();
  j["gnss_position"] = gnss_counts_.ToJson();
  j["gnss_heading"] = heading_counts_.ToJson();
  j["gnss_velocity"] = gvel_counts_.ToJson();
  j["wheel"] = wheel_counts_.ToJson();
  j["zero_velocity"] = zupt_counts_.ToJson();
  j["final_odom_scale"] = scale_;
  const Vec3 g_w = gravity();
  j["final_gravity"] = {g_w.x(), g_w.y(), g_w.z()};
  j["final_gyro_bias_deg_h"] = {x_.bg.x() * kRadToDeg * 3600, x_.bg.y() * kRadToDeg * 3600, x_.bg.z() * kRadToDeg * 3600};
  j["final_acc_bias_m_s2"] = {x_.ba.x(), x_.ba.y(), x_.ba.z()};
  return j;
}

}  // namespace gins
