// Feeding a simulated drive to a EstimatorPipeline, as the runner feeds it a log's records.
#pragma once

#include "core/sim/simulator.h"
#include "solver/estimator_pipeline.h"

namespace gins::test {

inline void FeedSession(EstimatorPipeline* session, const SimRecord& rec) { session->Add(rec); }

}  // namespace gins::test
