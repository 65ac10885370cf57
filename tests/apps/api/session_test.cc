// The public API (gins/gins.h) on the bundled sample: callbacks and polling, out-of-order input within and
// beyond the reorder window, a callback that throws, invalid measurements, configs and logs that do not
// load, and the status.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "gins/gins.h"

namespace gins::api {
namespace GINS_TEST_FILE {

const std::string kSample = std::string(GINS_TEST_DATA_DIR) + "/sample/log.txt.gz";

// The sample's records, read once.
const std::vector<Record>& SampleRecords() {
  static const std::vector<Record> records = [] {
    std::vector<Record> out;
    LogReader reader(kSample, Config());
    Record r;
    while (reader.Next(&r)) out.push_back(r);
    return out;
  }();
  return records;
}

// Every state of one run over `records`, through a callback.
std::vector<State> RunThrough(const std::vector<Record>& records, const Config& config, Mode mode = Mode::kEskf) {
  Session session(config, mode);
  std::vector<State> states;
  session.OnState([&](const State& s) { states.push_back(s); });
  for (const Record& r : records) EXPECT_TRUE(session.Push(r)) << r.t();
  session.Finish();
  return states;
}

// Bit for bit: every number of every state.
void ExpectSameStates(const std::vector<State>& a, const std::vector<State>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].stream, b[i].stream) << i;
    ASSERT_EQ(a[i].t, b[i].t) << i;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(a[i].p_enu[k], b[i].p_enu[k]) << i;
      ASSERT_EQ(a[i].v_enu[k], b[i].v_enu[k]) << i;
      ASSERT_EQ(a[i].sigma_p[k], b[i].sigma_p[k]) << i;
    }
    for (int k = 0; k < 4; ++k) ASSERT_EQ(a[i].q_wb[k], b[i].q_wb[k]) << i;
  }
}

const std::vector<State>& ReferenceEskf() {
  static const std::vector<State> states = RunThrough(SampleRecords(), Config());
  return states;
}

TEST(ApiSessionTest, SampleGivesOneEskfStatePerImuSampleAfterInitialisation) {
  const std::vector<State>& states = ReferenceEskf();
  ASSERT_GT(states.size(), 15000u);
  const Geodetic origin{31.508183, 120.401989, 12.0};  // the sample's first fix, near enough
  EXPECT_NEAR(states.front().lla[0], origin.lat_deg, 1e-4);
  EXPECT_NEAR(states.front().lla[1], origin.lon_deg, 1e-4);
  // In time order; a state may repeat the time of the one before (an update at that time supersedes it).
  for (size_t i = 1; i < states.size(); ++i) ASSERT_GE(states[i].t, states[i - 1].t);
  const State& last = states.back();
  EXPECT_NEAR(std::hypot(last.q_wb[0], std::hypot(last.q_wb[1], std::hypot(last.q_wb[2], last.q_wb[3]))), 1.0, 1e-9);
  EXPECT_GT(last.sigma_p[0], 0.0);
  EXPECT_LT(last.sigma_p[0], 1.0);
}

TEST(ApiSessionTest, PollingGivesTheSameStatesAsTheCallback) {
  Session session(Config(), Mode::kEskf);
  std::vector<State> polled;
  State s;
  for (const Record& r : SampleRecords()) {
    session.Push(r);
    while (session.Poll(&s)) polled.push_back(s);
  }
  session.Finish();
  while (session.Poll(&s)) polled.push_back(s);
  ExpectSameStates(polled, ReferenceEskf());
  EXPECT_EQ(session.status().states, polled.size());
}

TEST(ApiSessionTest, FullPollQueueDropsTheOldest) {
  SessionOptions options;
  options.max_queued_states = 10;
  Session session(Config(), options);
  for (const Record& r : SampleRecords()) session.Push(r);
  session.Finish();
  std::vector<State> polled;
  State s;
  while (session.Poll(&s)) polled.push_back(s);
  ASSERT_EQ(polled.size(), 10u);
  EXPECT_EQ(polled.back().t, ReferenceEskf().back().t);
  EXPECT_EQ(session.status().states_dropped, ReferenceEskf().size() - 10);
}

// GNSS fixes delivered 0.15 s late (after the IMU samples that follow them), as a live receiver does,
// from 30 s on: the first fixes arrive in time, so the session initialises even when the late ones are
// refused (the initialiser needs a few fixes, not one at the end of the log).
std::vector<Record> WithLateFixes(double delay, size_t* moved) {
  constexpr double kInTimeFor = 30.0;  // s
  std::vector<Record> out;
  std::vector<Record> waiting;
  *moved = 0;
  const double t_first = SampleRecords().front().t();
  for (const Record& r : SampleRecords()) {
    while (!waiting.empty() && r.t() > waiting.front().t() + delay) {
      out.push_back(waiting.front());
      waiting.erase(waiting.begin());
    }
    if (r.type == Record::Type::kGnss && r.t() >= t_first + kInTimeFor) {
      waiting.push_back(r);
    } else {
      out.push_back(r);
    }
  }
  out.insert(out.end(), waiting.begin(), waiting.end());
  // Those that now come after a newer record.
  double newest = 0.0;
  for (const Record& r : out) {
    *moved += r.t() < newest;
    newest = std::max(newest, r.t());
  }
  return out;
}

TEST(ApiSessionTest, OutOfOrderWithinTheWindowIsSortedIntoPlace) {
  size_t moved = 0;
  const std::vector<Record> late = WithLateFixes(0.15, &moved);
  ASSERT_GT(moved, 100u);
  const Config config = Config::FromYaml("input: {reorder_window_s: 0.2}");
  Session session(config, Mode::kEskf);
  std::vector<State> states;
  session.OnState([&](const State& s) { states.push_back(s); });
  for (const Record& r : late) ASSERT_TRUE(session.Push(r)) << r.t();
  session.Finish();
  ExpectSameStates(states, ReferenceEskf());  // the same run as in order
  const Status status = session.status();
  EXPECT_EQ(status.reordered, moved);
  EXPECT_EQ(status.rejected, 0u);
}

TEST(ApiSessionTest, OutOfOrderBeyondTheWindowIsRejectedAndCounted) {
  size_t moved = 0;
  const std::vector<Record> late = WithLateFixes(0.15, &moved);
  Session session(Config::FromYaml("input: {reorder_window_s: 0.1}"), Mode::kEskf);
  size_t refused = 0;
  for (const Record& r : late) refused += !session.Push(r);
  session.Finish();
  const Status status = session.status();
  EXPECT_EQ(refused, moved);  // every fix came more than 0.1 s after a newer IMU sample
  EXPECT_EQ(status.rejected, moved);
  bool found = false;
  for (const Rejection& r : status.rejections) {
    if (r.source == "input") {
      EXPECT_EQ(r.measurement, "gnss");
      EXPECT_EQ(r.reason, "late");
      EXPECT_EQ(r.count, moved);
      found = true;
    }
  }
  EXPECT_TRUE(found);
  EXPECT_NE(session.StatsJson().find("\"late\":" + std::to_string(moved)), std::string::npos);
}

// The exception comes out of the push that produced the state, after the estimator finished its step:
// the states, including the rest of the run, are those of a run whose callback never threw.
TEST(ApiSessionTest, CallbackThatThrowsLeavesTheSessionUsable) {
  Session session(Config(), Mode::kEskf);
  std::vector<State> states;
  session.OnState([&](const State& s) {
    states.push_back(s);
    if (states.size() == 100 || states.size() == 5000) throw std::logic_error("consumer failed");
  });
  int thrown = 0;
  for (const Record& r : SampleRecords()) {
    try {
      session.Push(r);
    } catch (const std::logic_error& e) {  // the callback's own type
      EXPECT_STREQ(e.what(), "consumer failed");
      ++thrown;
    }
  }
  session.Finish();
  EXPECT_EQ(thrown, 2);
  ExpectSameStates(states, ReferenceEskf());
  EXPECT_EQ(session.status().callback_errors, 2u);
}

TEST(ApiSessionTest, CallbackThatThrowsInFinishIsRethrownThere) {
  Session session(Config(), Mode::kSmoother);
  bool finishing = false;
  int calls_after = 0;
  session.OnState([&](const State&) {
    if (!finishing) return;
    ++calls_after;
    throw std::runtime_error("full disk");
  });
  for (const Record& r : SampleRecords()) session.Push(r);
  finishing = true;
  EXPECT_THROW(session.Finish(), std::runtime_error);
  EXPECT_GT(calls_after, 1);  // the smoother's window still went to the callback after the first throw
}

TEST(ApiSessionTest, InvalidMeasurementsAreRefusedWithTheLogReadersReasons) {
  Session session(Config(), Mode::kEskf);
  Imu imu;
  imu.t = 1.0;
  imu.acc[2] = 9.8;
  EXPECT_TRUE(session.Push(imu));
  imu.t = 1.01;
  imu.gyro[1] = std::nan("");
  EXPECT_FALSE(session.Push(imu));
  Gnss fix;
  fix.t = 1.02;
  fix.lat_deg = 95.0;
  EXPECT_FALSE(session.Push(fix));
  Wheel wheel;
  wheel.t = 0.5;  // older than the newest, window 0
  EXPECT_FALSE(session.Push(wheel));
  const Status status = session.status();
  EXPECT_EQ(status.accepted, 1u);
  EXPECT_EQ(status.rejected, 3u);
  std::vector<std::string> reasons;
  for (const Rejection& r : status.rejections) reasons.push_back(r.measurement + "/" + r.reason);
  EXPECT_EQ(reasons, (std::vector<std::string>{"gnss/absurd_value", "imu/non_finite", "wheel/late"}));
  EXPECT_FALSE(status.initialized);
  EXPECT_FALSE(status.origin.has_value());
  EXPECT_NE(status.diagnosis.find("no GNSS fix"), std::string::npos) << status.diagnosis;
}

// imu.max_gyro_rad_s and imu.max_acc_m_s2 are the sensor's range: a reading beyond it is refused as in a log,
// pushed or read, and a wider range lets through what the defaults refuse.
TEST(ApiSessionTest, ImuRangeComesFromTheConfig) {
  const Config narrow = Config::FromYaml("imu: {max_gyro_rad_s: 10, max_acc_m_s2: 100}");
  const Config wide = Config::FromYaml("imu: {max_gyro_rad_s: 50, max_acc_m_s2: 300}");
  Imu imu;
  imu.t = 1.0;
  imu.acc[0] = 150.0;
  imu.acc[2] = 9.8;
  Session defaults(Config(), Mode::kEskf);
  Session n(narrow, Mode::kEskf);
  Session w(wide, Mode::kEskf);
  EXPECT_TRUE(defaults.Push(imu));
  EXPECT_FALSE(n.Push(imu));
  EXPECT_TRUE(w.Push(imu));
  imu.t = 1.01;
  imu.acc[0] = 250.0;
  EXPECT_FALSE(defaults.Push(imu));
  EXPECT_TRUE(w.Push(imu));
  imu.t = 1.02;
  imu.acc[0] = 0.0;
  imu.gyro[2] = 20.0;
  EXPECT_FALSE(n.Push(imu));
  ASSERT_EQ(n.status().rejections.size(), 1u);
  EXPECT_EQ(n.status().rejections[0].measurement + "/" + n.status().rejections[0].reason, "imu/absurd_value");
  EXPECT_EQ(n.status().rejections[0].count, 2u);
  EXPECT_EQ(n.status().rejected, 2u);

  const std::string path = ::testing::TempDir() + "/gins_imu_range_log.txt";
  {
    std::ofstream out(path);
    out << "IMU 1.0 0 0 0 0 0 9.8\nIMU 1.01 0 0 0 150 0 9.8\nIMU 1.02 0 0 0 250 0 9.8\n";
  }
  const auto count = [&](const Config& config) {
    LogReader reader(path, config);
    Record r;
    size_t records = 0;
    while (reader.Next(&r)) ++records;
    return records;
  };
  EXPECT_EQ(count(Config()), 2u);
  EXPECT_EQ(count(narrow), 1u);
  EXPECT_EQ(count(wide), 3u);
}

TEST(ApiSessionTest, StatusNamesTheEstimatorsRejections) {
  Session session(Config(), Mode::kBoth);
  for (const Record& r : SampleRecords()) session.Push(r);
  session.Finish();
  const Status status = session.status();
  EXPECT_TRUE(status.initialized);
  EXPECT_EQ(status.diagnosis, "initialised");
  ASSERT_TRUE(status.origin.has_value());
  EXPECT_NEAR(status.origin->lat_deg, 31.508183, 1e-4);
  EXPECT_EQ(status.accepted, SampleRecords().size());
  // The sample's last fix is an outlier both estimators reject (summary.json: gnss_position chi2_gate).
  int gates = 0;
  for (const Rejection& r : status.rejections) {
    gates += r.measurement == "gnss_position" && r.reason == "chi2_gate" && r.count >= 1 &&
             (r.source == "eskf" || r.source == "smoother");
  }
  EXPECT_EQ(gates, 2);
  EXPECT_EQ(status.watchdog_resets, 0u);
}

TEST(ApiSessionTest, UsageErrorsAndNoSolution) {
  Session never(Config(), Mode::kEskf);
  Imu imu;
  imu.t = 1.0;
  never.Push(imu);
  try {
    never.Finish();
    ADD_FAILURE() << "no Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::kNoSolution);
    EXPECT_NE(std::string(e.what()).find("no GNSS fix"), std::string::npos) << e.what();
  }
  try {
    never.Push(imu);
    ADD_FAILURE() << "no Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::kUsage);
  }
}

TEST(ApiSessionTest, InitialisationTimeOut) {
  Session session(Config::FromYaml("init: {max_wait_s: 1}"), Mode::kEskf);
  Imu imu;
  imu.acc[2] = 9.8;
  for (int i = 0; i <= 150; ++i) {
    imu.t = 100.0 + 0.01 * i;
    session.Push(imu);
  }
  EXPECT_TRUE(session.init_timed_out());
  EXPECT_TRUE(session.status().init_timed_out);
  EXPECT_FALSE(session.initialized());
}

TEST(ApiSessionTest, GeodeticOffLeavesLlaNaNAndTheRestAlone) {
  SessionOptions options;
  options.geodetic = false;
  Session session(Config(), options);
  std::vector<State> states;
  session.OnState([&](const State& s) { states.push_back(s); });
  for (const Record& r : SampleRecords()) session.Push(r);
  session.Finish();
  ExpectSameStates(states, ReferenceEskf());
  EXPECT_TRUE(std::isnan(states.front().lla[0]));
}

TEST(ApiSessionTest, AMovedSessionKeepsDelivering) {
  Session first(Config(), Mode::kEskf);
  std::vector<State> states;
  first.OnState([&](const State& s) { states.push_back(s); });
  const std::vector<Record>& records = SampleRecords();
  const size_t half = records.size() / 2;
  for (size_t i = 0; i < half; ++i) first.Push(records[i]);
  Session second = std::move(first);
  for (size_t i = half; i < records.size(); ++i) second.Push(records[i]);
  second.Finish();
  ExpectSameStates(states, ReferenceEskf());
}

TEST(ApiConfigTest, AConfigThatDoesNotLoadSaysWhy) {
  try {
    Config::FromYaml("imu:\n  gyro_noise_deg_sqrt_hh: 1\n", "my.yaml");
    ADD_FAILURE() << "no Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::kConfig);
    EXPECT_NE(std::string(e.what()).find("my.yaml: imu.gyro_noise_deg_sqrt_hh: unknown key"), std::string::npos)
        << e.what();
  }
  try {
    Config::FromFile("/nonexistent/gins.yaml");
    ADD_FAILURE() << "no Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::kConfig);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/gins.yaml"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Config::FromYaml("input: {reorder_window_s: -1}"), Error);
  const Config config = Config::FromYaml("input: {reorder_window_s: 0.25}");
  EXPECT_EQ(config.reorder_window_s(), 0.25);
  EXPECT_EQ(Config::FromYaml(config.ToYaml()).reorder_window_s(), 0.25);
  EXPECT_EQ(Config().reorder_window_s(), 0.1);  // the default: a logger's cross-thread jitter
}

TEST(ApiConfigTest, ALogThatCannotBeReadSaysWhy) {
  try {
    LogReader reader("/nonexistent/log.txt", Config());
    ADD_FAILURE() << "no Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::kInput);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/log.txt: cannot open"), std::string::npos) << e.what();
  }
}

TEST(ApiConfigTest, NamesAndAttitude) {
  Mode mode;
  EXPECT_TRUE(ParseMode("smoother", &mode));
  EXPECT_EQ(mode, Mode::kSmoother);
  EXPECT_FALSE(ParseMode("kalman", &mode));
  EXPECT_STREQ(StreamName(Stream::kSmootherOnline), "smoother_online");
  EXPECT_STREQ(Version(), GINS_PROJECT_VERSION);
  State s;  // identity: body x along east
  EXPECT_NEAR(HeadingDeg(s), 90.0, 1e-12);
  const double c = std::cos(M_PI / 8), sn = std::sin(M_PI / 8);  // 45° about up: x to north-east
  s.q_wb[0] = c, s.q_wb[3] = sn;
  EXPECT_NEAR(HeadingDeg(s), 45.0, 1e-9);
  double rpy[3];
  RollPitchYawDeg(s, rpy);
  EXPECT_NEAR(rpy[0], 0.0, 1e-9);
  EXPECT_NEAR(rpy[1], 0.0, 1e-9);
  EXPECT_NEAR(rpy[2], 45.0, 1e-9);
}

}  // namespace
}  // namespace gins::api
