#include <gtest/gtest.h>

#include "plslam/core/config_reader.h"
#include "plslam/core/error.h"
#include "plslam/system/system_config.h"

namespace plslam::system {
namespace {

SystemOptions from_yaml(const std::string& yaml) {
  return apply_config(ConfigReader::from_string(yaml, "test.yaml"), SystemOptions::euroc());
}

TEST(SystemConfig, SeedHasAFixedDefaultAndIsRead) {
  EXPECT_EQ(from_yaml("").seed, 1u);
  EXPECT_EQ(from_yaml("system: {seed: 42}").seed, 42u);
  EXPECT_EQ(from_yaml("system: {seed: 0}").seed, 0u);
}

TEST(SystemConfig, BadSeedOrUnknownKeyNamesTheFileAndKey) {
  for (const char* yaml : {"system: {seed: -1}", "system: {seed: 1.5}", "system: {seed: abc}", "system: {sed: 3}"}) {
    try {
      from_yaml(yaml);
      ADD_FAILURE() << yaml << " was accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("test.yaml"), std::string::npos) << what;
      EXPECT_NE(what.find("system.se"), std::string::npos) << what;
    }
  }
}

TEST(SystemConfig, ShippedPresetsLoad) {
  for (const auto format : {io::DatasetFormat::kEuroc, io::DatasetFormat::kKitti}) {
    const auto file = std::filesystem::path(PLSLAM_SOURCE_DIR) / "config" / (format == io::DatasetFormat::kKitti ? "kitti.yaml" : "euroc.yaml");
    EXPECT_NO_THROW(load_system_options(format, file)) << file;
  }
}

TEST(SystemConfig, PlaceRecognitionAndRelocalizationKeys) {
  const auto d = from_yaml("");
  EXPECT_TRUE(d.place_recognition);
  EXPECT_TRUE(d.vocabulary.empty());
  EXPECT_TRUE(d.tracker.relocalization.enabled);
  const auto o = from_yaml(
      "place: {enabled: false, vocabulary: voc/small.plvoc}\n"
      "relocalization: {enabled: false, max_candidates: 3, min_bow_matches: 20, min_inliers: 40, search_radius: 2,"
      " new_segment_after_s: 0.5}");
  EXPECT_FALSE(o.place_recognition);
  // Relative to the config file's folder ("test.yaml": the current one).
  EXPECT_EQ(o.vocabulary, std::filesystem::path("voc/small.plvoc"));
  const auto& r = o.tracker.relocalization;
  EXPECT_FALSE(r.enabled);
  EXPECT_EQ(r.max_candidates, 3u);
  EXPECT_EQ(r.min_bow_matches, 20);
  EXPECT_EQ(r.min_inliers, 40);
  EXPECT_DOUBLE_EQ(r.search_radius, 2.0);
  EXPECT_DOUBLE_EQ(r.new_segment_after_s, 0.5);
  const auto nested = apply_config(ConfigReader::from_string("place: {vocabulary: v.plvoc}", "/etc/plslam/run.yaml"),
                                   SystemOptions::euroc());
  EXPECT_EQ(nested.vocabulary, std::filesystem::path("/etc/plslam/v.plvoc"));
  for (const char* yaml : {"relocalization: {max_candidates: 0}", "relocalization: {min_bow_matches: 3}",
                           "relocalization: {min_inliers: 0}", "relocalization: {search_radius: 0}",
                           "relocalization: {new_segment_after_s: -1}", "place: {vocabluary: x}"}) {
    EXPECT_THROW(from_yaml(yaml), InputError) << yaml;
  }
  EXPECT_FALSE(load_vocabulary(o));  // place recognition off: no vocabulary loaded
  EXPECT_GT(load_vocabulary(d)->size(), 5000u);  // the shipped default
  auto missing = d;
  missing.vocabulary = "/nonexistent/v.plvoc";
  EXPECT_THROW(load_vocabulary(missing), InputError);
}

}  // namespace
}  // namespace plslam::system
