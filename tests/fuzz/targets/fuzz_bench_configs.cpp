// The configurations file of `plslam bench slam --config-file`: parse, check names, apply each
// configuration's overrides to both presets.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/bench/slam_configurations.h"

namespace plslam::fuzz {

int fuzz_bench_configs(const std::uint8_t* data, std::size_t size) {
  return expect_only_input_errors("bench_configs", [&] {
    (void)bench::parse_slam_configurations(as_string(data, size), "fuzz_configs.yaml");
  });
}

}  // namespace plslam::fuzz
