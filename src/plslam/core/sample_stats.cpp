#include "plslam/core/sample_stats.h"

#include <algorithm>
#include <numeric>

namespace plslam {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

double mean(const std::vector<double>& v) {
  return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

nlohmann::json summarize(const std::vector<double>& v) {
  if (v.empty()) return {{"median", nullptr}, {"p90", nullptr}, {"mean", nullptr}, {"max", nullptr}};
  return {{"median", percentile(v, 0.5)},
          {"p90", percentile(v, 0.9)},
          {"mean", mean(v)},
          {"max", *std::max_element(v.begin(), v.end())}};
}

}  // namespace plslam
