#pragma once
// A frame as words of the vocabulary: the bag-of-words vector (TF-IDF weights, L1-normalised) that
// place recognition scores, and the feature vector (the frame's features grouped by vocabulary
// node a few levels above the words) that limits descriptor matching to features in one node.
#include <cstdint>
#include <utility>
#include <vector>

namespace plslam::place {

// (word id, weight), sorted by word id, weights summing to 1: flat, so scoring is a merge.
using BowVector = std::vector<std::pair<std::uint32_t, double>>;

// (node id, indices of the frame's features under that node), sorted by node id.
using FeatureVector = std::vector<std::pair<std::uint32_t, std::vector<std::uint32_t>>>;

// DBoW2's L1 score of two L1-normalised vectors: 1 - |a - b|_1 / 2, in [0, 1]; 1 for the same
// words in the same proportions, 0 for no word in common.
double l1_score(const BowVector& a, const BowVector& b);

}  // namespace plslam::place
