#include "plslam/system/system_config.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::system {

SystemOptions apply_config(const ConfigReader& config, SystemOptions o) {
  const auto features = config.section("features");
  features.get("n_points", o.extractor.orb.n_features);
  features.get("levels", o.extractor.orb.levels);
  features.get("scale_factor", o.extractor.orb.scale_factor);
  features.get("fast_threshold", o.extractor.orb.fast_threshold);
  std::string distribution = features::to_string(o.extractor.orb.distribution);
  features.get("distribution", distribution);
  try {
    o.extractor.orb.distribution = features::parse_distribution(distribution);
    o.extractor.orb.validate();
  } catch (const InputError& e) {
    throw InputError(config.source(), std::string("features: ") + e.problem());
  }

  const auto lines = config.section("lines");
  bool lines_enabled = o.extractor.lines;
  lines.get("enabled", lines_enabled);
  int max_lines = static_cast<int>(o.extractor.line_extractor.max_lines);
  lines.get("max_lines", max_lines);
  if (max_lines < 0) throw InputError(config.source(), "lines.max_lines: must be >= 0");
  o.extractor.line_extractor.max_lines = static_cast<std::size_t>(max_lines);
  if (!lines_enabled) o.disable_lines();

  const auto tracking = config.section("tracking");
  tracking.get("init_min_points", o.tracker.init_min_points);
  tracking.get("close_depth_baselines", o.tracker.close_depth_baselines);
  tracking.get("far_stereo_baselines", o.tracker.far_stereo_baselines);
  if (o.tracker.far_stereo_baselines < 0) throw InputError(config.source(), "tracking.far_stereo_baselines: must be >= 0");
  tracking.get("motion_radius", o.tracker.motion_radius);
  tracking.get("local_map_radius", o.tracker.local_map_radius);
  tracking.get("line_radius", o.tracker.line_radius);
  tracking.get("motion_min_inlier_share", o.tracker.motion_min_inlier_share);
  if (!(o.tracker.motion_min_inlier_share >= 0 && o.tracker.motion_min_inlier_share <= 1))
    throw InputError(config.source(), "tracking.motion_min_inlier_share: must be in [0, 1]");
  tracking.get("motion_retry_scale", o.tracker.motion_retry_scale);
  if (!(o.tracker.motion_retry_scale >= 1))
    throw InputError(config.source(), "tracking.motion_retry_scale: must be >= 1");
  tracking.get("min_local_inliers", o.tracker.min_local_inliers);
  tracking.get("local_keyframes_max", o.tracker.local_keyframes_max);
  if (o.tracker.local_keyframes_max < 1) throw InputError(config.source(), "tracking.local_keyframes_max: must be >= 1");

  const auto kf = config.section("keyframe");
  auto& k = o.tracker.keyframe;
  kf.get("ratio", k.ratio);
  kf.get("max_frames", k.max_frames);
  kf.get("pid", k.pid);
  kf.get("pid_kp", k.pid_gains.kp);
  kf.get("pid_ki", k.pid_gains.ki);
  kf.get("pid_kd", k.pid_gains.kd);
  kf.get("pid_output_limit", k.pid_output_limit);
  kf.get("kalman", k.kalman);
  kf.get("max_speed", k.max_speed);
  kf.get("velocity_min_frames", k.velocity_min_frames);
  k.validate(config.source());

  const auto optim = config.section("optim");
  optim.get("line_information", o.tracker.line_information);
  if (!(o.tracker.line_information > 0)) throw InputError(config.source(), "optim.line_information: must be positive");

  const auto mapping = config.section("mapping");
  mapping.get("local_ba", o.mapper.local_ba);
  mapping.get("ba_iterations", o.mapper.ba.iterations);
  mapping.get("culling_redundancy", o.mapper.keyframe_culling.redundancy);

  const auto place = config.section("place");
  place.get("enabled", o.place_recognition);
  std::string vocabulary = o.vocabulary.string();
  place.get("vocabulary", vocabulary);
  if (vocabulary != o.vocabulary.string()) {
    // A relative path in a file is relative to that file's folder, so a config and its vocabulary
    // can move together.
    std::filesystem::path v(vocabulary);
    if (v.is_relative() && !config.source().empty()) v = std::filesystem::path(config.source()).parent_path() / v;
    o.vocabulary = v;
  }

  const auto reloc = config.section("relocalization");
  auto& r = o.tracker.relocalization;
  reloc.get("enabled", r.enabled);
  int max_candidates = static_cast<int>(r.max_candidates);
  reloc.get("max_candidates", max_candidates);
  if (max_candidates < 1) throw InputError(config.source(), "relocalization.max_candidates: must be >= 1");
  r.max_candidates = static_cast<std::size_t>(max_candidates);
  reloc.get("min_bow_matches", r.min_bow_matches);
  if (r.min_bow_matches < 4) throw InputError(config.source(), "relocalization.min_bow_matches: must be >= 4");
  reloc.get("min_inliers", r.min_inliers);
  if (r.min_inliers < 1) throw InputError(config.source(), "relocalization.min_inliers: must be >= 1");
  reloc.get("search_radius", r.search_radius);
  if (!(r.search_radius > 0)) throw InputError(config.source(), "relocalization.search_radius: must be positive");
  reloc.get("max_speed", r.max_speed);
  if (!(r.max_speed >= 0)) throw InputError(config.source(), "relocalization.max_speed: must be >= 0");
  reloc.get("gate_margin", r.gate_margin);
  if (!(r.gate_margin >= 0)) throw InputError(config.source(), "relocalization.gate_margin: must be >= 0");
  reloc.get("new_segment_after_s", r.new_segment_after_s);
  if (!(r.new_segment_after_s >= 0)) throw InputError(config.source(), "relocalization.new_segment_after_s: must be >= 0");

  const auto loop = config.section("loop");
  loop.get("enabled", o.loop_closing);
  auto& l = o.loop;
  loop.get("consistency", l.detector.consistency);
  loop.get("min_matches", l.verifier.min_matches);
  loop.get("min_inliers", l.verifier.min_inliers);
  loop.get("min_projection_inliers", l.min_projection_inliers);
  loop.get("projection_radius", l.projection_radius);
  loop.get("keyframes_between_loops", l.keyframes_between_loops);
  loop.get("max_drift_ratio", l.max_drift_ratio);
  loop.get("min_drift_m", l.min_drift_m);
  loop.get("max_drift_deg", l.max_drift_deg);
  loop.get("essential_min_weight", l.correction.graph.min_covisibility_weight);
  loop.get("essential_iterations", l.correction.graph.iterations);
  loop.get("global_ba", l.global_ba);
  loop.get("global_ba_iterations", l.global_ba_options.iterations);
  loop.get("finish_wait_s", l.finish_wait_s);
  try {
    l.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(config.source(), e.what());
  }

  const auto system = config.section("system");
  int seed = static_cast<int>(o.seed);
  system.get("seed", seed);
  if (seed < 0) throw InputError(config.source(), "system.seed: must be >= 0");
  o.seed = static_cast<std::uint32_t>(seed);

  config.check_all_used();
  return o;
}

std::filesystem::path default_vocabulary_path() {
  // The source tree's copy (a build tree), then the installed one: beside the running program
  // (<prefix>/bin/../share/plslam, wherever the prefix was moved) or at the configured prefix (a
  // program that embeds the library and lives elsewhere).
  const std::filesystem::path source = PLSLAM_DEFAULT_VOCABULARY;
  const auto name = source.filename();
  // PLSLAM_DATA_DIR (<prefix>/share/plslam) names an installed copy explicitly, for a prefix moved
  // after the build.
  if (const char* dir = std::getenv("PLSLAM_DATA_DIR"); dir && *dir) {
    return std::filesystem::path(dir) / "vocabulary" / name;
  }
  std::vector<std::filesystem::path> candidates = {source};
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path().parent_path() / "share/plslam/vocabulary" / name);
  const std::filesystem::path installed = std::filesystem::path(PLSLAM_INSTALL_DATA_DIR) / "vocabulary" / name;
  candidates.push_back(installed);
  for (const auto& c : candidates) {
    if (std::filesystem::is_regular_file(c, ec)) return c;
  }
  return installed;  // missing: loading it names this path
}

std::shared_ptr<const place::Vocabulary> load_vocabulary(const SystemOptions& o) {
  if (!o.place_recognition) return nullptr;
  const auto path = o.vocabulary.empty() ? default_vocabulary_path() : o.vocabulary;
  return std::make_shared<const place::Vocabulary>(place::Vocabulary::load(path));
}

SystemOptions load_system_options(io::DatasetFormat format, const std::optional<std::filesystem::path>& file) {
  const SystemOptions preset = format == io::DatasetFormat::kKitti ? SystemOptions::kitti() : SystemOptions::euroc();
  return apply_config(file ? ConfigReader::from_file(*file) : ConfigReader(), preset);
}

}  // namespace plslam::system
