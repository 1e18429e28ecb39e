// BoW-guided matching on descriptors whose true correspondences are known: a second view holds
// noisy copies of the first view's descriptors in another order, rotated by one angle.
#include <random>

#include <gtest/gtest.h>

#include "place/synthetic_descriptors.h"
#include "plslam/place/bow_matching.h"
#include "plslam/place/vocabulary_training.h"

namespace plslam::place {
namespace {

struct TwoViews {
  cv::Mat train_desc, query_desc;
  std::vector<cv::KeyPoint> train_kp, query_kp;
  FeatureVector train_fv, query_fv;
  std::vector<int> truth;  // train index of each query feature
};

const Vocabulary& vocabulary() {
  static const Vocabulary voc = [] {
    std::mt19937_64 rng(3);
    std::vector<std::vector<Descriptor256>> images(20);
    for (auto& im : images) {
      for (int i = 0; i < 200; ++i) im.push_back(random_descriptor(rng));
    }
    VocabularyTrainingOptions o;
    o.k = 8;
    o.levels = 3;
    return train_vocabulary(images, o);
  }();
  return voc;
}

// n features; the query view is rotated by `rotation_deg` and lists them in reverse order.
TwoViews two_views(int n, double rotation_deg, int noise_bits, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Descriptor256> train, query;
  TwoViews v;
  for (int i = 0; i < n; ++i) {
    train.push_back(random_descriptor(rng));
    v.train_kp.emplace_back(cv::Point2f(static_cast<float>(i), 0.f), 7.f, static_cast<float>(rng() % 360));
  }
  for (int i = n - 1; i >= 0; --i) {
    query.push_back(flip_bits(train[static_cast<std::size_t>(i)], noise_bits, rng));
    const float angle = std::fmod(v.train_kp[static_cast<std::size_t>(i)].angle + static_cast<float>(rotation_deg), 360.f);
    v.query_kp.emplace_back(cv::Point2f(0.f, static_cast<float>(i)), 7.f, angle);
    v.truth.push_back(i);
  }
  v.train_desc = to_mat(train);
  v.query_desc = to_mat(query);
  vocabulary().transform(v.train_desc, &v.train_fv, 1);
  vocabulary().transform(v.query_desc, &v.query_fv, 1);
  return v;
}

BowImage query_of(const TwoViews& v) { return {&v.query_desc, &v.query_fv, &v.query_kp}; }
BowImage train_of(const TwoViews& v) { return {&v.train_desc, &v.train_fv, &v.train_kp}; }

TEST(BowMatching, FindsTheTrueCorrespondencesOfARotatedView) {
  const auto v = two_views(400, 40.0, 6, 1);
  const auto matches = match_by_bow(query_of(v), train_of(v));
  // Noise can move a descriptor into another node (random descriptors have no clusters to keep
  // them in one); more than half stay, and every match found is right.
  EXPECT_GT(matches.size(), 200u);
  for (const auto& m : matches) {
    EXPECT_EQ(m.train, v.truth[static_cast<std::size_t>(m.query)]);
    EXPECT_LE(m.distance, 12);
  }
  for (std::size_t i = 1; i < matches.size(); ++i) EXPECT_LT(matches[i - 1].train, matches[i].train);
}

TEST(BowMatching, UnusableTrainFeaturesAreNeverMatched) {
  const auto v = two_views(200, 0.0, 4, 2);
  const auto matches = match_by_bow(query_of(v), train_of(v), [](int i) { return i % 3 == 0; });
  ASSERT_FALSE(matches.empty());
  for (const auto& m : matches) EXPECT_EQ(m.train % 3, 0);
}

TEST(BowMatching, OrientationCheckDropsMatchesThatDisagreeWithTheRotation) {
  auto v = two_views(300, 90.0, 4, 3);
  // A fifth of the query features turned by random angles: their descriptors still match.
  std::mt19937_64 rng(9);
  for (std::size_t i = 0; i < v.query_kp.size(); i += 5) v.query_kp[i].angle = static_cast<float>(rng() % 360);
  BowMatchOptions no_check;
  no_check.check_orientation = false;
  const auto all = match_by_bow(query_of(v), train_of(v), {}, no_check);
  const auto checked = match_by_bow(query_of(v), train_of(v));
  int turned_all = 0, turned_kept = 0;
  for (const auto& m : all) turned_all += m.query % 5 == 0;
  for (const auto& m : checked) turned_kept += m.query % 5 == 0;
  EXPECT_GT(turned_all, 30);
  // Random angles land in the three kept bins (of 30) about a tenth of the time.
  EXPECT_LT(turned_kept, turned_all / 4);
  EXPECT_GE(checked.size(), all.size() - static_cast<std::size_t>(turned_all));
}

TEST(BowMatching, AmbiguousAndDistantFeaturesAreRejected) {
  auto v = two_views(100, 0.0, 0, 4);
  // Train feature 0 duplicated into feature 1: both equally close to query features of either.
  v.train_desc.row(0).copyTo(v.train_desc.row(1));
  vocabulary().transform(v.train_desc, &v.train_fv, 1);
  const auto matches = match_by_bow(query_of(v), train_of(v));
  for (const auto& m : matches) EXPECT_GT(m.train, 1);
  BowMatchOptions tight;
  tight.max_hamming = 0;
  const auto noisy = two_views(100, 0.0, 20, 5);
  EXPECT_TRUE(match_by_bow(query_of(noisy), train_of(noisy), {}, tight).empty());
}

TEST(BowMatching, OrientationConsistencyKeepsTheThreeFullestBins) {
  std::vector<double> diffs;
  for (int i = 0; i < 50; ++i) diffs.push_back(31.0);          // bin 2 (12 degrees each)
  for (int i = 0; i < 20; ++i) diffs.push_back(-329.0 + 12.0);  // 43: bin 3
  for (int i = 0; i < 8; ++i) diffs.push_back(200.0);           // bin 16
  for (int i = 0; i < 4; ++i) diffs.push_back(300.0);           // bin 25: fourth, dropped
  diffs.push_back(100.0);                                       // bin 8: dropped
  const auto kept = orientation_consistent(diffs, 30);
  EXPECT_EQ(kept.size(), 78u);
  for (std::size_t i : kept) EXPECT_LT(i, 78u);
  // A third bin under a tenth of the fullest is dropped too.
  std::vector<double> skew(100, 10.0);
  skew.push_back(250.0);
  EXPECT_EQ(orientation_consistent(skew, 30).size(), 100u);
  EXPECT_THROW(orientation_consistent(skew, 0), std::invalid_argument);
}

}  // namespace
}  // namespace plslam::place
