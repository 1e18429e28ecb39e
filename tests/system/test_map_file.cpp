// Map reuse: the .plmap file (round trip, corrupt and mismatched files) and `plslam run
// --save-map / --load-map [--localize]`, `plslam map info / export`, on a short rendered office
// sequence mapped once per suite.
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <random>

#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "plslam/core/error.h"
#include "plslam/eval/frame_log.h"
#include "plslam/io/dataset.h"
#include "plslam/system/map_file.h"
#include "plslam/system/slam_system.h"
#include "plslam/system/system_config.h"
#include "support/test_support.h"
#include "system/tiny_map.h"

namespace plslam {
namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 40;

class MapReuse : public ::testing::Test {
 protected:
  // The rendered sequence and its map are made once per build folder and kept (ctest runs every
  // test in its own process, and under the sanitizers of CI the render and the mapping run cost
  // about 20 s). Processes that race to make them each render into a folder of their own, and the
  // first rename wins. The key holds the map format version: a new format maps again.
  static void SetUpTestSuite() {
    tmp_ = std::make_unique<test::TempDir>();
    const fs::path cache_root = fs::path(PLSLAM_CLI_PATH).parent_path() / "test_cache";
    cache_ = cache_root / ("map_reuse_v" + std::to_string(system::kMapFileVersion));
    if (fs::exists(cache_ / "office.plmap")) return;
    fs::create_directories(cache_root);
    const fs::path work = cache_root / (".map_reuse." + std::to_string(::getpid()));
    fs::remove_all(work);
    auto r = test::run_cli("synth --out \"" + (work / "office").string() +
                           "\" --scene office --preset euroc --frames " + std::to_string(kFrames) +
                           " --seed 3 --threads 2");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    r = test::run_cli("run \"" + (work / "office").string() + "\" --out \"" + (work / "mapping").string() +
                      "\" --quiet --sequential --save-map \"" + (work / "office.plmap").string() + "\"");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::error_code ec;
    fs::rename(work, cache_, ec);
    if (ec) fs::remove_all(work);  // another process was first
    ASSERT_TRUE(fs::exists(cache_ / "office.plmap"));
  }
  static void TearDownTestSuite() { tmp_.reset(); }
  static fs::path sequence() { return cache_ / "office"; }
  static fs::path map_file() { return cache_ / "office.plmap"; }
  static std::string map_bytes() { return test::read_file(map_file()); }

  // A copy of the map with `edit` applied to its contents, saved under `name`.
  static fs::path edited_map(const std::string& name, const std::function<void(system::MapContents&)>& edit) {
    auto c = system::load_map_file(map_file());
    edit(c);
    const fs::path p = tmp_->path() / name;
    system::save_map_file(p, c);
    return p;
  }
  static fs::path written(const std::string& name, const std::string& bytes) {
    const fs::path p = tmp_->path() / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }
  static test::CliResult localize(const fs::path& map, const fs::path& out, const std::string& extra = "") {
    return test::run_cli("run \"" + sequence().string() + "\" --out \"" + out.string() + "\" --quiet --load-map \"" +
                         map.string() + "\"" + extra);
  }

  static std::unique_ptr<test::TempDir> tmp_;
  static fs::path cache_;
};

std::unique_ptr<test::TempDir> MapReuse::tmp_;
fs::path MapReuse::cache_;

// frames.csv's state column, frame by frame.
std::vector<std::string> frame_states(const fs::path& run) {
  const auto log = eval::read_frame_log(run / "frames.csv");
  const auto col = std::find(log.header.begin(), log.header.end(), "state") - log.header.begin();
  std::vector<std::string> out;
  for (const auto& row : log.rows) out.push_back(row[static_cast<std::size_t>(col)]);
  return out;
}

std::size_t tum_rows(const fs::path& file) {
  std::ifstream in(file);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty() && line[0] != '#';
  return n;
}

std::unique_ptr<system::System> make_system(const io::Dataset& ds, bool localization_only = false) {
  auto options = system::load_system_options(ds.format(), std::nullopt);
  options.sequential = true;
  options.localization_only = localization_only;
  return std::make_unique<system::System>(ds.calibration(), options, system::load_vocabulary(options));
}

TEST_F(MapReuse, SaveLoadSaveIsByteIdentical) {
  const std::string bytes = map_bytes();
  const auto contents = system::map_from_bytes(bytes, "office.plmap");
  EXPECT_GE(contents.keyframes.size(), 3u);
  EXPECT_GT(contents.points.size(), 500u);
  EXPECT_GT(contents.lines.size(), 50u);
  const auto ds = io::open_dataset(sequence(), {});
  auto slam = make_system(*ds);
  slam->load_map(contents);
  EXPECT_EQ(slam->map().num_keyframes(), contents.keyframes.size());
  EXPECT_EQ(slam->map().num_points(), contents.points.size());
  EXPECT_EQ(slam->map().num_lines(), contents.lines.size());
  ASSERT_NE(slam->keyframe_database(), nullptr);
  EXPECT_EQ(slam->keyframe_database()->size(), contents.keyframes.size());
  auto meta = contents.meta;
  const auto again = system::map_to_bytes(slam->capture_map(meta));
  ASSERT_EQ(again.size(), bytes.size());
  EXPECT_TRUE(again == bytes);
}

TEST_F(MapReuse, RestoredObjectsAreTheSavedOnes) {
  const auto contents = system::load_map_file(map_file());
  map::Map map;
  system::restore_map(contents, map, nullptr);
  const auto kfs = map.keyframes();
  ASSERT_EQ(kfs.size(), contents.keyframes.size());
  for (std::size_t i = 0; i < kfs.size(); ++i) {
    const auto& saved = contents.keyframes[i];
    EXPECT_EQ(kfs[i]->id(), saved.id);
    EXPECT_TRUE(kfs[i]->pose().matrix() == saved.T_cw.matrix());
    EXPECT_EQ(kfs[i]->data().keypoints.size(), saved.data->keypoints.size());
    EXPECT_TRUE(kfs[i]->data().has_grid());
    for (const auto& [id, w] : saved.covisibility) {
      const auto it = std::find_if(kfs.begin(), kfs.end(), [id = id](auto* k) { return k->id() == id; });
      ASSERT_NE(it, kfs.end());
      EXPECT_EQ(kfs[i]->weight(*it), w);
    }
    if (saved.parent >= 0) {
      ASSERT_NE(kfs[i]->parent(), nullptr);
      EXPECT_EQ(kfs[i]->parent()->id(), saved.parent);
    }
  }
  const auto points = map.points();
  ASSERT_EQ(points.size(), contents.points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto& saved = contents.points[i];
    EXPECT_EQ(points[i]->id(), saved.id);
    EXPECT_EQ(points[i]->position(), saved.a);
    EXPECT_EQ(static_cast<std::size_t>(points[i]->num_observations()), saved.observations.size());
    for (const auto& [kf, idx] : points[i]->observation_list()) EXPECT_EQ(kf->map_point(idx), points[i]);
  }
  // New objects never reuse a saved id.
  auto* p = map.create_point(Eigen::Vector3d::Zero(), kfs.front(), 0);
  EXPECT_GE(p->id(), contents.meta.next_ids.point);
}

TEST_F(MapReuse, EveryFlippedByteIsCaught) {
  const std::string bytes = map_bytes();
  std::mt19937_64 rng(7);
  for (int i = 0; i < 300; ++i) {
    std::string b = bytes;
    const std::size_t at = rng() % b.size();
    b[at] = static_cast<char>(b[at] ^ static_cast<char>(1 + rng() % 255));
    EXPECT_THROW(system::map_from_bytes(b, "flipped.plmap"), InputError) << "byte " << at;
  }
}

// Behind the checksums: random bytes flipped in a file whose checksums are not verified give a
// clean error or a map that restores, never a crash (the sanitizer stages watch this one).
TEST_F(MapReuse, FlippedBytesBehindTheChecksumsNeverCrash) {
  const std::string bytes = map_bytes();
  std::mt19937_64 rng(11);
  int rejected = 0, accepted = 0;
  system::MapReadOptions unchecked;
  unchecked.verify_checksums = false;
  for (int i = 0; i < 300; ++i) {
    std::string b = bytes;
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int f = 0; f < flips; ++f) {
      // Half the flips land in the first 64 KB (headers, meta, the first keyframe's counts).
      const std::size_t at = (i % 2 ? rng() % std::min<std::size_t>(b.size(), 65536) : rng() % b.size());
      b[at] = static_cast<char>(b[at] ^ static_cast<char>(1 << (rng() % 8)));
    }
    try {
      const auto c = system::map_from_bytes(b, "flipped.plmap", unchecked);
      map::Map map;
      system::restore_map(c, map, nullptr);
      ++accepted;
    } catch (const InputError&) {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_GT(accepted, 0);  // most flips in float payloads leave a valid map
}

TEST_F(MapReuse, TruncatedAndForeignFilesAreRejected) {
  const std::string bytes = map_bytes();
  for (std::size_t keep : {std::size_t{0}, std::size_t{7}, std::size_t{16}, std::size_t{40}, bytes.size() / 2,
                           bytes.size() - 1}) {
    try {
      system::map_from_bytes(bytes.substr(0, keep), "cut.plmap");
      ADD_FAILURE() << "accepted a file cut to " << keep << " bytes";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      EXPECT_EQ(e.file(), "cut.plmap");
    }
  }
  EXPECT_THROW(system::map_from_bytes(bytes + "x", "long.plmap"), InputError);
  EXPECT_THROW(system::map_from_bytes("plsvocab and more bytes here", "voc.plmap"), InputError);
}

TEST_F(MapReuse, BadMapFilesGetOneLineErrorsAndExit2) {
  const std::string bytes = map_bytes();
  std::string wrong_version = bytes;
  wrong_version[8] = 9;
  std::string corrupt = bytes;
  corrupt[bytes.size() / 2] = static_cast<char>(corrupt[bytes.size() / 2] ^ 0x10);
  const std::vector<std::pair<fs::path, std::string>> cases = {
      {written("cut.plmap", bytes.substr(0, bytes.size() / 3)), "truncated"},
      {written("corrupt.plmap", corrupt), "checksum mismatch"},
      {written("version.plmap", wrong_version), "version 9"},
      {written("foreign.plmap", "just some text\n"), "not a plslam map"},
      {tmp_->path() / "missing.plmap", "not found"},
      {edited_map("vocab.plmap", [](auto& c) { c.meta.vocabulary_checksum ^= 1; }), "vocabulary"},
      {edited_map("baseline.plmap", [](auto& c) { c.meta.calib.baseline *= 2; }), "baseline"},
      {edited_map("size.plmap", [](auto& c) { c.meta.calib.width = 640; }), "640x480"},
      {edited_map("fx.plmap", [](auto& c) { c.meta.calib.fx *= 1.01; }), "intrinsics"},
  };
  for (const auto& [file, expected] : cases) {
    test::TempDir out;
    const auto r = localize(file, out.path() / "run", " --localize");
    EXPECT_EQ(r.exit_code, 2) << file << ": " << r.err;
    EXPECT_NE(r.err.find(file.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out.path() / "run" / "stats.json")) << file;
  }
  // Usage: --localize needs a map; no place recognition cannot find the camera in one.
  test::TempDir out;
  EXPECT_EQ(test::run_cli("run \"" + sequence().string() + "\" --out \"" + out.path().string() + "\" --localize")
                .exit_code,
            2);
  const auto r = localize(map_file(), out.path() / "np", " --no-place-recognition");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("place recognition"), std::string::npos) << r.err;
}

TEST_F(MapReuse, UnwritableSaveMapFailsBeforeAnyFrame) {
  test::TempDir out;
  const fs::path a_file = out.path() / "a_file";
  std::ofstream(a_file) << "x";
  for (const fs::path& target : {a_file / "map.plmap", out.path()}) {
    const auto r = test::run_cli("run \"" + sequence().string() + "\" --out \"" + (out.path() / "run").string() +
                                 "\" --quiet --save-map \"" + target.string() + "\"");
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(target.string()), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out.path() / "run" / "stats.json"));
  }
  // A failing write leaves no file under the final name (PLSLAM_FAIL_WRITE stands in for a full disk).
  const fs::path map = out.path() / "full.plmap";
  ::setenv("PLSLAM_FAIL_WRITE", "full.plmap", 1);
  const auto r = test::run_cli("run \"" + sequence().string() + "\" --out \"" + (out.path() / "run2").string() +
                               "\" --quiet --max-frames 5 --save-map \"" + map.string() + "\"");
  ::unsetenv("PLSLAM_FAIL_WRITE");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("full.plmap"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(map));
  for (const auto& e : fs::directory_iterator(out.path())) {
    EXPECT_EQ(e.path().filename().string().find("full.plmap"), std::string::npos) << e.path();
  }
}

TEST_F(MapReuse, LocalizationOnlyTracksEveryFrameInTheMapFrameAndAddsNothing) {
  test::TempDir out;
  const auto r = localize(map_file(), out.path() / "loc", " --localize --save-map \"" +
                                                              (out.path() / "after.plmap").string() + "\"");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto stats = nlohmann::json::parse(test::read_file(out.path() / "loc" / "stats.json"));
  const auto contents = system::load_map_file(map_file());
  // The first frame is relocalized in the map, and the frames recover from it until it is
  // confirmed (EuRoC preset: 5 frames, each with inliers all over the map's part of the image);
  // every frame from then on is localized.
  const auto states = frame_states(out.path() / "loc");
  ASSERT_EQ(states.size(), static_cast<std::size_t>(kFrames));
  const auto first = std::find(states.begin(), states.end(), "localized") - states.begin();
  EXPECT_GE(first, 4);
  EXPECT_LE(first, 10);
  for (long i = 0; i < kFrames; ++i) EXPECT_EQ(states[i], i < first ? "recovering" : "localized") << i;
  const auto localized = static_cast<std::size_t>(kFrames - first);
  EXPECT_EQ(stats["tracked_frames"], localized);
  EXPECT_EQ(stats["frame_states"]["localized"], localized);
  EXPECT_EQ(stats["frame_states"]["recovering"], first);
  EXPECT_EQ(stats["relocalizations"]["frames"], nlohmann::json::array({0}));
  // trajectory.tum holds only the trusted poses: the localized ones.
  EXPECT_EQ(tum_rows(out.path() / "loc" / "trajectory.tum"), localized);
  EXPECT_NE(r.out.find(fmt::format("frame states: tracked 0, relocalized 0, localized {}, recovering {}, unanchored 0, inertial 0, lost 0",
                                   localized, first)),
            std::string::npos)
      << r.out;
  EXPECT_EQ(stats["keyframes"], contents.keyframes.size());
  EXPECT_EQ(stats["map"]["localization_only"], true);
  // The map's world is the mapping run's: positions agree with the ground truth through the
  // anchor saved with the map, with no alignment.
  ASSERT_TRUE(stats.contains("accuracy_in_map_frame")) << stats.dump();
  EXPECT_LT(stats["accuracy_in_map_frame"]["ape_trans_m"]["rmse"].get<double>(), 0.03);
  const auto after = system::load_map_file(out.path() / "after.plmap");
  EXPECT_EQ(after.keyframes.size(), contents.keyframes.size());
  EXPECT_EQ(after.points.size(), contents.points.size());
  EXPECT_EQ(after.lines.size(), contents.lines.size());
}

TEST_F(MapReuse, ALocalizationUnderMinLocalizedExitsThreeWithItsOutputsWritten) {
  test::TempDir out;
  const auto r = localize(map_file(), out.path() / "loc", " --localize --min-localized 1");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("--min-localized 1;"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(map_file().string()), std::string::npos) << r.err;
  // One error line (the rest of stderr is the log).
  const auto error_lines = [](const std::string& text) {
    std::size_t n = 0;
    for (std::size_t at = text.find("plslam: error:"); at != std::string::npos; at = text.find("plslam: error:", at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(error_lines(r.err), 1u) << r.err;
  for (const char* f : {"trajectory.tum", "frames.csv", "stats.json", "keyframes.tum"}) {
    EXPECT_TRUE(fs::exists(out.path() / "loc" / f)) << f;
  }
  const auto stats = nlohmann::json::parse(test::read_file(out.path() / "loc" / "stats.json"));
  EXPECT_EQ(stats["map"]["min_localized"], 1.0);
  // --min-localized is for --localize runs only.
  EXPECT_EQ(test::run_cli("run \"" + sequence().string() + "\" --out \"" + (out.path() / "x").string() +
                          "\" --load-map \"" + map_file().string() + "\" --min-localized 0.5")
                .exit_code,
            2);
}

TEST_F(MapReuse, MappingContinuesOnALoadedMap) {
  test::TempDir out;
  const fs::path first = out.path() / "first.plmap", both = out.path() / "both.plmap";
  auto r = test::run_cli("run \"" + sequence().string() + "\" --out \"" + (out.path() / "a").string() +
                         "\" --quiet --sequential --max-frames 20 --save-map \"" + first.string() + "\"");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_cli("run \"" + sequence().string() + "\" --out \"" + (out.path() / "b").string() +
                    "\" --quiet --sequential --start 10 --load-map \"" + first.string() + "\" --save-map \"" +
                    both.string() + "\"");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto stats = nlohmann::json::parse(test::read_file(out.path() / "b" / "stats.json"));
  // Frame 10 relocalizes in the loaded map; its frames recover (no keyframe) until it is confirmed,
  // then tracking maps on: tracked, relocalized once, tracked.
  const auto states = frame_states(out.path() / "b");
  ASSERT_EQ(states.size(), static_cast<std::size_t>(kFrames - 10));
  const auto confirmed = std::find(states.begin(), states.end(), "relocalized") - states.begin();
  ASSERT_LT(confirmed, static_cast<long>(states.size()));
  for (long i = 0; i < static_cast<long>(states.size()); ++i) {
    EXPECT_EQ(states[i], i < confirmed ? "recovering" : i == confirmed ? "relocalized" : "tracked") << i;
  }
  EXPECT_EQ(stats["tracked_frames"], kFrames - 10 - confirmed);
  EXPECT_EQ(stats["new_map_segments"]["count"], 0);
  EXPECT_EQ(stats["relocalizations"]["count"], 1) << stats["relocalizations"].dump();
  const auto a = system::load_map_file(first), b = system::load_map_file(both);
  EXPECT_GT(b.keyframes.size(), a.keyframes.size());
  EXPECT_GT(b.points.size(), a.points.size());
  // The loaded keyframes keep their ids; the new ones continue after them.
  EXPECT_EQ(b.keyframes.front().id, a.keyframes.front().id);
  EXPECT_GE(b.keyframes.back().id, a.meta.next_ids.keyframe);
  ASSERT_TRUE(stats.contains("accuracy_in_map_frame")) << stats.dump();
  EXPECT_LT(stats["accuracy_in_map_frame"]["ape_trans_m"]["rmse"].get<double>(), 0.05);
}

TEST_F(MapReuse, InfoAndExport) {
  auto r = test::run_cli("map info \"" + map_file().string() + "\" --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto contents = system::load_map_file(map_file());
  EXPECT_EQ(j["keyframes"], contents.keyframes.size());
  EXPECT_EQ(j["points"], contents.points.size());
  EXPECT_EQ(j["lines"], contents.lines.size());
  EXPECT_EQ(j["version"], system::kMapFileVersion);
  // A run's map has IMU states exactly when the run turned its world to gravity.
  EXPECT_EQ(j["gravity_aligned"].get<bool>(), j["keyframes_with_imu_state"].get<long>() > 0) << r.out;
  EXPECT_EQ(j["calibration"]["width"], 752);
  EXPECT_FALSE(j["vocabulary"].is_null());
  EXPECT_EQ(j["ground_truth_anchor"], true);
  EXPECT_NE(j["config"].get<std::string>().find("euroc"), std::string::npos);
  test::TempDir out;
  r = test::run_cli("map export \"" + map_file().string() + "\" --out \"" + out.path().string() + "\"");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(test::read_file(out.path() / "map_points.ply").find(fmt::format("element vertex {}", contents.points.size())),
            std::string::npos);
  EXPECT_TRUE(fs::exists(out.path() / "map_lines.ply"));
  std::ifstream tum(out.path() / "keyframes.tum");
  std::size_t rows = 0;
  for (std::string line; std::getline(tum, line);) rows += !line.empty() && line[0] != '#';
  EXPECT_EQ(rows, contents.keyframes.size());
  r = test::run_cli("map info \"" + (tmp_->path() / "nothing.plmap").string() + "\"");
  EXPECT_EQ(r.exit_code, 2);
}

}  // namespace
}  // namespace plslam

namespace plslam {
namespace {

// Exact data: every field written is read back as it was, and bytes -> contents -> bytes holds.
TEST(MapFileFormat, HandMadeContentsRoundTripExactly) {
  const auto c = test::tiny_map_contents();
  const std::string bytes = system::map_to_bytes(c);
  if (const char* seed = std::getenv("PLSLAM_WRITE_MAP_SEED")) std::ofstream(seed, std::ios::binary) << bytes;
  const auto r = system::map_from_bytes(bytes, "tiny.plmap");
  EXPECT_EQ(system::map_to_bytes(r), bytes);
  EXPECT_EQ(r.meta.calib.cx, 31.5);
  EXPECT_EQ(r.meta.vocabulary_checksum, 0x1234u);
  ASSERT_TRUE(r.meta.T_gt_map.has_value());
  EXPECT_TRUE(r.meta.T_gt_map->matrix() == c.meta.T_gt_map->matrix());
  ASSERT_EQ(r.keyframes.size(), 2u);
  const auto& k = r.keyframes[1];
  EXPECT_EQ(k.parent, 0);
  EXPECT_EQ(k.data->keypoints[2].angle, 90.f);
  EXPECT_EQ(k.data->keypoints[1].octave, 1);
  EXPECT_EQ(k.data->u_right[2], -1.f);
  EXPECT_EQ(k.data->descriptors.at<unsigned char>(2, 31), 8);
  EXPECT_EQ(k.data->lines[0].end_cam, Eigen::Vector3d(0.5, 0.3, 2.5));
  EXPECT_TRUE(k.data->lines[0].stereo);
  EXPECT_TRUE(k.data->has_grid());
  ASSERT_NE(k.place, nullptr);
  EXPECT_EQ(k.place->features[0].second, (std::vector<std::uint32_t>{0, 2}));
  EXPECT_EQ(r.points[0].observations, c.points[0].observations);
  EXPECT_EQ(r.points[0].state.visible, 4);
  EXPECT_EQ(r.lines[0].b, c.lines[0].b);
  EXPECT_TRUE(r.meta.gravity_aligned);
  ASSERT_TRUE(r.keyframes[0].imu && r.keyframes[1].imu);
  EXPECT_EQ(r.keyframes[0].imu->previous, -1);
  EXPECT_TRUE(r.keyframes[0].imu->estimated);
  const auto& imu = *r.keyframes[1].imu;
  EXPECT_EQ(imu.v, c.keyframes[1].imu->v);
  EXPECT_EQ(imu.bias.acc, c.keyframes[1].imu->bias.acc);
  EXPECT_FALSE(imu.estimated);
  EXPECT_EQ(imu.previous, 0);
  ASSERT_NE(imu.from_previous, nullptr);
  // Integrated again from the saved samples: the same deltas, bit for bit.
  const auto& pim = *c.keyframes[1].imu->from_previous;
  EXPECT_TRUE(imu.from_previous->delta_R() == pim.delta_R());
  EXPECT_TRUE(imu.from_previous->delta_p() == pim.delta_p());
  EXPECT_TRUE(imu.from_previous->covariance() == pim.covariance());
  map::Map map;
  system::restore_map(r, map, nullptr);
  ASSERT_TRUE(map.keyframes()[1]->has_imu());
  EXPECT_EQ(map.keyframes()[1]->imu()->previous, map.keyframes()[0]);
  EXPECT_EQ(map.keyframes()[0]->imu_next(), map.keyframes()[1]);
  EXPECT_EQ(map.keyframes()[1]->imu()->from_previous, imu.from_previous);
  EXPECT_EQ(map.keyframes()[1]->parent(), map.keyframes()[0]);
  EXPECT_EQ(map.keyframes()[0]->loop_edges().size(), 1u);
  EXPECT_EQ(map.points()[0]->observation_weight(), 4);  // two stereo observations
  EXPECT_EQ(map.next_ids().point, 5);
}

// Files of format version 1 (before the IMU states) are read: no IMU state, a world not known to be
// gravity-aligned. The fuzz seed tiny_two_keyframes is one.
TEST(MapFileFormat, VersionOneFilesAreRead) {
  const auto path = fs::path(PLSLAM_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / "map_file" / "tiny_two_keyframes";
  const std::string bytes = test::read_file(path);
  std::uint32_t version = 0;
  ASSERT_GE(bytes.size(), 12u);
  std::memcpy(&version, bytes.data() + 8, 4);
  ASSERT_EQ(version, 1u);
  const auto r = system::map_from_bytes(bytes, path.string());
  ASSERT_EQ(r.keyframes.size(), 2u);
  EXPECT_EQ(r.meta.version, 1u);
  EXPECT_FALSE(r.meta.gravity_aligned);
  EXPECT_FALSE(r.keyframes[0].imu || r.keyframes[1].imu);
  // Written again, it is a version 2 file with the same contents.
  const auto again = system::map_from_bytes(system::map_to_bytes(r), "again.plmap");
  EXPECT_EQ(again.keyframes.size(), 2u);
  EXPECT_EQ(again.points[0].observations, r.points[0].observations);
}

// What the structure checks catch behind valid checksums.
TEST(MapFileFormat, InconsistentContentsAreRejected) {
  const std::vector<std::pair<std::function<void(system::MapContents&)>, std::string>> cases = {
      {[](auto& c) { c.points[0].observations[1].second = 7; }, "out of range"},
      {[](auto& c) { c.points[0].observations[1].first = 9; }, "unknown keyframe 9"},
      {[](auto& c) {
         c.lines.push_back(c.lines[0]);
         c.lines[1].id = 3;
         c.meta.next_ids.line = 4;
       }, "holds two lines"},
      {[](auto& c) { c.keyframes[0].parent = 1; }, "cycle"},
      {[](auto& c) { c.keyframes[1].covisibility = {{5, 1}}; }, "unknown keyframe 5"},
      {[](auto& c) { c.points[0].id = 9; }, "next id"},
      {[](auto& c) { c.meta.calib.baseline = 0; }, "calibration"},
      {[](auto& c) { c.keyframes[0].T_cw = geometry::SE3(2 * Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()); }, "rotation"},
      {[](auto& c) {
         auto p = std::make_shared<place::PlaceDescription>(*c.keyframes[0].place);
         p->bow[1].first = 10;
         c.keyframes[0].place = p;
       }, "bad word"},
      {[](auto& c) { c.keyframes[1].imu->previous = 7; }, "IMU predecessor 7 unknown"},
      {[](auto& c) { c.keyframes[0].imu.reset(); }, "IMU predecessor 0 has no IMU state"},
      {[](auto& c) {
         auto d = std::make_shared<map::FrameData>(*c.keyframes[1].data);
         d->timestamp = 0.6;  // the samples end at 0.5
         c.keyframes[1].data = d;
       }, "is not the one from keyframe 0"},
  };
  for (const auto& [edit, expected] : cases) {
    auto c = test::tiny_map_contents();
    edit(c);
    try {
      system::map_from_bytes(system::map_to_bytes(c), "tiny.plmap");
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace plslam
