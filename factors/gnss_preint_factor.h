// GNSS fix at its own time t, between keyframes i and the next: PreintAttachedFactor<GnssAtTime>
// (factors/preint_attached_factor.h).
//   r = (p_t + R_t·lever_b − z_w) ./ σ_w      with (p_t, R_t) = PredictKinematics(Δ_i→t, state i)
#pragma once

#include <memory>
#include <utility>

#include "factors/preint_attached_factor.h"

namespace gins {

class GnssPreintFactor : public PreintAttachedFactor<GnssAtTime> {
 public:
  GnssPreintFactor(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth, const Vec3& z_w,
                   const Vec3& sigma_w, const Vec3& lever_b)
      : PreintAttachedFactor<GnssAtTime>(std::move(preint), earth,
                                         GnssAtTime{z_w, sigma_w.cwiseInverse(), lever_b}) {}

  // PreintAttachedCostFunction<GnssAtTime> (analytic Jacobians). Requires σ > 0.
  static ceres::CostFunction* Create(std::shared_ptr<const Preintegration> preint, const ImuEarthTerms& earth,
                                     const Vec3& z_w, const Vec3& sigma_w, const Vec3& lever_b);
};

}  // namespace gins
