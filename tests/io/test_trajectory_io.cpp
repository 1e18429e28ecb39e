#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/io/trajectory_io.h"
#include "support/test_support.h"

namespace plslam::io {
namespace {

Trajectory random_trajectory(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Trajectory traj;
  double t = 1403715273.262142976;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
    q.normalize();
    StampedPose sp;
    sp.t = t;
    sp.T.linear() = q.toRotationMatrix();
    sp.T.translation() = Eigen::Vector3d(g(rng), g(rng), g(rng)) * 100.0;
    traj.push_back(sp);
    t += 0.05;
  }
  return traj;
}

void write_text(const std::filesystem::path& p, const std::string& s) {
  std::ofstream(p) << s;
}

class RoundTrip : public ::testing::TestWithParam<TrajectoryFormat> {};

TEST_P(RoundTrip, WrittenFileReadsBackToSamePoses) {
  test::TempDir tmp;
  const auto traj = random_trajectory(200, 7);
  const auto path = tmp.path() / "traj.txt";
  write_trajectory(path, traj, GetParam());
  std::vector<double> times;
  for (const auto& p : traj) times.push_back(p.t);
  const auto back = read_trajectory(path, GetParam(), &times);
  ASSERT_EQ(back.size(), traj.size());
  for (std::size_t i = 0; i < traj.size(); ++i) {
    EXPECT_NEAR(back[i].t, traj[i].t, 1e-6);
    EXPECT_LT((back[i].T.matrix() - traj[i].T.matrix()).cwiseAbs().maxCoeff(), 1e-9) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(AllFormats, RoundTrip,
                         ::testing::Values(TrajectoryFormat::kTum, TrajectoryFormat::kKitti,
                                           TrajectoryFormat::kEuroc));

TEST(TrajectoryIo, TumTimestampsRoundTripToNanoseconds) {
  test::TempDir tmp;
  const auto traj = random_trajectory(10, 1);
  write_trajectory(tmp.path() / "a.tum", traj, TrajectoryFormat::kTum);
  const auto back = read_trajectory(tmp.path() / "a.tum", TrajectoryFormat::kTum);
  for (std::size_t i = 0; i < traj.size(); ++i) EXPECT_NEAR(back[i].t, traj[i].t, 1e-9);
}

TEST(TrajectoryIo, ReadsEurocCsvWithExtraColumns) {
  test::TempDir tmp;
  const auto p = tmp.path() / "gt.csv";
  write_text(p,
             "#timestamp, p_x, p_y, p_z, q_w, q_x, q_y, q_z, v_x, v_y, v_z\n"
             "1403715273262142976,0.878,2.142,0.947,0.0,1.0,0.0,0.0,0.1,0.2,0.3\n"
             "1403715273312143104,0.879,2.143,0.948,1.0,0.0,0.0,0.0,0.1,0.2,0.3\n");
  const auto traj = read_trajectory(p, TrajectoryFormat::kEuroc);
  ASSERT_EQ(traj.size(), 2u);
  EXPECT_NEAR(traj[0].t, 1403715273.262142976, 1e-6);
  EXPECT_NEAR(traj[0].T.translation().y(), 2.142, 1e-12);
  // q = (w=0, x=1): a rotation of pi about x.
  EXPECT_NEAR(traj[0].T.rotation()(1, 1), -1.0, 1e-12);
  EXPECT_NEAR(traj[1].T.rotation()(1, 1), 1.0, 1e-12);
}

TEST(TrajectoryIo, KittiWithoutTimesUsesIndex) {
  test::TempDir tmp;
  const auto p = tmp.path() / "00.txt";
  write_text(p, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1.5 0 1 0 0 0 0 1 2\n");
  const auto traj = read_trajectory(p, TrajectoryFormat::kKitti);
  ASSERT_EQ(traj.size(), 2u);
  EXPECT_DOUBLE_EQ(traj[1].t, 1.0);
  EXPECT_DOUBLE_EQ(traj[1].T.translation().x(), 1.5);
  EXPECT_DOUBLE_EQ(traj[1].T.translation().z(), 2.0);
}

TEST(TrajectoryIo, DetectsFormatByExtensionAndColumns) {
  test::TempDir tmp;
  write_text(tmp.path() / "a.txt", "0 0 0 0 0 0 0 1\n");
  write_text(tmp.path() / "b.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
  write_text(tmp.path() / "c.txt", "1,0,0,0,1,0,0,0\n");
  write_text(tmp.path() / "d.txt", "1 2 3\n");
  EXPECT_EQ(detect_trajectory_format(tmp.path() / "a.txt"), TrajectoryFormat::kTum);
  EXPECT_EQ(detect_trajectory_format(tmp.path() / "b.txt"), TrajectoryFormat::kKitti);
  EXPECT_EQ(detect_trajectory_format(tmp.path() / "c.txt"), TrajectoryFormat::kEuroc);
  EXPECT_EQ(detect_trajectory_format(tmp.path() / "x.csv"), TrajectoryFormat::kEuroc);
  EXPECT_THROW(detect_trajectory_format(tmp.path() / "d.txt"), InputError);
}

// Bad input: each case throws an InputError whose message names the file and the line.
struct BadCase {
  const char* name;
  TrajectoryFormat format;
  const char* text;
  const char* expect;  // a fragment of the message
};

class BadTrajectory : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadTrajectory, GivesOneLineErrorNamingFile) {
  test::TempDir tmp;
  const auto p = tmp.path() / "bad.txt";
  write_text(p, GetParam().text);
  try {
    read_trajectory(p, GetParam().format);
    FAIL() << "no error for " << GetParam().name;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(GetParam().expect), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadTrajectory,
    ::testing::Values(
        BadCase{"tum_7_columns", TrajectoryFormat::kTum, "0 0 0 0 0 0 1\n", "line 1: expected 8 columns"},
        BadCase{"kitti_11_columns", TrajectoryFormat::kKitti, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 1 0 0 0 0 1 0\n",
                "line 2: expected 12 columns"},
        BadCase{"euroc_short", TrajectoryFormat::kEuroc, "1,2,3\n", "expected at least 8 columns"},
        BadCase{"nan", TrajectoryFormat::kTum, "0 nan 0 0 0 0 0 1\n", "non-finite"},
        BadCase{"text", TrajectoryFormat::kTum, "0 abc 0 0 0 0 0 1\n", "is not a number"},
        BadCase{"unsorted", TrajectoryFormat::kTum, "1 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n", "not after"},
        BadCase{"bad_quaternion", TrajectoryFormat::kTum, "0 0 0 0 0 0 0 3\n", "quaternion norm"},
        BadCase{"empty", TrajectoryFormat::kTum, "# only a comment\n", "empty trajectory"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(TrajectoryIo, MissingFileIsInputError) {
  EXPECT_THROW(read_trajectory("/nonexistent/traj.txt", TrajectoryFormat::kTum), InputError);
}

TEST(TrajectoryIo, KittiTimesLengthMismatchIsInputError) {
  test::TempDir tmp;
  write_text(tmp.path() / "k.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
  const std::vector<double> times{0.0, 0.1};
  EXPECT_THROW(read_trajectory(tmp.path() / "k.txt", TrajectoryFormat::kKitti, &times), InputError);
}

}  // namespace
}  // namespace plslam::io
