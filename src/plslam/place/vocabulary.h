#pragma once
// plslam's visual vocabulary: a tree of 256-bit cluster centres (k children per node, up to L
// levels) whose leaves are the words, with an IDF weight per word. A descriptor becomes a word by
// descending from the root to the nearest child at each level.
//
// File format (little-endian, one read, no parsing beyond checks):
//   header  char[8] "plsvocab", u32 version (1), u32 descriptor type (1: ORB, 256 bits),
//           u32 k, u32 levels, u32 node count, u32 word count, u64 FNV-1a 64 checksum of the body
//   body    node count x 32 bytes    centre descriptor of each node (the root's is zero)
//           node count x u32         first child (children of a node are contiguous)
//           node count x u32         number of children (0: a word)
//           node count x i32         word id of a leaf, -1 for an inner node
//           word count x f32         IDF weight of each word
// Nodes are stored breadth first, so every child comes after its parent and the tree has no cycle.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "plslam/place/bow_vector.h"
#include "plslam/place/descriptor256.h"

namespace plslam::place {

class Vocabulary {
 public:
  struct Node {
    Descriptor256 centre{};
    std::uint32_t first_child = 0;
    std::uint32_t child_count = 0;
    std::int32_t word = -1;
    std::uint32_t depth = 0;  // 0 for the root (derived on load, not stored)
  };

  Vocabulary() = default;
  // Takes a tree built by training (breadth first, see the file format) and its word weights;
  // throws std::invalid_argument when the structure is inconsistent.
  Vocabulary(int k, int levels, std::vector<Node> nodes, std::vector<float> word_weights);

  int k() const { return k_; }
  int levels() const { return levels_; }
  std::size_t size() const { return word_weights_.size(); }  // number of words
  bool empty() const { return word_weights_.empty(); }
  const std::vector<Node>& nodes() const { return nodes_; }
  float word_weight(std::uint32_t word) const { return word_weights_.at(word); }
  // The identity of the vocabulary: the FNV-1a 64 checksum of its file body (as in the header).
  // Map files record it, because word ids mean nothing under another vocabulary.
  std::uint64_t checksum() const { return checksum_; }

  // The word of one descriptor, and the node on its path `levels_up` levels above the leaf's
  // level L (clamped to the root; a leaf higher up is its own node).
  std::uint32_t word_of(const Descriptor256& d) const;
  void descend(const Descriptor256& d, int levels_up, std::uint32_t* word, std::uint32_t* node) const;

  // The bag of words of a frame's N x 32 CV_8U descriptors (TF-IDF, L1-normalised) and, when
  // `features` is not null, its feature vector at `levels_up` levels above the words.
  BowVector transform(const cv::Mat& descriptors, FeatureVector* features = nullptr, int levels_up = 2) const;
  BowVector transform(const std::vector<Descriptor256>& descriptors, FeatureVector* features = nullptr,
                      int levels_up = 2) const;

  // The file format above. from_bytes throws InputError(source, ...) for any inconsistency; load
  // reads the file with one read. (Writing goes through io::write_file_atomically, by the caller.)
  std::string to_bytes() const;
  static Vocabulary from_bytes(const std::string& bytes, const std::string& source);
  static Vocabulary load(const std::filesystem::path& path);

 private:
  int k_ = 0;
  int levels_ = 0;
  std::vector<Node> nodes_;
  std::vector<float> word_weights_;
  std::vector<std::uint32_t> word_nodes_;  // node of each word
  std::uint64_t checksum_ = 0;
  // The checks of the public constructor, with the body's checksum already known (from_bytes).
  Vocabulary(int k, int levels, std::vector<Node> nodes, std::vector<float> word_weights, std::uint64_t checksum);
  std::string body_bytes() const;
};

}  // namespace plslam::place
