#include "plslam/place/vocabulary.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/core/input_file.h"

namespace plslam::place {
namespace {

constexpr char kMagic[8] = {'p', 'l', 's', 'v', 'o', 'c', 'a', 'b'};
constexpr std::uint32_t kVersion = 1;
constexpr std::uint32_t kOrb256 = 1;
constexpr std::size_t kHeaderBytes = 8 + 6 * 4 + 8;
constexpr std::size_t kNodeBytes = 32 + 4 + 4 + 4;
// Far above any useful vocabulary (10^6 words is ORB-SLAM's), and small enough that sizes
// computed from a header cannot overflow.
constexpr std::uint32_t kMaxNodes = 1u << 26;

std::uint64_t fnv1a(const char* data, std::size_t n) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

template <typename T>
void put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <typename T>
T get(const char*& p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  p += sizeof(T);
  return v;
}

// Checks the structure the constructor and the loader rely on; returns what is wrong, or empty.
std::string structure_problem(int k, int levels, const std::vector<Vocabulary::Node>& nodes,
                              std::size_t words) {
  if (k < 2 || k > 256) return fmt::format("branching factor k = {} (expected 2 to 256)", k);
  if (levels < 1 || levels > 16) return fmt::format("levels L = {} (expected 1 to 16)", levels);
  if (nodes.empty()) return "no nodes";
  if (words == 0) return "no words";
  // Breadth first: node 0 is the root; the children of the nodes, in order, fill 1, 2, ... with
  // no gap and no node twice. That makes every node reachable exactly once and the tree acyclic.
  std::size_t next = 1, seen_words = 0;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const auto& n = nodes[i];
    if (n.child_count > static_cast<std::uint32_t>(k)) {
      return fmt::format("node {} has {} children, more than k = {}", i, n.child_count, k);
    }
    if (n.child_count == 0) {
      if (n.word < 0 || static_cast<std::size_t>(n.word) >= words) {
        return fmt::format("leaf node {} has word id {} (expected 0 to {})", i, n.word, words - 1);
      }
      ++seen_words;
      continue;
    }
    if (n.word != -1) return fmt::format("inner node {} carries word id {}", i, n.word);
    if (n.first_child != next || n.first_child <= i) {
      return fmt::format("node {}: children start at {}, expected {} (nodes must be breadth first)", i,
                         n.first_child, next);
    }
    next += n.child_count;
    if (next > nodes.size()) return fmt::format("node {}: children run past the {} nodes", i, nodes.size());
  }
  if (next != nodes.size()) return fmt::format("{} of {} nodes are nobody's child", nodes.size() - next, nodes.size());
  if (nodes[0].child_count == 0 && nodes.size() != 1) return "the root has no children";
  if (seen_words != words) return fmt::format("{} leaves for {} words", seen_words, words);
  return {};
}

}  // namespace

Vocabulary::Vocabulary(int k, int levels, std::vector<Node> nodes, std::vector<float> word_weights)
    : Vocabulary(k, levels, std::move(nodes), std::move(word_weights), 0) {
  const std::string body = body_bytes();
  checksum_ = fnv1a(body.data(), body.size());
}

Vocabulary::Vocabulary(int k, int levels, std::vector<Node> nodes, std::vector<float> word_weights,
                       std::uint64_t checksum)
    : k_(k), levels_(levels), nodes_(std::move(nodes)), word_weights_(std::move(word_weights)), checksum_(checksum) {
  if (const auto problem = structure_problem(k_, levels_, nodes_, word_weights_.size()); !problem.empty()) {
    throw std::invalid_argument("Vocabulary: " + problem);
  }
  word_nodes_.assign(word_weights_.size(), std::numeric_limits<std::uint32_t>::max());
  nodes_[0].depth = 0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const Node& n = nodes_[i];
    for (std::uint32_t c = 0; c < n.child_count; ++c) nodes_[n.first_child + c].depth = n.depth + 1;
    if (n.child_count == 0) {
      if (word_nodes_[static_cast<std::size_t>(n.word)] != std::numeric_limits<std::uint32_t>::max()) {
        throw std::invalid_argument(fmt::format("Vocabulary: word {} appears twice", n.word));
      }
      word_nodes_[static_cast<std::size_t>(n.word)] = static_cast<std::uint32_t>(i);
    }
    if (n.depth > static_cast<std::uint32_t>(levels_)) {
      throw std::invalid_argument(fmt::format("Vocabulary: node {} lies deeper than L = {}", i, levels_));
    }
  }
  for (float w : word_weights_) {
    if (!std::isfinite(w) || w < 0.0f) throw std::invalid_argument("Vocabulary: word weights must be finite and >= 0");
  }
}

namespace {

// The leaf of `d`, and the last node on its path at depth <= node_depth. Always inlined, so that
// descend_popcnt and Vocabulary::descend each compile its popcounts for their own target.
[[gnu::always_inline]] inline void descend_nodes(const std::vector<Vocabulary::Node>& nodes, const Descriptor256& d,
                                                 std::uint32_t node_depth, std::uint32_t* leaf, std::uint32_t* kept) {
  std::uint32_t at = 0;
  *kept = 0;
  while (nodes[at].child_count > 0) {
    const auto& n = nodes[at];
    std::uint32_t best = n.first_child;
    int best_distance = hamming(d, nodes[best].centre);
    for (std::uint32_t c = n.first_child + 1; c < n.first_child + n.child_count; ++c) {
      const int dist = hamming(d, nodes[c].centre);
      if (dist < best_distance) {  // ties: the first child, so transforms are reproducible
        best_distance = dist;
        best = c;
      }
    }
    at = best;
    if (nodes[at].depth <= node_depth) *kept = at;
  }
  *leaf = at;
}

#if defined(__x86_64__)
// Each descriptor meets k centres per level, 4 popcounts each. The build targets baseline x86-64,
// where std::popcount is a libgcc call (__popcountdi2: 0.4 % of a whole KITTI run's profile); this
// copy uses the POPCNT instruction. Dispatched by a flag set at start-up, as in
// features/orb_descriptor.cpp (target_clones needs an ifunc resolver, which crashes under TSan).
__attribute__((target("popcnt"))) void descend_popcnt(const std::vector<Vocabulary::Node>& nodes,
                                                      const Descriptor256& d, std::uint32_t node_depth,
                                                      std::uint32_t* leaf, std::uint32_t* kept) {
  descend_nodes(nodes, d, node_depth, leaf, kept);
}
const bool kDescendWithPopcnt = (__builtin_cpu_init(), __builtin_cpu_supports("popcnt"));
#endif

}  // namespace

void Vocabulary::descend(const Descriptor256& d, int levels_up, std::uint32_t* word, std::uint32_t* node) const {
  const std::uint32_t node_depth = static_cast<std::uint32_t>(std::max(0, levels_ - levels_up));
  std::uint32_t leaf = 0, kept = 0;
#if defined(__x86_64__)
  if (kDescendWithPopcnt) {
    descend_popcnt(nodes_, d, node_depth, &leaf, &kept);
  } else {
    descend_nodes(nodes_, d, node_depth, &leaf, &kept);
  }
#else
  descend_nodes(nodes_, d, node_depth, &leaf, &kept);
#endif
  if (word) *word = static_cast<std::uint32_t>(nodes_[leaf].word);
  if (node) *node = kept;  // the leaf itself when it lies above node_depth
}

std::uint32_t Vocabulary::word_of(const Descriptor256& d) const {
  std::uint32_t w = 0;
  descend(d, 0, &w, nullptr);
  return w;
}

BowVector Vocabulary::transform(const cv::Mat& descriptors, FeatureVector* features, int levels_up) const {
  return transform(descriptors_from_mat(descriptors), features, levels_up);
}

BowVector Vocabulary::transform(const std::vector<Descriptor256>& descriptors, FeatureVector* features,
                                int levels_up) const {
  if (empty()) throw std::logic_error("Vocabulary::transform: empty vocabulary");
  std::vector<std::pair<std::uint32_t, std::uint32_t>> words(descriptors.size());  // (word, node)
  for (std::size_t i = 0; i < descriptors.size(); ++i) {
    descend(descriptors[i], levels_up, &words[i].first, features ? &words[i].second : nullptr);
  }
  // TF-IDF: each occurrence adds the word's IDF; L1 normalisation then divides by the total,
  // which is the term frequency's denominator.
  std::vector<std::uint32_t> order(descriptors.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::uint32_t>(i);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return words[a].first != words[b].first ? words[a].first < words[b].first : a < b;
  });
  BowVector bow;
  double total = 0.0;
  for (std::uint32_t i : order) {
    const std::uint32_t w = words[i].first;
    const double weight = word_weights_[w];
    if (weight <= 0.0) continue;  // a word in every training image tells nothing
    if (bow.empty() || bow.back().first != w) bow.emplace_back(w, 0.0);
    bow.back().second += weight;
    total += weight;
  }
  if (total > 0.0) {
    for (auto& [w, v] : bow) v /= total;
  }
  if (features) {
    features->clear();
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
      return words[a].second != words[b].second ? words[a].second < words[b].second : a < b;
    });
    for (std::uint32_t i : order) {
      if (features->empty() || features->back().first != words[i].second) features->emplace_back(words[i].second, std::vector<std::uint32_t>{});
      features->back().second.push_back(i);
    }
  }
  return bow;
}

std::string Vocabulary::to_bytes() const {
  const std::string body = body_bytes();
  std::string out(kMagic, sizeof(kMagic));
  put<std::uint32_t>(out, kVersion);
  put<std::uint32_t>(out, kOrb256);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(k_));
  put<std::uint32_t>(out, static_cast<std::uint32_t>(levels_));
  put<std::uint32_t>(out, static_cast<std::uint32_t>(nodes_.size()));
  put<std::uint32_t>(out, static_cast<std::uint32_t>(word_weights_.size()));
  put<std::uint64_t>(out, fnv1a(body.data(), body.size()));
  return out + body;
}

std::string Vocabulary::body_bytes() const {
  std::string body;
  body.reserve(nodes_.size() * kNodeBytes + word_weights_.size() * 4);
  for (const auto& n : nodes_) body.append(reinterpret_cast<const char*>(n.centre.data()), 32);
  for (const auto& n : nodes_) put<std::uint32_t>(body, n.first_child);
  for (const auto& n : nodes_) put<std::uint32_t>(body, n.child_count);
  for (const auto& n : nodes_) put<std::int32_t>(body, n.word);
  for (float w : word_weights_) put<float>(body, w);
  return body;
}

Vocabulary Vocabulary::from_bytes(const std::string& bytes, const std::string& source) {
  if (bytes.size() < kHeaderBytes) {
    throw InputError(source, fmt::format("not a plslam vocabulary: {} bytes, shorter than the header", bytes.size()));
  }
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    throw InputError(source, "not a plslam vocabulary (no 'plsvocab' magic)");
  }
  const char* p = bytes.data() + sizeof(kMagic);
  const auto version = get<std::uint32_t>(p);
  const auto type = get<std::uint32_t>(p);
  const auto k = get<std::uint32_t>(p);
  const auto levels = get<std::uint32_t>(p);
  const auto node_count = get<std::uint32_t>(p);
  const auto word_count = get<std::uint32_t>(p);
  const auto checksum = get<std::uint64_t>(p);
  if (version != kVersion) throw InputError(source, fmt::format("vocabulary format version {} (this plslam reads {})", version, kVersion));
  if (type != kOrb256) throw InputError(source, fmt::format("descriptor type {} (this plslam uses 1: 256-bit ORB)", type));
  if (node_count == 0 || node_count > kMaxNodes || word_count == 0 || word_count > node_count) {
    throw InputError(source, fmt::format("implausible sizes: {} nodes, {} words", node_count, word_count));
  }
  const std::size_t expected = kHeaderBytes + std::size_t{node_count} * kNodeBytes + std::size_t{word_count} * 4;
  if (bytes.size() != expected) {
    throw InputError(source, fmt::format("{} bytes, expected {} for {} nodes and {} words (truncated?)", bytes.size(),
                                         expected, node_count, word_count));
  }
  if (fnv1a(p, bytes.size() - kHeaderBytes) != checksum) throw InputError(source, "checksum mismatch (corrupt file)");
  std::vector<Node> nodes(node_count);
  for (auto& n : nodes) {
    std::memcpy(n.centre.data(), p, 32);
    p += 32;
  }
  for (auto& n : nodes) n.first_child = get<std::uint32_t>(p);
  for (auto& n : nodes) n.child_count = get<std::uint32_t>(p);
  for (auto& n : nodes) n.word = get<std::int32_t>(p);
  std::vector<float> weights(word_count);
  for (auto& w : weights) w = get<float>(p);
  if (k > 256 || levels > 16) throw InputError(source, fmt::format("implausible k = {}, L = {}", k, levels));
  try {
    // The body was checked against the header's checksum above: that is the identity.
    return Vocabulary(static_cast<int>(k), static_cast<int>(levels), std::move(nodes), std::move(weights), checksum);
  } catch (const std::invalid_argument& e) {
    throw InputError(source, std::string("inconsistent vocabulary: ") + e.what());
  }
}

Vocabulary Vocabulary::load(const std::filesystem::path& path) {
  std::ifstream in = open_input_file(path, "vocabulary file not found");
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::size_t>(in.tellg());
  std::string bytes(size, '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), static_cast<std::streamsize>(size))) throw InputError(path.string(), "read error");
  return from_bytes(bytes, path.string());
}

}  // namespace plslam::place
