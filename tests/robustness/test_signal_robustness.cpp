// SIGTERM stops `plslam synth` and `plslam bench` like `plslam run` (issue 20, class 3): synth
// leaves no dataset and no staging folder, bench reports the frames it measured, marked as
// interrupted; both exit 143.
#include <csignal>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace plslam {
namespace {

namespace fs = std::filesystem;

// True once `pid` has a handler for SIGTERM (the SigCgt mask of /proc/<pid>/status).
bool catches_sigterm(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("SigCgt:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> (SIGTERM - 1)) & 1U;
  }
  return false;
}

struct Stopped {
  int exit_code = -1;
  std::string out, err;
};

// Starts plslam with `args` (stdout and stderr to files), waits until `ready(stderr so far)` or
// for its SIGTERM handler, sends SIGTERM and waits for the exit.
Stopped start_and_stop(const fs::path& dir, const std::vector<std::string>& args,
                       const std::function<bool(const std::string&)>& ready) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  std::vector<char*> argv{const_cast<char*>(PLSLAM_CLI_PATH)};
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), 1);
    dup2(::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), 2);
    execv(PLSLAM_CLI_PATH, argv.data());
    _exit(127);
  }
  for (int i = 0; i < 1200 && !(catches_sigterm(pid) && ready(test::read_file(err))); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  Stopped s;
  s.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
  s.out = test::read_file(out);
  s.err = test::read_file(err);
  return s;
}

TEST(SignalRobustness, SynthSigtermLeavesNoDatasetAndExits143) {
  test::TempDir tmp;
  const fs::path out = tmp.path() / "s";
  // The first progress line means rendering has begun.
  const auto r = start_and_stop(tmp.path(),
                                {"synth", "--scene", "office", "--preset", "euroc", "--frames", "400", "--threads", "1",
                                 "--out", out.string()},
                                [](const std::string& err) { return err.find("frames, ETA") != std::string::npos; });
  EXPECT_EQ(r.exit_code, 143) << r.err;
  EXPECT_NE(r.err.find("stopped by SIGTERM"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(tmp.path())) {
    EXPECT_EQ(e.path().filename().string().find(".s."), std::string::npos) << "staging folder left: " << e.path();
  }
}

TEST(SignalRobustness, BenchSigtermReportsTheFramesMeasuredAsInterrupted) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  const auto start = std::chrono::steady_clock::now();
  const auto r = start_and_stop(tmp.path(), {"bench", "features", (data / "kitti/sequences/06").string(), "--json"},
                                [&](const std::string&) {
                                  return std::chrono::steady_clock::now() - start > std::chrono::milliseconds(1500);
                                });
  EXPECT_EQ(r.exit_code, 143) << r.err;
  EXPECT_NE(r.err.find("stopped by SIGTERM"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(r.out, nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << "stdout is not one JSON document: " << r.out.substr(0, 300);
  EXPECT_EQ(j["interrupted_by"], "SIGTERM");
  EXPECT_TRUE(j.contains("fast_ms")) << "the points measured before the signal are reported";
}

}  // namespace
}  // namespace plslam
