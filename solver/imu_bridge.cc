#include "solver/imu_bridge.h"

#include <cmath>

#include "core/imu_kernel.h"
#include "core/so3.h"

namespace gins {
namespace {

// Linear share s of the end variances plus the bridge term s(1-s)·q, per axis.
Vec3 BridgeSigma(const Vec3& sigma_a, const Vec3& sigma_b, double s, double q) {
  const Vec3 var = (1.0 - s) * sigma_a.cwiseAbs2() + s * sigma_b.cwiseAbs2() + Vec3::Constant(s * (1.0 - s) * q);
  return var.cwiseSqrt();
}

}  // namespace

void EmitBridge(const StateEstimate& a, const StateEstimate* b, const std::vector<HeldImuSample>& steps,
                const ImuEarthTerms& earth, const BridgeNoise& noise, bool standing, const StateCallback& out) {
  out(a);
  if (steps.empty()) return;
  // The propagation from a, kept so that the mismatch at b is known before the first state goes out.
  std::vector<Kinematics> path;
  path.reserve(steps.size());
  Kinematics k{a.x.q_wb, a.x.v_w, a.x.p_wb};
  if (standing) k.v.setZero();
  double T = 0.0;
  for (const HeldImuSample& step : steps) {
    if (!standing) {
      k = ImuStep(k, step.sample.gyro - a.x.bg, step.sample.acc - a.x.ba, earth.g_w, step.dt, nullptr, earth.rate_w);
    }
    T += step.dt;
    path.push_back(k);
  }
  // The mismatch at b: position, velocity, attitude about the world axes (R_b = Exp(φ_w)·R̂_b), biases.
  Vec3 dp = Vec3::Zero(), dv = Vec3::Zero(), dphi_w = Vec3::Zero(), dbg = Vec3::Zero(), dba = Vec3::Zero();
  if (b != nullptr) {
    dp = b->x.p_wb - path.back().p;
    dv = b->x.v_w - path.back().v;
    dphi_w = LogQuat<double>(b->x.q_wb * path.back().q.conjugate());
    dbg = b->x.bg - a.x.bg;
    dba = b->x.ba - a.x.ba;
  }
  // The bridge's white-noise variances over the whole interval: attitude σg²T, velocity σa²T, position
  // σa²T³/3 (the integrated random walk).
  const double qg = noise.gyro_noise_density * noise.gyro_noise_density * T;
  const double qa = noise.acc_noise_density * noise.acc_noise_density;
  const double q_v = qa * T, q_p = qa * T * T * T / 3.0;
  double t = a.x.t, elapsed = 0.0;
  for (size_t i = 0; i < path.size(); ++i) {
    t += steps[i].dt;
    elapsed += steps[i].dt;
    if (b != nullptr && i + 1 == path.size()) break;  // b emits itself
    const double s = b != nullptr && T > 0.0 ? elapsed / T : 0.0;
    StateEstimate m = a;
    m.x.t = t;
    m.x.p_wb = path[i].p + s * dp;
    m.x.v_w = path[i].v + s * dv;
    m.x.q_wb = (ExpQuat<double>(s * dphi_w) * path[i].q).normalized();
    m.x.bg = a.x.bg + s * dbg;
    m.x.ba = a.x.ba + s * dba;
    if (b != nullptr) {
      m.sigma_p = BridgeSigma(a.sigma_p, b->sigma_p, s, q_p);
      m.sigma_v = BridgeSigma(a.sigma_v, b->sigma_v, s, q_v);
      m.sigma_att = BridgeSigma(a.sigma_att, b->sigma_att, s, qg);
      m.odom_scale = (1.0 - s) * a.odom_scale + s * b->odom_scale;
    }
    out(m);
  }
}

}  // namespace gins
