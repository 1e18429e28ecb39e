// The YAML configuration of `plslam run` (--config): parse, apply to a preset, validate.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/core/config_reader.h"
#include "plslam/system/system_config.h"

namespace plslam::fuzz {

int fuzz_config(const std::uint8_t* data, std::size_t size) {
  return expect_only_input_errors("config", [&] {
    const auto reader = ConfigReader::from_string(as_string(data, size), "fuzz.yaml");
    (void)system::apply_config(reader, size % 2 ? system::SystemOptions::kitti() : system::SystemOptions::euroc());
  });
}

}  // namespace plslam::fuzz
