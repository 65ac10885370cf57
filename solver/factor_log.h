// What the window built, kept for the whole-log smoother (--mode batch, solver/batch_smoother.h): every
// factor the window added (the cost function itself, shared, not the window's first-estimate wrapper),
// its robust loss and blocks, and every keyframe once it left the window. Recording is off unless a
// KeyframeStore is given a log; the window's own behaviour does not depend on it.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <cstddef>
#include <limits>
#include <map>
#include <memory>
#include <vector>

#include "solver/keyframe.h"

namespace gins {

struct LoggedFactor {
  std::shared_ptr<ceres::CostFunction> cost;
  const ceres::LossFunction* loss = nullptr;  // an attacher's: alive as long as the smoother
  std::vector<BlockRef> blocks;               // keyframes the log keeps alive
  bool active = true;  // used: false when the window replaced it (a re-integrated IMU factor) or rejected it
  // A measurement whose acceptance the whole-log smoother checks again on its two-sided solution: the χ²
  // gate it was checked with (+∞: not revisited). Rejected ones are logged inactive.
  double gate = std::numeric_limits<double>::infinity();
  bool revisitable() const { return gate < std::numeric_limits<double>::infinity(); }
};

class FactorLog {
 public:
  size_t Add(LoggedFactor f) {
    factors_.push_back(std::move(f));
    return factors_.size() - 1;
  }
  void Deactivate(size_t i) { factors_.at(i).active = false; }
  void SetActive(size_t i, bool active) { factors_.at(i).active = active; }
  void SetGate(size_t i, double gate) { factors_.at(i).gate = gate; }
  // The same factor on the same blocks, another cost (an IMU factor integrated again).
  void Replace(size_t i, std::shared_ptr<ceres::CostFunction> cost) { factors_.at(i).cost = std::move(cost); }
  // A keyframe that left the window (in time order). Its blocks keep the window's final estimate.
  void Keep(std::unique_ptr<Keyframe> kf) { keyframes_.push_back(std::move(kf)); }
  // The IMU steps after the last keyframe of a chain (the window was rebuilt, or the log ended there).
  void SetTail(const Keyframe* kf, std::vector<HeldImuSample> steps) { tails_[kf] = std::move(steps); }

  const std::vector<LoggedFactor>& factors() const { return factors_; }
  const std::vector<std::unique_ptr<Keyframe>>& keyframes() const { return keyframes_; }
  const std::vector<HeldImuSample>* TailOf(const Keyframe* kf) const {
    const auto it = tails_.find(kf);
    return it == tails_.end() ? nullptr : &it->second;
  }

 private:
  std::vector<LoggedFactor> factors_;
  std::vector<std::unique_ptr<Keyframe>> keyframes_;
  std::map<const Keyframe*, std::vector<HeldImuSample>> tails_;
};

}  // namespace gins
