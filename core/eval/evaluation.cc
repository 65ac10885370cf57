#include "core/eval/evaluation.h"

#include <cmath>

#include "core/so3.h"

namespace gins {
namespace {

// Largest estimate gap across which the estimate is interpolated (s).
constexpr double kMaxInterpolationGap = 1.0;

}  // namespace

StreamingEvaluator::StreamingEvaluator(std::function<bool(TruthSample*)> truth) : truth_(std::move(truth)) {}

StreamingEvaluator::StreamingEvaluator(std::vector<TruthSample> truth)
    : StreamingEvaluator([samples = std::make_shared<const std::vector<TruthSample>>(std::move(truth)),
                          i = size_t{0}](TruthSample* s) mutable {
        if (i == samples->size()) return false;
        *s = (*samples)[i++];
        return true;
      }) {}

void StreamingEvaluator::Add(const NavState& x) {
  if (!have_prev_) {
    prev_ = x;
    have_prev_ = true;
    NextTruth();
    while (have_next_ && next_.t < x.t) NextTruth();
  }
  while (have_next_ && next_.t <= x.t) {
    const TruthSample& tr = next_;
    const double span = x.t - prev_.t;
    if (span <= kMaxInterpolationGap && tr.t >= prev_.t) {
      const double a = span > 0.0 ? (tr.t - prev_.t) / span : 1.0;
      NavState e = x;
      e.t = tr.t;
      e.p_wb = (1.0 - a) * prev_.p_wb + a * x.p_wb;
      e.v_w = (1.0 - a) * prev_.v_w + a * x.v_w;
      e.q_wb = prev_.q_wb.slerp(a, x.q_wb);
      Accumulate(tr, e);
    }
    NextTruth();
  }
  prev_ = x;
}

void StreamingEvaluator::Accumulate(const TruthSample& tr, const NavState& e) {
  const Vec3 d = e.p_wb - tr.p_w;
  const double h2 = d.head<2>().squaredNorm();
  sum_h2_ += h2;
  sum_v2_ += d.z() * d.z();
  max_h_ = std::max(max_h_, std::sqrt(h2));
  sum_vel2_ += (e.v_w - tr.v_w).squaredNorm();
  const double dyaw = WrapAngle(YawOfXAxis<double>(e.R_wb()) - YawOfXAxis<double>(tr.q_wb.toRotationMatrix()));
  sum_yaw2_ += dyaw * dyaw;
  sum_att2_ += LogQuat<double>(tr.q_wb.conjugate() * e.q_wb).squaredNorm();
  ++n_;
}

AccuracyMetrics StreamingEvaluator::Metrics() const {
  AccuracyMetrics m;
  m.count = n_;
  if (n_ == 0) return m;
  const double n = static_cast<double>(n_);
  m.rmse_h = std::sqrt(sum_h2_ / n);
  m.rmse_v = std::sqrt(sum_v2_ / n);
  m.rmse_3d = std::sqrt((sum_h2_ + sum_v2_) / n);
  m.max_h = max_h_;
  m.rmse_vel = std::sqrt(sum_vel2_ / n);
  m.rmse_heading_deg = std::sqrt(sum_yaw2_ / n) * kRadToDeg;
  m.rmse_att_deg = std::sqrt(sum_att2_ / n) * kRadToDeg;
  return m;
}

}  // namespace gins
