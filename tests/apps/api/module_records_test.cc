// A measurement module's records through the public API (gins/gins.h: OtherRecord): read from a log as their
// token and numbers, pushed back into a session and used by its estimators; a token no module has, or a
// count of numbers its record cannot have, is an input error that names it.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "gins/gins.h"

namespace gins::api {
namespace GINS_TEST_FILE {

const std::string kSample = std::string(GINS_TEST_DATA_DIR) + "/sample/log.txt.gz";

TEST(ApiModuleRecords, ReadAsTheirTokenAndNumbers) {
  const std::string path = testing::TempDir() + "/module_records_test_log.txt";
  {
    std::ofstream f(path);
    f << "BARO 1700000001.5 12.25\nBARO 1700000002.5 13 0.4\n";
  }
  LogReader reader(path, Config());
  Record r;
  ASSERT_TRUE(reader.Next(&r));
  ASSERT_EQ(r.type, Record::Type::kOther);
  EXPECT_EQ(r.other.type, "BARO");
  EXPECT_EQ(r.other.values, (std::vector<double>{1700000001.5, 12.25}));
  EXPECT_EQ(r.t(), 1700000001.5);
  EXPECT_EQ(r.line, 1u);
  ASSERT_TRUE(reader.Next(&r));
  EXPECT_EQ(r.other.values, (std::vector<double>{1700000002.5, 13.0, 0.4}));
  EXPECT_FALSE(reader.Next(&r));
  std::remove(path.c_str());
}

TEST(ApiModuleRecords, PushedAndUsedByBothEstimators) {
  Session session(Config(), Mode::kBoth);
  LogReader reader(kSample, Config());
  size_t baro = 0;
  for (Record r; reader.Next(&r);) {
    ASSERT_TRUE(session.Push(r));
    if (r.type != Record::Type::kGnss) continue;
    Record b;
    b.type = Record::Type::kOther;
    b.other = {"BARO", {r.gnss.t, r.gnss.alt_m, 0.5}};  // the fix's own height: consistent, if noisy
    ASSERT_TRUE(session.Push(b));
    ++baro;
  }
  session.Finish();
  ASSERT_GT(baro, 100u);
  const std::string stats = session.StatsJson();
  for (const char* estimator : {"\"eskf\":", "\"smoother\":"}) {
    const size_t at = stats.find(estimator);
    ASSERT_NE(at, std::string::npos) << stats;
    const size_t b = stats.find("\"barometer\":{", at);
    ASSERT_NE(b, std::string::npos) << estimator;
    const size_t used = stats.find("\"used\":", b);
    ASSERT_NE(used, std::string::npos);
    EXPECT_GT(std::stoul(stats.substr(used + 7)), baro / 2) << estimator << " " << stats.substr(b, 120);
  }
}

// Pushing r throws an Error of kind kInput whose message holds `text`.
void ExpectInputError(Session* session, const Record& r, const std::string& text) {
  try {
    session->Push(r);
    ADD_FAILURE() << "no error for " << r.other.type;
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::kInput);
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(ApiModuleRecords, UnknownTokenOrCountIsAnInputError) {
  Session session(Config(), Mode::kEskf);
  Record r;
  r.type = Record::Type::kOther;
  r.other = {"MAGN", {1.0, 2.0}};
  ExpectInputError(&session, r, "'MAGN'");
  r.other = {"BARO", {1.0, 2.0, 3.0, 4.0}};
  ExpectInputError(&session, r, "BARO record has 4 values, needs 2 or 3");
}

}  // namespace GINS_TEST_FILE
}  // namespace gins::api
