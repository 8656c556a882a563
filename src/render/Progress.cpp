#include "render/Progress.h"

#include <unistd.h>

#include <cstdio>

namespace envgi {

Progress::Progress(size_t total, bool enabled)
    : total_(total > 0 ? total : 1), enabled_(enabled), tty_(::isatty(2)), start_(std::chrono::steady_clock::now()) {}

void Progress::add(size_t n) {
  if (!enabled_) return;
  size_t done = done_.fetch_add(n) + n;
  std::lock_guard<std::mutex> lock(m_);
  double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  int pct = int(100.0 * double(done) / double(total_));
  if (tty_ ? (t - lastPrint_ < 0.2 && done < total_) : (pct < lastPct_ + 10 && done < total_)) return;
  lastPrint_ = t;
  lastPct_ = pct;
  double eta = done > 0 ? t * double(total_ - done) / double(done) : 0.0;
  int bar = pct / 4;
  std::fprintf(stderr, "%s[%.*s%*s] %3d%%  %.1fs elapsed, %.1fs left%s", tty_ ? "\r" : "", bar,
               "=========================", 25 - bar, "", pct, t, eta, tty_ ? "" : "\n");
  if (tty_ && done >= total_) std::fprintf(stderr, "\n");
}

}  // namespace envgi
