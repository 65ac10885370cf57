// A record of the log (docs/formats.md §3), the one record type below the public API: what the reader yields,
// what the simulator generates (core/sim/simulator.h: SimRecord, with its truth), what the writer writes and
// what the solver's EstimatorPipeline takes (EstimatorPipeline::Add). Its types are listed once, in
// LogRecordData (a measurement module's, in core/measurement_modules.h); what the code around a type needs
// to know of it (token, names, field counts: RecordTypeInfo, core/measurement_module.h) is its RecordTraits
// row. Per-type code (parsing, writing, dispatch) visits the variant, so a type left out is a
// compile error; the time stamp and the counts by type need no per-type code at all.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <type_traits>
#include <variant>

#include "core/measurement_modules.h"
#include "core/measurements.h"

namespace gins {

// The record types, in the order of every list of them (messages, ReadStats::records, the summary): the
// built-in ones, then the measurement modules' (core/measurement_modules.h).
using LogRecordData = MeasurementModules::RecordsAfter<ImuSample, WheelRecord, GnssRecord, GnssVelocityRecord>;
inline constexpr size_t kNumRecordTypes = std::variant_size_v<LogRecordData>;

// One specialisation per built-in alternative of LogRecordData; a measurement module's record carries its row.
template <typename R>
struct RecordTraits {
  static constexpr RecordTypeInfo kInfo = R::kInfo;
};

namespace record_fields {
inline constexpr const char* kImu[] = {"t", "gx", "gy", "gz", "ax", "ay", "az"};
inline constexpr const char* kWheel[] = {"t", "left_pulses", "right_pulses"};
inline constexpr const char* kGnss[] = {"t",       "lat",     "lon",    "alt", "heading", "heading_valid",
                                        "sigma_e", "sigma_n", "sigma_u"};
inline constexpr const char* kGnssVelocity[] = {"t", "ve", "vn", "vu", "sigma_e", "sigma_n", "sigma_u"};
}  // namespace record_fields

template <>
struct RecordTraits<ImuSample> {
  static constexpr RecordTypeInfo kInfo = {"IMU", "imu", "imu", record_fields::kImu, std::size(record_fields::kImu),
                                           std::size(record_fields::kImu), false};
};
template <>
struct RecordTraits<WheelRecord> {
  static constexpr RecordTypeInfo kInfo = {"ODOM", "wheel", "odom", record_fields::kWheel,
                                           std::size(record_fields::kWheel), std::size(record_fields::kWheel), false};
};
template <>
struct RecordTraits<GnssRecord> {
  static constexpr RecordTypeInfo kInfo = {"GNSS", "gnss", "gnss", record_fields::kGnss,
                                           std::size(record_fields::kGnss), 6, false};
};
template <>
struct RecordTraits<GnssVelocityRecord> {
  static constexpr RecordTypeInfo kInfo = {"GVEL", "gnss_velocity", "gvel", record_fields::kGnssVelocity,
                                           std::size(record_fields::kGnssVelocity), 4, true};
};

namespace record_detail {
template <typename Variant>
struct Table;
template <typename... R>
struct Table<std::variant<R...>> {
  static constexpr std::array<RecordTypeInfo, sizeof...(R)> kRows = {RecordTraits<R>::kInfo...};
  template <typename X>
  static constexpr size_t IndexOf() {
    constexpr bool same[] = {std::is_same_v<X, R>...};
    size_t i = 0;
    while (i < sizeof...(R) && !same[i]) ++i;
    return i;
  }
};

template <typename R>
constexpr size_t RecordIndex() {
  constexpr size_t index = Table<LogRecordData>::IndexOf<R>();
  static_assert(index < kNumRecordTypes, "not an alternative of LogRecordData");
  return index;
}
}  // namespace record_detail

// The rows by LogRecordData's index, and the index of a type.
inline constexpr const std::array<RecordTypeInfo, kNumRecordTypes>& kRecordTypes =
    record_detail::Table<LogRecordData>::kRows;
template <typename R>
inline constexpr size_t kRecordIndex = record_detail::RecordIndex<R>();

// Counts of records by type, by LogRecordData's index.
using RecordCounts = std::array<uint64_t, kNumRecordTypes>;
template <typename R>
uint64_t CountOf(const RecordCounts& counts) {
  return counts[kRecordIndex<R>];
}

struct LogRecord {
  LogRecordData data;
  uint64_t line = 0;  // 1-based line number in the file

  double t() const {
    return std::visit([](const auto& m) { return m.t; }, data);
  }
  void set_t(double t) {
    std::visit([t](auto& m) { m.t = t; }, data);
  }
  size_t type_index() const { return data.index(); }  // into kRecordTypes and RecordCounts
  const RecordTypeInfo& info() const { return kRecordTypes[data.index()]; }

  // The measurement as R: get where the type is known (std::bad_variant_access otherwise), get_if to ask.
  template <typename R>
  bool is() const {
    return std::holds_alternative<R>(data);
  }
  template <typename R>
  R& get() {
    return std::get<R>(data);
  }
  template <typename R>
  const R& get() const {
    return std::get<R>(data);
  }
  template <typename R>
  R* get_if() {
    return std::get_if<R>(&data);
  }
  template <typename R>
  const R* get_if() const {
    return std::get_if<R>(&data);
  }
};

}  // namespace gins
