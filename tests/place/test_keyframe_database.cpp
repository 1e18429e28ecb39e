// The keyframe database on places with known descriptors: each place is a set of random
// prototype descriptors, and a keyframe of a place holds noisy copies of them. A query must find
// its own place first, never a culled or excluded keyframe, and group covisible keyframes; adds,
// erases and queries from several threads must be safe (this suite runs under ThreadSanitizer).
#include <algorithm>
#include <atomic>
#include <memory>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "place/synthetic_descriptors.h"
#include "plslam/map/keyframe.h"
#include "plslam/map/map.h"
#include "plslam/place/keyframe_database.h"
#include "plslam/place/vocabulary_training.h"

namespace plslam::place {
namespace {

constexpr int kPlaces = 12;
constexpr int kPerPlace = 150;

struct Places {
  std::vector<std::vector<Descriptor256>> prototypes;  // per place
  std::shared_ptr<const Vocabulary> vocabulary;
  std::mt19937_64 rng{7};

  Places() {
    for (int p = 0; p < kPlaces; ++p) {
      prototypes.emplace_back();
      for (int i = 0; i < kPerPlace; ++i) prototypes.back().push_back(random_descriptor(rng));
    }
    std::vector<std::vector<Descriptor256>> images;
    for (int p = 0; p < kPlaces; ++p) images.push_back(view(p));
    VocabularyTrainingOptions o;
    o.k = 8;
    o.levels = 3;
    vocabulary = std::make_shared<const Vocabulary>(train_vocabulary(images, o));
  }
  // A view of place p: its prototypes with 6 bits of noise each.
  std::vector<Descriptor256> view(int p) {
    std::vector<Descriptor256> out;
    for (const auto& d : prototypes[static_cast<std::size_t>(p)]) out.push_back(flip_bits(d, 6, rng));
    return out;
  }
  std::shared_ptr<map::FrameData> frame(long id, int p) {
    auto d = std::make_shared<map::FrameData>();
    d->frame_id = id;
    d->descriptors = to_mat(view(p));
    d->keypoints.resize(static_cast<std::size_t>(d->descriptors.rows));
    return d;
  }
};

Places& places() {
  static Places p;
  return p;
}

TEST(KeyframeDatabase, QueryFindsTheKeyframeOfTheSamePlaceFirst) {
  map::Map m;
  KeyframeDatabase db(places().vocabulary);
  std::vector<map::KeyFrame*> kfs;
  for (int p = 0; p < kPlaces; ++p) {
    kfs.push_back(m.create_keyframe(places().frame(p, p), geometry::SE3()));
    db.add(kfs.back());
  }
  EXPECT_EQ(db.size(), static_cast<std::size_t>(kPlaces));
  for (int p = 0; p < kPlaces; ++p) {
    const auto q = db.describe(to_mat(places().view(p)));
    const auto c = db.query(q.bow);
    ASSERT_FALSE(c.empty()) << "place " << p;
    EXPECT_EQ(c.front().keyframe, kfs[static_cast<std::size_t>(p)]) << "place " << p;
    EXPECT_GT(c.front().score, 0.3);
    // Other places share only chance words: far lower scores, dropped from the candidates.
    for (std::size_t i = 1; i < c.size(); ++i) EXPECT_LT(c[i].score, 0.5 * c.front().score);
  }
  // The stored description is the keyframe's own transform.
  const auto d = db.description(kfs[3]);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->bow, places().vocabulary->transform(kfs[3]->data().descriptors));
}

TEST(KeyframeDatabase, ErasedBadAndExcludedKeyframesAreNeverReturned) {
  map::Map m;
  KeyframeDatabase db(places().vocabulary);
  std::vector<map::KeyFrame*> kfs;
  for (int i = 0; i < 4; ++i) {
    kfs.push_back(m.create_keyframe(places().frame(i, i < 3 ? 0 : 1), geometry::SE3()));
    db.add(kfs.back());
  }
  db.add(kfs[1]);  // re-adding re-indexes, it does not duplicate
  EXPECT_EQ(db.size(), 4u);
  const auto q = db.describe(to_mat(places().view(0))).bow;
  auto returned = [&](const map::KeyFrame* kf, const DatabaseQueryOptions& o = {}) {
    for (const auto& c : db.query(q, o)) {
      if (c.keyframe == kf) return true;
    }
    return false;
  };
  EXPECT_TRUE(returned(kfs[0]));
  EXPECT_TRUE(returned(kfs[1]));
  db.erase(kfs[1]);
  db.erase(kfs[1]);  // twice is harmless
  EXPECT_EQ(db.size(), 3u);
  EXPECT_FALSE(db.description(kfs[1]));
  EXPECT_FALSE(returned(kfs[1]));
  kfs[2]->set_bad();  // culled but not yet erased: still never returned
  EXPECT_FALSE(returned(kfs[2]));
  DatabaseQueryOptions o;
  o.exclude = [&](const map::KeyFrame* kf) { return kf == kfs[0]; };
  EXPECT_FALSE(returned(kfs[0], o));
  EXPECT_TRUE(returned(kfs[0]));
  // A keyframe added after an erase takes the freed slot: it is found under its own words, with
  // its own count of common words, and the erased one stays gone.
  map::KeyFrame* later = m.create_keyframe(places().frame(9, 2), geometry::SE3());
  db.add(later);
  const auto q2 = db.describe(to_mat(places().view(2))).bow;
  const auto c2 = db.query(q2);
  ASSERT_FALSE(c2.empty());
  EXPECT_EQ(c2.front().keyframe, later);
  const auto& later_bow = db.description(later)->bow;
  int common = 0;
  for (const auto& [word, weight] : q2) {
    common += std::any_of(later_bow.begin(), later_bow.end(), [&, w = word](const auto& e) { return e.first == w; });
  }
  EXPECT_EQ(c2.front().common_words, common);
  for (const auto& c : c2) EXPECT_NE(c.keyframe, kfs[1]);
  EXPECT_FALSE(returned(kfs[1]));
  // No word in common: nothing.
  EXPECT_TRUE(db.query({}).empty());
  EXPECT_TRUE(db.describe(cv::Mat()).bow.empty());
}

TEST(KeyframeDatabase, CovisibleKeyframesOfOnePlaceFormOneCandidateWithTheirSummedScore) {
  map::Map m;
  KeyframeDatabase db(places().vocabulary);
  map::KeyFrame* a = m.create_keyframe(places().frame(0, 5), geometry::SE3());
  map::KeyFrame* b = m.create_keyframe(places().frame(1, 5), geometry::SE3());
  map::KeyFrame* lone = m.create_keyframe(places().frame(2, 5), geometry::SE3());
  a->add_connection(b, 100);
  b->add_connection(a, 100);
  for (auto* kf : {a, b, lone}) db.add(kf);
  const auto q = db.describe(to_mat(places().view(5))).bow;
  // {a, b} as one group, and lone, whose score alone is about half the group's.
  DatabaseQueryOptions loose;
  loose.min_group_share = 0.3;
  const auto c = db.query(q, loose);
  ASSERT_EQ(c.size(), 2u);
  const double sa = l1_score(q, db.description(a)->bow), sb = l1_score(q, db.description(b)->bow);
  EXPECT_NEAR(c.front().group_score, sa + sb, 1e-12);
  EXPECT_EQ(c.front().keyframe, sa >= sb ? a : b);
  EXPECT_EQ(c.back().keyframe, lone);
  DatabaseQueryOptions one = loose;
  one.max_candidates = 1;
  EXPECT_EQ(db.query(q, one).size(), 1u);
  // By default, groups under 0.75 of the best are dropped.
  const auto strict = db.query(q);
  ASSERT_EQ(strict.size(), 1u);
  EXPECT_NE(strict.front().keyframe, lone);
}

TEST(KeyframeDatabase, ConcurrentAddEraseAndQueryAreSafe) {
  map::Map m;
  KeyframeDatabase db(places().vocabulary);
  std::vector<map::KeyFrame*> kfs;
  for (int i = 0; i < 40; ++i) kfs.push_back(m.create_keyframe(places().frame(i, i % kPlaces), geometry::SE3()));
  std::vector<BowVector> queries;
  for (int p = 0; p < kPlaces; ++p) queries.push_back(db.describe(to_mat(places().view(p))).bow);
  std::atomic<bool> done{false};
  std::atomic<int> answers{0};
  std::thread reader([&] {
    while (!done.load()) {
      for (const auto& q : queries) {
        for (const auto& c : db.query(q)) {
          if (db.description(c.keyframe)) answers.fetch_add(1);
        }
      }
    }
  });
  for (auto* kf : kfs) db.add(kf);
  for (std::size_t i = 0; i < kfs.size(); i += 2) db.erase(kfs[i]);
  done.store(true);
  reader.join();
  EXPECT_EQ(db.size(), kfs.size() / 2);
  for (std::size_t i = 0; i < kfs.size(); ++i) EXPECT_EQ(static_cast<bool>(db.description(kfs[i])), i % 2 == 1);
  EXPECT_GE(answers.load(), 0);
}

}  // namespace
}  // namespace plslam::place
