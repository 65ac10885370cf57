// What gins's own tools (`gins run`, `gins stream`) need of the API objects beyond the public header: the
// loaded options and the internal session and reader behind them, for summary.json. Not installed.
#pragma once

#include <nlohmann/json.hpp>

#include "config/options.h"
#include "core/io/log_reader.h"
#include "gins/gins.h"
#include "solver/estimator_pipeline.h"

namespace gins::api::internal {

class Access {
 public:
  static const Options& options(const Config& config);
  static Config MakeConfig(const Options& options);
  static const ::gins::EstimatorPipeline& session(const Session& session);
  // The internal session's Stats() and the API's own counts under "session" (as Session::StatsJson()).
  static nlohmann::json stats(const Session& session);
  static const ReadStats& read_stats(const LogReader& reader);
};

}  // namespace gins::api::internal
