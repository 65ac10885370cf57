// The estimators built from a whole config, as the API's session builds them (apps/api/session.cc): each
// takes only the sections it reads.
#pragma once

#include <memory>
#include <utility>

#include "config/options.h"
#include "solver/eskf.h"
#include "solver/smoother.h"

namespace gins::test {

inline std::unique_ptr<Eskf> MakeEskf(const Options& o, StateCallback on_state, StateCallback on_rts = nullptr) {
  return std::make_unique<Eskf>(o.sensors, o.eskf, o.standstill, o.watchdog, std::move(on_state), std::move(on_rts));
}

inline std::unique_ptr<Smoother> MakeSmoother(const Options& o, StateCallback on_final, StateCallback on_online,
                                              StateCallback on_batch = nullptr) {
  return std::make_unique<Smoother>(o.sensors, o.eskf, o.smoother, o.batch, o.standstill, o.watchdog,
                                    std::move(on_final), std::move(on_online), std::move(on_batch));
}

}  // namespace gins::test
