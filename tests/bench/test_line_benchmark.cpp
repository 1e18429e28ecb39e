// The line benchmark's JSON carries every key `plslam bench features` promises, with sane values.
#include <gtest/gtest.h>

#include "features/line_synthetic_scene.h"
#include "plslam/bench/line_benchmark.h"
#include "plslam/io/dataset.h"
#include "support/test_support.h"

namespace plslam::bench {
namespace {

TEST(LineBenchmark, ReportsAllKeysOnSyntheticFrames) {
  const auto a = test::make_line_scene(false, 1), b = test::make_line_scene(true, 2);
  const nlohmann::json j = benchmark_lines({{a.left, a.right}, {b.left, b.right}}, a.calib);
  for (const char* key : {"lsd_ms", "fast_lines_ms", "merge_ms", "lbd_ms", "stereo_lines_ms", "lines_detected",
                          "lines_after_merge", "stereo_line_matches", "lines_image_ms", "opencv_lbd_ms"}) {
    ASSERT_TRUE(j.contains(key)) << key;
    EXPECT_GE(j[key]["p90"].get<double>(), j[key]["median"].get<double>()) << key;
    EXPECT_GE(j[key]["median"].get<double>(), 0.0) << key;
  }
  EXPECT_EQ(j["frames"].get<int>(), 2);
  EXPECT_GT(j["lsd_ms"]["median"].get<double>(), 0.0);
  EXPECT_GE(j["lines_detected"]["median"].get<double>(), j["lines_after_merge"]["median"].get<double>());
  EXPECT_GE(j["stereo_line_matches"]["median"].get<double>(), 10.0);
  EXPECT_GT(j["lines_speedup_vs_opencv"].get<double>(), 0.0);
  EXPECT_THROW(benchmark_lines({}, a.calib), std::invalid_argument);
}

}  // namespace
}  // namespace plslam::bench

namespace plslam::bench {
namespace {

TEST(LineBenchmark, RealSequencesThroughDatasetReader) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  io::DatasetOptions d;
  d.max_frames = 3;
  LineBenchmarkOptions kitti;
  kitti.extractor = features::LineExtractorOptions::kitti();
  kitti.reference = false;
  const auto jk = benchmark_lines(*io::open_dataset(data / "kitti/sequences/06", d), 0, kitti);
  EXPECT_EQ(jk["frames"].get<int>(), 3);
  EXPECT_GE(jk["stereo_line_matches"]["median"].get<double>(), 100.0);
  EXPECT_FALSE(jk.contains("lsd_ms"));
  LineBenchmarkOptions euroc;
  euroc.reference = false;
  const auto je = benchmark_lines(*io::open_dataset(data / "euroc/V1_01_easy_micro", d), 2, euroc);
  EXPECT_EQ(je["frames"].get<int>(), 2);
  EXPECT_LE(je["lines_after_merge"]["median"].get<double>(), je["lines_detected"]["median"].get<double>());
  EXPECT_GE(je["stereo_line_matches"]["median"].get<double>(), 30.0);
}

}  // namespace
}  // namespace plslam::bench
