// Every statistic against hand-computed values.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "plslam/eval/statistics.h"

namespace plslam::eval {
namespace {

TEST(Statistics, EvenCountAllSeven) {
  const auto s = compute_statistics({4.0, 1.0, 3.0, 2.0});
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));  // (1+4+9+16)/4
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);           // mean of the two middle values
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population std, as numpy
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
}

TEST(Statistics, OddCountMedianIsTheMiddleValue) {
  const auto s = compute_statistics({0.3, 0.1, 10.0, 0.2, 0.25});
  EXPECT_DOUBLE_EQ(s.median, 0.25);
  EXPECT_DOUBLE_EQ(s.min, 0.1);
  EXPECT_DOUBLE_EQ(s.max, 10.0);
  EXPECT_NEAR(s.mean, 10.85 / 5.0, 1e-15);
}

TEST(Statistics, SingleValue) {
  const auto s = compute_statistics({0.7});
  EXPECT_DOUBLE_EQ(s.rmse, 0.7);
  EXPECT_DOUBLE_EQ(s.median, 0.7);
  EXPECT_DOUBLE_EQ(s.std, 0.0);
  EXPECT_DOUBLE_EQ(s.sse, 0.49);
}

TEST(Statistics, StdKeepsDigitsWhenSmallAgainstTheMean) {
  const auto s = compute_statistics({1e6 + 1.0, 1e6 - 1.0, 1e6 + 1.0, 1e6 - 1.0});
  EXPECT_NEAR(s.std, 1.0, 1e-9);
}

TEST(Statistics, EmptyThrows) { EXPECT_THROW(compute_statistics({}), std::invalid_argument); }

}  // namespace
}  // namespace plslam::eval
