// The live viewer: the deltas it publishes, and `plslam run --viewer` watched by a client from
// the first frames to the final state.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <future>
#include <algorithm>
#include <cstdlib>
#include <map>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "plslam/viz/live_viewer.h"
#include "support/test_support.h"

// Last: <resolv.h>, which it brings, defines `_res`, a name Eigen's headers use.
#include <httplib.h>

namespace plslam::viz {
namespace {

using nlohmann::json;

map::MapSnapshot two_keyframes() {
  map::MapSnapshot m;
  for (long i = 0; i < 2; ++i) {
    map::KeyframeSnapshot k;
    k.id = i;
    k.T_wc = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(static_cast<double>(i), 0, 0));
    k.parent = i - 1;
    m.keyframes.push_back(k);
  }
  m.points = {{1, {0, 0, 1}}, {2, {0, 0, 2}}, {3, {0, 0, 3}}};
  m.lines = {{7, {0, 0, 1}, {1, 0, 1}}};
  return m;
}

TEST(SceneDelta, HoldsWhatWasAddedMovedAndRemovedAndNothingElse) {
  const auto before = two_keyframes();
  auto after = before;
  after.points[0].position.z() += 0.0005;  // below the threshold: not sent
  after.points[1].position.z() += 0.01;    // moved
  after.points.erase(after.points.begin() + 2);  // point 3 culled
  after.points.push_back({4, {1, 1, 1}});  // new
  after.keyframes[1].T_wc = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1.5, 0, 0));
  map::KeyframeSnapshot k;
  k.id = 2;
  k.parent = 1;
  after.keyframes.push_back(k);
  after.keyframes[0].covisibility = {{2, 30}};
  after.keyframes[2].covisibility = {{0, 30}};
  after.keyframes[0].loop_edges = {2};
  after.keyframes[2].loop_edges = {0};
  SceneInfo info;
  info.trajectory = {{0, 0, 0}, {0.5, 0, 0}, {1, 0, 0}};
  info.frame = 9;
  info.final = false;
  const json d = scene_delta(before, after, info, 2, 5);
  EXPECT_EQ(d["revision"], 5);
  EXPECT_EQ(d["final"], false);
  EXPECT_EQ(d["points"]["ids"], json({2, 4}));
  EXPECT_EQ(d["points"]["xyz"].size(), 6u);
  EXPECT_EQ(d["points_removed"], json({3}));
  EXPECT_EQ(d["lines"]["ids"], json::array());
  EXPECT_EQ(d["lines_removed"], json::array());
  EXPECT_EQ(d["keyframes"]["ids"], json({1, 2}));
  EXPECT_EQ(d["keyframes_removed"], json::array());
  EXPECT_EQ(d["covisibility"], json({{0, 2, 30}}));
  EXPECT_EQ(d["loop_edges"], json({{0, 2}}));
  EXPECT_EQ(d["trajectory_append"], json({1.0, 0.0, 0.0}));  // only what the page does not have
  EXPECT_EQ(d["counts"]["points"], 3);
  EXPECT_EQ(d["counts"]["keyframes"], 3);
  EXPECT_EQ(d["counts"]["frame"], 9);
  // Nothing changed: empty lists, and the graph is not resent.
  const json none = scene_delta(after, after, info, 3, 6);
  EXPECT_TRUE(none["points"]["ids"].empty());
  EXPECT_TRUE(none["keyframes"]["ids"].empty());
  EXPECT_TRUE(none["trajectory_append"].empty());
  EXPECT_FALSE(none.contains("covisibility"));
  EXPECT_FALSE(none.contains("loop_edges"));
  EXPECT_FALSE(none.contains("trajectory"));  // the page has it: only trajectory_append is sent
  EXPECT_EQ(none["counts"]["loop_edges"], 1);  // the counts stay whole without the graph
  // No count of what the page has: the whole trajectory, replacing the page's.
  const json whole = scene_delta(after, after, info, std::nullopt, 7);
  EXPECT_EQ(whole["trajectory"].size(), 9u);
  EXPECT_FALSE(whole.contains("trajectory_append"));
}

// Landmarks and keyframes are compared with where the page has them, not with the last snapshot:
// moves below the threshold add up until one is sent, so the page never drifts from the map by
// more than the threshold. Numbers go out rounded to a tenth of a millimetre, in few digits.
TEST(SceneDelta, SmallMovesAddUpUntilTheyAreSentAndNumbersAreShort) {
  const auto page = two_keyframes();
  const SceneInfo info;
  const double step = 0.6 * kPageMinMove;
  auto after = page;
  after.points[0].position.z() += step;
  after.keyframes[1].T_wc = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1 + step, 0, 0));
  map::MapSnapshot page_after;
  const json first = scene_delta(page, after, info, 0, 1, kPageMinMove, &page_after);
  EXPECT_TRUE(first["points"]["ids"].empty());
  EXPECT_TRUE(first["keyframes"]["ids"].empty());
  EXPECT_EQ(page_after.points[0].position, page.points[0].position);  // the page keeps its copy
  EXPECT_EQ(page_after.keyframes[1].T_wc.translation(), page.keyframes[1].T_wc.translation());

  // Another step: each is below the threshold, the sum is above it.
  auto later = after;
  later.points[0].position.z() += step;
  later.points[1].position = {1.23456789, -0.000012, 2};  // moved far: sent, and shows the rounding
  later.keyframes[1].T_wc = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1 + 2 * step, 0, 0));
  map::MapSnapshot page_later;
  const json second = scene_delta(page_after, later, info, 0, 2, kPageMinMove, &page_later);
  EXPECT_EQ(second["points"]["ids"], json({1, 2}));
  EXPECT_EQ(second["keyframes"]["ids"], json({1}));
  EXPECT_EQ(page_later.points[0].position, later.points[0].position);
  EXPECT_EQ(second["points"]["xyz"].dump(), fmt::format("[0.0,0.0,{},1.2346,-0.0,2.0]", 1 + 2 * step));
  // Compared with the snapshot before it, the second step alone would not have been sent.
  EXPECT_EQ(scene_delta(after, later, info, 0, 2)["points"]["ids"], json({2}));
}

// The local map's ids go out when they differ from those the page got last, and are left out
// while they are the same (the page keeps its own); without the page's info they always go out.
TEST(SceneDelta, TheLocalMapIsSentOnlyWhenItChanged) {
  const auto map = two_keyframes();
  SceneInfo page_info;
  page_info.local_map = std::make_pair(std::vector<long>{0, 1}, std::vector<long>{1, 2});
  SceneInfo info = page_info;
  const json same = scene_delta(map, map, info, 0, 2, kPageMinMove, nullptr, &page_info);
  EXPECT_FALSE(same.contains("local_map"));
  EXPECT_TRUE(same.contains("counts"));  // the rest of the delta is there
  EXPECT_EQ(scene_delta(map, map, info, 0, 2)["local_map"]["points"], json({1, 2}));

  info.local_map->second.push_back(3);
  const json grown = scene_delta(map, map, info, 0, 3, kPageMinMove, nullptr, &page_info);
  EXPECT_EQ(grown["local_map"]["keyframes"], json({0, 1}));
  EXPECT_EQ(grown["local_map"]["points"], json({1, 2, 3}));

  // A lost camera has no local map: the page is told (null), not left with the old one.
  info.local_map.reset();
  const json lost = scene_delta(map, map, info, 0, 4, kPageMinMove, nullptr, &page_info);
  ASSERT_TRUE(lost.contains("local_map"));
  EXPECT_TRUE(lost["local_map"].is_null());
}

// Centres move with their keyframes; the page gets the new tail, or the whole trail once a centre
// it has moved by more than the threshold (a loop correction), and never for local BA's millimetres.
TEST(LiveTrail, CentresFollowTheirKeyframesAndAreResentOnlyWhenTheyMovedFar) {
  auto map = two_keyframes();  // keyframe 0 at x = 0, keyframe 1 at x = 1
  LiveTrail trail(0.02);
  trail.add(0, {0, 0, 0.5}, {0, 0, 0.5});
  trail.add(1, {0, 0, 0.5}, {1, 0, 0.5});
  trail.add(9, {0, 0, 0}, {5, 5, 5});  // a keyframe not in the snapshot: stays in place
  EXPECT_FALSE(trail.update(map));
  trail.sent(false);
  EXPECT_EQ(trail.page_size(), 3u);
  EXPECT_TRUE(trail.centres()[1].isApprox(Eigen::Vector3d(1, 0, 0.5)));

  // Local BA: keyframe 1 moves 5 mm. The centre follows, nothing is resent.
  map.keyframes[1].T_wc = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1.005, 0, 0));
  trail.add(1, {0, 0, 1}, {1.005, 0, 1});
  EXPECT_FALSE(trail.update(map));
  EXPECT_NEAR(trail.centres()[1].x(), 1.005, 1e-12);
  trail.sent(false);
  EXPECT_EQ(trail.page_size(), 4u);

  // A loop correction turns keyframe 1 by 90 degrees about y and moves it back 0.3 m.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  map.keyframes[1].T_wc = geometry::SE3(R, Eigen::Vector3d(0.7, 0, 0));
  EXPECT_TRUE(trail.update(map));
  EXPECT_TRUE(trail.centres()[1].isApprox(Eigen::Vector3d(0.7 + 0.5, 0, 0), 1e-12));  // R * (0, 0, 0.5) = (0.5, 0, 0)
  EXPECT_TRUE(trail.centres()[3].isApprox(Eigen::Vector3d(1.7, 0, 0), 1e-12));
  EXPECT_TRUE(trail.centres()[0].isApprox(Eigen::Vector3d(0, 0, 0.5)));
  EXPECT_TRUE(trail.centres()[2].isApprox(Eigen::Vector3d(5, 5, 5)));
  trail.sent(true);
  EXPECT_EQ(trail.page_size(), 4u);
  EXPECT_FALSE(trail.update(map));  // the page has them now
}

// Reads the "viewer: URL" line of a command started with popen.
struct CliProcess {
  FILE* pipe = nullptr;
  explicit CliProcess(const std::string& args) {
    pipe = ::popen((std::string(PLSLAM_CLI_PATH) + " " + args + " 2>/dev/null").c_str(), "r");
  }
  std::string read_line() {
    char buf[512];
    return pipe && std::fgets(buf, sizeof buf, pipe) ? std::string(buf) : std::string();
  }
  int close() {
    const int status = pipe ? ::pclose(pipe) : -1;
    pipe = nullptr;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  ~CliProcess() { close(); }
};

// A client follows a run from its first revisions to the end by deltas, as the page does, and
// ends with the counts of stats.json.
TEST(LiveViewerRun, AClientFollowsTheMapAsItGrowsAndEndsOnTheFinalState) {
  test::TempDir dir;
  const auto seq = dir.path() / "office";
  ASSERT_EQ(test::run_cli("synth --scene office --frames 60 --seed 3 --out " + seq.string()).exit_code, 0);
  CliProcess run("run " + seq.string() + " --out " + (dir.path() / "out").string() +
                 " --quiet --viewer --port 0 --viewer-rate 10 --viewer-linger 3");
  // std::regex is avoided: GCC 12 warns inside <regex> at -O1 (the sanitizer builds), -Werror.
  const std::string line = run.read_line();
  const std::string prefix = "viewer: http://127.0.0.1:";
  ASSERT_EQ(line.rfind(prefix, 0), 0u) << line;
  const int port = std::atoi(line.c_str() + prefix.size());
  ASSERT_GT(port, 0) << line;
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(std::chrono::seconds(10));
  auto res = client.Get("/api/scene");
  ASSERT_TRUE(res);
  json doc = json::parse(res->body);
  EXPECT_EQ(doc["source"], "live");
  long revision = doc["revision"];
  std::map<long, int> keyframes_seen;  // keyframe count -> how often seen
  std::set<long> points;
  for (const auto& id : doc["points"]["ids"]) points.insert(id.get<long>());
  bool final = false;
  int deltas = 0;
  // A deadline, not a count: under the sanitizers the run takes minutes.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(5);
  while (!final && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    res = client.Get("/api/scene?since=" + std::to_string(revision));
    ASSERT_TRUE(res);
    if (res->status == 204) continue;
    ASSERT_EQ(res->status, 200);
    const json reply = json::parse(res->body);
    if (reply.value("type", "") == "delta") {
      EXPECT_EQ(reply["from"], revision);
      for (const auto& d : reply["deltas"]) {
        ++deltas;
        for (const auto& id : d["points"]["ids"]) points.insert(id.get<long>());
        for (const auto& id : d["points_removed"]) points.erase(id.get<long>());
        // Applying the deltas gives the map the server counts.
        EXPECT_EQ(points.size(), d["counts"]["points"].get<std::size_t>());
        keyframes_seen[d["counts"]["keyframes"].get<long>()]++;
        final = d["final"];
      }
    } else {
      final = reply["final"];
      doc = reply;
    }
    revision = reply["revision"];
  }
  ASSERT_TRUE(final) << "the run never published its final state";
  EXPECT_GT(deltas, 5);
  EXPECT_GE(keyframes_seen.size(), 3u) << "the keyframe count did not grow while watched";
  EXPECT_EQ(doc["source"], "run");
  const json stats = json::parse(test::read_file(dir.path() / "out/stats.json"));
  EXPECT_EQ(doc["counts"]["keyframes"], stats["keyframes"]);
  EXPECT_EQ(doc["counts"]["points"], stats["map_points"]);
  EXPECT_EQ(doc["counts"]["lines"], stats["map_lines"]);
  EXPECT_EQ(doc["counts"]["frames"], stats["frames"]);
  EXPECT_NEAR(doc["ground_truth"]["ate_rmse_m"].get<double>(), stats["accuracy"]["ape_trans_m"]["rmse"].get<double>(),
              1e-9);
  EXPECT_EQ(run.close(), 0);
}

TEST(LiveViewerRun, APortInUseStopsTheRunBeforeItsFirstFrame) {
  test::TempDir dir;
  httplib::Server blocker;
  const int port = blocker.bind_to_any_port("127.0.0.1");
  ASSERT_GT(port, 0);
  const auto seq = dir.path() / "office";
  ASSERT_EQ(test::run_cli("synth --scene office --frames 5 --seed 3 --out " + seq.string()).exit_code, 0);
  const auto r = test::run_cli("run " + seq.string() + " --out " + (dir.path() / "out").string() +
                               " --viewer --port " + std::to_string(port));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("127.0.0.1:" + std::to_string(port) + ": cannot serve the viewer there (the port is in use"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out/stats.json"));  // no frame was processed
  const auto bad = test::run_cli("run x --out " + (dir.path() / "o").string() + " --port 9000");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("need --viewer"), std::string::npos) << bad.err;
}

TEST(ViewCli, BadTargetsAndOptionsAreOneLineErrors) {
  test::TempDir dir;
  std::ofstream(dir.path() / "not_a_map.plmap") << "hello";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"view " + (dir.path() / "missing.plmap").string(), "missing.plmap: map file not found"},
      {"view " + dir.path().string(), "stats.json: file not found"},
      {"view " + (dir.path() / "not_a_map.plmap").string(), "not_a_map.plmap: "},
      {"view " + dir.path().string() + " --port 70000", "--port 70000: must be 0..65535"},
      {"view " + dir.path().string() + " --assets " + dir.path().string(), "no index.html"},
  };
  for (const auto& [args, message] : cases) {
    const auto r = test::run_cli(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << "no URL for a viewer that is not serving: " << r.out;
  }
}

}  // namespace
}  // namespace plslam::viz
