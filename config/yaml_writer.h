// The visitor of config/config_keys.h that writes the options as YAML in the users' units (OptionsToYaml).
// Numbers are written with the fewest digits that load back to the identical double. Internal to config/.
#pragma once

#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "config/key_spec.h"
#include "config/options.h"

namespace gins::config_internal {

// The shortest decimal text whose value, converted by unit.to_si, is exactly `si` (see yaml_writer.cc).
std::string FormatNumber(double si, const Unit& unit = kNoUnit);

class YamlWriter {
 public:
  // A block writer writes "section:\n  key: value\n" lines; a flow writer (an item of a list) writes
  // "key: value, key: value" for the caller to wrap in braces.
  enum class Style { kBlock, kFlow };
  explicit YamlWriter(Style style = Style::kBlock) : style_(style) {}

  void Comment(const std::string& line) { os_ << line << "\n"; }
  std::string str() const { return os_.str(); }

  void Number(const char* key, double value, const Unit& unit, const Check& /*check*/,
              Presence /*presence*/ = Presence::kOptional) {
    Put(key, FormatNumber(value, unit));
  }
  template <class Int>
  void Integer(const char* key, Int value, long long /*min*/, long long /*max*/ = 0) {
    Put(key, std::to_string(value));
  }
  void NumberOrWord(const char* key, double value, bool is_word, const char* word, const Unit& unit,
                    const Check& /*check*/) {
    Put(key, is_word ? std::string(word) : FormatNumber(value, unit));
  }
  void Boolean(const char* key, bool value) { Put(key, value ? "true" : "false"); }
  void String(const char* key, const std::string& value);  // double-quoted, so any text reads back as it is

  template <class T>
  void Choice(const char* key, const T& value, const Choices<T>& choices) {
    for (const auto& [name, choice] : choices) {
      if (choice == value) return Put(key, name);
    }
    // Only a string set in code can be outside its list (enum and bool lists are complete): write it as is.
    if constexpr (std::is_same_v<T, std::string>) Put(key, value);
  }

  void Vector3(const char* key, const Vec3& v, const std::string& /*what*/, const Check& /*check*/);
  void Axes(const char* key, const Mat3& R);
  void Origin(const char* key, const std::optional<GeodeticPoint>& p);
  void Origin(const char* key, const GeodeticPoint& p);
  void Outages(const char* key, const std::vector<std::pair<double, double>>& outages);
  void PeriodicOutages(const char* key, const GnssOptions::PeriodicOutages& p);

  template <class T, class Keys>
  void Section(const char* key, T& section, Keys keys) {
    os_ << (os_.tellp() > 0 ? "\n" : "") << key << ":\n";
    keys(*this, section);
  }

  // Items one per line, in flow style: "  key:\n    - {k: v, ...}\n"; an empty list is "  key: []".
  template <class T, class Keys>
  void List(const char* key, const char* /*item_noun*/, std::vector<T>& items, Keys keys) {
    if (items.empty()) return Put(key, "[]");
    os_ << "  " << key << ":\n";
    for (T& item : items) {
      YamlWriter flow(Style::kFlow);
      keys(flow, item);
      os_ << "    - {" << flow.str() << "}\n";
    }
  }

 private:
  void Put(const char* key, const std::string& value);

  Style style_;
  bool first_ = true;  // no key written yet (flow style)
  std::ostringstream os_;
};

}  // namespace gins::config_internal
