#include "plslam/io/output_folder.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "plslam/core/error.h"

namespace fs = std::filesystem;
using plslam::InputError;
using plslam::io::prepare_output_folder;

namespace {
fs::path base(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("plslam_outdir_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}
}  // namespace

TEST(OutputFolder, CreatesMissingFolderAndLeavesNoProbe) {
  const auto d = base("new");
  prepare_output_folder(d / "a" / "b");
  ASSERT_TRUE(fs::is_directory(d / "a" / "b"));
  EXPECT_TRUE(fs::is_empty(d / "a" / "b"));
  fs::remove_all(d);
}

TEST(OutputFolder, RejectsEmptyString) { EXPECT_THROW(prepare_output_folder(""), InputError); }

TEST(OutputFolder, RejectsAFileNamingIt) {
  const auto d = base("file");
  fs::create_directories(d);
  std::ofstream(d / "f") << "x";
  try {
    prepare_output_folder(d / "f");
    ADD_FAILURE() << "expected a rejection";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a folder"), std::string::npos) << e.what();
  }
  fs::remove_all(d);
}

TEST(OutputFolder, RejectsUnwritableFolder) {
  if (::geteuid() == 0) GTEST_SKIP() << "root ignores folder permissions";
  const auto d = base("ro");
  fs::create_directories(d);
  fs::permissions(d, fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_THROW(prepare_output_folder(d), InputError);
  fs::permissions(d, fs::perms::owner_all);
  fs::remove_all(d);
}

TEST(OutputFolder, RejectsFolderThatCannotBeCreatedEvenByRoot) {
  EXPECT_THROW(prepare_output_folder("/proc/1/plslam_out"), InputError);
}
