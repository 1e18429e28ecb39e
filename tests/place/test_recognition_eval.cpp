// The precision-recall measure of place recognition on samples with known places: a loop driven
// twice, where the second lap sees the first lap's places again.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "place/synthetic_descriptors.h"
#include "plslam/place/recognition_eval.h"
#include "plslam/place/vocabulary_training.h"

namespace plslam::place {
namespace {

constexpr int kPlacesPerLap = 20;

struct Loop {
  std::vector<std::vector<Descriptor256>> segments;  // prototypes of each stretch of the loop
  std::shared_ptr<const Vocabulary> vocabulary;
  std::mt19937_64 rng{11};

  Loop() {
    for (int s = 0; s < kPlacesPerLap; ++s) {
      segments.emplace_back();
      for (int i = 0; i < 100; ++i) segments.back().push_back(random_descriptor(rng));
    }
    VocabularyTrainingOptions o;
    o.k = 8;
    o.levels = 3;
    vocabulary = std::make_shared<const Vocabulary>(train_vocabulary(segments, o));
  }
  // Sample i (1 s apart) at place i % 20 of a 20 m circle: it sees its stretch and the next, so
  // consecutive samples share half their features.
  PlaceSample sample(int i) {
    const int p = i % kPlacesPerLap;
    const double a = 2 * std::numbers::pi * p / kPlacesPerLap;
    PlaceSample s;
    s.timestamp = i;
    s.centre = Eigen::Vector3d(std::cos(a), std::sin(a), 0) * (20 / (2 * std::numbers::pi));
    s.direction = Eigen::Vector3d(-std::sin(a), std::cos(a), 0);
    std::vector<Descriptor256> d;
    for (int k : {p, (p + 1) % kPlacesPerLap}) {
      for (const auto& x : segments[static_cast<std::size_t>(k)]) d.push_back(flip_bits(x, 5, rng));
    }
    s.descriptors = to_mat(d);
    return s;
  }
};

TEST(RecognitionEval, EveryRevisitOfASecondLapIsFoundWithFullPrecision) {
  Loop loop;
  std::vector<PlaceSample> samples;
  for (int i = 0; i < 2 * kPlacesPerLap; ++i) samples.push_back(loop.sample(i));
  const auto r = evaluate_place_recognition(samples, loop.vocabulary);
  // Sample 0-2 have no database yet (2 s excluded); 3..39 query it. The second lap's 20 samples
  // each have a true match (the same place, 20 s earlier), and so has sample 19, 1 m and 18
  // degrees from sample 0 where the loop closes.
  const int revisits = kPlacesPerLap + 1;
  EXPECT_EQ(r.queries.size(), 37u);
  EXPECT_EQ(r.with_true_match, revisits);
  for (const auto& q : r.queries) {
    if (!q.has_true_match) continue;
    EXPECT_TRUE(q.correct) << "sample " << q.sample;
    if (q.sample >= static_cast<std::size_t>(kPlacesPerLap)) {
      EXPECT_EQ(q.top, static_cast<long>(q.sample) - kPlacesPerLap);
    }
  }
  EXPECT_DOUBLE_EQ(r.recall_at_precision(0.95), 1.0);
  ASSERT_FALSE(r.curve.empty());
  for (std::size_t k = 1; k < r.curve.size(); ++k) {
    EXPECT_LT(r.curve[k].threshold, r.curve[k - 1].threshold);
    EXPECT_GE(r.curve[k].recall, r.curve[k - 1].recall);
  }
  // `ranked` holds the answered queries in the order the curve accepts them.
  ASSERT_EQ(r.ranked.size(), static_cast<std::size_t>(r.curve.back().accepted));
  for (std::size_t k = 1; k < r.ranked.size(); ++k) {
    EXPECT_GE(r.queries[r.ranked[k - 1]].score, r.queries[r.ranked[k]].score);
  }
  // Accepting every top candidate: the first lap's answers are all wrong.
  EXPECT_EQ(r.curve.back().correct, revisits);
  EXPECT_NEAR(r.curve.back().precision, static_cast<double>(revisits) / r.curve.back().accepted, 1e-12);
}

TEST(RecognitionEval, AnAliasedPlaceCostsPrecisionAtFullRecall) {
  Loop loop;
  std::vector<PlaceSample> samples;
  for (int i = 0; i < 2 * kPlacesPerLap; ++i) samples.push_back(loop.sample(i));
  // Sample 12 of the first lap looks exactly like sample 5 (and 11 like 4, so that 12's reference
  // score stays high), but stands elsewhere: perceptual aliasing.
  for (int k : {11, 12}) samples[static_cast<std::size_t>(k)].descriptors = samples[static_cast<std::size_t>(k - 7)].descriptors.clone();
  const auto r = evaluate_place_recognition(samples, loop.vocabulary);
  const auto& q12 = r.queries[12 - 3];
  ASSERT_EQ(q12.sample, 12u);
  EXPECT_FALSE(q12.has_true_match);
  EXPECT_EQ(q12.top, 5);
  EXPECT_FALSE(q12.correct);
  // 7 of 20 places around the 20 m circle: 126 degrees turned, the chord 2 R sin(63 deg) away.
  EXPECT_NEAR(q12.top_angle_deg, 126.0, 1e-9);
  EXPECT_NEAR(q12.top_distance_m, 2 * (20 / (2 * std::numbers::pi)) * std::sin(63.0 * std::numbers::pi / 180), 1e-9);
  // Its score ranks with the true revisits: no threshold keeps every revisit without it.
  EXPECT_LT(r.curve.back().precision, 1.0);
  EXPECT_LT(r.recall_at_precision(1.0), 1.0);
}

TEST(RecognitionEval, SamplesOutOfTimeOrderAreRefused) {
  Loop loop;
  std::vector<PlaceSample> samples{loop.sample(1), loop.sample(0)};
  EXPECT_THROW(evaluate_place_recognition(samples, loop.vocabulary), std::invalid_argument);
  EXPECT_TRUE(evaluate_place_recognition({}, loop.vocabulary).queries.empty());
}

}  // namespace
}  // namespace plslam::place
