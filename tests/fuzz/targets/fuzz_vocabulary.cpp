// plslam vocabulary files (place/vocabulary.h), read by place recognition.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/place/vocabulary.h"

namespace plslam::fuzz {

int fuzz_vocabulary(const std::uint8_t* data, std::size_t size) {
  return expect_only_input_errors("vocabulary", [&] {
    const auto voc = place::Vocabulary::from_bytes(as_string(data, size), "vocab.bin");
    // A vocabulary that loads must also transform: descend every path without leaving the tree.
    const std::vector<place::Descriptor256> probe = {{0, 0, 0, 0}, {~0ull, ~0ull, ~0ull, ~0ull}, {1, 2, 3, 4}};
    place::FeatureVector fv;
    (void)voc.transform(probe, &fv, 1);
  });
}

}  // namespace plslam::fuzz
