// Inputs a user really hands to plslam (issue 20, class 6): files saved on Windows (byte-order
// mark, CRLF), trailing slashes, symlinked folders, JPEG and PGM image folders, the dataset root
// `plslam synth --format kitti` writes, a folder where a file belongs and the other way round, a
// zero baseline, out-of-range numbers on the command line, `synth` into a used folder, and stdout
// of `--json` commands while OpenCV logs. (Signals: test_signal_robustness.cpp.) Each case runs the CLI and asserts the exit code, the
// message (one line, naming the file) or what was accepted, and what was left on disk.
#include <cstdlib>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "io/fake_datasets.h"
#include "support/test_support.h"

namespace plslam {
namespace {

namespace fs = std::filesystem;

void overwrite(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << text;
}

// Rewrites a text file as a Windows editor saves it: CRLF line ends and/or a UTF-8 byte-order mark.
void windows_style(const fs::path& p, bool bom, bool crlf) {
  std::string text = test::read_file(p), out = bom ? "\xEF\xBB\xBF" : "";
  for (char c : text) {
    if (c == '\n' && crlf) out += '\r';
    out += c;
  }
  overwrite(p, out);
}

// A folder where a file belongs.
void replace_with_folder(const fs::path& p) {
  fs::remove_all(p);
  fs::create_directories(p / "inside");
}

// Re-encodes the images of a fake KITTI sequence in another format (the .png files are removed).
void convert_kitti_images(const fs::path& seq, const std::string& ext) {
  for (const char* cam : {"image_0", "image_1"}) {
    std::vector<fs::path> pngs;
    for (const auto& e : fs::directory_iterator(seq / cam)) pngs.push_back(e.path());
    for (const auto& p : pngs) {
      const cv::Mat img = cv::imread(p.string(), cv::IMREAD_GRAYSCALE);
      fs::path q = p;
      q.replace_extension(ext);
      ASSERT_TRUE(cv::imwrite(q.string(), img, {cv::IMWRITE_JPEG_QUALITY, 100}));
      fs::remove(p);
    }
  }
}

// 30 poses on a gentle curve, in TUM format.
std::string tum_curve(double offset) {
  std::string s;
  for (int i = 0; i < 30; ++i) {
    const double t = 0.1 * i;
    s += std::to_string(t) + " " + std::to_string(t + offset) + " " + std::to_string(0.2 * t * t) + " 0 0 0 0 1\n";
  }
  return s;
}

// fmt, not operator+: GCC 12 warns falsely (-Wrestrict) on the inlined concatenation.
std::string q(const fs::path& p) { return fmt::format("\"{}\"", p.string()); }

struct InputCase {
  std::string name;
  std::string input_class;  // what the user did, for the report
  // Builds the input in `tmp` and returns the CLI arguments.
  std::function<std::string(const fs::path& tmp)> setup;
  int exit_code;
  std::vector<std::string> err_has;  // fragments stderr must hold (refusals: file and problem)
  // Further checks on the result (accepted cases: what was read; refusals: what is on disk).
  std::function<void(const fs::path& tmp, const test::CliResult&)> check = {};
};

// gtest prints a failing case by its name, not as bytes.
void PrintTo(const InputCase& c, std::ostream* os) { *os << c.name; }

class InputRobustness : public ::testing::TestWithParam<InputCase> {};

TEST_P(InputRobustness, AcceptedOrRefusedWithOneLineNamingTheFile) {
  const InputCase& c = GetParam();
  test::TempDir tmp;
  const std::string args = c.setup(tmp.path());
  if (HasFatalFailure()) return;
  const auto r = test::run_cli(args);
  EXPECT_EQ(r.exit_code, c.exit_code) << c.input_class << "\nstdout: " << r.out << "\nstderr: " << r.err;
  for (const auto& fragment : c.err_has) EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
  if (c.exit_code == 2) {
    // One error line, from plslam or from the option parser, and nothing half-written on stdout.
    const auto error_line = r.err.find("error: ") != std::string::npos ? r.err.find("error: ") : r.err.find("--");
    ASSERT_NE(error_line, std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  if (c.check) c.check(tmp.path(), r);
}

// `info --json` read the dataset: frame count, and whether ground truth was found.
std::function<void(const fs::path&, const test::CliResult&)> reads(std::size_t frames, bool gt,
                                                                    const std::string& format = "") {
  return [=](const fs::path&, const test::CliResult& r) {
    const auto j = nlohmann::json::parse(r.out, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << r.out;
    EXPECT_EQ(j["frames"].get<std::size_t>(), frames);
    EXPECT_EQ(j["has_ground_truth"].get<bool>(), gt);
    EXPECT_NEAR(j["baseline_m"].get<double>(), format == "euroc" ? 0.11 : 0.5, 1e-9);
    if (!format.empty()) {
      EXPECT_EQ(j["format"], format);
    }
  };
}

std::string info(const fs::path& p) { return "info --json " + q(p); }

fs::path kitti(const fs::path& tmp, const std::function<void(const fs::path&)>& edit = {}) {
  const auto seq = test::make_kitti(tmp / "k");
  if (edit) edit(seq);
  return seq;
}

fs::path euroc(const fs::path& tmp, const std::function<void(const fs::path&)>& edit = {}) {
  const auto root = test::make_euroc(tmp / "e");
  if (edit) edit(root / "mav0");
  return root;
}

// A file the user's text editor saved: the reader must accept it.
InputCase windows_text(const std::string& name, bool is_kitti, const std::string& file, bool bom, bool crlf) {
  return {name, "text file with " + std::string(bom ? "a byte-order mark" : "") + (bom && crlf ? " and " : "") +
                    (crlf ? "CRLF line ends" : ""),
          [=](const fs::path& tmp) {
            const auto path = is_kitti ? kitti(tmp) : euroc(tmp);
            const auto base = is_kitti ? path : path / "mav0";
            windows_style(base / file, bom, crlf);
            return info(path);
          },
          0, {}, reads(3, true, is_kitti ? "kitti" : "euroc")};
}

// A CLI option out of its range: exit 2 and the option named.
InputCase bad_option(const std::string& name, const std::string& command, const std::string& option,
                     const std::string& value, bool needs_dataset = true) {
  return {name, "numeric option out of range",
          [=](const fs::path& tmp) {
            std::string args = command;
            if (needs_dataset) args += " " + q(kitti(tmp));
            if (command == "run") args += " --out " + q(tmp / "out");
            if (command == "synth") args += " --out " + q(tmp / "synth");
            if (command == "eval") {
              test::write_file(tmp / "a.tum", tum_curve(0));
              args += " --gt " + q(tmp / "a.tum") + " --est " + q(tmp / "a.tum");
            }
            return args + " " + option + " " + value;
          },
          2, {option},
          [](const fs::path& tmp, const test::CliResult&) {
            EXPECT_FALSE(fs::exists(tmp / "out")) << "a refused run wrote outputs";
            EXPECT_FALSE(fs::exists(tmp / "synth")) << "a refused synth wrote a dataset";
          }};
}

// A folder where a file belongs: exit 2, the path named, "is a folder".
InputCase folder_for_file(const std::string& name, bool is_kitti, const std::string& file,
                          const std::string& problem = "is a folder, expected a file") {
  return {name, "folder where a file belongs",
          [=](const fs::path& tmp) {
            const auto path = is_kitti ? kitti(tmp) : euroc(tmp);
            const auto target = is_kitti ? (file.rfind("../", 0) == 0 ? tmp / "k" / file.substr(3) : path / file)
                                         : path / "mav0" / file;
            replace_with_folder(target);
            return info(path);
          },
          2, {fs::path(file).filename().string(), problem}};
}

std::string synth_args(const fs::path& out, const std::string& extra = "") {
  return "synth --scene office --preset euroc --frames 2 --threads 1 --out " + q(out) + extra;
}

const InputCase kCases[] = {
    // ---- Files saved on Windows: accepted. ----
    windows_text("kitti_calib_bom", true, "calib.txt", true, false),
    windows_text("kitti_calib_crlf", true, "calib.txt", false, true),
    windows_text("kitti_calib_bom_crlf", true, "calib.txt", true, true),
    windows_text("kitti_times_bom_crlf", true, "times.txt", true, true),
    windows_text("kitti_poses_bom_crlf", true, "../../poses/00.txt", true, true),
    windows_text("euroc_sensor_yaml_bom", false, "cam0/sensor.yaml", true, false),
    windows_text("euroc_sensor_yaml_crlf", false, "cam1/sensor.yaml", false, true),
    windows_text("euroc_image_list_bom_crlf", false, "cam0/data.csv", true, true),
    windows_text("euroc_ground_truth_bom_crlf", false, "state_groundtruth_estimate0/data.csv", true, true),
    {"eval_trajectories_bom_crlf", "text file with a byte-order mark and CRLF line ends",
     [](const fs::path& tmp) {
       test::write_file(tmp / "gt.tum", tum_curve(0));
       test::write_file(tmp / "est.txt", tum_curve(0.01));
       windows_style(tmp / "gt.tum", true, true);
       windows_style(tmp / "est.txt", true, true);  // no extension: the format is detected
       return "eval --json --gt " + q(tmp / "gt.tum") + " --est " + q(tmp / "est.txt");
     },
     0, {},
     [](const fs::path&, const test::CliResult& r) {
       const auto j = nlohmann::json::parse(r.out, nullptr, false);
       ASSERT_FALSE(j.is_discarded()) << r.out;
       EXPECT_NE(r.out.find("30"), std::string::npos) << "all 30 poses paired: " << r.out;
     }},

    // ---- Paths: trailing slashes, symlinks, the synth KITTI root. Accepted. ----
    {"kitti_trailing_slash", "trailing slash",
     [](const fs::path& tmp) { return info(kitti(tmp).string() + "/"); }, 0, {}, reads(3, true, "kitti")},
    {"euroc_root_trailing_slash", "trailing slash",
     [](const fs::path& tmp) { return info(euroc(tmp).string() + "/"); }, 0, {}, reads(3, true, "euroc")},
    {"euroc_mav0_trailing_slash", "trailing slash",
     [](const fs::path& tmp) { return info((euroc(tmp) / "mav0").string() + "/"); }, 0, {}, reads(3, true, "euroc")},
    {"euroc_mav0_double_slash", "trailing slash",
     [](const fs::path& tmp) { return info((euroc(tmp) / "mav0").string() + "//"); }, 0, {}, reads(3, true, "euroc")},
    {"kitti_sequence_symlink_keeps_ground_truth", "symlink",
     [](const fs::path& tmp) {
       fs::create_directory_symlink(kitti(tmp), tmp / "my_sequence");
       return info(tmp / "my_sequence");
     },
     0, {}, reads(3, true, "kitti")},
    {"kitti_root_symlink_keeps_ground_truth", "symlink",
     [](const fs::path& tmp) {
       kitti(tmp);
       fs::create_directory_symlink(tmp / "k", tmp / "link");
       return info(tmp / "link" / "sequences" / "00");
     },
     0, {}, reads(3, true, "kitti")},
    {"euroc_symlink", "symlink",
     [](const fs::path& tmp) {
       fs::create_directory_symlink(euroc(tmp), tmp / "link");
       return info(tmp / "link");
     },
     0, {}, reads(3, true, "euroc")},
    {"kitti_odometry_root_with_one_sequence", "the root `synth --format kitti` writes",
     [](const fs::path& tmp) {
       kitti(tmp);
       return info(tmp / "k");
     },
     0, {}, reads(3, true, "kitti")},
    {"kitti_odometry_root_with_two_sequences", "an ambiguous KITTI root",
     [](const fs::path& tmp) {
       kitti(tmp);
       fs::create_directories(tmp / "k" / "sequences" / "01");
       fs::copy(tmp / "k" / "sequences" / "00", tmp / "k" / "sequences" / "01", fs::copy_options::recursive);
       return info(tmp / "k");
     },
     2, {"holds 2 KITTI sequences", "sequences/00"}},
    {"synth_kitti_root_is_read_by_info", "the root `synth --format kitti` writes",
     [](const fs::path& tmp) {
       const auto r = test::run_cli("synth --scene office --preset kitti --frames 2 --threads 1 --out " +
                                    q(tmp / "s"));
       EXPECT_EQ(r.exit_code, 0) << r.err;
       return info(tmp / "s");
     },
     0, {},
     [](const fs::path&, const test::CliResult& r) {
       const auto j = nlohmann::json::parse(r.out, nullptr, false);
       ASSERT_FALSE(j.is_discarded()) << r.out;
       EXPECT_EQ(j["frames"], 2);
       EXPECT_TRUE(j["has_ground_truth"].get<bool>());
     }},

    // ---- Image formats: accepted. ----
    {"kitti_jpeg_images", "JPEG image folder",
     [](const fs::path& tmp) {
       const auto seq = kitti(tmp);
       convert_kitti_images(seq, ".jpg");
       return info(seq);
     },
     0, {}, reads(3, true, "kitti")},
    {"kitti_pgm_images", "PGM image folder",
     [](const fs::path& tmp) {
       const auto seq = kitti(tmp);
       convert_kitti_images(seq, ".pgm");
       return info(seq);
     },
     0, {}, reads(3, true, "kitti")},
    {"kitti_uppercase_extension", "image folder with .PNG names",
     [](const fs::path& tmp) {
       const auto seq = kitti(tmp);
       for (const char* cam : {"image_0", "image_1"}) {
         for (int i = 0; i < 3; ++i) {
           const auto p = seq / cam / fmt::format("{:06d}.png", i);
           fs::rename(p, seq / cam / fmt::format("{:06d}.PNG", i));
         }
       }
       return info(seq);
     },
     0, {}, reads(3, true, "kitti")},

    // ---- A folder where a file belongs, a file where a folder belongs: refused. ----
    folder_for_file("kitti_calib_is_a_folder", true, "calib.txt"),
    folder_for_file("kitti_times_is_a_folder", true, "times.txt"),
    folder_for_file("kitti_poses_is_a_folder", true, "../poses/00.txt"),
    folder_for_file("kitti_first_image_is_a_folder", true, "image_0/000000.png", "image file"),
    folder_for_file("euroc_sensor_yaml_is_a_folder", false, "cam1/sensor.yaml"),
    folder_for_file("euroc_image_list_is_a_folder", false, "cam0/data.csv"),
    folder_for_file("euroc_ground_truth_is_a_folder", false, "state_groundtruth_estimate0/data.csv"),
    {"kitti_image_folder_is_a_file", "file where a folder belongs",
     [](const fs::path& tmp) {
       const auto seq = kitti(tmp);
       fs::remove_all(seq / "image_1");
       test::write_file(seq / "image_1", "x");
       return info(seq);
     },
     2, {"image_1", "expected the image folder"}},
    {"dataset_is_a_file", "file where a folder belongs",
     [](const fs::path& tmp) { return info(kitti(tmp) / "calib.txt"); }, 2, {"calib.txt", "not a folder"}},
    {"config_is_a_folder", "folder where a file belongs",
     [](const fs::path& tmp) {
       fs::create_directories(tmp / "cfg.yaml");
       return "run " + q(kitti(tmp)) + " --out " + q(tmp / "out") + " --config " + q(tmp / "cfg.yaml");
     },
     2, {"cfg.yaml", "is a folder"},
     [](const fs::path& tmp, const test::CliResult&) { EXPECT_FALSE(fs::exists(tmp / "out" / "stats.json")); }},
    {"eval_estimate_is_a_folder", "folder where a file belongs",
     [](const fs::path& tmp) {
       test::write_file(tmp / "gt.tum", tum_curve(0));
       fs::create_directories(tmp / "est.tum");
       return "eval --gt " + q(tmp / "gt.tum") + " --est " + q(tmp / "est.tum");
     },
     2, {"est.tum", "is a folder"}},
    {"run_out_is_a_file", "file where a folder belongs",
     [](const fs::path& tmp) {
       test::write_file(tmp / "out", "x");
       return "run " + q(kitti(tmp)) + " --out " + q(tmp / "out");
     },
     2, {"out"}},

    // ---- Degenerate stereo: refused with its own message, never an OpenCV assertion. ----
    {"kitti_zero_baseline", "zero stereo baseline",
     [](const fs::path& tmp) {
       return info(kitti(tmp, [](const fs::path& s) {
         test::write_file(s / "calib.txt", "P0: 500 0 32 0 0 500 24 0 0 0 1 0\nP1: 500 0 32 0 0 500 24 0 0 0 1 0\n");
       }));
     },
     2, {"calib.txt", "baseline must be positive, got 0 m"}},
    {"euroc_zero_baseline", "zero stereo baseline",
     [](const fs::path& tmp) {
       return info(euroc(tmp, [](const fs::path& m) {
         test::write_file(m / "cam1" / "sensor.yaml", test::euroc_sensor_yaml(0.0));
       }));
     },
     2, {"sensor.yaml", "baseline must be positive, got 0 m"}},

    // ---- Numbers on the command line: range-checked. ----
    bad_option("run_negative_max_frames", "run", "--max-frames", "-2"),
    bad_option("run_negative_start", "run", "--start", "-5"),
    bad_option("run_overflowing_max_frames", "run", "--max-frames", "99999999999999999999999"),
    bad_option("run_overflowing_start", "run", "--start", "1e30"),
    bad_option("run_zero_repeat", "run", "--repeat", "0"),
    bad_option("info_negative_start", "info", "--start", "-1"),
    bad_option("bench_negative_frames", "bench features", "--frames", "-3"),
    bad_option("bench_negative_features", "bench features", "--features", "-1"),
    bad_option("bench_overflowing_features", "bench features", "--features", "4294967296"),
    bad_option("bench_zero_right_factor", "bench features", "--right-factor", "0"),
    bad_option("synth_negative_frames", "synth", "--frames", "-1", false),
    bad_option("synth_negative_threads", "synth", "--threads", "-1", false),
    bad_option("synth_negative_seed", "synth", "--seed", "-1", false),
    bad_option("eval_negative_rpe_delta", "eval", "--rpe-delta", "-1", false),
    bad_option("eval_negative_time_difference", "eval", "--t-max-diff", "-0.1", false),

    // ---- synth writes a whole dataset into a fresh folder, or nothing. ----
    {"synth_into_non_empty_folder_is_refused", "synth into a used folder",
     [](const fs::path& tmp) {
       test::write_file(tmp / "s" / "old.txt", "keep me");
       return synth_args(tmp / "s");
     },
     2, {"not empty", "--force"},
     [](const fs::path& tmp, const test::CliResult&) {
       EXPECT_EQ(test::read_file(tmp / "s" / "old.txt"), "keep me");
       EXPECT_FALSE(fs::exists(tmp / "s" / "mav0"));
     }},
    {"synth_force_replaces_the_folder", "synth into a used folder",
     [](const fs::path& tmp) {
       test::write_file(tmp / "s" / "old.txt", "stale");
       return synth_args(tmp / "s", " --force");
     },
     0, {},
     [](const fs::path& tmp, const test::CliResult&) {
       EXPECT_FALSE(fs::exists(tmp / "s" / "old.txt")) << "a stale file survived --force";
       EXPECT_TRUE(fs::exists(tmp / "s" / "mav0" / "synth" / "synth.json"));
       for (const auto& e : fs::directory_iterator(tmp)) {
         EXPECT_EQ(e.path().filename().string().find(".s."), std::string::npos) << "left " << e.path();
       }
     }},
    {"synth_into_empty_folder", "synth into a fresh folder",
     [](const fs::path& tmp) {
       fs::create_directories(tmp / "s");
       return synth_args(tmp / "s");
     },
     0, {},
     [](const fs::path& tmp, const test::CliResult&) {
       EXPECT_TRUE(fs::exists(tmp / "s" / "mav0" / "synth" / "synth.json"));
       EXPECT_EQ(std::distance(fs::directory_iterator(tmp), fs::directory_iterator()), 1) << "staging folder left";
     }},
    {"synth_out_is_a_file", "file where a folder belongs",
     [](const fs::path& tmp) {
       test::write_file(tmp / "s", "x");
       return synth_args(tmp / "s");
     },
     2, {"is a file"}, [](const fs::path& tmp, const test::CliResult&) { EXPECT_EQ(test::read_file(tmp / "s"), "x"); }},
};

INSTANTIATE_TEST_SUITE_P(Cases, InputRobustness, ::testing::ValuesIn(kCases),
                         [](const auto& info) { return info.param.name; });

// ---- stdout of --json commands holds only JSON, even while OpenCV logs at DEBUG level. ----

class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

void expect_only_json(const test::CliResult& r) {
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << "stdout is not one JSON document:\n" << r.out.substr(0, 500);
}

TEST(JsonStdoutRobustness, BenchInfoAndEvalPrintOnlyJsonWhileOpenCvLogs) {
  test::TempDir tmp;
  const auto seq = test::make_kitti(tmp.path() / "k", 3, 320, 240);
  const ScopedEnv debug_log("OPENCV_LOG_LEVEL", "DEBUG");
  expect_only_json(test::run_cli("bench features --json --frames 2 " + q(seq)));
  expect_only_json(test::run_cli("info --json " + q(seq)));
  test::write_file(tmp.path() / "a.tum", tum_curve(0));
  expect_only_json(test::run_cli("eval --json --gt " + q(tmp.path() / "a.tum") + " --est " + q(tmp.path() / "a.tum")));
}

// ---- A configuration saved on Windows is read like any other. ----

TEST(ConfigRobustness, ByteOrderMarkAndCrlfConfigIsRead) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  test::write_file(tmp.path() / "cfg.yaml", "system:\n  seed: 7\n");
  windows_style(tmp.path() / "cfg.yaml", true, true);
  const auto r = test::run_cli("run " + q(data / "kitti/sequences/06") + " --max-frames 4 --sequential --quiet --out " +
                               q(tmp.path() / "out") + " --config " + q(tmp.path() / "cfg.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto stats = nlohmann::json::parse(test::read_file(tmp.path() / "out" / "stats.json"));
  EXPECT_EQ(stats["seed"], 7);
}

}  // namespace
}  // namespace plslam
