// SSC: exact count within tolerance, pairwise spacing above the final width, homogeneity,
// determinism, and the closed-form width bounds.
#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "plslam/features/keypoint_uniformity.h"
#include "plslam/features/orb_extractor.h"
#include "plslam/features/ssc.h"
#include "plslam/io/dataset.h"
#include "support/test_support.h"

namespace plslam::features {
namespace {

// Distinct integer positions with integer FAST-like scores; `clustered` puts 80 % of them,
// with the highest scores, in the top-left quarter.
std::vector<cv::KeyPoint> random_keypoints(int n, cv::Size size, uint32_t seed, bool clustered = false) {
  std::mt19937 rng(seed);
  std::set<std::pair<int, int>> used;
  std::vector<cv::KeyPoint> kps;
  while (static_cast<int>(kps.size()) < n) {
    const bool in_cluster = clustered && static_cast<int>(kps.size()) < n * 8 / 10;
    const int w = in_cluster ? size.width / 4 : size.width, h = in_cluster ? size.height / 4 : size.height;
    const int x = static_cast<int>(rng() % static_cast<uint32_t>(w));
    const int y = static_cast<int>(rng() % static_cast<uint32_t>(h));
    if (!used.insert({x, y}).second) continue;
    const float score = in_cluster ? static_cast<float>(150 + rng() % 100) : static_cast<float>(7 + rng() % 140);
    kps.emplace_back(cv::Point2f(static_cast<float>(x), static_cast<float>(y)), 7.f, -1.f, score);
  }
  return kps;
}

double min_max_norm_distance(const std::vector<cv::KeyPoint>& kps, const std::vector<int>& idx) {
  double best = 1e9;
  for (std::size_t a = 0; a < idx.size(); ++a)
    for (std::size_t b = a + 1; b < idx.size(); ++b) {
      const auto& p = kps[static_cast<std::size_t>(idx[a])].pt;
      const auto& q = kps[static_cast<std::size_t>(idx[b])].pt;
      best = std::min(best, static_cast<double>(std::max(std::abs(p.x - q.x), std::abs(p.y - q.y))));
    }
  return best;
}

std::vector<cv::KeyPoint> subset(const std::vector<cv::KeyPoint>& kps, const std::vector<int>& idx) {
  std::vector<cv::KeyPoint> out;
  for (int i : idx) out.push_back(kps[static_cast<std::size_t>(i)]);
  return out;
}

TEST(Ssc, CountWithinToleranceAndSpacingAboveWidth) {
  const cv::Size size(752, 480);
  for (const int target : {50, 387, 1200, 3000}) {
    const auto kps = random_keypoints(12000, size, 1u + static_cast<uint32_t>(target));
    const SscResult r = ssc_select(kps, target, size);
    const int tolerance = static_cast<int>(std::floor(0.001 * target));
    EXPECT_LE(std::abs(static_cast<int>(r.kept.size()) - target), tolerance) << "target " << target;
    ASSERT_GT(r.width, 0.0);
    // Kept points are pairwise more than w apart in the max-norm (the grid gives exactly that).
    EXPECT_GT(min_max_norm_distance(kps, r.kept), r.width) << "target " << target;
    const SscBounds b = ssc_width_bounds(12000, target, size);
    EXPECT_GE(r.width, std::floor(b.low));
    EXPECT_LE(r.width, std::ceil(b.high));
    // The search ends near the widest feasible cover, not at a tiny width (the bound assumes a
    // perfect lattice; greedy covers of 10x more candidates reach about 60-80 % of it).
    if (target <= 1200) {
      EXPECT_GT(r.width, 0.5 * b.high) << "target " << target;
    }
    // Strongest first.
    for (std::size_t i = 1; i < r.kept.size(); ++i)
      EXPECT_GE(kps[static_cast<std::size_t>(r.kept[i - 1])].response, kps[static_cast<std::size_t>(r.kept[i])].response);
  }
}

TEST(Ssc, SpreadsClusteredStrongPointsOverTheImage) {
  const cv::Size size(752, 480);
  const auto kps = random_keypoints(10000, size, 3u, /*clustered=*/true);
  const int target = 400;
  const SscResult r = ssc_select(kps, target, size);
  ASSERT_EQ(static_cast<int>(r.kept.size()), target);
  // Top-N by score lands almost entirely in the cluster quarter; SSC fills the whole image.
  std::vector<int> order = order_by_response(kps);
  order.resize(static_cast<std::size_t>(target));
  const double cv_top = grid_count_cv(subset(kps, order), size);
  const double cv_ssc = grid_count_cv(subset(kps, r.kept), size);
  EXPECT_GT(cv_top, 1.5);
  EXPECT_LT(cv_ssc, 0.6);
  int in_cluster = 0;
  for (int i : r.kept)
    if (kps[static_cast<std::size_t>(i)].pt.x < size.width / 4 && kps[static_cast<std::size_t>(i)].pt.y < size.height / 4) ++in_cluster;
  // The cluster quarter is 1/16 of the image; allow twice its share.
  EXPECT_LT(in_cluster, target * 2 / 16);
}

TEST(Ssc, DeterministicAndIndependentOfInputOrder) {
  const cv::Size size(640, 480);
  auto kps = random_keypoints(8000, size, 5u);
  // Distinct responses so the order of the input cannot matter.
  for (std::size_t i = 0; i < kps.size(); ++i) kps[i].response = static_cast<float>(i) * 0.37f + 0.11f;
  const SscResult a = ssc_select(kps, 500, size);
  const SscResult b = ssc_select(kps, 500, size);
  EXPECT_EQ(a.kept, b.kept);
  EXPECT_EQ(a.width, b.width);
  std::vector<int> perm(kps.size());
  for (std::size_t i = 0; i < perm.size(); ++i) perm[i] = static_cast<int>(i);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(9));
  std::vector<cv::KeyPoint> shuffled;
  for (int i : perm) shuffled.push_back(kps[static_cast<std::size_t>(i)]);
  const SscResult c = ssc_select(shuffled, 500, size);
  std::vector<int> mapped;
  for (int i : c.kept) mapped.push_back(perm[static_cast<std::size_t>(i)]);
  EXPECT_EQ(mapped, a.kept);
}

TEST(Ssc, WidthHintShortensTheSearchAndKeepsTheGuarantees) {
  const cv::Size size(752, 480);
  const auto kps = random_keypoints(12000, size, 21u);
  const SscResult plain = ssc_select(kps, 400, size);
  ASSERT_GT(plain.iterations, 2);
  const SscResult hinted = ssc_select(kps, 400, size, 0.001, plain.width);
  EXPECT_LE(hinted.iterations, 2);
  EXPECT_EQ(hinted.width, plain.width);
  EXPECT_EQ(hinted.kept, plain.kept);
  // A bad hint costs passes but not correctness.
  for (const double bad : {2.0, 500.0, plain.width + 7}) {
    const SscResult r = ssc_select(kps, 400, size, 0.001, bad);
    EXPECT_EQ(r.kept.size(), 400u);
    EXPECT_GT(min_max_norm_distance(kps, r.kept), r.width);
  }
}

TEST(Ssc, FewCandidatesAreAllKept) {
  const cv::Size size(200, 100);
  const auto kps = random_keypoints(30, size, 2u);
  const SscResult r = ssc_select(kps, 50, size);
  EXPECT_EQ(r.kept.size(), kps.size());
  EXPECT_TRUE(ssc_select(kps, 0, size).kept.empty());
  EXPECT_TRUE(ssc_select({}, 10, size).kept.empty());
}

TEST(Ssc, UpperBoundIsTightForALattice) {
  // A full lattice of spacing s in a W x H image holds (W/s+1)(H/s+1) points with max-norm
  // spacing s: for exactly that N the bound must return s.
  const double W = 300, H = 200, s = 20;
  const int n = static_cast<int>((W / s + 1) * (H / s + 1));
  const SscBounds b = ssc_width_bounds(100000, n, cv::Size(300, 200));
  EXPECT_NEAR(b.high, s, 1e-9);
  // Lower bound from the covering argument: (sqrt(K/N) - 1) / 2.5.
  EXPECT_NEAR(ssc_width_bounds(40000, 400, cv::Size(640, 480)).low, (10.0 - 1.0) / 2.5, 1e-12);
  EXPECT_DOUBLE_EQ(ssc_width_bounds(500, 400, cv::Size(640, 480)).low, 1.0);  // clamped
}

TEST(Ssc, LowerBoundKeepsEnoughPointsOnDensestInput) {
  // Every pixel of a 120 x 100 image is a candidate (the densest distinct-integer input); at the
  // lower-bound width the cover must still keep at least N points.
  const cv::Size size(120, 100);
  std::vector<cv::KeyPoint> kps;
  std::mt19937 rng(4);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      kps.emplace_back(cv::Point2f(static_cast<float>(x), static_cast<float>(y)), 7.f, -1.f, static_cast<float>(rng() % 200));
  const int target = 60;
  const SscBounds b = ssc_width_bounds(static_cast<int>(kps.size()), target, size);
  ASSERT_GT(b.low, 1.0);
  const SscResult r = ssc_select(kps, target, size);
  EXPECT_EQ(static_cast<int>(r.kept.size()), target);
  EXPECT_GE(r.width, std::floor(b.low));
}

TEST(Ssc, FloatCellFormulaIsExactIntegerDivision) {
  // floor(2x / w) for every coordinate a level can have and widths far beyond any search.
  std::vector<int> widths;
  for (int w = 1; w <= 300; ++w) widths.push_back(w);
  for (int w : {511, 512, 1000, 4097, 32768, 65535, 65536}) widths.push_back(w);
  for (int w : widths) {
    int bad = 0;
    for (uint32_t x = 0; x < 65536; ++x) bad += detail::ssc_cell(x, w) != static_cast<int>(2 * x / static_cast<uint32_t>(w));
    ASSERT_EQ(bad, 0) << "w = " << w;
  }
}

TEST(Ssc, VectorAndPortableScansAgree) {
  // The AVX2 scan (when the CPU has it) and the portable one keep the same points; integer and
  // non-integer responses, several sizes, targets and hints.
  for (const bool integer_scores : {true, false}) {
    for (const cv::Size size : {cv::Size(752, 480), cv::Size(97, 61)}) {
      auto kps = random_keypoints(size.area() / 20, size, 31u + static_cast<uint32_t>(size.width), true);
      if (!integer_scores)
        for (auto& k : kps) k.response += 0.5f;
      for (const int target : {7, 40, 333}) {
        for (const double hint : {0.0, 9.0}) {
          const SscResult fast = ssc_select(kps, target, size, 0.001, hint);
          SscResult portable;
          {
            const detail::PortableSscScope scope;
            portable = ssc_select(kps, target, size, 0.001, hint);
          }
          EXPECT_EQ(fast.kept, portable.kept) << size << " target " << target;
          EXPECT_EQ(fast.width, portable.width);
          EXPECT_EQ(fast.iterations, portable.iterations);
        }
      }
    }
  }
}

TEST(Ssc, RealPyramidCandidatesVectorAndPortableAgreeWithGuarantees) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  for (const char* seq : {"kitti/sequences/06", "euroc/V1_01_easy_micro"}) {
    const auto ds = io::open_dataset(data / seq);
    const OrbExtractor ex(std::string(seq).find("kitti") != std::string::npos ? OrbOptions::kitti() : OrbOptions::euroc());
    ImagePyramid p;
    ex.build_pyramid(ds->load(0).left, p);
    const PyramidCandidates cand = ex.detect(p);
    const std::vector<int> targets = ex.level_targets(cand);
    for (std::size_t l = 0; l < cand.size(); ++l) {
      const SscResult fast = ssc_select(cand[l].keypoints, targets[l], cand[l].region, 0.001, 11.0);
      SscResult portable;
      {
        const detail::PortableSscScope scope;
        portable = ssc_select(cand[l].keypoints, targets[l], cand[l].region, 0.001, 11.0);
      }
      EXPECT_EQ(fast.kept, portable.kept) << seq << " level " << l;
      EXPECT_EQ(static_cast<int>(fast.kept.size()), targets[l]);
      EXPECT_GT(min_max_norm_distance(cand[l].keypoints, fast.kept), fast.width);
    }
  }
}

TEST(Ssc, ReusedBuffersGiveIdenticalResultsAcrossManyCalls) {
  // The per-thread cover grid is stamped instead of cleared; the stamps wrap around after 255
  // passes and the grid grows with the image: neither may change a result.
  const cv::Size small(200, 150), large(900, 700);
  const auto a = random_keypoints(3000, small, 41u);
  const auto b = random_keypoints(20000, large, 42u);
  const SscResult ref_a = ssc_select(a, 120, small);
  const SscResult ref_b = ssc_select(b, 700, large);
  for (int i = 0; i < 150; ++i) {
    const SscResult ra = ssc_select(a, 120, small);
    ASSERT_EQ(ra.kept, ref_a.kept) << "call " << i;
    if (i % 25 == 0) {
      ASSERT_EQ(ssc_select(b, 700, large).kept, ref_b.kept) << "call " << i;
    }
  }
}

TEST(Ssc, OrderByResponseIsStableDescending) {
  std::vector<cv::KeyPoint> kps;
  for (float r : {3.f, 9.f, 3.f, 250.f, 0.f, 9.f}) kps.emplace_back(cv::Point2f(0, 0), 1.f, -1.f, r);
  EXPECT_EQ(order_by_response(kps), (std::vector<int>{3, 1, 5, 0, 2, 4}));
  kps[0].response = 3.5f;  // not an integer: the comparison sort must agree
  EXPECT_EQ(order_by_response(kps), (std::vector<int>{3, 1, 5, 0, 2, 4}));
}

TEST(Uniformity, GridCountCv) {
  std::vector<cv::KeyPoint> even, one_cell;
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 16; ++x) {
      even.emplace_back(cv::Point2f(x * 40.f + 5.f, y * 40.f + 5.f), 1.f);
      one_cell.emplace_back(cv::Point2f(1.f, 1.f), 1.f);
    }
  EXPECT_DOUBLE_EQ(grid_count_cv(even, cv::Size(640, 480)), 0.0);
  // All 192 in one of 192 cells: mean 1, std sqrt(191).
  EXPECT_NEAR(grid_count_cv(one_cell, cv::Size(640, 480)), std::sqrt(191.0), 1e-9);
}

}  // namespace
}  // namespace plslam::features
