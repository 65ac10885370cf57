#include "core/alignment.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>

#include "core/alignment_terms.h"
#include "core/chi2.h"
#include "core/imu_kernel.h"
#include "core/preintegration.h"
#include "core/so3.h"

namespace gins {
namespace {

using X15 = std::array<double, nav::kDim>;

// Whitened residuals beyond this many σ weigh linearly (Huber): a GNSS jump must not pull the attitude.
constexpr double kHuberScale = 3.0;
// Re-preintegrate when the biases moved this far from the linearisation point: the deltas' bias Jacobians are
// first order, and over a window of tens of seconds the gravity part of Δp is kilometres long.
constexpr double kRelinGyro = 1e-4;  // rad/s
constexpr double kRelinAcc = 0.01;   // m/s²
constexpr int kMaxRelinearisations = 3;
// Two solutions whose yaws differ by less than this are the same one.
constexpr double kSameYaw = 2.0 * kDegToRad;
// The largest covariance inflation the residuals may ask for (σ × 10).
constexpr double kMaxInflation = 100.0;

// The preintegrated IMU from t0 to every measurement epoch.
struct Snapshots {
  std::vector<PreintSnapshot> fix, gnss_velocity, wheel;
  std::vector<Vec3> fix_omega_b, gvel_omega_b;  // gyro less bias at each fix's and GNSS velocity's epoch
  std::unique_ptr<Preintegration> total;  // to the last epoch
};

// Wheel speeds are means over their counting interval: their epoch is its middle.
double WheelEpoch(const WheelMeasurement& w) { return w.t - 0.5 * w.interval; }

Snapshots Integrate(const AlignmentInput& in, const Vec3& bg, const Vec3& ba, const ImuOptions& imu) {
  struct Request {
    double t;
    int kind;  // 0 fix, 1 gnss_velocity, 2 wheel
    size_t index;
  };
  std::vector<Request> req;
  for (size_t i = 0; i < in.fixes.size(); ++i) req.push_back({in.fixes[i].t, 0, i});
  for (size_t i = 0; i < in.gnss_velocities.size(); ++i) req.push_back({in.gnss_velocities[i].t, 1, i});
  for (size_t i = 0; i < in.wheels.size(); ++i) req.push_back({WheelEpoch(in.wheels[i]), 2, i});
  std::stable_sort(req.begin(), req.end(), [](const Request& a, const Request& b) { return a.t < b.t; });
  Snapshots s;
  s.fix.resize(in.fixes.size());
  s.gnss_velocity.resize(in.gnss_velocities.size());
  s.fix_omega_b.resize(in.fixes.size(), Vec3::Zero());
  s.gvel_omega_b.resize(in.gnss_velocities.size(), Vec3::Zero());
  s.wheel.resize(in.wheels.size());
  s.total = std::make_unique<Preintegration>(bg, ba, imu.gyro_noise_density, imu.acc_noise_density);
  Preintegration& pre = *s.total;
  double tc = in.imu.front().t;
  size_t r = 0;
  auto take = [&](const Request& q, const ImuSample& held) {
    if (q.t > tc) {
      pre.Integrate(held, q.t - tc);
      tc = q.t;
    }
    const PreintSnapshot snap(pre);
    if (q.kind == 0) {
      s.fix[q.index] = snap;
      s.fix_omega_b[q.index] = held.gyro - bg;
    }
    if (q.kind == 1) {
      s.gnss_velocity[q.index] = snap;
      s.gvel_omega_b[q.index] = held.gyro - bg;
    }
    if (q.kind == 2) s.wheel[q.index] = snap;
  };
  for (size_t i = 1; i < in.imu.size(); ++i) {
    const ImuSample held = HeldBetween(in.imu[i - 1], in.imu[i]);
    for (; r < req.size() && req[r].t <= in.imu[i].t; ++r) take(req[r], held);
    if (in.imu[i].t > tc) {
      pre.Integrate(held, in.imu[i].t - tc);
      tc = in.imu[i].t;
    }
  }
  for (; r < req.size(); ++r) take(req[r], in.imu.back());  // just after the last sample: hold it
  return s;
}

double IsotropicVariance(const Mat3& cov) { return cov.trace() / 3.0; }

// One fit problem: every term of the window about the reference attitude q_ref.
struct Problem {
  ceres::Problem problem;
  int residuals = 0;
  std::vector<ceres::ResidualBlockId> gnss_blocks;  // in time order, for the residuals' correlation
};

template <int N, typename Term>
ceres::ResidualBlockId Add(Problem* p, Term term, double* x, bool robust) {
  auto* cost = new ceres::AutoDiffCostFunction<Term, N, nav::kDim>(new Term(std::move(term)));
  p->residuals += N;
  return p->problem.AddResidualBlock(cost, robust ? new ceres::HuberLoss(kHuberScale) : nullptr, x);
}

struct FitContext {
  const AlignmentInput* in;
  const AlignmentOptions* options;
  ImuEarthTerms earth;
  bool nhc = false;  // the non-holonomic constraint at every fix
};

void BuildProblem(const FitContext& c, const Snapshots& s, const Quat& q_ref, double* x, Problem* p) {
  const AlignmentInput& in = *c.in;
  const SensorOptions& so = c.options->sensors;
  for (size_t i = 0; i < in.fixes.size(); ++i) {
    const GnssMeasurement& m = in.fixes[i];
    const align::Epoch epoch(s.fix[i], c.earth, q_ref);
    const double imu_var = IsotropicVariance(s.fix[i].cov().block<3, 3>(preint::kP, preint::kP));
    const Vec3 sigma = (m.sigma_w.cwiseAbs2() + Vec3::Constant(imu_var)).cwiseSqrt();
    p->gnss_blocks.push_back(
        Add<3>(p, align::GnssTerm{epoch, so.gnss.lever_b, m.p_w, sigma.cwiseInverse()}, x, true));
    if (so.gnss.use_heading && m.heading_valid) {
      Add<1>(p, align::HeadingTerm{epoch, so.gnss.mount_yaw, m.yaw_G, 1.0 / m.sigma_yaw}, x, true);
    }
    if (c.nhc && s.fix[i].dt() > 0.0) {
      Add<2>(p, align::NhcTerm{epoch, s.fix_omega_b[i], so.wheel.lever_b, 1.0 / so.vehicle.nhc_sigma}, x, true);
    }
  }
  for (size_t i = 0; i < in.gnss_velocities.size(); ++i) {
    const GnssVelocityMeasurement& m = in.gnss_velocities[i];
    const double imu_var = IsotropicVariance(s.gnss_velocity[i].cov().block<3, 3>(preint::kV, preint::kV));
    const Vec3 sigma = (m.sigma_w.cwiseAbs2() + Vec3::Constant(imu_var)).cwiseSqrt();
    Add<3>(p,
           align::GvelTerm{align::Epoch(s.gnss_velocity[i], c.earth, q_ref), s.gvel_omega_b[i], so.gnss.lever_b, m.v_w,
                           sigma.cwiseInverse()},
           x, true);
  }
  for (size_t i = 0; i < in.wheels.size(); ++i) {
    const WheelMeasurement& w = in.wheels[i];
    const double imu_var = IsotropicVariance(s.wheel[i].cov().block<3, 3>(preint::kV, preint::kV));
    // The odometer scale is not estimated here: its prior uncertainty is part of the speed's.
    const double sigma = std::sqrt(w.sigma * w.sigma + std::pow(so.wheel.scale_sigma * w.speed, 2) + imu_var);
    Add<1>(p, align::WheelTerm{align::Epoch(s.wheel[i], c.earth, q_ref), w.speed, 1.0 / sigma}, x, true);
  }
  if (in.standstill) {
    const StaticSummary& st = *in.standstill;
    const double n = std::max(1, st.n);
    // The measured spread at rest, but never far below the stated white noise (a simulated sensor may be
    // perfect; a real one is not).
    const double dt = std::max(st.mean_dt, 1e-4);
    const double acc_std = std::max(st.acc_std.maxCoeff(), 0.1 * so.imu.acc_noise_density / std::sqrt(dt));
    const double gyro_std = std::max(st.gyro_std.maxCoeff(), 0.1 * so.imu.gyro_noise_density / std::sqrt(dt));
    align::StaticTerm term;
    term.q_ref = q_ref;
    term.g_w = c.earth.g_w;
    term.rate_w = c.earth.rate_w;
    term.acc_mean = st.acc_mean;
    term.gyro_mean = st.gyro_mean;
    term.inv_sigma_acc = std::sqrt(n) / acc_std;
    term.inv_sigma_gyro = std::sqrt(n) / gyro_std;
    term.inv_sigma_v = 1.0 / c.options->zero_velocity_sigma;
    Add<9>(p, term, x, false);
  }
  align::BiasPriorTerm prior;
  prior.inv_sigma_bg = 1.0 / so.imu.init_gyro_bias_sigma;
  prior.inv_sigma_ba = 1.0 / so.imu.init_acc_bias_sigma;
  Add<6>(p, prior, x, false);
}

struct Candidate {
  Quat q_ref = Quat::Identity();
  X15 x{};
  double chi2 = std::numeric_limits<double>::infinity();
  double yaw = 0.0;
};

// Moves the attitude increment into the reference (δθ = 0 at the solution, where the covariance is taken).
void Anchor(Candidate* c) {
  const Vec3 dtheta(c->x[nav::kTheta], c->x[nav::kTheta + 1], c->x[nav::kTheta + 2]);
  c->q_ref = (c->q_ref * ExpQuat<double>(dtheta)).normalized();
  for (int i = 0; i < 3; ++i) c->x[nav::kTheta + i] = 0.0;
  c->yaw = YawOfXAxis<double>(c->q_ref.toRotationMatrix());
}

void Solve(const FitContext& ctx, const Snapshots& s, Candidate* c) {
  Problem p;
  BuildProblem(ctx, s, c->q_ref, c->x.data(), &p);
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = 50;
  so.function_tolerance = 1e-10;
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-10;
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &p.problem, &summary);
  c->chi2 = summary.IsSolutionUsable() ? 2.0 * summary.final_cost : std::numeric_limits<double>::infinity();
  Anchor(c);
}

Vec3 BiasG(const X15& x) { return Vec3(x[nav::kBg], x[nav::kBg + 1], x[nav::kBg + 2]); }
Vec3 BiasA(const X15& x) { return Vec3(x[nav::kBa], x[nav::kBa + 1], x[nav::kBa + 2]); }

// Solves again until the preintegration's linearisation point is the solution's biases.
Snapshots Relinearise(const FitContext& ctx, Snapshots s, Candidate* c) {
  for (int k = 0; k < kMaxRelinearisations; ++k) {
    const Preintegration& lin = *s.total;
    if ((BiasG(c->x) - lin.bg_lin()).norm() < kRelinGyro && (BiasA(c->x) - lin.ba_lin()).norm() < kRelinAcc) break;
    s = Integrate(*ctx.in, BiasG(c->x), BiasA(c->x), ctx.options->sensors.imu);
    Solve(ctx, s, c);
  }
  return s;
}

// The information at the solution, inverted; and the residuals' inflation: their size (χ²/dof) and their
// correlation from one GNSS epoch to the next (N independent fixes that are really N(1−ρ)/(1+ρ)).
Mat15 Covariance(const FitContext& ctx, const Snapshots& s, Candidate* c, int* dof, double* inflation) {
  Problem p;
  BuildProblem(ctx, s, c->q_ref, c->x.data(), &p);
  ceres::CRSMatrix crs;
  std::vector<double> residuals;
  double cost = 0.0;
  p.problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, &residuals, nullptr, &crs);
  MatX J = MatX::Zero(crs.num_rows, crs.num_cols);
  for (int i = 0; i < crs.num_rows; ++i) {
    for (int k = crs.rows[i]; k < crs.rows[i + 1]; ++k) J(i, crs.cols[k]) = crs.values[k];
  }
  const Mat15 H = J.transpose() * J;
  const Eigen::SelfAdjointEigenSolver<Mat15> eig(H);
  const Vec15 lambda = eig.eigenvalues().cwiseMax(1e-12);
  Mat15 P = eig.eigenvectors() * lambda.cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
  *dof = std::max(1, p.residuals - nav::kDim);
  double rho_num = 0.0, rho_den = 0.0;
  std::vector<double> r(3, 0.0), prev;
  for (ceres::ResidualBlockId id : p.gnss_blocks) {
    double cost_block = 0.0;
    p.problem.EvaluateResidualBlock(id, false, &cost_block, r.data(), nullptr);
    for (int i = 0; i < 3; ++i) {
      rho_den += r[i] * r[i];
      if (!prev.empty()) rho_num += r[i] * prev[i];
    }
    prev = r;
  }
  const double rho = rho_den > 0.0 ? std::clamp(rho_num / rho_den, 0.0, 0.999) : 0.0;
  const double chi2_dof = 2.0 * cost / *dof;
  *inflation = std::min(kMaxInflation, std::max(1.0, chi2_dof) * (1.0 + rho) / (1.0 - rho));
  return *inflation * P;
}

double AngleBetween(double a, double b) { return std::abs(WrapAngle(a - b)); }

// The GNSS course over the window (chord of the track, or the mean GNSS velocity), for the first yaws.
double Course(const AlignmentInput& in) {
  Vec2 d = Vec2::Zero();
  if (in.fixes.size() >= 2) d = (in.fixes.back().p_w - in.fixes.front().p_w).head<2>();
  if (d.norm() < 3.0 * in.fixes.back().sigma_w.head<2>().norm() && !in.gnss_velocities.empty()) {
    d.setZero();
    for (const GnssVelocityMeasurement& g : in.gnss_velocities) d += g.v_w.head<2>();
  }
  return d.norm() > 0.0 ? std::atan2(d.y(), d.x()) : 0.0;
}

// Velocity at t0 from the first fixes (zero after a standstill).
Vec3 FirstVelocity(const AlignmentInput& in) {
  if (in.standstill) return Vec3::Zero();
  if (!in.gnss_velocities.empty() && in.gnss_velocities.front().t - in.imu.front().t < 1.0) return in.gnss_velocities.front().v_w;
  const double t0 = in.imu.front().t;
  const GnssMeasurement* a = nullptr;
  const GnssMeasurement* b = nullptr;
  for (const GnssMeasurement& f : in.fixes) {
    if (f.t < t0) continue;
    if (!a) {
      a = &f;
    } else if (f.t - a->t >= 1.0 || !b) {
      b = &f;
      if (f.t - a->t >= 1.0) break;
    }
  }
  return a && b && b->t > a->t ? Vec3((b->p_w - a->p_w) / (b->t - a->t)) : Vec3::Zero();
}

// The body's "up" from the accelerometer: the standstill's mean, else the first second's (acceleration
// left in: the fit takes it out).
Vec3 UpInBody(const AlignmentInput& in) {
  if (in.standstill) return in.standstill->acc_mean.normalized();
  Vec3 sum = Vec3::Zero();
  for (const ImuSample& s : in.imu) {
    if (s.t - in.imu.front().t > 1.0) break;
    sum += s.acc;
  }
  return sum.normalized();
}

Candidate Seed(const AlignmentInput& in, const FitContext& ctx, double yaw) {
  const SensorOptions& so = ctx.options->sensors;
  Candidate c;
  const Quat q_level = Quat::FromTwoVectors(UpInBody(in), Vec3::UnitZ());
  c.q_ref = (QuatFromYaw(yaw - YawOfXAxis<double>(q_level.toRotationMatrix())) * q_level).normalized();
  const Vec3 p = in.fixes.front().p_w - c.q_ref * so.gnss.lever_b;
  const Vec3 v = FirstVelocity(in);
  Vec3 bg = Vec3::Zero();
  if (in.standstill) bg = in.standstill->gyro_mean - c.q_ref.conjugate() * ctx.earth.rate_w;
  for (int i = 0; i < 3; ++i) {
    c.x[nav::kP + i] = p[i];
    c.x[nav::kV + i] = v[i];
    c.x[nav::kTheta + i] = 0.0;
    c.x[nav::kBg + i] = bg[i];
    c.x[nav::kBa + i] = 0.0;
  }
  c.yaw = yaw;
  return c;
}

NavState StateOf(const Candidate& c, double t) {
  NavState x;
  x.t = t;
  x.p_wb = Vec3(c.x[nav::kP], c.x[nav::kP + 1], c.x[nav::kP + 2]);
  x.v_w = Vec3(c.x[nav::kV], c.x[nav::kV + 1], c.x[nav::kV + 2]);
  x.q_wb = c.q_ref;
  x.bg = BiasG(c.x);
  x.ba = BiasA(c.x);
  return x;
}

// 1-σ of the attitude about world z (yaw) and the larger about E and N (tilt), right-perturbed in b.
void AttitudeSigmas(const NavState& x, const Mat15& P, double* yaw, double* tilt) {
  const Mat3 R = x.R_wb();
  const Mat3 P_w = R * P.block<3, 3>(nav::kTheta, nav::kTheta) * R.transpose();
  *yaw = std::sqrt(std::max(P_w(2, 2), 0.0));
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(P_w.topLeftCorner<2, 2>());
  *tilt = std::sqrt(std::max(eig.eigenvalues().maxCoeff(), 0.0));
}

// The best solution from the first yaws and the best other one, relinearised; residual count in *residuals.
struct Search {
  bool ok = false;
  Candidate best, second;
  bool have_second = false;
  Snapshots snaps;
  int residuals = 0;
};

Search SearchYaws(const FitContext& ctx, const std::vector<double>& yaws) {
  const AlignmentInput& in = *ctx.in;
  Search out;
  Snapshots snaps = Integrate(in, BiasG(Seed(in, ctx, yaws.front()).x), Vec3::Zero(), ctx.options->sensors.imu);
  std::vector<Candidate> found;
  for (double yaw : yaws) {
    Candidate c = Seed(in, ctx, yaw);
    Solve(ctx, snaps, &c);
    if (!std::isfinite(c.chi2)) continue;
    bool same = false;
    for (Candidate& f : found) {
      if (AngleBetween(f.yaw, c.yaw) < kSameYaw) {
        same = true;
        if (c.chi2 < f.chi2) f = c;
      }
    }
    if (!same) found.push_back(c);
  }
  if (found.empty()) return out;
  std::sort(found.begin(), found.end(), [](const Candidate& a, const Candidate& b) { return a.chi2 < b.chi2; });
  out.best = found.front();
  out.snaps = Relinearise(ctx, std::move(snaps), &out.best);
  if (found.size() > 1) {
    out.second = found[1];
    Solve(ctx, out.snaps, &out.second);  // at the best's linearisation point, so the two compare
    out.have_second = AngleBetween(out.second.yaw, out.best.yaw) >= kSameYaw && out.second.chi2 >= out.best.chi2;
  }
  Problem p;
  X15 x = out.best.x;
  BuildProblem(ctx, out.snaps, out.best.q_ref, x.data(), &p);
  out.residuals = p.residuals;
  out.ok = true;
  return out;
}

}  // namespace

double ImuWindowForSigma(const ImuOptions& imu, double g_norm, double sigma_m, double min_s, double max_s) {
  auto var = [&](double T) {
    const double a = g_norm * imu.gyro_noise_density, b = imu.acc_noise_density;
    return a * a * std::pow(T, 5) / 20.0 + b * b * std::pow(T, 3) / 3.0;
  };
  if (var(max_s) <= sigma_m * sigma_m) return max_s;
  double lo = min_s, hi = max_s;
  if (var(lo) >= sigma_m * sigma_m) return min_s;
  for (int i = 0; i < 50; ++i) {
    const double mid = 0.5 * (lo + hi);
    (var(mid) <= sigma_m * sigma_m ? lo : hi) = mid;
  }
  return lo;
}

AlignmentFit Align(const AlignmentInput& in, const AlignmentOptions& options, const EarthModel& earth) {
  AlignmentFit out;
  if (in.imu.empty() || in.fixes.empty()) {
    out.problem = "too few IMU samples or GNSS fixes";
    return out;
  }
  FitContext ctx{&in, &options, ImuEarthTerms{}, options.sensors.vehicle.nonholonomic};
  Vec3 centroid = Vec3::Zero();
  for (const GnssMeasurement& f : in.fixes) centroid += f.p_w;
  ctx.earth.g_w = earth.Gravity(centroid / static_cast<double>(in.fixes.size()));
  ctx.earth.rate_w = earth.rate_w();

  // First yaws: the heading when there is one, else four about the course (forward, left, back, right).
  std::vector<double> yaws;
  for (const GnssMeasurement& f : in.fixes) {
    if (options.sensors.gnss.use_heading && f.heading_valid) {
      yaws = {f.yaw_G - options.sensors.gnss.mount_yaw};
      out.heading_used = true;
      break;
    }
  }
  if (yaws.empty()) {
    const double course = Course(in);
    for (int k = 0; k < 4; ++k) yaws.push_back(WrapAngle(course + k * 0.5 * kPi));
  }
  Search search = SearchYaws(ctx, yaws);
  out.nhc_used = ctx.nhc;
  if (!search.ok) {
    out.problem = "the fit did not converge";
    return out;
  }
  Candidate& best = search.best;
  out.runner_up_delta_chi2 = std::numeric_limits<double>::infinity();
  if (search.have_second) {
    out.runner_up_delta_chi2 = search.second.chi2 - best.chi2;
    out.runner_up_yaw = search.second.yaw;
  }
  const Snapshots& snaps = search.snaps;
  const double t0 = in.imu.front().t;
  out.P0 = Covariance(ctx, snaps, &best, &out.dof, &out.inflation);
  out.chi2 = best.chi2;
  out.x0 = StateOf(best, t0);
  const Preintegration& pre = *snaps.total;
  out.x = pre.Predict(out.x0, ctx.earth);
  out.x.t = t0 + pre.dt();
  out.P = PredictedCovariance(out.x0, out.P0, pre, options.sensors.imu.gyro_bias_rw, options.sensors.imu.acc_bias_rw);
  AttitudeSigmas(out.x, out.P, &out.yaw_sigma, &out.tilt_sigma);
  out.fixes_used = static_cast<int>(in.fixes.size());
  out.solved = out.x.AllFinite() && out.P.allFinite();
  if (!out.solved) out.problem = "the fit's solution is not finite";
  return out;
}

}  // namespace gins
