// Walker/Vose alias table: O(1) discrete sampling, the alternative to binary search.
#pragma once

#include <vector>

#include "core/Common.h"

namespace envgi {

struct AliasTableView {
  const float* prob = nullptr;    // acceptance probability of bin i
  const int* alias = nullptr;     // bin taken when bin i rejects
  const float* pmf = nullptr;     // normalised weights
  int n = 0;

  // Picks a bin: u1 chooses the column, u2 decides between it and its alias, so each
  // decision keeps a float's full precision even for millions of bins. *u2Remapped is u2
  // stretched back to a fresh uniform number.
  ENVGI_HD int sample(float u1, float u2, float* pmfOut, float* u2Remapped) const {
    float scaled = u1 * float(n);
    int i = scaled < float(n) ? int(scaled) : n - 1;
    int chosen;
    float remap;
    if (u2 < prob[i]) {
      chosen = i;
      remap = u2 / prob[i];
    } else {
      chosen = alias[i];
      remap = (u2 - prob[i]) / (1.f - prob[i]);
    }
    if (pmfOut) *pmfOut = pmf[chosen];
    if (u2Remapped) *u2Remapped = remap < kOneMinusEpsilon ? remap : kOneMinusEpsilon;
    return chosen;
  }
};

class AliasTable {
 public:
  AliasTable() = default;
  // Weights need not be normalised; all-zero weights give the uniform distribution.
  AliasTable(const float* weights, size_t n);
  AliasTableView view() const { return {prob_.data(), alias_.data(), pmf_.data(), int(prob_.size())}; }
  size_t bytes() const { return prob_.size() * (2 * sizeof(float) + sizeof(int)); }

 private:
  std::vector<float> prob_, pmf_;
  std::vector<int> alias_;
};

}  // namespace envgi
