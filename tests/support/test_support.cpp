#include "support/test_support.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include <sys/wait.h>

namespace plslam::test {

std::optional<std::filesystem::path> shared_data_dir() {
  std::filesystem::path shared = PLSLAM_DEFAULT_SHARED_DIR;
  if (const char* env = std::getenv("PLSLAM_SHARED_DIR")) shared = env;
  const auto data = shared / "data";
  if (!std::filesystem::is_directory(data)) return std::nullopt;
  return data;
}

std::filesystem::path artifacts_dir() {
  std::filesystem::path dir = PLSLAM_TEST_ARTIFACTS;
  std::filesystem::create_directories(dir);
  return dir;
}

TempDir::TempDir() {
  std::random_device rd;
  const auto base = std::filesystem::temp_directory_path();
  for (int attempt = 0; attempt < 100; ++attempt) {
    auto candidate = base / ("plslam_test_" + std::to_string(rd()));
    if (std::filesystem::create_directory(candidate)) {
      path_ = candidate;
      return;
    }
  }
  throw std::runtime_error("cannot create a temporary directory");
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

CliResult run_cli(const std::string& args) {
  TempDir tmp;
  const auto out = tmp.path() / "out.txt";
  const auto err = tmp.path() / "err.txt";
  const std::string cmd = std::string("\"") + PLSLAM_CLI_PATH + "\" " + args + " >\"" +
                          out.string() + "\" 2>\"" + err.string() + "\"";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(out);
  r.err = read_file(err);
  return r;
}

}  // namespace plslam::test
