// Timestamp association with evo's semantics: gaps, offsets, ties, repeats, length order.
#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/eval/association.h"

namespace plslam::eval {
namespace {

using V = std::vector<std::size_t>;

TEST(Association, GapsAndOffsetsWithinMaxDiff) {
  // Ground truth at 100 Hz, estimate at ~10 Hz with 3 ms offset and a gap between 0.4 and 0.8 s.
  std::vector<double> gt, est;
  for (int i = 0; i <= 100; ++i) gt.push_back(i * 0.01);
  for (double t : {0.003, 0.103, 0.203, 0.303, 0.803, 0.903}) est.push_back(t);
  const auto p = associate_by_time(gt, est, 0.01);
  EXPECT_EQ(p.est, (V{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(p.gt, (V{0, 10, 20, 30, 80, 90}));
}

TEST(Association, DropsStampsBeyondMaxDiff) {
  const std::vector<double> gt = {0.0, 1.0, 2.0, 3.0, 4.0};
  const std::vector<double> est = {0.005, 1.02, 2.0, 5.0};
  const auto p = associate_by_time(gt, est, 0.01);
  EXPECT_EQ(p.est, (V{0, 2}));
  EXPECT_EQ(p.gt, (V{0, 2}));
  // max_diff itself is accepted (evo compares with <=).
  const auto q = associate_by_time({0.0, 1.0, 2.0}, {0.25, 1.0}, 0.25);
  EXPECT_EQ(q.est, (V{0, 1}));
  EXPECT_EQ(q.gt, (V{0, 1}));
}

TEST(Association, ShorterSideIsMatchedIntoTheLongerOne) {
  // Estimate longer than ground truth: each gt stamp picks its nearest estimate, and an estimate
  // stamp can be picked twice.
  const std::vector<double> gt = {1.0, 1.004};
  const std::vector<double> est = {0.0, 0.5, 1.001, 2.0, 3.0};
  const auto p = associate_by_time(gt, est, 0.01);
  EXPECT_EQ(p.gt, (V{0, 1}));
  EXPECT_EQ(p.est, (V{2, 2}));
}

TEST(Association, EqualLengthsMatchEstimateIntoGroundTruth) {
  const std::vector<double> gt = {0.0, 0.1, 0.2};
  const std::vector<double> est = {0.099, 0.101, 0.5};
  const auto p = associate_by_time(gt, est, 0.01);
  EXPECT_EQ(p.est, (V{0, 1}));
  EXPECT_EQ(p.gt, (V{1, 1}));
}

TEST(Association, TieGoesToTheEarlierStampAndTheFirstOfRepeats) {
  const auto tie = associate_by_time({0.0, 0.5, 1.0, 1.5}, {0.25}, 0.3);
  EXPECT_EQ(tie.gt, (V{0}));
  const auto rep = associate_by_time({1.0, 2.0, 2.0, 3.0, 4.0}, {2.4}, 1.0);
  EXPECT_EQ(rep.gt, (V{1}));
  const auto past_end = associate_by_time({1.0, 2.0, 2.0}, {2.4}, 1.0);
  EXPECT_EQ(past_end.gt, (V{1}));
}

TEST(Association, EmptyGivesNoPairs) {
  EXPECT_EQ(associate_by_time({}, {1.0}, 0.01).size(), 0u);
  EXPECT_EQ(associate_by_time({1.0}, {}, 0.01).size(), 0u);
}

TEST(Association, ByIndexNeedsEqualLengths) {
  const auto p = associate_by_index(4, 4);
  EXPECT_EQ(p.gt, (V{0, 1, 2, 3}));
  EXPECT_EQ(p.est, p.gt);
  EXPECT_THROW(associate_by_index(4, 5), InputError);
}

}  // namespace
}  // namespace plslam::eval
