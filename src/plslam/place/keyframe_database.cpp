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
  erase_locked(kf);
  int slot;
  if (free_slots_.empty()) {
    slot = static_cast<int>(slots_.size());
    slots_.emplace_back();
  } else {
    slot = free_slots_.back();
    free_slots_.pop_back();
  }
  for (const auto& [word, weight] : d->bow) inverted_[word].push_back(slot);
  slots_[static_cast<std::size_t>(slot)] = {kf, std::move(d)};
  entries_.emplace(kf, slot);
}

void KeyframeDatabase::erase_locked(const map::KeyFrame* kf) {
  auto it = entries_.find(kf);
  if (it == entries_.end()) return;
  const int slot = it->second;
  Slot& s = slots_[static_cast<std::size_t>(slot)];
  for (const auto& [word, weight] : s.description->bow) {
    auto& list = inverted_[word];
    list.erase(std::remove(list.begin(), list.end(), slot), list.end());
  }
  s = {};
  free_slots_.push_back(slot);
  entries_.erase(it);
}

void KeyframeDatabase::erase(const map::KeyFrame* kf) {
  std::lock_guard lock(mutex_);
  erase_locked(kf);
}

std::shared_ptr<const PlaceDescription> KeyframeDatabase::description(const map::KeyFrame* kf) const {
  std::lock_guard lock(mutex_);
  auto it = entries_.find(kf);
  return it == entries_.end() ? nullptr : slots_[static_cast<std::size_t>(it->second)].description;
}

std::size_t KeyframeDatabase::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

std::vector<PlaceCandidate> KeyframeDatabase::query(const BowVector& bow, const DatabaseQueryOptions& o) const {
  // Keyframe, common words and score, ordered by keyframe id (ties break the same every run).
  struct Scored {
    map::KeyFrame* keyframe;
    int common;
    double score;
    int slot;
  };
  std::vector<Scored> scores;
  const auto by_id = [](const Scored& a, const Scored& b) { return a.keyframe->id() < b.keyframe->id(); };
  {
    std::lock_guard lock(mutex_);
    // 1. Keyframes sharing words, with how many.
    std::vector<int> common(slots_.size(), 0);
    std::vector<int> touched;
    for (const auto& [word, weight] : bow) {
      if (word >= inverted_.size()) continue;
      for (const int slot : inverted_[word]) {
        if (common[static_cast<std::size_t>(slot)]++ == 0) touched.push_back(slot);
      }
    }
    std::vector<Scored> shared;
    shared.reserve(touched.size());
    int max_common = 0;
    for (const int slot : touched) {
      map::KeyFrame* kf = slots_[static_cast<std::size_t>(slot)].keyframe;
      if (kf->is_bad() || (o.exclude && o.exclude(kf))) continue;
      const int n = common[static_cast<std::size_t>(slot)];
      max_common = std::max(max_common, n);
      shared.push_back({kf, n, 0.0, slot});
    }
    std::sort(shared.begin(), shared.end(), by_id);
    // 2. Score those sharing enough words.
    const double min_common = o.min_common_share * max_common;
    for (Scored& c : shared) {
      if (c.common < min_common) continue;
      c.score = l1_score(bow, slots_[static_cast<std::size_t>(c.slot)].description->bow);
      if (c.score >= o.min_score) scores.push_back(c);
    }
  }
  const auto scored = [&](const map::KeyFrame* kf) -> const Scored* {
    const auto it = std::lower_bound(scores.begin(), scores.end(), kf->id(),
                                     [](const Scored& a, long id) { return a.keyframe->id() < id; });
    return it != scores.end() && it->keyframe == kf ? &*it : nullptr;
  };
  // 3. Sum each scored keyframe's score with its covisible neighbours' (outside the database lock:
  //    the covisibility graph has its own).
  std::vector<PlaceCandidate> groups;
  double best_group = 0;
  for (const Scored& k : scores) {
    PlaceCandidate c{k.keyframe, k.score, k.score, k.common};
    for (map::KeyFrame* n : k.keyframe->best_covisibles(o.group_size)) {
      const Scored* other = scored(n);
      if (!other) continue;
      c.group_score += other->score;
      if (other->score > c.score) {
        c.score = other->score;
        c.keyframe = n;
        c.common_words = other->common;
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
