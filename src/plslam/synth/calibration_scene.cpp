#include "plslam/synth/calibration_scene.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

#include "plslam/synth/texture.h"

namespace plslam::synth {
namespace {

constexpr int kPxPerSquare = 64;  // a power of two: square edges stay on texel edges in every mip level

// The card: the board and a white margin of one square, in the top left of a square texture of
// `canvas` texels (a power of two), of which the quad shows the card only.
struct BoardLayout {
  int canvas = 0;         // texture size, texels
  int width = 0, height = 0;  // the card, texels
  double square = 0;      // metres
  double width_m() const { return width / static_cast<double>(kPxPerSquare) * square; }
  double height_m() const { return height / static_cast<double>(kPxPerSquare) * square; }
};

BoardLayout layout(const calib::BoardSpec& board) {
  BoardLayout l;
  l.square = board.square_m;
  l.width = (board.cols + 2) * kPxPerSquare;
  l.height = (board.rows + 2) * kPxPerSquare;
  l.canvas = 64;
  while (l.canvas < std::max(l.width, l.height)) l.canvas *= 2;
  return l;
}

}  // namespace

// The card spans [0, width] along world x and [0, height] along y at z = 0, its pattern side
// facing +z. The texture's columns run along +x and the renderer shows a quad's texture mirrored
// from its front (columns along u, rows along v, front along u x v), so the board is drawn
// mirrored left to right: seen from +z, it reads as printed. Its first corner is at texel column
// width - 64, row 64.
Eigen::Isometry3d board_pose(const calib::BoardSpec& board) {
  const BoardLayout l = layout(board);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << -1, 0, 0, 0, 1, 0, 0, 0, -1;  // x along -x (columns), y along +y (rows), z into the board
  T.translation() = Eigen::Vector3d(l.width_m() - board.square_m, board.square_m, 0.0);
  return T;
}

Scene calibration_scene(const calib::BoardSpec& board, std::uint64_t seed) {
  Scene s;
  s.kind = SceneKind::kCalibration;
  s.ambient = 1.0;
  s.background = 0.5f;
  const BoardLayout l = layout(board);
  const cv::Mat pattern = calib::draw_board(board, kPxPerSquare);
  Texture t;
  t.repeat = false;
  t.levels.resize(1);
  t.levels[0].size = l.canvas;
  t.levels[0].texels.assign(static_cast<std::size_t>(l.canvas) * l.canvas, 0.9f);  // white card
  for (int r = 0; r < pattern.rows; ++r) {
    for (int c = 0; c < pattern.cols; ++c) {
      const int x = l.width - kPxPerSquare - 1 - c, y = kPxPerSquare + r;  // mirrored left to right
      t.levels[0].texels[static_cast<std::size_t>(y) * l.canvas + x] = pattern.at<std::uint8_t>(r, c) ? 0.9f : 0.06f;
    }
  }
  build_mips(t);
  const int board_tex = s.add_texture(std::move(t));
  // u x v = +z: the pattern faces +z.
  s.add_quad({0, 0, 0}, {l.width_m(), 0, 0}, {0, l.height_m(), 0}, board_tex);
  s.quads.back().repeat_u = static_cast<float>(l.width) / static_cast<float>(l.canvas);
  s.quads.back().repeat_v = static_cast<float>(l.height) / static_cast<float>(l.canvas);
  const double side = std::max(l.width_m(), l.height_m());
  // A wall behind the board (from the cameras: beyond it), and a dummy path for CameraPath.
  const int wall = s.add_texture(make_noise(512, seed, 0.45f, 0.35f, 8));
  s.add_quad({-4, -4, -1.5}, {8 + side, 0, 0}, {0, 8 + side, 0}, wall, 1.0);
  s.path = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  s.camera_height = 0.5;
  s.bake_lighting();
  return s;
}

std::vector<Eigen::Isometry3d> calibration_views(const calib::BoardSpec& board, const geometry::LensCamera& lens,
                                                 int frames, std::uint64_t seed) {
  Rng rng(seed * 0x9E3779B97F4A7C15ULL + 0xCA11B);
  const Eigen::Isometry3d T_wb = board_pose(board);
  const Eigen::Vector3d centre_b(0.5 * board.cols * board.square_m, 0.5 * board.rows * board.square_m, 0.0);
  const double width_m = board.cols * board.square_m;
  std::vector<Eigen::Isometry3d> views;
  constexpr int kGridX = 5, kGridY = 4;  // image cells the board's centre visits in turn
  for (int k = 0; k < frames; ++k) {
    const int cell = k % (kGridX * kGridY);
    const double u = (cell % kGridX + rng.uniform()) / kGridX * (lens.width - 1);
    const double v = (cell / kGridX + rng.uniform()) / kGridY * (lens.height - 1);
    const Eigen::Vector3d ray = lens.unproject({u, v}).value_or(Eigen::Vector3d::UnitZ());
    const double across = rng.uniform(0.35, 0.75) * lens.width;  // pixels the board spans near the centre
    const double distance = lens.fx * width_m / across;
    // Tilt about an axis in the board's plane, then a turn within it; the board faces the camera
    // (its z, into the board, along the ray) before tilting.
    const double axis_angle = rng.uniform(0, 2 * M_PI);
    const Eigen::Vector3d axis(std::cos(axis_angle), std::sin(axis_angle), 0);
    const Eigen::Matrix3d tilt = Eigen::AngleAxisd(rng.uniform(0.1, 0.87), axis).toRotationMatrix() *
                                 Eigen::AngleAxisd(rng.uniform(-0.5, 0.5), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    // Face the ray: turn the optical axis onto it (shortest rotation), so the board is seen
    // frontally from where it sits before the tilt.
    const Eigen::Matrix3d facing = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), ray).toRotationMatrix();
    const Eigen::Matrix3d R_cb = facing * tilt;
    const Eigen::Vector3d t_cb = ray * distance - R_cb * centre_b;  // the board's centre on the ray
    Eigen::Isometry3d T_cb = Eigen::Isometry3d::Identity();
    T_cb.linear() = R_cb;
    T_cb.translation() = t_cb;
    views.push_back(T_wb * T_cb.inverse());
  }
  return views;
}

}  // namespace plslam::synth
