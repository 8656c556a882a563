#include "sampling/AliasTable.h"

#include <stdexcept>

namespace envgi {

AliasTable::AliasTable(const float* weights, size_t n) : bins_(n) {
  if (n == 0) throw std::invalid_argument("AliasTable: no weights");
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) sum += (weights[i] > 0.f && std::isfinite(weights[i])) ? weights[i] : 0.0;
  std::vector<double> scaled(n);
  for (size_t i = 0; i < n; ++i) {
    double w = (weights[i] > 0.f && std::isfinite(weights[i])) ? weights[i] : 0.0;
    double p = sum > 0.0 ? w / sum : 1.0 / double(n);
    bins_[i].pmf = float(p);
    scaled[i] = p * double(n);
  }
  // Vose's method: pair each under-full bin with an over-full one.
  std::vector<size_t> small, large;
  for (size_t i = 0; i < n; ++i) (scaled[i] < 1.0 ? small : large).push_back(i);
  while (!small.empty() && !large.empty()) {
    size_t s = small.back(), l = large.back();
    small.pop_back();
    large.pop_back();
    bins_[s].prob = float(scaled[s]);
    bins_[s].alias = int(l);
    scaled[l] = (scaled[l] + scaled[s]) - 1.0;
    (scaled[l] < 1.0 ? small : large).push_back(l);
  }
  // Leftovers are 1 up to rounding.
  for (size_t i : large) bins_[i] = {1.f, int(i), bins_[i].pmf};
  for (size_t i : small) bins_[i] = {1.f, int(i), bins_[i].pmf};
}

}  // namespace envgi
