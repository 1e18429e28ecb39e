#include "plslam/io/atomic_file.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "plslam/core/error.h"

namespace fs = std::filesystem;
using plslam::InputError;
using plslam::io::write_file_atomically;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("plslam_atomic_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Only the final name may remain: a temporary left behind is a half output.
std::size_t entries(const fs::path& d) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(d), fs::directory_iterator()));
}

}  // namespace

TEST(AtomicFile, WritesContentAndCreatesFolder) {
  const auto d = fresh_dir("ok");
  write_file_atomically(d / "sub" / "a.txt", [](std::ostream& o) { o << "hello\n"; });
  EXPECT_EQ(slurp(d / "sub" / "a.txt"), "hello\n");
  EXPECT_EQ(entries(d / "sub"), 1u);
  fs::remove_all(d);
}

TEST(AtomicFile, InjectedFailureKeepsOldFileAndNoTemp) {
  const auto d = fresh_dir("fail");
  write_file_atomically(d / "a.txt", [](std::ostream& o) { o << "old\n"; });
  ::setenv("PLSLAM_FAIL_WRITE", "a.txt", 1);
  try {
    write_file_atomically(d / "a.txt", [](std::ostream& o) { o << "new\n"; });
    ADD_FAILURE() << "expected a write failure";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a.txt"), std::string::npos) << e.what();
  }
  ::unsetenv("PLSLAM_FAIL_WRITE");
  EXPECT_EQ(slurp(d / "a.txt"), "old\n");
  EXPECT_EQ(entries(d), 1u);
  fs::remove_all(d);
}

TEST(AtomicFile, WriterExceptionRemovesTemp) {
  const auto d = fresh_dir("throw");
  EXPECT_THROW(write_file_atomically(d / "b.txt",
                                     [](std::ostream& o) {
                                       o << "partial";
                                       throw std::runtime_error("boom");
                                     }),
               std::runtime_error);
  EXPECT_FALSE(fs::exists(d / "b.txt"));
  EXPECT_EQ(entries(d), 0u);
  fs::remove_all(d);
}

TEST(AtomicFile, UnwritableTargetNamesTheFile) {
  const auto d = fresh_dir("dirtarget");
  fs::create_directories(d / "c.txt" / "inner");  // a non-empty folder under the final name
  try {
    write_file_atomically(d / "c.txt", [](std::ostream& o) { o << "x"; });
    ADD_FAILURE() << "expected a failure";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("c.txt"), std::string::npos) << e.what();
  }
  EXPECT_EQ(entries(d), 1u);
  fs::remove_all(d);
}
