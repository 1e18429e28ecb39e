// The visual-inertial initialisation during `plslam run`: on the real EuRoC micro excerpt (the
// drone stands nearly still) gravity is refused as unobservable and the gyro bias is estimated,
// against EuRoC's ground-truth bias; a rendered car is initialised near the truth; a rendered
// handheld walk with EuRoC's noise and biases is initialised with gravity and the gyro bias near
// the truth, and its map file, with the IMU states, is loaded with the IMU (stereo-inertial in the
// map's world) and without.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "plslam/eval/frame_log.h"
#include "plslam/io/text_table.h"
#include "plslam/system/map_file.h"
#include "support/test_support.h"

namespace plslam {
namespace {

namespace fs = std::filesystem;

nlohmann::json run_imu(const fs::path& seq, const fs::path& out, const std::string& extra = "") {
  const auto r = test::run_cli("run \"" + seq.string() + "\" --out \"" + out.string() + "\" --quiet" + extra);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(out / "stats.json");
  if (r.exit_code != 0 || !in) return {};
  return nlohmann::json::parse(in)["imu"];
}

// Frames first .. first + count - 1 of both cameras of a render of `frames` frames turn black.
void black_out(const fs::path& seq, std::size_t frames, int first, int count) {
  for (const char* cam : {"cam0", "cam1"}) {
    std::vector<fs::path> images;
    for (const auto& e : fs::directory_iterator(seq / "mav0" / cam / "data")) images.push_back(e.path());
    std::sort(images.begin(), images.end(), [](const fs::path& a, const fs::path& b) {
      return std::stoll(a.stem().string()) < std::stoll(b.stem().string());
    });
    ASSERT_EQ(images.size(), frames);
    const cv::Mat image = cv::imread(images[0].string(), cv::IMREAD_UNCHANGED);
    for (int i = first; i < first + count; ++i) {
      ASSERT_TRUE(cv::imwrite(images[static_cast<std::size_t>(i)].string(), cv::Mat::zeros(image.size(), image.type())));
    }
  }
}

// Columns 11-13 of state_groundtruth_estimate0 (the gyro bias) in the row nearest `t`.
Eigen::Vector3d true_gyro_bias(const fs::path& mav0, double t) {
  Eigen::Vector3d best = Eigen::Vector3d::Constant(NAN);
  double best_dt = 1e300;
  for (const auto& row : io::read_numeric_rows(mav0 / "state_groundtruth_estimate0" / "data.csv")) {
    const auto& v = row.values;
    if (v.size() >= 17 && std::abs(v[0] * 1e-9 - t) < best_dt) {
      best_dt = std::abs(v[0] * 1e-9 - t);
      best = Eigen::Vector3d(v[11], v[12], v[13]);
    }
  }
  return best;
}

Eigen::Vector3d vec(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

// The initialisation's gravity against a render's: the run's world is the first camera's, where
// gravity comes from the rendered ground truth (z up).
double gravity_error_deg(const fs::path& seq, const nlohmann::json& init) {
  const std::vector<double> first = io::read_numeric_rows(seq / "mav0" / "synth" / "left_camera.tum").front().values;
  const Eigen::Quaterniond q(first[7], first[4], first[5], first[6]);
  const Eigen::Vector3d g_true = q.toRotationMatrix().transpose() * Eigen::Vector3d(0, 0, -1);
  const Eigen::Vector3d g = vec(init["gravity_direction_world"]);
  return std::atan2(g.cross(g_true).norm(), g.dot(g_true)) * 180 / M_PI;
}

TEST(RunImuInit, EurocMicroRefusesGravityAndEstimatesTheGyroBias) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  test::TempDir tmp;
  const fs::path mav0 = data / "euroc" / "V1_01_easy_micro" / "mav0";
  const auto imu = run_imu(mav0, tmp.path() / "run");
  ASSERT_TRUE(imu.is_object());
  EXPECT_FALSE(imu["initialised"].get<bool>());
  const auto& last = imu["last_attempt"];
  EXPECT_NE(last["reason"].get<std::string>().find("not observable"), std::string::npos) << last["reason"];
  EXPECT_LT(last["rotation_deg"].get<double>(), 1.0);
  const double t = imu["attempts_t_span_sigma_deg"].back()[0].get<double>();
  const Eigen::Vector3d truth = true_gyro_bias(mav0, t), estimate = vec(last["gyro_bias"]);
  std::printf("micro: gyro bias [%.5f %.5f %.5f], EuRoC's [%.5f %.5f %.5f], error %.2e (%.1f %%)\n", estimate.x(),
              estimate.y(), estimate.z(), truth.x(), truth.y(), truth.z(), (estimate - truth).norm(),
              100 * (estimate - truth).norm() / truth.norm());
  EXPECT_LT((estimate - truth).norm(), 0.1 * truth.norm());
}

// A car on the rendered street (5 m/s, its first corner after 8 s): stereo tracking's positions
// drift by centimetres over the 25 m of a 5 s window, and with a position prior of 4 mm alone the
// initialisation took gravity off by 1.18 deg at a claimed sigma of 0.14 deg here (at 6.5 s; the
// 600-frame loop of seed 31: 1.45 deg at 0.17). With the prior that widens with the path
// (ViInitOptions::pose_position_sigma_per_m): at 8.1 s, 0.28 deg off at a sigma of 0.14.
TEST(RunImuInit, RenderedCarIsInitialisedNearTheTruthOrNotAtAll) {
  test::TempDir tmp;
  const auto seq = tmp.path() / "street";
  const auto synth = test::run_cli("synth --out \"" + seq.string() +
                                   "\" --scene street --preset kitti --format euroc --frames 115 --seed 31 --imu-noise euroc");
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  const auto imu = run_imu(seq, tmp.path() / "run", " --preset kitti --no-loop-closing");
  ASSERT_TRUE(imu.is_object());
  const auto& init = imu.contains("initialisation") ? imu["initialisation"] : imu["last_attempt"];
  const double g_err = gravity_error_deg(seq, init);
  std::printf("street seed 31: %s at %.2f s, gravity error %.3f deg (sigma %.3f)\n",
              imu["initialised"].get<bool>() ? "initialised" : "refused", init.value("at_time_s", -1.0), g_err,
              init["gravity_sigma_deg"].get<double>());
  EXPECT_TRUE(imu["initialised"].get<bool>());
  if (imu["initialised"].get<bool>()) {
    EXPECT_LT(g_err, 0.5);
  }
  EXPECT_LT(g_err, 3 * init["gravity_sigma_deg"].get<double>());
}

TEST(RunImuInit, RenderedHandheldWalkIsInitialisedNearTheTruth) {
  test::TempDir tmp;
  const auto seq = tmp.path() / "office";
  const auto synth = test::run_cli("synth --out \"" + seq.string() +
                                   "\" --scene office --frames 170 --seed 4 --motion handheld --imu-noise euroc");
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  const fs::path map_file = tmp.path() / "walk.plmap";
  const auto imu = run_imu(seq, tmp.path() / "run", " --save-map \"" + map_file.string() + "\"");
  ASSERT_TRUE(imu.is_object());
  ASSERT_TRUE(imu["initialised"].get<bool>()) << imu.dump();
  const auto& init = imu["initialisation"];
  const double g_err = gravity_error_deg(seq, init);
  const Eigen::Vector3d bg_true = true_gyro_bias(seq / "mav0", init["at_time_s"].get<double>());
  const double bg_err = (vec(init["gyro_bias"]) - bg_true).norm();
  std::printf("handheld seed 4: initialised after %.2f s, gravity error %.3f deg (sigma %.3f), gyro bias error %.2e of %.2e\n",
              init["seconds_of_motion"].get<double>(), g_err, init["gravity_sigma_deg"].get<double>(), bg_err,
              bg_true.norm());
  EXPECT_LT(g_err, 0.5);
  EXPECT_LT(bg_err, std::max(0.1 * bg_true.norm(), 2e-4));

  // The world then turned to the gravity-aligned one: every output pose, also those of the frames
  // before the initialisation, has the camera's tilt of the rendered world (z up), and the first
  // camera keeps its place.
  ASSERT_TRUE(imu["world"]["gravity_aligned"].get<bool>()) << imu["world"].dump();
  std::map<long, Eigen::Matrix3d> truth;  // by time in ms
  for (const auto& row : io::read_numeric_rows(seq / "mav0" / "synth" / "left_camera.tum")) {
    const auto& v = row.values;
    truth[std::lround(v[0] * 1000)] = Eigen::Quaterniond(v[7], v[4], v[5], v[6]).toRotationMatrix();
  }
  for (const char* file : {"trajectory.tum", "keyframes.tum"}) {
    const auto rows = io::read_numeric_rows(tmp.path() / "run" / file);
    ASSERT_GT(rows.size(), 10u) << file;
    double worst = 0;
    for (const auto& row : rows) {
      const auto& v = row.values;
      const Eigen::Matrix3d R = Eigen::Quaterniond(v[7], v[4], v[5], v[6]).toRotationMatrix();
      const auto it = truth.find(std::lround(v[0] * 1000));
      ASSERT_NE(it, truth.end()) << file << " t " << v[0];
      const Eigen::Vector3d down = R.transpose() * Eigen::Vector3d(0, 0, -1);
      const Eigen::Vector3d down_true = it->second.transpose() * Eigen::Vector3d(0, 0, -1);
      worst = std::max(worst, std::atan2(down.cross(down_true).norm(), down.dot(down_true)) * 180 / M_PI);
    }
    std::printf("%s: %zu poses, worst tilt error %.3f deg\n", file, rows.size(), worst);
    EXPECT_LT(worst, 0.5) << file;
    const auto& first = rows.front().values;
    EXPECT_LT(Eigen::Vector3d(first[1], first[2], first[3]).norm(), 1e-9) << file;
  }

  // From the turn on, tracking and local BA used the IMU; local BA's estimates of the biases at
  // the end against the rendered IMU's (a random walk). Measured: gyro 1.5 % off, acc 0.015 m/s^2.
  const auto& slam = imu["slam"];
  EXPECT_EQ(slam["mode"], "stereo-inertial") << slam.dump();
  EXPECT_GE(slam["imu_tracked_frames"].get<int>(), 30) << slam.dump();
  ASSERT_TRUE(slam.contains("final_gyro_bias")) << slam.dump();
  const auto last = io::read_numeric_rows(seq / "mav0" / "state_groundtruth_estimate0" / "data.csv").back().values;
  const Eigen::Vector3d bg_end(last[11], last[12], last[13]), ba_end(last[14], last[15], last[16]);
  EXPECT_LT((vec(slam["final_gyro_bias"]) - bg_end).norm(), 0.05 * bg_end.norm());
  EXPECT_LT((vec(slam["final_acc_bias"]) - ba_end).norm(), 0.03);

  // The map file carries the world's alignment and the keyframes' IMU states, chained in time.
  const auto saved = system::load_map_file(map_file);
  EXPECT_TRUE(saved.meta.gravity_aligned);
  std::size_t with_imu = 0, chained = 0;
  for (const auto& k : saved.keyframes) {
    with_imu += k.imu.has_value();
    chained += k.imu && k.imu->previous >= 0;
  }
  std::printf("map file: %zu keyframes, %zu with an IMU state, %zu chained\n", saved.keyframes.size(), with_imu, chained);
  EXPECT_GE(with_imu, 10u);
  EXPECT_GE(chained + 1, with_imu);
  // It loads in both modes. With the IMU, the run relocalizes in it, initialises again, finds
  // gravity where the map has its z axis and tracks stereo-inertial in the map's world as it is.
  const auto again = run_imu(seq, tmp.path() / "again", " --load-map \"" + map_file.string() + "\"");
  ASSERT_TRUE(again.is_object());
  std::printf("loaded with the IMU: %s\n", again["world"].dump().c_str());
  EXPECT_EQ(again["world"]["loaded_map_gravity_aligned"], true) << again.dump();
  EXPECT_LT(again["world"]["loaded_map_tilt_deg"].get<double>(), 1.0) << again.dump();
  EXPECT_EQ(again["slam"]["mode"], "stereo-inertial") << again["slam"].dump();
  EXPECT_GE(again["slam"]["imu_tracked_frames"].get<int>(), 30) << again["slam"].dump();
  // The first frames relocalize: 4 frames 'recovering' until the place is confirmed (measured).
  const auto stats = nlohmann::json::parse(test::read_file(tmp.path() / "again" / "stats.json"));
  EXPECT_GE(stats["tracked_frames"].get<int>(), 160);
  EXPECT_EQ(stats["frame_states"]["lost"], 0);
  EXPECT_LT(stats["accuracy"]["ape_trans_m"]["rmse"].get<double>(), 0.03) << stats["accuracy"].dump();
  // Without it (localization only: stereo), every frame is localized in the map as well.
  const auto r = test::run_cli("run \"" + seq.string() + "\" --out \"" + (tmp.path() / "localize").string() +
                               "\" --quiet --localize --load-map \"" + map_file.string() + "\"");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const auto localized = nlohmann::json::parse(test::read_file(tmp.path() / "localize" / "stats.json"));
  EXPECT_GE(localized["tracked_frames"].get<int>(), 160);
  EXPECT_EQ(localized["frame_states"]["lost"], 0);
}

// Black-outs (issue 53): 3 s of black frames in both cameras after the IMU's initialisation. With
// the IMU, the black frames are carried by it (frames.csv state inertial: trusted, in trajectory.tum),
// and tracking resumes in the same map when the images come back: no loss, no relocalization, no
// new map segment. Without it (--no-imu), the black frames are skipped as before.
TEST(RunImuBlackOut, ThreeSecondsOfBlackFramesAreCarriedByTheImuAndRejoinTheMap) {
  test::TempDir tmp;
  const auto seq = tmp.path() / "office";
  const auto synth = test::run_cli("synth --out \"" + seq.string() +
                                   "\" --scene office --frames 240 --seed 6 --motion handheld --imu-noise euroc");
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  constexpr int kFirst = 150, kBlack = 60;  // 7.5 s in (initialised at ~4.5 s), 3 s at 20 Hz
  black_out(seq, 240, kFirst, kBlack);
  const auto imu = run_imu(seq, tmp.path() / "vi");
  ASSERT_TRUE(imu.is_object());
  EXPECT_EQ(imu["slam"]["mode"], "stereo-inertial");
  EXPECT_LT(imu["slam"]["from_frame"].get<int>(), kFirst) << imu["slam"].dump();
  EXPECT_EQ(imu["slam"]["inertial_frames"], kBlack) << imu["slam"].dump();
  const auto stats = nlohmann::json::parse(test::read_file(tmp.path() / "vi" / "stats.json"));
  std::printf("3 s black-out with the IMU: %s, ATE %.4f m\n", stats["frame_states"].dump().c_str(),
              stats["accuracy"]["ape_trans_m"]["rmse"].get<double>());
  EXPECT_EQ(stats["frame_states"]["inertial"], kBlack);
  EXPECT_EQ(stats["frame_states"]["lost"], 0);
  EXPECT_EQ(stats["lost_events"], 0);
  EXPECT_EQ(stats["relocalizations"]["count"], 0);
  EXPECT_EQ(stats["new_map_segments"]["count"], 0) << stats["new_map_segments"].dump();
  EXPECT_EQ(stats["skipped_frames"], 0);
  EXPECT_EQ(stats["tracked_frames"], 240);
  // The global BA that refines the initialisation 5 s after it (imu.refine_after_s) ran, at the
  // first keyframe after the black-out; the one 15 s after it lies beyond the run's 12 s.
  EXPECT_EQ(stats["loop_closing"]["global_ba_inertial_refinements"], 1) << stats["loop_closing"].dump();
  // With the IMU's poses of the black-out, smoothed between the frames vision tracked on either
  // side (measured: 0.0093 m; without the black-out 0.0069. Predicted forward only, as tracking
  // had them: 0.0315 m, the inertial frames 0.126 m off at the black-out's end).
  EXPECT_LT(stats["accuracy"]["ape_trans_m"]["rmse"].get<double>(), 0.015);
  // frames.csv: the black frames are the inertial ones; trajectory.tum holds every frame.
  const auto log = eval::read_frame_log(tmp.path() / "vi" / "frames.csv");
  const auto frame_column = std::find(log.header.begin(), log.header.end(), "frame") - log.header.begin();
  const auto state_column = std::find(log.header.begin(), log.header.end(), "state") - log.header.begin();
  ASSERT_EQ(log.rows.size(), 240u);
  for (const auto& row : log.rows) {
    const int frame = std::stoi(row[static_cast<std::size_t>(frame_column)]);
    const bool black = frame >= kFirst && frame < kFirst + kBlack;
    EXPECT_EQ(row[static_cast<std::size_t>(state_column)], black ? "inertial" : "tracked") << "frame " << frame;
  }
  EXPECT_EQ(io::read_numeric_rows(tmp.path() / "vi" / "trajectory.tum").size(), 240u);

  const auto r = test::run_cli("run \"" + seq.string() + "\" --out \"" + (tmp.path() / "vo").string() + "\" --quiet --no-imu");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const auto vo = nlohmann::json::parse(test::read_file(tmp.path() / "vo" / "stats.json"));
  EXPECT_EQ(vo["skipped_frames"], kBlack);
  EXPECT_EQ(vo["frame_states"]["inertial"], 0);
  EXPECT_GE(vo["lost_events"].get<int>(), 1);  // stereo alone loses the camera there (a new segment)
}

// A black-out that ends facing what the map has not seen (the drone turned during it): vision
// finds nothing to place the frame by, and the IMU's pose starts mapping the view, in the same map
// (without imu.map_new_views the camera is lost there for 20 frames and a new map segment starts:
// measured, ATE 0.0054 m over the tracked frames). Measured: 0.0078 m, without the black-out 0.0057.
TEST(RunImuBlackOut, AViewTheMapLacksAfterABlackOutIsMappedFromTheImu) {
  test::TempDir tmp;
  const auto seq = tmp.path() / "office";
  const auto synth = test::run_cli("synth --out \"" + seq.string() +
                                   "\" --scene office --frames 480 --loop --seed 8 --motion drone --imu-noise euroc");
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  constexpr int kFirst = 300, kBlack = 20, kFrames = 345;  // 1 s; the run stops 1.25 s after it
  black_out(seq, 480, kFirst, kBlack);
  const auto imu = run_imu(seq, tmp.path() / "vi", " --max-frames " + std::to_string(kFrames));
  ASSERT_TRUE(imu.is_object());
  EXPECT_EQ(imu["slam"]["new_views_from_imu"], 1) << imu["slam"].dump();
  const auto stats = nlohmann::json::parse(test::read_file(tmp.path() / "vi" / "stats.json"));
  EXPECT_EQ(stats["lost_events"], 0);
  EXPECT_EQ(stats["relocalizations"]["count"], 0);
  EXPECT_EQ(stats["new_map_segments"]["count"], 0) << stats["new_map_segments"].dump();
  EXPECT_EQ(stats["frame_states"]["inertial"], kBlack + 1) << stats["frame_states"].dump();
  EXPECT_EQ(stats["tracked_frames"], kFrames);
  EXPECT_LT(stats["accuracy"]["ape_trans_m"]["rmse"].get<double>(), 0.012);
  const auto log = eval::read_frame_log(tmp.path() / "vi" / "frames.csv");
  const auto column = [&](const char* name) {
    return static_cast<std::size_t>(std::find(log.header.begin(), log.header.end(), name) - log.header.begin());
  };
  ASSERT_EQ(log.rows.size(), static_cast<std::size_t>(kFrames));
  const auto& first_after = log.rows[kFirst + kBlack];
  EXPECT_EQ(first_after[column("state")], "inertial");
  EXPECT_EQ(first_after[column("keyframe_reason")], "new-view");
  for (int i = kFirst + kBlack + 1; i < kFrames; ++i) EXPECT_EQ(log.rows[i][column("state")], "tracked") << "frame " << i;
}

}  // namespace
}  // namespace plslam
