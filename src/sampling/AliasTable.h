// Walker/Vose alias table: O(1) discrete sampling, the alternative to binary search.
#pragma once

#include <cmath>
#include <vector>

#include "core/Vec.h"

namespace envgi {

// One bin: its acceptance probability, its alias, and its own probability, side by side so a
// draw that keeps its bin reads a single cache line.
struct AliasBin {
  float prob;
  int alias;
  float pmf;
};

struct AliasTableView {
  const AliasBin* bins = nullptr;
  int n = 0;

  ENVGI_HD float pmf(int i) const { return bins[i].pmf; }

  // The column sample() reads first (its bin, the one miss a draw from a large table is sure to
  // take), and the rest of u's 48 bits within it.
  ENVGI_HD int column(Vec2f u, uint64_t* rem = nullptr) const {
    const uint64_t k24 = uint64_t(1) << 24, mask24 = k24 - 1;
    uint64_t hi = uint64_t(u.x * float(k24)) & mask24, lo = uint64_t(u.y * float(k24)) & mask24;
    // (hi 2^24 + lo) n / 2^48 without 128-bit arithmetic: both products fit in 55 bits.
    uint64_t a = hi * uint64_t(n), b = lo * uint64_t(n);
    uint64_t a2 = a + (b >> 24);
    uint64_t i64 = a2 >> 24;
    if (rem) *rem = ((a2 & mask24) << 24) | (b & mask24);
    return i64 < uint64_t(n) ? int(i64) : n - 1;
  }

  // Picks a bin from both coordinates of u, read as one 48-bit number (samplers give 24-bit
  // floats): its top part times n chooses the column, so every column is chosen with its exact
  // probability to 2^-48 however many there are (u.x alone would pick 2^24 columns at most, some
  // of them 8 and some 9 times in 2^24); the rest decides between the column and its alias and
  // is then stretched back to a uniform number, *rest, with the bits the choice left over
  // (48 - log2 n, less a few for the coin).
  ENVGI_HD int sample(Vec2f u, float* pmfOut, float* rest) const {
    uint64_t rem;  // uniform in [0, 2^48) within the column
    int i = column(u, &rem);
    const double k48 = 281474976710656.0;  // 2^48
    const AliasBin bin = bins[i];
    double t = double(bin.prob) * k48, r = double(rem);
    int chosen;
    double remap;
    if (r < t) {
      chosen = i;
      remap = r / t;
    } else {
      chosen = bin.alias;
      remap = (r - t) / (k48 - t);
    }
    if (pmfOut) *pmfOut = bins[chosen].pmf;
    if (rest) {
      float f = float(remap);
      *rest = f < kOneMinusEpsilon ? f : kOneMinusEpsilon;
    }
    return chosen;
  }
};

// A choice's leftover number (AliasTableView::sample's *rest) as a point of the unit square,
// for the place inside what was chosen: 12 bits across, 11 down, each centred in its step so
// that float rounding never carries the point over the square's edge.
ENVGI_INLINE Vec2f splitLeftover(float r) {
  const float a = std::floor(r * 4096.f), rest = r * 4096.f - a;
  return {(a + 0.5f) * (1.f / 4096.f), (std::floor(rest * 2048.f) + 0.5f) * (1.f / 2048.f)};
}

class AliasTable {
 public:
  AliasTable() = default;
  // Weights need not be normalised; all-zero weights give the uniform distribution.
  AliasTable(const float* weights, size_t n);
  AliasTableView view() const { return {bins_.data(), int(bins_.size())}; }
  size_t bytes() const { return bins_.size() * sizeof(AliasBin); }

 private:
  std::vector<AliasBin> bins_;
};

}  // namespace envgi
