#include "render/Progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace envgi {

Progress::Progress(size_t total, bool enabled, double timeLimit, std::atomic<float>* fraction)
    : total_(total > 0 ? total : 1),
      enabled_(enabled),
      tty_(::isatty(2)),
      timeLimit_(timeLimit),
      start_(std::chrono::steady_clock::now()),
      fraction_(fraction) {
  if (fraction_) fraction_->store(0.f, std::memory_order_relaxed);
}

void Progress::add(size_t n) {
  if (!enabled_ && !fraction_) return;
  size_t done = done_.fetch_add(n) + n;
  std::lock_guard<std::mutex> lock(m_);
  store(done);
  if (enabled_) draw(done);
}

// Under m_.
void Progress::store(size_t done) {
  if (fraction_) fraction_->store(float(std::min(1.0, double(done) / double(total_))), std::memory_order_relaxed);
}

// Under m_.
void Progress::draw(size_t done) {
  double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  double fraction = double(done) / double(total_);
  if (timeLimit_ > 0.0) fraction = std::max(fraction, std::min(1.0, t / timeLimit_));
  int pct = int(100.0 * std::min(1.0, fraction));
  if (tty_ ? (t - lastPrint_ < 0.2 && done < total_) : (pct < lastPct_ + 10 && done < total_)) return;
  if (!tty_ && pct == lastPct_) return;  // the end already drawn
  lastPrint_ = t;
  lastPct_ = pct;
  double eta = done > 0 && done < total_ ? t * double(total_ - done) / double(done) : 0.0;
  if (timeLimit_ > 0.0) eta = std::min(eta, std::max(0.0, timeLimit_ - t));
  int bar = pct / 4;
  std::fprintf(stderr, "%s[%.*s%*s] %3d%%  %.1fs elapsed, %.1fs left%s", tty_ ? "\r" : "", bar,
               "=========================", 25 - bar, "", pct, t, eta, tty_ ? "" : "\n");
  open_ = tty_ && done < total_;
  if (tty_ && done >= total_) std::fprintf(stderr, "\n");
}

void Progress::shrinkTotal(size_t n) {
  std::lock_guard<std::mutex> lock(m_);
  size_t done = done_.load();
  total_ = std::max<size_t>({total_ > n ? total_ - n : 0, done, 1});
  store(done);
  if (enabled_ && n > 0) draw(done);  // the bar jumps forward; at the end, its last line
}

void Progress::finish() {
  std::lock_guard<std::mutex> lock(m_);
  if (open_) std::fprintf(stderr, "\n");
  open_ = false;
}

}  // namespace envgi
