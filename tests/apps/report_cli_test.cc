// `gins report`: one row per run, the numbers of each run's summary.json, folders searched for runs, and a
// run without a summary listed and failing the exit code.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "apps/report_command.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

namespace fs = std::filesystem;

const std::string kGins = GINS_BINARY;

// Runs a shell command; returns its exit code, with stdout in *out.
int Shell(const std::string& cmd, const std::string& dir, std::string* out) {
  const int status = std::system((cmd + " >" + dir + "/stdout 2>" + dir + "/stderr").c_str());
  *out = test::ReadFile(dir + "/stdout");
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::vector<std::string> LinesStartingWith(const std::string& text, const std::string& prefix) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(prefix, 0) == 0) lines.push_back(line);
  }
  return lines;
}

class ReportCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::MakeTempDir("report");
    const std::string data = GINS_TEST_DATA_DIR;
    std::string out;
    ASSERT_EQ(
        Shell(kGins + " run --config " + GINS_SOURCE_DIR + "/config/default.yaml --log " + data +
                  "/sample/log.txt.gz --truth " + data + "/sample/truth.csv.gz --mode eskf --out " + dir_ + "/runs/a",
              dir_, &out),
        0);
    fs::copy(dir_ + "/runs/a", dir_ + "/runs/b");
    fs::copy(dir_ + "/runs/a", dir_ + "/runs/c");
    // c: a run with damaged lines, a watchdog reset and no truth.
    nlohmann::json c = nlohmann::json::parse(test::ReadFile(dir_ + "/runs/c/summary.json"));
    c["input"]["skipped"] = {{"bad_number", 2}, {"time_jump", 1}};
    c["estimators"]["eskf"]["watchdog"]["count"] = 1;
    c["estimators"]["eskf"]["wheel"]["rejected"]["chi2_gate"] = 4;
    c.erase("accuracy");
    test::WriteFile(dir_ + "/runs/c/summary.json", c.dump());
  }
  static std::string dir_;
};
std::string ReportCliTest::dir_;

TEST_F(ReportCliTest, OneRowPerRunWithItsNumbers) {
  std::string out;
  ASSERT_EQ(Shell(kGins + " report " + dir_ + "/runs/a " + dir_ + "/runs/b " + dir_ + "/runs/c/summary.json --json " +
                      dir_ + "/report.json",
                  dir_, &out),
            0)
      << out;
  EXPECT_EQ(LinesStartingWith(out, "run ").size(), 1u) << out;
  // A column per output, the two-sided ones of --mode all included.
  for (const char* column : {"eskf H m", "smooth H m", "online H m", "batch H m", "rts H m"}) {
    EXPECT_NE(LinesStartingWith(out, "run ").at(0).find(column), std::string::npos) << column;
  }
  EXPECT_EQ(LinesStartingWith(out, "...").size() + LinesStartingWith(out, dir_).size(), 3u) << out;
  EXPECT_NE(out.find("3 runs, 0.15 h of log; 7 rejected, 3 skipped lines, 1 watchdog resets"), std::string::npos)
      << out;

  const nlohmann::json report = nlohmann::json::parse(test::ReadFile(dir_ + "/report.json"));
  ASSERT_EQ(report["runs"].size(), 3u);
  const nlohmann::json a = nlohmann::json::parse(test::ReadFile(dir_ + "/runs/a/summary.json"));
  const nlohmann::json& row = report["runs"][0];
  EXPECT_EQ(row["run"], dir_ + "/runs/a");
  EXPECT_EQ(row["mode"], "eskf");
  EXPECT_EQ(row["duration_s"], a["timing"]["log_duration_s"]);
  EXPECT_EQ(row["real_time_factor"], a["timing"]["real_time_factor"]);
  EXPECT_EQ(row["rmse_horizontal_m"]["eskf"], a["accuracy"]["eskf"]["rmse_horizontal_m"]);
  EXPECT_EQ(row["rejected"], 1);  // the sample's outlier fix
  EXPECT_EQ(row["rejected_by"]["eskf.gnss_position.chi2_gate"], 1);
  const nlohmann::json& c = report["runs"][2];
  EXPECT_EQ(c["skipped_lines"], 3);
  EXPECT_EQ(c["watchdog_resets"], 1);
  EXPECT_EQ(c["rejected"], 5);
  EXPECT_TRUE(c["rmse_horizontal_m"].empty());
  EXPECT_EQ(report["totals"]["runs"], 3);
}

TEST_F(ReportCliTest, FoldersAreSearchedAndRunsWithoutSummaryListed) {
  std::string out;
  ASSERT_EQ(Shell(kGins + " report " + dir_ + "/runs", dir_, &out), 0) << out;
  EXPECT_NE(out.find("3 runs"), std::string::npos) << out;

  fs::create_directories(dir_ + "/runs_failed/d");
  EXPECT_EQ(Shell(kGins + " report " + dir_ + "/runs/a " + dir_ + "/runs_failed/d", dir_, &out), 1);
  EXPECT_NE(out.find("no summary.json (the run failed or has not finished)"), std::string::npos) << out;
  EXPECT_NE(out.find("1 runs, 0.05 h of log; 1 rejected, 0 skipped lines, 0 watchdog resets; 1 without a summary"),
            std::string::npos)
      << out;

  // The folder of a fleet with a failed run (gins run leaves its --out folder empty): listed too, as
  // `runs_mixed/*/` lists it, and the exit code says so; a run's own empty subfolder is not a run.
  fs::create_directories(dir_ + "/runs_mixed");
  fs::copy(dir_ + "/runs/a", dir_ + "/runs_mixed/a");
  fs::create_directories(dir_ + "/runs_mixed/a/plots");
  fs::create_directories(dir_ + "/runs_mixed/failed");
  for (const std::string& inputs : {dir_ + "/runs_mixed", dir_ + "/runs_mixed/*/"}) {
    EXPECT_EQ(Shell(kGins + " report " + inputs, dir_, &out), 1) << inputs;
    EXPECT_EQ(LinesStartingWith(out, "...").size() + LinesStartingWith(out, dir_).size(), 2u) << out;
    EXPECT_NE(out.find("1 runs, 0.05 h of log; 1 rejected, 0 skipped lines, 0 watchdog resets; 1 without a summary"),
              std::string::npos)
        << out;
  }

  test::WriteFile(dir_ + "/runs_failed/bad.json", "{not json");
  EXPECT_EQ(Shell(kGins + " report " + dir_ + "/runs_failed/bad.json", dir_, &out), 1);
  EXPECT_NE(test::ReadFile(dir_ + "/stderr").find("bad.json: not a summary"), std::string::npos);
}

}  // namespace
}  // namespace gins
