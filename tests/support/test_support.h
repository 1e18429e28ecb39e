#pragma once
// Helpers every test folder shares: where the real data lives, where artefacts go, and how to
// run the CLI binary and capture its output.
#include <filesystem>
#include <optional>
#include <string>

#include <gtest/gtest.h>

namespace plslam::test {

// ../shared/data, or $PLSLAM_SHARED_DIR/data; nullopt when it is absent.
std::optional<std::filesystem::path> shared_data_dir();

// Folder for PNGs and other artefacts a person may want to look at after the run.
std::filesystem::path artifacts_dir();

// A fresh empty temporary directory, removed when the object goes out of scope.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

struct CliResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// The whole file, bytes as they are; empty when it cannot be read.
std::string read_file(const std::filesystem::path& p);

// Runs build/plslam with the given argument string (shell-quoted by the caller).
CliResult run_cli(const std::string& args);

}  // namespace plslam::test

// Skips the current test when ../shared/data is missing, and binds `data` to its path.
#define PLSLAM_REQUIRE_SHARED_DATA(data)                                             \
  const auto data##_opt = ::plslam::test::shared_data_dir();                        \
  if (!data##_opt) GTEST_SKIP() << "../shared/data not found (set PLSLAM_SHARED_DIR)"; \
  const std::filesystem::path data = *data##_opt
