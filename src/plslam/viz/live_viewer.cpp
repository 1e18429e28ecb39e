#include "plslam/viz/live_viewer.h"

#include <tuple>
#include <utility>
#include <unordered_map>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "plslam/core/error.h"
#include "plslam/core/thread_priority.h"
#include "plslam/map/map_snapshot.h"

namespace plslam::viz {
namespace {

using nlohmann::json;

// The keyframe arrays of the document, for the given keyframes.
json keyframe_arrays(const std::vector<const map::KeyframeSnapshot*>& keyframes) {
  json ids = json::array(), poses = json::array(), parents = json::array();
  for (const auto* kf : keyframes) {
    ids.push_back(kf->id);
    for (auto& v : page_pose(kf->T_wc)) poses.push_back(std::move(v));
    parents.push_back(kf->parent);
  }
  return {{"ids", ids}, {"poses", poses}, {"parents", parents}};
}

// The left image at half size, grey, with the matched points (green) and lines (orange) drawn.
std::string annotated_jpeg(const LiveFrame& f) {
  cv::Mat small, colour;
  cv::resize(f.left, small, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  if (small.channels() == 1) {
    cv::cvtColor(small, colour, cv::COLOR_GRAY2BGR);
  } else {
    colour = small;
  }
  for (const auto& [a, b] : f.tracked_lines) cv::line(colour, a * 0.5f, b * 0.5f, cv::Scalar(0, 140, 255), 1, cv::LINE_AA);
  for (const auto& p : f.tracked_points) cv::circle(colour, p * 0.5f, 2, cv::Scalar(0, 220, 0), 1, cv::LINE_AA);
  std::vector<uchar> bytes;
  cv::imencode(".jpg", colour, bytes, {cv::IMWRITE_JPEG_QUALITY, 75});
  return std::string(bytes.begin(), bytes.end());
}

bool same_pose(const geometry::SE3& a, const geometry::SE3& b, double min_move_m) {
  return (a.translation() - b.translation()).norm() <= min_move_m &&
         (a.rotation() - b.rotation()).cwiseAbs().maxCoeff() <= 1e-4;
}

}  // namespace

void LiveViewerOptions::validate() const {
  server.validate();
  if (!(rate_hz > 0 && rate_hz <= 60)) throw InputError("", fmt::format("viewer rate {} Hz: must be in (0, 60]", rate_hz));
}

void LiveTrail::add(long keyframe, const Eigen::Vector3d& centre_in_keyframe, const Eigen::Vector3d& centre_world) {
  anchors_.push_back({keyframe, centre_in_keyframe});
  centres_.push_back(centre_world);
}

bool LiveTrail::update(const map::MapSnapshot& map) {
  std::unordered_map<long, const geometry::SE3*> pose_of;
  pose_of.reserve(map.keyframes.size());
  for (const auto& kf : map.keyframes) pose_of.emplace(kf.id, &kf.T_wc);
  bool resend = false;
  for (std::size_t i = 0; i < anchors_.size(); ++i) {
    const auto it = pose_of.find(anchors_[i].keyframe);
    if (it == pose_of.end()) continue;  // culled since, or not in the map yet: stays where it was
    centres_[i] = *it->second * anchors_[i].in_keyframe;
    if (i < page_.size() && (centres_[i] - page_[i]).norm() > resend_move_m_) resend = true;
  }
  return resend;
}

void LiveTrail::sent(bool whole) {
  if (whole) page_.clear();
  page_.insert(page_.end(), centres_.begin() + static_cast<std::ptrdiff_t>(page_.size()), centres_.end());
}

json scene_delta(const map::MapSnapshot& page, const map::MapSnapshot& after, const SceneInfo& info,
                 std::optional<std::size_t> trail_sent, long revision, double min_move_m,
                 map::MapSnapshot* page_after, const SceneInfo* page_info) {
  // What the page will hold: `after`, with the unsent keyframes and landmarks where the page has
  // them. Filled in below when asked for.
  if (page_after) *page_after = after;

  // Keyframes: upserted when new or moved; the graph is resent whole when any keyframe changed
  // (a few thousand edges at most).
  std::unordered_map<long, const map::KeyframeSnapshot*> old_kfs;
  for (const auto& kf : page.keyframes) old_kfs.emplace(kf.id, &kf);
  std::vector<const map::KeyframeSnapshot*> changed_kfs;
  bool graph_changed = page.keyframes.size() != after.keyframes.size();
  for (std::size_t i = 0; i < after.keyframes.size(); ++i) {
    const auto& kf = after.keyframes[i];
    const auto it = old_kfs.find(kf.id);
    if (it == old_kfs.end() || !same_pose(it->second->T_wc, kf.T_wc, min_move_m) || it->second->parent != kf.parent) {
      changed_kfs.push_back(&kf);
    } else if (page_after) {
      page_after->keyframes[i].T_wc = it->second->T_wc;
    }
    if (it == old_kfs.end() || it->second->loop_edges != kf.loop_edges ||
        it->second->covisibility != kf.covisibility) {
      graph_changed = true;
    }
    if (it != old_kfs.end()) old_kfs.erase(it);
  }
  json removed_kfs = json::array();
  for (const auto& [id, kf] : old_kfs) removed_kfs.push_back(id);

  std::unordered_map<long, Eigen::Vector3d> old_points;
  old_points.reserve(page.points.size());
  for (const auto& p : page.points) old_points.emplace(p.id, p.position);
  json point_ids = json::array(), point_xyz = json::array();
  for (std::size_t i = 0; i < after.points.size(); ++i) {
    const auto& p = after.points[i];
    const auto it = old_points.find(p.id);
    if (it == old_points.end() || (it->second - p.position).norm() > min_move_m) {
      point_ids.push_back(p.id);
      append_page_position(point_xyz, p.position);
    } else if (page_after) {
      page_after->points[i].position = it->second;
    }
    if (it != old_points.end()) old_points.erase(it);
  }
  json removed_points = json::array();
  for (const auto& [id, p] : old_points) removed_points.push_back(id);

  std::unordered_map<long, std::pair<Eigen::Vector3d, Eigen::Vector3d>> old_lines;
  for (const auto& l : page.lines) old_lines.emplace(l.id, std::make_pair(l.start, l.end));
  json line_ids = json::array(), line_xyz = json::array();
  for (std::size_t i = 0; i < after.lines.size(); ++i) {
    const auto& l = after.lines[i];
    const auto it = old_lines.find(l.id);
    if (it == old_lines.end() || (it->second.first - l.start).norm() > min_move_m ||
        (it->second.second - l.end).norm() > min_move_m) {
      line_ids.push_back(l.id);
      append_page_position(line_xyz, l.start);
      append_page_position(line_xyz, l.end);
    } else if (page_after) {
      std::tie(page_after->lines[i].start, page_after->lines[i].end) = it->second;
    }
    if (it != old_lines.end()) old_lines.erase(it);
  }
  json removed_lines = json::array();
  for (const auto& [id, l] : old_lines) removed_lines.push_back(id);

  // Only what changes per update: the trajectory gains its new tail, and the graph is built only
  // when it changed (building the whole document here cost a full serialisation per update).
  json trail = json::array();
  for (std::size_t i = trail_sent.value_or(0); i < info.trajectory.size(); ++i) {
    append_page_position(trail, info.trajectory[i]);
  }
  json d = {{"revision", revision},
            {"final", info.final},
            {"counts", scene_counts(after, info)},
            {"camera", scene_camera(info)},
            {"local_map", scene_local_map(info)},
            {trail_sent ? "trajectory_append" : "trajectory", trail},
            {"keyframes", keyframe_arrays(changed_kfs)},
            {"keyframes_removed", removed_kfs},
            {"points", {{"ids", point_ids}, {"xyz", point_xyz}}},
            {"points_removed", removed_points},
            {"lines", {{"ids", line_ids}, {"xyz", line_xyz}}},
            {"lines_removed", removed_lines}};
  if (graph_changed) {
    auto graph = scene_graph(after);
    d["loop_edges"] = std::move(graph.loop_edges);
    d["covisibility"] = std::move(graph.covisibility);
  }
  if (page_info && info.local_map == page_info->local_map) d.erase("local_map");
  return d;
}

LiveViewer::LiveViewer(LiveViewerOptions options, const map::Map& map, SceneInfo base)
    : options_((options.validate(), std::move(options))), map_(map), base_(std::move(base)), server_(options_.server) {
  base_.source = "live";
  base_.final = false;
  auto first = std::make_shared<Scene>();
  first->info = base_;
  first->info.revision = 0;
  last_ = first;
  server_.publish(0, [first] { return scene_document(first->map, first->info).dump(); }, {});
  thread_ = std::thread([this] {
    core::name_this_thread("plslam-viewer");
    publish_loop();
  });
}

LiveViewer::~LiveViewer() {
  {
    std::lock_guard lock(stop_mutex_);
    stop_ = true;
  }
  stop_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void LiveViewer::on_frame(LiveFrame frame) {
  std::lock_guard lock(frame_mutex_);
  frame_ = std::move(frame);
  new_frame_ = true;
}

long LiveViewer::revision() const { return revision_.load(); }

void LiveViewer::publish_loop() {
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / options_.rate_hz));
  auto next = std::chrono::steady_clock::now();
  std::unique_lock lock(stop_mutex_);
  while (!stop_) {
    next += period;
    if (stop_cv_.wait_until(lock, next, [this] { return stop_; })) break;
    lock.unlock();
    publish_once();
    lock.lock();
  }
}

void LiveViewer::publish_once() {
  std::optional<LiveFrame> frame;  // the last one; it may be one already published
  bool fresh = false;
  {
    std::lock_guard lock(frame_mutex_);
    if (!new_frame_ && map_.changes() == last_changes_) return;  // nothing to tell
    fresh = std::exchange(new_frame_, false);
    frame = frame_;
  }
  last_changes_ = map_.changes();
  auto scene = std::make_shared<Scene>();
  scene->map = map::take_snapshot(map_);
  auto& info = scene->info;
  info = base_;
  if (frame) {
    if (fresh && frame->tracked) trail_.add(frame->anchor_keyframe, frame->centre_in_anchor, frame->T_wc.translation());
    info.frame = frame->frame;
    info.frames = frame->frames;
    info.tracked = frame->tracked_frames;
    info.state = frame->state;
    info.fps = frame->fps;
    info.loops = frame->loops;
    info.relocalizations = frame->relocalizations;
    if (frame->tracked) info.camera = frame->T_wc;
    info.local_map = std::make_pair(frame->local_keyframes, frame->local_points);
  }
  const bool resend_trail = trail_.update(scene->map);
  info.trajectory = trail_.centres();
  // The camera image at half the update rate: encoding costs a few ms of this thread.
  if (fresh && !frame->left.empty() && image_updates_++ % 2 == 0) server_.publish_image(annotated_jpeg(*frame));
  const long revision = revision_.load() + 1;
  info.revision = revision;
  map::MapSnapshot page_after;
  const auto delta = scene_delta(page_, scene->map, info,
                                 resend_trail ? std::nullopt : std::optional(trail_.page_size()), revision,
                                 kPageMinMove, &page_after, &last_->info)
                         .dump();
  page_ = std::move(page_after);
  trail_.sent(resend_trail);
  last_ = scene;
  server_.publish(revision, [scene] { return scene_document(scene->map, scene->info).dump(); }, delta);
  revision_.store(revision);
}

void LiveViewer::finish(const Scene& final_scene) {
  {
    std::lock_guard lock(stop_mutex_);
    stop_ = true;
  }
  stop_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  auto scene = std::make_shared<Scene>(final_scene);
  scene->info.final = true;
  const long revision = revision_.load() + 1;
  scene->info.revision = revision;
  // A full document, no delta: the final state replaces what the page built up.
  server_.publish(revision, [scene] { return scene_document(scene->map, scene->info).dump(); }, {});
  revision_.store(revision);
}

}  // namespace plslam::viz
