#pragma once
// Loop detection (ORB-SLAM2's LoopClosing::DetectLoop): for each keyframe local mapping has
// processed, keyframes outside its covisible neighbourhood that look at least as much like it as
// its least similar neighbour does, and that keep being found by consecutive keyframes. A single
// look-alike is often perceptual aliasing; the same place found three keyframes in a row rarely is.
// Geometric verification (loop_verifier.h) still follows.
#include <vector>

#include "plslam/map/by_id.h"
#include "plslam/place/keyframe_database.h"

namespace plslam::loop {

struct LoopDetectorOptions {
  int consistency = 3;          // consecutive keyframes that must find the same place
  std::size_t group_size = 10;  // covisible keyframes that form a candidate's place
  // No detection until the map holds this many keyframes (ORB-SLAM2: 10): the start of a map is
  // one neighbourhood, and everything in it is covisible.
  std::size_t min_keyframes = 10;
  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

struct LoopDetection {
  map::KeyFrame* keyframe = nullptr;  // the earlier keyframe where the place was seen
  double score = 0;                   // its L1 score with the query keyframe
  int consistency = 0;                // consecutive keyframes that found this place
};

class LoopDetector {
 public:
  explicit LoopDetector(const place::KeyframeDatabase& database, LoopDetectorOptions options = {});

  // The loop candidates of `kf` (already in the database, with its covisibility edges), ordered
  // by score; empty most of the time. Keyframes must come in the order local mapping made them.
  std::vector<LoopDetection> detect(map::KeyFrame* kf);
  // Forgets the consistency state (after a loop was closed, or the map changed wholesale).
  void reset() { groups_.clear(); }

 private:
  struct Group {
    map::IdSet<map::KeyFrame> members;
    int consistency = 0;
  };
  const place::KeyframeDatabase& database_;
  LoopDetectorOptions options_;
  std::vector<Group> groups_;  // the places the previous keyframe found
};

}  // namespace plslam::loop
