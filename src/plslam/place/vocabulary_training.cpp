#include "plslam/place/vocabulary_training.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <random>
#include <unordered_set>

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::place {
namespace {

// mt19937_64 is fully specified by the standard, and so is this conversion: the same seed trains
// the same vocabulary with any standard library.
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

struct Cluster {
  Descriptor256 centre{};
  std::vector<std::uint32_t> members;
};

// Bitwise majority of the members (a bit is set when more than half of them have it): the
// centre that minimises the summed Hamming distance, as the mean does for squared distances.
Descriptor256 majority(const std::vector<Descriptor256>& all, const std::vector<std::uint32_t>& members) {
  std::array<std::uint32_t, 256> ones{};
  for (std::uint32_t m : members) {
    for (int w = 0; w < 4; ++w) {
      for (std::uint64_t x = all[m][static_cast<std::size_t>(w)]; x != 0; x &= x - 1) {
        ++ones[static_cast<std::size_t>(64 * w + std::countr_zero(x))];
      }
    }
  }
  Descriptor256 c{};
  for (std::size_t b = 0; b < 256; ++b) {
    if (2 * ones[b] > members.size()) c[b / 64] |= std::uint64_t{1} << (b % 64);
  }
  return c;
}

// k-means++ seeding: each next centre is drawn with probability proportional to the squared
// distance to the nearest centre so far. Fewer than k centres when the members run out of
// distinct descriptors.
std::vector<Descriptor256> seed_centres(const std::vector<Descriptor256>& all, const std::vector<std::uint32_t>& members,
                                        int k, std::mt19937_64& rng) {
  std::vector<Descriptor256> centres;
  centres.push_back(all[members[static_cast<std::size_t>(uniform01(rng) * static_cast<double>(members.size()))]]);
  std::vector<double> d2(members.size());
  for (std::size_t j = 0; j < members.size(); ++j) {
    const double d = hamming(all[members[j]], centres[0]);
    d2[j] = d * d;
  }
  while (static_cast<int>(centres.size()) < k) {
    double total = 0.0;
    for (double v : d2) total += v;
    if (total <= 0.0) break;
    const double r = uniform01(rng) * total;
    double cumulative = 0.0;
    std::size_t pick = members.size() - 1;
    for (std::size_t j = 0; j < members.size(); ++j) {
      cumulative += d2[j];
      if (cumulative > r) {
        pick = j;
        break;
      }
    }
    centres.push_back(all[members[pick]]);
    for (std::size_t j = 0; j < members.size(); ++j) {
      const double d = hamming(all[members[j]], centres.back());
      d2[j] = std::min(d2[j], d * d);
    }
  }
  return centres;
}

// One node's k-majority clustering; returns the non-empty clusters.
std::vector<Cluster> k_majority(const std::vector<Descriptor256>& all, const std::vector<std::uint32_t>& members, int k,
                                int max_iterations, std::mt19937_64& rng) {
  std::vector<Cluster> clusters;
  for (const auto& c : seed_centres(all, members, k, rng)) clusters.push_back({c, {}});
  std::vector<std::uint32_t> assignment(members.size(), 0), previous;
  for (int it = 0; it < max_iterations; ++it) {
    for (auto& c : clusters) c.members.clear();
    for (std::size_t j = 0; j < members.size(); ++j) {
      const auto& d = all[members[j]];
      std::uint32_t best = 0;
      int best_distance = hamming(d, clusters[0].centre);
      for (std::uint32_t c = 1; c < clusters.size(); ++c) {
        const int dist = hamming(d, clusters[c].centre);
        if (dist < best_distance) {
          best_distance = dist;
          best = c;
        }
      }
      assignment[j] = best;
      clusters[best].members.push_back(members[j]);
    }
    if (assignment == previous) break;
    previous = assignment;
    for (auto& c : clusters) {
      if (!c.members.empty()) c.centre = majority(all, c.members);  // an empty one keeps its centre
    }
  }
  std::erase_if(clusters, [](const Cluster& c) { return c.members.empty(); });
  return clusters;
}

}  // namespace

void VocabularyTrainingOptions::validate() const {
  if (k < 2 || k > 256) throw InputError("--k", fmt::format("branching factor {} out of range 2 to 256", k));
  if (levels < 1 || levels > 16) throw InputError("--levels", fmt::format("{} levels out of range 1 to 16", levels));
  if (std::pow(static_cast<double>(k), levels) > double{1 << 24}) {
    throw InputError("--levels", fmt::format("k^L = {}^{} words is more than 2^24", k, levels));
  }
  if (max_iterations < 1) throw InputError("", "max_iterations must be at least 1");
}

Vocabulary train_vocabulary(const std::vector<std::vector<Descriptor256>>& images,
                            const VocabularyTrainingOptions& options, const TrainingProgress& progress) {
  options.validate();
  std::vector<Descriptor256> all;
  for (const auto& image : images) all.insert(all.end(), image.begin(), image.end());
  if (all.empty()) throw InputError("", "no descriptors to train the vocabulary on");

  std::mt19937_64 rng(options.seed);
  std::vector<Vocabulary::Node> nodes(1);
  std::vector<std::uint32_t> depth{0};
  std::vector<std::vector<std::uint32_t>> members(1);
  members[0].resize(all.size());
  for (std::size_t i = 0; i < all.size(); ++i) members[0][i] = static_cast<std::uint32_t>(i);
  // Breadth first, so the children of successive nodes are appended contiguously (file format).
  std::size_t done = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    std::vector<std::uint32_t> mine = std::move(members[i]);
    members[i] = {};
    if (depth[i] < static_cast<std::uint32_t>(options.levels) && mine.size() > 1) {
      auto clusters = k_majority(all, mine, options.k, options.max_iterations, rng);
      if (clusters.size() > 1) {
        nodes[i].first_child = static_cast<std::uint32_t>(nodes.size());
        nodes[i].child_count = static_cast<std::uint32_t>(clusters.size());
        for (auto& c : clusters) {
          Vocabulary::Node child;
          child.centre = c.centre;
          nodes.push_back(child);
          depth.push_back(depth[i] + 1);
          members.push_back(std::move(c.members));
        }
        continue;
      }
    }
    done += mine.size();  // a leaf: its descriptors are placed
    if (progress) progress(done, all.size());
  }
  std::int32_t words = 0;
  for (auto& n : nodes) {
    if (n.child_count == 0) n.word = words++;
  }

  // IDF over the training images, counting each word once per image.
  const Vocabulary unweighted(options.k, options.levels, nodes, std::vector<float>(static_cast<std::size_t>(words), 0.0f));
  std::vector<std::uint32_t> images_with(static_cast<std::size_t>(words), 0);
  std::size_t non_empty = 0;
  for (const auto& image : images) {
    if (image.empty()) continue;
    ++non_empty;
    std::unordered_set<std::uint32_t> seen;
    for (const auto& d : image) seen.insert(unweighted.word_of(d));
    for (std::uint32_t w : seen) ++images_with[w];
  }
  std::vector<float> weights(static_cast<std::size_t>(words));
  for (std::size_t w = 0; w < weights.size(); ++w) {
    // A word no training image reaches (its centre moved away from its members) is as rare as can be.
    const double n = std::max<std::uint32_t>(images_with[w], 1);
    weights[w] = static_cast<float>(std::log(static_cast<double>(non_empty) / n));
  }
  return Vocabulary(options.k, options.levels, std::move(nodes), std::move(weights));
}

}  // namespace plslam::place
