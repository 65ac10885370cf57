// IMU preintegration between two keyframes i and j (reference ch. 4.2, eqs. 4.9-4.34).
//
// The preintegrated measurement is the IMU kinematics propagated through the one kernel (ImuStep) with
// gravity zero from the identity, with the biases held at a linearisation point (bg_lin, ba_lin):
//   ΔR = Π Exp(φ_k),  Δv = Σ ΔR_k(I + ½[φ_k]×)a_k·dt,  Δp = Σ [Δv_k·dt + ½ΔR_k(I + ⅓[φ_k]×)a_k·dt²],
// with φ_k = (ω̃_k − bg)·dt and a_k = ã_k − ba held over the step (ImuStep: the specific force rotated by
// the attitude the body has on average over the step).
//
// Error order everywhere in this class (covariance rows/columns, Jacobian rows) is the kernel's:
//   δp (0..2), δv (3..5), δθ (6..8),   Δ_true = Δ ⊞ δ  (δθ right-perturbed: ΔR_true = ΔR·Exp(δθ)).
// With the kernel's Jacobians A (∂δx'/∂δx) and B (∂δx'/∂[δb] = noise Jacobian) per step:
//   Σ' = A·Σ·Aᵀ + B·Q·Bᵀ   (Q = discrete white noise of [ηg; ηa] over dt),
//   J' = A·J + B           (J = ∂Δ/∂[bg, ba], 9×6, columns δbg (0..2), δba (3..5)).
// The bias random walk between keyframes is NOT in Σ: it is the bias random-walk factor's business.
#pragma once

#include <vector>

#include "core/conventions.h"
#include "core/measurements.h"
#include "core/nav_state.h"
#include "core/so3.h"

namespace gins {

namespace preint {
constexpr int kP = 0;      // δp rows
constexpr int kV = 3;      // δv rows
constexpr int kTheta = 6;  // δθ rows
constexpr int kDim = 9;
constexpr int kBg = 0;  // bias-Jacobian columns
constexpr int kBa = 3;
}  // namespace preint

using Mat96 = Eigen::Matrix<double, 9, 6>;

template <typename T>
struct PredictedKinematics {
  Eigen::Matrix<T, 3, 1> p, v;
  Eigen::Quaternion<T> q;
};

// The Earth's part of what a preintegration predicts over its interval Δt (core/earth.h): gravity in w, held
// over the interval, and the Earth rate ω_ie in w (zero: the flat model). The preintegrated deltas are body
// increments against inertial space; w turns under them, and the Coriolis term integrates in closed form
// because ∫v dt is the displacement:
//   R_j = Exp(−ωΔt)·R_i·ΔR
//   v_j = v_i + g·Δt − 2ω×(p_j − p_i) + Exp(−ωΔt/2)·R_i·Δv
//   p_j = p_i + v_i·Δt + ½g·Δt² − ω×(p_j − p_i)·Δt + Exp(−ωΔt/3)·R_i·Δp
// The half and third rotations are where w has turned on average under Δv and Δp (exact for a constant
// specific force in w); the Coriolis terms take the path between i and j as straight. Both are first order
// in ω·Δt (1e-4 over a second), far below the IMU noise.
struct ImuEarthTerms {
  Vec3 g_w = GravityWorld(kStandardGravity);
  Vec3 rate_w = Vec3::Zero();

  // The left rotations Exp(ω·Δt·k) for k = 1, 1/2, 1/3 (E1, E2, E3); the residuals use their transposes.
  static Quat Turn(const Vec3& rate_w, double dt, double fraction);
};

// The constants of one prediction over Δt: the turns of w and (I + [ω]×Δt)⁻¹ of the position equation.
struct EarthTurns {
  bool rotating = false;
  Quat back_r = Quat::Identity();  // Exp(−ωΔt)
  Quat back_v = Quat::Identity();  // Exp(−ωΔt/2)
  Quat back_p = Quat::Identity();  // Exp(−ωΔt/3)
  Mat3 m_inv = Mat3::Identity();   // (I + [ω]×Δt)⁻¹
  EarthTurns() = default;
  EarthTurns(const ImuEarthTerms& earth, double dt);
};

class Preintegration {
 public:
  // A preintegrated (ΔR, Δv, Δp) triple, body frame of keyframe i.
  struct Delta {
    Quat dq = Quat::Identity();
    Vec3 dv = Vec3::Zero();
    Vec3 dp = Vec3::Zero();
  };

  // bg_lin, ba_lin: bias linearisation point (rad/s, m/s²). Noise densities as in ImuOptions
  // (gyro rad/s/√Hz, accel m/s²/√Hz).
  Preintegration(const Vec3& bg_lin, const Vec3& ba_lin, double gyro_noise_density, double acc_noise_density);

  // Adds one interval of length dt (s) with the raw sample at its start held constant. dt must be finite
  // and ≥ 0; a zero-length interval contributes nothing and is not stored.
  void Integrate(const Vec3& gyro, const Vec3& acc, double dt);
  void Integrate(const ImuSample& sample_at_start, double dt) {
    Integrate(sample_at_start.gyro, sample_at_start.acc, dt);
  }
  // As Integrate, for a step whose held rate and specific force are only a guess (across an IMU gap): an
  // unknown constant error of 1-σ held_gyro_sigma (rad/s) and held_acc_sigma (m/s²) per axis, held over the
  // step, is added to the covariance (where the held sample enters, as the bias does), and so is a white
  // acceleration of the same σ (PSD held_acc_sigma²·dt). The held error alone moves δp and δv of one step
  // together (δp = ½·a·dt², δv = a·dt): three directions of the 9×9 covariance would be empty, and the
  // factor's square-root information would pin them to 1e-12 of the largest variance, so tightly that the
  // smoother's solve stalled on them (every fix of a dropout rejected) and its covariance recovery failed.
  void IntegrateGuess(const Vec3& gyro, const Vec3& acc, double dt, double held_gyro_sigma, double held_acc_sigma);
  // The same with the rate's σ per body axis (a vehicle's unknown turn is mostly about its vertical).
  void IntegrateGuess(const Vec3& gyro, const Vec3& acc, double dt, const Vec3& held_gyro_sigma,
                      double held_acc_sigma);

  // Re-runs the stored samples with a new linearisation point (exact, not first order). Noise densities
  // are kept.
  void Reintegrate(const Vec3& bg_lin, const Vec3& ba_lin);

  // First-order bias-corrected delta for biases (bg, ba) (eq. 4.27):
  //   ΔR·Exp(∂ΔR/∂bg·δbg),  Δv + ∂Δv/∂bg·δbg + ∂Δv/∂ba·δba,  Δp + ...   with δb = b − b_lin.
  Delta Corrected(const Vec3& bg, const Vec3& ba) const;

  // State at j from state i and gravity g_w, using i's biases with first-order correction:
  //   R_j = R_i·ΔR,  v_j = v_i + g·Δt + R_i·Δv,  p_j = p_i + v_i·Δt + ½g·Δt² + R_i·Δp;
  // biases are carried over, t_j = t_i + Δt.
  NavState Predict(const NavState& state_i, const Vec3& g_w) const;
  // With the Earth's rotation (ImuEarthTerms).
  NavState Predict(const NavState& state_i, const ImuEarthTerms& earth) const;

  double dt() const { return dt_total_; }
  const Delta& delta() const { return delta_; }
  const Quat& dq() const { return delta_.dq; }
  const Vec3& dv() const { return delta_.dv; }
  const Vec3& dp() const { return delta_.dp; }
  const Vec3& bg_lin() const { return bg_lin_; }
  const Vec3& ba_lin() const { return ba_lin_; }
  double gyro_noise_density() const { return gyro_noise_density_; }
  double acc_noise_density() const { return acc_noise_density_; }
  int num_samples() const { return static_cast<int>(samples_.size()); }

  // Covariance of (δp, δv, δθ) (m², (m/s)², rad²).
  const Mat9& cov() const { return cov_; }
  // ∂(δp, δv, δθ)/∂(bg, ba), 9×6.
  const Mat96& bias_jacobian() const { return J_bias_; }
  Mat3 dp_dbg() const { return J_bias_.block<3, 3>(preint::kP, preint::kBg); }
  Mat3 dp_dba() const { return J_bias_.block<3, 3>(preint::kP, preint::kBa); }
  Mat3 dv_dbg() const { return J_bias_.block<3, 3>(preint::kV, preint::kBg); }
  Mat3 dv_dba() const { return J_bias_.block<3, 3>(preint::kV, preint::kBa); }
  Mat3 dR_dbg() const { return J_bias_.block<3, 3>(preint::kTheta, preint::kBg); }

 private:
  struct Sample {
    Vec3 gyro;
    Vec3 acc;
    double dt;
    Vec3 held_gyro_sigma = Vec3::Zero();  // IntegrateGuess
    double held_acc_sigma = 0.0;
  };
  void Reset();
  void Step(const Sample& s);
  void AddWhiteAcceleration(double sigma, double dt);

  Vec3 bg_lin_, ba_lin_;
  double gyro_noise_density_, acc_noise_density_;
  std::vector<Sample> samples_;
  double dt_total_ = 0.0;
  Delta delta_;
  Mat9 cov_ = Mat9::Zero();
  Mat96 J_bias_ = Mat96::Zero();
};

// Covariance of Predict's state j (NavState tangent order δp, δv, δθ, δbg, δba) given state i's covariance P_i:
// the error propagated through the bias-corrected deltas (Φ), plus the preintegration's noise rotated into w
// and the bias random walks over Δt (gyro_bias_rw rad/s/√s, acc_bias_rw m/s²/√s, as ImuOptions). The random
// walks enter the biases only, not the kinematics within the interval (second order over a keyframe
// interval), and Earth rotation changes Φ by ~ω·Δt (1e-4): both are left out.
Mat15 PredictedCovariance(const NavState& x_i, const Mat15& P_i, const Preintegration& pre, double gyro_bias_rw,
                          double acc_bias_rw);
// The same as a transition δx_j = Φ·δx_i + n, cov(n) = Q (for joint covariances of states i and j).
void PredictedTransition(const NavState& x_i, const Preintegration& pre, double gyro_bias_rw, double acc_bias_rw,
                         Mat15* Phi, Mat15* Q);

// Preintegration::Predict written once for any scalar type (the factors that attach a measurement at a time
// between keyframes differentiate it with Ceres's Jets): pose and velocity at j from state i and its biases,
// first-order bias-corrected, with the Earth terms of ImuEarthTerms. Pre is a Preintegration or anything with
// its accessors (dt, dq, dv, dp, bg_lin, ba_lin and the bias Jacobians: the alignment's snapshots).
template <typename T, typename Pre>
PredictedKinematics<T> PredictKinematics(const Pre& pre, const ImuEarthTerms& earth,
                                         const EarthTurns& turns, const Eigen::Matrix<T, 3, 1>& p_i,
                                         const Eigen::Quaternion<T>& q_i, const Eigen::Matrix<T, 3, 1>& v_i,
                                         const Eigen::Matrix<T, 3, 1>& bg, const Eigen::Matrix<T, 3, 1>& ba) {
  using Vec3T = Eigen::Matrix<T, 3, 1>;
  const Vec3 bg_lin = pre.bg_lin(), ba_lin = pre.ba_lin(), dv0 = pre.dv(), dp0 = pre.dp();
  const Quat dq0 = pre.dq();
  const Mat3 dR_dbg = pre.dR_dbg(), dv_dbg = pre.dv_dbg(), dv_dba = pre.dv_dba(), dp_dbg = pre.dp_dbg(),
             dp_dba = pre.dp_dba();
  const Vec3T dbg = bg - bg_lin.cast<T>();
  const Vec3T dba = ba - ba_lin.cast<T>();
  const Eigen::Quaternion<T> dq = dq0.cast<T>() * ExpQuat<T>(Vec3T(dR_dbg.cast<T>() * dbg));
  const Vec3T dv = dv0.cast<T>() + dv_dbg.cast<T>() * dbg + dv_dba.cast<T>() * dba;
  const Vec3T dp = dp0.cast<T>() + dp_dbg.cast<T>() * dbg + dp_dba.cast<T>() * dba;
  const T dt = T(pre.dt());
  const Vec3T g = earth.g_w.cast<T>();
  PredictedKinematics<T> out;
  if (!turns.rotating) {
    out.q = q_i * dq;
    out.v = v_i + g * dt + q_i * dv;
    out.p = p_i + v_i * dt + T(0.5) * g * dt * dt + q_i * dp;
    return out;
  }
  out.q = turns.back_r.cast<T>() * q_i * dq;
  const Vec3T rhs = v_i * dt + T(0.5) * g * dt * dt + turns.back_p.cast<T>() * (q_i * dp);
  const Vec3T d_p = turns.m_inv.cast<T>() * rhs;
  out.p = p_i + d_p;
  out.v = v_i + g * dt - T(2) * earth.rate_w.cast<T>().cross(d_p) + turns.back_v.cast<T>() * (q_i * dv);
  return out;
}

}  // namespace gins
