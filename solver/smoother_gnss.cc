// The smoother's GNSS entry: the watchdog's decision, the window rebuilt from a fix, and the prior relieved
// when a run of agreeing fixes says the window's position is off.
#include "solver/smoother.h"

#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>

#include "solver/estimator_common.h"
#include "solver/marginalizer.h"
#include "solver/smoother_gate.h"
#include "solver/smoother_output.h"

namespace gins {

void Smoother::Use(const GnssMeasurement& m, const Measurement& measurement) {
  if (!initialized_ || m.t < t_now_ - kSameEpoch || m.t < window_.back().t - kSameEpoch) return;
  if (m.t > window_.back().t + kSameEpoch) SolveIfPending();
  if (WatchdogTakes(m)) {
    for (auto& attacher : attachers_) attacher->OnResetFix(m);  // counted as used: offered stays every fix
    return;
  }
  AttachWatched(m, measurement);
}

bool Smoother::WatchdogTakes(const GnssMeasurement& m) {
  if (!watchdog_options_.enabled) return false;
  // The σ at the fix, predicted from the newest keyframe, and that of the keyframe that left the window
  // last (a window behind, it lags a long gap by a window's time).
  const Prediction p = PredictAt(m.t);
  const Mat15 P = NavCovariance(window_.EstimatedTypes(), p.cov);
  const double sigma_p = std::sqrt(P.block<3, 3>(nav::kP, nav::kP).diagonal().maxCoeff());
  const bool finite = window_.back().State().AllFinite() && pred_.AllFinite() && std::isfinite(sigma_p);
  const FixVerdict verdict =
      WatchdogVerdict(m, finite, std::max(sigma_p, last_sigma_p_), sensors_, watchdog_options_, p.x, P, &course_wait_, &prev_fix_);
  if (verdict == FixVerdict::kUse) return false;
  if (verdict == FixVerdict::kReset) {
    ResetFromGnss(m, finite ? "covariance" : "non_finite");
    prev_fix_ = m;
  }
  return true;
}

void Smoother::AttachWatched(const GnssMeasurement& fix, const Measurement& measurement) {
  reset_reason_.clear();
  const std::optional<GnssMeasurement> prev_fix = prev_fix_;
  prev_fix_ = fix;
  if (Attach(measurement)) solve_pending_ = true;
  if (!reset_reason_.empty()) {
    prev_fix_ = prev_fix;  // the fix before this one, for the velocity
    SolveIfPending();
    ResetFromGnss(fix, reset_reason_);
    prev_fix_ = fix;
  }
}

void Smoother::WatchGnss(double t, bool accepted) {
  if (watchdog_.Watch(t, accepted)) reset_reason_ = "gnss_rejected";
}

void Smoother::ResetFromGnss(const GnssMeasurement& m, const std::string& reason_in) {
  const std::string reason = reason_in;  // may be reset_reason_, which is cleared below
  // Attitude and biases at the fix's time (pred_), from the newest keyframe, with the covariance predicted
  // there: after a long coast (a logger pause) the yaw is lost, and the reset must see it.
  const Prediction at_fix_prediction = PredictAt(m.t);
  const NavState at_fix = pred_;
  // What the window knows of the newest keyframe: its state, and its covariance from the whole window.
  InitResult init;
  Mat15 cov = Mat15::Zero();
  bool have_cov = false;
  const bool finite = window_.back().State().AllFinite();
  if (finite) {
    const std::vector<BlockType> types = window_.EstimatedTypes();
    // The older keyframes leave the window as usual (final output); the newest is replaced by the prior.
    while (window_.size() > 1) MarginalizeOldest(nullptr);
    const MatX& predicted = at_fix_prediction.cov;
    if (predicted.rows() == static_cast<int>(NavIndexOfTangent(types).size()) && predicted.allFinite()) {
      cov = NavCovariance(types, predicted);
      have_cov = true;
    } else {
      have_cov = OldestCovariance(window_, &cov);
    }
    init.x0 = at_fix.AllFinite() ? at_fix : window_.front().State();
    window_.KeepValues(window_.front());
  } else {
    init.x0.q_wb = FallbackAttitude(m, sensors_.gnss);
    window_.ForgetValues();
  }
  if (!have_cov) cov = FallbackCovariance(sensors_.imu);
  init.g_norm = earth_.g_norm();
  init.earth = earth_;
  const FixReset how = ResetPositionFromFix(m, prev_fix_, sensors_, watchdog_options_, &init.x0, cov, course_wait_.Take());
  // Tiny floors keep the prior invertible whatever the window's covariance was.
  cov = 0.5 * (cov + cov.transpose());
  cov.diagonal() = cov.diagonal().cwiseMax(1e-12);
  init.P0 = cov;

  // The chain the whole-log smoother sees ends at the newest keyframe, with the IMU steps after it.
  if (factor_log_ && finite) factor_log_->SetTail(&window_.back(), interval_samples_);
  const std::optional<ImuSample> last_imu = last_imu_;
  const double last_sample_t = last_sample_t_;
  Initialize(init);  // a fresh problem and window; emits the new keyframe on the online stream
  last_imu_ = last_imu;
  last_sample_t_ = last_sample_t;
  for (auto& attacher : attachers_) attacher->OnWindowRebuilt();
  last_sigma_p_ = 0.0;
  reset_reason_.clear();
  watchdog_.Reset(m.t, reason);
  LOG(WARNING) << "smoother watchdog: window rebuilt from GNSS at t=" << std::fixed << m.t << " (" << reason
               << "; " << Describe(how) << ")";
}

void Smoother::RelievePrior(double factor) {
  ++prior_reliefs_;
  if (prior_id_ == nullptr || !(factor > 1.0)) return;
  const auto* prior = dynamic_cast<const MarginalizationPrior*>(problem_->GetCostFunctionForResidualBlock(prior_id_));
  if (prior == nullptr) return;
  std::vector<double*> blocks;
  problem_->GetParameterBlocksForResidualBlock(prior_id_, &blocks);
  // What a run of agreeing rejected fixes says is that the window's position is off, not its attitude,
  // velocity or biases (the IMU between them is as good as before): the prior gains the uncertainty of one
  // common translation d of its poses, with cov(d) = (factor − 1)·its position covariance, and keeps the
  // rest. With T the tangent columns of the poses' positions and A = J·T, the prior ½|r0 + J·δ|² becomes
  // ½|L·(r0 + J·δ)|² with LᵀL = (I + A·cov(d)·Aᵀ)⁻¹ (Woodbury: its information is that of Σ + T·cov(d)·Tᵀ).
  const MatX& J = prior->J();
  MatX T = MatX::Zero(J.cols(), 3);
  int offset = 0, poses = 0;
  for (const PriorBlock& b : prior->blocks()) {
    if (b.kind == BlockKind::kPose) {
      T.middleRows<3>(offset + pose::kP).setIdentity();
      ++poses;
    }
    offset += b.tangent_size;
  }
  if (poses == 0) return;
  // The prior's own covariance of its poses' mean position, Tᵀ·H⁺·T / poses² (the information may be
  // rank-deficient: the pseudo-inverse over the eigenvalues it has).
  const Eigen::SelfAdjointEigenSolver<MatX> es(J.transpose() * J);
  const VecX lambda = es.eigenvalues();
  VecX inv = VecX::Zero(lambda.size());
  for (int k = 0; k < lambda.size(); ++k) {
    if (lambda[k] > 1e-12 * lambda.maxCoeff()) inv[k] = 1.0 / lambda[k];
  }
  const MatX VT = es.eigenvectors().transpose() * T;
  const MatX cov_p = VT.transpose() * inv.asDiagonal() * VT / static_cast<double>(poses * poses);
  if (!cov_p.allFinite() || !(cov_p.diagonal().array() > 0.0).all()) return;
  const MatX cov_d = (factor - 1.0) * cov_p;
  const MatX A = J * T;
  const MatX W = (MatX::Identity(J.rows(), J.rows()) + A * cov_d * A.transpose()).inverse();
  const Eigen::LLT<MatX> llt(0.5 * (W + W.transpose()));
  if (llt.info() != Eigen::Success) return;
  const MatX L = llt.matrixU();  // LᵀL = W
  auto relieved = std::make_unique<MarginalizationPrior>(prior->blocks(), MatX(L * J), VecX(L * prior->r0()));
  problem_->RemoveResidualBlock(prior_id_);
  prior_id_ = problem_->AddResidualBlock(relieved.release(), nullptr, blocks);
}

}  // namespace gins
