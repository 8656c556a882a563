// A progress bar on stderr for long work: redrawn in place on a terminal, every 10% in a log.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>

namespace envgi {

class Progress {
 public:
  Progress(size_t total, bool enabled);
  void add(size_t n);

 private:
  size_t total_;
  bool enabled_, tty_;
  std::chrono::steady_clock::time_point start_;
  std::atomic<size_t> done_{0};
  std::mutex m_;
  double lastPrint_ = -1.0;
  int lastPct_ = -100;
};

}  // namespace envgi
