// A bounded single-producer, single-consumer read-ahead: a background thread calls `produce` and hands the
// items over in batches; the caller takes them with Next() in the same order.
//
// Why: reading and parsing a log at IMU rate costs a fifth of the ESKF's run; on two cores it runs beside
// the estimator. At most `max_batches` full batches wait, so memory is bounded however long the log.
//
// An exception `produce` throws is rethrown by Next() at its place in the stream: after every item produced
// before it, exactly where a direct call would have thrown. The destructor stops the producer (before its
// next item) and joins, so a consumer that gives up early never waits for the rest of the log.
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace gins {

template <typename T>
class ReadAhead {
 public:
  // produce(&item) fills item and returns true, or returns false at the end of the stream.
  explicit ReadAhead(std::function<bool(T*)> produce, size_t batch_size = 256, size_t max_batches = 4)
      : produce_(std::move(produce)), batch_size_(batch_size > 0 ? batch_size : 1),
        max_batches_(max_batches > 0 ? max_batches : 1) {
    thread_ = std::thread([this] { Run(); });
  }
  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;
  ~ReadAhead() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    space_.notify_one();
    thread_.join();
  }

  // The next item (true), or the end of the stream (false); rethrows the producer's exception in its place.
  bool Next(T* item) {
    while (pos_ == batch_.size()) {
      std::unique_lock<std::mutex> lock(mutex_);
      ready_.wait(lock, [this] { return !queue_.empty() || finished_; });
      if (queue_.empty()) {
        if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
        return false;
      }
      batch_ = std::move(queue_.front());
      queue_.pop_front();
      pos_ = 0;
      lock.unlock();
      space_.notify_one();
    }
    *item = std::move(batch_[pos_++]);
    return true;
  }

 private:
  void Run() {
    std::vector<T> batch;
    std::exception_ptr error;
    try {
      for (;;) {
        batch.reserve(batch_size_);
        T item;
        bool more = true;
        while (batch.size() < batch_size_ && !stop_.load(std::memory_order_relaxed) && (more = produce_(&item))) {
          batch.push_back(std::move(item));
        }
        if (stop_.load() || (!batch.empty() && !Hand(&batch))) return;  // the consumer is gone
        if (!more) break;
      }
    } catch (...) {
      error = std::current_exception();
      if (!batch.empty() && !Hand(&batch)) return;  // what came before the error goes first
    }
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = error;
    finished_ = true;
    ready_.notify_one();
  }

  // Queues the batch (waiting for room); false when the consumer is gone.
  bool Hand(std::vector<T>* batch) {
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [this] { return queue_.size() < max_batches_ || stop_; });
    if (stop_) return false;
    queue_.push_back(std::move(*batch));
    batch->clear();
    lock.unlock();
    ready_.notify_one();
    return true;
  }

  std::function<bool(T*)> produce_;
  const size_t batch_size_, max_batches_;
  std::vector<T> batch_;  // consumer side: the batch being read, from pos_
  size_t pos_ = 0;
  std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<std::vector<T>> queue_;
  bool finished_ = false;     // the producer is done (end of stream or error)
  std::atomic<bool> stop_{false};  // the consumer is gone
  std::exception_ptr error_;  // the producer's, handed over with finished_
  std::thread thread_;        // last: starts once the members above exist
};

}  // namespace gins
