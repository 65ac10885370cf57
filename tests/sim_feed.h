// Feeding a simulated drive to a Session, as the runner feeds it a log's records.
#pragma once

#include "core/sim/simulator.h"
#include "solver/session.h"

namespace gins::test {

inline void FeedSession(Session* session, const SimRecord& rec) {
  switch (rec.type) {
    case SimRecord::Type::kImu:
      session->AddImu(rec.imu);
      break;
    case SimRecord::Type::kOdom:
      session->AddOdom(rec.odom);
      break;
    case SimRecord::Type::kGnss:
      session->AddGnss(rec.gnss);
      break;
    case SimRecord::Type::kGvel:
      session->AddGvel(rec.gvel);
      break;
  }
}

}  // namespace gins::test
