#pragma once
// The keyframe database: the bag of words and feature vector of every keyframe, and an inverted
// file from each word to the keyframes containing it, so that a query scores only keyframes that
// share words with it (DBoW2's database, ORB-SLAM2's KeyFrameDatabase). Thread-safe: local mapping
// adds and forgets keyframes while tracking (relocalization) and loop closing query.
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/map/by_id.h"
#include "plslam/place/bow_vector.h"
#include "plslam/place/vocabulary.h"

namespace plslam::map {
class KeyFrame;
}  // namespace plslam::map

namespace plslam::place {

// A frame or keyframe as words: what queries score and what BoW matching groups by.
struct PlaceDescription {
  BowVector bow;
  FeatureVector features;
};

struct DatabaseQueryOptions {
  // Only keyframes sharing at least this share of the best candidate's number of common words are
  // scored (ORB-SLAM2: 0.8): the others cannot score well and scoring is the costly part.
  double min_common_share = 0.8;
  double min_score = 0;              // absolute floor of a keyframe's L1 score
  // A candidate's support is the sum of the scores of its best covisible keyframes (a place is
  // seen from several keyframes); groups below this share of the best group's are dropped.
  std::size_t group_size = 10;
  double min_group_share = 0.75;
  std::size_t max_candidates = 0;    // 0: every group that passes
  // Keyframes the query must not return (loop detection skips the current neighbourhood).
  std::function<bool(const map::KeyFrame*)> exclude;
};

struct PlaceCandidate {
  map::KeyFrame* keyframe = nullptr;  // the best-scoring keyframe of its covisible group
  double score = 0;                   // its L1 score
  double group_score = 0;             // summed over the group
  int common_words = 0;
};

class KeyframeDatabase {
 public:
  // `feature_levels_up`: the level of the feature vector, counted up from the words. With k = 10
  // and 4 levels, 2 levels up gives 100 nodes of about 20 features each for 2000 features: small
  // enough for cheap matching, large enough that true matches rarely fall into different nodes.
  explicit KeyframeDatabase(std::shared_ptr<const Vocabulary> vocabulary, int feature_levels_up = 2);

  const Vocabulary& vocabulary() const { return *vocabulary_; }
  // The words of N x 32 CV_8U descriptors (no database lock: callable from any thread).
  PlaceDescription describe(const cv::Mat& descriptors) const;

  // Describes the keyframe's point descriptors and indexes it; a keyframe added twice is
  // re-indexed. Local mapping calls it, off the tracking thread.
  void add(map::KeyFrame* kf);
  // Indexes a keyframe under a description made earlier (a map file stores them, so loading
  // does not describe every keyframe again).
  void add(map::KeyFrame* kf, std::shared_ptr<const PlaceDescription> description);
  int feature_levels_up() const { return feature_levels_up_; }
  // Forgets a keyframe (culled); unknown keyframes are ignored.
  void erase(const map::KeyFrame* kf);
  // The stored description of a keyframe, null when it is not in the database.
  std::shared_ptr<const PlaceDescription> description(const map::KeyFrame* kf) const;
  std::size_t size() const;

  // Keyframes that look like `bow`, best group first. Bad keyframes are never returned.
  std::vector<PlaceCandidate> query(const BowVector& bow, const DatabaseQueryOptions& options = {}) const;

 private:
  std::shared_ptr<const Vocabulary> vocabulary_;
  int feature_levels_up_;
  mutable std::mutex mutex_;
  // Each indexed keyframe has a slot; the inverted file lists slots, so that a query counts
  // common words in a plain array (an ordered map per query took 0.66 % of a sequential street
  // loop's samples, the array 0.23 %). Freed slots are reused.
  struct Slot {
    map::KeyFrame* keyframe = nullptr;  // null: free
    std::shared_ptr<const PlaceDescription> description;
  };
  std::vector<std::vector<int>> inverted_;  // word -> slots, in insertion order
  std::vector<Slot> slots_;
  std::vector<int> free_slots_;
  map::IdMap<const map::KeyFrame, int> entries_;  // keyframe -> slot

  void erase_locked(const map::KeyFrame* kf);
};

}  // namespace plslam::place
