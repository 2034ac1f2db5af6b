// Order statistics of a sample: the one definition of the median that fem_bench's tables, the
// lessons' tables and chapter 09's adaptive team share, so that a median in one table means
// what it means in every other.
#pragma once

#include <cstddef>
#include <vector>

namespace fem {

// The q-quantile (0 <= q <= 1) of n values sorted ascending, by linear interpolation between
// the order statistics (Hyndman & Fan 1996, definition 7; numpy's default): the median of an
// even count is the mean of the two middle values. 0 for no values.
double sorted_quantile(const double* sorted, std::size_t n, double q);

// Sorts [first, last) in place and returns its median: no allocation, for a caller that keeps
// its window in a fixed array.
double median_in_place(double* first, double* last);

double median(std::vector<double> v);

// min, first quartile, median, third quartile, max: a box of the plots.
struct Spread {
  double min = 0.0, q1 = 0.0, median = 0.0, q3 = 0.0, max = 0.0;
};
Spread spread(std::vector<double> v);

}  // namespace fem
