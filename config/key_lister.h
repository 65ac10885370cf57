// The visitor of config/config_keys.h that lists key paths, in declaration order: sections ("imu"), their
// keys ("imu.axes") and the keys of a list's items ("simulate.segments[].duration_s"). Gives ConfigKeys()
// and the reader's description of a list's items. Internal to config/.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace gins::config_internal {

class KeyLister {
 public:
  explicit KeyLister(std::string prefix = "") : prefix_(std::move(prefix)) {}

  const std::vector<std::string>& keys() const { return keys_; }

  // Only the key matters here; the other arguments (value, unit, check, ...) are the reader's and writer's.
  template <class... Rest>
  void Number(const char* key, Rest&&...) {
    Add(key);
  }
  template <class... Rest>
  void NumberOrWord(const char* key, Rest&&...) {
    Add(key);
  }
  template <class... Rest>
  void Integer(const char* key, Rest&&...) {
    Add(key);
  }
  template <class... Rest>
  void Boolean(const char* key, Rest&&...) {
    Add(key);
  }
  template <class... Rest>
  void String(const char* key, Rest&&...) {
    Add(key);
  }
  template <class... Rest>
  void Choice(const char* key, Rest&&...) {
    Add(key);
  }
  template <class... Rest>
  void Vector3(const char* key, Rest&&...) {
    Add(key);
  }
  template <class... Rest>
  void Axes(const char* key, Rest&&...) {
    Add(key);
  }
  template <class... Rest>
  void Origin(const char* key, Rest&&...) {
    Add(key);
  }
  template <class... Rest>
  void Outages(const char* key, Rest&&...) {
    Add(key);
  }
  template <class... Rest>
  void PeriodicOutages(const char* key, Rest&&...) {
    Add(key);
  }

  template <class T, class Visit>
  void Section(const char* key, T& section, Visit visit) {
    Add(key);
    Nested(prefix_ + key + ".", section, visit);
  }

  template <class T, class Visit>
  void List(const char* key, const char* /*item_noun*/, std::vector<T>& /*items*/, Visit visit) {
    Add(key);
    T item;
    Nested(prefix_ + key + "[].", item, visit);
  }

 private:
  void Add(const char* key) { keys_.push_back(prefix_ + key); }

  template <class T, class Visit>
  void Nested(std::string prefix, T& value, Visit visit) {
    KeyLister sub(std::move(prefix));
    visit(sub, value);
    keys_.insert(keys_.end(), sub.keys_.begin(), sub.keys_.end());
  }

  std::string prefix_;
  std::vector<std::string> keys_;
};

}  // namespace gins::config_internal
