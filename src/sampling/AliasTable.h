// Walker/Vose alias table: O(1) discrete sampling, the alternative to binary search.
#pragma once

#include <vector>

#include "core/Common.h"

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

  // Picks a bin: u1 chooses the column, u2 decides between it and its alias, so each
  // decision keeps a float's full precision even for millions of bins. *u2Remapped is u2
  // stretched back to a fresh uniform number.
  ENVGI_HD int sample(float u1, float u2, float* pmfOut, float* u2Remapped) const {
    float scaled = u1 * float(n);
    int i = scaled < float(n) ? int(scaled) : n - 1;
    const AliasBin b = bins[i];
    int chosen;
    float remap, pmf;
    if (u2 < b.prob) {
      chosen = i;
      remap = u2 / b.prob;
      pmf = b.pmf;
    } else {
      chosen = b.alias;
      remap = (u2 - b.prob) / (1.f - b.prob);
      pmf = bins[chosen].pmf;
    }
    if (pmfOut) *pmfOut = pmf;
    if (u2Remapped) *u2Remapped = remap < kOneMinusEpsilon ? remap : kOneMinusEpsilon;
    return chosen;
  }
};

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
