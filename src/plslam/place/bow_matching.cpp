#include "plslam/place/bow_matching.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "plslam/features/orb_descriptor.h"
#include "plslam/place/descriptor256.h"

namespace plslam::place {

std::vector<std::size_t> orientation_consistent(const std::vector<double>& diffs, int bins) {
  if (bins <= 0) throw std::invalid_argument("orientation_consistent: bins must be positive");
  std::vector<std::vector<std::size_t>> hist(static_cast<std::size_t>(bins));
  for (std::size_t i = 0; i < diffs.size(); ++i) {
    double d = std::fmod(diffs[i], 360.0);
    if (d < 0) d += 360.0;
    auto b = static_cast<std::size_t>(d * bins / 360.0);
    hist[std::min(b, hist.size() - 1)].push_back(i);
  }
  // The three most populated bins (ties: the lower bin), each holding at least a tenth of the top.
  std::vector<std::size_t> order(hist.size());
  for (std::size_t b = 0; b < order.size(); ++b) order[b] = b;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return hist[a].size() > hist[b].size(); });
  std::vector<std::size_t> kept;
  const std::size_t top = hist[order[0]].size();
  for (std::size_t r = 0; r < std::min<std::size_t>(3, order.size()); ++r) {
    const auto& bin = hist[order[r]];
    if (bin.empty() || 10 * bin.size() < top) break;
    kept.insert(kept.end(), bin.begin(), bin.end());
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

std::vector<BowMatch> match_by_bow(const BowImage& q, const BowImage& t, const std::function<bool(int)>& usable,
                                   const BowMatchOptions& o) {
  if (!q.descriptors || !q.features || !t.descriptors || !t.features)
    throw std::invalid_argument("match_by_bow: descriptors and feature vectors are required");
  if (o.check_orientation && (!q.keypoints || !t.keypoints))
    throw std::invalid_argument("match_by_bow: the orientation check needs keypoints");
  const auto qd = descriptors_from_mat(*q.descriptors);
  const auto td = descriptors_from_mat(*t.descriptors);
  // Best train match of each query feature so far, and the distance of its second best: two
  // train features equally close to one query feature (repeated texture) are ambiguous too.
  std::vector<BowMatch> best_of_query(qd.size());
  std::vector<int> second_of_query(qd.size(), std::numeric_limits<int>::max());
  auto qi = q.features->begin();
  auto ti = t.features->begin();
  while (qi != q.features->end() && ti != t.features->end()) {
    if (qi->first < ti->first) {
      ++qi;
      continue;
    }
    if (ti->first < qi->first) {
      ++ti;
      continue;
    }
    for (std::uint32_t tf : ti->second) {
      const int train = static_cast<int>(tf);
      if (train >= static_cast<int>(td.size()) || (usable && !usable(train))) continue;
      int best = std::numeric_limits<int>::max(), second = best, best_q = -1;
      for (std::uint32_t qf : qi->second) {
        if (qf >= qd.size()) continue;
        // The POPCNT build of the distance: place::hamming's std::popcount is a libgcc call on
        // baseline x86-64 (0.9 % of a street loop's profile came from here).
        const int dist = features::hamming_distance(reinterpret_cast<const std::uint8_t*>(td[tf].data()),
                                                    reinterpret_cast<const std::uint8_t*>(qd[qf].data()));
        if (dist < best) {
          second = best;
          best = dist;
          best_q = static_cast<int>(qf);
        } else if (dist < second) {
          second = dist;
        }
      }
      if (best_q < 0 || best > o.max_hamming) continue;
      if (second != std::numeric_limits<int>::max() && best >= o.ratio * second) continue;
      auto& slot = best_of_query[static_cast<std::size_t>(best_q)];
      auto& slot_second = second_of_query[static_cast<std::size_t>(best_q)];
      if (slot.train < 0 || best < slot.distance) {
        if (slot.train >= 0) slot_second = slot.distance;
        slot = {best_q, train, best};
      } else {
        slot_second = std::min(slot_second, best);
      }
    }
    ++qi;
    ++ti;
  }
  std::vector<BowMatch> matches;
  for (std::size_t i = 0; i < best_of_query.size(); ++i) {
    const auto& m = best_of_query[i];
    if (m.train < 0) continue;
    if (second_of_query[i] != std::numeric_limits<int>::max() && m.distance >= o.ratio * second_of_query[i]) continue;
    matches.push_back(m);
  }
  if (o.check_orientation && !matches.empty()) {
    std::vector<double> diffs;
    diffs.reserve(matches.size());
    for (const auto& m : matches) {
      diffs.push_back((*q.keypoints)[static_cast<std::size_t>(m.query)].angle -
                      (*t.keypoints)[static_cast<std::size_t>(m.train)].angle);
    }
    std::vector<BowMatch> kept;
    for (std::size_t i : orientation_consistent(diffs, o.orientation_bins)) kept.push_back(matches[i]);
    matches = std::move(kept);
  }
  std::sort(matches.begin(), matches.end(), [](const BowMatch& a, const BowMatch& b) { return a.train < b.train; });
  return matches;
}

}  // namespace plslam::place
