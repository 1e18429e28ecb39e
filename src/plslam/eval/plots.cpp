#include "plslam/eval/plots.h"

#include <algorithm>
#include <array>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "plslam/core/error.h"
#include "plslam/eval/chart.h"
#include "plslam/io/atomic_file.h"

namespace plslam::eval {
namespace {

// matplotlib's tab10, in BGR.
const cv::Scalar kBlue(180, 119, 31), kOrange(14, 127, 255), kGreen(44, 160, 44),
    kRed(40, 39, 214), kPurple(189, 103, 148), kGrey(90, 90, 90);

constexpr std::array<const char*, 3> kAxisNames = {"x", "y", "z"};

void add_statistic_lines(Chart& c, const ErrorStatistics& s, const char* unit) {
  c.add_hline(s.rmse, {kRed, 2, false}, fmt::format("rmse {:.4g} {}", s.rmse, unit));
  c.add_hline(s.mean, {kGreen, 2, true}, fmt::format("mean {:.4g} {}", s.mean, unit));
  c.add_hline(s.median, {kPurple, 2, true}, fmt::format("median {:.4g} {}", s.median, unit));
}

std::string time_axis(const PlotOptions& o) { return o.x_is_frame ? "frame" : "time [s]"; }

double time_of(const Trajectory& gt, std::size_t i, const PlotOptions& o) {
  return o.x_is_frame ? gt[i].t : gt[i].t - gt.front().t;
}

std::string alignment_text(const EvalResult& r) {
  switch (r.align) {
    case AlignMode::kNone: return "no alignment";
    case AlignMode::kSE3: return "SE(3) alignment";
    case AlignMode::kSim3: return fmt::format("Sim(3) alignment, scale {:.4f}", r.alignment.s);
  }
  return "";
}

}  // namespace

void save_png(const cv::Mat& img, const std::filesystem::path& path) {
  std::vector<uchar> png;
  if (!cv::imencode(".png", img, png)) throw InputError(path.string(), "cannot encode the plot");
  io::write_file_atomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}

std::pair<int, int> top_view_axes(const Trajectory& gt) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const auto& p : gt) {
    lo = lo.cwiseMin(p.T.translation());
    hi = hi.cwiseMax(p.T.translation());
  }
  Eigen::Index dropped = 2;
  if (!gt.empty()) (hi - lo).minCoeff(&dropped);
  if (dropped == 0) return {1, 2};
  if (dropped == 1) return {0, 2};
  return {0, 1};
}

std::vector<std::filesystem::path> write_plots(const EvalResult& r, const std::filesystem::path& dir,
                                               const PlotOptions& options) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir.string(), "cannot create the plot folder: " + ec.message());
  std::vector<std::filesystem::path> written;

  {  // Top view.
    const auto [a, b] = top_view_axes(r.gt);
    std::vector<cv::Point2d> gt_pts, est_pts;
    for (const auto& p : r.gt) gt_pts.emplace_back(p.T.translation()(a), p.T.translation()(b));
    for (const auto& p : r.est) est_pts.emplace_back(p.T.translation()(a), p.T.translation()(b));
    Chart c;
    c.set_title(fmt::format("Trajectory, top view ({}-{} plane), {}", kAxisNames[a], kAxisNames[b],
                            alignment_text(r)));
    c.set_xlabel(fmt::format("{} [m]", kAxisNames[a]));
    c.set_ylabel(fmt::format("{} [m]", kAxisNames[b]));
    c.set_equal_aspect(true);
    const cv::Point2d start = gt_pts.front();
    c.add_line(std::move(gt_pts), {kGrey, 2, false}, "ground truth");
    c.add_line(std::move(est_pts), {kBlue, 2, false}, "estimate");
    c.add_marker(start, cv::Scalar(0, 0, 0), "start");
    cv::Mat img(900, 900, CV_8UC3);
    c.draw(img);
    written.push_back(dir / "trajectory.png");
    save_png(img, written.back());
  }

  {  // APE over time.
    std::vector<cv::Point2d> pts;
    for (std::size_t i = 0; i < r.ape_trans_m.size(); ++i) {
      pts.emplace_back(time_of(r.gt, i, options), r.ape_trans_m[i]);
    }
    Chart c;
    c.set_title(fmt::format("APE, translation part ({}), {} pairs", alignment_text(r), r.pairs.size()));
    c.set_xlabel(time_axis(options));
    c.set_ylabel("APE [m]");
    c.set_y_from_zero(true);
    c.add_line(std::move(pts), {kBlue, 1, false}, "APE");
    add_statistic_lines(c, r.ape_trans_stats, "m");
    cv::Mat img(450, 1100, CV_8UC3);
    c.draw(img);
    written.push_back(dir / "ape.png");
    save_png(img, written.back());
  }

  {  // RPE over time: translation above, rotation below, at the end pose of each pair.
    std::vector<cv::Point2d> trans, rot;
    for (std::size_t k = 0; k < r.rpe.pairs.size(); ++k) {
      const double t = time_of(r.gt, r.rpe.pairs[k].second, options);
      trans.emplace_back(t, r.rpe.trans_m[k]);
      rot.emplace_back(t, r.rpe.rot_deg[k]);
    }
    const auto& o = r.rpe_options;
    const std::string delta = fmt::format("delta {} {}, {} pairs", o.delta,
                                          o.unit == DeltaUnit::kMeters ? "m" : o.delta == 1.0 ? "frame" : "frames",
                                          o.all_pairs ? "all" : "consecutive");
    cv::Mat img(800, 1100, CV_8UC3);
    Chart ct;
    ct.set_title("RPE, translation (" + delta + ")");
    ct.set_xlabel(time_axis(options));
    ct.set_ylabel("RPE trans. [m]");
    ct.set_y_from_zero(true);
    ct.add_line(std::move(trans), {kBlue, 1, false}, "RPE trans.");
    add_statistic_lines(ct, r.rpe_trans_stats, "m");
    cv::Mat upper = img(cv::Rect(0, 0, img.cols, img.rows / 2));
    ct.draw(upper);
    Chart cr;
    cr.set_title("RPE, rotation angle (" + delta + ")");
    cr.set_xlabel(time_axis(options));
    cr.set_ylabel("RPE rot. [deg]");
    cr.set_y_from_zero(true);
    cr.add_line(std::move(rot), {kOrange, 1, false}, "RPE rot.");
    add_statistic_lines(cr, r.rpe_rot_stats, "deg");
    cv::Mat lower = img(cv::Rect(0, img.rows / 2, img.cols, img.rows - img.rows / 2));
    cr.draw(lower);
    written.push_back(dir / "rpe.png");
    save_png(img, written.back());
  }
  return written;
}

std::filesystem::path write_tracking_plot(const EvalResult& r, const FrameLog& log, const std::filesystem::path& dir,
                                          const PlotOptions& options) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir.string(), "cannot create the plot folder: " + ec.message());
  const auto stamps = log.numbers(options.x_is_frame ? "frame" : "timestamp");
  const auto keyframe = log.numbers("keyframe");
  const auto tracked = log.numbers("tracked");
  const double t0 = options.x_is_frame || r.gt.empty() ? 0.0 : r.gt.front().t;
  auto series = [&](const std::string& column) {
    const auto v = log.numbers(column);
    std::vector<cv::Point2d> pts;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (tracked[i] > 0) pts.emplace_back(stamps[i] - t0, v[i]);
    }
    return pts;
  };
  cv::Mat img(1200, 1100, CV_8UC3);
  const int h = img.rows / 3;

  Chart ape;
  ape.set_title(fmt::format("APE ({}) and keyframes (red)", alignment_text(r)));
  ape.set_xlabel(time_axis(options));
  ape.set_ylabel("APE [m]");
  ape.set_y_from_zero(true);
  std::vector<cv::Point2d> ape_pts;
  for (std::size_t i = 0; i < r.ape_trans_m.size(); ++i) ape_pts.emplace_back(time_of(r.gt, i, options), r.ape_trans_m[i]);
  // A keyframe is marked on the APE curve at the paired pose nearest in time.
  int marked = 0;
  for (std::size_t i = 0; i < keyframe.size(); ++i) {
    if (keyframe[i] <= 0 || ape_pts.empty()) continue;
    const double t = stamps[i] - t0;
    const auto it = std::min_element(ape_pts.begin(), ape_pts.end(), [t](const cv::Point2d& a, const cv::Point2d& b) {
      return std::abs(a.x - t) < std::abs(b.x - t);
    });
    ape.add_marker(*it, kRed, marked++ == 0 ? fmt::format("keyframe ({})", static_cast<int>(std::count_if(keyframe.begin(), keyframe.end(), [](double k) { return k > 0; }))) : "");
  }
  ape.add_line(std::move(ape_pts), {kBlue, 1, false}, "APE");
  cv::Mat p1 = img(cv::Rect(0, 0, img.cols, h));
  ape.draw(p1);

  Chart inl;
  inl.set_title("Tracked inliers and the keyframe rule (a keyframe when inliers < threshold)");
  inl.set_xlabel(time_axis(options));
  inl.set_ylabel("count");
  inl.set_y_from_zero(true);
  inl.add_line(series("point_inliers"), {kBlue, 1, false}, "point inliers");
  inl.add_line(series("line_inliers"), {kOrange, 1, false}, "line inliers");
  inl.add_line(series("reference_tracked"), {kGrey, 1, false}, "reference keyframe's tracked");
  inl.add_line(series("keyframe_threshold"), {kRed, 1, true}, "threshold");
  cv::Mat p2 = img(cv::Rect(0, h, img.cols, h));
  inl.draw(p2);

  Chart loc;
  loc.set_title("Local map and stereo depth use");
  loc.set_xlabel(time_axis(options));
  loc.set_ylabel("count");
  loc.set_y_from_zero(true);
  loc.add_line(series("local_points"), {kBlue, 1, false}, "local map points");
  loc.add_line(series("local_lines"), {kOrange, 1, false}, "local map lines");
  loc.add_line(series("tracked_close"), {kGreen, 1, false}, "close stereo points tracked");
  loc.add_line(series("untracked_close"), {kPurple, 1, false}, "close stereo points not in the map");
  cv::Mat p3 = img(cv::Rect(0, 2 * h, img.cols, img.rows - 2 * h));
  loc.draw(p3);

  const auto path = dir / "tracking.png";
  save_png(img, path);
  return path;
}

bool has_resource_columns(const FrameLog& log) {
  for (const char* c : {"map_keyframes", "map_points", "map_lines", "rss_mb", "tracking_ms"}) {
    if (std::find(log.header.begin(), log.header.end(), c) == log.header.end()) return false;
  }
  return true;
}

namespace {

std::vector<double> running_median(const std::vector<double>& v, int window) {
  std::vector<double> out(v.size());
  const std::size_t half = static_cast<std::size_t>(std::max(window, 1) / 2);
  std::vector<double> w;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::size_t lo = i >= half ? i - half : 0;
    const std::size_t hi = std::min(v.size(), i + half + 1);
    w.assign(v.begin() + static_cast<std::ptrdiff_t>(lo), v.begin() + static_cast<std::ptrdiff_t>(hi));
    std::nth_element(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(w.size() / 2), w.end());
    out[i] = w[w.size() / 2];
  }
  return out;
}

}  // namespace

std::filesystem::path write_resources_plot(const FrameLog& log, const std::filesystem::path& dir, int window) {
  if (!has_resource_columns(log)) {
    throw InputError(log.source, "no map_keyframes, map_points, map_lines and rss_mb columns (a frames.csv of an older run)");
  }
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir.string(), "cannot create the plot folder: " + ec.message());
  const auto frame = log.numbers("frame");
  auto series = [&](const std::vector<double>& v, double scale = 1.0) {
    std::vector<cv::Point2d> pts;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (v[i] >= 0) pts.emplace_back(frame[i], v[i] * scale);
    }
    return pts;
  };
  cv::Mat img(1200, 1100, CV_8UC3);
  const int h = img.rows / 3;

  const auto ms = log.numbers("tracking_ms");
  Chart time;
  time.set_title(fmt::format("Tracking time per frame and its running median over {} frames", window));
  time.set_xlabel("frame");
  time.set_ylabel("ms");
  time.set_y_from_zero(true);
  time.add_line(series(ms), {kGrey, 1, false}, "per frame");
  time.add_line(series(running_median(ms, window)), {kBlue, 2, false}, "running median");
  cv::Mat p1 = img(cv::Rect(0, 0, img.cols, h));
  time.draw(p1);

  Chart mem;
  mem.set_title("Resident memory of the process");
  mem.set_xlabel("frame");
  mem.set_ylabel("MiB");
  mem.set_y_from_zero(true);
  mem.add_line(series(log.numbers("rss_mb")), {kRed, 2, false}, "resident set size");
  cv::Mat p2 = img(cv::Rect(0, h, img.cols, h));
  mem.draw(p2);

  Chart map;
  // Scaled to one axis: a map has about 100 points and 10 lines per keyframe.
  map.set_title("Map size: keyframes, points / 100, lines / 10");
  map.set_xlabel("frame");
  map.set_ylabel("count");
  map.set_y_from_zero(true);
  map.add_line(series(log.numbers("map_keyframes")), {kGreen, 2, false}, "keyframes");
  map.add_line(series(log.numbers("map_points"), 1e-2), {kBlue, 2, false}, "points / 100");
  map.add_line(series(log.numbers("map_lines"), 1e-1), {kOrange, 2, false}, "lines / 10");
  cv::Mat p3 = img(cv::Rect(0, 2 * h, img.cols, img.rows - 2 * h));
  map.draw(p3);

  const auto path = dir / "resources.png";
  save_png(img, path);
  return path;
}

}  // namespace plslam::eval
