// plslam::Slam (plslam/plslam.h): the public API over system::System.
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "plslam/core/log.h"
#include "plslam/core/version.h"
#include "plslam/eval/evaluate.h"
#include "plslam/io/calibration_file.h"
#include "plslam/io/dataset.h"
#include "plslam/map/map_snapshot.h"
#include "plslam/plslam.h"
#include "plslam/system/map_file.h"
#include "plslam/system/slam_system.h"
#include "plslam/system/system_config.h"

namespace plslam {

const char* version() { return kVersion; }

const char* to_string(TrackingState state) {
  switch (state) {
    case TrackingState::kNotInitialized: return "not_initialized";
    case TrackingState::kTracking: return "tracking";
    case TrackingState::kLost: return "lost";
  }
  return "?";
}

const char* to_string(FrameState state) {
  return tracking::to_string(static_cast<tracking::FrameState>(state));
}

namespace {

static_assert(static_cast<int>(FrameState::kLocalized) == static_cast<int>(tracking::FrameState::kLocalized) &&
                  static_cast<int>(FrameState::kRecovering) == static_cast<int>(tracking::FrameState::kRecovering) &&
                  static_cast<int>(FrameState::kRelocalized) == static_cast<int>(tracking::FrameState::kRelocalized) &&
                  static_cast<int>(FrameState::kTracked) == static_cast<int>(tracking::FrameState::kTracked) &&
                  static_cast<int>(FrameState::kUnanchored) == static_cast<int>(tracking::FrameState::kUnanchored) &&
                  static_cast<int>(FrameState::kInertial) == static_cast<int>(tracking::FrameState::kInertial),
              "the public FrameState mirrors tracking::FrameState");

TrackingState public_state(tracking::TrackingState s) {
  switch (s) {
    case tracking::TrackingState::kNotInitialized: return TrackingState::kNotInitialized;
    case tracking::TrackingState::kOk: return TrackingState::kTracking;
    case tracking::TrackingState::kLost: return TrackingState::kLost;
  }
  return TrackingState::kLost;
}

// The intrinsics as every dataset reader checks them, plus the image size a reader takes from the
// images but a caller states.
void check_calibration(const StereoCalibration& c) {
  if (c.width <= 0 || c.height <= 0) {
    throw InputError("", fmt::format("calibration: the image size must be positive, got {}x{}", c.width, c.height));
  }
  io::validate_calibration(c, "");
}

system::SystemOptions system_options(const SlamOptions& o) {
  auto options = system::load_system_options(
      o.preset == Preset::kKitti ? io::DatasetFormat::kKitti : io::DatasetFormat::kEuroc,
      o.config_file.empty() ? std::nullopt : std::optional(o.config_file));
  if (!o.lines) options.disable_lines();
  if (!o.vocabulary.empty()) options.vocabulary = o.vocabulary;
  if (!o.place_recognition) options.place_recognition = false;
  if (!o.loop_closing) options.loop_closing = false;
  options.sequential = o.sequential;
  options.deterministic = o.deterministic;
  options.localization_only = o.localization_only;
  return options;
}

// The extractor works on 8-bit grey; a colour camera's BGR is converted.
cv::Mat grey_image(const cv::Mat& image, const char* side, const StereoCalibration& calib) {
  if (image.empty()) throw InputError("", fmt::format("track: the {} image is empty", side));
  if (image.cols != calib.width || image.rows != calib.height) {
    throw InputError("", fmt::format("track: the {} image is {}x{}, the calibration says {}x{}", side, image.cols,
                                     image.rows, calib.width, calib.height));
  }
  if (image.type() == CV_8UC1) return image;
  cv::Mat grey;
  if (image.type() == CV_8UC3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.type() == CV_8UC4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  } else {
    throw InputError("", fmt::format("track: the {} image must be 8-bit grey or BGR (OpenCV type {})", side,
                                     image.type()));
  }
  return grey;
}

}  // namespace

StereoCalibration read_calibration(const std::filesystem::path& file) { return io::read_calibration_file(file); }

struct Sequence::Impl {
  std::unique_ptr<io::Dataset> dataset;
};

Sequence::Sequence(const std::filesystem::path& folder) : impl_(std::make_unique<Impl>()) {
  impl_->dataset = io::open_dataset(folder);
}
Sequence::~Sequence() = default;
Sequence::Sequence(Sequence&&) noexcept = default;
Sequence& Sequence::operator=(Sequence&&) noexcept = default;
std::size_t Sequence::size() const { return impl_->dataset->size(); }
const StereoCalibration& Sequence::calibration() const { return impl_->dataset->calibration(); }
Preset Sequence::preset() const {
  return impl_->dataset->format() == io::DatasetFormat::kKitti ? Preset::kKitti : Preset::kEuroc;
}
StereoImages Sequence::frame(std::size_t i) const {
  if (i >= size()) throw std::out_of_range(fmt::format("plslam::Sequence::frame: {} of {}", i, size()));
  auto f = impl_->dataset->load(i);
  return {f.timestamp, std::move(f.left), std::move(f.right)};
}
const ImuData* Sequence::imu() const {
  const auto& imu = impl_->dataset->imu();
  return imu ? &*imu : nullptr;
}

const Trajectory* Sequence::ground_truth() const {
  const auto& gt = impl_->dataset->ground_truth();
  return gt ? &*gt : nullptr;
}

TrajectoryErrors evaluate_trajectory(const Trajectory& ground_truth, const Trajectory& estimate) {
  const auto r = eval::evaluate(ground_truth, estimate, eval::EvalOptions{});
  TrajectoryErrors e;
  e.pairs = r.pairs.size();
  e.ate_rmse_m = r.ape_trans_stats.rmse;
  e.rpe_trans_rmse_m = r.rpe_trans_stats.rmse;
  e.rpe_rot_rmse_deg = r.rpe_rot_stats.rmse;
  return e;
}

struct Slam::Impl {
  Impl(const StereoCalibration& c, const SlamOptions& o) : calib(c) {
    // spdlog's own default logger writes to stdout, which belongs to the embedding program: unless
    // the program installed a logger of its own, plslam's messages go to stderr.
    if (spdlog::default_logger()->name().empty()) init_logging(LogLevel::kInfo);
    check_calibration(c);
    const auto sys_options = system_options(o);
    vocabulary = system::load_vocabulary(sys_options);
    slam = std::make_unique<system::System>(calib, sys_options, vocabulary);
  }

  StereoCalibration calib;
  std::shared_ptr<const place::Vocabulary> vocabulary;
  std::unique_ptr<system::System> slam;
  long frames = 0;
  long tracked = 0;
  std::optional<double> last_timestamp;
  bool shut_down = false;
  std::optional<geometry::SE3> T_gt_map;  // a loaded map's ground-truth anchor, kept on save
};

Slam::Slam(const StereoCalibration& calibration, const SlamOptions& options)
    : impl_(std::make_unique<Impl>(calibration, options)) {}

Slam::~Slam() {
  if (impl_) shutdown();
}

Slam::Slam(Slam&&) noexcept = default;
Slam& Slam::operator=(Slam&&) noexcept = default;

TrackedFrame Slam::track(const cv::Mat& left, const cv::Mat& right, double timestamp) {
  auto& d = *impl_;
  if (d.shut_down) throw std::logic_error("plslam::Slam::track: called after shutdown()");
  if (!std::isfinite(timestamp) || (d.last_timestamp && timestamp <= *d.last_timestamp)) {
    throw InputError("", fmt::format("track: timestamp {} does not follow the previous one ({})", timestamp,
                                     d.last_timestamp ? *d.last_timestamp : NAN));
  }
  io::StereoFrame frame;
  frame.index = static_cast<std::size_t>(d.frames);
  frame.timestamp = timestamp;
  frame.left = grey_image(left, "left", d.calib);
  frame.right = grey_image(right, "right", d.calib);
  const auto r = d.slam->process(frame);
  d.last_timestamp = timestamp;
  ++d.frames;

  TrackedFrame out;
  out.index = r.frame_id;
  out.timestamp = r.timestamp;
  out.state = public_state(r.track.state);
  out.frame_state = static_cast<FrameState>(r.track.frame_state);
  out.tracked = r.track.tracked;
  if (r.track.tracked) {
    // From the frame's reference keyframe, which is where the trajectory takes it from too.
    out.T_world_camera = *r.T_world_camera;
    ++d.tracked;
  }
  out.point_inliers = r.track.point_inliers;
  out.line_inliers = r.track.line_inliers;
  out.pose_covariance = r.track.pose_covariance;
  out.keyframe = r.track.keyframe;
  out.relocalized = r.track.relocalized;
  out.new_map_segment = r.track.new_map_segment;
  out.tracking_ms = r.tracking_ms;
  return out;
}

Trajectory Slam::trajectory() const { return impl_->slam->tracked_trajectory(); }

MapSnapshot Slam::map() const {
  const auto snap = map::take_snapshot(impl_->slam->map());
  MapSnapshot s;
  s.points.resize(static_cast<Eigen::Index>(snap.points.size()), 3);
  for (std::size_t i = 0; i < snap.points.size(); ++i) {
    s.points.row(static_cast<Eigen::Index>(i)) = snap.points[i].position.transpose();
    s.point_ids.push_back(snap.points[i].id);
  }
  s.lines.resize(static_cast<Eigen::Index>(snap.lines.size()), 6);
  for (std::size_t i = 0; i < snap.lines.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    s.lines.block<1, 3>(row, 0) = snap.lines[i].start.transpose();
    s.lines.block<1, 3>(row, 3) = snap.lines[i].end.transpose();
    s.line_ids.push_back(snap.lines[i].id);
  }
  for (const auto& kf : snap.keyframes) s.keyframes.push_back({kf.timestamp, kf.T_wc.isometry()});
  std::sort(s.keyframes.begin(), s.keyframes.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
  s.changes = snap.changes;
  return s;
}

long Slam::map_changes() const { return impl_->slam->map().changes(); }

SlamStats Slam::stats() const {
  const auto& sys = *impl_->slam;
  SlamStats s;
  s.frames = impl_->frames;
  s.tracked = impl_->tracked;
  s.lost_events = sys.tracker().lost_events();
  s.relocalizations = static_cast<long>(sys.tracker().relocalized_frames().size());
  s.loops = sys.loop_closer() ? static_cast<long>(sys.loop_closer()->stats().loops.size()) : 0;
  s.keyframes = sys.map().num_keyframes();
  s.points = sys.map().num_points();
  s.lines = sys.map().num_lines();
  s.gravity_aligned = sys.gravity_alignment().has_value();
  return s;
}

const StereoCalibration& Slam::calibration() const { return impl_->calib; }

void Slam::use_imu(const ImuData& imu) {
  if (impl_->frames > 0 || impl_->shut_down) throw std::logic_error("plslam::Slam::use_imu: call it before the first track()");
  impl_->slam->set_imu(imu);
}

void Slam::load_map(const std::filesystem::path& file) {
  auto& d = *impl_;
  if (d.frames > 0 || d.shut_down) {
    throw std::logic_error("plslam::Slam::load_map: call it before the first track()");
  }
  const auto contents = system::load_map_file(file);
  system::check_map_matches(contents.meta, d.calib, d.vocabulary.get(), file.string());
  d.T_gt_map = contents.meta.T_gt_map;
  d.slam->load_map(contents);
}

void Slam::save_map(const std::filesystem::path& file) {
  shutdown();
  auto& d = *impl_;
  if (!d.slam->map().first_keyframe()) {
    throw std::logic_error("plslam::Slam::save_map: the map is empty (tracking never initialised)");
  }
  system::MapFileMeta meta;
  meta.created_by = fmt::format("plslam {} (library)", kVersion);
  meta.T_gt_map = d.T_gt_map;
  system::save_map_file(file, d.slam->capture_map(std::move(meta)));
}

void Slam::shutdown() {
  if (impl_->shut_down) return;
  impl_->shut_down = true;
  impl_->slam->finish();
}

bool Slam::is_shut_down() const { return impl_->shut_down; }

system::System& Slam::system() { return *impl_->slam; }
const system::System& Slam::system() const { return *impl_->slam; }

}  // namespace plslam
