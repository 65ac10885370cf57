#include "solver/eskf.h"

#include <glog/logging.h>

#include <cmath>

#include "core/chi2.h"
#include "core/gnss_model.h"
#include "core/gnss_velocity_model.h"
#include "core/heading_model.h"
#include "core/imu_kernel.h"
#include "core/linearize.h"
#include "core/so3.h"
#include "core/wheel_model.h"
#include "solver/summary_keys.h"

namespace gins {

using eskf::Block;
using eskf::BlockOf;
constexpr int kTd = eskf::Offset(Block::kTd);

namespace {

// Whether any passive block (δs, td) has a variance: if none, their rows and columns of P are zero for good.
bool PassiveEstimated(const SensorOptions& o) {
  return OdometerScaleEstimated(o) || o.gnss.estimate_time_offset;
}

}  // namespace

Eskf::Eskf(const SensorOptions& sensors, const EskfOptions& eskf, const StandstillOptions& standstill,
           const WatchdogOptions& watchdog, StateCallback on_state, StateCallback on_rts)
    : sensors_(sensors),
      eskf_options_(eskf),
      standstill_options_(standstill),
      watchdog_options_(watchdog),
      on_state_(std::move(on_state)),
      on_rts_(std::move(on_rts)),
      gnss_consistency_(sensors.gnss.gate_probability, 3),
      watchdog_(watchdog) {
  gate_gnss_ = Chi2Gate(sensors_.gnss.gate_probability, 3);
  gate_heading_ = Chi2Gate(sensors_.gnss.gate_probability, 1);
  raw_.w_max = std::sqrt(gate_heading_);
  gate_wheel_ = Chi2Gate(sensors_.wheel.gate_probability, 1);
  gate_nhc_ = Chi2Gate(sensors_.wheel.gate_probability, 2);
  gate_wheel_yaw_ = Chi2Gate(sensors_.wheel.gate_probability, 1);
  gate_zupt_ = Chi2Gate(sensors_.wheel.gate_probability, 3);
  gate_zero_rate_ = Chi2Gate(kZeroRateGateProbability, 3);
  SetModuleGates();
  pre_init_.SetBackwardFiller([this](const BackwardSpan& span) {
    return FillBackward(sensors_, eskf_options_, standstill_options_, span);
  });
}

Eskf::~Eskf() = default;

void Eskf::Finish() {
  if (!initialized_) return;
  FlushCovariance();
  if (!rts_) return;
  rts_->AfterUpdates(Nominal(), P_);
  rts_->Smooth(earth_, pre_init_.TwoSided(on_rts_));
}

void Eskf::AddRestState(const StateEstimate& s) { pre_init_.Add(s, on_state_); }

void Eskf::Initialize(const InitResult& init) {
  pre_init_.Start(init, on_state_);
  nom_.x = init.x0;
  earth_ = init.earth;
  nom_.additive = EskfNominal::Start();
  P_.setZero();
  pending_ = PendingCovariance();
  P_.topLeftCorner<nav::kDim, nav::kDim>() = init.P0;
  SetAdditivePriors();
  last_imu_.reset();
  last_sample_t_ = nom_.x.t;
  gyro_sum_.setZero();
  gyro_count_ = 0;
  gyro_sum_start_ = nom_.x.t;
  wheel_gyro_sum_.setZero();
  wheel_gyro_count_ = 0;
  last_nhc_t_ = nom_.x.t;
  gnss_inflation_.Accepted();
  watchdog_.Clear();
  initialized_ = true;
  if (on_rts_) {
    rts_ = std::make_unique<EskfRts>(BridgeNoise{sensors_.imu.gyro_noise_density, sensors_.imu.acc_noise_density},
                                     eskf_options_.estimate_gravity);
    rts_->StartChain(Nominal(), P_);
  }
  if (on_state_) on_state_(Estimate());
}

void Eskf::Propagate(double t, const ImuSample* held) {
  const double dt = t - nom_.x.t;
  if (dt <= 0.0) return;
  if (rts_) rts_->AfterUpdates(Nominal(), P_);  // the updates at nom_.x.t are done
  if (held == nullptr && last_imu_) held = &*last_imu_;
  // Across an IMU gap, coast: no rotation, no acceleration (the held sample says nothing about the gap). The
  // gap is judged from the newest sample, whatever the state's time, and a step no sample covers (a fix
  // after the initialisation, before the first sample) coasts too: the state always reaches t.
  const bool gap = held == nullptr || PastImuGap(t);
  const Vec3 g_w = gravity();
  const Vec3& rate_w = earth_.rate_w();
  const Vec3 omega = gap ? Vec3(nom_.x.q_wb.conjugate() * rate_w) : Vec3(held->gyro - nom_.x.bg);
  const Vec3 acc =
      gap ? Vec3(nom_.x.q_wb.conjugate() * (2.0 * rate_w.cross(nom_.x.v_w) - g_w)) : Vec3(held->acc - nom_.x.ba);
  // The covariance steps per sample, or over intervals of several (FlushCovariance), never across a gap.
  const bool per_sample = gap || eskf_options_.covariance_interval <= 0.0;
  if (gap) FlushCovariance();
  Kinematics k{nom_.x.q_wb, nom_.x.v_w, nom_.x.p_wb};
  if (!per_sample && pending_.steps == 0) {
    pending_.start = k;
    pending_.g_w = g_w;
  }
  ImuStepJacobians J;
  k = ImuStep(k, omega, acc, g_w, dt, per_sample ? &J : nullptr, rate_w);
  if (gap) {
    // The coast's transition (CoastCovariance): its errors depend on neither the attitude nor the biases.
    J.A.block<3, 3>(0, 6).setZero();
    J.A.block<3, 3>(3, 6).setZero();
    J.A.block<3, 3>(6, 6).setIdentity();
    J.B.setZero();
    J.G.setZero();
  }
  if (rts_) rts_->RecordStep(omega + nom_.x.bg, acc + nom_.x.ba, nom_.x.t, dt);
  a_w_ = (k.v - nom_.x.v_w) / dt;
  nom_.x.q_wb = k.q;
  nom_.x.v_w = k.v;
  nom_.x.p_wb = k.p;
  nom_.x.t = t;
  ++imu_steps_;
  if (per_sample) {
    if (rts_) rts_->Compound(J);
    if (gap) {
      CoastCovariance(dt);
    } else {
      PropagateCovariance(J, dt);
    }
  } else {
    pending_.omega = omega;
    pending_.acc = acc;
    pending_.omega_dt += omega * dt;
    pending_.acc_dt += acc * dt;
    pending_.dt += dt;
    ++pending_.steps;
    if (pending_.dt >= eskf_options_.covariance_interval - 1e-9) FlushCovariance();
  }
}

void Eskf::FlushCovariance() {
  if (pending_.steps == 0) return;
  // One kernel step over the interval from its start, at the mean rate and specific force: the first-order
  // transition of the samples' steps (their product differs in second-order terms of the interval). A
  // single step is the sample's own, bit for bit.
  const double dt = pending_.dt;
  const Vec3 omega = pending_.steps == 1 ? pending_.omega : Vec3(pending_.omega_dt / dt);
  const Vec3 acc = pending_.steps == 1 ? pending_.acc : Vec3(pending_.acc_dt / dt);
  ImuStepJacobians J;
  ImuStep(pending_.start, omega, acc, pending_.g_w, dt, &J, earth_.rate_w());
  if (rts_) rts_->Compound(J);
  PropagateCovariance(J, dt);
  pending_ = PendingCovariance();
}

void Eskf::CoastCovariance(double dt) {
  // The coast's mean is a constant velocity and attitude, made without the sensor, so its errors do not
  // depend on the attitude's or the biases' (the kernel's Jacobians would say they do: a tilt would then be
  // read into the velocity, and a returning fix's innovation back into the tilt). F = [[I, I·dt, 0],
  // [0, I, 0], [0, 0, I]] on (δp, δv, δθ), identity elsewhere.
  P_.middleRows<3>(nav::kP) += dt * P_.middleRows<3>(nav::kV);  // F·P
  P_.middleCols<3>(nav::kP) += dt * P_.middleCols<3>(nav::kV);  // (F·P)·Fᵀ
  // The unknown motion as random walks, so a gap cut into steps (by the fixes inside it) grows the same
  // uncertainty as one step: a white acceleration in w, and a rotation mostly about the vertical (a car's
  // roll and pitch change only with the road's grade and banking).
  const double qa = kImuGapAccDensity * kImuGapAccDensity;
  P_.block<3, 3>(nav::kP, nav::kP).diagonal().array() += qa * dt * dt * dt / 3.0;
  P_.block<3, 3>(nav::kP, nav::kV).diagonal().array() += qa * dt * dt / 2.0;
  P_.block<3, 3>(nav::kV, nav::kP).diagonal().array() += qa * dt * dt / 2.0;
  P_.block<3, 3>(nav::kV, nav::kV).diagonal().array() += qa * dt;
  const Vec3 q_w(kImuGapTiltDensity * kImuGapTiltDensity, kImuGapTiltDensity * kImuGapTiltDensity,
                 kImuGapYawDensity * kImuGapYawDensity);
  const Mat3 R_bw = nom_.x.R_wb().transpose();  // δθ is about the body axes
  P_.block<3, 3>(nav::kTheta, nav::kTheta) += R_bw * (q_w * dt).asDiagonal() * R_bw.transpose();
  AddRandomWalks(dt);
}

void Eskf::PropagateCovariance(const ImuStepJacobians& J, double dt) {
  // F = [[A, C], [0, I]] with the kinematic block a = (δp, δv, δθ) and b = (δbg, δba, δg, δs), C = [B G 0]:
  // P'aa = A·Paa·Aᵀ + A·Pab·Cᵀ + C·Pba·Aᵀ + C·Pbb·Cᵀ = M1·Aᵀ + M·Cᵀ with M1 = A·Paa + C·Pba and
  // M = P'ab = A·Pab + C·Pbb. The products skip A's and C's zero and identity blocks, and run transposed
  // (MulAT, MulBGT: P is symmetric, so Pabᵀ = Pba and Pbbᵀ = Pbb are P's own blocks). C has columns for the
  // driving blocks (δbg, δba, δg) only, so Pba and Pbb enter through their driving rows.
  // M's driving and passive rows go separately: 9 and 2 rows unroll and vectorise, 11 do not (a third of
  // the run's covariance cost), and the passive rows of blocks not estimated are zero and stay zero.
  constexpr int kA = eskf::kKinematicDim, kD = eskf::kDrivingDim, kP = eskf::kNonKinematicDim - kD;
  using MatAA = Eigen::Matrix<double, kA, kA>;
  const bool with_g = eskf_options_.estimate_gravity;
  const Eigen::Matrix<double, kD, kA> Mt_driving =
      MulAT<kD>(J, P_.block<kD, kA>(kA, 0)) + MulBGT<kD>(J, P_.block<kD, kD>(kA, kA), with_g);
  if (PassiveEstimated(sensors_)) {
    const Eigen::Matrix<double, kP, kA> Mt_passive =
        MulAT<kP>(J, P_.block<kP, kA>(kA + kD, 0)) + MulBGT<kP>(J, P_.block<kP, kD>(kA + kD, kA), with_g);
    P_.block<kA, kP>(0, kA + kD) = Mt_passive.transpose();
    P_.block<kP, kA>(kA + kD, 0) = Mt_passive;
  }
  const MatAA M1 =
      (MulAT<kA>(J, P_.topLeftCorner<kA, kA>()) + MulBGT<kA>(J, P_.block<kA, kD>(0, kA), with_g)).transpose();
  P_.block<kA, kD>(0, kA) = Mt_driving.transpose();
  P_.block<kD, kA>(kA, 0) = Mt_driving;
  P_.topLeftCorner<kA, kA>() = MulAT<kA>(J, M1) + MulBGT<kA>(J, P_.block<kA, kD>(0, kA), with_g);

  // Process noise: sensor white noise through B, bias and scale random walks.
  const Mat6 Qn = ImuDiscreteNoise(sensors_.imu.gyro_noise_density, sensors_.imu.acc_noise_density, dt);
  AddDrivingNoise(J, Qn.diagonal(), P_.topLeftCorner<kA, kA>());
  AddRandomWalks(dt);
}

void Eskf::SetAdditivePriors() {
  // A block not estimated keeps a zero variance: no update moves it (its gain row is zero).
  if (eskf_options_.estimate_gravity) {
    BlockOf<Block::kG>(P_).diagonal().setConstant(eskf_options_.gravity_sigma * eskf_options_.gravity_sigma);
  }
  if (OdometerScaleEstimated(sensors_)) {
    P_(eskf::kS, eskf::kS) = sensors_.wheel.scale_sigma * sensors_.wheel.scale_sigma;
  }
  if (sensors_.gnss.estimate_time_offset) {
    P_(kTd, kTd) = sensors_.gnss.time_offset_sigma * sensors_.gnss.time_offset_sigma;
  }
}

void Eskf::AddRandomWalks(double dt) {
  const double qbg = sensors_.imu.gyro_bias_rw * sensors_.imu.gyro_bias_rw * dt;
  const double qba = sensors_.imu.acc_bias_rw * sensors_.imu.acc_bias_rw * dt;
  BlockOf<Block::kBg>(P_).diagonal().array() += qbg;
  BlockOf<Block::kBa>(P_).diagonal().array() += qba;
  if (OdometerScaleEstimated(sensors_)) {
    P_(eskf::kS, eskf::kS) += sensors_.wheel.scale_rw * sensors_.wheel.scale_rw * dt;
  }
  if (sensors_.gnss.estimate_time_offset) {
    P_(kTd, kTd) += sensors_.gnss.time_offset_rw * sensors_.gnss.time_offset_rw * dt;
  }
}

void Eskf::AddImu(const ImuSample& imu) {
  if (!initialized_) return;
  if (imu.t < nom_.x.t) return;  // samples before the initialisation epoch were used by the initialiser
  // Before the first sample after the initialisation, its epoch is the newest sample (a dropout right after
  // it is a gap as any other).
  if (PastImuGap(imu.t)) imu_gaps_.Add(last_sample_t_, imu.t);
  const ImuSample mid = last_imu_ ? HeldBetween(*last_imu_, imu) : imu;
  Propagate(imu.t, &mid);
  last_imu_ = imu;
  last_sample_t_ = imu.t;
  gyro_sum_ += imu.gyro;
  ++gyro_count_;
  wheel_gyro_sum_ += imu.gyro;
  ++wheel_gyro_count_;
  // The vehicle's own constraint, at its own rate, wheels or not.
  if (sensors_.vehicle.nonholonomic && imu.t - last_nhc_t_ >= 1.0 / sensors_.vehicle.nhc_rate - 1e-9) {
    last_nhc_t_ = imu.t;
    UpdateNonHolonomic(imu.t);
  }
  if (on_state_) on_state_(Estimate());
}

template <int M>
bool Eskf::Update(const Model<M>& model, const Eigen::Matrix<double, M, M>& R, double gate, MeasurementCounts* counts,
                  double t, double inflation, Eigen::Matrix<double, M, 1>* innovation_out,
                  Eigen::Matrix<double, M, M>* S_out) {
  using MatM = Eigen::Matrix<double, M, M>;
  using MatPM = Eigen::Matrix<double, eskf::kDim, M>;
  FlushCovariance();
  Linearized<M> lin = model();
  if (S_out != nullptr || innovation_out != nullptr) {
    if (S_out != nullptr) *S_out = lin.H * P_.lazyProduct(lin.H.transpose()) + R;
    if (innovation_out != nullptr) *innovation_out = -lin.r;
  }
  // The prior, its covariance doubted by the inflation on the kinematic block (D·P·D keeps it positive).
  MatP P0 = P_;
  if (inflation > 1.0) {
    const double f = std::sqrt(inflation);
    P0.topRows<eskf::kKinematicDim>() *= f;
    P0.leftCols<eskf::kKinematicDim>() *= f;
  }
  MatPM PHt = P0.lazyProduct(lin.H.transpose());
  MatM S = lin.H.lazyProduct(PHt) + R;
  Eigen::LLT<MatM> llt(S);
  if (llt.info() != Eigen::Success || !lin.r.allFinite()) {
    counts->Reject("numerical", t);
    return false;
  }
  if (!(lin.r.dot(llt.solve(lin.r)) <= gate)) {  // a NaN χ² is rejected too
    counts->Reject("chi2_gate", t);
    return false;
  }
  // Iterated update (IKFoM): at iterate x_i = x̂ ⊞ δ the prior is N(−δ, P_i) in x_i's tangent, with P_i
  // the prior covariance carried there (its δθ rows and columns by Jr(δθ)); the Gauss-Newton step from x_i
  // is e = −δ − K_i·(r_i − H_i·δ). One iteration is the classic ESKF update.
  // The prior undoubted: the RTS gain P⁺Φᵀ(P⁻)⁻¹ needs P⁻ consistent with the chain before it (an
  // inflation that doubts both alike leaves the gain unchanged; one on P⁻ alone would cut it).
  if (rts_) rts_->BeforeUpdate(Nominal(), P_);
  const EskfNominal x0 = nom_;
  MatP Pi = P0;
  MatPM K = llt.solve(PHt.transpose()).transpose();
  VecP e = -K * lin.r;
  for (int it = 1;; ++it) {
    position_corrections_ += eskf::SegmentOf<Block::kP>(e);
    nom_.PlusInPlace(e);
    // Converged when the step is below 1 % of the σ of every state.
    const bool small = (e.array().abs() <= 0.01 * Pi.diagonal().array().sqrt()).all();
    if (it >= eskf_options_.iterations || small) break;
    lin = model();
    const VecP delta = nom_.Minus(x0);
    const Mat3 Jr = RightJacobian(Vec3(eskf::SegmentOf<Block::kTheta>(delta)));
    Pi = P0;
    const Eigen::Matrix<double, 3, eskf::kDim> rows = Jr * eskf::RowsOf<Block::kTheta>(Pi);
    eskf::RowsOf<Block::kTheta>(Pi) = rows;
    const Eigen::Matrix<double, eskf::kDim, 3> cols = eskf::ColsOf<Block::kTheta>(Pi) * Jr.transpose();
    eskf::ColsOf<Block::kTheta>(Pi) = cols;
    PHt = Pi.lazyProduct(lin.H.transpose());
    S = lin.H.lazyProduct(PHt) + R;
    llt.compute(S);
    if (llt.info() != Eigen::Success) break;  // keep the last good iterate
    K = llt.solve(PHt.transpose()).transpose();
    e = -delta - K * (lin.r - lin.H * delta);
  }
  // Joseph form at the last linearisation, (I−KH)P(I−KH)ᵀ + KRKᵀ, which keeps P symmetric and positive for
  // any gain, expanded as P − K(PHᵀ)ᵀ − PHᵀKᵀ + KSKᵀ: rank-M products instead of three N×N ones.
  const MatPM KS = K.lazyProduct(S);
  const MatP KHP = K.lazyProduct(PHt.transpose());
  P_ = Pi + KS.lazyProduct(K.transpose()) - KHP - KHP.transpose();
  ResetCovariance(e);
  ++counts->used;
  return true;
}

void Eskf::ResetCovariance(const VecP& dx) {
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

// The measurement updates' instantiations (solver/eskf_measurements.cc calls them).
template bool Eskf::Update<1>(const Model<1>&, const Eigen::Matrix<double, 1, 1>&, double, MeasurementCounts*, double,
                              double, Eigen::Matrix<double, 1, 1>*, Eigen::Matrix<double, 1, 1>*);
template bool Eskf::Update<2>(const Model<2>&, const Eigen::Matrix<double, 2, 2>&, double, MeasurementCounts*, double,
                              double, Eigen::Matrix<double, 2, 1>*, Eigen::Matrix<double, 2, 2>*);
template bool Eskf::Update<3>(const Model<3>&, const Eigen::Matrix<double, 3, 3>&, double, MeasurementCounts*, double,
                              double, Eigen::Matrix<double, 3, 1>*, Eigen::Matrix<double, 3, 3>*);
template bool Eskf::Update<Eigen::Dynamic>(const Model<Eigen::Dynamic>&, const MatX&, double, MeasurementCounts*,
                                           double, double, VecX*, MatX*);

bool Eskf::WatchGnss(const GnssMeasurement& m, bool accepted) {
  if (!watchdog_.Watch(m.t, accepted)) return false;
  ResetFromGnss(m, "gnss_rejected");
  return true;
}

void Eskf::ResetFromGnss(const GnssMeasurement& m, const std::string& reason) {
  FlushCovariance();
  if (rts_) rts_->AfterUpdates(Nominal(), P_);  // the chain before the re-initialisation ends here
  const bool finite = nom_.x.AllFinite() && P_.allFinite();
  if (!finite) {
    nom_.x.q_wb = FallbackAttitude(m, sensors_.gnss);
    nom_.x.bg.setZero();
    nom_.x.ba.setZero();
    nom_.x.v_w.setZero();
    nom_.ResetNonFinite();
    P_.setZero();
    P_.topLeftCorner<nav::kDim, nav::kDim>() = FallbackCovariance(sensors_.imu);
    SetAdditivePriors();
  }
  const FixReset how = ResetPositionFromFix(m, prev_fix_, sensors_, watchdog_options_, &nom_.x, P_, course_wait_.Take());
  phase_epoch_.valid = false;  // the position jumped: no displacement to difference across
  P_ = 0.5 * (P_ + P_.transpose());
  gyro_sum_.setZero();
  gyro_count_ = 0;
  gyro_sum_start_ = m.t;
  watchdog_.Reset(m.t, reason);
  LOG(WARNING) << "eskf watchdog: re-initialised from GNSS at t=" << std::fixed << m.t << " (" << reason << "; "
               << Describe(how) << ")";
  if (rts_) rts_->StartChain(Nominal(), P_);
  if (on_state_) on_state_(Estimate());
}

StateEstimate Eskf::Estimate() const {
  StateEstimate e;
  e.x = nom_.x;
  e.sigma_p = BlockOf<Block::kP>(P_).diagonal().cwiseSqrt();
  e.sigma_v = BlockOf<Block::kV>(P_).diagonal().cwiseSqrt();
  const Mat3 R = nom_.x.R_wb();
  e.sigma_att = (R * BlockOf<Block::kTheta>(P_) * R.transpose()).diagonal().cwiseSqrt();
  e.odom_scale = nom_.Scalar<Block::kS>();
  return e;
}

nlohmann::json Eskf::Stats() const {
  nlohmann::json j;
  j["imu_steps"] = imu_steps_;
  imu_gaps_.ToJson(&j);
  j[summary_keys::kWatchdog] = watchdog_.ToJson();
  j["gnss_position"] = gnss_counts_.ToJson();
  j["gnss_heading"] = heading_counts_.ToJson();
  j["gnss_velocity"] = gnss_velocity_counts_.ToJson();
  if (raw_.epochs > 0) j["gnss_raw"] = raw_.ToJson();
  j["wheel"] = wheel_counts_.ToJson();
  j["wheel_yaw_rate"] = wheel_yaw_counts_.ToJson();
  j["nonholonomic"] = nhc_counts_.ToJson();
  j["gnss_reacquired"] = gnss_inflation_.reacquired();
  j["gnss_gate_scale"] = {{"final", gnss_consistency_.scale()}, {"max", gnss_consistency_.max_scale()}};
  j["zero_velocity"] = zupt_counts_.ToJson();
  AddModuleStats(&j);
  j["final_odom_scale"] = nom_.Scalar<Block::kS>();
  // The GNSS time offset: the stated value plus the estimated part (gnss.time_offset_s).
  j["time_offset"] =
      TimeOffsetJson(sensors_.gnss, nom_.Scalar<Block::kTd>(), std::sqrt(std::max(P_(kTd, kTd), 0.0)));
  const Vec3 g_w = gravity();
  j["final_gravity"] = {g_w.x(), g_w.y(), g_w.z()};
  j["final_gyro_bias_deg_h"] = {nom_.x.bg.x() * kRadToDeg * 3600, nom_.x.bg.y() * kRadToDeg * 3600,
                                nom_.x.bg.z() * kRadToDeg * 3600};
  j["final_acc_bias_m_s2"] = {nom_.x.ba.x(), nom_.x.ba.y(), nom_.x.ba.z()};
  if (rts_) j["rts"] = rts_->Stats();
  return j;
}

}  // namespace gins
