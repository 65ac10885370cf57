// The registered measurement modules (core/measurement_module.h): a module's header, and its name in the
// list. The order of the list is the order of the records after the built-in ones (ReadStats::records,
// summary.json), of the config's sections after gravity.* and of the estimators' stats.
#pragma once

#include "core/measurement_module.h"

#include "core/barometer.h"

namespace gins {

using MeasurementModules = ModuleList<BarometerModule>;

}  // namespace gins
