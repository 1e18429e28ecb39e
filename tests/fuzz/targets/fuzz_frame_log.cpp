// frames.csv of a run, read by `plslam eval --frames`.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/eval/frame_log.h"

namespace plslam::fuzz {

int fuzz_frame_log(const std::uint8_t* data, std::size_t size) {
  return expect_only_input_errors("frame_log", [&] {
    const auto log = eval::parse_frame_log(as_string(data, size), "frames.csv");
    for (const auto& column : log.header) (void)log.numbers(column);
  });
}

}  // namespace plslam::fuzz
