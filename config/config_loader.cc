#include "config/config_loader.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "config/config_keys.h"
#include "config/key_lister.h"
#include "config/yaml_reader.h"
#include "config/yaml_writer.h"

namespace gins {
namespace {

using config_internal::Context;
using config_internal::kOptionsKeys;
using config_internal::OneLine;

// Listens to a YAML parser for where documents start (LoadOptionsFromString).
class DocumentStarts : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> marks;
  void OnDocumentStart(const YAML::Mark& mark) override { marks.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

// Parses the text's one document (syntax errors become ConfigErrors).
YAML::Node ParseDocument(const Context& ctx, const std::string& yaml, const std::string& name_for_errors) {
  YAML::Node root;
  DocumentStarts starts;
  try {
    // Not YAML::LoadAll: on a stray ',' at the top level (a file that is just ",") yaml-cpp 0.7's parser
    // stops advancing and LoadAll collects empty documents until memory runs out (found by
    // tests/fuzz/config_fuzzer). A listening parser counts at most three document starts instead (two at one
    // position: the parser is stuck), and YAML::Load reads the first document.
    std::istringstream in(yaml);
    YAML::Parser parser(in);
    for (int i = 0; i < 3 && parser.HandleNextDocument(starts); ++i) {
    }
    for (size_t i = 1; i < starts.marks.size(); ++i) {
      const YAML::Mark& m = starts.marks[i];
      if (m.pos == starts.marks[i - 1].pos) {
        throw ConfigError(OneLine(name_for_errors + ": YAML syntax error: unexpected text outside any mapping or " +
                                  "list (line " + std::to_string(m.line + 1) + ", column " +
                                  std::to_string(m.column + 1) + ")"));
      }
    }
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    std::string message = name_for_errors + ": YAML syntax error: " + e.msg;
    if (!e.mark.is_null()) {
      message += " (line " + std::to_string(e.mark.line + 1) + ", column " + std::to_string(e.mark.column + 1) + ")";
    }
    throw ConfigError(OneLine(message));
  }
  // A second document (after `---`) would otherwise be silently ignored.
  if (starts.marks.size() > 1) {
    ctx.Fail("(top level)", "more than one YAML document; put all sections in one", starts.marks[1]);
  }
  return root;
}

}  // namespace

Options LoadOptionsFromString(const std::string& yaml, const std::string& name_for_errors) {
  const Context ctx(name_for_errors);
  const YAML::Node root = ParseDocument(ctx, yaml, name_for_errors);
  try {
    Options o;
    config_internal::YamlReader top(ctx, root, "");
    kOptionsKeys(top, o);
    top.Finish();
    return o;
  } catch (const YAML::Exception& e) {
    // Our readers check types before converting, so this is a gap in them; still report it usefully.
    std::string message = name_for_errors + ": " + e.msg;
    if (!e.mark.is_null()) message += " (line " + std::to_string(e.mark.line + 1) + ")";
    throw ConfigError(OneLine(message));
  }
}

Options LoadOptions(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw ConfigError(path + ": is a directory, not a config file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ConfigError(path + ": read error");
  return LoadOptionsFromString(text.str(), path);
}

std::string OptionsToYaml(const Options& o) {
  config_internal::YamlWriter w;
  w.Comment("# gins effective options (keys, units and meanings: config/default.yaml)");
  Options copy = o;  // the key declarations take mutable options (the reader fills them)
  kOptionsKeys(w, copy);
  return w.str();
}

std::vector<std::string> ConfigKeys() {
  config_internal::KeyLister lister;
  Options o;
  kOptionsKeys(lister, o);
  return lister.keys();
}

}  // namespace gins
