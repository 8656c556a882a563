// A progress bar on stderr for long work: redrawn in place on a terminal, every 10% in a log.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>

namespace envgi {

class Progress {
 public:
  // timeLimit > 0: the work may stop then (render --time-limit), so the bar shows whichever of
  // the work and the time is further along, and the time left is at most the limit's.
  // fraction: where set, the share of the work done (0 to 1) is stored there at each step,
  // drawn or not (a caller's own display: the Python module's tqdm bar).
  Progress(size_t total, bool enabled, double timeLimit = 0.0, std::atomic<float>* fraction = nullptr);
  void add(size_t n);
  // Takes n from the work still to do (adaptive sampling: pixels that stopped early), never
  // below what is done.
  void shrinkTotal(size_t n);
  // Ends the bar's line when the work stopped short of the total (a time limit, Ctrl-C).
  void finish();

 private:
  void draw(size_t done);
  void store(size_t done);

  size_t total_;
  bool enabled_, tty_;
  double timeLimit_;
  bool open_ = false;  // a bar is drawn on a terminal line not yet ended
  std::chrono::steady_clock::time_point start_;
  std::atomic<size_t> done_{0};
  std::atomic<float>* fraction_;
  std::mutex m_;
  double lastPrint_ = -1.0;
  int lastPct_ = -100;
};

}  // namespace envgi
