#include "plslam/system/config_table.h"

#include <filesystem>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::system {
namespace {

template <class T>
constexpr ConfigType type_of() {
  if constexpr (std::is_same_v<T, bool>) return ConfigType::kBool;
  if constexpr (std::is_same_v<T, int>) return ConfigType::kInt;
  if constexpr (std::is_same_v<T, double>) return ConfigType::kDouble;
  if constexpr (std::is_same_v<T, std::string>) return ConfigType::kString;
}

// A key stored as is in a field of SystemOptions; `ref` is a generic lambda returning the field
// (callable on const and non-const options).
template <class Ref>
ConfigKey field(const char* section, const char* name, Ref ref, const char* description,
                std::optional<ConfigCheck> check = std::nullopt) {
  using T = std::remove_cvref_t<decltype(ref(std::declval<SystemOptions&>()))>;
  ConfigKey k{section, name, type_of<T>(), description, {}, {}, std::move(check), {}, {}};
  k.get = [ref](const SystemOptions& o) { return ConfigValue(ref(o)); };
  k.set = [ref](SystemOptions& o, const ConfigValue& v, const std::string&) { ref(o) = std::get<T>(v); };
  return k;
}

// An int key kept in an unsigned field (a count or a seed).
template <class Ref>
ConfigKey unsigned_field(const char* section, const char* name, Ref ref, const char* description, ConfigCheck check) {
  using T = std::remove_cvref_t<decltype(ref(std::declval<SystemOptions&>()))>;
  ConfigKey k{section, name, ConfigType::kInt, description, {}, {}, std::move(check), {}, {}};
  k.get = [ref](const SystemOptions& o) { return ConfigValue(static_cast<int>(ref(o))); };
  k.set = [ref](SystemOptions& o, const ConfigValue& v, const std::string&) { ref(o) = static_cast<T>(std::get<int>(v)); };
  return k;
}

double number(const ConfigValue& v) {
  return std::holds_alternative<int>(v) ? static_cast<double>(std::get<int>(v)) : std::get<double>(v);
}

ConfigCheck at_least(double lo) {
  return {[lo](const ConfigValue& v) { return number(v) >= lo; }, fmt::format("must be >= {:g}", lo)};
}
ConfigCheck positive() {
  return {[](const ConfigValue& v) { return number(v) > 0; }, "must be positive"};
}
ConfigCheck in_closed(double lo, double hi) {
  return {[lo, hi](const ConfigValue& v) { return number(v) >= lo && number(v) <= hi; },
          fmt::format("must be in [{:g}, {:g}]", lo, hi)};
}
ConfigCheck in_open_closed(double lo, double hi) {
  return {[lo, hi](const ConfigValue& v) { return number(v) > lo && number(v) <= hi; },
          fmt::format("must be in ({:g}, {:g}]", lo, hi)};
}

ConfigKey distribution_key() {
  ConfigKey k{"features", "distribution", ConfigType::kString,
              "how keypoints are spread over the image: spatial suppression or ORB-SLAM2's quadtree", {}, {}, std::nullopt, {},
              "ssc or quadtree"};
  k.get = [](const SystemOptions& o) { return ConfigValue(std::string(features::to_string(o.extractor.orb.distribution))); };
  k.set = [](SystemOptions& o, const ConfigValue& v, const std::string&) {
    o.extractor.orb.distribution = features::parse_distribution(std::get<std::string>(v));
  };
  k.check_message = [](const ConfigValue& v) -> std::string {
    try {
      features::parse_distribution(std::get<std::string>(v));
      return "";
    } catch (const InputError& e) {
      return std::string("features: ") + e.problem();
    }
  };
  return k;
}

ConfigKey lines_enabled_key() {
  ConfigKey k{"lines", "enabled", ConfigType::kBool, "line features everywhere (false: points only, as --no-lines)",
              {}, {}, std::nullopt, {}, {}};
  k.get = [](const SystemOptions& o) { return ConfigValue(o.extractor.lines); };
  k.set = [](SystemOptions& o, const ConfigValue& v, const std::string&) {
    if (!std::get<bool>(v)) o.disable_lines();
  };
  return k;
}

ConfigKey vocabulary_key() {
  ConfigKey k{"place", "vocabulary", ConfigType::kString,
              "vocabulary file, relative to the configuration file (empty: the one shipped in data/vocabulary)",
              {}, {}, std::nullopt, {}, {}};
  k.get = [](const SystemOptions& o) { return ConfigValue(o.vocabulary.string()); };
  k.set = [](SystemOptions& o, const ConfigValue& v, const std::string& file) {
    const auto& vocabulary = std::get<std::string>(v);
    if (vocabulary == o.vocabulary.string()) return;
    // A relative path in a file is relative to that file's folder, so a config and its vocabulary
    // can move together.
    std::filesystem::path p(vocabulary);
    if (p.is_relative() && !file.empty()) p = std::filesystem::path(file).parent_path() / p;
    o.vocabulary = p;
  };
  return k;
}

std::vector<ConfigKey> make_table() {
  // clang-format off
  return {
    field("features", "n_points", [](auto& o) -> auto& { return o.extractor.orb.n_features; },
          "ORB features per image, over all pyramid levels"),
    field("features", "levels", [](auto& o) -> auto& { return o.extractor.orb.levels; }, "pyramid levels"),
    field("features", "scale_factor", [](auto& o) -> auto& { return o.extractor.orb.scale_factor; },
          "scale between pyramid levels"),
    field("features", "fast_threshold", [](auto& o) -> auto& { return o.extractor.orb.fast_threshold; },
          "FAST corner threshold"),
    field("features", "right_points_factor", [](auto& o) -> auto& { return o.extractor.right_points_factor; },
          "the right image keeps this many times n_points (more candidates for stereo matches)", in_closed(0.1, 10)),
    distribution_key(),

    lines_enabled_key(),
    unsigned_field("lines", "max_lines", [](auto& o) -> auto& { return o.extractor.line_extractor.max_lines; },
                   "line segments kept per image", at_least(0)),
    field("lines", "guided_stereo", [](auto& o) -> auto& { return o.extractor.guided_stereo_lines; },
          "right-image lines from a search along each left line's rows, instead of a second detection"),

    field("tracking", "init_min_points", [](auto& o) -> auto& { return o.tracker.init_min_points; },
          "stereo points a frame needs to start a map"),
    field("tracking", "close_depth_baselines", [](auto& o) -> auto& { return o.tracker.close_depth_baselines; },
          "close stereo points (keyframe decision, new points): depth below this many baselines"),
    field("tracking", "far_stereo_baselines", [](auto& o) -> auto& { return o.tracker.far_stereo_baselines; },
          "right-image matches beyond this many baselines only seed depths, never constrain optimisation (0: all do)",
          at_least(0)),
    field("tracking", "motion_radius", [](auto& o) -> auto& { return o.tracker.motion_radius; },
          "motion-model search radius, pixels at level 0"),
    field("tracking", "local_map_radius", [](auto& o) -> auto& { return o.tracker.local_map_radius; },
          "local-map search radius factor"),
    field("tracking", "line_radius", [](auto& o) -> auto& { return o.tracker.line_radius; },
          "line search radius, pixels"),
    field("tracking", "motion_min_inlier_share", [](auto& o) -> auto& { return o.tracker.motion_min_inlier_share; },
          "below this share of inliers among its matches, the motion model searches again in wider windows",
          in_closed(0, 1)),
    field("tracking", "motion_min_match_share", [](auto& o) -> auto& { return o.tracker.motion_min_match_share; },
          "below this share of the last frame's tracked points among its matches, the motion model searches again "
          "in wider windows", in_closed(0, 1)),
    field("tracking", "motion_retry_scale", [](auto& o) -> auto& { return o.tracker.motion_retry_scale; },
          "how much wider those windows are", at_least(1)),
    field("tracking", "jump_deviation_m", [](auto& o) -> auto& { return o.tracker.jump_deviation_m; },
          "a tracked camera centre this far from the motion model's prediction is reported as a suspect jump "
          "(0: no check)", at_least(0)),
    field("tracking", "jump_deviation_deg", [](auto& o) -> auto& { return o.tracker.jump_deviation_deg; },
          "the same for the rotation, degrees (0: no check)", at_least(0)),
    field("tracking", "recover_after_gap_s",
          [](auto& o) -> auto& { return o.tracker.recover_after_gap_s; },
          "a frame tracked this long after the one before it recovers as a relocalization does (0: never)",
          at_least(0)),
    field("tracking", "min_local_inliers", [](auto& o) -> auto& { return o.tracker.min_local_inliers; },
          "point + line inliers of local map tracking for the frame to count as tracked"),
    field("tracking", "local_keyframes_max", [](auto& o) -> auto& { return o.tracker.local_keyframes_max; },
          "keyframes of the local map tracked against", at_least(1)),
    field("tracking", "new_keyframe_points", [](auto& o) -> auto& { return o.tracker.new_keyframe_points; },
          "a new keyframe creates at least this many stereo points, closest first", at_least(0)),
    field("tracking", "min_motion_matches", [](auto& o) -> auto& { return o.tracker.min_motion_matches; },
          "motion-model matches needed before its pose optimisation", at_least(1)),
    field("tracking", "min_pose_inliers", [](auto& o) -> auto& { return o.tracker.min_pose_inliers; },
          "inliers the motion-model or reference-keyframe pose needs", at_least(1)),
    field("tracking", "reference_match_ratio", [](auto& o) -> auto& { return o.tracker.reference_match_ratio; },
          "descriptor ratio test when matching the reference keyframe", in_open_closed(0, 1)),
    field("tracking", "min_reference_matches", [](auto& o) -> auto& { return o.tracker.min_reference_matches; },
          "reference-keyframe matches needed to optimise the pose from them", at_least(1)),
    field("tracking", "min_pnp_matches", [](auto& o) -> auto& { return o.tracker.min_pnp_matches; },
          "matches needed to try PnP RANSAC as a second start for the reference-keyframe pose", at_least(4)),
    field("tracking", "local_map_covisibles", [](auto& o) -> auto& { return o.tracker.local_map_covisibles; },
          "best covisibles of each keyframe seeing a match that join the local map", at_least(0)),

    field("keyframe", "ratio", [](auto& o) -> auto& { return o.tracker.keyframe.ratio; },
          "a keyframe when the tracked inliers fall below this share of the reference's (with the PID offset)"),
    field("keyframe", "max_frames", [](auto& o) -> auto& { return o.tracker.keyframe.max_frames; },
          "frames after which a keyframe is due regardless"),
    field("keyframe", "min_frames", [](auto& o) -> auto& { return o.tracker.keyframe.min_frames; },
          "frames since the last keyframe before the inlier rule may take one (tracking too weak or close "
          "points missing still take one)"),
    field("keyframe", "pid", [](auto& o) -> auto& { return o.tracker.keyframe.pid; },
          "the PID offset on the inlier rule"),
    field("keyframe", "pid_kp", [](auto& o) -> auto& { return o.tracker.keyframe.pid_gains.kp; }, "PID gain kp"),
    field("keyframe", "pid_ki", [](auto& o) -> auto& { return o.tracker.keyframe.pid_gains.ki; }, "PID gain ki, per second"),
    field("keyframe", "pid_kd", [](auto& o) -> auto& { return o.tracker.keyframe.pid_gains.kd; }, "PID gain kd, seconds"),
    field("keyframe", "pid_output_limit", [](auto& o) -> auto& { return o.tracker.keyframe.pid_output_limit; },
          "bound of the PID offset, as a share of the reference's tracked features"),
    field("keyframe", "kalman", [](auto& o) -> auto& { return o.tracker.keyframe.kalman; },
          "the Kalman velocity rule"),
    field("keyframe", "max_speed", [](auto& o) -> auto& { return o.tracker.keyframe.max_speed; },
          "m/s: faster motion forces a keyframe"),
    field("keyframe", "velocity_min_frames", [](auto& o) -> auto& { return o.tracker.keyframe.velocity_min_frames; },
          "the velocity rule fires at most every this many frames"),
    field("keyframe", "max_queued", [](auto& o) -> auto& { return o.tracker.keyframe.max_queued; },
          "no new keyframe while this many wait for local mapping"),

    field("optim", "line_information", [](auto& o) -> auto& { return o.tracker.line_information; },
          "weight of line residuals against point residuals (tracking, local and global BA)", positive()),

    field("mapping", "local_ba", [](auto& o) -> auto& { return o.mapper.local_ba; }, "local bundle adjustment"),
    field("mapping", "ba_merge_after_frames", [](auto& o) -> auto& { return o.mapper.ba_merge_after_frames; },
          "deterministic mode: a keyframe's local BA enters the map before the frame this many frames later "
          "is tracked (or before the next keyframe is mapped); 1: before the next frame",
          at_least(1)),
    field("mapping", "ba_merge_ms_per_1000_observations",
          [](auto& o) -> auto& { return o.mapper.ba_merge_ms_per_1000_observations; },
          "deterministic mode: ... and not before the frame this many ms (input time) per 1000 observations "
          "of its window after the keyframe's (a large window, after a loop, needs longer); 0: frames only",
          at_least(0)),
    field("mapping", "abort_ba_on_new_keyframe", [](auto& o) -> auto& { return o.mapper.abort_ba_on_new_keyframe; },
          "a keyframe queued during local BA cuts it short (mapping thread only)"),
    field("mapping", "ba_iterations", [](auto& o) -> auto& { return o.mapper.ba.iterations; },
          "local BA: iterations of the robust first pass"),
    field("mapping", "culling_redundancy", [](auto& o) -> auto& { return o.mapper.keyframe_culling.redundancy; },
          "a keyframe is redundant when more than this share of its close points is seen by culling_observers others"),
    field("mapping", "ba_second_iterations", [](auto& o) -> auto& { return o.mapper.ba.second_iterations; },
          "local BA: iterations after the outliers are dropped", at_least(0)),
    field("mapping", "triangulation_neighbors", [](auto& o) -> auto& { return o.mapper.triangulation.neighbors; },
          "best covisible keyframes a new keyframe triangulates new points and lines with", at_least(0)),
    field("mapping", "triangulation_min_baselines", [](auto& o) -> auto& { return o.mapper.triangulation.min_baselines; },
          "no triangulation with a keyframe closer than this many stereo baselines", at_least(0)),
    field("mapping", "triangulation_max_hamming", [](auto& o) -> auto& { return o.mapper.triangulation.point_max_hamming; },
          "a keypoint match for triangulation is closer than this (of 256 bits)", in_closed(1, 256)),
    field("mapping", "triangulation_max_parallax_cos",
          [](auto& o) -> auto& { return o.mapper.triangulation.max_parallax_cos; },
          "rays closer to parallel than this cosine are not triangulated", in_closed(0, 1)),
    field("mapping", "triangulation_scale_tolerance",
          [](auto& o) -> auto& { return o.mapper.triangulation.scale_tolerance; },
          "the two distances' ratio must match the octaves' to within this times the scale factor", positive()),
    field("mapping", "line_triangulation_max_hamming",
          [](auto& o) -> auto& { return o.mapper.triangulation.line_max_hamming; },
          "a line match for triangulation is closer than this (of 256 LBD bits)", in_closed(1, 256)),
    field("mapping", "line_triangulation_min_ray_plane_sine",
          [](auto& o) -> auto& { return o.mapper.triangulation.line_min_ray_plane_sine; },
          "lines closer than this (sine) to the epipolar plane are not triangulated", in_closed(0, 1)),
    field("mapping", "line_triangulation_depth_tolerance",
          [](auto& o) -> auto& { return o.mapper.triangulation.line_depth_tolerance; },
          "a triangulated line's endpoint depths agree with the stereo ones to within this share", at_least(0)),
    field("mapping", "fusion_neighbors", [](auto& o) -> auto& { return o.mapper.fusion.neighbors; },
          "best covisible keyframes searched for duplicates of a new keyframe's points", at_least(0)),
    field("mapping", "recent_min_found_ratio", [](auto& o) -> auto& { return o.mapper.recent.min_found_ratio; },
          "a new landmark is culled when tracking finds it in fewer than this share of the frames that should see it",
          in_closed(0, 1)),
    field("mapping", "recent_min_point_weight", [](auto& o) -> auto& { return o.mapper.recent.min_point_weight; },
          "a new point needs this observation weight after its probation (stereo observations count 2)",
          at_least(0)),
    field("mapping", "recent_min_line_observers", [](auto& o) -> auto& { return o.mapper.recent.min_line_observers; },
          "a new line needs this many observing keyframes after its probation", at_least(0)),
    field("mapping", "recent_probation_keyframes",
          [](auto& o) -> auto& { return o.mapper.recent.probation_keyframes; },
          "keyframes before the observation rule applies to a new landmark", at_least(0)),
    field("mapping", "culling_observers", [](auto& o) -> auto& { return o.mapper.keyframe_culling.observers; },
          "other keyframes that must see a point for it to count towards culling_redundancy", at_least(1)),
    field("mapping", "culling_close_depth_baselines",
          [](auto& o) -> auto& { return o.mapper.keyframe_culling.close_depth_baselines; },
          "keyframe culling counts the points closer than this many baselines", positive()),

    field("place", "enabled", [](auto& o) -> auto& { return o.place_recognition; },
          "place recognition (a keyframe database): relocalization and loop closing need it"),
    vocabulary_key(),

    field("relocalization", "enabled", [](auto& o) -> auto& { return o.tracker.relocalization.enabled; },
          "relocalization while lost (false: a lost camera starts a new map segment)"),
    unsigned_field("relocalization", "max_candidates",
                   [](auto& o) -> auto& { return o.tracker.relocalization.max_candidates; },
                   "keyframes tried per frame, best place first", at_least(1)),
    field("relocalization", "min_bow_matches", [](auto& o) -> auto& { return o.tracker.relocalization.min_bow_matches; },
          "BoW matches a candidate needs before PnP", at_least(4)),
    field("relocalization", "min_inliers", [](auto& o) -> auto& { return o.tracker.relocalization.min_inliers; },
          "point + line inliers to accept a pose", at_least(1)),
    field("relocalization", "min_found_ratio",
          [](auto& o) -> auto& { return o.tracker.relocalization.min_found_ratio; },
          "share of the place's map points visible from the pose that must be matched (a look-alike place "
          "matches only what repeats)",
          in_closed(0, 1)),
    field("relocalization", "search_radius", [](auto& o) -> auto& { return o.tracker.relocalization.search_radius; },
          "factor of the local-map search window around the PnP pose", positive()),
    field("relocalization", "max_speed", [](auto& o) -> auto& { return o.tracker.relocalization.max_speed; },
          "m/s: a pose further from the last tracked one than this times the time since (plus gate_margin) is a "
          "look-alike place (0: no gate)",
          at_least(0)),
    field("relocalization", "confirm_frames",
          [](auto& o) -> auto& { return o.tracker.relocalization.confirm_frames; },
          "frames in a row tracked from a relocalization before its poses are trusted (until then: recovering, "
          "no keyframe)",
          at_least(1)),
    field("relocalization", "confirm_distance_m",
          [](auto& o) -> auto& { return o.tracker.relocalization.confirm_distance_m; },
          "... and the camera moved this far from the relocalized pose (or turned confirm_angle_deg; both 0: "
          "no such condition)",
          at_least(0)),
    field("relocalization", "confirm_angle_deg",
          [](auto& o) -> auto& { return o.tracker.relocalization.confirm_angle_deg; },
          "... or turned this far from it", at_least(0)),
    field("relocalization", "min_cell_coverage",
          [](auto& o) -> auto& { return o.tracker.relocalization.min_cell_coverage; },
          "while recovering: share of the image cells showing local map points that must hold inliers (a "
          "look-alike matches only the repeated object; 0: no check)",
          in_closed(0, 1)),
    field("relocalization", "max_cell_misses",
          [](auto& o) -> auto& { return o.tracker.relocalization.max_cell_misses; },
          "recovering frames under min_cell_coverage that are forgiven, each after two frames that held it and "
          "for one more such frame before the confirmation (0: every one refutes)",
          at_least(0)),
    field("relocalization", "continuity_s",
          [](auto& o) -> auto& { return o.tracker.relocalization.continuity_s; },
          "a relocalization this soon after the last trusted frame that lands where the motion model puts it "
          "(within tracking.jump_deviation_m/_deg) is confirmed at once (0: never)",
          at_least(0)),
    field("relocalization", "gate_margin", [](auto& o) -> auto& { return o.tracker.relocalization.gate_margin; },
          "metres added to that reach", at_least(0)),
    field("relocalization", "new_segment_after_s",
          [](auto& o) -> auto& { return o.tracker.relocalization.new_segment_after_s; },
          "seconds of textured frames failing to relocalize before a new map segment", at_least(0)),
    field("relocalization", "search_covisibles",
          [](auto& o) -> auto& { return o.tracker.relocalization.search_covisibles; },
          "best covisibles of a candidate whose landmarks are searched too", at_least(0)),

    field("loop", "enabled", [](auto& o) -> auto& { return o.loop_closing; },
          "loop closing (needs place.enabled), in its own thread after local mapping"),
    field("loop", "consistency", [](auto& o) -> auto& { return o.loop.detector.consistency; },
          "consecutive keyframes that must find the same place"),
    field("loop", "min_matches", [](auto& o) -> auto& { return o.loop.verifier.min_matches; },
          "BoW matches between map points before the SE(3) RANSAC"),
    field("loop", "min_inliers", [](auto& o) -> auto& { return o.loop.verifier.min_inliers; },
          "RANSAC inliers (reprojection in both keyframes)"),
    field("loop", "min_projection_inliers", [](auto& o) -> auto& { return o.loop.min_projection_inliers; },
          "inliers after projecting the place's points and refining the pose (>= min_inliers)"),
    field("loop", "projection_radius", [](auto& o) -> auto& { return o.loop.projection_radius; },
          "pixels at the predicted level, for that projection search"),
    field("loop", "keyframes_between_loops", [](auto& o) -> auto& { return o.loop.keyframes_between_loops; },
          "no new loop within this many keyframes of the last one"),
    field("loop", "max_drift_ratio", [](auto& o) -> auto& { return o.loop.max_drift_ratio; },
          "a loop may move the keyframe by this share of the path since the place (plus min_drift_m)"),
    field("loop", "min_drift_m", [](auto& o) -> auto& { return o.loop.min_drift_m; }, "metres added to that"),
    field("loop", "max_drift_deg", [](auto& o) -> auto& { return o.loop.max_drift_deg; },
          "degrees a loop may turn the keyframe"),
    field("loop", "essential_min_weight",
          [](auto& o) -> auto& { return o.loop.correction.graph.min_covisibility_weight; },
          "covisibility weight of the essential graph's edges"),
    field("loop", "essential_iterations", [](auto& o) -> auto& { return o.loop.correction.graph.iterations; },
          "pose-graph iterations"),
    field("loop", "global_ba", [](auto& o) -> auto& { return o.loop.global_ba; },
          "global BA after each loop, in a background thread"),
    field("loop", "global_ba_after_relocalization",
          [](auto& o) -> auto& { return o.loop.global_ba_after_relocalization; },
          "also after tracking relocalized in the same map after a loss (a revisit no loop is closed for)"),
    field("loop", "across_relocalization",
          [](auto& o) -> auto& { return o.loop.loop_across_relocalization; },
          "before that global BA, verify a loop from the last keyframe before the loss to the revisit's first "
          "(a loss that hid the loop's detection); needs global_ba_after_relocalization"),
    field("loop", "global_ba_iterations", [](auto& o) -> auto& { return o.loop.global_ba_options.iterations; },
          "global BA iterations (per pass)"),
    field("loop", "global_ba_remove_outliers", [](auto& o) -> auto& { return o.loop.global_ba_options.remove_outliers; },
          "global BA drops the observations beyond their gate after its robust pass and runs a second pass"),
    field("loop", "finish_wait_s", [](auto& o) -> auto& { return o.loop.finish_wait_s; },
          "at the end of a run, seconds to wait for a running global BA"),
    field("loop", "global_ba_merge_after_s", [](auto& o) -> auto& { return o.loop.global_ba_merge_after_s; },
          "deterministic mode: a global BA's result enters the map at the first frame this many seconds "
          "(input time) after the frame that started it; tracking waits there if it is not done"),
    field("loop", "correction_merge_after_frames", [](auto& o) -> auto& { return o.loop.correction_merge_after_frames; },
          "deterministic mode: a loop correction's essential graph is solved beside tracking and the rest of "
          "the map moves before the frame this many frames after the correction began", at_least(1)),

    field("imu", "enabled", [](auto& o) -> auto& { return o.use_input_imu; },
          "plslam run uses the input's IMU (false: stereo only, as --no-imu)"),
    field("imu", "visual_inertial", [](auto& o) -> auto& { return o.visual_inertial; },
          "once the IMU is initialised, tracking and local BA use it (false: it only turns the world to gravity)"),
    field("imu", "local_ba_keyframes", [](auto& o) -> auto& { return o.mapper.imu_window; },
          "keyframes of the IMU chain that local BA optimises with their IMU factors", at_least(1)),
    field("imu", "seed_keyframes", [](auto& o) -> auto& { return o.tracker.imu.seed_keyframes; },
          "the last keyframes of the map that start the IMU chain once the IMU is initialised (0: all of them)",
          at_least(0)),
    field("imu", "max_keyframe_interval_s", [](auto& o) -> auto& { return o.tracker.imu.max_keyframe_interval_s; },
          "with the IMU, a keyframe is due once the last one is this old (preintegration stays short)", at_least(0.05)),
    field("imu", "max_culled_interval_s", [](auto& o) -> auto& { return o.mapper.keyframe_culling.max_imu_interval_s; },
          "a keyframe of the IMU chain is culled only if its neighbours are then at most this far apart in time",
          at_least(0.05)),
    field("imu", "max_prediction_s", [](auto& o) -> auto& { return o.tracker.imu.max_prediction_s; },
          "the IMU predicts a frame from the newest keyframe whose state local BA estimated, at most this much older",
          at_least(0.05)),
    field("imu", "max_texture_points", [](auto& o) -> auto& { return o.tracker.imu.max_texture_points; },
          "only a frame with fewer stereo points than this is carried by the IMU when vision fails", at_least(0)),
    field("imu", "max_inertial_s", [](auto& o) -> auto& { return o.tracker.imu.max_inertial_s; },
          "frames vision cannot track take the IMU's pose for at most this long, then the camera is lost",
          at_least(0)),
    field("imu", "map_new_views", [](auto& o) -> auto& { return o.tracker.imu.map_new_views; },
          "a textured frame vision cannot place, within max_inertial_s, facing a view the map lacks: a keyframe at "
          "the IMU's pose maps it (false: the camera is lost)"),
    field("imu", "new_view_max_visible_points", [](auto& o) -> auto& { return o.tracker.imu.new_view_max_visible_points; },
          "a view is new if fewer map points than this are visible from the IMU's pose", at_least(1)),
    field("imu", "refine_after_s", [](auto& o) -> auto& { return o.imu_refine_after_s; },
          "input seconds after the turn to stereo-inertial at which a global BA with the IMU factors refines gravity, "
          "velocities and biases over the whole map (0: not; needs loop closing)", at_least(0)),
    field("imu", "refine_again_after_s", [](auto& o) -> auto& { return o.imu_refine_again_after_s; },
          "a second such refinement, this many input seconds after the turn (0: not)", at_least(0)),
    unsigned_field("system", "seed", [](auto& o) -> auto& { return o.seed; },
                   "seed of every random choice (the PnP RANSAC of relocalization and loop closing)", at_least(0)),
  };
  // clang-format on
}

}  // namespace

const char* to_string(ConfigType t) {
  switch (t) {
    case ConfigType::kBool: return "bool";
    case ConfigType::kInt: return "int";
    case ConfigType::kDouble: return "double";
    case ConfigType::kString: return "string";
  }
  return "?";
}

const std::vector<ConfigKey>& config_table() {
  static const std::vector<ConfigKey> table = make_table();
  return table;
}

const std::vector<SectionCheck>& section_checks() {
  static const std::vector<SectionCheck> checks = {
      {"features",
       [](const SystemOptions& o, const std::string& file) {
         try {
           o.extractor.orb.validate();
         } catch (const InputError& e) {
           throw InputError(file, std::string("features: ") + e.problem());
         }
       }},
      {"keyframe", [](const SystemOptions& o, const std::string& file) { o.tracker.keyframe.validate(file); }},
      {"loop",
       [](const SystemOptions& o, const std::string& file) {
         try {
           o.loop.validate();
         } catch (const std::invalid_argument& e) {
           throw InputError(file, e.what());
         }
       }},
  };
  return checks;
}

std::string to_yaml_text(const ConfigValue& v) {
  if (const bool* b = std::get_if<bool>(&v)) return *b ? "true" : "false";
  if (const int* i = std::get_if<int>(&v)) return fmt::format("{}", *i);
  if (const double* d = std::get_if<double>(&v)) return fmt::format("{}", *d);
  return std::get<std::string>(v);
}

}  // namespace plslam::system
