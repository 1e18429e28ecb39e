// The vocabulary on descriptors with known structure: clusters around random prototypes must
// become words, training is reproducible, the file round-trips and every damaged file is refused.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/place/bow_vector.h"
#include "plslam/place/vocabulary.h"
#include "plslam/place/vocabulary_training.h"
#include "place/synthetic_descriptors.h"

namespace plslam::place {
namespace {

// `clusters` random prototypes (about 128 bits apart); image i holds `per_image` noisy copies
// (8 flipped bits) of prototypes i % clusters and (i + 1) % clusters.
struct Synthetic {
  std::vector<Descriptor256> prototypes;
  std::vector<std::vector<Descriptor256>> images;
  std::vector<std::vector<int>> labels;
};

Synthetic synthetic(int clusters, int n_images, int per_image, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Synthetic s;
  for (int c = 0; c < clusters; ++c) s.prototypes.push_back(random_descriptor(rng));
  for (int i = 0; i < n_images; ++i) {
    s.images.emplace_back();
    s.labels.emplace_back();
    for (int j = 0; j < per_image; ++j) {
      const int label = (i + j % 2) % clusters;
      s.images.back().push_back(flip_bits(s.prototypes[static_cast<std::size_t>(label)], 8, rng));
      s.labels.back().push_back(label);
    }
  }
  return s;
}

TEST(Vocabulary, ClustersAroundPrototypesBecomeOneWordEach) {
  const auto s = synthetic(8, 16, 40, 3);
  VocabularyTrainingOptions o;
  o.k = 8;
  o.levels = 1;
  const Vocabulary voc = train_vocabulary(s.images, o);
  EXPECT_EQ(voc.size(), 8u);
  std::vector<std::set<std::uint32_t>> words_of_label(8);
  for (std::size_t i = 0; i < s.images.size(); ++i) {
    for (std::size_t j = 0; j < s.images[i].size(); ++j) {
      words_of_label[static_cast<std::size_t>(s.labels[i][j])].insert(voc.word_of(s.images[i][j]));
    }
  }
  std::set<std::uint32_t> all_words;
  for (const auto& w : words_of_label) {
    EXPECT_EQ(w.size(), 1u) << "one prototype's copies fell into several words";
    all_words.insert(w.begin(), w.end());
  }
  EXPECT_EQ(all_words.size(), 8u) << "two prototypes share a word";
  // Each word occurs in 4 of the 16 images: IDF = log(16 / 4).
  for (std::uint32_t w = 0; w < 8; ++w) EXPECT_NEAR(voc.word_weight(w), std::log(4.0), 1e-6);
}

TEST(Vocabulary, DeeperTreeKeepsEveryLeafWithinItsLevelsAndIsReproducible) {
  const auto s = synthetic(30, 30, 60, 5);
  VocabularyTrainingOptions o;
  o.k = 4;
  o.levels = 3;
  o.seed = 11;
  const Vocabulary a = train_vocabulary(s.images, o);
  const Vocabulary b = train_vocabulary(s.images, o);
  EXPECT_EQ(a.to_bytes(), b.to_bytes()) << "training is not deterministic for a seed";
  EXPECT_LE(a.size(), 64u);
  EXPECT_GE(a.size(), 20u);
  for (const auto& n : a.nodes()) EXPECT_LE(n.depth, 3u);
  std::size_t progress_calls = 0, last_done = 0;
  train_vocabulary(s.images, o, [&](std::size_t done, std::size_t total) {
    ++progress_calls;
    EXPECT_GE(done, last_done);
    EXPECT_LE(done, total);
    last_done = done;
  });
  EXPECT_GT(progress_calls, 0u);
  EXPECT_EQ(last_done, 30u * 60u);
}

TEST(Vocabulary, TransformGivesNormalisedSortedWordsAndAFeatureVectorOverEveryFeature) {
  const auto s = synthetic(16, 20, 50, 7);
  VocabularyTrainingOptions o;
  o.k = 4;
  o.levels = 2;
  const Vocabulary voc = train_vocabulary(s.images, o);
  FeatureVector fv;
  const BowVector bow = voc.transform(s.images[3], &fv, 1);
  double sum = 0.0;
  for (std::size_t i = 0; i < bow.size(); ++i) {
    sum += bow[i].second;
    if (i > 0) {
      EXPECT_LT(bow[i - 1].first, bow[i].first);
    }
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  std::vector<int> seen(s.images[3].size(), 0);
  for (std::size_t i = 0; i < fv.size(); ++i) {
    if (i > 0) {
      EXPECT_LT(fv[i - 1].first, fv[i].first);
    }
    EXPECT_LE(voc.nodes()[fv[i].first].depth, 1u);
    for (auto f : fv[i].second) ++seen[f];
  }
  for (int c : seen) EXPECT_EQ(c, 1);
  // All the way up: one node, the root, holding every feature.
  voc.transform(s.images[3], &fv, 2);
  ASSERT_EQ(fv.size(), 1u);
  EXPECT_EQ(fv[0].first, 0u);
  EXPECT_EQ(fv[0].second.size(), s.images[3].size());
}

TEST(Vocabulary, ScoreIsOneForTheSameImageAndHigherForTheSamePlace) {
  const auto s = synthetic(20, 20, 60, 9);
  VocabularyTrainingOptions o;
  o.k = 8;
  o.levels = 2;
  const Vocabulary voc = train_vocabulary(s.images, o);
  const BowVector a = voc.transform(s.images[10]);
  EXPECT_NEAR(l1_score(a, a), 1.0, 1e-12);
  // Image 10 shows prototypes 10 and 11; image 11 shows 11 and 12; image 15 shows 15 and 16.
  std::mt19937_64 rng(1);
  std::vector<Descriptor256> revisit;
  for (const auto& d : s.images[10]) revisit.push_back(flip_bits(d, 4, rng));
  const double same_place = l1_score(a, voc.transform(revisit));
  const double neighbour = l1_score(a, voc.transform(s.images[11]));
  const double elsewhere = l1_score(a, voc.transform(s.images[15]));
  EXPECT_GT(same_place, 0.8);
  EXPECT_GT(same_place, neighbour);
  EXPECT_GT(neighbour, elsewhere);
  EXPECT_LT(elsewhere, 0.1);
}

TEST(BowVector, L1ScoreOfKnownVectors) {
  const BowVector a = {{1, 0.5}, {2, 0.5}}, b = {{2, 0.5}, {3, 0.5}}, c = {{7, 1.0}};
  EXPECT_NEAR(l1_score(a, a), 1.0, 1e-15);
  EXPECT_NEAR(l1_score(a, b), 0.5, 1e-15);  // |a - b|_1 = 0.5 + 0 + 0.5
  EXPECT_NEAR(l1_score(a, c), 0.0, 1e-15);
  EXPECT_NEAR(l1_score(a, {}), 0.0, 1e-15);
}

Vocabulary small_vocabulary() {
  const auto s = synthetic(12, 12, 30, 13);
  VocabularyTrainingOptions o;
  o.k = 3;
  o.levels = 3;
  return train_vocabulary(s.images, o);
}

TEST(VocabularyFile, RoundTripKeepsEveryByteAndTransform) {
  const Vocabulary voc = small_vocabulary();
  const std::string bytes = voc.to_bytes();
  const Vocabulary back = Vocabulary::from_bytes(bytes, "mem");
  EXPECT_EQ(back.to_bytes(), bytes);
  EXPECT_EQ(back.k(), 3);
  EXPECT_EQ(back.levels(), 3);
  const auto s = synthetic(12, 12, 30, 13);
  EXPECT_EQ(back.transform(s.images[5]), voc.transform(s.images[5]));
}

// Each damage is refused with an InputError naming the source and the problem.
void expect_refused(const std::string& bytes, const std::string& problem) {
  try {
    Vocabulary::from_bytes(bytes, "voc.bin");
    FAIL() << "accepted a vocabulary that should say: " << problem;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("voc.bin"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
  }
}

std::uint64_t fnv1a(const char* data, std::size_t n) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

// Rewrites the header checksum so that only the structure checks can catch the damage.
std::string with_valid_checksum(std::string bytes) {
  const std::uint64_t h = fnv1a(bytes.data() + 40, bytes.size() - 40);
  std::memcpy(bytes.data() + 32, &h, 8);
  return bytes;
}

TEST(VocabularyFile, DamagedFilesAreRefused) {
  const std::string good = small_vocabulary().to_bytes();
  expect_refused("", "shorter than the header");
  expect_refused(good.substr(0, 39), "shorter than the header");
  std::string magic = good;
  magic[0] = 'X';
  expect_refused(magic, "magic");
  std::string version = good;
  version[8] = 9;
  expect_refused(version, "format version 9");
  std::string type = good;
  type[12] = 2;
  expect_refused(type, "descriptor type 2");
  expect_refused(good.substr(0, good.size() - 1), "truncated");
  expect_refused(good + "x", "truncated");
  std::string flipped = good;
  flipped[60] ^= 1;
  expect_refused(flipped, "checksum mismatch");
  std::string huge = good;
  const std::uint32_t many = 0xFFFFFFFFu;
  std::memcpy(huge.data() + 24, &many, 4);  // node count
  expect_refused(huge, "implausible sizes");

  // Structure damage behind a valid checksum.
  const std::uint32_t nodes = *reinterpret_cast<const std::uint32_t*>(good.data() + 24);
  const std::size_t first_child = 40 + 32 * std::size_t{nodes}, child_count = first_child + 4 * std::size_t{nodes};
  const std::size_t word_ids = child_count + 4 * std::size_t{nodes};
  std::string cycle = good;
  const std::uint32_t zero = 0;
  std::memcpy(cycle.data() + first_child, &zero, 4);  // the root its own first child
  expect_refused(with_valid_checksum(cycle), "inconsistent vocabulary");
  std::string bad_word = good;
  std::int32_t word = -1;
  for (std::uint32_t i = 0; i < nodes; ++i) {
    std::uint32_t count = 0;
    std::memcpy(&count, good.data() + child_count + 4 * i, 4);
    if (count == 0) {
      word = 1 << 30;
      std::memcpy(bad_word.data() + word_ids + 4 * i, &word, 4);
      break;
    }
  }
  expect_refused(with_valid_checksum(bad_word), "word id");
  std::string too_many_children = good;
  const std::uint32_t nine = 9;
  std::memcpy(too_many_children.data() + child_count, &nine, 4);
  expect_refused(with_valid_checksum(too_many_children), "more than k");
  std::string nan_weight = good;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan_weight.data() + nan_weight.size() - 4, &nan, 4);
  expect_refused(with_valid_checksum(nan_weight), "weights must be finite");
}

TEST(VocabularyTraining, BadOptionsAndNoDescriptorsAreInputErrors) {
  VocabularyTrainingOptions o;
  o.k = 1;
  EXPECT_THROW(o.validate(), InputError);
  o.k = 10;
  o.levels = 9;
  EXPECT_THROW(o.validate(), InputError);  // 10^9 words
  o.levels = 0;
  EXPECT_THROW(o.validate(), InputError);
  EXPECT_THROW(train_vocabulary({{}, {}}, VocabularyTrainingOptions{}), InputError);
}

TEST(VocabularyTraining, IdenticalDescriptorsGiveOneWord) {
  const Descriptor256 d{1, 2, 3, 4};
  const Vocabulary voc = train_vocabulary({{d, d, d}, {d}}, VocabularyTrainingOptions{});
  EXPECT_EQ(voc.size(), 1u);
  EXPECT_EQ(voc.word_of(d), 0u);
  EXPECT_FLOAT_EQ(voc.word_weight(0), 0.0f);  // in every image: it tells nothing
  EXPECT_TRUE(voc.transform(std::vector<Descriptor256>{d}).empty());
}

}  // namespace
}  // namespace plslam::place
