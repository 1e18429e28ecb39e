// Replays every checked-in corpus input (tests/fuzz/corpus/<target>/) through its fuzz target,
// in every build: the seeds and every crash the fuzzers found stay fixed, also under ASan+UBSan.
// A target aborts when anything but plslam::InputError escapes a parser (fuzz_support.h).
#include <algorithm>
#include <fstream>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include "fuzz/targets/fuzz_bench_configs.cpp"
#include "fuzz/targets/fuzz_bench_plan.cpp"
#include "fuzz/targets/fuzz_calibration_file.cpp"
#include "fuzz/targets/fuzz_config.cpp"
#include "fuzz/targets/fuzz_datasets.cpp"
#include "fuzz/targets/fuzz_euroc_sensor.cpp"
#include "fuzz/targets/fuzz_frame_log.cpp"
#include "fuzz/targets/fuzz_image.cpp"
#include "fuzz/targets/fuzz_imu.cpp"
#include "fuzz/targets/fuzz_map_file.cpp"
#include "fuzz/targets/fuzz_trajectory.cpp"
#include "fuzz/targets/fuzz_run_folder.cpp"
#include "fuzz/targets/fuzz_vocabulary.cpp"

namespace plslam::fuzz {
namespace {

namespace fs = std::filesystem;

struct Target {
  const char* name;
  int (*run)(const std::uint8_t*, std::size_t);
};

// Every target of scripts/fuzz.sh, with its corpus folder name.
const Target kTargets[] = {
    {"config", fuzz_config},
    {"trajectory", fuzz_trajectory},
    {"euroc_sensor", fuzz_euroc_sensor},
    {"euroc_data_csv", fuzz_euroc_data_csv},
    {"euroc_groundtruth", fuzz_euroc_groundtruth},
    {"kitti_calib", fuzz_kitti_calib},
    {"kitti_times", fuzz_kitti_times},
    {"frame_log", fuzz_frame_log},
    {"image", fuzz_image},
    {"map_file", fuzz_map_file},
    {"vocabulary", fuzz_vocabulary},
    {"bench_configs", fuzz_bench_configs},
    {"bench_plan", fuzz_bench_plan},
    {"published_results", fuzz_published_results},
    {"calibration_file", fuzz_calibration_file},
    {"run_folder", fuzz_run_folder},
    {"imu_csv", fuzz_imu_csv},
    {"imu_sensor", fuzz_imu_sensor},
};

class FuzzReplay : public testing::TestWithParam<Target> {};

TEST_P(FuzzReplay, EveryCorpusInputIsAcceptedOrRefusedWithAnInputError) {
  const fs::path dir = fs::path(PLSLAM_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / GetParam().name;
  ASSERT_TRUE(fs::is_directory(dir)) << dir;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file()) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 3u) << "a target needs seeds: " << dir;
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    const std::string bytes = s.str();
    SCOPED_TRACE(f.string());
    EXPECT_EQ(GetParam().run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), 0);
  }
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzReplay, testing::ValuesIn(kTargets),
                         [](const testing::TestParamInfo<Target>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace plslam::fuzz
