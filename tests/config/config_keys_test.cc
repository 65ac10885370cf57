// config/default.yaml documents every key of the one declaration (config/config_keys.h, listed by
// ConfigKeys()) and no other.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "config/config_loader.h"

namespace gins {
namespace GINS_TEST_FILE {

std::string ReadDefaultYaml() {
  std::ifstream in(GINS_SOURCE_DIR "/config/default.yaml");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// One line of a config file as default.yaml writes it: sections at column 0, their keys indented by 2.
struct Line {
  enum class Kind { kBlank, kComment, kKey, kOther } kind = Kind::kOther;
  std::string text;
  std::string path;  // of a key: "section" or "section.key"
};

// A key line: up to two spaces, a name of [A-Za-z0-9_], a colon, then nothing or white space and a value.
// Hand-parsed: std::regex trips GCC 12's -Wmaybe-uninitialized in the sanitizer build (-O1 -Werror).
bool ParseKeyLine(const std::string& s, size_t* indent, std::string* name) {
  const size_t first = s.find_first_not_of(' ');
  if (first == std::string::npos || first > 2) return false;
  size_t end = first;
  while (end < s.size() && (std::isalnum(static_cast<unsigned char>(s[end])) != 0 || s[end] == '_')) ++end;
  if (end == first || end >= s.size() || s[end] != ':') return false;
  if (end + 1 < s.size() && std::isspace(static_cast<unsigned char>(s[end + 1])) == 0) return false;
  *indent = first;
  *name = s.substr(first, end - first);
  return true;
}

std::vector<Line> Classify(const std::string& text) {
  std::vector<Line> lines;
  std::istringstream in(text);
  std::string section;
  for (std::string s; std::getline(in, s);) {
    Line line;
    line.text = s;
    const size_t first = s.find_first_not_of(' ');
    size_t indent = 0;
    std::string name;
    if (first == std::string::npos) {
      line.kind = Line::Kind::kBlank;
    } else if (s[first] == '#') {
      line.kind = Line::Kind::kComment;
    } else if (ParseKeyLine(s, &indent, &name)) {
      line.kind = Line::Kind::kKey;
      if (indent == 0) section = name;
      line.path = indent == 0 ? section : section + "." + name;
    }
    lines.push_back(line);
  }
  return lines;
}

// Keys that default.yaml documents together with the key line above them, under one comment (e.g. "# Hz,
// sensor rates." over imu_rate_hz, gnss_rate_hz and wheel_rate_hz). Any other key needs a comment line
// directly above it: without this list, deleting the comment between two keys would go unnoticed.
const std::set<std::string> kSharesCommentAbove = {"simulate.gnss_rate_hz",
                                                   "simulate.wheel_rate_hz",
                                                   "simulate.acc_noise_m_s_sqrt_h",
                                                   "simulate.gyro_bias_rw_deg_h_sqrt_h",
                                                   "simulate.acc_bias_rw_m_s2_sqrt_h",
                                                   "simulate.acc_turn_on_bias_m_s2",
                                                   "simulate.mount_yaw_deg",
                                                   "simulate.pulses_per_rev"};

// The comment lines documenting key line i: those directly above it or, for a key that shares the comment
// of the key line above it, that key's.
std::string CommentAbove(const std::vector<Line>& lines, size_t i, const std::set<std::string>& shares_above) {
  if (i > 0 && lines[i - 1].kind == Line::Kind::kKey && shares_above.count(lines[i].path) != 0) {
    return CommentAbove(lines, i - 1, shares_above);
  }
  std::string comment;
  for (size_t j = i; j > 0 && lines[j - 1].kind == Line::Kind::kComment; --j) {
    comment = lines[j - 1].text + "\n" + comment;
  }
  return comment;
}

bool MentionsWord(const std::string& text, const std::string& word) {
  const auto is_word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
    const size_t end = at + word.size();
    if ((at == 0 || !is_word(text[at - 1])) && (end == text.size() || !is_word(text[end]))) return true;
  }
  return false;
}

// What keeps `text` (default.yaml) from documenting exactly the `declared` keys; empty when it does. Each
// declared key needs a key line with a comment above it (see kSharesCommentAbove), each key line must be
// declared, and the keys of a list's items ("simulate.segments[].duration_s") must be named in the comment
// above the list's key.
std::vector<std::string> Problems(const std::string& text, const std::vector<std::string>& declared,
                                  const std::set<std::string>& shares_above) {
  const std::vector<Line> lines = Classify(text);
  std::vector<std::string> problems;
  std::map<std::string, std::string> comments;  // key path -> the comment documenting it
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].kind != Line::Kind::kKey) continue;
    const std::string& path = lines[i].path;
    const std::string where = "line " + std::to_string(i + 1) + ": " + path;
    comments[path] = CommentAbove(lines, i, shares_above);
    if (std::find(declared.begin(), declared.end(), path) == declared.end()) {
      problems.push_back(where + " is not a declared key");
    }
    if (comments[path].empty()) problems.push_back(where + " has no comment above it");
  }
  for (const std::string& key : declared) {
    const size_t item = key.find("[].");
    if (item == std::string::npos) {
      if (comments.count(key) == 0) problems.push_back(key + " is not in the file");
      continue;
    }
    const std::string list = key.substr(0, item);
    if (!MentionsWord(comments[list], key.substr(item + 3))) {
      problems.push_back(key + " is not named in the comment above " + list);
    }
  }
  return problems;
}

std::string Join(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += x + "\n";
  return s;
}

TEST(ConfigKeysTest, DefaultYamlDocumentsEveryDeclaredKeyAndNoOther) {
  const std::vector<std::string> problems = Problems(ReadDefaultYaml(), ConfigKeys(), kSharesCommentAbove);
  EXPECT_TRUE(problems.empty()) << "config/default.yaml:\n" << Join(problems);
}

// The check above can fail: a key without a comment, a key nobody declared, a declared key missing from the
// file and a list item's key the list's comment does not name are each reported.
TEST(ConfigKeysTest, UndocumentedOrUndeclaredKeysAreFound) {
  const std::vector<std::string> declared = {"s",          "s.a",        "s.b", "s.c", "s.list",
                                             "s.list[].x", "s.list[].y", "t",   "t.z"};
  const std::set<std::string> shares_above = {"s.c"};
  const std::string good =
      "# section s\ns:\n  # a\n  a: 1\n  # b and c\n  b: 2\n  c: 3\n  # the list: items of {x, y}\n  list: []\n"
      "# t\nt:\n  # z\n  z: 0\n";
  EXPECT_TRUE(Problems(good, declared, shares_above).empty()) << Join(Problems(good, declared, shares_above));

  const auto expect_problem = [&](const std::string& text, const std::string& problem) {
    const std::vector<std::string> found = Problems(text, declared, shares_above);
    EXPECT_TRUE(std::find(found.begin(), found.end(), problem) != found.end())
        << "expected '" << problem << "' among:\n"
        << Join(found) << "for:\n"
        << text;
  };
  // `good` with its first `from` replaced by `to`.
  const auto edited = [&good](const std::string& from, const std::string& to) {
    std::string text = good;
    return text.replace(text.find(from), from.size(), to);
  };
  expect_problem(edited("  # a\n", ""), "line 3: s.a has no comment above it");        // a follows its section
  expect_problem(edited("  # b and c\n", ""), "line 5: s.b has no comment above it");  // not a's to share
  const std::string colour = edited("  c: 3\n", "  c: 3\n\n  colour: blue\n");
  expect_problem(colour, "line 9: s.colour is not a declared key");
  expect_problem(colour, "line 9: s.colour has no comment above it");
  expect_problem(edited("  c: 3\n", "  c: 3\n  colour: blue\n"), "line 8: s.colour has no comment above it");
  expect_problem(edited("  z: 0\n", ""), "t.z is not in the file");
  expect_problem(edited("x, y", "x, yy"), "s.list[].y is not named in the comment above s.list");
}

// The same on default.yaml itself: deleting the comment above any of its keys is noticed.
TEST(ConfigKeysTest, DeletingAnyCommentOfDefaultYamlIsNoticed) {
  const std::vector<Line> lines = Classify(ReadDefaultYaml());
  const std::vector<std::string> keys = ConfigKeys();
  int tried = 0;
  for (size_t i = 1; i < lines.size(); ++i) {
    if (lines[i].kind != Line::Kind::kKey || lines[i - 1].kind != Line::Kind::kComment) continue;
    size_t first = i - 1;
    while (first > 0 && lines[first - 1].kind == Line::Kind::kComment) --first;
    std::string text;
    for (size_t j = 0; j < lines.size(); ++j) {
      if (j < first || j >= i) text += lines[j].text + "\n";
    }
    const std::vector<std::string> problems = Problems(text, keys, kSharesCommentAbove);
    const std::string expected = ": " + lines[i].path + " has no comment above it";
    EXPECT_TRUE(std::any_of(problems.begin(), problems.end(),
                            [&](const std::string& p) { return p.find(expected) != std::string::npos; }))
        << "deleting the comment above " << lines[i].path << " gave:\n"
        << Join(problems);
    ++tried;
  }
  EXPECT_GT(tried, 90);  // every key line but those sharing a comment
}

// The lister and the writer walk the same declaration: the writer writes exactly the listed keys (list items
// aside), in the listed order.
TEST(ConfigKeysTest, WriterWritesTheListedKeysInOrder) {
  std::vector<std::string> listed;
  for (const std::string& key : ConfigKeys()) {
    if (key.find("[]") == std::string::npos) listed.push_back(key);
  }
  std::vector<std::string> written;
  for (const auto& section : YAML::Load(OptionsToYaml(Options()))) {
    const std::string name = section.first.Scalar();
    written.push_back(name);
    for (const auto& kv : section.second) written.push_back(name + "." + kv.first.Scalar());
  }
  EXPECT_EQ(listed, written);
  EXPECT_EQ(std::set<std::string>(listed.begin(), listed.end()).size(), listed.size()) << "a key declared twice";
}

TEST(ConfigKeysTest, ListsSectionsKeysAndListItemKeys) {
  const std::vector<std::string> keys = ConfigKeys();
  for (const char* key : {"input", "imu.axes", "gnss.periodic_outages_s", "smoother.linear_solver", "simulate",
                          "simulate.segments", "simulate.segments[].duration_s", "simulate.segments[].grade_deg"}) {
    EXPECT_NE(std::find(keys.begin(), keys.end(), key), keys.end()) << key;
  }
  EXPECT_EQ(keys.front(), "input");
}

}  // namespace
}  // namespace gins
