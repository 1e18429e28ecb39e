#include "plslam/place/recognition_eval.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "plslam/map/map.h"
#include "plslam/place/keyframe_database.h"

namespace plslam::place {

double RecognitionEvalResult::recall_at_precision(double precision) const {
  double best = 0;
  for (const auto& p : curve) {
    if (p.precision >= precision) best = std::max(best, p.recall);
  }
  return best;
}

RecognitionEvalResult evaluate_place_recognition(const std::vector<PlaceSample>& samples,
                                                 std::shared_ptr<const Vocabulary> vocabulary,
                                                 const RecognitionEvalOptions& o) {
  for (std::size_t i = 1; i < samples.size(); ++i) {
    if (samples[i].timestamp < samples[i - 1].timestamp)
      throw std::invalid_argument("evaluate_place_recognition: samples must be in time order");
  }
  // The real database over real keyframes (without covisibility edges: each is its own group).
  map::Map map;
  KeyframeDatabase db(std::move(vocabulary));
  std::vector<map::KeyFrame*> keyframes;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    auto data = std::make_shared<map::FrameData>();
    data->frame_id = static_cast<long>(i);
    data->timestamp = samples[i].timestamp;
    data->descriptors = samples[i].descriptors;
    keyframes.push_back(map.create_keyframe(std::move(data), geometry::SE3()));
  }
  const double cos_max = std::cos(o.max_angle_deg * std::numbers::pi / 180.0);
  auto true_match = [&](std::size_t a, std::size_t b) {
    return (samples[a].centre - samples[b].centre).norm() <= o.max_distance_m &&
           samples[a].direction.dot(samples[b].direction) >= cos_max;
  };
  RecognitionEvalResult r;
  std::size_t added = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    while (added < i && samples[added].timestamp < samples[i].timestamp - o.exclude_recent_s) db.add(keyframes[added++]);
    if (added == 0) continue;
    RecognitionQuery q;
    q.sample = i;
    for (std::size_t j = 0; j < added && !q.has_true_match; ++j) q.has_true_match = true_match(i, j);
    const auto bow = db.describe(samples[i].descriptors).bow;
    const auto candidates = db.query(bow);
    if (!candidates.empty()) {
      q.top = candidates.front().keyframe->frame_id();
      q.raw_score = candidates.front().score;
      // DBoW2's normalised similarity: raw scores depend on the scene (texture, number of
      // features), so a candidate is judged against how well the query matches the keyframe just
      // before it, the best score it can expect from the same place.
      const double reference = l1_score(bow, db.describe(samples[i - 1].descriptors).bow);
      q.score = reference > 0 ? q.raw_score / reference : 0;
      const auto& top = samples[static_cast<std::size_t>(q.top)];
      q.correct = true_match(i, static_cast<std::size_t>(q.top));
      q.top_distance_m = (samples[i].centre - top.centre).norm();
      const double cos_angle = std::clamp(samples[i].direction.dot(top.direction), -1.0, 1.0);
      q.top_angle_deg = std::acos(cos_angle) * 180.0 / std::numbers::pi;
    }
    r.with_true_match += q.has_true_match;
    r.queries.push_back(q);
  }
  // Thresholds at every distinct top score, highest first.
  for (std::size_t k = 0; k < r.queries.size(); ++k) {
    if (r.queries[k].top >= 0) r.ranked.push_back(k);
  }
  std::stable_sort(r.ranked.begin(), r.ranked.end(),
                   [&](std::size_t a, std::size_t b) { return r.queries[a].score > r.queries[b].score; });
  const auto answered = [&](std::size_t k) -> const RecognitionQuery& { return r.queries[r.ranked[k]]; };
  PrPoint p;
  for (std::size_t k = 0; k < r.ranked.size(); ++k) {
    ++p.accepted;
    p.correct += answered(k).correct;
    if (k + 1 < r.ranked.size() && answered(k + 1).score == answered(k).score) continue;
    p.threshold = answered(k).score;
    p.precision = static_cast<double>(p.correct) / p.accepted;
    p.recall = r.with_true_match > 0 ? static_cast<double>(p.correct) / r.with_true_match : 0;
    r.curve.push_back(p);
  }
  return r;
}

}  // namespace plslam::place
