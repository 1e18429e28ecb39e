#include "plslam/bench/slam_bench.h"

#include <algorithm>
#include <fstream>
#include <functional>
#include <set>
#include <string_view>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/core/sample_stats.h"
#include "plslam/eval/evaluate.h"
#include "plslam/eval/kitti_metric.h"
#include "plslam/eval/rpe.h"
#include "plslam/eval/statistics.h"
#include "plslam/io/trajectory_io.h"

namespace plslam::bench {
namespace fs = std::filesystem;
using nlohmann::json;

std::vector<BenchRow> bench_rows(const std::vector<SlamConfiguration>& configs, const std::string& anchor_name) {
  std::vector<BenchRow> rows;
  bool odometry = false;
  for (const auto& c : configs) {
    rows.push_back({c.name, false, !disables_loop_closing(c), c});
    odometry = odometry || !rows.back().loop_closing;
  }
  if (!anchor_name.empty()) {
    rows.push_back({anchor_name, true, true, {}});
    if (odometry) rows.push_back({anchor_name + "-no-loop-closing", true, false, {}});
  }
  return rows;
}

std::vector<BenchJob> plan_jobs(std::size_t datasets, std::size_t rows, int runs) {
  std::vector<BenchJob> jobs;
  for (int r = 1; r <= runs; ++r) {
    for (std::size_t d = 0; d < datasets; ++d) {
      for (std::size_t k = 0; k < rows; ++k) jobs.push_back({d, k, r});
    }
  }
  return jobs;
}

std::vector<BenchDataset> name_datasets(const std::vector<fs::path>& paths, const std::vector<std::string>& preferred) {
  std::vector<BenchDataset> out;
  std::set<std::string> used;
  for (std::size_t k = 0; k < paths.size(); ++k) {
    const fs::path& p = paths[k];
    fs::path clean = p.lexically_normal();
    if (clean.filename().empty()) clean = clean.parent_path();
    std::string name = clean.filename().string();
    if (name == "mav0") name = clean.parent_path().filename().string();
    if (!name.empty() && std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      name = "kitti-" + name;
    }
    if (name.empty() || name == "." || name == "..") name = "dataset";
    if (k < preferred.size() && !preferred[k].empty()) name = preferred[k];
    std::string unique = name;
    for (int i = 2; used.count(unique); ++i) unique = fmt::format("{}-{}", name, i);
    used.insert(unique);
    out.push_back({unique, p, {}, {}});
  }
  return out;
}

fs::path run_folder(const fs::path& out, const BenchDataset& d, const BenchRow& r, int run) {
  return out / "runs" / d.name / r.name / fmt::format("run-{}", run);
}

const std::vector<MetricInfo>& bench_metrics() {
  static const std::vector<MetricInfo> metrics = {
      {"ate_m", "ATE m", 4},
      {"rpe_frame_trans_m", "RPE 1 frame m", 4},
      {"rpe_frame_rot_deg", "RPE 1 frame deg", 3},
      {"rpe_1m_trans_m", "RPE 1 m m", 4},
      {"rpe_1m_rot_deg", "RPE 1 m deg", 3},
      {"kitti_t_rel_percent", "KITTI t_rel %", 2},
      {"kitti_r_rel_deg_per_100m", "KITTI r_rel deg/100 m", 2},
      {"tracked_share", "tracked %", 3},
      {"imu_share", "IMU %", 3},
      {"lost_events", "lost", 0},
      {"relocalizations", "reloc", 0},
      {"loops", "loops", 0},
      {"keyframes", "KF", 0},
      {"map_points", "points", 0},
      {"map_lines", "lines", 0},
      {"tracking_ms_median", "track ms", 1},
      {"tracking_ms_p90", "track ms p90", 1},
  };
  return metrics;
}

json read_json_file(const fs::path& p) {
  std::ifstream in(p);
  if (!in) throw InputError(p.string(), "missing");
  try {
    return json::parse(in);
  } catch (const json::exception& e) {
    throw InputError(p.string(), std::string("not JSON: ") + e.what());
  }
}

namespace {

json number_at(const json& j, std::initializer_list<const char*> path) {
  const json* cur = &j;
  for (const char* key : path) {
    if (!cur->is_object() || !cur->contains(key)) return nullptr;
    cur = &(*cur)[key];
  }
  return cur->is_number() ? *cur : json(nullptr);
}

double ratio(const json& a, const json& b) {
  if (!a.is_number() || !b.is_number() || b.get<double>() <= 0) return 0.0;
  return a.get<double>() / b.get<double>();
}

// The KITTI devkit's t_rel and r_rel on trajectory.kitti (one pose per input frame, the last one
// held where tracking was lost, as the devkit expects), paired with the ground truth by index.
// Null where the run wrote no such file or the path is shorter than the devkit's 100 m.
void measure_kitti_devkit(const Trajectory& gt, const fs::path& folder, json& m) {
  const fs::path file = folder / "trajectory.kitti";
  if (!fs::exists(file)) return;
  try {
    const auto est = io::read_trajectory(file, io::TrajectoryFormat::kKitti);
    if (est.size() != gt.size()) {
      m["kitti_error"] = fmt::format("{}: {} poses for {} ground-truth frames", file.string(), est.size(), gt.size());
      return;
    }
    const auto k = eval::kitti_odometry_metric(gt, est);
    m["kitti_t_rel_percent"] = k.t_rel_percent;
    m["kitti_r_rel_deg_per_100m"] = k.r_rel_deg_per_100m;
  } catch (const InputError&) {
    // Shorter than one 100 m segment: no devkit figure.
  }
}

}  // namespace

json measure_run(const io::Dataset& dataset, const fs::path& folder, bool anchor) {
  json m = json::object();
  for (const auto& k : bench_metrics()) m[k.key] = nullptr;
  json stats;
  try {
    stats = read_json_file(folder / "stats.json");
  } catch (const InputError& e) {
    m["error"] = e.what();
    return m;
  }
  const json frames = number_at(stats, {anchor ? "frames" : "input_frames"});
  const json tracked = number_at(stats, {anchor ? "frames_tracked_ok" : "tracked_frames"});
  if (tracked.is_number() && frames.is_number() && frames.get<double>() > 0) m["tracked_share"] = ratio(tracked, frames);
  if (anchor) {
    m["lost_events"] = number_at(stats, {"events", "lost_transitions"});
    m["relocalizations"] = number_at(stats, {"events", "relocalized"});
    m["loops"] = number_at(stats, {"loop_corrections"});
  } else {
    m["lost_events"] = number_at(stats, {"lost_events"});
    m["relocalizations"] = number_at(stats, {"relocalizations", "count"});
    m["loops"] = stats.contains("loops") && stats["loops"].is_array() ? json(stats["loops"].size()) : json(nullptr);
    m["map_lines"] = number_at(stats, {"map_lines"});
    // Frames the IMU helped to track; 0 where it was off, absent or never initialised.
    const json imu_frames = number_at(stats, {"imu", "slam", "imu_tracked_frames"});
    if (frames.is_number() && frames.get<double>() > 0) m["imu_share"] = imu_frames.is_number() ? ratio(imu_frames, frames) : 0.0;
  }
  m["keyframes"] = number_at(stats, {"keyframes"});
  m["map_points"] = number_at(stats, {"map_points"});
  m["tracking_ms_median"] = number_at(stats, {"tracking_ms", "median"});
  m["tracking_ms_p90"] = number_at(stats, {"tracking_ms", "p90"});

  const fs::path traj = folder / "trajectory.tum";
  if (!dataset.ground_truth()) {
    m["error"] = "the dataset has no ground truth";
    return m;
  }
  if (!fs::exists(traj)) {
    m["error"] = traj.string() + ": missing (the run wrote no trajectory)";
    return m;
  }
  try {
    const auto est = io::read_trajectory(traj, io::TrajectoryFormat::kTum);
    eval::EvalOptions o;
    o.align = eval::AlignMode::kSE3;
    const auto r = eval::evaluate(*dataset.ground_truth(), est, o);
    m["ate_m"] = r.ape_trans_stats.rmse;
    m["rpe_frame_trans_m"] = r.rpe_trans_stats.rmse;
    m["rpe_frame_rot_deg"] = r.rpe_rot_stats.rmse;
    m["coverage"] = r.coverage;
    try {
      // On the pairs already associated and aligned above: only the RPE's delta differs.
      eval::RpeOptions one_metre;
      one_metre.delta = 1.0;
      one_metre.unit = eval::DeltaUnit::kMeters;
      const auto rpe = eval::compute_rpe(r.gt, r.est, one_metre);
      m["rpe_1m_trans_m"] = eval::compute_statistics(rpe.trans_m).rmse;
      m["rpe_1m_rot_deg"] = eval::compute_statistics(rpe.rot_deg).rmse;
    } catch (const InputError&) {
      // A path shorter than 1 m has no 1 m pair: the metric stays null.
    }
    if (dataset.format() == io::DatasetFormat::kKitti) measure_kitti_devkit(*dataset.ground_truth(), folder, m);
  } catch (const InputError& e) {
    m["error"] = e.what();
  }
  return m;
}

json summarize_runs(const json& results, const std::vector<BenchDataset>& datasets, const std::vector<BenchRow>& rows) {
  json summary = json::object();
  for (const auto& d : datasets) {
    json per_row = json::object();
    for (const auto& row : rows) {
      json s = json::object();
      int failed = 0, done = 0;
      for (const auto& k : bench_metrics()) {
        std::vector<double> v;
        for (const auto& r : results) {
          if (r["dataset"] != d.name || r["row"] != row.name) continue;
          if (r["exit_code"] != 0) continue;
          const auto& x = r["metrics"][k.key];
          if (x.is_number()) v.push_back(x.get<double>());
        }
        if (v.empty()) {
          s[k.key] = nullptr;
          continue;
        }
        std::sort(v.begin(), v.end());
        s[k.key] = {{"median", percentile(v, 0.5)}, {"min", v.front()}, {"max", v.back()}, {"n", v.size()}};
      }
      for (const auto& r : results) {
        if (r["dataset"] != d.name || r["row"] != row.name) continue;
        ++done;
        if (r["exit_code"] != 0) ++failed;
      }
      s["runs"] = done;
      s["failed_runs"] = failed;
      per_row[row.name] = s;
    }
    auto median_of = [&](const std::string& row, const char* key) -> json {
      if (!per_row.contains(row) || !per_row[row][key].is_object()) return nullptr;
      return per_row[row][key]["median"];
    };
    for (const auto& row : rows) {
      json& s = per_row[row.name];
      if (!row.anchor && row.name != "full" && per_row.contains("full")) {
        s["ratio_to_full"] = {{"ate_m", ratio(median_of(row.name, "ate_m"), median_of("full", "ate_m"))},
                              {"tracking_ms_median", ratio(median_of(row.name, "tracking_ms_median"),
                                                           median_of("full", "tracking_ms_median"))}};
      }
      if (row.name == "stereo-inertial" && per_row.contains("stereo")) {
        s["ratio_to_stereo"] = {{"ate_m", ratio(median_of(row.name, "ate_m"), median_of("stereo", "ate_m"))},
                                {"tracking_ms_median", ratio(median_of(row.name, "tracking_ms_median"),
                                                             median_of("stereo", "tracking_ms_median"))}};
      }
      if (!row.anchor) {
        // Against the anchor with the same loop-closing setting.
        for (const auto& a : rows) {
          if (!a.anchor || a.loop_closing != row.loop_closing) continue;
          s["ratio_to_anchor"] = {{"anchor", a.name},
                                  {"ate_m", ratio(median_of(row.name, "ate_m"), median_of(a.name, "ate_m"))},
                                  {"tracking_ms_median", ratio(median_of(row.name, "tracking_ms_median"),
                                                               median_of(a.name, "tracking_ms_median"))}};
        }
      }
    }
    summary[d.name] = per_row;
  }
  return summary;
}

namespace {

std::string cell(const json& s, const MetricInfo& k) {
  if (!s.is_object() || !s.contains(k.key) || !s[k.key].is_object()) return "–";
  const auto& v = s[k.key];
  const double med = v["median"].get<double>(), lo = v["min"].get<double>(), hi = v["max"].get<double>();
  const bool share = std::string(k.key) == "tracked_share" || std::string(k.key) == "imu_share";
  const double f = share ? 100.0 : 1.0;
  const int dec = share ? 1 : k.decimals;
  if (v["n"].get<int>() == 1 || lo == hi) return fmt::format("{:.{}f}", med * f, dec);
  return fmt::format("{:.{}f} ({:.{}f}–{:.{}f})", med * f, dec, lo * f, dec, hi * f, dec);
}

std::string ratio_cell(const json& s, const char* which, const char* key) {
  if (!s.contains(which) || !s[which][key].is_number() || s[which][key].get<double>() <= 0) return "–";
  return fmt::format("{:.3g}", s[which][key].get<double>());
}

using Column = std::pair<std::string, std::function<std::string(const json&)>>;

// One markdown table: a line per row of the report, the metrics [first, last), then `extra`.
std::string table(const json& report, const json& per_row, const std::vector<MetricInfo>& metrics,
                  const std::vector<Column>& extra) {
  std::string head = "| configuration |", rule = "|---|";
  for (const auto& k : metrics) {
    head += fmt::format(" {} |", k.label);
    rule += "---|";
  }
  for (const auto& [label, value] : extra) {
    head += fmt::format(" {} |", label);
    rule += "---|";
  }
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on chains of "literal" + string.
  std::string md = head;
  md.append("\n").append(rule).append("\n");
  for (const auto& row : report["rows"]) {
    const std::string r = row["name"].get<std::string>();
    const json& s = per_row[r];
    md.append("| ").append(r).append(" |");
    for (const auto& k : metrics) md.append(" ").append(cell(s, k)).append(" |");
    for (const auto& [label, value] : extra) md.append(" ").append(value(s)).append(" |");
    md.append("\n");
  }
  return md;
}

// The published figures of a sequence, under the measured ones (published_comparison's json).
std::string published_table(const json& p, const json& report) {
  std::string md = "Published, on the whole sequence (" + std::to_string(p["frames_published"].get<long>()) + " frames)";
  md += p["full_sequence"].get<bool>() ? ":\n\n" : "; this dataset is an excerpt, so no row is compared with them:\n\n";
  md += "| published | mode | ATE m | KITTI t_rel % | KITTI r_rel deg/100 m | RPE trans m | RPE rot rad | source | beaten by |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  const auto& sources = report.contains("published_sources") ? report["published_sources"] : json::object();
  for (const auto& r : p["rows"]) {
    std::string line = "| " + r["system"].get<std::string>() + " (published) | " + r["mode"].get<std::string>() + " |";
    for (const char* k : {"ate_m", "kitti_t_rel_percent", "kitti_r_rel_deg_per_100m", "rpe_trans_m", "rpe_rot_rad"}) {
      const json& v = r["values"].contains(k) ? r["values"][k] : json();
      line += v.is_number() ? fmt::format(" {:g} |", v.get<double>()) : v.is_null() && r["values"].contains(k) ? " lost |" : " – |";
    }
    const std::string src = r["source"].get<std::string>();
    std::string cite = sources.contains(src) ? sources[src].value("short", src) : src;
    for (const auto& t : r["tables"]) cite.append(", ").append(t.get<std::string>());
    if (!r["verified"].get<bool>()) cite += " (not checked against the paper's text)";
    line += " " + cite + " |";
    std::string by;
    for (const auto& b : r["beaten_by"]) by.append(by.empty() ? "**" : ", **").append(b.get<std::string>()).append("**");
    line += " " + (by.empty() ? std::string("–") : by) + " |\n";
    md += line;
  }
  return md + "\n";
}

}  // namespace

std::string format_report_markdown(const json& report) {
  std::string md = "# plslam bench slam\n\n";
  md += fmt::format("`{}`\n\n", report.value("command", std::string("plslam bench slam")));
  md += fmt::format("{} · plslam {} · {} runs per row, {} mode · {} hardware threads · wall {:.0f} s{}\n\n",
                    report.value("date", std::string("")), report.value("version", std::string("")),
                    report.value("runs", 0), report.value("mode", std::string("")), report.value("hardware_threads", 0),
                    report.value("wall_s", 0.0),
                    report["interrupted_by"].is_string()
                        ? " · **interrupted by " + report["interrupted_by"].get<std::string>() + "**: partial"
                        : std::string());
  md += "Cells: median (min–max) over the runs. ATE: SE(3)-aligned RMSE of the translation; RPE with evo's "
        "definitions (consecutive pairs 1 frame or 1 m of path apart). Ratios are of medians.\n\n";
  const bool mixed_hosts =
      report.contains("timing") && report["timing"].is_object() && !report["timing"].value("comparable", true);
  if (mixed_hosts) {
    md += "**Timings are not comparable**: the runs came from " + report["timing"]["hosts"].dump() +
          " (tracking ms, their ratios and Table I mix machines).\n\n";
  }
  if (report.contains("missing_runs") && !report["missing_runs"].empty()) {
    md += fmt::format("**{} planned runs are missing**:", report["missing_runs"].size());
    for (const auto& m : report["missing_runs"]) md.append(" `").append(m.get<std::string>()).append("`");
    md += "\n\n";
  }
  if (report.contains("missing_sequences") && !report["missing_sequences"].empty()) {
    md += "Standard sequences not found under the roots given:\n\n";
    for (const auto& m : report["missing_sequences"]) md.append("- ").append(m.get<std::string>()).append("\n");
    md += "\n";
  }
  md += "Configurations:\n\n";
  for (const auto& c : report["configurations"]) {
    md += fmt::format("- `{}`: {}\n", c["name"].get<std::string>(), c["description"].get<std::string>());
  }
  md += "\n";
  for (const auto& d : report["datasets"]) {
    const std::string name = d["name"].get<std::string>();
    md += fmt::format("## {}\n\n`{}`, {} frames{}\n\n", name, d["path"].get<std::string>(), d.value("frames", 0),
                      d["gt_length_m"].is_number() ? fmt::format(", ground truth {:.2f} m", d["gt_length_m"].get<double>())
                                                   : std::string());
    if (d.contains("convention") && d["convention"].is_string()) {
      md += "Evaluation: " + d["convention"].get<std::string>() + ".\n\n";
    }
    const json& per_row = report["summary"][name];
    const auto& metrics = bench_metrics();
    // Accuracy (the KITTI devkit's columns on KITTI input only), then the system's behaviour and cost.
    std::vector<MetricInfo> accuracy;
    for (std::size_t k = 0; k < kAccuracyMetrics; ++k) {
      if (std::string_view(metrics[k].key).substr(0, 6) != "kitti_" || d.value("format", std::string()) == "kitti") {
        accuracy.push_back(metrics[k]);
      }
    }
    md += table(report, per_row, accuracy,
                {{"ATE / full", [](const json& s) { return ratio_cell(s, "ratio_to_full", "ate_m"); }},
                 {"ATE / anchor", [](const json& s) { return ratio_cell(s, "ratio_to_anchor", "ate_m"); }}});
    md += "\n";
    if (d.contains("published") && d["published"].is_object()) md += published_table(d["published"], report);
    if (mixed_hosts) {
      md += "Timing (track ms and its ratios) not comparable: these runs came from several hosts.\n\n";
    }
    md += table(report, per_row, {metrics.begin() + kAccuracyMetrics, metrics.end()},
                {{"ms / full", [](const json& s) { return ratio_cell(s, "ratio_to_full", "tracking_ms_median"); }},
                 {"ms / anchor", [](const json& s) { return ratio_cell(s, "ratio_to_anchor", "tracking_ms_median"); }},
                 {"failed runs", [](const json& s) {
                    return fmt::format("{}/{}", s.value("failed_runs", 0), s.value("runs", 0));
                  }}});
    md += "\n";
    if (per_row.contains("stereo-inertial") && per_row["stereo-inertial"].contains("ratio_to_stereo")) {
      const json& si = per_row["stereo-inertial"];
      const json& st = per_row["stereo"];
      auto metric = [&](std::string_view key) {
        return *std::find_if(metrics.begin(), metrics.end(), [&](const MetricInfo& k) { return k.key == key; });
      };
      const MetricInfo ate = metric("ate_m"), ms = metric("tracking_ms_median"), imu = metric("imu_share");
      md += "Stereo-inertial against stereo: ATE " + cell(si, ate) + " m against " + cell(st, ate) + " m (" +
            ratio_cell(si, "ratio_to_stereo", "ate_m") + "x), tracking " + cell(si, ms) + " ms against " + cell(st, ms) +
            " ms (" + ratio_cell(si, "ratio_to_stereo", "tracking_ms_median") + "x); the IMU helped to track " +
            cell(si, imu) + " % of the frames.\n\n";
    }
    if (report.contains("figures") && report["figures"].contains(name)) {
      for (const auto& f : report["figures"][name]) md += fmt::format("![{0}]({0})\n", f.get<std::string>());
      md += "\n";
    }
  }
  if (report.contains("table1") && !report["table1"].empty()) {
    md += "## Table I: keypoint distribution (one thread, left image, same FAST candidates)\n\n";
    md += "| dataset | frames | SSC ms | quadtree ms | SSC speed-up |\n|---|---|---|---|---|\n";
    for (const auto& d : report["datasets"]) {
      const std::string name = d["name"].get<std::string>();
      if (!report["table1"].contains(name)) continue;
      const json& t = report["table1"][name];
      md += fmt::format("| {} | {} | {:.3f} | {:.3f} | {:.1f}x |\n", name, t.value("frames", 0), t.value("ssc_ms", 0.0),
                        t.value("quadtree_ms", 0.0), t.value("ssc_speedup", 0.0));
    }
    md += "\n";
  }
  if (report.contains("figures") && report["figures"].contains("all")) {
    for (const auto& f : report["figures"]["all"]) md += fmt::format("![{0}]({0})\n", f.get<std::string>());
    md += "\n";
  }
  return md;
}

}  // namespace plslam::bench
