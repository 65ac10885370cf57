// A measurement type added as a module: everything gins needs to know of it in one header under core/, and
// one line in core/measurement_modules.h that registers it. The reader, the writer, the API, the config,
// the pipeline and both estimators then take it with no code of their own (docs/architecture.md, "Recipe: a
// new measurement type"). The types that predate modules (IMU, wheel, GNSS fix, GNSS velocity, raw GNSS)
// have their own code in each of those places.
//
// A module Mod provides:
//   Mod::kName          its name: its counts in each estimator's stats (summary.json), "barometer"
//   Mod::Record         the log record, as written: `double t` and its fields, and
//     static constexpr RecordTypeInfo kInfo;                         token, names, field counts
//     static std::string Absurd(const double* v, size_t n);          why the n numbers (t first) cannot be
//                                                                    a record, empty if they can
//     static void Fill(const double* v, size_t n, Record* r);        the numbers into the record
//     static size_t Values(const Record& r, double* v);              and back (at most kInfo.max_fields)
//   Mod::Options        its config section: kSection (the YAML key), kKeys (a generic lambda (v, o), o an Options,
//                       declaring each key as config/config_keys.h does), and the members `bool enabled` and
//                       `double gate_probability` (the χ² gate of both estimators; 0 = off)
//   Mod::Measurement    in the world frame, ready for an estimator: `double t`, and what its model needs
//   Mod::Model          the residual, whitened, of the kinematic state at the measurement's time:
//     static constexpr int kResidualDim;  (1 to 3)
//     template <typename T> void operator()(const PredictedKinematics<T>& k, T* residual) const;
//   static std::optional<Measurement> ToMeasurement(const Record&, const Options&, const LocalEnuFrame& w);
//                       the record in w (nullopt: unusable, counted by the pipeline)
//   static Model ModelOf(const Measurement&, const Options&);
// A measurement of the state at its time is the common case (a position, a velocity, an attitude, a height);
// a type that needs more (two epochs' states, a state block of its own) is written as the built-in types are.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <tuple>
#include <type_traits>
#include <variant>

namespace gins {

// One record type's row.
struct RecordTypeInfo {
  const char* token;          // the log's type token, "IMU"
  const char* name;           // the API's measurement name (api::Status::rejections), "imu"
  const char* count_key;      // its key in summary.json's input.records, "imu"
  const char* const* fields;  // names of the numbers after the token, in log order (for messages)
  size_t max_fields;          // a line has all of them,
  size_t min_fields;          // or only the first min_fields: the rest are the optional σ, all three or none
  bool quiet_when_none;       // a count of zero is left out of messages (a log before GVEL has none)
};

template <typename Mod>
struct ModuleTag {
  using type = Mod;
};

// The registered modules (core/measurement_modules.h: MeasurementModules), and what the code around them
// derives from the list.
template <typename... Mod>
struct ModuleList {
  static constexpr size_t kSize = sizeof...(Mod);
  // Each module's options, in list order (SensorOptions::modules).
  using Options = std::tuple<typename Mod::Options...>;
  // The variants of records and measurements: the built-in types T, then the modules'.
  template <typename... T>
  using RecordsAfter = std::variant<T..., typename Mod::Record...>;
  template <typename... T>
  using MeasurementsAfter = std::variant<T..., typename Mod::Measurement...>;

  template <typename R>
  static constexpr bool kHasRecord = (std::is_same_v<R, typename Mod::Record> || ...);
  template <typename M>
  static constexpr bool kHasMeasurement = (std::is_same_v<M, typename Mod::Measurement> || ...);

  // f(ModuleTag<Mod>{}) for each module, in list order.
  template <typename F>
  static void ForEach(F&& f) {
    (f(ModuleTag<Mod>{}), ...);
  }

  // The index in the list of module M, and of the module whose measurement (or record) type is M.
  template <typename M>
  static constexpr size_t IndexOf() {
    return FirstTrue({std::is_same_v<M, Mod>...});
  }
  template <typename M>
  static constexpr size_t IndexOfMeasurement() {
    return FirstTrue({std::is_same_v<M, typename Mod::Measurement>...});
  }
  template <typename R>
  static constexpr size_t IndexOfRecord() {
    return FirstTrue({std::is_same_v<R, typename Mod::Record>...});
  }
  template <size_t I>
  using At = std::tuple_element_t<I, std::tuple<Mod...>>;

 private:
  // The first index whose flag is set (kSize if none).
  static constexpr size_t FirstTrue(std::initializer_list<bool> flags) {
    size_t i = 0;
    for (const bool f : flags) {
      if (f) return i;
      ++i;
    }
    return kSize;
  }
};

}  // namespace gins
