#pragma once
// Training a Vocabulary: hierarchical k-majority clustering (k-means with Hamming distance and
// bitwise-majority centres, k-means++ seeding) of the descriptors of many images, then one IDF
// weight per word, log(images / images containing the word). Deterministic for a given seed.
#include <cstdint>
#include <functional>
#include <vector>

#include "plslam/place/descriptor256.h"
#include "plslam/place/vocabulary.h"

namespace plslam::place {

struct VocabularyTrainingOptions {
  int k = 10;       // branching factor
  int levels = 4;   // depth: at most k^levels words
  std::uint64_t seed = 1;
  int max_iterations = 10;  // k-majority rounds per node (it usually settles sooner)
  // Throws InputError naming the bad field.
  void validate() const;
};

// Called after each node is clustered: (descriptors clustered so far, descriptors in all).
using TrainingProgress = std::function<void(std::size_t, std::size_t)>;

// `images[i]` holds the descriptors of training image i. Throws InputError when there are no
// descriptors at all.
Vocabulary train_vocabulary(const std::vector<std::vector<Descriptor256>>& images,
                            const VocabularyTrainingOptions& options, const TrainingProgress& progress = {});

}  // namespace plslam::place
