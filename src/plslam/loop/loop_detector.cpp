#include "plslam/loop/loop_detector.h"

#include <algorithm>
#include <stdexcept>

#include "plslam/map/keyframe.h"

namespace plslam::loop {

void LoopDetectorOptions::validate() const {
  if (consistency < 1) throw std::invalid_argument("loop.consistency: must be >= 1");
  if (group_size < 1) throw std::invalid_argument("loop.group_size: must be >= 1");
}

LoopDetector::LoopDetector(const place::KeyframeDatabase& database, LoopDetectorOptions options)
    : database_(database), options_(options) {
  options_.validate();
}

std::vector<LoopDetection> LoopDetector::detect(map::KeyFrame* kf) {
  const auto description = database_.description(kf);
  if (!description || database_.size() < options_.min_keyframes) {
    groups_.clear();
    return {};
  }
  // The neighbourhood: the keyframe and everything covisible with it. The least similar neighbour
  // sets the bar a distant keyframe must reach.
  map::IdSet<const map::KeyFrame> neighbourhood;
  neighbourhood.insert(kf);
  double min_score = 1.0;
  bool any = false;
  for (map::KeyFrame* n : kf->covisibles()) {
    neighbourhood.insert(n);
    const auto d = database_.description(n);
    if (!d || n->is_bad()) continue;
    min_score = std::min(min_score, place::l1_score(description->bow, d->bow));
    any = true;
  }
  if (!any) {
    groups_.clear();
    return {};
  }
  place::DatabaseQueryOptions q;
  q.min_score = min_score;
  q.group_size = options_.group_size;
  q.exclude = [&](const map::KeyFrame* k) { return neighbourhood.count(k) > 0; };
  const auto candidates = database_.query(description->bow, q);

  // Consistency: a candidate's place (it and its covisibles) continues a place the previous
  // keyframe found when the two share a keyframe.
  std::vector<Group> current;
  std::vector<LoopDetection> found;
  for (const auto& c : candidates) {
    Group g;
    g.members.insert(c.keyframe);
    for (map::KeyFrame* n : c.keyframe->covisibles()) g.members.insert(n);
    for (const auto& previous : groups_) {
      const bool shared = std::any_of(g.members.begin(), g.members.end(),
                                      [&](map::KeyFrame* m) { return previous.members.count(m) > 0; });
      if (shared) g.consistency = std::max(g.consistency, previous.consistency + 1);
    }
    if (g.consistency + 1 >= options_.consistency) found.push_back({c.keyframe, c.score, g.consistency + 1});
    current.push_back(std::move(g));
  }
  groups_ = std::move(current);
  std::stable_sort(found.begin(), found.end(), [](const LoopDetection& a, const LoopDetection& b) { return a.score > b.score; });
  return found;
}

}  // namespace plslam::loop
