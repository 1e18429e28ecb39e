#include "plslam/place/keyframe_database.h"

#include <algorithm>
#include <stdexcept>

#include "plslam/map/keyframe.h"

namespace plslam::place {

KeyframeDatabase::KeyframeDatabase(std::shared_ptr<const Vocabulary> vocabulary, int feature_levels_up)
    : vocabulary_(std::move(vocabulary)), feature_levels_up_(feature_levels_up) {
  if (!vocabulary_ || vocabulary_->empty()) throw std::invalid_argument("KeyframeDatabase: empty vocabulary");
  inverted_.resize(vocabulary_->size());
}

PlaceDescription KeyframeDatabase::describe(const cv::Mat& descriptors) const {
  PlaceDescription d;
  if (descriptors.empty()) return d;
  d.bow = vocabulary_->transform(descriptors, &d.features, feature_levels_up_);
  return d;
}

void KeyframeDatabase::add(map::KeyFrame* kf) {
  add(kf, std::make_shared<const PlaceDescription>(describe(kf->data().descriptors)));
}

void KeyframeDatabase::add(map::KeyFrame* kf, std::shared_ptr<const PlaceDescription> d) {
  std::lock_guard lock(mutex_);
  if (auto it = entries_.find(kf); it != entries_.end()) {
    unindex_locked(kf, *it->second);
    entries_.erase(it);
  }
  for (const auto& [word, weight] : d->bow) inverted_[word].push_back(kf);
  entries_.emplace(kf, std::move(d));
}

void KeyframeDatabase::unindex_locked(const map::KeyFrame* kf, const PlaceDescription& d) {
  for (const auto& [word, weight] : d.bow) {
    auto& list = inverted_[word];
    list.erase(std::remove(list.begin(), list.end(), kf), list.end());
  }
}

void KeyframeDatabase::erase(const map::KeyFrame* kf) {
  std::lock_guard lock(mutex_);
  auto it = entries_.find(kf);
  if (it == entries_.end()) return;
  unindex_locked(kf, *it->second);
  entries_.erase(it);
}

std::shared_ptr<const PlaceDescription> KeyframeDatabase::description(const map::KeyFrame* kf) const {
  std::lock_guard lock(mutex_);
  auto it = entries_.find(kf);
  return it == entries_.end() ? nullptr : it->second;
}

std::size_t KeyframeDatabase::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

std::vector<PlaceCandidate> KeyframeDatabase::query(const BowVector& bow, const DatabaseQueryOptions& o) const {
  // 1. Keyframes sharing words, with how many (ordered by id, so ties break the same every run).
  map::IdMap<map::KeyFrame, int> common;
  map::IdMap<map::KeyFrame, double> scores;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [word, weight] : bow) {
      if (word >= inverted_.size()) continue;
      for (map::KeyFrame* kf : inverted_[word]) ++common[kf];
    }
    int max_common = 0;
    for (auto it = common.begin(); it != common.end();) {
      if (it->first->is_bad() || (o.exclude && o.exclude(it->first))) {
        it = common.erase(it);
      } else {
        max_common = std::max(max_common, it->second);
        ++it;
      }
    }
    // 2. Score those sharing enough words.
    const double min_common = o.min_common_share * max_common;
    for (const auto& [kf, n] : common) {
      if (n < min_common) continue;
      const double s = l1_score(bow, entries_.at(kf)->bow);
      if (s >= o.min_score) scores.emplace(kf, s);
    }
  }
  // 3. Sum each scored keyframe's score with its covisible neighbours' (outside the database lock:
  //    the covisibility graph has its own).
  std::vector<PlaceCandidate> groups;
  double best_group = 0;
  for (const auto& [kf, s] : scores) {
    PlaceCandidate c{kf, s, s, common.at(kf)};
    for (map::KeyFrame* n : kf->best_covisibles(o.group_size)) {
      auto it = scores.find(n);
      if (it == scores.end()) continue;
      c.group_score += it->second;
      if (it->second > c.score) {
        c.score = it->second;
        c.keyframe = n;
        c.common_words = common.at(n);
      }
    }
    best_group = std::max(best_group, c.group_score);
    groups.push_back(c);
  }
  // 4. Strong groups only, one candidate per keyframe, best group first.
  std::vector<PlaceCandidate> out;
  std::stable_sort(groups.begin(), groups.end(),
                   [](const PlaceCandidate& a, const PlaceCandidate& b) { return a.group_score > b.group_score; });
  map::IdSet<map::KeyFrame> taken;
  for (const auto& c : groups) {
    if (c.group_score < o.min_group_share * best_group) break;
    if (!taken.insert(c.keyframe).second) continue;
    out.push_back(c);
    if (o.max_candidates && out.size() >= o.max_candidates) break;
  }
  return out;
}

}  // namespace plslam::place
