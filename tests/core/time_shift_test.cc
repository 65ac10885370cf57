#include "core/time_shift.h"

#include <gtest/gtest.h>

#include <cmath>

namespace gins {
namespace GINS_TEST_FILE {

// A car on a circle of radius r at rate w (heading along the track, FLU body): the exact state at any time.
struct Circle {
  double r = 20.0, w = 0.5;
  Vec3 p(double t) const { return Vec3(r * std::cos(w * t), r * std::sin(w * t), 0.0); }
  Vec3 v(double t) const { return Vec3(-r * w * std::sin(w * t), r * w * std::cos(w * t), 0.0); }
  Vec3 a(double t) const { return -w * w * p(t); }
  Quat q(double t) const { return Quat(Eigen::AngleAxisd(w * t + M_PI / 2, Vec3::UnitZ())); }
};

// The shifted state matches the exact one to third order in τ (position; the rotation and velocity to
// second): halving τ cuts the position error by about 8.
TEST(TimeShift, MatchesTheExactStateToThirdOrder) {
  const Circle c;
  const double t = 3.0;
  const Vec3 omega_b(0.0, 0.0, c.w);
  double previous = 0.0;
  for (const double tau : {0.2, 0.1, 0.05, -0.1}) {
    const ShiftedKinematics<double> s = ShiftBack<double>(c.p(t), c.v(t), c.q(t), c.a(t), omega_b, tau);
    const double err_p = (s.p_wb - c.p(t - tau)).norm();
    const double err_v = (s.v_w - c.v(t - tau)).norm();
    const double err_q = s.q_wb.angularDistance(c.q(t - tau));
    const double jerk = c.r * std::pow(c.w, 3);
    // Third-order terms: |p'''|·|τ|³/6 and |v''|·τ²/2 (here v'' has the jerk's magnitude).
    EXPECT_LT(err_p, 1.01 * jerk * std::pow(std::abs(tau), 3) / 6.0) << tau;
    EXPECT_GT(err_p, 0.5 * jerk * std::pow(std::abs(tau), 3) / 6.0) << tau;  // the bound is tight, not loose
    EXPECT_LT(err_v, 1.01 * jerk * tau * tau / 2.0) << tau;
    EXPECT_LT(err_q, 1e-12) << tau;  // a constant rate: exact
    if (tau == 0.1) {
      EXPECT_NEAR(previous / err_p, 8.0, 0.2);
    }
    previous = err_p;
  }
}

TEST(TimeShift, ZeroOffsetIsTheStateItself) {
  const Circle c;
  const ShiftedKinematics<double> s = ShiftBack<double>(c.p(1.0), c.v(1.0), c.q(1.0), c.a(1.0), Vec3(0, 0, c.w), 0.0);
  EXPECT_EQ(s.p_wb, c.p(1.0));
  EXPECT_EQ(s.v_w, c.v(1.0));
  EXPECT_EQ(s.q_wb.coeffs(), c.q(1.0).coeffs());
}

}  // namespace
}  // namespace gins
