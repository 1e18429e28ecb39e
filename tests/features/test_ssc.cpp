// SSC: exact count within tolerance, pairwise spacing above the final width, homogeneity,
// determinism, and the closed-form width bounds.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <set>
#include <sstream>
#include <string>

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

// FAST candidates of one real left image, with the extractor configured for its dataset.
struct RealCandidates {
  OrbExtractor extractor;
  PyramidCandidates candidates;
};
RealCandidates real_candidates(const std::filesystem::path& data, const std::string& seq, bool middle_frame) {
  const auto ds = io::open_dataset(data / seq);
  OrbExtractor ex(seq.find("kitti") != std::string::npos ? OrbOptions::kitti() : OrbOptions::euroc());
  ImagePyramid p;
  ex.build_pyramid(ds->load(middle_frame ? ds->size() / 2 : 0).left, p);
  PyramidCandidates cand = ex.detect(p);
  return {std::move(ex), std::move(cand)};
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
  EXPECT_TRUE(ssc_select(std::vector<cv::KeyPoint>{}, 10, size).kept.empty());
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
    const auto [ex, cand] = real_candidates(data, seq, false);
    const std::vector<int> targets = ex.level_targets(cand);
    for (std::size_t l = 0; l < cand.size(); ++l) {
      const std::vector<cv::KeyPoint> kps = cand[l].corners.keypoints();
      const SscResult fast = ssc_select(kps, targets[l], cand[l].region, 0.001, 11.0);
      SscResult portable;
      {
        const detail::PortableSscScope scope;
        portable = ssc_select(kps, targets[l], cand[l].region, 0.001, 11.0);
      }
      EXPECT_EQ(fast.kept, portable.kept) << seq << " level " << l;
      EXPECT_EQ(static_cast<int>(fast.kept.size()), targets[l]);
      EXPECT_GT(min_max_norm_distance(kps, fast.kept), fast.width);
    }
  }
}

// The corners path must keep exactly the corners the keypoint path keeps, in the same order,
// with the same width and passes.
void expect_corners_match_keypoints(const FastCorners& corners, int target, cv::Size size, double hint,
                                    const std::string& what) {
  const std::vector<cv::KeyPoint> kps = corners.keypoints();
  const SscResult ref = ssc_select(kps, target, size, 0.001, hint);
  for (const bool portable : {false, true}) {
    SscCornersResult r;
    if (portable) {
      const detail::PortableSscScope scope;
      r = ssc_select(corners, target, size, 0.001, hint);
    } else {
      r = ssc_select(corners, target, size, 0.001, hint);
    }
    const std::string tag = what + (portable ? " portable" : "");
    ASSERT_EQ(r.kept.size(), ref.kept.size()) << tag;
    ASSERT_EQ(r.kept.position.size(), r.kept.score.size()) << tag;
    for (std::size_t i = 0; i < ref.kept.size(); ++i) {
      const auto id = static_cast<std::size_t>(ref.kept[i]);
      ASSERT_EQ(r.kept.position[i], corners.position[id]) << tag << " kept " << i;
      ASSERT_EQ(r.kept.score[i], corners.score[id]) << tag << " kept " << i;
    }
    EXPECT_EQ(r.width, ref.width) << tag;
    EXPECT_EQ(r.iterations, ref.iterations) << tag;
  }
}

TEST(Ssc, CornersGiveTheKeypointSelection) {
  for (const cv::Size size : {cv::Size(752, 480), cv::Size(97, 61), cv::Size(1226, 370)}) {
    for (const bool clustered : {false, true}) {
      auto kps = random_keypoints(size.area() / 25, size, 7u + static_cast<uint32_t>(size.width), clustered);
      // The extreme scores too (the counting sort's first and last bins).
      kps[3].response = 0.f;
      kps[5].response = 255.f;
      kps[8].response = 255.f;
      const FastCorners corners = FastCorners::from_keypoints(kps);
      for (const int target : {1, 7, 40, 333, static_cast<int>(kps.size()) - 1, static_cast<int>(kps.size()),
                               static_cast<int>(kps.size()) + 5}) {
        for (const double hint : {0.0, 3.0, 9.0}) {
          std::ostringstream what;
          what << size << (clustered ? " clustered" : "") << " target " << target << " hint " << hint;
          expect_corners_match_keypoints(corners, target, size, hint, what.str());
        }
      }
    }
  }
  // Many equal scores (long runs), and a single score.
  const cv::Size size(300, 200);
  auto kps = random_keypoints(6000, size, 77u);
  for (std::size_t i = 0; i < kps.size(); ++i) kps[i].response = static_cast<float>(20 + (i % 3));
  expect_corners_match_keypoints(FastCorners::from_keypoints(kps), 150, size, 0.0, "three scores");
  for (auto& k : kps) k.response = 9.f;
  expect_corners_match_keypoints(FastCorners::from_keypoints(kps), 150, size, 5.0, "one score");
}

TEST(Ssc, CornersOfRealPyramidsGiveTheKeypointSelection) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  for (const char* seq : {"kitti/sequences/06", "euroc/V1_01_easy_micro"}) {
    const auto [ex, cand] = real_candidates(data, seq, true);
    const std::vector<int> targets = ex.level_targets(cand);
    for (std::size_t l = 0; l < cand.size(); ++l)
      for (const double hint : {0.0, 11.0})
        expect_corners_match_keypoints(cand[l].corners, targets[l], cand[l].region, hint,
                                       std::string(seq) + " level " + std::to_string(l));
  }
}

TEST(Ssc, CornersOutsideTheImageAreRejected) {
  const cv::Size size(100, 80);
  FastCorners c = FastCorners::from_keypoints(random_keypoints(500, size, 3u));
  EXPECT_NO_THROW(ssc_select(c, 50, size));
  FastCorners wide = c;
  wide.position[17] = FastCorners::pack(100, 5);
  EXPECT_THROW(ssc_select(wide, 50, size), std::invalid_argument);
  FastCorners low = c;
  low.position[499] = FastCorners::pack(5, 80);
  EXPECT_THROW(ssc_select(low, 50, size), std::invalid_argument);
  FastCorners ragged = c;
  ragged.score.pop_back();
  EXPECT_THROW(ssc_select(ragged, 50, size), std::invalid_argument);
  EXPECT_TRUE(ssc_select(FastCorners{}, 10, size).kept.empty());
  EXPECT_TRUE(ssc_select(c, 0, size).kept.empty());
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
