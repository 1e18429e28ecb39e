#include "plslam/bench/published_results.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "plslam/core/error.h"
#include "plslam/system/system_config.h"

namespace plslam::bench {
namespace fs = std::filesystem;

std::vector<PublishedResult> PublishedResults::of(const std::string& sequence) const {
  std::vector<PublishedResult> out;
  std::copy_if(results.begin(), results.end(), std::back_inserter(out),
               [&](const PublishedResult& r) { return r.sequence == sequence; });
  return out;
}

const std::vector<std::string>& published_metrics() {
  static const std::vector<std::string> m = {"ate_m", "rpe_trans_m", "rpe_rot_rad", "kitti_t_rel_percent",
                                             "kitti_r_rel_deg_per_100m"};
  return m;
}

namespace {

std::string text_of(const YAML::Node& n, const std::string& key, const std::string& where, const std::string& src,
                    bool required = true) {
  const YAML::Node v = n[key];
  if (!v) {
    if (required) throw InputError(src, where + ": missing '" + key + "'");
    return "";
  }
  if (!v.IsScalar()) throw InputError(src, where + "." + key + ": expected text");
  return v.Scalar();
}

bool flag_of(const YAML::Node& n, const std::string& where, const std::string& src) {
  if (!n["verified"]) return true;
  try {
    return n["verified"].as<bool>();
  } catch (const YAML::Exception&) {
    throw InputError(src, where + ".verified: expected true or false");
  }
}

std::optional<double> number_of(const YAML::Node& v, const std::string& where, const std::string& src) {
  if (!v || v.IsNull()) return std::nullopt;
  double x = 0;
  try {
    x = v.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(src, where + ": expected a number or null");
  }
  if (!std::isfinite(x) || x < 0) throw InputError(src, where + ": expected a finite number >= 0");
  return x;
}

}  // namespace

PublishedResults parse_published_results(const std::string& text, const std::string& src) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(src, std::string("not YAML: ") + e.what());
  }
  if (!root.IsMap() || !root["sources"] || !root["sources"].IsMap() || !root["sequences"] ||
      !root["sequences"].IsMap() || !root["results"] || !root["results"].IsSequence()) {
    throw InputError(src, "expected the maps 'sources' and 'sequences' and the list 'results'");
  }
  PublishedResults out;
  for (const auto& kv : root["sources"]) {
    if (!kv.first.IsScalar() || !kv.second.IsMap()) throw InputError(src, "sources: expected id: {title: ...}");
    const std::string where = "sources." + kv.first.Scalar();
    out.sources[kv.first.Scalar()] = {text_of(kv.second, "title", where, src), text_of(kv.second, "authors", where, src),
                                      text_of(kv.second, "venue", where, src), text_of(kv.second, "url", where, src),
                                      text_of(kv.second, "cite", where, src)};
  }
  for (const auto& kv : root["sequences"]) {
    if (!kv.first.IsScalar() || !kv.second.IsMap()) throw InputError(src, "sequences: expected id: {folder: ...}");
    const std::string where = "sequences." + kv.first.Scalar();
    PublishedSequence s;
    s.folder = text_of(kv.second, "folder", where, src);
    const auto frames = number_of(kv.second["frames"], where + ".frames", src);
    if (!frames || *frames < 1 || *frames > 1e9 || *frames != std::floor(*frames)) {
      throw InputError(src, where + ".frames: expected a count of frames");
    }
    s.frames = static_cast<long>(*frames);
    s.length_m = number_of(kv.second["length_m"], where + ".length_m", src);
    out.sequences[kv.first.Scalar()] = s;
  }
  const auto& metrics = published_metrics();
  std::size_t i = 0;
  for (const auto& n : root["results"]) {
    const std::string where = "results[" + std::to_string(i++) + "]";
    if (!n.IsMap()) throw InputError(src, where + ": expected {system: ..., sequence: ..., ...}");
    PublishedResult r;
    r.system = text_of(n, "system", where, src);
    r.mode = text_of(n, "mode", where, src);
    r.sequence = text_of(n, "sequence", where, src);
    r.metric = text_of(n, "metric", where, src);
    r.source = text_of(n, "source", where, src);
    r.table = text_of(n, "table", where, src);
    r.note = text_of(n, "note", where, src, false);
    if (!n["value"]) throw InputError(src, where + ": missing 'value' (null for a lost sequence)");
    r.value = number_of(n["value"], where + ".value", src);
    r.verified = flag_of(n, where, src);
    if (r.mode != "stereo" && r.mode != "stereo-inertial") throw InputError(src, where + ".mode: stereo or stereo-inertial");
    if (std::find(metrics.begin(), metrics.end(), r.metric) == metrics.end()) {
      throw InputError(src, where + ".metric: '" + r.metric + "' is not one of ate_m, rpe_trans_m, rpe_rot_rad, "
                                                               "kitti_t_rel_percent, kitti_r_rel_deg_per_100m");
    }
    if (!out.sources.count(r.source)) throw InputError(src, where + ".source: '" + r.source + "' is not in sources");
    if (!out.sequences.count(r.sequence)) throw InputError(src, where + ".sequence: '" + r.sequence + "' is not in sequences");
    out.results.push_back(std::move(r));
  }
  return out;
}

PublishedResults load_published_results(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "cannot be read");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_published_results(ss.str(), file.string());
}

nlohmann::json published_comparison(const PublishedResults& published, const std::string& sequence,
                                    std::size_t dataset_frames, const nlohmann::json& per_row,
                                    const std::vector<std::string>& plslam_rows) {
  using nlohmann::json;
  const auto results = published.of(sequence);
  const auto seq = published.sequences.find(sequence);
  if (results.empty() || seq == published.sequences.end()) return nullptr;
  const bool full = static_cast<double>(dataset_frames) >= 0.95 * static_cast<double>(seq->second.frames);
  json rows = json::array();
  for (const auto& r : results) {
    json* row = nullptr;
    for (auto& x : rows) {
      if (x["system"] == r.system && x["mode"] == r.mode && x["source"] == r.source) row = &x;
    }
    if (!row) {
      rows.push_back({{"system", r.system}, {"mode", r.mode}, {"source", r.source}, {"tables", json::array()},
                      {"values", json::object()}, {"notes", json::array()}, {"verified", true}});
      row = &rows.back();
    }
    if (std::find((*row)["tables"].begin(), (*row)["tables"].end(), r.table) == (*row)["tables"].end()) {
      (*row)["tables"].push_back(r.table);
    }
    (*row)["values"][r.metric] = r.value ? json(*r.value) : json(nullptr);
    if (!r.note.empty()) (*row)["notes"].push_back(r.metric + ": " + r.note);
    (*row)["verified"] = (*row)["verified"].get<bool>() && r.verified;
  }
  for (auto& row : rows) {
    json beaten = json::array();
    for (const auto& name : plslam_rows) {
      if (!full || !per_row.contains(name)) continue;
      int compared = 0;
      bool better = true;
      for (const char* k : {"ate_m", "kitti_t_rel_percent", "kitti_r_rel_deg_per_100m"}) {
        const json& mine = per_row[name].value(k, json(nullptr));
        if (!row["values"].contains(k) || !mine.is_object()) continue;
        const json& theirs = row["values"][k];
        ++compared;  // a published null is a sequence the system lost: any score beats it
        if (theirs.is_number() && !(mine["median"].get<double>() < theirs.get<double>())) better = false;
      }
      if (compared > 0 && better) beaten.push_back(name);
    }
    row["beaten_by"] = beaten;
  }
  return {{"sequence", sequence}, {"frames_published", seq->second.frames}, {"full_sequence", full}, {"rows", rows}};
}

fs::path default_published_results_file() {
  return system::shipped_data_file(fs::path("published") / "slam_results.yaml");
}

}  // namespace plslam::bench
