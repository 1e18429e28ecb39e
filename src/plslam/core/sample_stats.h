#pragma once
// Summaries of timing and count samples for benchmarks and run statistics.
#include <vector>

#include <nlohmann/json.hpp>

namespace plslam {

// The q-quantile (0 <= q <= 1) with linear interpolation between order statistics (numpy's
// default); 0 for an empty sample.
double percentile(std::vector<double> values, double q);
double mean(const std::vector<double>& values);

// {median, p90, mean, max}; nulls for an empty sample.
nlohmann::json summarize(const std::vector<double>& values);

}  // namespace plslam
