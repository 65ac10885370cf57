// The documentation (README.md and every file under docs/) cites only what the repository holds: no design
// document outside it, and every repository path it writes in backticks exists. And the examples of
// docs/formats.md read as that page says with gins's own readers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/conventions.h"
#include "core/geodesy.h"
#include "core/io/log_reader.h"
#include "core/io/truth_reader.h"
#include "test_util.h"

namespace gins {
namespace GINS_TEST_FILE {

namespace fs = std::filesystem;

const fs::path kSourceDir = GINS_SOURCE_DIR;

struct Doc {
  std::string name;  // relative to the source directory, for messages
  std::vector<std::string> lines;
};

// README.md and every regular file under docs/, in path order.
std::vector<Doc> ReadDocs() {
  std::vector<fs::path> paths = {kSourceDir / "README.md"};
  for (const auto& e : fs::recursive_directory_iterator(kSourceDir / "docs")) {
    if (e.is_regular_file()) paths.push_back(e.path());
  }
  std::sort(paths.begin() + 1, paths.end());
  std::vector<Doc> docs;
  for (const fs::path& p : paths) {
    Doc doc{fs::relative(p, kSourceDir).string(), {}};
    std::istringstream in(test::ReadFile(p.string()));
    for (std::string line; std::getline(in, line);) doc.lines.push_back(line);
    docs.push_back(std::move(doc));
  }
  return docs;
}

bool IsWordChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// The word DESIGN (upper case, on its own: "DESIGN §3", "DESIGN.md", "../shared/DESIGN.md") names the design
// document that lives outside the repository.
bool NamesDesignDocument(const std::string& line) {
  for (size_t at = line.find("DESIGN"); at != std::string::npos; at = line.find("DESIGN", at + 1)) {
    const bool starts = at == 0 || !IsWordChar(line[at - 1]);
    const bool ends = at + 6 == line.size() || !IsWordChar(line[at + 6]);
    if (starts && ends) return true;
  }
  return false;
}

// The `code spans` of a line outside fenced blocks.
std::vector<std::string> CodeSpans(const std::string& line) {
  std::vector<std::string> spans;
  size_t open = line.find('`');
  while (open != std::string::npos) {
    const size_t close = line.find('`', open + 1);
    if (close == std::string::npos) break;
    spans.push_back(line.substr(open + 1, close - open - 1));
    open = line.find('`', close + 1);
  }
  return spans;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A span that looks like a path: one word with a '/', naming a source, doc, config or script file or (ending
// in '/') a directory. Placeholders and globs (`core/<name>_model.h`, `logs/*.txt.gz`) are patterns, not paths.
bool LooksLikePath(const std::string& s) {
  if (s.find('/') == std::string::npos || s.find_first_of(" \t<>*{}$?[]|") != std::string::npos) return false;
  for (const char* ext : {".h", ".cc", ".md", ".yaml", ".py", ".sh", "/"}) {
    if (EndsWith(s, ext)) return true;
  }
  return false;
}

// Why a path-like span is wrong, or empty. A path whose first component is not an entry of the source
// directory is not a repository path (an install prefix `P/include/...`, the output of a command such as
// `build-asan/` or `out/...`, another project's `src/fileio/...`, an include name `gins/gins.h`): not checked.
std::string CheckPath(std::string s) {
  if (s.rfind("./", 0) == 0) s = s.substr(2);
  if (s.rfind("../", 0) == 0 || s.rfind("/", 0) == 0) return "names a file outside the repository";
  const std::string first = s.substr(0, s.find('/'));
  // The outputs' folders (.gitignore's out*/ and build*/) may exist in a working tree, not in the repository.
  if (first.rfind("out", 0) == 0 || first.rfind("build", 0) == 0) return {};
  if (!fs::exists(kSourceDir / first)) return {};
  const fs::path p = kSourceDir / s;
  if (EndsWith(s, "/")) return fs::is_directory(p) ? "" : "no such directory in the repository";
  return fs::exists(p) ? "" : "no such file in the repository";
}

TEST(DocsReferences, NoDocumentNamesTheDesignDocument) {
  const std::vector<Doc> docs = ReadDocs();
  ASSERT_GE(docs.size(), 2u);
  for (const Doc& doc : docs) {
    for (size_t i = 0; i < doc.lines.size(); ++i) {
      EXPECT_FALSE(NamesDesignDocument(doc.lines[i]))
          << doc.name << ":" << i + 1 << ": cites DESIGN, a document outside the repository (cite docs/formats.md "
          << "or the file that states it): " << doc.lines[i];
    }
  }
}

// Calls f(doc, line number, span) for every code span of every document, fenced blocks left out.
template <typename F>
void ForEachSpan(const std::vector<Doc>& docs, F f) {
  for (const Doc& doc : docs) {
    bool fenced = false;
    for (size_t i = 0; i < doc.lines.size(); ++i) {
      const std::string& line = doc.lines[i];
      const size_t indent = line.find_first_not_of(' ');
      if (indent != std::string::npos && line.compare(indent, 3, "```") == 0) {
        fenced = !fenced;
        continue;
      }
      if (fenced) continue;
      for (const std::string& span : CodeSpans(line)) f(doc, i + 1, span);
    }
  }
}

bool IsIdentifier(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), IsWordChar);
}

// CamelCase of two humps or more (`EstimatorPipeline`, `GnssRecord`), or a constant (`kBlockSpecs`): a name
// only code has. One hump (`Update`, `IMU`) is as likely an English word or a log token.
bool LooksLikeTypeOrConstant(const std::string& s) {
  if (s.size() > 2 && s[0] == 'k' && std::isupper(static_cast<unsigned char>(s[1]))) return true;
  int humps = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    if (!std::isupper(static_cast<unsigned char>(s[i]))) continue;
    const bool followed = i + 1 < s.size() && std::isupper(static_cast<unsigned char>(s[i + 1])) == 0 &&
                          IsWordChar(s[i + 1]) && s[i + 1] != '_';
    if (!followed) return false;  // an upper-case run (`IMU`, `GNSS`) is no CamelCase
    ++humps;
  }
  return humps >= 2 && std::isupper(static_cast<unsigned char>(s[0]));
}

// The parts of a span that names a C++ symbol (`Eskf::Update`, `LogRecord::Type::kWheel`, `Smoother::Solve()`,
// `EstimatorPipeline`, `kBlockSpecs`), the namespaces of gins and its libraries left out; empty for any other span.
std::vector<std::string> SymbolParts(std::string s) {
  if (EndsWith(s, "()")) s.resize(s.size() - 2);
  std::vector<std::string> parts;
  for (size_t from = 0;;) {
    const size_t at = s.find("::", from);
    std::string part = s.substr(from, at == std::string::npos ? std::string::npos : at - from);
    if (!part.empty() && part[0] == '~') part.erase(0, 1);
    if (!IsIdentifier(part)) return {};
    parts.push_back(part);
    if (at == std::string::npos) break;
    from = at + 2;
  }
  if (parts.size() == 1 && !LooksLikeTypeOrConstant(parts[0])) return {};
  for (const char* ns : {"std", "ceres", "Eigen", "GeographicLib", "gins"}) {
    if (parts.size() > 1 && parts[0] == ns) parts.erase(parts.begin());
  }
  return parts;
}

// Every word of the code: the sources, tests, scripts and examples; not this file, whose strings name symbols
// that must not exist.
std::set<std::string> CodeWords() {
  std::set<std::string> words;
  std::vector<fs::path> files = {kSourceDir / "CMakeLists.txt"};
  for (const char* dir : {"core", "factors", "solver", "config", "apps", "tests", "scripts", "examples"}) {
    for (const auto& e : fs::recursive_directory_iterator(kSourceDir / dir)) {
      const std::string ext = e.path().extension().string();
      const bool code = ext == ".h" || ext == ".cc" || ext == ".py" || ext == ".in" || ext == ".sh";
      if (e.is_regular_file() && code && e.path().filename() != "docs_references_test.cc") {
        files.push_back(e.path());
      }
    }
  }
  for (const fs::path& f : files) {
    const std::string text = test::ReadFile(f.string());
    for (size_t i = 0; i < text.size();) {
      if (!IsWordChar(text[i])) {
        ++i;
        continue;
      }
      size_t j = i;
      while (j < text.size() && IsWordChar(text[j])) ++j;
      words.insert(text.substr(i, j - i));
      i = j;
    }
  }
  return words;
}

TEST(DocsReferences, EveryPathInBackticksExists) {
  int checked = 0;
  ForEachSpan(ReadDocs(), [&](const Doc& doc, size_t line, const std::string& span) {
    if (!LooksLikePath(span)) return;
    ++checked;
    const std::string why = CheckPath(span);
    EXPECT_TRUE(why.empty()) << doc.name << ":" << line << ": `" << span << "` " << why;
  });
  EXPECT_GT(checked, 100);  // the docs name well over a hundred files: the scan sees them
}

// A symbol the docs name in backticks is in the code: a renamed or removed one fails here, naming the line.
TEST(DocsReferences, EverySymbolInBackticksExists) {
  const std::set<std::string> words = CodeWords();
  int checked = 0;
  ForEachSpan(ReadDocs(), [&](const Doc& doc, size_t line, const std::string& span) {
    const std::vector<std::string> parts = SymbolParts(span);
    if (parts.empty()) return;
    ++checked;
    for (const std::string& part : parts) {
      EXPECT_TRUE(words.count(part) > 0) << doc.name << ":" << line << ": `" << span << "`: no " << part
                                         << " in the code";
    }
  });
  EXPECT_GT(checked, 50);  // the docs name many symbols: the scan sees them
}

TEST(DocsReferences, SymbolCheckTellsSymbolsFromWords) {
  EXPECT_EQ(SymbolParts("Eskf::Update"), (std::vector<std::string>{"Eskf", "Update"}));
  EXPECT_EQ(SymbolParts("LogRecord::Type::kWheel"), (std::vector<std::string>{"LogRecord", "Type", "kWheel"}));
  EXPECT_EQ(SymbolParts("Smoother::Solve()"), (std::vector<std::string>{"Smoother", "Solve"}));
  EXPECT_EQ(SymbolParts("std::variant"), (std::vector<std::string>{"variant"}));
  EXPECT_EQ(SymbolParts("EstimatorPipeline"), (std::vector<std::string>{"EstimatorPipeline"}));
  EXPECT_EQ(SymbolParts("kBlockSpecs"), (std::vector<std::string>{"kBlockSpecs"}));
  for (const char* not_symbol :
       {"Update", "IMU", "GNSS", "RTKLIB", "gins run", "core/io/log_reader.h", "a::", "3::4"}) {
    EXPECT_TRUE(SymbolParts(not_symbol).empty()) << not_symbol;
  }
  const std::set<std::string> words = CodeWords();
  EXPECT_EQ(words.count("EstimatorPipeline"), 1u);
  EXPECT_EQ(words.count("Inject"), 0u);  // the name a recipe once cited for a function that did not exist
}

TEST(DocsReferences, PathCheckTellsRepositoryPathsFromOthers) {
  EXPECT_TRUE(LooksLikePath("core/io/log_reader.h"));
  EXPECT_TRUE(LooksLikePath("tests/core/io/"));
  EXPECT_FALSE(LooksLikePath("config/default.yaml --mode both"));
  EXPECT_FALSE(LooksLikePath("core/<name>_model.h"));
  EXPECT_FALSE(LooksLikePath("out/sample/eval.json"));
  EXPECT_EQ(CheckPath("core/io/log_reader.h"), "");
  EXPECT_EQ(CheckPath("core/io/"), "");
  EXPECT_NE(CheckPath("core/io/no_such_reader.h"), "");
  EXPECT_NE(CheckPath("core/trajectory_metrics.h"), "");  // moved to core/eval/
  EXPECT_NE(CheckPath("core/no_such_folder/"), "");
  EXPECT_NE(CheckPath("core/io/log_reader.h/"), "");  // a file, not a directory
  EXPECT_NE(CheckPath("../shared/DESIGN.md"), "");
  EXPECT_EQ(CheckPath("P/include/gins/gins.h"), "");  // an install prefix: not a repository path
}

// The block of docs/formats.md that follows the marker comment containing `marker`.
std::string FormatsBlock(const std::string& marker) {
  const std::string text = test::ReadFile((kSourceDir / "docs/formats.md").string());
  const size_t at = text.find(marker);
  if (at == std::string::npos) return {};
  const size_t open = text.find("```text\n", at);
  const size_t close = text.find("\n```", open);
  if (open == std::string::npos || close == std::string::npos) return {};
  return text.substr(open + 8, close - open - 8 + 1);
}

TEST(DocsReferences, FormatsExampleLogReadsWithoutDamage) {
  const std::string block = FormatsBlock("read by tests/core/docs_references_test.cc with gins's log reader");
  ASSERT_FALSE(block.empty()) << "docs/formats.md §3.9: the example log or its marker is missing";
  const std::string path = test::MakeTempDir("docs_formats") + "/log.txt";
  test::WriteFile(path, block);
  InputOptions options;
  options.on_error = InputErrorPolicy::kStop;  // any damaged line throws, naming it
  LogReader reader(path, options);
  LogRecord r;
  std::vector<LogRecord> records;
  while (reader.Next(&r)) records.push_back(r);
  EXPECT_EQ(reader.stats().total_skipped(), 0u);
  EXPECT_EQ(CountOf<ImuSample>(reader.stats().records), 5u);
  EXPECT_EQ(CountOf<WheelRecord>(reader.stats().records), 2u);
  EXPECT_EQ(CountOf<GnssRecord>(reader.stats().records), 2u);
  EXPECT_EQ(CountOf<GnssVelocityRecord>(reader.stats().records), 1u);
  // §3.9: the first fix's heading with gnss.mount_yaw_deg 12.06 is a vehicle facing north-east (§2.4).
  const auto first_fix = std::find_if(records.begin(), records.end(),
                                      [](const LogRecord& x) { return x.is<GnssRecord>(); });
  ASSERT_NE(first_fix, records.end());
  ASSERT_TRUE(first_fix->get<GnssRecord>().heading_valid);
  EXPECT_NEAR(CompassDegToEnuYaw(first_fix->get<GnssRecord>().heading_deg + 12.06), 45.0 * kDegToRad, 1e-9);
  EXPECT_TRUE(first_fix->get<GnssRecord>().has_sigma);
}

TEST(DocsReferences, FormatsExampleTruthReadsAsDescribed) {
  const std::string block = FormatsBlock("read by tests/core/docs_references_test.cc with gins's truth reader");
  ASSERT_FALSE(block.empty()) << "docs/formats.md §4.3: the example truth or its marker is missing";
  const std::string path = test::MakeTempDir("docs_formats") + "/truth.csv";
  test::WriteFile(path, block);
  const LocalEnuFrame frame(GeodeticPoint{31.508183, 120.401989, 12.0});
  const std::vector<TruthSample> truth = ReadTruth(path, frame);
  ASSERT_EQ(truth.size(), 2u);
  // §4.3: the body's x axis points north-east, as in the example log.
  const Vec3 x_w = truth[0].q_wb * Vec3::UnitX();
  EXPECT_NEAR(x_w.x(), std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(x_w.y(), std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(truth[0].p_w.norm(), 0.0, 1e-6);
}

}  // namespace
}  // namespace gins
