// Keys of summary.json that one part of gins writes and another reads back in the same run: each written
// once, here, so that a rename is a compile error instead of a count silently read back as 0. (Keys only
// written, or read from older summaries on disk, e.g. by `gins report`, stay where they are used.)
#pragma once

namespace gins::summary_keys {

// EstimatorPipeline::Stats() (solver/estimator_pipeline.h), read into summary.json's "input" and "faults".
inline constexpr char kOdomIgnoredWheelDisabled[] = "odom_ignored_wheel_disabled";
inline constexpr char kGvelUnused[] = "gvel_unused";
inline constexpr char kImuIntervalJitter[] = "imu_interval_jitter";
inline constexpr char kImuRateChanges[] = "imu_rate_changes";
inline constexpr char kImuSameStamp[] = "imu_same_stamp";
inline constexpr char kWheelIntervalJitter[] = "wheel_interval_jitter";
inline constexpr char kWheelGaps[] = "wheel_gaps";
inline constexpr char kDroppedBeforeFirstFix[] = "dropped_before_first_fix";
inline constexpr char kRestStatesBeforeInitialization[] = "rest_states_before_initialization";
// The API session's own part of it (apps/api/session.cc): "session": {"reorder_window_s", "stamps", ...}.
inline constexpr char kSession[] = "session";
inline constexpr char kReorderWindow[] = "reorder_window_s";
inline constexpr char kStamps[] = "stamps";

// Each estimator's Stats(): its IMU gaps (ImuGapLog) and the watchdog's {"count", "resets"} (GnssWatchdog).
inline constexpr char kImuGaps[] = "imu_gaps";
inline constexpr char kWatchdog[] = "watchdog";
inline constexpr char kWatchdogCount[] = "count";

}  // namespace gins::summary_keys
