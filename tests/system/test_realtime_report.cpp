// `plslam run --realtime` reports how far behind real time the run fell (issue 19): the lag of
// each frame behind the time it was due, and the frames later than one frame period.
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "plslam/system/run_report.h"
#include "support/test_support.h"

namespace plslam::system {
namespace {

TEST(RealtimeReport, FramesLaterThanOnePeriodAreCounted) {
  // 20 Hz: a frame period is 50 ms. 0 and 50 are on time (50 is not more than a period).
  const auto j = realtime_json({0, 10, 50, 50.5, 120}, 20.0);
  EXPECT_DOUBLE_EQ(j["rate_hz"].get<double>(), 20.0);
  EXPECT_EQ(j["frames"], 5);
  EXPECT_EQ(j["frames_late"], 2);
  EXPECT_DOUBLE_EQ(j["lag_ms"]["median"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(j["lag_ms"]["max"].get<double>(), 120.0);
  EXPECT_EQ(realtime_summary(j),
            "real time at 20.0 Hz: 2 of 5 frames late by more than a frame period "
            "(lag median 50.0 ms, p90 92.2, max 120.0)");
}

TEST(RealtimeReport, NoFrameMeansNoLagButSaysSo) {
  const auto j = realtime_json({}, 10.0);
  EXPECT_EQ(j["frames"], 0);
  EXPECT_EQ(j["frames_late"], 0);
  EXPECT_TRUE(j["lag_ms"]["max"].is_null());
  EXPECT_EQ(realtime_summary(j), "real time at 10.0 Hz: no frame processed");
}

// End to end: a paced run records one lag per frame, and a run without --realtime records none.
// The counts only: how late frames are depends on the machine, so no bound on the lag itself.
TEST(RealtimeReport, APacedRunReportsItsLagPerFrame) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  const auto seq = (data / "euroc/V1_01_easy_micro").string();
  const auto paced = test::run_cli("run \"" + seq + "\" --max-frames 20 --realtime --quiet --out \"" +
                                   (tmp.path() / "paced").string() + "\"");
  ASSERT_EQ(paced.exit_code, 0) << paced.err;
  EXPECT_NE(paced.err.find("real time at 20.0 Hz:"), std::string::npos) << paced.err;
  std::ifstream in(tmp.path() / "paced" / "stats.json");
  const auto stats = nlohmann::json::parse(in);
  ASSERT_TRUE(stats["realtime"].is_object());
  EXPECT_EQ(stats["realtime"]["frames"], 20);
  EXPECT_GE(stats["realtime"]["lag_ms"]["median"].get<double>(), 0.0);
  EXPECT_LE(stats["realtime"]["frames_late"].get<int>(), 20);
  EXPECT_GE(stats["local_mapping"]["max_queue"].get<int>(), 1);
  EXPECT_GE(stats["local_mapping"]["keyframes_processed"].get<int>(), 1);

  const auto unpaced = test::run_cli("run \"" + seq + "\" --max-frames 5 --sequential --quiet --out \"" +
                                     (tmp.path() / "unpaced").string() + "\"");
  ASSERT_EQ(unpaced.exit_code, 0) << unpaced.err;
  std::ifstream in2(tmp.path() / "unpaced" / "stats.json");
  const auto stats2 = nlohmann::json::parse(in2);
  EXPECT_TRUE(stats2["realtime"].is_null());
  EXPECT_EQ(stats2["local_mapping"]["max_queue"], 1);  // sequential: each keyframe is mapped at once
}

}  // namespace
}  // namespace plslam::system
