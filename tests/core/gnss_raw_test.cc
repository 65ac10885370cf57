// Raw GNSS for the tightly coupled estimators (core/gnss_raw.h): the residuals' gradients against numeric
// differences; per-satellite screening finds a planted fault and leaves clean epochs whole; differencing
// within a clock's group is the update with that clock as a free state; the Doppler velocity from
// simulated epochs (core/sim/raw_gnss.h on data/rinex/walk.nav).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/gnss_raw.h"
#include "core/io/rinex.h"
#include "core/sim/raw_gnss.h"

namespace gins {
namespace GINS_TEST_FILE {

constexpr double kT0 = 1440437500.0;  // GPS s: walk.nav's records are in date

RawSatellite SomeSatellite() {
  RawSatellite s;
  s.r_sat_ecef = Vec3(-12.0e6, -14.0e6, 18.0e6);
  s.v_sat_ecef = Vec3(1800.0, -900.0, 2400.0);
  s.range_m = 2.3e7;
  s.has_rate = true;
  s.rate_m_s = -350.0;
  return s;
}

TEST(GnssRaw, ResidualGradientsMatchNumericDifferences) {
  const RawSatellite s = SomeSatellite();
  const Vec3 r(-1276969.0, -4717225.3, 4087226.7), v(3.0, -1.0, 0.5);
  Vec3 u;
  RangeResidual(s, r, &u);
  for (int k = 0; k < 3; ++k) {
    const double h = 1e-3;
    Vec3 e = Vec3::Zero();
    e[k] = h;
    const double d_range = (RangeResidual(s, r + e, nullptr) - RangeResidual(s, r - e, nullptr)) / (2 * h);
    EXPECT_NEAR(d_range, -u[k], 1e-6) << k;  // ∂/∂r_rx = −uᵀ
    const double d_rate = (RateResidual(s, r, v + e, nullptr) - RateResidual(s, r, v - e, nullptr)) / (2 * h);
    EXPECT_NEAR(d_rate, -u[k], 1e-9) << k;  // ∂/∂v_rx = −uᵀ
  }
  // A residual is predicted − measured: the satellite 100 m further than measured reads +100 m.
  RawSatellite near = s;
  near.range_m = (s.r_sat_ecef - r).norm() - 100.0;
  EXPECT_NEAR(RangeResidual(near, r, nullptr), 100.0, 1e-6);
}

MatX RandomMatrix(int rows, int cols, std::mt19937* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  MatX m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = n(*rng);
  return m;
}

// Rows h(x) − z for a state error x_err seen through H, with a clock per group and white noise.
NuisanceRows SimulatedRows(const MatX& H, const VecX& x_err, const std::vector<int>& group, double sigma,
                           unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, sigma);
  NuisanceRows rows;
  rows.H = H;
  rows.group = group;
  rows.variance = VecX::Constant(H.rows(), sigma * sigma);
  rows.r = H * x_err;
  for (int i = 0; i < H.rows(); ++i) rows.r(i) += 40.0 * group[i] + n(rng);  // any clock, per group
  return rows;
}

TEST(GnssRaw, ScreeningFindsThePlantedFaultAndKeepsCleanEpochs) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  const int rows_n = 12, dim = 6;
  const MatX H = RandomMatrix(rows_n, dim, &rng);
  const std::vector<int> group = {1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 3};  // the lone row of group 3: untestable
  const MatX P = MatX::Identity(dim, dim) * 0.25;
  const double w_max = 3.89;  // √χ²(0.9999, 1)
  int kept_all = 0;
  for (unsigned seed = 0; seed < 50; ++seed) {
    VecX x_err(dim);
    for (int j = 0; j < dim; ++j) x_err(j) = 0.5 * n(rng);
    NuisanceRows rows = SimulatedRows(H, x_err, group, 1.0, seed);
    kept_all += ScreenSatellites(rows, P, w_max).size() == static_cast<size_t>(rows_n);
    rows.r(4) += 15.0;  // 15 σ on one satellite
    const std::vector<int> keep = ScreenSatellites(rows, P, w_max);
    ASSERT_EQ(keep.size(), static_cast<size_t>(rows_n - 1)) << seed;
    EXPECT_EQ(std::count(keep.begin(), keep.end(), 4), 0) << seed;
  }
  EXPECT_GE(kept_all, 49);  // at 0.9999 per row, a clean epoch is almost never cut
}

TEST(GnssRaw, DifferencingIsTheUpdateWithAFreeClockPerGroup) {
  std::mt19937 rng(5);
  const int rows_n = 9, dim = 5;
  const MatX H = RandomMatrix(rows_n, dim, &rng);
  const std::vector<int> group = {0, 0, 0, 0, 1, 1, 1, 1, 2};
  const MatX A = RandomMatrix(dim, dim, &rng);
  const MatX P = A * A.transpose() + MatX::Identity(dim, dim);
  NuisanceRows rows = SimulatedRows(H, VecX::Constant(dim, 0.3), group, 0.7, 9);
  for (int i = 0; i < rows_n; ++i) rows.variance(i) = 0.2 + 0.1 * i;  // unequal: the reference is the least

  VecX r_d;
  MatX H_d, R_d;
  int groups = 0;
  DifferenceByGroup(rows, &r_d, &H_d, &R_d, &groups);
  EXPECT_EQ(groups, 2);  // group 2 has one row
  ASSERT_EQ(r_d.size(), rows_n - 3);
  const MatX S = H_d * P * H_d.transpose() + R_d;
  const MatX K = P * H_d.transpose() * S.inverse();
  const VecX dx = -K * r_d;
  const MatX P_post = P - K * H_d * P;

  // The same with the three clocks as states of a vast prior.
  const int g = 3;
  MatX Pa = MatX::Zero(dim + g, dim + g);
  Pa.topLeftCorner(dim, dim) = P;
  Pa.bottomRightCorner(g, g) = MatX::Identity(g, g) * 1e8;  // vast against σ² ~ 1, still well conditioned
  MatX Ha = MatX::Zero(rows_n, dim + g);
  Ha.leftCols(dim) = rows.H;
  for (int i = 0; i < rows_n; ++i) Ha(i, dim + group[i]) = 1.0;
  const MatX Sa = Ha * Pa * Ha.transpose() + MatX(rows.variance.asDiagonal());
  const MatX Ka = Pa * Ha.transpose() * Sa.inverse();
  const VecX dxa = -Ka * rows.r;
  const MatX Pa_post = Pa - Ka * Ha * Pa;
  EXPECT_LT((dx - dxa.head(dim)).norm(), 1e-5 * (1.0 + dx.norm()));
  EXPECT_LT((P_post - Pa_post.topLeftCorner(dim, dim)).norm(), 1e-5 * P.norm());
}

// ‖S·(x − z)‖² − (whitened squared norm of the rows at x): the same at every x when S, z hold the rows.
double CompressionGap(const LinearConstraint3& c, const VecX& r_d, const MatX& H_d, const MatX& R_d,
                      const Vec3& x0, const Vec3& x) {
  const Eigen::LLT<MatX> llt(R_d);
  const VecX e = llt.matrixL().solve(r_d + H_d * (x - x0));
  return (c.sqrt_info * (x - c.z)).squaredNorm() - e.squaredNorm();
}

TEST(GnssRaw, CompressedRowsKeepTheirQuadraticFormAndLeastSquaresPoint) {
  std::mt19937 rng(11);
  const int rows_n = 7;
  const MatX H = RandomMatrix(rows_n, 3, &rng);
  const MatX A = RandomMatrix(rows_n, rows_n, &rng);
  const MatX R = A * A.transpose() + MatX::Identity(rows_n, rows_n);
  const VecX r = RandomMatrix(rows_n, 1, &rng);
  const Vec3 x0(3.0, -2.0, 7.0);
  const LinearConstraint3 c = CompressRows(r, H, R, x0);
  EXPECT_EQ(c.rank, 3);
  // z is the generalised least-squares x: r + H·(z − x0) = 0 in R⁻¹'s norm.
  const MatX Ri = R.inverse();
  const Vec3 z = x0 - (H.transpose() * Ri * H).ldlt().solve(H.transpose() * Ri * r);
  EXPECT_LT((c.z - z).norm(), 1e-9 * (1.0 + z.norm()));
  const double gap0 = CompressionGap(c, r, H, R, x0, x0);
  for (int k = 0; k < 5; ++k) {
    const Vec3 x = x0 + Vec3(RandomMatrix(3, 1, &rng)) * 4.0;
    EXPECT_NEAR(CompressionGap(c, r, H, R, x0, x), gap0, 1e-8 * (1.0 + std::abs(gap0))) << k;
  }
}

TEST(GnssRaw, CompressedRowsOfOneDirectionHaveRankOne) {
  // Two satellites of one system: one difference, one direction seen; the others stay free (zero rows).
  std::mt19937 rng(13);
  const MatX H = RandomMatrix(1, 3, &rng);
  const MatX R = MatX::Constant(1, 1, 0.8);
  const VecX r = VecX::Constant(1, 2.5);
  const Vec3 x0(1.0, 2.0, 3.0);
  const LinearConstraint3 c = CompressRows(r, H, R, x0);
  ASSERT_EQ(c.rank, 1);
  EXPECT_LT(c.sqrt_info.bottomRows(2).norm(), 1e-15);
  // z moves from x0 along the seen direction only, to where the row reads zero.
  const Vec3 h = H.row(0).transpose();
  EXPECT_NEAR(r(0) + h.dot(c.z - x0), 0.0, 1e-9);
  EXPECT_LT(((c.z - x0) - h * (h.dot(c.z - x0) / h.squaredNorm())).norm(), 1e-9);
  const double gap0 = CompressionGap(c, r, H, R, x0, x0);
  for (int k = 0; k < 5; ++k) {
    const Vec3 x = x0 + Vec3(RandomMatrix(3, 1, &rng)) * 4.0;
    EXPECT_NEAR(CompressionGap(c, r, H, R, x0, x), gap0, 1e-8 * (1.0 + std::abs(gap0))) << k;
  }
  // No rows: no constraint, z at x0.
  const LinearConstraint3 none = CompressRows(VecX(), MatX(0, 3), MatX(0, 0), x0);
  EXPECT_EQ(none.rank, 0);
  EXPECT_EQ(none.z, x0);
}

TEST(GnssRaw, DopplerVelocityFromSimulatedEpochs) {
  const std::vector<KeplerEphemeris> ephs =
      ReadRinexNav(std::string(GINS_TEST_DATA_DIR) + "/rinex/walk.nav", InputOptions{}).kepler;
  RawGnssSimOptions sim;
  sim.code_sigma_a_m = sim.code_sigma_b_m = 0.0;
  sim.multipath_sigma_m = 0.0;
  sim.doppler_sigma_m_s = 0.05;
  RawGnssSimulator simulator(ephs, sim, 11);
  auto nav = std::make_shared<RawGnssNav>();
  nav->ephemerides = ephs;
  nav->spp.elevation_mask_rad = 10.0 * kDegToRad;
  nav->spp.ionosphere = IonosphereModel::kNone;
  nav->doppler_sigma = 0.025;  // σ = 0.025·(1 + 1/sin el) ≥ 0.05 m/s: at least the simulated noise
  const Vec3 r(-1276969.0, -4717225.3, 4087226.7), v(10.0, -5.0, 1.0);
  double sum_sq = 0.0, nees = 0.0;
  const int epochs = 100;
  for (int k = 0; k < epochs; ++k) {
    const double t = kT0 + k;
    const RinexObsEpoch e = simulator.Simulate({t, r + v * k, v});
    RawGnssMeasurement m;
    m.rx_gps_s = e.gps_s;
    m.nav = nav;
    for (const RinexSatelliteObs& s : e.satellites) {
      RawGnssObservation o;
      o.code.sat = s.sat;
      const std::string band = sim.signals.at(s.sat.system).front();
      ASSERT_TRUE(RinexSignal(s.sat.system, band, &o.code.signal));
      o.code.pseudorange_m = s.Find("C" + band)->value;
      o.has_doppler = true;
      o.doppler_hz = s.Find("D" + band)->value;
      m.satellites.push_back(o);
    }
    const std::vector<RawSatellite> sats = PrepareSatellites(m, r + v * k);
    ASSERT_GE(sats.size(), 10u);
    Vec3 v_est;
    Mat3 cov;
    int used = 0;
    ASSERT_TRUE(SolveDopplerVelocity(sats, r + v * k, 3.89, &v_est, &cov, &used));
    const Vec3 d = v_est - v;
    sum_sq += d.squaredNorm();
    nees += d.dot(cov.ldlt().solve(d));
  }
  EXPECT_LT(std::sqrt(sum_sq / epochs), 0.15);  // m/s, 3D (the vertical is the weakest)
  // Its covariance is not optimistic (the model's σ is at least the simulated noise): mean NEES ≤ 3.
  EXPECT_LT(nees / epochs, 3.0 * 1.3);
}

}  // namespace
}  // namespace gins
