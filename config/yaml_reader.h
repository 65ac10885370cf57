// The visitor of config/config_keys.h that reads a parsed YAML file into the options: it checks each
// declared key's type and range, converts the user's unit to SI, and rejects what the file has beyond the
// declared keys. Errors are ConfigErrors of the form "<file>: <key.path>: <reason> (line N)" (see
// config/config_loader.h). Internal to config/.
#pragma once

#include <yaml-cpp/yaml.h>

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "config/key_lister.h"
#include "config/key_spec.h"
#include "config/options.h"

namespace gins::config_internal {

// Error messages stay one line whatever the file holds: control bytes (a key with "\n" in it, or yaml-cpp's
// "unknown escape character" quoting the raw character) are written as \xNN. (Found by tests/fuzz.)
std::string OneLine(const std::string& message);

// What a node holds, for messages: "'abc'", "a list of 2", "a mapping", "nothing (null)".
std::string Describe(const YAML::Node& n);

// The file being read, for messages.
class Context {
 public:
  explicit Context(std::string file) : file_(std::move(file)) {}

  // Throws ConfigError("<file>: <path>: <reason> (line N)").
  [[noreturn]] void Fail(const std::string& path, const std::string& reason, const YAML::Mark& mark) const;

 private:
  std::string file_;
};

// One YAML mapping: the whole file, a section, or an item of a list of mappings. Each visitor method looks
// its key up, which records the key as known; Finish() then rejects whatever the mapping has beyond them.
class YamlReader {
 public:
  // `node` undefined or null is an empty mapping (all defaults). `path` is the mapping's key path for
  // messages ("" at the top level); `item_noun` names an item of a list ("segment").
  YamlReader(const Context& ctx, const YAML::Node& node, std::string path, std::string item_noun = "");

  void Number(const char* key, double& out, const Unit& unit, const Check& check,
              Presence presence = Presence::kOptional);

  template <class Int>
  void Integer(const char* key, Int& out, long long min, long long max = std::numeric_limits<int>::max()) {
    if (const YAML::Node* n = Find(key)) out = static_cast<Int>(ReadInteger(*n, Path(key), min, max));
  }

  // A number, or the one word `word` (is_word set, out untouched), e.g. `time_offset_s: estimate`.
  void NumberOrWord(const char* key, double& out, bool& is_word, const char* word, const Unit& unit,
                    const Check& check);

  void Boolean(const char* key, bool& out);
  void String(const char* key, std::string& out);  // a scalar taken as it is; null: empty

  template <class T>
  void Choice(const char* key, T& out, const Choices<T>& choices) {
    std::vector<std::string> names;
    for (const auto& choice : choices) names.push_back(choice.first);
    const int index = ChoiceIndex(key, names);
    if (index >= 0) out = choices[index].second;
  }

  // `what` names the elements for messages, e.g. "[east, north, up]".
  void Vector3(const char* key, Vec3& out, const std::string& what, const Check& check);
  void Axes(const char* key, Mat3& out);
  void Origin(const char* key, std::optional<GeodeticPoint>& out);  // null allowed
  void Origin(const char* key, GeodeticPoint& out);
  void Outages(const char* key, std::vector<std::pair<double, double>>& out);
  void PeriodicOutages(const char* key, GnssOptions::PeriodicOutages& out);

  template <class T, class Keys>
  void Section(const char* key, T& section, Keys keys) {
    const YAML::Node* n = Find(key);
    YamlReader reader(ctx_, n != nullptr ? *n : YAML::Node(), Path(key));
    keys(reader, section);
    reader.Finish();
  }

  // A list of mappings (null = none); each item starts from a default T.
  template <class T, class Keys>
  void List(const char* key, const char* item_noun, std::vector<T>& out, Keys keys) {
    const YAML::Node* n = Find(key);
    if (n == nullptr) return;
    std::vector<T> items;
    if (!n->IsNull()) {
      KeyLister lister;  // the item's keys, for messages
      T probe;
      keys(lister, probe);
      const std::vector<std::string>& names = lister.keys();
      if (!n->IsSequence()) Fail(key, "expected a list of {" + Join(names) + "}, got " + Describe(*n), *n);
      for (size_t i = 0; i < n->size(); ++i) {
        const YAML::Node item = (*n)[i];
        const std::string item_path = Path(key) + "[" + std::to_string(i) + "]";
        if (!item.IsMap()) {
          ctx_.Fail(item_path, "expected a mapping {" + names.front() + ", ...}, got " + Describe(item), item.Mark());
        }
        YamlReader reader(ctx_, item, item_path, item_noun);
        T value;
        keys(reader, value);
        reader.Finish();
        items.push_back(value);
      }
    }
    out = std::move(items);
  }

  // Rejects keys no visitor method asked for, in file order.
  void Finish() const;

 private:
  std::string Path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  [[noreturn]] void Fail(const char* key, const std::string& reason, const YAML::Node& n) const {
    ctx_.Fail(Path(key), reason, n.Mark());
  }
  static std::string Join(const std::vector<std::string>& names);

  // The value of `key`, or nullptr when the file does not set it. Records `key` as known.
  const YAML::Node* Find(const std::string& key);
  // The index of the key's value in `names`, or -1 when the file does not set it.
  int ChoiceIndex(const char* key, const std::vector<std::string>& names);

  double ReadNumber(const YAML::Node& n, const std::string& path, const Unit& unit, const Check& check) const;
  long long ReadInteger(const YAML::Node& n, const std::string& path, long long min, long long max) const;
  Vec3 ReadVec3(const YAML::Node& n, const std::string& path, const std::string& what, const Check& check) const;
  std::optional<GeodeticPoint> ReadOrigin(const YAML::Node& n, const std::string& path, bool allow_null) const;

  const Context& ctx_;
  std::string path_;
  std::string item_noun_;
  YAML::Mark mark_ = YAML::Mark::null_mark();  // of the mapping itself
  std::map<std::string, YAML::Node> values_;
  std::vector<std::pair<std::string, YAML::Mark>> order_;
  std::vector<std::string> known_;
};

}  // namespace gins::config_internal
