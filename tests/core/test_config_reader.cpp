#include <gtest/gtest.h>

#include "plslam/core/config_reader.h"
#include "plslam/core/error.h"
#include "support/test_support.h"

namespace plslam {
namespace {

TEST(ConfigReader, ReadsSectionsAndKeepsDefaults) {
  const auto cfg = ConfigReader::from_string("features:\n  n_points: 2000\n  fast: 7\nkeyframe:\n  pid: false\n");
  int n = 1200, fast = 20, levels = 8;
  bool pid = true;
  double ratio = 0.75;
  cfg.section("features").get("n_points", n);
  cfg.section("features").get("fast", fast);
  cfg.section("features").get("levels", levels);
  cfg.section("keyframe").get("pid", pid);
  cfg.section("keyframe").get("ratio", ratio);
  EXPECT_EQ(n, 2000);
  EXPECT_EQ(fast, 7);
  EXPECT_EQ(levels, 8);
  EXPECT_FALSE(pid);
  EXPECT_DOUBLE_EQ(ratio, 0.75);
  EXPECT_NO_THROW(cfg.check_all_used());
}

TEST(ConfigReader, UnknownKeyIsAnErrorNamingIt) {
  const auto cfg = ConfigReader::from_string("features:\n  n_points: 2000\n  n_pionts: 3\n", "my.yaml");
  int n = 0;
  cfg.section("features").get("n_points", n);
  try {
    cfg.check_all_used();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "my.yaml: unknown key 'features.n_pionts'");
  }
}

TEST(ConfigReader, UnknownSectionIsAnError) {
  const auto cfg = ConfigReader::from_string("featurez:\n  n_points: 2000\n", "c.yaml");
  EXPECT_THROW(cfg.check_all_used(), InputError);
}

TEST(ConfigReader, WrongTypeNamesFileAndKey) {
  const auto cfg = ConfigReader::from_string("keyframe:\n  ratio: abc\n", "c.yaml");
  double ratio = 0;
  try {
    cfg.section("keyframe").get("ratio", ratio);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "c.yaml: keyframe.ratio: expected a number");
  }
  int n = 0;
  EXPECT_THROW(ConfigReader::from_string("a:\n  n: 1.5\n").section("a").get("n", n), InputError);
  EXPECT_THROW(ConfigReader::from_string("a:\n  x: .nan\n").section("a").get("x", ratio), InputError);
  EXPECT_THROW(ConfigReader::from_string("a: 3\n").section("a"), InputError);
}

TEST(ConfigReader, MalformedYamlAndMissingFile) {
  EXPECT_THROW(ConfigReader::from_string("a: [1, 2\n"), InputError);
  EXPECT_THROW(ConfigReader::from_string("- 1\n- 2\n"), InputError);
  EXPECT_THROW(ConfigReader::from_file("/nonexistent/plslam.yaml"), InputError);
}

}  // namespace
}  // namespace plslam
