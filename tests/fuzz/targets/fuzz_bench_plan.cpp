// What `plslam bench slam --report-from` reads from folders collected from anywhere: plan.json; and
// the published figures file (data/published/slam_results.yaml, or one under $PLSLAM_DATA_DIR).
#include "fuzz/targets/fuzz_support.h"
#include "plslam/bench/bench_plan.h"
#include "plslam/bench/published_results.h"

namespace plslam::fuzz {

int fuzz_bench_plan(const std::uint8_t* data, std::size_t size) {
  return expect_only_input_errors("bench_plan", [&] {
    (void)bench::parse_bench_plan(as_string(data, size), "plan.json");
  });
}

int fuzz_published_results(const std::uint8_t* data, std::size_t size) {
  return expect_only_input_errors("published_results", [&] {
    (void)bench::parse_published_results(as_string(data, size), "slam_results.yaml");
  });
}

}  // namespace plslam::fuzz
