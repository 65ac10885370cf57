#include "factors/preint_attached_factor.h"

#include <ceres/autodiff_cost_function.h>
#include <glog/logging.h>

#include "core/so3.h"
#include "factors/delayed_factor.h"
#include "factors/raw_gnss_factor.h"

namespace gins {
namespace {

using Mat9x15 = Eigen::Matrix<double, 9, 15>;
// Rows (δp_t, δθ_t, δv_t), columns (δp_i, δθ_i, δv_i, δbg, δba).
constexpr int kRowP = 0, kRowTheta = 3, kRowV = 6;
constexpr int kColP = 0, kColTheta = 3, kColV = 6, kColBg = 9;  // δba: columns 12-14, after δbg

// The prediction's Jacobian (see PreintAttachedCostFunction in the header).
Mat9x15 PredictionJacobian(const Preintegration& pre, const ImuEarthTerms& earth, const EarthTurns& turns,
                           const Quat& q_i, const Vec3& bg, const Vec3& ba) {
  const Preintegration::Delta d = pre.Corrected(bg, ba);
  const Mat96& Jb = pre.bias_jacobian();
  const Mat3 R_i = q_i.toRotationMatrix();
  const double T = pre.dt();
  const Mat3 A = turns.m_inv;  // identity for the flat Earth
  const Mat3 Rp = turns.back_p.toRotationMatrix() * R_i;
  const Mat3 Rv = turns.back_v.toRotationMatrix() * R_i;
  Mat9x15 J = Mat9x15::Zero();
  // δp_t − δp_i first (the Coriolis term of δv_t needs it), then δp_t adds δp_i.
  Eigen::Matrix<double, 3, 15> dP = Eigen::Matrix<double, 3, 15>::Zero();
  dP.block<3, 3>(0, kColV) = A * T;
  dP.block<3, 3>(0, kColTheta) = -A * Rp * Hat<double>(d.dp);
  dP.block<3, 6>(0, kColBg) = A * Rp * Jb.middleRows<3>(preint::kP);
  J.middleRows<3>(kRowP) = dP;
  J.block<3, 3>(kRowP, kColP).setIdentity();
  J.block<3, 3>(kRowTheta, kColTheta) = d.dq.toRotationMatrix().transpose();
  const Vec3 phi = Jb.block<3, 3>(preint::kTheta, preint::kBg) * (bg - pre.bg_lin());
  J.block<3, 3>(kRowTheta, kColBg) = RightJacobian(phi) * Jb.block<3, 3>(preint::kTheta, preint::kBg);
  J.block<3, 3>(kRowV, kColV).setIdentity();
  J.block<3, 3>(kRowV, kColTheta) = -Rv * Hat<double>(d.dv);
  J.block<3, 6>(kRowV, kColBg) = Rv * Jb.middleRows<3>(preint::kV);
  if (turns.rotating) J.middleRows<3>(kRowV) -= 2.0 * Hat<double>(earth.rate_w) * dP;
  return J;
}

// One block's Jacobian (M rows) into Ceres's row-major array, when Ceres asks for it.
template <typename Derived>
void WriteJacobian(const Eigen::MatrixBase<Derived>& J, double* out) {
  constexpr int R = Derived::RowsAtCompileTime, C = Derived::ColsAtCompileTime;
  if (out == nullptr) return;
  Eigen::Map<Eigen::Matrix<double, R, C, C == 1 ? Eigen::ColMajor : Eigen::RowMajor>> block(out);
  block = J;
}

// A measurement at k's time − td (Delayed, core/time_shift.h), in (δp, δθ, δv, td): the model's Jacobian
// (Linearize) at the shifted state times the shift's, in closed form: δp_s = δp − td·δv, δv_s = δv,
// δθ_s = Exp(ω·td)·δθ, and in td: −v + a·td, −a, −ω (the rotation's right Jacobian keeps its axis).
template <class Measurement>
Eigen::Matrix<double, Measurement::kResidualDim, 10> MeasureDelayedAt(const Delayed<Measurement>& d,
                                                                      const PredictedKinematics<double>& k,
                                                                      double td, double* residuals) {
  const ShiftedKinematics<double> s = ShiftBack<double>(k.p, k.v, k.q, d.a_w, d.omega_b, td);
  const auto J_s = d.measurement.Linearize(PredictedKinematics<double>{s.p_wb, s.v_w, s.q_wb}, residuals);
  // J_s·S column block by column block (S is sparse: a dense 9×10 product costs more than the model).
  constexpr int M = Measurement::kResidualDim;
  Eigen::Matrix<double, M, 10> J;
  const auto J_p = J_s.template middleCols<3>(kRowP);
  const auto J_theta = J_s.template middleCols<3>(kRowTheta);
  const auto J_v = J_s.template middleCols<3>(kRowV);
  J.template middleCols<3>(kRowP) = J_p;
  J.template middleCols<3>(kRowTheta) = J_theta * ExpMat(d.omega_b * td);
  J.template middleCols<3>(kRowV) = J_v - td * J_p;
  J.col(9) = J_p * (d.a_w * td - k.v) - J_theta * d.omega_b - J_v * d.a_w;
  return J;
}

// The measurement at the state predicted at its stamp t (kDelayed: at t − td, td the fourth block), its
// Jacobians the prediction's times the measurement's own.
template <class Measurement, bool kDelayed>
bool EvaluateAttached(const PreintAttachedFactor<Measurement>& factor, const Vec3& a_w, const Vec3& omega_b,
                      double const* const* parameters, double* residuals, double** jacobians) {
  constexpr int M = Measurement::kResidualDim;
  const double* pose_i = parameters[0];
  const Eigen::Map<const Vec3> p_i(pose_i + pose::kP), v_i(parameters[1]);
  const Eigen::Map<const Quat> q_i(pose_i + pose::kQ);
  const Eigen::Map<const Vec3> bg(parameters[2]), ba(parameters[2] + 3);
  const Preintegration& pre = factor.preintegration();
  const PredictedKinematics<double> k = PredictKinematics<double>(
      pre, factor.earth(), factor.turns(), Vec3(p_i), Quat(q_i), Vec3(v_i), Vec3(bg), Vec3(ba));
  Eigen::Matrix<double, M, kDelayed ? 10 : 9> J_meas;
  if constexpr (kDelayed) {
    J_meas = MeasureDelayedAt(Delayed<Measurement>{factor.measurement(), a_w, omega_b}, k, parameters[3][0],
                              residuals);
  } else {
    J_meas = factor.measurement().Linearize(k, residuals);
  }
  if (jacobians == nullptr) return true;
  const Eigen::Matrix<double, M, 9> J_state = J_meas.template leftCols<9>();
  const Eigen::Matrix<double, M, 15> J =
      J_state * PredictionJacobian(pre, factor.earth(), factor.turns(), Quat(q_i), Vec3(bg), Vec3(ba));
  if (jacobians[0] != nullptr) {  // pose_i: tangent (δp, δθ) lifted to the ambient block
    WriteAmbientPoseJacobian<M>(J.template middleCols<3>(kColP), J.template middleCols<3>(kColTheta), Quat(q_i),
                                jacobians[0]);
  }
  WriteJacobian(J.template middleCols<3>(kColV), jacobians[1]);
  WriteJacobian(J.template middleCols<6>(kColBg), jacobians[2]);
  if constexpr (kDelayed) WriteJacobian(J_meas.template rightCols<1>(), jacobians[3]);
  return true;
}

}  // namespace

template <class Measurement>
bool PreintAttachedCostFunction<Measurement>::Evaluate(double const* const* parameters, double* residuals,
                                                       double** jacobians) const {
  return EvaluateAttached<Measurement, false>(factor_, Vec3::Zero(), Vec3::Zero(), parameters, residuals,
                                              jacobians);
}

template <class Measurement>
bool DelayedAttachedCostFunction<Measurement>::Evaluate(double const* const* parameters, double* residuals,
                                                        double** jacobians) const {
  return EvaluateAttached<Measurement, true>(factor_, a_w_, omega_b_, parameters, residuals, jacobians);
}

template <class Measurement>
bool DelayedAtKeyframeCostFunction<Measurement>::Evaluate(double const* const* parameters, double* residuals,
                                                          double** jacobians) const {
  constexpr int M = Measurement::kResidualDim;
  const Eigen::Map<const Quat> q(parameters[0] + pose::kQ);
  const PredictedKinematics<double> k{Eigen::Map<const Vec3>(parameters[0] + pose::kP),
                                      Eigen::Map<const Vec3>(parameters[1]), Quat(q)};
  const Delayed<Measurement>& d = factor_.delayed();
  const Eigen::Matrix<double, M, 10> J = MeasureDelayedAt(d, k, parameters[2][0], residuals);
  if (jacobians == nullptr) return true;
  if (jacobians[0] != nullptr) {
    WriteAmbientPoseJacobian<M>(J.template middleCols<3>(kRowP), J.template middleCols<3>(kRowTheta), Quat(q),
                                jacobians[0]);
  }
  WriteJacobian(J.template middleCols<3>(kRowV), jacobians[1]);
  WriteJacobian(J.template rightCols<1>(), jacobians[2]);
  return true;
}

namespace {
// DelayedAttachedCostFunction's residual for autodiff: PredictKinematics, then the shift and the model.
template <class Measurement>
struct DelayedAttachedResidual {
  PreintAttachedFactor<Measurement> factor;
  Vec3 a_w, omega_b;
  template <typename T>
  bool operator()(const T* pose_i, const T* vel_i, const T* bias_i, const T* td, T* residual) const {
    using Vec3T = Eigen::Matrix<T, 3, 1>;
    const PredictedKinematics<T> k = PredictKinematics<T>(
        factor.preintegration(), factor.earth(), factor.turns(), Vec3T(PosePosition(pose_i)),
        Eigen::Quaternion<T>(PoseRotation(pose_i)), Eigen::Map<const Vec3T>(vel_i), Eigen::Map<const Vec3T>(bias_i),
        Eigen::Map<const Vec3T>(bias_i + 3));
    Delayed<Measurement>{factor.measurement(), a_w, omega_b}(k, td[0], residual);
    return true;
  }
};
}  // namespace

template <class Measurement>
ceres::CostFunction* DelayedAttachedCostFunction<Measurement>::Create(std::shared_ptr<const Preintegration> preint,
                                                                      const ImuEarthTerms& earth,
                                                                      Delayed<Measurement> delayed) {
  CHECK(preint != nullptr && preint->dt() > 0.0) << "DelayedAttachedCostFunction over an empty preintegration";
  return new DelayedAttachedCostFunction<Measurement>(std::move(preint), earth, std::move(delayed));
}

template <class Measurement>
ceres::CostFunction* DelayedAttachedCostFunction<Measurement>::CreateAutoDiff(
    std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth, Delayed<Measurement> delayed) {
  CHECK(preint != nullptr && preint->dt() > 0.0) << "DelayedAttachedCostFunction over an empty preintegration";
  using Residual = DelayedAttachedResidual<Measurement>;
  return new ceres::AutoDiffCostFunction<Residual, Measurement::kResidualDim, pose::kAmbient, 3, 6, 1>(
      new Residual{PreintAttachedFactor<Measurement>(std::move(preint), earth, delayed.measurement), delayed.a_w,
                   delayed.omega_b});
}

template class PreintAttachedCostFunction<GnssAtTime>;
template class PreintAttachedCostFunction<HeadingAtTime>;
template class PreintAttachedCostFunction<GnssVelocityAtTime>;
template class PreintAttachedCostFunction<RawRangeAtTime>;
template class PreintAttachedCostFunction<RawRateAtTime>;
template class DelayedAttachedCostFunction<GnssAtTime>;
template class DelayedAttachedCostFunction<HeadingAtTime>;
template class DelayedAttachedCostFunction<GnssVelocityAtTime>;
template class DelayedAtKeyframeCostFunction<GnssAtTime>;
template class DelayedAtKeyframeCostFunction<HeadingAtTime>;
template class DelayedAtKeyframeCostFunction<GnssVelocityAtTime>;

}  // namespace gins
