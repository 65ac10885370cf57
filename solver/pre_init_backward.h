// The outputs before the initialisation (solver/pre_init_output.h, docs/estimators.md "Initialisation"): a
// vehicle that stood, moved and stood again before the fit's window (or a log that starts while moving) has
// fixes and IMU samples there that no forward estimator could use, having no attitude yet. Once a state is
// known (the fit's first state for the forward streams, the first two-sided state for the others), the same
// ESKF runs backwards in time from it through those samples, fixes and standstills, and its own RTS pass
// smooths the result: each epoch then has every measurement of the span on both sides of it.
//
// Time reversal (t' = 2·t_s − t): the mechanisation is the same with the gyro, the velocity, the gyro bias
// and the Earth's rotation negated (EarthModel::TimeReversed); specific force, gravity, positions and
// attitudes are unchanged. The backward run holds the GNSS time offset at 0 and uses neither wheels nor
// GNSS velocities (their models are not time-symmetric as written).
#pragma once

#include <utility>
#include <vector>

#include "core/earth.h"
#include "core/measurements.h"
#include "core/standstill_detector.h"
#include "solver/estimator.h"
#include "solver/estimator_options.h"

namespace gins {

struct BackwardSpan {
  StateEstimate start;   // the earliest state the stream has (at t_s = start.x.t)
  double from = 0.0;     // states from here (and the first IMU sample) on
  Mat15 P = Mat15::Identity();  // its covariance in the NavState tangent
  EarthModel earth;
  std::vector<ImuSample> imu;                     // before t_s, in time order
  std::vector<GnssMeasurement> fixes;             // before t_s, in time order
  std::vector<std::pair<double, double>> rests;   // standstills [from, to] before t_s
};

// The smoothed states in [max(span.from, the first IMU sample), span.start.x.t), in time order; empty
// without a fix there. The sections are the forward ESKF's (the backward run has no watchdog).
std::vector<StateEstimate> FillBackward(const SensorOptions& sensors, const EskfOptions& eskf,
                                        const StandstillOptions& standstill, const BackwardSpan& span);

}  // namespace gins
