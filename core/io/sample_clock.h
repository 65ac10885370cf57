// Time-stamp regularisation of a periodic sensor stream (input.regularize_stamps): a logger that stamps each
// record when its thread gets to it adds tens of milliseconds of jitter to a sensor that samples on its own
// clock. Integrated over their stamped intervals, such samples put the state tens of centimetres along the
// track from where it was at a fix's time; stamped on the sensor's own regular grid, they do not.
//
// Records in arrival order (a log's line order, not sorted). Over the last kWindow stamps of a run (a run
// ends at a gap longer than max_gap, or a stamp that goes back by more), the jitter is the mean absolute
// second difference of the stamps (a running sum): zero for a regular stream; a rate change is one kink and
// a lost sample two, each a period's fraction over the window. Above a tenth of the period the stream is
// regularised: each stamp becomes the least-squares line's through the window at its index (fitted every
// kFitEvery records, causal: the line ends at the newest sample), kept increasing and within kMaxCorrection
// of the raw stamp. Below a twentieth, stamps pass unchanged (bit for bit). ±20 ms of uniform jitter at
// 100 Hz: 11.5 ms RMS -> about 2 ms (the test).
#pragma once

#include <cstdint>
#include <deque>

namespace gins {

class SampleClock {
 public:
  static constexpr int kWindow = 128;           // stamps in the fit
  static constexpr int kMinSamples = 16;        // before any judgement
  static constexpr double kMaxCorrection = 0.1; // s: beyond this, the raw stamp (and a new run)
  static constexpr int kFitEvery = 8;           // records between two fits of the line

  explicit SampleClock(double max_gap) : max_gap_(max_gap) {}

  // The stamp to use for the next record, stamped t.
  double Stamp(double t);

  uint64_t regularized() const { return regularized_; }  // records given a stamp other than their own
  double max_correction() const { return max_correction_; }

 private:
  void Reset();
  void Fit();  // slope_ and fit_end_ from the window
  double max_gap_;
  std::deque<double> raw_;
  std::deque<double> d2_;  // |second differences| of raw_
  double sum_d2_ = 0.0;
  bool active_ = false;
  int since_fit_ = kFitEvery;
  double slope_ = 0.0, fit_end_ = 0.0;
  bool have_out_ = false;
  double last_out_ = 0.0;
  uint64_t regularized_ = 0;
  double max_correction_ = 0.0;
};

}  // namespace gins
