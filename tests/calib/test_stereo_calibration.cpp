// Calibration against exact ground truth: rendered board views of each camera model, detected and
// solved, against the rig the renderer used; and the board detector against a drawn board.
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <fmt/format.h>

#include "plslam/calib/stereo_calibration.h"
#include "plslam/core/error.h"
#include "plslam/synth/sequence.h"

namespace plslam::calib {
namespace {

struct Rendered {
  std::vector<StereoView> views;
  synth::Sequence seq;
};

std::vector<StereoView> render_and_detect(const synth::Sequence& seq, const BoardSpec& board) {
  synth::StereoRenderer renderer(seq);
  std::vector<StereoView> views;
  for (std::size_t i = 0; i < seq.size(); ++i) {
    const auto im = renderer.render(i);
    views.push_back({static_cast<int>(i), detect_board(im.left, board), detect_board(im.right, board)});
  }
  return views;
}

void expect_accurate(const geometry::LensCamera& truth, const geometry::LensCamera& est, const char* name) {
  SCOPED_TRACE(name);
  EXPECT_LT(std::abs(est.fx / truth.fx - 1), 0.002) << est.fx << " vs " << truth.fx;
  EXPECT_LT(std::abs(est.fy / truth.fy - 1), 0.002) << est.fy << " vs " << truth.fy;
  EXPECT_LT(std::abs(est.cx - truth.cx), 0.5) << est.cx << " vs " << truth.cx;
  EXPECT_LT(std::abs(est.cy - truth.cy), 0.5) << est.cy << " vs " << truth.cy;
}

// On the board as drawn (padded with white), every corner is found where the squares meet: pixel
// centres at integers, so the corner between pixels 63 and 64 is at 63.5. OpenCV 4.6's ChArUco
// interpolation alone is half a pixel off; the detector refines again.
TEST(BoardDetector, CornersOfADrawnBoardAreExact) {
  for (const char* text : {"charuco:10x7:0.06:0.045:5x5_100", "chessboard:9x6:0.05"}) {
    const BoardSpec spec = parse_board_spec(text);
    cv::Mat padded;
    cv::copyMakeBorder(draw_board(spec, 64), padded, 40, 40, 40, 40, cv::BORDER_CONSTANT, 255);
    const auto d = detect_board(padded, spec);
    ASSERT_EQ(static_cast<int>(d.ids.size()), spec.corner_count()) << text;
    const auto corners = spec.corners();
    for (std::size_t k = 0; k < d.ids.size(); ++k) {
      const auto& P = corners[static_cast<std::size_t>(d.ids[k])];
      // The drawn board and OpenCV's object points share the frame (origin at a board corner):
      // for the chessboard, whose two ends look alike, either direction is a valid answer.
      const double ex = P.x / spec.square_m * 64 - 0.5 + 40, ey = P.y / spec.square_m * 64 - 0.5 + 40;
      const double flipped_x = padded.cols - 1 - ex, flipped_y = padded.rows - 1 - ey;
      const double err = std::min(std::hypot(d.pixels[k].x - ex, d.pixels[k].y - ey),
                                  spec.kind == BoardKind::kChessboard
                                      ? std::hypot(d.pixels[k].x - flipped_x, d.pixels[k].y - flipped_y)
                                      : 1e9);
      // findChessboardCornersSB fits its own corner model, a few hundredths of a pixel off here.
      EXPECT_LT(err, spec.kind == BoardKind::kChessboard ? 0.05 : 0.02) << text << " corner " << d.ids[k];
    }
  }
  EXPECT_THROW(parse_board_spec("charuco:10x7:0.06:0.07"), InputError);  // marker larger than square
  EXPECT_THROW(parse_board_spec("charuco:30x30:0.06:0.045:4x4_50"), InputError);  // too few markers
  EXPECT_THROW(parse_board_spec("chessboard:9x:0.05"), InputError);
  EXPECT_THROW(parse_board_spec("aprilgrid:6x6:0.05"), InputError);
}

class CalibrationAccuracy : public ::testing::TestWithParam<synth::CameraKind> {};

// Per model: focal lengths within 0.2 %, principal points within 0.5 px, the baseline within
// 0.2 % and the rotation between the cameras within 0.05 degrees (issue 54's bar).
TEST_P(CalibrationAccuracy, RenderedBoardGivesTheRendererRig) {
  synth::SequenceOptions so;
  so.scene = synth::SceneKind::kCalibration;
  so.camera = GetParam();
  so.frames = 60;
  so.seed = 11;
  if (so.camera == synth::CameraKind::kEquidistant) so.fov_deg = 150;
  const synth::Sequence seq(so);
  const auto views = render_and_detect(seq, so.board);
  CalibrationOptions o;
  o.model = so.camera == synth::CameraKind::kEquidistant       ? CalibrationModel::kEquidistant
            : so.camera == synth::CameraKind::kRadialTangential ? CalibrationModel::kRadialTangential
                                                                : CalibrationModel::kPinhole;
  const auto r = calibrate_stereo(views, so.board, {so.preset.width, so.preset.height}, o, "test");
  expect_accurate(seq.lens(0), r.left.lens, "left");
  expect_accurate(seq.lens(1), r.right.lens, "right");
  const Eigen::Isometry3d truth = seq.T_left_right().inverse();  // T_right_left
  const double baseline = truth.translation().norm();
  EXPECT_LT(std::abs(r.T_right_left.translation().norm() / baseline - 1), 0.002) << r.T_right_left.translation().transpose();
  const double rot_err = Eigen::AngleAxisd(r.T_right_left.rotation() * truth.rotation().transpose()).angle() * 180 / M_PI;
  EXPECT_LT(rot_err, 0.05);
  EXPECT_LT(r.stereo_rms_px, 0.3);
  // The distortion: the coefficients of a fisheye are strongly correlated (each alone is poorly
  // determined), so the test is the mapping they make: rays across the image land where the true
  // lens puts them.
  // Where the board was seen often (the inner 80 % of each axis) the mapping is tight; towards the
  // image's corners, where views are few, it may drift further.
  double worst_px = 0, worst_inner_px = 0;
  for (int y = 0; y < so.preset.height; y += 24) {
    for (int x = 0; x < so.preset.width; x += 24) {
      const auto ray = seq.lens(0).unproject({x, y});
      const auto est = r.left.lens.project(*ray);
      ASSERT_TRUE(est.has_value());
      const double d = (*est - Eigen::Vector2d(x, y)).norm();
      worst_px = std::max(worst_px, d);
      if (std::abs(x - so.preset.width / 2.0) < 0.4 * so.preset.width &&
          std::abs(y - so.preset.height / 2.0) < 0.4 * so.preset.height)
        worst_inner_px = std::max(worst_inner_px, d);
    }
  }
  EXPECT_LT(worst_px, 1.0);
  EXPECT_LT(worst_inner_px, 0.5);  // the principal point alone may be 0.5 px off (the bar)
  std::printf("mapping: worst %.3f px over the image, %.3f px over its inner 80 %%\n", worst_px, worst_inner_px);
  std::printf("%s: fx %.3f/%.3f fy %.3f/%.3f cx %.3f/%.3f cy %.3f/%.3f  baseline %.6f/%.6f  rot %.4f deg  rms %.3f/%.3f/%.3f px  views %zu/%zu/%zu rejected %zu/%zu  coverage %.2f tilt %.0f\n",
              synth::to_string(so.camera), r.left.lens.fx, seq.lens(0).fx, r.left.lens.fy, seq.lens(0).fy, r.left.lens.cx,
              seq.lens(0).cx, r.left.lens.cy, seq.lens(0).cy, r.T_right_left.translation().norm(), baseline, rot_err,
              r.left.rms_px, r.right.rms_px, r.stereo_rms_px, r.left.views.size(), r.right.views.size(),
              r.stereo_views.size(), r.left.rejected.size(), r.right.rejected.size(), r.left.covered_share, r.left.max_tilt_deg);
  std::printf("  coeffs est %s truth %s\n", fmt::format("{}", fmt::join(r.left.lens.coeffs, " ")).c_str(),
              fmt::format("{}", fmt::join(seq.lens(0).coeffs, " ")).c_str());
  for (const auto& w : r.warnings) std::printf("  warning: %s\n", w.c_str());
}

// Pairs whose right image is the next view's: each camera alone calibrates fine, but no single rig
// fits both, and that is an error, not a calibration.
TEST(StereoCalibration, UnsynchronisedPairsAreRefused) {
  synth::SequenceOptions so;
  so.scene = synth::SceneKind::kCalibration;
  so.frames = 30;
  so.seed = 12;
  const synth::Sequence seq(so);
  auto views = render_and_detect(seq, so.board);
  for (std::size_t i = 0; i + 1 < views.size(); ++i) views[i].right = views[i + 1].right;
  views.pop_back();
  CalibrationOptions o;
  o.model = CalibrationModel::kPinhole;
  try {
    (void)calibrate_stereo(views, so.board, {so.preset.width, so.preset.height}, o, "pairs");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(e.problem().find("unsynchronised"), std::string::npos) << e.what();
  }
  // Too few views of the board is an error too, naming the input.
  views.resize(4);
  EXPECT_THROW((void)calibrate_stereo(views, so.board, {so.preset.width, so.preset.height}, o, "pairs"), InputError);
}

INSTANTIATE_TEST_SUITE_P(Models, CalibrationAccuracy,
                         ::testing::Values(synth::CameraKind::kPinhole, synth::CameraKind::kRadialTangential,
                                           synth::CameraKind::kEquidistant),
                         [](const auto& info) { return std::string(synth::to_string(info.param)); });

}  // namespace
}  // namespace plslam::calib
