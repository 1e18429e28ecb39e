#pragma once
// The seven summary statistics evo reports for an error array (numpy definitions: population
// std, median averaging the two middle values of an even-sized array).
#include <vector>

namespace plslam::eval {

struct ErrorStatistics {
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;  // sum of squared errors
};

// Throws std::invalid_argument on an empty array.
ErrorStatistics compute_statistics(const std::vector<double>& errors);

}  // namespace plslam::eval
