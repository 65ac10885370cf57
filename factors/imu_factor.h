// IMU preintegration factor between keyframes i and j (reference eqs. 4.36, 4.27).
//
// Parameter blocks (order, sizes):
//   pose_i (7: p_wb, q_wb x y z w — factors/pose_manifold.h), vel_i (3: v_w, m/s),
//   bias_i (6: bg rad/s, ba m/s²), pose_j (7), vel_j (3).
// Residual (9), order δp, δv, δθ (the order of Preintegration::cov()), before whitening:
//   r_p = R_iᵀ(p_j − p_i − v_i·Δt − ½g·Δt²) − Δp_corr      (m)
//   r_v = R_iᵀ(v_j − v_i − g·Δt) − Δv_corr                  (m/s)
//   r_θ = Log(ΔR_corrᵀ·R_iᵀ·R_j)                              (rad)
// With the Earth's rotation (ImuEarthTerms, core/preintegration.h; ω = ω_ie in w, D = p_j − p_i,
// E_k = Exp(ω·Δt·k)):
//   r_p = R_iᵀ·E_⅓·((I + [ω]×Δt)·D − v_i·Δt − ½g·Δt²) − Δp_corr
//   r_v = R_iᵀ·E_½·(v_j − v_i − g·Δt + 2ω×D) − Δv_corr
//   r_θ = Log(ΔR_corrᵀ·R_iᵀ·E_1·R_j)
// where (ΔR, Δv, Δp)_corr are first-order corrected for δb = bias_i − (bg_lin, ba_lin) of the
// preintegration. The residual is whitened: r_w = S·r with SᵀS = Σ⁻¹ (S = Lᵀ from the LLT of Σ⁻¹,
// computed once at construction), so |r_w|² is the Mahalanobis distance.
//
// The residual is written once (ImuFactor::Terms, templated). Production uses ImuCostFunction (analytic
// Jacobians, ImuFactor::Create); the AutoDiffCostFunction of the same functor (ImuFactor::CreateAutoDiff)
// is kept as the test oracle.
//
// The factor holds a shared_ptr to a const Preintegration and reads it in Evaluate (possibly from several
// threads): whoever re-integrates must build a new Preintegration and a new factor, never mutate the one a
// live factor points to.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/sized_cost_function.h>

#include <memory>
#include <utility>

#include "core/conventions.h"
#include "core/preintegration.h"
#include "core/so3.h"
#include "factors/pose_manifold.h"

namespace gins {

// Square root S (SᵀS = Σ⁻¹) of the information of a 9×9 covariance. Uses the LLT of Σ⁻¹ when Σ is well
// conditioned; otherwise (e.g. a one-sample interval, where δp and δv share the same noise) eigenvalues
// below 1e-12·λmax are floored there, so S stays finite.
Mat9 SqrtInformation(const Mat9& cov);

// Unwhitened residual of ImuFactor and the intermediate terms its analytic Jacobians reuse (one evaluation
// of the model; see ImuFactor::Terms).
template <typename T>
struct ImuResidualTerms {
  Eigen::Matrix<T, 9, 1> r;       // (r_p, r_v, r_θ), unwhitened
  Eigen::Matrix<T, 3, 1> dp_i;    // R_iᵀ(p_j − p_i − v_i·Δt − ½g·Δt²)
  Eigen::Matrix<T, 3, 1> dv_i;    // R_iᵀ(v_j − v_i − g·Δt)
  Eigen::Matrix<T, 3, 1> phi_bg;  // ∂ΔR/∂bg·δbg, the bias correction of ΔR (rad)
  Eigen::Quaternion<T> q_ij;      // R_iᵀ·R_j
  Eigen::Quaternion<T> q_err;     // ΔR_corrᵀ·R_iᵀ·R_j; r_θ = Log(q_err)
};

class ImuFactor {
 public:
  static constexpr int kResidualDim = 9;

  ImuFactor(std::shared_ptr<const Preintegration> preint, const Vec3& g_w);
  ImuFactor(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth);

  // The residual model, written once: the autodiff oracle (operator()) and the analytic cost function
  // (ImuCostFunction) both evaluate it through here.
  template <typename T>
  void Terms(const T* pose_i, const T* vel_i, const T* bias_i, const T* pose_j, const T* vel_j,
             ImuResidualTerms<T>* terms) const {
    using Vec3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Vec3T> p_i(pose_i), v_i(vel_i), p_j(pose_j), v_j(vel_j);
    const Eigen::Map<const Eigen::Quaternion<T>> q_i(pose_i + pose::kQ), q_j(pose_j + pose::kQ);
    const Eigen::Map<const Vec3T> bg(bias_i), ba(bias_i + 3);
    const Preintegration& pi = *preint_;

    // First-order bias correction about the preintegration's linearisation point.
    const Vec3T dbg = bg - pi.bg_lin().cast<T>();
    const Vec3T dba = ba - pi.ba_lin().cast<T>();
    terms->phi_bg = pi.dR_dbg().cast<T>() * dbg;
    const Eigen::Quaternion<T> dq_corr = pi.dq().cast<T>() * ExpQuat<T>(terms->phi_bg);
    const Vec3T dv_corr = pi.dv().cast<T>() + pi.dv_dbg().cast<T>() * dbg + pi.dv_dba().cast<T>() * dba;
    const Vec3T dp_corr = pi.dp().cast<T>() + pi.dp_dbg().cast<T>() * dbg + pi.dp_dba().cast<T>() * dba;

    const T dt = T(pi.dt());
    const Vec3T g = g_w_.cast<T>();
    const Eigen::Quaternion<T> q_iw = q_i.conjugate();
    if (rotating_) {
      const Vec3T w = rate_w_.cast<T>();
      const Vec3T D = p_j - p_i;
      terms->dp_i = (q_iw * turn_p_.cast<T>()) * Vec3T(D + w.cross(D) * dt - v_i * dt - T(0.5) * g * dt * dt);
      terms->dv_i = (q_iw * turn_v_.cast<T>()) * Vec3T(v_j - v_i - g * dt + T(2) * w.cross(D));
      terms->q_ij = q_iw * turn_r_.cast<T>() * q_j;
    } else {
      terms->dp_i = q_iw * Vec3T(p_j - p_i - v_i * dt - T(0.5) * g * dt * dt);
      terms->dv_i = q_iw * Vec3T(v_j - v_i - g * dt);
      terms->q_ij = q_iw * q_j;
    }
    terms->q_err = dq_corr.conjugate() * terms->q_ij;
    terms->r.template segment<3>(preint::kP) = terms->dp_i - dp_corr;
    terms->r.template segment<3>(preint::kV) = terms->dv_i - dv_corr;
    terms->r.template segment<3>(preint::kTheta) = LogQuat<T>(terms->q_err);
  }

  template <typename T>
  bool operator()(const T* pose_i, const T* vel_i, const T* bias_i, const T* pose_j, const T* vel_j,
                  T* residual) const {
    ImuResidualTerms<T> terms;
    Terms(pose_i, vel_i, bias_i, pose_j, vel_j, &terms);
    Eigen::Map<Eigen::Matrix<T, 9, 1>> residual_out(residual);
    residual_out = sqrt_info_.cast<T>() * terms.r;
    return true;
  }

  // The production cost function: ImuCostFunction (analytic Jacobians); caller owns it (or hands it to a
  // Problem).
  static ceres::CostFunction* Create(std::shared_ptr<const Preintegration> preint, const Vec3& g_w);
  static ceres::CostFunction* Create(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth);
  // AutoDiffCostFunction<ImuFactor, 9, 7, 3, 6, 7, 3> of the same residual: the test oracle of Create's
  // Jacobians (about 20× slower with Jacobians).
  static ceres::CostFunction* CreateAutoDiff(std::shared_ptr<const Preintegration> preint, const Vec3& g_w);
  static ceres::CostFunction* CreateAutoDiff(std::shared_ptr<const Preintegration> preint,
                                             const ImuEarthTerms& earth);

  const Mat9& sqrt_information() const { return sqrt_info_; }
  const Preintegration& preintegration() const { return *preint_; }
  bool rotating() const { return rotating_; }
  const Vec3& rate_w() const { return rate_w_; }
  // E_⅓, E_½, E_1 of the residual (identity for the flat model).
  const Quat& turn_p() const { return turn_p_; }
  const Quat& turn_v() const { return turn_v_; }
  const Quat& turn_r() const { return turn_r_; }

 private:
  std::shared_ptr<const Preintegration> preint_;
  Vec3 g_w_;
  bool rotating_ = false;
  Vec3 rate_w_ = Vec3::Zero();
  Quat turn_p_ = Quat::Identity(), turn_v_ = Quat::Identity(), turn_r_ = Quat::Identity();
  Mat9 sqrt_info_;
};

// ImuFactor with analytic Jacobians (blocks pose_i 7, vel_i 3, bias_i 6, pose_j 7, vel_j 3). The residual is
// ImuFactor::Terms; the Jacobians are derived in the right-perturbed tangent of each block (reference eqs.
// 4.41-4.48, Forster et al.), unwhitened, with E = ΔR_corrᵀR_iᵀR_j = Exp(r_θ), φ = ∂ΔR/∂bg·δbg and
// Jr⁻¹ = Jr⁻¹(r_θ):
//   ∂r_p/∂(δp_i, δθ_i) = (−R_iᵀ, [dp_i]×)   ∂r_p/∂v_i = −R_iᵀΔt   ∂r_p/∂(bg, ba) = −(∂Δp/∂bg, ∂Δp/∂ba)
//   ∂r_p/∂(δp_j, δθ_j) = (R_iᵀ, 0)
//   ∂r_v/∂(δp_i, δθ_i) = (0, [dv_i]×)        ∂r_v/∂v_i = −R_iᵀ     ∂r_v/∂(bg, ba) = −(∂Δv/∂bg, ∂Δv/∂ba)
//   ∂r_v/∂v_j = R_iᵀ
//   ∂r_θ/∂δθ_i = −Jr⁻¹·R_jᵀR_i   ∂r_θ/∂bg = −Jr⁻¹·Eᵀ·Jr(φ)·∂ΔR/∂bg   ∂r_θ/∂δθ_j = Jr⁻¹
// (δp is in world axes — Plus adds it to p_wb — so ∂r_p/∂δp_j is R_iᵀ, not Forster's R_iᵀR_j.) All are then
// whitened by S.
//
// Lifting to the ambient pose block. Ceres wants ∂r/∂x in the 7 ambient coordinates, but only ever uses
// their product with PoseManifold::PlusJacobian P(x) (7×6): the solver's Jacobian, GradientChecker,
// Problem::Evaluate and the marginalisation all see J_amb·P. Any J_amb with J_amb·P = J_tan is therefore
// equivalent; we return J_amb = J_tan·M(q), with M the 6×7 PoseManifold::MinusJacobian at x (identity on p;
// 2·[w·I − [v]×, −v] on q), for which M·P = I₆ for a unit q, so J_amb·P = J_tan exactly (to rounding). J_amb
// has no component along the radial direction q (M·q = 0); autodiff's ambient Jacobian does (q ⊗ v ⊗ q*
// is not scale invariant), so the two ambient Jacobians differ while their tangent Jacobians agree. (Where a
// caller lifts with P at another point than the one the Jacobian was evaluated at — the smoother's FEJ
// wrapper — the two therefore differ to first order in the distance between the points.)
class ImuCostFunction final : public ceres::SizedCostFunction<9, pose::kAmbient, 3, 6, pose::kAmbient, 3> {
 public:
  ImuCostFunction(std::shared_ptr<const Preintegration> preint, const Vec3& g_w)
      : factor_(std::move(preint), g_w) {}
  ImuCostFunction(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth)
      : factor_(std::move(preint), earth) {}

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  const ImuFactor& factor() const { return factor_; }

 private:
  ImuFactor factor_;
};

}  // namespace gins
