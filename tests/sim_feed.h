// Feeding a simulated drive to a Session, as the runner feeds it a log's records.
#pragma once

#include "core/sim/simulator.h"
#include "solver/session.h"

namespace gins::test {

inline void FeedSession(Session* session, const SimRecord& rec) { session->Add(rec); }

}  // namespace gins::test
