// The smoother's tightly coupled GNSS: raw epochs (core/gnss_raw.h) as factors in the window. Per epoch, at
// the state the window predicts for it:
// - the pseudoranges of the satellites that pass their own test (ScreenSatellites, with the predicted
//   antenna position's covariance), differenced within each receiver clock's group, through the χ² gate of
//   the differences (H·P·Hᵀ + R, as the ESKF's), then one factor on the antenna position
//   (factors/raw_gnss_factor.h: the differences' square-root information, rank 1-3);
// - the range rates the same way on the antenna velocity (one group: one oscillator's drift);
// - the carrier phases' changes since the previous epoch (slips dropped, core/gnss_raw.h's PhaseSlipped) the
//   same way on the antenna's displacement between the two epochs' keyframes (RawDisplacementFactor): every
//   epoch with phases is a keyframe, whatever smoother.min_keyframe_interval_s says; a gap of more than
//   kMaxPhaseInterval ends the chain.
// The epoch attaches at its reception time (the receiver's clock, not the logger's: no time offset).
#pragma once

#include <ceres/loss_function.h>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/gnss_raw.h"
#include "core/sensors.h"
#include "solver/smoother_attachers.h"

namespace gins {

class RawGnssAttacher final : public AttacherOf<RawGnssMeasurement> {
 public:
  // on_checked(t, accepted): each epoch's ranges' outcome, for the smoother's watchdog (none when there was
  // nothing to difference).
  RawGnssAttacher(const GnssOptions& gnss, std::function<void(double, bool)> on_checked);

  bool On(const RawGnssMeasurement& m, const AttachContext& ctx) override;
  void AddStats(nlohmann::json* stats) const override;
  void OnKeyframeLeaving(const Keyframe& kf) override;
  void OnWindowRebuilt() override { phase_epoch_.kf = nullptr; }

  // The predicted antenna in w and ECEF, the body rate, and the antenna position's and velocity's
  // covariance from the window's.
  struct PredictedAntenna {
    Vec3 p_w, v_w, r_ecef, v_ecef, omega_b;
    Mat3 P_p, P_v;
  };

 private:
  // The epoch's ranges (rates: its range rates) of sats at the predicted antenna: screened, differenced,
  // gated and attached; true if attached.
  bool AttachRows(const RawGnssMeasurement& m, const std::vector<RawSatellite>& sats, bool rates,
                  const Prediction& pred, const PredictedAntenna& a, const AttachContext& ctx, Anchor* anchor);

  // The epoch's phase changes since the previous one's keyframe, attached to it and this epoch's.
  bool AttachPhases(const RawGnssMeasurement& m, const std::vector<RawSatellite>& sats, const PredictedAntenna& a,
                    const Anchor& at_keyframe, const AttachContext& ctx);
  // Rows over a 3-vector (at x0, covariance P) of the satellites in: screened (rejections counted per
  // satellite), differenced within their groups, through the χ² gate (a rejection counted in counts), and
  // compressed to *c. False with c->rank 0 if no difference was left, −1 if the gate rejected them.
  bool Gate(const NuisanceRows& rows, const std::vector<const RawSatellite*>& in, const Mat3& P, const Vec3& x0,
            double t, MeasurementCounts* counts, LinearConstraint3* c, size_t* kept_n);

  Vec3 lever_b_;
  double gate_probability_;
  double w_max_;  // the standardised residual's bound: √χ²(gnss.gate_probability, 1)
  std::function<void(double, bool)> on_checked_;
  std::unique_ptr<ceres::LossFunction> loss_;
  MeasurementCounts ranges_, rates_;
  uint64_t epochs_ = 0, satellites_used_ = 0, unusable_ = 0, epochs_without_differences_ = 0;
  std::map<std::string, uint64_t> satellite_rejected_;
  MeasurementCounts phases_;
  uint64_t phase_slips_ = 0;
  struct PhaseEpoch {
    Keyframe* kf = nullptr;  // the previous epoch's keyframe; null: no chain (no phases, or it left)
    double t = 0.0;
    std::map<std::string, RawSatellite> sats;  // with phase, by satellite
  } phase_epoch_;
};

}  // namespace gins
