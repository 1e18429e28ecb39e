#pragma once
// Keyframes tracking made that local mapping has not processed yet (they wait in its queue, paused
// while a loop is corrected or merged): no covisibility and no parent yet, so neither the essential
// graph nor the spanning tree reaches them. Left where they are, they and the points tracking made
// with them stay in the old coordinates while the map around them moves, and the frames tracked
// against them inherit the difference. Each moves rigidly with its anchor instead: the latest
// connected keyframe made before it, the one whose drift it shares.
#include <vector>

#include "plslam/map/keyframe.h"

namespace plslam::loop {

struct UnmappedKeyFrame {
  map::KeyFrame* keyframe;
  map::KeyFrame* anchor;  // never null
};

struct KeyFramesByMapping {
  std::vector<map::KeyFrame*> connected;  // in the input's order
  std::vector<UnmappedKeyFrame> unmapped;
};

// `keyframes` in id order (Map::keyframes()). An unmapped keyframe with no connected keyframe
// before it (a map's very first keyframe) has nothing to move with and counts as connected.
KeyFramesByMapping split_unmapped(const std::vector<map::KeyFrame*>& keyframes);

}  // namespace plslam::loop
