// The API's reorder buffer (input.reorder_window_s): measurements that arrive older than the newest one by
// up to the window are held and handed on in time order; older ones are late. The log reader applies the
// same rule (core/io/log_reader.h), so a log's records are never late here: its out-of-window records are
// damage (out_of_order) there.
#pragma once

#include <cstdint>
#include <deque>
#include <iterator>
#include <utility>

#include "core/io/log_reader.h"

namespace gins::api {

class ReorderBuffer {
 public:
  explicit ReorderBuffer(double window) : window_(window) {}

  // Takes r (false if it is late: older than the newest by more than the window) and hands on, in time
  // order, every held record that no later arrival within the window can precede. Records with equal
  // times keep their arrival order. With window 0 an in-order record goes straight through.
  template <typename Release>
  bool Add(const LogRecord& r, Release&& release) {
    const double t = r.t();
    if (have_newest_ && t < newest_ - window_) return false;
    if (have_newest_ && t < newest_) {
      ++reordered_;
    } else {
      newest_ = t;
      have_newest_ = true;
    }
    const double due = newest_ - window_;
    if (held_.empty() && t <= due) {
      release(r);
      return true;
    }
    auto it = held_.end();
    while (it != held_.begin() && std::prev(it)->t() > t) --it;
    held_.insert(it, r);
    while (!held_.empty() && held_.front().t() <= due) Pop(release);
    return true;
  }

  // Hands on everything held (the end of the data).
  template <typename Release>
  void Flush(Release&& release) {
    while (!held_.empty()) Pop(release);
  }

  uint64_t reordered() const { return reordered_; }
  size_t held() const { return held_.size(); }
  double window() const { return window_; }

 private:
  template <typename Release>
  void Pop(Release& release) {
    const LogRecord r = std::move(held_.front());
    held_.pop_front();  // before release: a release that throws leaves the buffer consistent
    release(r);
  }

  const double window_;
  bool have_newest_ = false;
  double newest_ = 0.0;
  uint64_t reordered_ = 0;
  std::deque<LogRecord> held_;  // sorted by time, then arrival
};

}  // namespace gins::api
