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

}  // namespace
}  // namespace plslam::system
