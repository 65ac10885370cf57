// A bounded single-producer, single-consumer pipe to a background thread, in batches.
//
// Why: at IMU rate, formatting and writing the output files costs as much as the ESKF itself; on two cores
// a second thread does it while the estimator runs. Items are handed over in batches (one lock per batch,
// not per item) and at most `max_batches` are in flight, so memory is bounded (batch_size × max_batches
// items) however long the log: a producer that outruns the consumer waits.
//
// The consumer runs on the pipe's thread, in push order. An exception it throws stops the consumption
// (later items are dropped) and is rethrown by Close(). Close() waits for everything pushed before it; the
// destructor closes too but swallows the exception (call Close() to see it).
#pragma once

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
class BatchPipe {
 public:
  explicit BatchPipe(std::function<void(const T&)> consume, size_t batch_size = 1024, size_t max_batches = 4)
      : consume_(std::move(consume)), batch_size_(batch_size > 0 ? batch_size : 1),
        max_batches_(max_batches > 0 ? max_batches : 1) {
    current_.reserve(batch_size_);
    thread_ = std::thread([this] { Run(); });
  }
  BatchPipe(const BatchPipe&) = delete;
  BatchPipe& operator=(const BatchPipe&) = delete;
  ~BatchPipe() {
    try {
      Close();
    } catch (...) {  // Close() is where a caller sees it
    }
  }

  void Push(T item) {
    current_.push_back(std::move(item));
    if (current_.size() >= batch_size_) Hand();
  }

  // Waits until every pushed item is consumed and stops the thread; rethrows the consumer's exception.
  // Idempotent.
  void Close() {
    if (thread_.joinable()) {
      if (!current_.empty()) Hand();
      {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
      }
      ready_.notify_one();
      thread_.join();
    }
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }

 private:
  void Hand() {
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [this] { return queue_.size() < max_batches_; });
    queue_.push_back(std::move(current_));
    lock.unlock();
    ready_.notify_one();
    current_ = std::vector<T>();
    current_.reserve(batch_size_);
  }

  void Run() {
    for (;;) {
      std::vector<T> batch;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [this] { return !queue_.empty() || closed_; });
        if (queue_.empty()) return;  // closed and drained
        batch = std::move(queue_.front());
        queue_.pop_front();
      }
      space_.notify_one();
      if (error_) continue;  // keep draining so the producer never blocks forever
      try {
        for (const T& item : batch) consume_(item);
      } catch (...) {
        error_ = std::current_exception();  // read by Close() after the join
      }
    }
  }

  std::function<void(const T&)> consume_;
  const size_t batch_size_, max_batches_;
  std::vector<T> current_;  // producer side only
  std::mutex mutex_;
  std::condition_variable ready_, space_;
  std::deque<std::vector<T>> queue_;
  bool closed_ = false;
  std::exception_ptr error_;  // consumer side until the join
  std::thread thread_;
};

}  // namespace gins
