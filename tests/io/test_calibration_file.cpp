// The stereo calibration file of video and camera input: a round trip, and a one-line error naming
// the file and the key for every kind of bad content.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "io/fake_datasets.h"
#include "plslam/core/error.h"
#include "plslam/io/calibration_file.h"
#include "support/test_support.h"

namespace plslam::io {
namespace calibration_file_test {  // named: the unity build joins the test files

namespace fs = std::filesystem;

const char* const kValid =
    "width: 752\nheight: 480\nfx: 458.654\nfy: 457.296\ncx: 367.215\ncy: 248.375\nbaseline: 0.110073\n";

// The InputError message of reading `text` as a calibration file (empty when it was accepted).
std::string error_of(const std::string& text, fs::path* file = nullptr) {
  static test::TempDir tmp;
  const fs::path p = tmp.path() / "calib.yaml";
  test::write_file(p, text);
  if (file) *file = p;
  try {
    (void)read_calibration_file(p);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// One line, naming the file and the key.
void expect_error(const std::string& text, const std::string& key, const std::string& problem) {
  fs::path file;
  const std::string msg = error_of(text, &file);
  SCOPED_TRACE(text);
  ASSERT_FALSE(msg.empty()) << "accepted";
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  EXPECT_EQ(msg.rfind(file.string() + ": ", 0), 0u) << msg;
  EXPECT_NE(msg.find(key), std::string::npos) << msg;
  EXPECT_NE(msg.find(problem), std::string::npos) << msg;
}

// kValid with `key`'s line replaced by `line` (removed when empty).
std::string with_line(const std::string& key, const std::string& line) {
  std::string text = kValid;
  const auto at = text.find(key + ":");
  const auto end = text.find('\n', at);
  text.replace(at, end - at + 1, line.empty() ? "" : line + "\n");
  return text;
}

const char* const kKeys[] = {"width", "height", "fx", "fy", "cx", "cy", "baseline"};

TEST(CalibrationFile, ReadsTheDocumentedFormat) {
  test::TempDir tmp;
  test::write_file(tmp.path() / "c.yaml", std::string("# comment\n") + kValid);
  const auto c = read_calibration_file(tmp.path() / "c.yaml");
  EXPECT_EQ(c.width, 752);
  EXPECT_EQ(c.height, 480);
  EXPECT_DOUBLE_EQ(c.fx, 458.654);
  EXPECT_DOUBLE_EQ(c.fy, 457.296);
  EXPECT_DOUBLE_EQ(c.cx, 367.215);
  EXPECT_DOUBLE_EQ(c.cy, 248.375);
  EXPECT_DOUBLE_EQ(c.baseline, 0.110073);
}

TEST(CalibrationFile, RoundTripIsExact) {
  test::TempDir tmp;
  StereoCalibration c;
  c.width = 1241;
  c.height = 376;
  c.fx = 718.856;
  c.fy = 718.8560000000001;
  c.cx = 607.1928;
  c.cy = 185.2157;
  c.baseline = 0.1 + 0.2 + 0.237;  // not a short decimal
  const auto p = tmp.path() / "sub" / "calibration.yaml";
  write_calibration_file(p, c);
  const auto back = read_calibration_file(p);
  EXPECT_EQ(back.width, c.width);
  EXPECT_EQ(back.height, c.height);
  EXPECT_EQ(back.fx, c.fx);
  EXPECT_EQ(back.fy, c.fy);
  EXPECT_EQ(back.cx, c.cx);
  EXPECT_EQ(back.cy, c.cy);
  EXPECT_EQ(back.baseline, c.baseline);
  // The file says what the numbers are, rectified images included; nothing else is left beside it.
  const std::string text = test::read_file(p);
  EXPECT_NE(text.find("RECTIFIED"), std::string::npos) << text;
  EXPECT_NE(text.find("stereoRectify"), std::string::npos) << text;
  EXPECT_EQ(std::distance(fs::directory_iterator(p.parent_path()), fs::directory_iterator{}), 1);
}

TEST(CalibrationFile, MissingFileOrFolderIsAnError) {
  test::TempDir tmp;
  for (const auto& p : {tmp.path() / "none.yaml", tmp.path()}) {
    try {
      (void)read_calibration_file(p);
      ADD_FAILURE() << "accepted " << p;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(p.string() + ": ", 0), 0u) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
  try {
    (void)read_calibration_file(tmp.path() / "none.yaml");
  } catch (const InputError& e) {
    EXPECT_EQ(e.problem(), "calibration file not found");
  }
}

TEST(CalibrationFile, MalformedYamlIsAnError) {
  expect_error("width: [752\n", "line", "malformed YAML");
  expect_error("- 752\n- 480\n", "", "expected a mapping");
}

TEST(CalibrationFile, UnknownKeyIsAnError) {
  expect_error(std::string(kValid) + "fz: 458\n", "'fz'", "unknown key");
  expect_error(std::string(kValid) + "distortion: [0, 0, 0, 0]\n", "'distortion'", "unknown key");
}

TEST(CalibrationFile, EveryMissingKeyIsNamed) {
  for (const char* key : kKeys) expect_error(with_line(key, ""), std::string(key) + ": missing", "missing");
  expect_error("", "width: missing", "missing");
}

TEST(CalibrationFile, WrongTypesAreNamed) {
  expect_error(with_line("width", "width: 752.5"), "width", "expected an integer");
  expect_error(with_line("height", "height: tall"), "height", "expected an integer");
  expect_error(with_line("fx", "fx: [458, 457]"), "fx", "expected a number");
  expect_error(with_line("cy", "cy: {y: 248}"), "cy", "expected a number");
  expect_error(with_line("baseline", "baseline: 11cm"), "baseline", "expected a number");
  expect_error(with_line("fy", "fy:"), "fy", "expected a number");
}

TEST(CalibrationFile, NonPositiveValuesAreNamed) {
  for (const char* key : kKeys) {
    expect_error(with_line(key, std::string(key) + ": 0"), key, "must be positive, got 0");
    expect_error(with_line(key, std::string(key) + ": -2"), key, "must be positive, got -2");
  }
}

TEST(CalibrationFile, NonFiniteValuesAreNamed) {
  for (const char* key : {"fx", "fy", "cx", "cy", "baseline"}) {
    for (const char* v : {".nan", ".inf", "-.inf"}) {
      expect_error(with_line(key, std::string(key) + ": " + v), key, "expected a finite number");
    }
  }
}

}  // namespace calibration_file_test
}  // namespace plslam::io
