// `plslam bench features`: runs on real frames and reports the documented JSON keys.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace plslam {
namespace {

TEST(BenchFeaturesCli, JsonHasEveryStageOnKitti) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto r = test::run_cli("bench features '" + (data / "kitti/sequences/06").string() + "' --frames 2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("frames").get<int>(), 2);
  for (const char* key : {"pyramid_ms", "fast_ms", "ssc_ms", "quadtree_ms", "orb_ms", "stereo_points_ms", "keypoints",
                          "stereo_matches", "uniformity_cv"}) {
    ASSERT_TRUE(j.contains(key)) << key;
    EXPECT_TRUE(j.at(key).at("median").is_number()) << key;
  }
  EXPECT_GT(j["fast_ms"]["median"].get<double>(), 0.0);
  EXPECT_EQ(j["keypoints"]["median"].get<double>(), 2000.0);  // KITTI default budget
  EXPECT_EQ(j["keypoints"]["quadtree"]["median"].get<double>(), 2000.0);
  EXPECT_GT(j["keypoints"]["fast_candidates"]["median"].get<double>(), 2000.0);
  EXPECT_GT(j["stereo_matches"]["share"]["median"].get<double>(), 0.5);
  EXPECT_GT(j["uniformity_cv"]["quadtree"]["median"].get<double>(), 0.0);
  EXPECT_NE(j["config"]["fast_impl"].get<std::string>(), "auto");  // resolved to what ran

  // cv::FAST stays selectable for comparisons and finds the very same corners.
  const auto r_cv = test::run_cli("bench features '" + (data / "kitti/sequences/06").string() +
                                  "' --frames 2 --json --fast-impl opencv");
  ASSERT_EQ(r_cv.exit_code, 0) << r_cv.err;
  const auto j_cv = nlohmann::json::parse(r_cv.out);
  EXPECT_EQ(j_cv["config"]["fast_impl"].get<std::string>(), "opencv");
  EXPECT_EQ(j_cv["keypoints"]["fast_candidates"], j["keypoints"]["fast_candidates"]);
  EXPECT_EQ(j_cv["uniformity_cv"], j["uniformity_cv"]);
  EXPECT_EQ(j_cv["stereo_matches"]["median"], j["stereo_matches"]["median"]);
}

TEST(BenchFeaturesCli, HumanOutputAndBadInput) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto ok = test::run_cli("bench features '" + (data / "euroc/V1_01_easy_micro").string() + "' --frames 1");
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_NE(ok.out.find("SSC"), std::string::npos);
  EXPECT_NE(ok.out.find("quadtree"), std::string::npos);
  const auto missing = test::run_cli("bench features /nonexistent/sequence --json");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_TRUE(missing.out.empty());
  EXPECT_EQ(test::run_cli("bench features '" + (data / "euroc/V1_01_easy_micro").string() + "' --fast-impl neon").exit_code, 2);
  EXPECT_EQ(test::run_cli("bench").exit_code, 2);  // a subcommand is required
}

}  // namespace
}  // namespace plslam
