// run_process: exit codes, signals, the log, and the stop request forwarded as one SIGTERM.
#include <gtest/gtest.h>

#include <chrono>

#include "plslam/core/error.h"
#include "plslam/core/subprocess.h"
#include "support/test_support.h"

namespace plslam {
namespace {

TEST(Subprocess, ReturnsTheExitCodeAndWritesBothStreamsToTheLog) {
  test::TempDir dir;
  const auto log = dir.path() / "sub" / "log.txt";
  EXPECT_EQ(run_process({"sh", "-c", "echo out; echo err >&2; exit 7"}, log), 7);
  const auto text = test::read_file(log);
  EXPECT_NE(text.find("out"), std::string::npos);
  EXPECT_NE(text.find("err"), std::string::npos);
  EXPECT_EQ(run_process({"true"}, log), 0);
}

TEST(Subprocess, AChildKilledBySignalGives128PlusTheSignal) {
  test::TempDir dir;
  EXPECT_EQ(run_process({"sh", "-c", "kill -KILL $$"}, dir.path() / "log"), 128 + 9);
}

TEST(Subprocess, StopSendsOneSigtermThatTheChildCanHandle) {
  test::TempDir dir;
  const auto log = dir.path() / "log";
  // The child traps SIGTERM, says so and exits 143 as plslam run does after writing its outputs.
  const auto t0 = std::chrono::steady_clock::now();
  int polls = 0;
  const int rc = run_process({"sh", "-c", "trap 'echo stopping; exit 143' TERM; while :; do sleep 0.05; done"}, log,
                             [&] { return ++polls > 5; });
  EXPECT_EQ(rc, 143);
  EXPECT_NE(test::read_file(log).find("stopping"), std::string::npos);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
}

TEST(Subprocess, AMissingProgramIsAnInputErrorNamingIt) {
  test::TempDir dir;
  try {
    run_process({"/nonexistent/plslam-anchor"}, dir.path() / "log");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/plslam-anchor"), std::string::npos);
  }
}

}  // namespace
}  // namespace plslam
