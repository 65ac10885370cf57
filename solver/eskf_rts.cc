#include "solver/eskf_rts.h"

#include <glog/logging.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>

#include "solver/imu_bridge.h"

namespace gins {
namespace {

constexpr int kN = eskf::kDim;
constexpr int kA = eskf::kKinematicDim;
constexpr int kB = eskf::kNonKinematicDim;
constexpr int kD = eskf::kDrivingDim;
constexpr int kTriangle = kN * (kN + 1) / 2;  // a symmetric matrix's upper triangle

template <typename M>
void PackSymmetric(const M& P, double* out) {
  int k = 0;
  for (int r = 0; r < kN; ++r) {
    for (int c = r; c < kN; ++c) out[k++] = P(r, c);
  }
}

template <typename M>
void UnpackSymmetric(const double* in, M* P) {
  int k = 0;
  for (int r = 0; r < kN; ++r) {
    for (int c = r; c < kN; ++c) (*P)(r, c) = (*P)(c, r) = in[k++];
  }
}

StateEstimate EstimateOf(const EskfNominal& n, const EskfRts::MatP& P) {
  StateEstimate e;
  e.x = n.x;
  e.sigma_p = eskf::BlockOf<eskf::Block::kP>(P).diagonal().cwiseMax(0.0).cwiseSqrt();
  e.sigma_v = eskf::BlockOf<eskf::Block::kV>(P).diagonal().cwiseMax(0.0).cwiseSqrt();
  const Mat3 R = n.x.R_wb();
  e.sigma_att = (R * eskf::BlockOf<eskf::Block::kTheta>(P) * R.transpose()).diagonal().cwiseMax(0.0).cwiseSqrt();
  e.odom_scale = n.Scalar<eskf::Block::kS>();
  return e;
}

}  // namespace

// One node as it sits in the file: fixed size, so that the backward pass can seek to any of them.
struct EskfRts::Node {
  static constexpr int kDoubles = 2 + 2 * EskfNominal::kPackedSize + 2 * kTriangle + kA * kA + kA * kB;
  std::array<double, kDoubles> v{};
  double& t() { return v[0]; }
  double& chain_start() { return v[1]; }
  double* prior_x() { return v.data() + 2; }
  double* post_x() { return v.data() + 2 + EskfNominal::kPackedSize; }
  double* prior_P() { return v.data() + 2 + 2 * EskfNominal::kPackedSize; }
  double* post_P() { return prior_P() + kTriangle; }
  double* phi_a() { return post_P() + kTriangle; }
  double* phi_c() { return phi_a() + kA * kA; }
  MatP Phi() {
    MatP Phi = MatP::Identity();
    Phi.topLeftCorner<kA, kA>() = Eigen::Map<const Eigen::Matrix<double, kA, kA>>(phi_a());
    Phi.topRightCorner<kA, kB>() = Eigen::Map<const Eigen::Matrix<double, kA, kB>>(phi_c());
    return Phi;
  }
};

EskfRts::EskfRts(const BridgeNoise& noise, bool with_gravity) : noise_(noise), with_gravity_(with_gravity) {
  nodes_file_ = std::tmpfile();
  steps_file_ = std::tmpfile();
  if (nodes_file_ == nullptr || steps_file_ == nullptr) {
    LOG(WARNING) << "eskf RTS: no temporary file (" << std::strerror(errno) << "); no eskf_rts output";
    failed_ = true;
  }
  phi_a_.setIdentity();
  phi_c_.setZero();
}

EskfRts::~EskfRts() {
  if (nodes_file_ != nullptr) std::fclose(nodes_file_);
  if (steps_file_ != nullptr) std::fclose(steps_file_);
}

void EskfRts::StartChain(const EskfNominal& x, const MatP& P) {
  // A node still open here is the caller's to close first (with the state before the re-initialisation).
  open_ = true;
  chain_start_ = true;
  open_t_ = x.x.t;
  prior_x_ = x;
  prior_P_ = P;
  phi_a_.setIdentity();
  phi_c_.setZero();
  ++chains_;
}

void EskfRts::RecordStep(const Vec3& gyro, const Vec3& acc, double t_before, double dt) {
  if (failed_) return;
  const std::array<double, 8> step = {t_before, gyro.x(), gyro.y(), gyro.z(), acc.x(), acc.y(), acc.z(), dt};
  if (std::fwrite(step.data(), sizeof(double), step.size(), steps_file_) != step.size()) failed_ = true;
  ++steps_;
}

void EskfRts::Compound(const ImuStepJacobians& J) {
  if (failed_) return;
  // Φ ← F·Φ with F = [[A, C], [0, I]]: Φa ← A·Φa, Φc ← A·Φc + C.
  phi_a_ = MulA<kA>(J, phi_a_);
  Eigen::Matrix<double, kD, kB> E = Eigen::Matrix<double, kD, kB>::Zero();
  E.leftCols<kD>().setIdentity();
  phi_c_ = MulA<kB>(J, phi_c_) + MulBG<kB>(J, E, with_gravity_);
}

void EskfRts::BeforeUpdate(const EskfNominal& x, const MatP& P) {
  if (failed_ || (open_ && x.x.t == open_t_)) return;
  AfterUpdates(x, P);  // a node still open at an earlier time (cannot happen when the filter closes it)
  open_ = true;
  chain_start_ = false;
  open_t_ = x.x.t;
  prior_x_ = x;
  prior_P_ = P;
}

void EskfRts::AfterUpdates(const EskfNominal& x, const MatP& P) {
  if (!open_ || failed_) return;
  open_ = false;
  Node node;
  node.t() = open_t_;
  node.chain_start() = chain_start_ ? 1.0 : 0.0;
  prior_x_.Pack(node.prior_x());
  x.Pack(node.post_x());
  PackSymmetric(prior_P_, node.prior_P());
  PackSymmetric(P, node.post_P());
  Eigen::Map<Eigen::Matrix<double, kA, kA>>(node.phi_a()) = phi_a_;
  Eigen::Map<Eigen::Matrix<double, kA, kB>>(node.phi_c()) = phi_c_;
  Write(node);
  first_step_.push_back(steps_);
  phi_a_.setIdentity();
  phi_c_.setZero();
}

void EskfRts::Write(const Node& node) {
  if (std::fwrite(node.v.data(), sizeof(double), node.v.size(), nodes_file_) != node.v.size()) failed_ = true;
  ++nodes_;
}

bool EskfRts::Read(size_t index, Node* node) {
  const long offset = static_cast<long>(index * sizeof(double) * Node::kDoubles);
  return std::fseek(nodes_file_, offset, SEEK_SET) == 0 &&
         std::fread(node->v.data(), sizeof(double), node->v.size(), nodes_file_) == node->v.size();
}

void EskfRts::Smooth(const EarthModel& earth, const StateCallback& out) {
  if (failed_ || nodes_ == 0 || std::fflush(nodes_file_) != 0 || std::fflush(steps_file_) != 0) {
    failed_ = true;
    return;
  }
  const auto t0 = std::chrono::steady_clock::now();
  // Backward: the smoothed state and σ of every node (and its δg, for the bridges' gravity).
  std::vector<StateEstimate> smoothed(nodes_);
  std::vector<Vec3> dg(nodes_);
  std::vector<bool> chain_start(nodes_);
  Node next, node;
  EskfNominal xs_next;
  MatP Ps_next;
  for (size_t i = nodes_; i-- > 0;) {
    if (!Read(i, &node)) {
      failed_ = true;
      return;
    }
    const EskfNominal post = EskfNominal::Unpack(node.post_x(), node.t());
    MatP P_post;
    UnpackSymmetric(node.post_P(), &P_post);
    EskfNominal xs = post;
    MatP Ps = P_post;
    if (i + 1 < nodes_ && next.chain_start() == 0.0) {
      const EskfNominal prior_next = EskfNominal::Unpack(next.prior_x(), next.t());
      MatP P_prior_next;
      UnpackSymmetric(next.prior_P(), &P_prior_next);
      // A state the filter does not estimate (the odometer scale without wheels, δg when held) has a zero
      // row and column: a unit variance there decouples it exactly (its rows of P⁺Φᵀ are zero too).
      for (int r = 0; r < kN; ++r) {
        if (P_prior_next.row(r).isZero(0.0)) P_prior_next(r, r) = 1.0;
      }
      VecP delta;
      MatP P_s;
      if (RtsBackwardStep<kN>(P_post, next.Phi(), P_prior_next, xs_next.Minus(prior_next), Ps_next, &delta, &P_s)) {
        xs = post.Plus(delta);
        Ps = P_s;
      } else {
        ++singular_;  // keep the filtered node: the chain is smoothed again from here back
      }
    }
    smoothed[i] = EstimateOf(xs, Ps);
    dg[i] = xs.Get<eskf::Block::kG>();
    chain_start[i] = node.chain_start() != 0.0;
    xs_next = xs;
    Ps_next = Ps;
    next = node;
  }
  // Forward: the nodes and the IMU-rate states between them, in time order.
  if (std::fseek(steps_file_, 0, SEEK_SET) != 0) {
    failed_ = true;
    return;
  }
  const BridgeNoise& noise = noise_;
  std::vector<HeldImuSample> steps;
  for (size_t i = 0; i < nodes_; ++i) {
    const uint64_t end = i + 1 < nodes_ ? first_step_[i + 1] : steps_;
    steps.clear();
    for (uint64_t s = first_step_[i]; s < end; ++s) {
      std::array<double, 8> v{};
      if (std::fread(v.data(), sizeof(double), v.size(), steps_file_) != v.size()) {
        failed_ = true;
        return;
      }
      HeldImuSample h;
      h.sample.t = v[0];
      h.sample.gyro = Vec3(v[1], v[2], v[3]);
      h.sample.acc = Vec3(v[4], v[5], v[6]);
      h.dt = v[7];
      steps.push_back(h);
    }
    ImuEarthTerms terms;
    terms.g_w = earth.Gravity(smoothed[i].x.p_wb) + dg[i];
    terms.rate_w = earth.rate_w();
    const bool bridged = i + 1 < nodes_ && !chain_start[i + 1];
    EmitBridge(smoothed[i], bridged ? &smoothed[i + 1] : nullptr, steps, terms, noise, false, out);
  }
  smooth_time_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

nlohmann::json EskfRts::Stats() const {
  return {{"nodes", nodes_},
          {"imu_steps", steps_},
          {"chains", chains_},
          {"singular_steps", singular_},
          {"temporary_file_mb", static_cast<double>(nodes_ * sizeof(double) * Node::kDoubles +
                                                    steps_ * 8 * sizeof(double)) / 1e6},
          {"smooth_time_s", smooth_time_s_},
          {"failed", failed_}};
}

}  // namespace gins
