#include "common/statistics.hpp"

#include <algorithm>

namespace fem {

double sorted_quantile(const double* sorted, std::size_t n, double q) {
  if (n == 0) return 0.0;
  const double position = q * static_cast<double>(n - 1);
  const auto lo = static_cast<std::size_t>(position);
  const std::size_t hi = std::min(lo + 1, n - 1);
  return sorted[lo] + (position - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

double median_in_place(double* first, double* last) {
  std::sort(first, last);
  return sorted_quantile(first, static_cast<std::size_t>(last - first), 0.5);
}

double median(std::vector<double> v) { return median_in_place(v.data(), v.data() + v.size()); }

Spread spread(std::vector<double> v) {
  if (v.empty()) return {};
  std::sort(v.begin(), v.end());
  const auto at = [&v](double q) { return sorted_quantile(v.data(), v.size(), q); };
  return {v.front(), at(0.25), at(0.5), at(0.75), v.back()};
}

}  // namespace fem
