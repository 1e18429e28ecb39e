// libFuzzer's entry point for one target, chosen at compile time (PLSLAM_FUZZ_FUNCTION).
#include <cstddef>
#include <cstdint>

namespace plslam::fuzz {
int PLSLAM_FUZZ_FUNCTION(const std::uint8_t* data, std::size_t size);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return plslam::fuzz::PLSLAM_FUZZ_FUNCTION(data, size);
}
