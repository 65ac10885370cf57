// The YAML front door: the only code in gins that reads YAML.
//
// Every key is optional (a missing key keeps the in-class default of its option struct, config/options.h).
// Anything else that is not exactly right is an error: unknown keys (with a did-you-mean), duplicate keys,
// wrong types, wrong list lengths, NaN/inf, out-of-range values, unknown enum strings. Errors are thrown as
// ConfigError with a message of the form "<file>: <key.path>: <reason> (line N)", so a user can fix the file
// without reading code. Users' units (named by each key's suffix, e.g. `_deg_sqrt_h`) are converted to SI
// here, once. Each key is declared once, in config/config_keys.h; config/default.yaml documents every key.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "config/options.h"

namespace gins {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Loads and validates a YAML file. Throws ConfigError on any problem (including an unreadable file).
Options LoadOptions(const std::string& path);

// As LoadOptions, from text; `name_for_errors` stands for the file name in messages. Empty text gives the
// defaults.
Options LoadOptionsFromString(const std::string& yaml, const std::string& name_for_errors);

// The effective options as YAML in the users' units (for echoing into a run directory). Numbers are written
// with the fewest digits that load back to the identical double, so LoadOptionsFromString(OptionsToYaml(o))
// reproduces o bit for bit whenever o itself came from a config file or from the defaults.
std::string OptionsToYaml(const Options& o);

// Every key path a config file may hold, in file order: sections ("imu"), their keys ("imu.axes") and the
// keys of the items of a list ("simulate.segments[].duration_s").
std::vector<std::string> ConfigKeys();

}  // namespace gins
