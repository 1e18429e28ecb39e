#include "plslam/system/slam_system.h"

#include "plslam/core/resident_memory.h"
#include "plslam/core/stopwatch.h"
#include "plslam/core/thread_priority.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <chrono>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace plslam::system {

SystemOptions SystemOptions::euroc() {
  SystemOptions o;
  o.extractor = tracking::FrameExtractorOptions::euroc();
  // Indoors at 20 Hz the camera turns in place and the scene changes within a few frames: on the
  // rendered office loops (bench/odometry_analysis.sh, seeds 1-3, 5 concurrent runs each) a
  // keyframe at 85 % of the reference's tracked features instead of 75 % took 80 -> 120 keyframes
  // (ORB-SLAM3: 177) and the median ATE from 0.019-0.025 to 0.016-0.019 m.
  o.tracker.keyframe.ratio = 0.85;
  // Walkers and EuRoC's MAV stay below ~2.5 m/s: a relocalization further than 4 m/s from the
  // last tracked pose is a look-alike place (the rendered office repeats its windows and desks
  // every 5 m, and localization on another path through it jumped 10 m without this gate).
  o.tracker.relocalization.max_speed = 4.0;
  // A relocalization is trusted after 5 frames tracked from it, each with inliers in 3/4 of the
  // image cells where the local map shows points. On the office render's reversed paths,
  // look-alike shelves 5-12 m away were tracked for up to 26 frames (1.7 m), but with inliers in
  // 36-71 % of those cells (true places, same direction: 79-100 %); docs/analysis/aliasing.md.
  o.tracker.relocalization.confirm_frames = 5;
  o.tracker.relocalization.min_cell_coverage = 0.75;
  // A true place at the map's edge dipped to 0.743 on one frame between frames of 0.84-0.88 (the
  // office black-out at 360, after a 34 degree turn in the dark): one such frame is forgiven.
  o.tracker.relocalization.max_cell_misses = 1;
  // A black-out of 1 s at 20 Hz leaves 1.05 s between the frames around it: with 1.0 s, the
  // relocalization of the office black-out at frame 420, on the prediction, was left to the
  // cells, which refuted it (0.67-0.76 at the map's edge) and cost the loop (ATE 2.45x, now 1.00x).
  o.tracker.relocalization.continuity_s = 1.5;
  o.tracker.recover_after_gap_s = 0.5;
  return o;
}

SystemOptions SystemOptions::kitti() {
  SystemOptions o;
  o.extractor = tracking::FrameExtractorOptions::kitti();
  // Cars move fast: ORB-SLAM2's KITTI settings keep the same search radii; the keyframe policy's
  // max_frames follows the 10 Hz rate.
  o.tracker.keyframe.max_frames = 10;
  // KITTI's rectified pairs carry a constant disparity error of about 0.1-0.2 px, which made the
  // far points' stereo depths stretch the trajectory by 0.4-0.6 % (06) and 4-7 % (01, highway);
  // beyond 20 baselines (10.7 m, 35 px disparity) matches only seed depths (tracking.far_stereo_baselines).
  o.tracker.far_stereo_baselines = 20;
  o.tracker.relocalization.max_speed = 40.0;  // 144 km/h
  // At 10 Hz: 3 frames before a relocalization is trusted, each with inliers in 3/4 of the cells.
  o.tracker.relocalization.confirm_frames = 3;
  o.tracker.relocalization.min_cell_coverage = 0.75;
  o.tracker.relocalization.max_cell_misses = 1;
  o.tracker.relocalization.continuity_s = 1.0;
  o.tracker.recover_after_gap_s = 0.5;
  // With far matches left out, a long loop's scale is held loosely, and the global BA's LM bends it
  // back slowly: the rendered 240 m street loop ended at 0.058 m (median of 7 concurrent runs) after
  // 10 iterations per pass, at 0.043 m after 40 (0.6 -> 1.0 s in the background).
  o.loop.global_ba_options.iterations = 40;
  return o;
}

void SystemOptions::disable_lines() {
  extractor.lines = false;
  tracker.lines = false;
  mapper.lines = false;
}

System::System(const StereoCalibration& calib, SystemOptions options, std::shared_ptr<const place::Vocabulary> vocabulary)
    : options_(std::move(options)), extractor_(calib, options_.extractor), calib_(calib) {
  options_.tracker.localization_only = options_.localization_only;
  if (options_.localization_only) options_.loop_closing = false;
  options_.mapper.line_information = options_.tracker.line_information;
  options_.mapper.far_stereo_baselines = options_.tracker.far_stereo_baselines;
  options_.tracker.seed = options_.seed;
  if (vocabulary) database_ = std::make_unique<place::KeyframeDatabase>(std::move(vocabulary));
  mapper_ = std::make_unique<mapping::LocalMapper>(map_, options_.mapper);
  mapper_->set_keyframe_database(database_.get());
  if (database_ && options_.loop_closing) {
    options_.loop.verifier.seed = options_.seed;
    options_.loop.across_verifier.seed = options_.seed;
    options_.loop.correction.lines = options_.mapper.lines;
    options_.loop.global_ba_options.lines = options_.mapper.lines;
    options_.loop.global_ba_options.line_information = options_.mapper.line_information;
    options_.loop.global_ba_options.far_stereo_baselines = options_.mapper.far_stereo_baselines;
    options_.loop.defer_global_ba_merge = deterministic();
    options_.loop.defer_loop_correction = deterministic();
    loop_closer_ = std::make_unique<loop::LoopCloser>(map_, *database_, *mapper_, options_.loop);
    mapper_->set_keyframe_sink([closer = loop_closer_.get()](map::KeyFrame* kf) { closer->insert(kf); });
  }
  auto* mapper = mapper_.get();
  // Deterministic mode: tracking reads the map only once mapping has processed every keyframe
  // queued before, as in sequential mode; local mapping counts as busy (the keyframe rule's
  // "mapping idle") while a local BA is in flight, which is fixed by frames, not by timing.
  const bool sequential = options_.sequential || deterministic();
  tracker_ = std::make_unique<tracking::Tracker>(
      map_, options_.tracker, [mapper](map::KeyFrame* kf) { mapper->insert(kf); },
      [this, mapper, sequential] {
        if (deterministic()) return !ba_in_flight_ && !correction_open();
        return sequential || mapper->idle();
      });
  tracker_->set_mapping_queue([mapper, sequential] { return sequential ? std::size_t{0} : mapper->queued(); });
  tracker_->set_keyframe_database(database_.get());
  if (!sequential && !options_.localization_only) {
    mapper_->start();
    if (loop_closer_) loop_closer_->start();
  }
}

System::~System() { finish(); }

FrameResult System::process(const io::StereoFrame& frame) {
  const auto t0 = std::chrono::steady_clock::now();
  FrameResult r;
  r.frame_id = static_cast<long>(frame.index);
  r.timestamp = frame.timestamp;
  // The id is the frame's place in the input, so skipped frames leave gaps instead of shifting
  // every later frame (the keyframe policy counts frames by id, the outputs align by it).
  if (deterministic()) finish_due_local_ba_beside_extraction(static_cast<long>(frame.index), frame.timestamp);
  auto data = extractor_.extract(static_cast<long>(frame.index), frame.timestamp, frame.left, frame.right, &r.extraction);
  if (deterministic()) {
    // The meeting point: the map as the frames before left it, whatever the timing: the last
    // keyframe's edits, and the local BAs whose frame has come.
    const auto tw = std::chrono::steady_clock::now();
    wait_for_map_edits();
    if (!ba_in_flight_ && mapping_job_.joinable()) mapping_job_.join();  // a BA finished beside extraction
    join_loop_job();
    if (local_ba_due(static_cast<long>(frame.index), frame.timestamp)) finish_local_ba();
    run_loop_closing_steps(static_cast<long>(frame.index));
    mapping_waits_.add(ms_since(tw));
    merge_due_global_ba(static_cast<long>(frame.index), frame.timestamp);
    start_loop_job();
    if (!ba_in_flight_ && !loop_job_.joinable() && !correction_open()) {
      reclaim_culled();
      // No global BA either, started or computed and not merged: its result is in the old world.
      if (global_ba_merge_at_ < 0) align_world_with_gravity(static_cast<long>(frame.index));
    }
  } else {
    align_world_with_gravity(static_cast<long>(frame.index));
  }
  r.track = tracker_->track(std::move(data));
  r.tracking_ms = ms_since(t0);
  note_revisit(r.track);
  note_inertial_refinement(r.track, frame.timestamp);
  // What the frame reports of the map: in deterministic mode before its keyframe's local mapping
  // starts beside the caller, so that it is the same in every run.
  auto pose_now = [&] {
    if (r.track.tracked) r.T_world_camera = tracking::Tracker::pose_of(tracker_->records().back()).inverse().isometry();
    r.map_size = map_.sizes();
  };
  if (deterministic()) {
    pose_now();
    start_mapping_job(r.frame_id, frame.timestamp);
  } else {
    if (options_.sequential) {
      mapper_->process_pending();
      if (loop_closer_) loop_closer_->process_pending();
    }
    reclaim_culled();
    pose_now();
  }
  if (imu_init_) imu_init_->add(r.timestamp, r.T_world_camera);
  last_timestamp_ = frame.timestamp;
  r.rss_mb = core::resident_memory_mb();
  return r;
}

void System::note_revisit(const tracking::TrackResult& track) {
  // A relocalization that follows tracked frames is a revisit (the first pose of a loaded map is
  // not); its first new keyframe is where the revisit joins the map.
  // The keyframe the trusted trajectory last stood on before the loss is where the path's drift
  // ends: loop closing may tie it to the place (LoopClosingOptions::loop_across_relocalization).
  if (track.relocalized && tracked_before_) {
    revisit_pending_ = true;
    revisit_from_ = trusted_reference_;
  }
  const map::KeyFrame* reference = tracker_->records().empty() ? nullptr : tracker_->records().back().reference;
  if (track.tracked) {
    tracked_before_ = true;
    if (!track.relocalized && reference) trusted_reference_ = reference->id();
  }
  if (!revisit_pending_ || !track.keyframe || !reference) return;
  revisit_pending_ = false;
  if (!loop_closer_) return;
  // Deterministic mode: told at the next meeting point, where loop closing is not running beside.
  if (deterministic()) {
    revisit_for_loop_closing_ = {reference->id(), revisit_from_};
  } else {
    loop_closer_->global_ba_after_keyframe(reference->id(), revisit_from_);
  }
}

void System::note_inertial_refinement(const tracking::TrackResult& track, double timestamp) {
  if (inertial_refinements_due_.empty() || !track.keyframe || timestamp < inertial_refinements_due_.front()) return;
  const map::KeyFrame* reference = tracker_->records().empty() ? nullptr : tracker_->records().back().reference;
  if (!reference) return;
  inertial_refinements_due_.erase(inertial_refinements_due_.begin());
  // Deterministic mode: told at the next meeting point, where loop closing is not running beside.
  if (deterministic()) {
    refinement_for_loop_closing_ = reference->id();
  } else {
    loop_closer_->refine_inertial_after_keyframe(reference->id());
  }
}

void System::reclaim_culled() {
  const long next_keyframe = map_.next_ids().keyframe;
  if (next_keyframe == reclaimed_at_keyframe_) return;
  const auto t0 = std::chrono::steady_clock::now();
  if (!mapper_->try_pause()) return;
  if (!loop_closer_ || loop_closer_->try_pause()) {
    map_.reclaim([this] {
      tracker_->drop_bad_landmarks();
      mapper_->drop_bad_landmarks();
    });
    if (loop_closer_) loop_closer_->resume();
    reclaimed_at_keyframe_ = next_keyframe;
    ++reclaim_stats_.runs;
    reclaim_stats_.ms.push_back(ms_since(t0));
  }
  mapper_->resume();
}

void System::set_imu(const ImuData& imu, ImuInitMonitorOptions options) {
  if (!tracker_->records().empty()) throw std::logic_error("System::set_imu: after the first frame");
  if (options_.localization_only) return;
  imu_init_.reset();
  imu_data_ = imu;
  imu_init_.emplace(*imu_data_, options);
}

void System::align_world_with_gravity(long frame_id) {
  if (gravity_alignment_ || loaded_map_imu_ || !imu_init_ || !imu_init_->initialised()) return;
  // A loaded map's world is the map file's: a stereo map's stays as it is (and the run stereo).
  if (map_loaded_ && !loaded_map_gravity_aligned_) return;
  if (!mapper_->try_pause()) return;
  if (!loop_closer_ || loop_closer_->try_pause()) {
    const Eigen::Matrix3d R_gw = imu_init_->result()->R_gw();
    if (map_loaded_) {
      // The loaded map's z axis is up already; this run's gravity must agree with it.
      const Eigen::Vector3d up = R_gw.transpose() * Eigen::Vector3d::UnitZ();
      const double tilt_deg = std::acos(std::clamp(up.z(), -1.0, 1.0)) * 180 / M_PI;
      loaded_map_imu_ = LoadedMapImu{tilt_deg, frame_id};
      if (tilt_deg <= kMaxLoadedMapTiltDeg) {
        start_visual_inertial();
      } else {
        spdlog::warn("imu: this run's gravity is {:.2f} deg from the loaded map's up direction (at most {:.1f}): "
                     "tracking stays stereo", tilt_deg, kMaxLoadedMapTiltDeg);
      }
    } else {
      // About the origin (the first keyframe's camera centre): only the tilt changes.
      const geometry::SE3 T_new_old(R_gw, Eigen::Vector3d::Zero());
      map_.transform_world(T_new_old);
      tracker_->transform_world(T_new_old);
      gravity_alignment_ = GravityAlignment{T_new_old.rotation(), frame_id};
      start_visual_inertial();
      if (options_.visual_inertial && loop_closer_) {
        for (const double s : {options_.imu_refine_after_s, options_.imu_refine_again_after_s}) {
          if (s > 0) inertial_refinements_due_.push_back(last_timestamp_ + s);
        }
        std::sort(inertial_refinements_due_.begin(), inertial_refinements_due_.end());
      }
    }
    if (loop_closer_) loop_closer_->resume();
  }
  mapper_->resume();
}

void System::start_visual_inertial() {
  // The IMU's residuals assume gravity along -z: from here on tracking and local BA use them.
  if (!options_.visual_inertial) return;
  tracker_->use_imu(*imu_data_, imu_init_->result()->bias);
  const geometry::SE3 T_imu_cam(imu_data_->T_imu_cam);
  mapper_->use_imu(T_imu_cam);
  if (loop_closer_) loop_closer_->use_imu(T_imu_cam);
}

nlohmann::json System::imu_report() const {
  if (!imu_init_) return nullptr;
  nlohmann::json j = imu_init_->report();
  nlohmann::json world = {{"gravity_aligned", gravity_alignment_.has_value()}};
  if (gravity_alignment_) {
    world["from_frame"] = gravity_alignment_->from_frame;
    world["R_new_first_camera"] = j["initialisation"]["R_gravity_world"];  // row-major
  } else {
    world["kept"] = map_loaded_ ? "the loaded map's" : "the first keyframe's camera";
  }
  if (map_loaded_) world["loaded_map_gravity_aligned"] = loaded_map_gravity_aligned_;
  if (loaded_map_imu_) world["loaded_map_tilt_deg"] = loaded_map_imu_->tilt_deg;
  j["world"] = world;
  const bool inertial = tracker_->imu_on();
  nlohmann::json slam = {{"mode", inertial ? "stereo-inertial" : "stereo"},
                         {"imu_tracked_frames", tracker_->imu_tracked_frames()},
                         {"inertial_frames", tracker_->inertial_frames()},
                         {"new_views_from_imu", tracker_->new_views_from_imu()}};
  if (gravity_alignment_ && inertial) slam["from_frame"] = gravity_alignment_->from_frame;
  if (loaded_map_imu_ && inertial) slam["from_frame"] = loaded_map_imu_->from_frame;
  if (const auto bias = final_imu_bias()) {
    slam["final_gyro_bias"] = {bias->gyro.x(), bias->gyro.y(), bias->gyro.z()};
    slam["final_acc_bias"] = {bias->acc.x(), bias->acc.y(), bias->acc.z()};
  }
  j["slam"] = slam;
  return j;
}

std::optional<inertial::ImuBias> System::final_imu_bias() const {
  const auto keyframes = map_.keyframes();
  for (auto it = keyframes.rbegin(); it != keyframes.rend(); ++it) {
    if (const auto imu = (*it)->imu(); imu && imu->estimated) return imu->bias;
  }
  return std::nullopt;
}

std::string System::imu_summary() const {
  if (!imu_init_) return "mode: stereo (no IMU)";
  if (!tracker_->imu_on()) {
    return gravity_alignment_ ? "mode: stereo, the IMU only turned the world to gravity"
                              : "mode: stereo (the IMU was never initialised)";
  }
  std::string s = fmt::format("mode: stereo-inertial from frame {} ({} frames tracked with the IMU, {} carried by it alone)",
                              gravity_alignment_->from_frame, tracker_->imu_tracked_frames(), tracker_->inertial_frames());
  if (const auto b = final_imu_bias()) {
    s += fmt::format("; final biases: gyro [{:.4f} {:.4f} {:.4f}] rad/s, acc [{:.3f} {:.3f} {:.3f}] m/s^2", b->gyro.x(),
                     b->gyro.y(), b->gyro.z(), b->acc.x(), b->acc.y(), b->acc.z());
  }
  return s;
}

void WaitStats::add(double ms) {
  if (ms <= 0.1) return;
  ++count;
  total_ms += ms;
  max_ms = std::max(max_ms, ms);
}

bool System::deterministic() const { return options_.deterministic && !options_.sequential; }

void System::start_mapping_job(long frame_id, double timestamp) {
  if (mapper_->queued() == 0) return;
  // A local BA on a map half corrected (the query's side moved, the rest not yet) would bend it;
  // the keyframes made meanwhile wait, and move with the map when the correction ends.
  if (correction_open()) return;
  std::thread previous = std::move(mapping_job_);
  std::thread examining = std::move(loop_job_);
  const bool finish_previous = ba_in_flight_;
  {
    std::lock_guard lock(job_mutex_);
    job_edits_done_ = false;
  }
  mapping_job_ = std::thread([this, previous = std::move(previous), examining = std::move(examining),
                              finish_previous]() mutable {
    core::name_this_thread("plslam-mapping");
    if (previous.joinable()) previous.join();
    if (examining.joinable()) examining.join();  // it reads the map these edits change
    // Reclamation is left to the meeting points: the caller reads the tracker's local map
    // (the viewer) while this runs.
    if (finish_previous) {
      mapper_->finish_deferred();
      if (loop_closer_) {
        loop_closer_->refresh_queued_connections();
        loop_closer_->process_pending();
      }
    }
    mapper_->process_pending_deferring_ba();
    {
      std::lock_guard lock(job_mutex_);
      job_edits_done_ = true;
      job_ba_observations_ = mapper_->deferred_ba_observations();
    }
    job_cv_.notify_all();
    mapper_->optimise_deferred_ba();
  });
  ba_in_flight_ = true;
  ba_due_frame_ = frame_id + std::max(1, options_.mapper.ba_merge_after_frames);
  ba_due_time_ = -1;  // once the window is known
  job_timestamp_ = timestamp;
}

void System::wait_for_map_edits() {
  std::unique_lock lock(job_mutex_);
  job_cv_.wait(lock, [this] { return job_edits_done_; });
  if (ba_in_flight_ && ba_due_time_ < 0) {
    // A global BA optimising beside (from its start to its merge) takes a share of the cores.
    const double share = global_ba_merge_at_ >= 0 ? 2.0 : 1.0;
    ba_due_time_ = job_timestamp_ + share * options_.mapper.ba_merge_ms_per_1000_observations *
                                        static_cast<double>(job_ba_observations_) / 1e6;
  }
}

void System::finish_local_ba() {
  if (mapping_job_.joinable()) mapping_job_.join();
  if (!ba_in_flight_) return;
  ba_in_flight_ = false;
  join_loop_job();  // it reads what the result changes
  mapper_->finish_deferred();
}

bool System::local_ba_due(long frame_id, double timestamp) const {
  return ba_in_flight_ && frame_id >= ba_due_frame_ && timestamp >= ba_due_time_;
}

void System::finish_due_local_ba_beside_extraction(long frame_id, double timestamp) {
  // Due here, and its due time is known (wait_for_map_edits() fixed it): nothing reads the map
  // until the meeting point but loop closing's examination, which the job joins first; so the
  // map's operations are the meeting point's, in the same order, only sooner.
  if (ba_due_time_ < 0 || !local_ba_due(frame_id, timestamp)) return;
  std::thread job = std::move(mapping_job_);
  std::thread examining = std::move(loop_job_);
  ba_in_flight_ = false;
  mapping_job_ = std::thread([this, job = std::move(job), examining = std::move(examining)]() mutable {
    core::name_this_thread("plslam-mapping");
    if (job.joinable()) job.join();
    if (examining.joinable()) examining.join();  // it reads what the result changes
    mapper_->finish_deferred();
  });
}

void System::start_loop_job() {
  if (!loop_closer_ || loop_closer_->queued() == 0) return;
  loop_closer_->refresh_queued_connections();
  loop_job_ = std::thread([this] {
    core::name_this_thread("plslam-loop");
    loop_closer_->process_pending();
  });
}

void System::join_loop_job() {
  if (loop_job_.joinable()) loop_job_.join();
}

bool System::correction_open() const { return loop_closer_ && loop_closer_->correction_open(); }

void System::tell_loop_closing_of_requests() {
  if (refinement_for_loop_closing_) {
    loop_closer_->refine_inertial_after_keyframe(*refinement_for_loop_closing_);
    refinement_for_loop_closing_.reset();
  }
  if (!revisit_for_loop_closing_) return;
  loop_closer_->global_ba_after_keyframe(revisit_for_loop_closing_->first, revisit_for_loop_closing_->second);
  revisit_for_loop_closing_.reset();
}

void System::run_loop_closing_steps(long frame_id) {
  if (!loop_closer_) return;
  tell_loop_closing_of_requests();
  const bool end_due = loop_closer_->correction_open() && frame_id >= correction_due_frame_;
  const bool pending = loop_closer_->loop_pending();
  if (!end_due && !pending && !loop_closer_->global_ba_requested()) return;
  // A local BA in flight was built from the map before these steps: they wait for a frame where
  // it has gone in (the frame its keyframe fixed), or at most as many frames again.
  if (ba_in_flight_) {
    if (steps_due_frame_ < 0) steps_due_frame_ = frame_id + std::max(1, options_.mapper.ba_merge_after_frames);
    if (frame_id < steps_due_frame_) return;
  }
  steps_due_frame_ = -1;
  finish_local_ba();
  // One step per frame, each costs tracking tens of ms; but a correction's global BA starts where it
  // ends, before the local BAs of the next keyframes settle the map around the loop's seam (started
  // a step later, on the street loop 600 it ended at 0.0371 m instead of 0.0349 m).
  if (end_due) {
    loop_closer_->finish_deferred_correction();
    loop_closer_->start_requested_global_ba();
  } else if (pending) {
    loop_closer_->finish_deferred_correction();  // a newer loop: an older one ends first
    loop_closer_->begin_deferred_correction();
    correction_due_frame_ = frame_id + options_.loop.correction_merge_after_frames;
  } else {
    loop_closer_->start_requested_global_ba();
  }
}

void System::merge_due_global_ba(long frame_id, double timestamp) {
  if (!loop_closer_) return;
  if (const long starts = loop_closer_->global_ba_starts(); starts != seen_global_ba_starts_) {
    // Started by the last frame's keyframe: its merge frame is fixed now, by input time.
    seen_global_ba_starts_ = starts;
    global_ba_merge_at_ = last_timestamp_ + options_.loop.global_ba_merge_after_s;
  }
  if (global_ba_merge_at_ < 0 || timestamp < global_ba_merge_at_) return;
  global_ba_merge_at_ = -1;
  const auto t0 = std::chrono::steady_clock::now();
  // The local BA in flight was built before the global BA's result: it goes in first.
  finish_local_ba();
  if (loop_closer_->merge_deferred_global_ba()) global_ba_merge_frames_.push_back(frame_id);
  global_ba_waits_.add(ms_since(t0));
}

void System::finish() {
  if (finished_) return;
  finished_ = true;
  join_loop_job();
  finish_local_ba();
  // An open correction ends before the keyframes that waited for it are mapped.
  if (loop_closer_) loop_closer_->finish_deferred_correction();
  mapper_->wait_idle();
  mapper_->stop();
  if (loop_closer_) {
    tell_loop_closing_of_requests();
    loop_closer_->finish();
    loop_closer_->stop();
  }
  // Accepted by the last frames: everything is at rest now.
  if (!tracker_->records().empty()) align_world_with_gravity(tracker_->records().back().frame_id + 1);
  tracker_->settle_states();
}

void System::load_map(const MapContents& contents) {
  if (!tracker_->records().empty() || map_.first_keyframe()) {
    throw std::logic_error("System::load_map: the system already has a map");
  }
  {
    std::lock_guard lock(map_.update_mutex());
    restore_map(contents, map_, database_.get());
  }
  map_loaded_ = true;
  loaded_map_gravity_aligned_ = contents.meta.gravity_aligned;
  tracker_->start_in_loaded_map();
}

MapContents System::capture_map(MapFileMeta meta) const {
  meta.calib = calib_;
  meta.gravity_aligned = gravity_alignment_.has_value() || (map_loaded_ && loaded_map_gravity_aligned_);
  if (database_) {
    meta.vocabulary_checksum = database_->vocabulary().checksum();
    meta.vocabulary_words = static_cast<std::uint32_t>(database_->vocabulary().size());
    meta.vocabulary_nodes = static_cast<std::uint32_t>(database_->vocabulary().nodes().size());
  }
  return system::capture_map(map_, database_.get(), std::move(meta));
}

Trajectory System::tracked_trajectory() const {
  Trajectory out;
  for (const auto& rec : tracker_->records()) {
    if (rec.trusted()) out.push_back({rec.timestamp, tracking::Tracker::pose_of(rec).inverse().isometry()});
  }
  return out;
}

std::optional<long> System::initialized_at() const {
  for (const auto& rec : tracker_->records()) {
    if (rec.tracked) return rec.frame_id;
  }
  return std::nullopt;
}

Trajectory System::keyframe_trajectory() const {
  Trajectory out;
  for (auto* kf : map_.keyframes()) {
    // A keyframe of a segment no loop tied to the map is placed by a guess: not a trusted pose.
    if (map_.anchored(kf->segment())) out.push_back({kf->timestamp(), kf->pose_inverse().isometry()});
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.t < b.t; });
  return out;
}

}  // namespace plslam::system
