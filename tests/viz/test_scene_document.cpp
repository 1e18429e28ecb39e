// The viewer's scene document and the run-folder files it is read from (exact values written by
// the same writers `plslam run` uses).
#include <fstream>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/map_export.h"
#include "plslam/io/trajectory_io.h"
#include "plslam/viz/scene_document.h"
#include "support/test_support.h"

namespace plslam::viz {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

TEST(PlyFiles, ReadBackWhatTheWritersWrite) {
  test::TempDir dir;
  const std::vector<Eigen::Vector3d> points = {{1.5, -2.25, 3.125}, {0, 0, 0}, {-1e3, 2e-6, 7}};
  io::write_ply_points(dir.path() / "p.ply", points);
  const auto read = io::read_ply_points(dir.path() / "p.ply");
  ASSERT_EQ(read.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) EXPECT_LT((read[i] - points[i]).norm(), 1e-6);
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> lines = {{{0, 1, 2}, {3, 4, 5}}, {{-1, -2, -3}, {6, 7, 8}}};
  io::write_ply_lines(dir.path() / "l.ply", lines);
  const auto lread = io::read_ply_lines(dir.path() / "l.ply");
  ASSERT_EQ(lread.size(), 2u);
  EXPECT_LT((lread[1].second - lines[1].second).norm(), 1e-6);
  // Points read as lines (no edges) and lines read as points are refused.
  EXPECT_THROW(io::read_ply_lines(dir.path() / "p.ply"), InputError);
  EXPECT_THROW(io::read_ply_points(dir.path() / "l.ply"), InputError);
  io::write_ply_points(dir.path() / "empty.ply", {});
  EXPECT_TRUE(io::read_ply_points(dir.path() / "empty.ply").empty());
}

TEST(PlyFiles, MalformedFilesAreOneLineErrorsNamingTheFile) {
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
                             "property float z\nend_header\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "not a PLY file"},
      {"ply\nformat binary_little_endian 1.0\n", "format ascii"},
      {header + "1 2 3\n", "1 of 2 vertices"},
      {header + "1 2 3\n4 5\n", "line 9"},
      {header + "1 2 3\n4 5 nan\n", "finite"},
      {header + "1 2 3\n4 5 6\n7 8 9\n", "after the last element"},
      {"ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\nproperty float y\nproperty float z\n"
       "end_header\n1 2 3\n",
       "more than the file holds"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float z\nend_header\n1 2\n", "x y z"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "end_header"},
  };
  for (const auto& [text, problem] : cases) {
    try {
      io::parse_ply(text, "m.ply");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("m.ply: ", 0), 0u) << what;
      EXPECT_NE(what.find(problem), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

// A run folder as `plslam run` writes it, with a known map.
struct RunFolder {
  test::TempDir dir;
  map::MapSnapshot map;
  RunFolder() {
    for (long i = 0; i < 3; ++i) {
      map::KeyframeSnapshot k;
      k.id = 10 + i;
      k.timestamp = static_cast<double>(i);
      k.T_wc = geometry::SE3(Eigen::AngleAxisd(0.1 * static_cast<double>(i), Eigen::Vector3d::UnitY()).toRotationMatrix(),
                             Eigen::Vector3d(static_cast<double>(i), 0, 0.5));
      k.parent = i == 0 ? -1 : 9 + i;
      map.keyframes.push_back(k);
    }
    map.keyframes[0].loop_edges = {12};
    map.keyframes[2].loop_edges = {10};
    map.keyframes[0].covisibility = {{11, 40}, {12, 15}};
    map.keyframes[1].covisibility = {{10, 40}};
    map.keyframes[2].covisibility = {{10, 15}};
    io::write_file_atomically(dir.path() / "map_graph.json", [&](std::ostream& o) { o << map_graph_json(map).dump(); });
    io::write_ply_points(dir.path() / "map_points.ply", {{1, 2, 3}, {4, 5, 6}});
    io::write_ply_lines(dir.path() / "map_lines.ply", {{{0, 0, 1}, {0, 1, 1}}});
    Trajectory traj;
    for (int i = 0; i < 5; ++i) {
      StampedPose p;
      p.t = 0.5 * i;
      p.T.translation() = Eigen::Vector3d(0.5 * i, 0, 0.5);
      traj.push_back(p);
    }
    io::write_trajectory(dir.path() / "trajectory.tum", traj, io::TrajectoryFormat::kTum);
    write(dir.path() / "stats.json",
          R"({"frames": 5, "tracked_frames": 5, "complete": true, "interrupted_by": null, "loops": [{"frame": 4}],
              "relocalizations": {"count": 0, "frames": []},
              "input": {"name": "x", "calibration": {"width": 752, "height": 480, "fx": 458, "fy": 457, "cx": 367,
                                                     "cy": 248, "baseline": 0.11}}})");
  }
};

TEST(SceneDocument, ARunFolderGivesTheMapItsGraphAndTheCountsOfStatsJson) {
  RunFolder run;
  const auto scene = scene_from_run_folder(run.dir.path());
  const json doc = scene_document(scene.map, scene.info);
  EXPECT_EQ(doc["source"], "run");
  EXPECT_EQ(doc["final"], true);
  const auto& c = doc["counts"];
  EXPECT_EQ(c["keyframes"], 3);
  EXPECT_EQ(c["points"], 2);
  EXPECT_EQ(c["lines"], 1);
  EXPECT_EQ(c["loops"], 1);
  EXPECT_EQ(c["relocalizations"], 0);
  EXPECT_EQ(c["frames"], 5);
  EXPECT_EQ(c["frame"], 4);
  EXPECT_EQ(c["state"], "finished");
  EXPECT_EQ(doc["keyframes"]["ids"], json({10, 11, 12}));
  EXPECT_EQ(doc["keyframes"]["parents"], json({-1, 10, 11}));
  // Row-major 3x4: the third keyframe's translation sits at columns 3, 7, 11.
  const auto& poses = doc["keyframes"]["poses"];
  ASSERT_EQ(poses.size(), 36u);
  EXPECT_FLOAT_EQ(poses[24 + 3].get<float>(), 2.0f);
  EXPECT_FLOAT_EQ(poses[24 + 11].get<float>(), 0.5f);
  EXPECT_NEAR(poses[24 + 2].get<float>(), std::sin(0.2), 1e-6);  // R(0,2) of a turn about y
  // Each edge once.
  EXPECT_EQ(doc["loop_edges"], json({{10, 12}}));
  EXPECT_EQ(doc["covisibility"], json({{10, 11, 40}, {10, 12, 15}}));
  EXPECT_EQ(doc["points"]["xyz"], json({1.0, 2.0, 3.0, 4.0, 5.0, 6.0}));
  EXPECT_EQ(doc["lines"]["xyz"], json({0.0, 0.0, 1.0, 0.0, 1.0, 1.0}));
  EXPECT_EQ(doc["trajectory"].size(), 15u);
  EXPECT_FLOAT_EQ(doc["camera"][3].get<float>(), 2.0f);  // the last pose
  EXPECT_EQ(doc["camera_model"]["width"], 752);
  EXPECT_TRUE(doc["ground_truth"].is_null());  // stats.json names no dataset
  EXPECT_TRUE(doc["local_map"].is_null());
}

TEST(SceneDocument, ABrokenRunFolderIsAnInputErrorNamingTheFile) {
  {
    RunFolder run;
    fs::remove(run.dir.path() / "stats.json");
    EXPECT_THROW(scene_from_run_folder(run.dir.path()), InputError);
  }
  {
    RunFolder run;
    write(run.dir.path() / "map_graph.json", R"({"version": 1, "keyframes": [{"id": 1}]})");
    try {
      scene_from_run_folder(run.dir.path());
      FAIL();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("map_graph.json: keyframe 0"), std::string::npos) << e.what();
    }
  }
  {
    RunFolder run;
    write(run.dir.path() / "map_points.ply", "ply\n");
    try {
      scene_from_run_folder(run.dir.path());
      FAIL();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("map_points.ply"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(scene_from_run_folder("/no/such/folder"), InputError);
}

TEST(SceneDocument, StatsWithAnImpossibleCalibrationAreAnInputError) {
  const std::string head = R"({"frames": 3, "input": {"calibration": {"width": )";
  const std::string tail = R"(, "height": 480, "fx": 400, "fy": 400, "cx": 320, "cy": 240, "baseline": 0.1}}})";
  SceneInfo info;
  parse_run_stats(head + "640" + tail, "stats.json", info);
  ASSERT_TRUE(info.camera_model.has_value());
  EXPECT_EQ(info.camera_model->width, 640);
  EXPECT_EQ(info.frame, 2);
  // 1e20 is a float out of int's range (undefined behaviour in a plain get<int>), -640 and 6.5
  // are no image sizes.
  for (const std::string width : {"1e20", "-640", "6.5", "\"640\"", "null"}) {
    SceneInfo bad;
    try {
      parse_run_stats(head + width + tail, "stats.json", bad);
      FAIL() << width;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("stats.json: input.calibration.width"), std::string::npos) << e.what();
    }
  }
  SceneInfo nan_fx;
  EXPECT_THROW(parse_run_stats(R"({"input": {"calibration": {"width": 640, "height": 480, "fx": "x"}}})", "s", nan_fx),
               InputError);
}

TEST(SceneDocument, TheMapGraphReadsBackAsWritten) {
  RunFolder run;
  map::MapSnapshot back;
  parse_map_graph(test::read_file(run.dir.path() / "map_graph.json"), "g", back);
  ASSERT_EQ(back.keyframes.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.keyframes[i].id, run.map.keyframes[i].id);
    EXPECT_EQ(back.keyframes[i].parent, run.map.keyframes[i].parent);
    EXPECT_EQ(back.keyframes[i].loop_edges, run.map.keyframes[i].loop_edges);
    EXPECT_EQ(back.keyframes[i].covisibility, run.map.keyframes[i].covisibility);
    EXPECT_LT((back.keyframes[i].T_wc.translation() - run.map.keyframes[i].T_wc.translation()).norm(), 1e-6);
  }
  map::MapSnapshot dup;
  EXPECT_THROW(parse_map_graph(R"({"version": 1, "keyframes": [
      {"id": 1, "t": 0, "parent": -1, "T_wc": [1,0,0,0, 0,1,0,0, 0,0,1,0], "loop_edges": [], "covisibility": []},
      {"id": 1, "t": 0, "parent": -1, "T_wc": [1,0,0,0, 0,1,0,0, 0,0,1,0], "loop_edges": [], "covisibility": []}]})",
                               "g", dup),
               InputError);
}

// Numbers that parse as JSON but are no ids or weights: a float out of long's range (30 digits:
// undefined behaviour in a plain get<long>, found by fuzz_run_folder), a fraction, a negative
// weight, a number where an array belongs.
TEST(SceneDocument, TheMapGraphRefusesIdsAndWeightsThatAreNoWholeNumbers) {
  const std::string ok_id = R"("id": 1, "parent": -1)";
  const auto graph = [](const std::string& fields) {
    return R"({"version": 1, "keyframes": [{)" + fields +
           R"(, "t": 0, "T_wc": [1,0,0,0, 0,1,0,0, 0,0,1,0]}]})";
  };
  map::MapSnapshot good;
  parse_map_graph(graph(ok_id + R"(, "loop_edges": [2], "covisibility": [[2, 40]])"), "g", good);
  ASSERT_EQ(good.keyframes.size(), 1u);
  EXPECT_EQ(good.keyframes[0].covisibility, (std::vector<std::pair<long, int>>{{2, 40}}));
  for (const std::string bad :
       {R"("id": 222222222222222222222222222222, "parent": -1, "loop_edges": [], "covisibility": [])",
        R"("id": 1.5, "parent": -1, "loop_edges": [], "covisibility": [])",
        R"("id": 18446744073709551615, "parent": -1, "loop_edges": [], "covisibility": [])",
        R"("id": 1, "parent": -1, "loop_edges": [1e300], "covisibility": [])",
        R"("id": 1, "parent": -1, "loop_edges": 5, "covisibility": [])",
        R"("id": 1, "parent": -1, "loop_edges": [], "covisibility": [[2, -3]])",
        R"("id": 1, "parent": -1, "loop_edges": [], "covisibility": [[2, 1e10]])",
        R"("id": 1, "parent": -1, "loop_edges": [], "covisibility": [2, 40])"}) {
    map::MapSnapshot m;
    try {
      parse_map_graph(graph(bad), "map_graph.json", m);
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("map_graph.json: keyframe 0"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace plslam::viz
