#include "plslam/place/bow_vector.h"

#include <cmath>

namespace plslam::place {

double l1_score(const BowVector& a, const BowVector& b) {
  // With |a|_1 = |b|_1 = 1: |a - b|_1 = 2 + sum over common words of (|ai - bi| - ai - bi).
  double common = 0.0;
  auto i = a.begin();
  auto j = b.begin();
  while (i != a.end() && j != b.end()) {
    if (i->first < j->first) {
      ++i;
    } else if (j->first < i->first) {
      ++j;
    } else {
      common += std::abs(i->second - j->second) - i->second - j->second;
      ++i;
      ++j;
    }
  }
  return -0.5 * common;
}

}  // namespace plslam::place
