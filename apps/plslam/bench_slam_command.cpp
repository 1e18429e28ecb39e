#include "bench_slam_command.h"

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "json_stdout.h"
#include "plslam/bench/point_benchmark.h"
#include "plslam/bench/slam_bench.h"
#include "plslam/bench/slam_figures.h"
#include "plslam/core/error.h"
#include "plslam/core/subprocess.h"
#include "plslam/core/version.h"
#include "plslam/eval/evaluate.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/output_folder.h"
#include "plslam/io/trajectory_io.h"
#include "progress_eta.h"
#include "stop_signals.h"

namespace plslam::cli {
namespace fs = std::filesystem;
using nlohmann::json;

void add_bench_slam_options(CLI::App& sub, BenchSlamArgs& a) {
  sub.add_option("datasets", a.datasets, "Sequences (KITTI sequences/NN or EuRoC folders), added to the preset's");
  sub.add_option("--out", a.out, "Output folder: report.md, report.json, figures/, runs/")->required();
  sub.add_option("--runs", a.runs, "Runs per dataset and configuration")->check(CLI::Range(1, 100))->capture_default_str();
  sub.add_option("--configs", a.configs,
                 "Comma-separated configurations, or all: full, no-lines, quadtree, no-pid, no-kalman, "
                 "no-loop-closing, and those of --config-file")
      ->capture_default_str();
  sub.add_option("--config-file", a.config_file, "YAML file of more configurations: configs: {NAME: {overrides: {...}}}");
  sub.add_option("--anchor", a.anchor,
                 "External runner with the interface of ../shared/anchors/orbslam3/run (run <dataset> --out DIR "
                 "[--no-loop-closing]), added as a row");
  sub.add_option("--preset", a.preset,
                 "quick: a short rendered sequence, every configuration (minutes); paper: every sequence in "
                 "<shared>/data plus rendered office loop, corridor and street loop")
      ->check(CLI::IsMember({"quick", "paper"}));
  sub.add_option("--shared", a.shared, "The shared folder for --preset paper (default: $PLSLAM_SHARED_DIR, else ../shared)");
  sub.add_option("--jobs", a.jobs, "Runs at a time (only 1: parallel runs would distort every timing)")
      ->check(CLI::Range(1, 1))->capture_default_str();
  add_mode_flags(sub, a.mode, "plslam runs with --sequential (anchors unaffected)",
                 "plslam runs in its default deterministic mode (the default)",
                 "plslam runs with --free-running (anchors unaffected)");
  sub.add_option("--table1-frames", a.table1_frames, "Frames per dataset for Table I (keypoint distribution); 0: skip")
      ->check(CLI::Range(0, 100000))->capture_default_str();
  sub.add_flag("--json", a.json, "Print report.json on stdout (logs stay on stderr)");
}

namespace {

struct Rendered {
  std::string name;
  std::vector<std::string> synth_args;
  std::string dataset_subpath;  // inside the rendered folder
};

std::vector<Rendered> preset_renders(const std::string& preset) {
  if (preset == "quick") {
    return {{"office-quick", {"--scene", "office", "--preset", "euroc", "--frames", "60", "--seed", "11"}, ""}};
  }
  if (preset == "paper") {
    return {{"office-loop", {"--scene", "office", "--preset", "euroc", "--frames", "480", "--loop", "--seed", "1"}, ""},
            {"corridor", {"--scene", "corridor", "--preset", "euroc", "--frames", "400", "--seed", "1"}, ""},
            {"street-loop",
             {"--scene", "street", "--preset", "kitti", "--format", "kitti", "--frames", "300", "--loop", "--seed", "2"},
             "sequences/00"}};
  }
  return {};
}

// Renders a preset's sequence once into OUT/data/<name>; a folder that opens as a dataset is reused.
fs::path render(const fs::path& out, const Rendered& r) {
  const fs::path dir = out / "data" / r.name;
  const fs::path dataset = r.dataset_subpath.empty() ? dir : dir / r.dataset_subpath;
  if (fs::exists(dir)) {
    try {
      io::open_dataset(dataset);
      return dataset;
    } catch (const InputError&) {
      spdlog::info("{}: incomplete, rendering again", dir.string());
    }
  }
  spdlog::info("rendering {} (plslam synth {})", dir.string(), fmt::join(r.synth_args, " "));
  std::vector<std::string> argv = {current_executable().string(), "synth", "--out", dir.string(), "--force"};
  argv.insert(argv.end(), r.synth_args.begin(), r.synth_args.end());
  const fs::path log = out / "data" / (r.name + ".log");
  const int rc = run_process(argv, log, [] { return app::stop_requested(); });
  if (app::stop_requested()) return {};
  if (rc != 0) throw InputError(log.string(), fmt::format("plslam synth failed (exit {})", rc));
  return dataset;
}

std::vector<fs::path> paper_real_sequences(const std::string& shared_arg) {
  fs::path shared = shared_arg;
  if (shared.empty()) {
    const char* env = std::getenv("PLSLAM_SHARED_DIR");
    shared = env && *env ? fs::path(env) : fs::path("../shared");
  }
  const fs::path data = shared / "data";
  std::vector<fs::path> out = {data / "kitti/sequences/06", data / "kitti/sequences/01", data / "euroc/V1_01_easy_micro"};
  for (const auto& p : out) {
    if (!fs::exists(p)) throw InputError(p.string(), "missing (--preset paper reads the shared data; set --shared)");
  }
  return out;
}

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", &tm);
  return buf;
}

std::vector<std::string> job_argv(const bench::BenchRow& row, const fs::path& dataset, const fs::path& folder,
                                  const fs::path& out, const BenchSlamArgs& a) {
  if (row.anchor) {
    std::vector<std::string> argv = {a.anchor, dataset.string(), "--out", folder.string()};
    if (!row.loop_closing) argv.push_back("--no-loop-closing");
    return argv;
  }
  std::vector<std::string> argv = {current_executable().string(), "run", dataset.string(), "--out", folder.string(),
                                   "--quiet", "--config", (out / "configs" / (row.name + ".yaml")).string()};
  if (!a.mode.run_flag().empty()) argv.push_back(a.mode.run_flag());
  return argv;
}

// The command as given, to head the report (arguments with spaces quoted).
std::string command_line(const BenchSlamArgs& a) {
  auto arg = [](const std::string& v) { return v.find_first_of(" \t'\"") == std::string::npos ? v : "'" + v + "'"; };
  std::string c = "plslam bench slam";
  for (const auto& d : a.datasets) c += " " + arg(d);
  if (!a.preset.empty()) c += " --preset " + a.preset;
  c += fmt::format(" --runs {}", a.runs);
  if (a.configs != "all") c += " --configs " + arg(a.configs);
  if (!a.config_file.empty()) c += " --config-file " + arg(a.config_file);
  if (!a.anchor.empty()) c += " --anchor " + arg(a.anchor);
  if (!a.shared.empty()) c += " --shared " + arg(a.shared);
  if (a.mode.sequential) c += " --sequential";
  if (a.mode.deterministic) c += " --deterministic";
  if (a.mode.free_running) c += " --free-running";
  if (a.table1_frames != 20) c += fmt::format(" --table1-frames {}", a.table1_frames);
  return c + " --out " + arg(a.out);
}

// The successful run whose ATE is the median of its row (the lower middle for an even count).
std::optional<json> median_run(const json& results, const std::string& dataset, const std::string& row) {
  std::vector<json> ok;
  for (const auto& r : results) {
    if (r["dataset"] == dataset && r["row"] == row && r["exit_code"] == 0 && r["metrics"]["ate_m"].is_number()) {
      ok.push_back(r);
    }
  }
  if (ok.empty()) return std::nullopt;
  std::sort(ok.begin(), ok.end(), [](const json& x, const json& y) {
    return x["metrics"]["ate_m"].get<double>() < y["metrics"]["ate_m"].get<double>();
  });
  return ok[(ok.size() - 1) / 2];
}

}  // namespace

int run_bench_slam(const BenchSlamArgs& a) {
  app::install_stop_signals();
  const auto start = std::chrono::steady_clock::now();
  const fs::path out = a.out;
  io::prepare_output_folder(out);
  if (fs::exists(out / "runs")) {
    throw InputError(out.string(), "already holds the runs of an earlier bench; choose another --out");
  }

  // Configurations and rows, all checked before the first run.
  auto available = bench::builtin_slam_configurations();
  if (!a.config_file.empty()) {
    for (auto& c : bench::load_slam_configurations(a.config_file)) {
      for (const auto& b : available) {
        if (b.name == c.name) throw InputError(a.config_file, "configs." + c.name + ": a built-in configuration has this name");
      }
      available.push_back(std::move(c));
    }
  }
  const auto configs = bench::select_slam_configurations(a.configs, available);
  if (!a.anchor.empty() && !fs::exists(a.anchor)) throw InputError(a.anchor, "--anchor: no such runner");
  const auto rows = bench::bench_rows(configs, a.anchor.empty() ? "" : "anchor");
  for (const auto& c : configs) {
    io::write_file_atomically(out / "configs" / (c.name + ".yaml"), [&](std::ostream& o) {
      o << "# plslam bench slam configuration " << c.name << ": " << c.description << "\n" << c.yaml;
    });
  }

  // Datasets: the preset's (rendered ones first), then the user's.
  std::vector<fs::path> paths;
  std::vector<std::string> names;  // the rendered sequences are named by the preset
  for (const auto& r : preset_renders(a.preset)) {
    auto p = render(out, r);
    if (app::stop_requested()) return app::stop_exit_code();
    paths.push_back(p);
    names.push_back(r.name);
  }
  if (a.preset == "paper") {
    for (auto& p : paper_real_sequences(a.shared)) paths.push_back(p);
  }
  for (const auto& d : a.datasets) paths.emplace_back(d);
  if (paths.empty()) throw InputError("", "no dataset: give sequences or --preset quick|paper");
  const auto datasets = bench::name_datasets(paths, names);
  std::vector<std::unique_ptr<io::Dataset>> opened;
  for (const auto& d : datasets) {
    opened.push_back(io::open_dataset(d.path));
    if (!opened.back()->ground_truth()) throw InputError(d.path.string(), "no ground truth: the bench scores every run");
  }

  const auto jobs = bench::plan_jobs(datasets.size(), rows.size(), a.runs);
  spdlog::info("bench slam: {} datasets x {} rows x {} runs = {} runs into {}", datasets.size(), rows.size(), a.runs,
               jobs.size(), out.string());
  json results = json::array();
  int failed = 0;
  const auto runs_start = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < jobs.size() && !app::stop_requested(); ++k) {
    const auto& job = jobs[k];
    const auto& d = datasets[job.dataset];
    const auto& row = rows[job.row];
    const fs::path folder = bench::run_folder(out, d, row, job.run);
    const fs::path log = folder.parent_path() / fmt::format("run-{}.log", job.run);
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = run_process(job_argv(row, d.path, folder, out, a), log, [] { return app::stop_requested(); });
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    json metrics = bench::measure_run(*opened[job.dataset], folder, row.anchor);
    if (rc != 0) ++failed;
    results.push_back({{"dataset", d.name}, {"row", row.name}, {"run", job.run}, {"exit_code", rc},
                       {"folder", fs::relative(folder, out).string()}, {"log", fs::relative(log, out).string()},
                       {"wall_s", wall}, {"metrics", metrics}});
    const json& ate = metrics["ate_m"];
    spdlog::info("[{}/{}] {} {} run {}: {}{}, {:.1f} s, ETA {:.0f} s", k + 1, jobs.size(), d.name, row.name, job.run,
                 ate.is_number() ? fmt::format("ATE {:.4f} m", ate.get<double>()) : std::string("no ATE"),
                 rc == 0 ? std::string() : fmt::format(" (exit {}, see {})", rc, log.string()), wall,
                 eta_seconds(runs_start, k + 1, jobs.size()));
  }

  // Table I: the keypoint distribution on the same FAST candidates, one thread.
  json table1 = json::object();
  for (std::size_t i = 0; i < datasets.size() && a.table1_frames > 0 && !app::stop_requested(); ++i) {
    io::DatasetOptions o;
    o.max_frames = static_cast<std::size_t>(a.table1_frames);
    const auto ds = io::open_dataset(datasets[i].path, o);
    bench::PointBenchmarkOptions po;
    po.stop = [] { return app::stop_requested(); };
    const json j = bench::run_point_benchmark(*ds, po);
    table1[datasets[i].name] = {{"frames", j["frames"]}, {"ssc_ms", j["ssc_ms"]["median"]},
                                {"quadtree_ms", j["quadtree_ms"]["median"]}, {"ssc_speedup", j["ssc_speedup"]}};
  }

  json report;
  report["command"] = command_line(a);
  report["version"] = kVersion;
  report["date"] = now_utc();
  report["hardware_threads"] = std::thread::hardware_concurrency();
  report["runs"] = a.runs;
  report["mode"] = a.mode.name();
  report["preset"] = a.preset.empty() ? json(nullptr) : json(a.preset);
  report["anchor"] = a.anchor.empty() ? json(nullptr) : json(a.anchor);
  report["configurations"] = json::array();
  for (const auto& c : configs) report["configurations"].push_back({{"name", c.name}, {"description", c.description}, {"overrides", c.yaml}});
  if (!a.anchor.empty()) {
    report["configurations"].push_back({{"name", "anchor"}, {"description", "the anchor " + a.anchor + ", its defaults"}, {"overrides", ""}});
    for (const auto& r : rows) {
      if (r.anchor && !r.loop_closing) {
        report["configurations"].push_back({{"name", r.name}, {"description", "the anchor with --no-loop-closing"}, {"overrides", ""}});
      }
    }
  }
  report["rows"] = json::array();
  for (const auto& r : rows) report["rows"].push_back({{"name", r.name}, {"anchor", r.anchor}});
  report["datasets"] = json::array();
  for (std::size_t i = 0; i < datasets.size(); ++i) {
    report["datasets"].push_back({{"name", datasets[i].name}, {"path", datasets[i].path.string()},
                                  {"frames", opened[i]->size()}, {"gt_length_m", opened[i]->ground_truth_length()}});
  }
  report["results"] = results;
  report["failed_runs"] = failed;
  report["summary"] = bench::summarize_runs(results, datasets, rows);
  report["table1"] = table1;

  // Figures from each row's median-ATE run.
  json figures = json::object();
  const fs::path fig_dir = out / "figures";
  for (std::size_t i = 0; i < datasets.size(); ++i) {
    std::vector<bench::FigureRun> fr;
    for (const auto& row : rows) {
      const auto r = median_run(results, datasets[i].name, row.name);
      if (!r) continue;
      bench::FigureRun f;
      f.row = row.name;
      const fs::path folder = out / (*r)["folder"].get<std::string>();
      try {
        f.estimate = io::read_trajectory(folder / "trajectory.tum", io::TrajectoryFormat::kTum);
        f.result = eval::evaluate(*opened[i]->ground_truth(), f.estimate, eval::EvalOptions{});
      } catch (const InputError& e) {
        spdlog::warn("figures: {}", e.what());
        continue;
      }
      f.frame_ms = bench::read_frame_times(folder);
      fr.push_back(std::move(f));
    }
    if (fr.empty()) continue;
    json names = json::array();
    for (const auto& n : bench::write_dataset_figures(fig_dir, datasets[i].name, *opened[i]->ground_truth(), fr)) {
      names.push_back("figures/" + n);
    }
    figures[datasets[i].name] = names;
  }
  if (!results.empty()) {
    figures["all"] = json::array({"figures/" + bench::write_keyframe_bars(fig_dir, report["summary"], datasets, rows)});
  }
  report["figures"] = figures;
  report["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report["interrupted_by"] = app::stop_requested() ? json(app::stop_signal_name()) : json(nullptr);

  const std::string text = report.dump(2);
  io::write_file_atomically(out / "report.json", [&](std::ostream& o) { o << text << "\n"; });
  const std::string md = bench::format_report_markdown(report);
  io::write_file_atomically(out / "report.md", [&](std::ostream& o) { o << md; });
  if (a.json) {
    print_json(text + "\n");
  } else {
    for (const auto& d : datasets) {
      std::cout << d.name << ":";
      for (const auto& row : rows) {
        const auto& s = report["summary"][d.name][row.name]["ate_m"];
        if (s.is_object()) std::cout << fmt::format("  {} {:.4f}", row.name, s["median"].get<double>());
      }
      std::cout << "  (median ATE, m)\n";
    }
    std::cout << fmt::format("report: {}\n", (out / "report.md").string());
  }
  if (app::stop_requested()) {
    spdlog::warn("bench slam: stopped by {} after {} of {} runs; the report covers those", app::stop_signal_name(),
                 results.size(), jobs.size());
    return app::stop_exit_code();
  }
  if (failed > 0) {
    std::cerr << fmt::format("plslam: error: {} of {} runs failed; report.md marks them and names their logs\n", failed,
                             results.size());
    return kExitRunsFailed;
  }
  return 0;
}

}  // namespace plslam::cli
