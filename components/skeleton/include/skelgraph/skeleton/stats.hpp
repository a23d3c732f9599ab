#pragma once
// Order statistics used across the cores (calibration, gesture, evaluation):
// one definition each. Eigen/std only.

#include <vector>

namespace skelgraph::stats {

// The median: for an even count the mean of the two middle values. NaN when empty.
double median(std::vector<double> v);
// The value at index n/2 of the sorted values (for an even count the upper of
// the two middle ones): what the calibration's acceptance rules and their
// figures are defined with. NaN when empty.
double upper_median(std::vector<double> v);

}  // namespace skelgraph::stats
