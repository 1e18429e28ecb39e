#include "bench_slam_command.h"

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <optional>
#include <set>
#include <iostream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "json_stdout.h"
#include "plslam/bench/bench_plan.h"
#include "plslam/bench/dataset_suites.h"
#include "plslam/bench/point_benchmark.h"
#include "plslam/bench/published_results.h"
#include "plslam/bench/slam_bench.h"
#include "plslam/bench/slam_figures.h"
#include "plslam/core/build_id.h"
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
  sub.add_option("--euroc-root", a.euroc_root,
                 "Folder holding EuRoC's sequences by their official names (MH_01_easy/mav0 ..., or the download "
                 "site's machine_hall/, vicon_room1/, vicon_room2/): every one present is run, the missing are named");
  sub.add_option("--kitti-root", a.kitti_root, "KITTI odometry's dataset folder: sequences/00-10 with poses/NN.txt");
  sub.add_option("--tumvi-root", a.tumvi_root,
                 "Folder holding TUM-VI's dataset-room1_512_16 ... room6 (mav0 with mocap0; dso/camchain.yaml "
                 "when mav0 has no sensor.yaml)");
  sub.add_option("--plan", a.plan,
                 "Write the run matrix as one shell command per line to FILE, and FILE.sbatch (a Slurm job array "
                 "over its lines), instead of running it: for GNU parallel or Slurm; then --report-from");
  sub.add_option("--report-from", a.report_from,
                 "Build the report from the runs under these folders (each: an --out of a plan or a bench, or a "
                 "copy of its runs/), checked against the plan.json found there")
      ->expected(1, -1);
  sub.add_flag("--resume", a.resume, "Keep the runs of --out already complete (exit file 0), run the rest");
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

std::vector<std::string> job_argv(const bench::BenchRow& row, const bench::BenchDataset& d, const fs::path& folder,
                                  const fs::path& out, const std::string& anchor, const std::string& run_flag) {
  if (row.anchor) {
    std::vector<std::string> argv = {anchor, d.path.string(), "--out", folder.string()};
    if (!row.loop_closing) argv.push_back("--no-loop-closing");
    return argv;
  }
  std::vector<std::string> argv = {current_executable().string(), "run", d.path.string(), "--out", folder.string(),
                                   "--quiet", "--config", (out / "configs" / (row.name + ".yaml")).string()};
  if (!d.calibration.empty()) {
    argv.push_back("--calib");
    argv.push_back(d.calibration.string());
  }
  if (!run_flag.empty()) argv.push_back(run_flag);
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
  if (!a.euroc_root.empty()) c += " --euroc-root " + arg(a.euroc_root);
  if (!a.kitti_root.empty()) c += " --kitti-root " + arg(a.kitti_root);
  if (!a.tumvi_root.empty()) c += " --tumvi-root " + arg(a.tumvi_root);
  if (!a.plan.empty()) c += " --plan " + arg(a.plan);
  for (const auto& d : a.report_from) c += " --report-from " + arg(d);
  if (a.resume) c += " --resume";
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

// The matrix from the command line: configurations (checked), rows, and the datasets of the
// preset, the suites' roots and the arguments, each opened once to check its ground truth.
bench::BenchMatrix build_matrix(const BenchSlamArgs& a, const fs::path& out) {
  bench::BenchMatrix m;
  auto available = bench::builtin_slam_configurations();
  if (!a.config_file.empty()) {
    for (auto& c : bench::load_slam_configurations(a.config_file)) {
      for (const auto& b : available) {
        if (b.name == c.name) throw InputError(a.config_file, "configs." + c.name + ": a built-in configuration has this name");
      }
      available.push_back(std::move(c));
    }
  }
  m.configs = bench::select_slam_configurations(a.configs, available);
  if (!a.anchor.empty() && !fs::exists(a.anchor)) throw InputError(a.anchor, "--anchor: no such runner");
  m.anchor = a.anchor.empty() ? std::string() : fs::absolute(a.anchor).string();
  m.rows = bench::bench_rows(m.configs, a.anchor.empty() ? "" : "anchor");
  m.runs = a.runs;
  m.mode = a.mode.name();
  m.run_flag = a.mode.run_flag();
  m.preset = a.preset;

  auto opt_root = [](const std::string& s) { return s.empty() ? std::nullopt : std::optional<fs::path>(s); };
  const auto suites = bench::discover_suites(opt_root(a.euroc_root), opt_root(a.kitti_root), opt_root(a.tumvi_root));
  m.missing_sequences = suites.missing;
  const bool any_root = !a.euroc_root.empty() || !a.kitti_root.empty() || !a.tumvi_root.empty();
  if (any_root) {
    spdlog::info("suites: {} standard sequences found, {} missing", suites.found.size(), suites.missing.size());
    for (const auto& miss : suites.missing) spdlog::warn("missing: {}", miss);
    if (suites.found.empty()) throw InputError("", "no standard sequence under the roots given (see the missing above)");
  }

  // Datasets: the preset's (rendered ones first), the suites', then the user's.
  std::vector<fs::path> paths;
  std::vector<std::string> names, ids;
  std::vector<fs::path> calibs;
  auto add = [&](const fs::path& p, const std::string& name, const std::string& id, const fs::path& calib) {
    paths.push_back(p);
    names.push_back(name);
    ids.push_back(id);
    calibs.push_back(calib);
  };
  for (const auto& r : preset_renders(a.preset)) {
    auto p = render(out, r);
    if (app::stop_requested()) return m;
    add(p, r.name, "", {});
  }
  if (a.preset == "paper") {
    for (auto& p : paper_real_sequences(a.shared)) add(p, "", bench::standard_sequence_id(p), {});
  }
  for (const auto& s : suites.found) add(s.path, s.name, s.id, s.calibration);
  for (const auto& d : a.datasets) add(d, "", bench::standard_sequence_id(d), {});
  if (paths.empty()) throw InputError("", "no dataset: give sequences, --preset quick|paper or a suite's root");
  m.datasets = bench::name_datasets(paths, names);
  for (std::size_t i = 0; i < m.datasets.size(); ++i) {
    m.datasets[i].path = fs::absolute(m.datasets[i].path).lexically_normal();
    m.datasets[i].sequence_id = ids[i];
    m.datasets[i].calibration = calibs[i];
  }
  return m;
}

std::vector<std::unique_ptr<io::Dataset>> open_datasets(const bench::BenchMatrix& m) {
  std::vector<std::unique_ptr<io::Dataset>> opened;
  for (const auto& d : m.datasets) {
    io::DatasetOptions o;
    o.calibration = d.calibration;
    opened.push_back(io::open_dataset(d.path, o));
    if (!opened.back()->ground_truth()) throw InputError(d.path.string(), "no ground truth: the bench scores every run");
  }
  return opened;
}

void write_configs(const bench::BenchMatrix& m, const fs::path& out) {
  for (const auto& c : m.configs) {
    io::write_file_atomically(out / "configs" / (c.name + ".yaml"), [&](std::ostream& o) {
      o << "# plslam bench slam configuration " << c.name << ": " << c.description << "\n" << c.yaml;
    });
  }
}

// plan.json in `out`: written when absent; when present it must hold the same matrix (a bench
// resumed, a plan written again), so that runs of two matrices never mix in one folder.
void check_or_write_plan(const bench::BenchMatrix& m, const fs::path& out) {
  const fs::path file = out / "plan.json";
  const json matrix = bench::matrix_json(m);
  if (fs::exists(file)) {
    const json old = bench::read_json_file(file);
    if (!old.contains("matrix") || old["matrix"] != matrix) {
      throw InputError(file.string(), "holds another matrix (datasets, configurations, runs or mode differ); "
                                      "choose another --out");
    }
    return;
  }
  const json plan = {{"plslam_bench_plan", 1}, {"version", kVersion}, {"build_id", build_id()}, {"matrix", matrix}};
  io::write_file_atomically(file, [&](std::ostream& o) { o << plan.dump(2) << "\n"; });
}

bool run_complete(const fs::path& folder) {
  const auto e = bench::read_run_exit(folder);
  return e && e->code == 0 && fs::exists(folder / "stats.json");
}

std::string job_name(const bench::BenchDataset& d, const bench::BenchRow& r, int run) {
  return fmt::format("{}/{}/run-{}", d.name, r.name, run);
}

json result_entry(const bench::BenchDataset& d, const bench::BenchRow& row, int run, int rc, const fs::path& folder,
                  const fs::path& base, json wall, json metrics) {
  auto rel = [&](const fs::path& p) { return base.empty() ? p.string() : fs::relative(p, base).string(); };
  return {{"dataset", d.name}, {"row", row.name}, {"run", run}, {"exit_code", rc}, {"folder", rel(folder)},
          {"log", rel(bench::run_log_file(folder))}, {"wall_s", wall}, {"metrics", metrics}};
}

// Exit code and message for runs that failed (the report marks them and names their logs).
int runs_failed(long failed, std::size_t runs) {
  std::cerr << fmt::format("plslam: error: {} of {} runs failed; report.md marks them and names their logs\n", failed,
                           runs);
  return kExitRunsFailed;
}

// Writes report.json and report.md (and the figures) into `out`; prints the summary or the JSON.
void write_report(const BenchSlamArgs& a, const bench::BenchMatrix& m, const std::vector<std::unique_ptr<io::Dataset>>& opened,
                  const json& results, const json& table1, const json& extra, const fs::path& out,
                  std::chrono::steady_clock::time_point start) {
  json report;
  report["command"] = command_line(a);
  report["version"] = kVersion;
  report["build_id"] = build_id();
  report["date"] = now_utc();
  report["hardware_threads"] = std::thread::hardware_concurrency();
  report["runs"] = m.runs;
  report["mode"] = m.mode;
  report["preset"] = m.preset.empty() ? json(nullptr) : json(m.preset);
  report["anchor"] = m.anchor.empty() ? json(nullptr) : json(m.anchor);
  report["configurations"] = json::array();
  for (const auto& c : m.configs) report["configurations"].push_back({{"name", c.name}, {"description", c.description}, {"overrides", c.yaml}});
  if (!m.anchor.empty()) {
    report["configurations"].push_back({{"name", "anchor"}, {"description", "the anchor " + m.anchor + ", its defaults"}, {"overrides", ""}});
    for (const auto& r : m.rows) {
      if (r.anchor && !r.loop_closing) {
        report["configurations"].push_back({{"name", r.name}, {"description", "the anchor with --no-loop-closing"}, {"overrides", ""}});
      }
    }
  }
  report["rows"] = json::array();
  for (const auto& r : m.rows) report["rows"].push_back({{"name", r.name}, {"anchor", r.anchor}});
  report["results"] = results;
  report["failed_runs"] = std::count_if(results.begin(), results.end(), [](const json& r) { return r["exit_code"] != 0; });
  report["summary"] = bench::summarize_runs(results, m.datasets, m.rows);
  report["table1"] = table1;
  report["missing_sequences"] = m.missing_sequences;
  for (const auto& [k, v] : extra.items()) report[k] = v;

  // The datasets with their evaluation convention and the published figures of their sequence.
  std::optional<bench::PublishedResults> published;
  try {
    published = bench::load_published_results(bench::default_published_results_file());
  } catch (const InputError& e) {
    spdlog::warn("published figures left out: {}", e.what());
  }
  std::vector<std::string> plslam_rows;
  for (const auto& r : m.rows) {
    if (!r.anchor) plslam_rows.push_back(r.name);
  }
  report["datasets"] = json::array();
  report["published_sources"] = json::object();
  for (std::size_t i = 0; i < m.datasets.size(); ++i) {
    const auto& d = m.datasets[i];
    const bool kitti = opened[i]->format() == io::DatasetFormat::kKitti;
    const auto suite = kitti ? bench::Suite::kKitti : d.sequence_id.rfind("tumvi/", 0) == 0 ? bench::Suite::kTumvi : bench::Suite::kEuroc;
    json pub = published && !d.sequence_id.empty()
                   ? bench::published_comparison(*published, d.sequence_id, opened[i]->size(), report["summary"][d.name], plslam_rows)
                   : json(nullptr);
    if (pub.is_object()) {
      for (const auto& r : pub["rows"]) {
        const auto& src = published->sources.at(r["source"].get<std::string>());
        report["published_sources"][r["source"].get<std::string>()] = {
            {"short", src.cite}, {"authors", src.authors}, {"title", src.title}, {"venue", src.venue}, {"url", src.url}};
      }
    }
    report["datasets"].push_back({{"name", d.name}, {"path", d.path.string()}, {"frames", opened[i]->size()},
                                  {"gt_length_m", opened[i]->ground_truth_length()}, {"format", kitti ? "kitti" : "euroc"},
                                  {"sequence_id", d.sequence_id.empty() ? json(nullptr) : json(d.sequence_id)},
                                  {"convention", bench::suite_convention(suite)}, {"published", pub}});
  }

  // Figures from each row's median-ATE run.
  json figures = json::object();
  const fs::path fig_dir = out / "figures";
  for (std::size_t i = 0; i < m.datasets.size(); ++i) {
    std::vector<bench::FigureRun> fr;
    for (const auto& row : m.rows) {
      const auto r = median_run(results, m.datasets[i].name, row.name);
      if (!r) continue;
      bench::FigureRun f;
      f.row = row.name;
      const fs::path folder = out / (*r)["folder"].get<std::string>();  // absolute for collected runs
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
    for (const auto& n : bench::write_dataset_figures(fig_dir, m.datasets[i].name, *opened[i]->ground_truth(), fr)) {
      names.push_back("figures/" + n);
    }
    figures[m.datasets[i].name] = names;
  }
  if (!results.empty()) {
    figures["all"] = json::array({"figures/" + bench::write_keyframe_bars(fig_dir, report["summary"], m.datasets, m.rows)});
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
    for (const auto& d : m.datasets) {
      std::cout << d.name << ":";
      for (const auto& row : m.rows) {
        const auto& s = report["summary"][d.name][row.name]["ate_m"];
        if (s.is_object()) std::cout << fmt::format("  {} {:.4f}", row.name, s["median"].get<double>());
      }
      std::cout << "  (median ATE, m)\n";
    }
    std::cout << fmt::format("report: {}\n", (out / "report.md").string());
  }
}

// --plan: the matrix's commands into FILE (the runs --resume finds complete left out), and
// FILE.sbatch.
int write_plan(const BenchSlamArgs& a, const bench::BenchMatrix& m, const fs::path& out) {
  const auto jobs = bench::plan_jobs(m.datasets.size(), m.rows.size(), m.runs);
  std::string lines;
  std::size_t count = 0, skipped = 0;
  for (const auto& job : jobs) {
    const auto& d = m.datasets[job.dataset];
    const auto& row = m.rows[job.row];
    const fs::path folder = bench::run_folder(out, d, row, job.run);
    if (a.resume && run_complete(folder)) {
      ++skipped;
      continue;
    }
    lines += bench::plan_line(job_argv(row, d, folder, out, m.anchor, m.run_flag), folder) + "\n";
    ++count;
  }
  const fs::path plan = fs::absolute(a.plan).lexically_normal();
  io::prepare_output_file(plan, "--plan");
  io::write_file_atomically(plan, [&](std::ostream& o) { o << lines; });
  const fs::path sbatch = plan.string() + ".sbatch";
  fs::create_directories(out / "slurm");
  io::write_file_atomically(sbatch, [&](std::ostream& o) { o << bench::slurm_array_script(plan, count, out / "slurm"); });
  fs::permissions(sbatch, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec, fs::perm_options::add);
  if (a.json) {
    print_json(json({{"plan", plan.string()}, {"sbatch", sbatch.string()}, {"runs", count}, {"complete", skipped},
                     {"out", out.string()}}).dump(2) + "\n");
  } else {
    std::cout << fmt::format("plan: {} runs in {} ({} complete left out); Slurm: {}\n", count, plan.string(), skipped,
                             sbatch.string());
    std::cout << fmt::format("run them: parallel --jobs 1 --sshloginfile HOSTS --joblog {0}/joblog < {1}\n"
                             "      or: sbatch {2}\n"
                             "then:     plslam bench slam --report-from {0} --out {0}\n",
                             out.string(), plan.string(), sbatch.string());
  }
  return 0;
}

// --report-from: the plan's runs, each looked for in the folders given (the first holding its
// exit file wins); checked to come from one build; timing comparable only from one host.
int report_from(const BenchSlamArgs& a, const fs::path& out, std::chrono::steady_clock::time_point start) {
  std::vector<fs::path> dirs;
  for (const auto& d : a.report_from) {
    if (!fs::is_directory(d)) throw InputError(d, "--report-from: not a folder");
    dirs.push_back(fs::absolute(d).lexically_normal());
  }
  std::optional<json> plan;
  fs::path plan_file;
  for (const auto& d : dirs) {
    if (!fs::exists(d / "plan.json")) continue;
    json p = bench::read_json_file(d / "plan.json");
    if (!plan) {
      plan = p;
      plan_file = d / "plan.json";
    } else if (p.value("matrix", json()) != plan->value("matrix", json())) {
      throw InputError((d / "plan.json").string(), "another matrix than " + plan_file.string());
    }
  }
  if (!plan) throw InputError(a.report_from.front(), "--report-from: no plan.json in the folders given (the --out of --plan)");
  const bench::BenchMatrix m = bench::parse_bench_plan(plan->dump(), plan_file.string());
  const auto opened = open_datasets(m);
  const std::string plan_build = plan->value("build_id", std::string());

  json results = json::array();
  json missing = json::array();
  std::set<std::string> hosts;
  std::string run_build, run_build_folder;
  for (const auto& job : bench::plan_jobs(m.datasets.size(), m.rows.size(), m.runs)) {
    const auto& d = m.datasets[job.dataset];
    const auto& row = m.rows[job.row];
    std::optional<fs::path> folder;
    std::optional<bench::RunExit> exit;
    for (const auto& dir : dirs) {
      const fs::path f = bench::run_folder(dir, d, row, job.run);
      if ((exit = bench::read_run_exit(f))) {
        folder = f;
        break;
      }
    }
    if (!folder) {
      missing.push_back(job_name(d, row, job.run));
      continue;
    }
    hosts.insert(exit->host);
    if (!row.anchor && fs::exists(*folder / "stats.json")) {
      const json stats = bench::read_json_file(*folder / "stats.json");
      const std::string id = stats.contains("build") ? stats["build"].value("build_id", std::string("unknown")) : "unknown";
      // Against the build that wrote the plan (its lines call that program), else the first run's.
      if (run_build.empty()) {
        run_build = plan_build.empty() ? id : plan_build;
        run_build_folder = plan_build.empty() ? folder->string() : "the plan " + plan_file.string();
      }
      if (id != run_build) {
        throw InputError((*folder / "stats.json").string(), fmt::format("build {} differs from build {} of {}: the runs "
                                                                        "come from different builds of plslam",
                                                                        id, run_build, run_build_folder));
      }
    }
    results.push_back(result_entry(d, row, job.run, exit->code, *folder, {}, nullptr,
                                   bench::measure_run(*opened[job.dataset], *folder, row.anchor)));
  }
  json extra;
  extra["collected_from"] = json::array();
  for (const auto& d : dirs) extra["collected_from"].push_back(d.string());
  extra["missing_runs"] = missing;
  extra["runs_build_id"] = run_build.empty() ? json(nullptr) : json(run_build);
  extra["timing"] = {{"hosts", hosts}, {"comparable", hosts.size() <= 1}};
  fs::create_directories(out);
  write_report(a, m, opened, results, json::object(), extra, out, start);
  const auto failed = std::count_if(results.begin(), results.end(), [](const json& r) { return r["exit_code"] != 0; });
  if (!missing.empty()) {
    std::cerr << fmt::format("plslam: error: {} of {} planned runs are missing (first: {}); report.md names them all\n",
                             missing.size(), missing.size() + results.size(), missing.front().get<std::string>());
    return kExitRunsFailed;
  }
  if (failed > 0) {
    return runs_failed(failed, results.size());
  }
  return 0;
}

}  // namespace

int run_bench_slam(const BenchSlamArgs& a) {
  app::install_stop_signals();
  const auto start = std::chrono::steady_clock::now();
  const fs::path out = fs::absolute(a.out).lexically_normal();
  io::prepare_output_folder(out);
  if (!a.report_from.empty()) {
    if (!a.datasets.empty() || !a.preset.empty() || !a.euroc_root.empty() || !a.kitti_root.empty() ||
        !a.tumvi_root.empty() || !a.plan.empty() || a.resume) {
      throw InputError("", "--report-from takes the matrix from the plan.json it finds: give no datasets, preset, "
                           "roots, --plan or --resume with it");
    }
    return report_from(a, out, start);
  }
  if (fs::exists(out / "runs") && !a.resume && a.plan.empty()) {
    throw InputError(out.string(), "already holds the runs of an earlier bench; choose another --out, or --resume it");
  }

  const bench::BenchMatrix m = build_matrix(a, out);
  if (app::stop_requested()) return app::stop_exit_code();
  const auto opened = open_datasets(m);
  if (a.resume && !fs::exists(out / "plan.json")) throw InputError((out / "plan.json").string(), "--resume: missing");
  check_or_write_plan(m, out);
  write_configs(m, out);
  if (!a.plan.empty()) return write_plan(a, m, out);

  const auto jobs = bench::plan_jobs(m.datasets.size(), m.rows.size(), m.runs);
  std::vector<bool> done(jobs.size(), false);
  std::size_t to_run = jobs.size();
  if (a.resume) {
    for (std::size_t k = 0; k < jobs.size(); ++k) {
      done[k] = run_complete(bench::run_folder(out, m.datasets[jobs[k].dataset], m.rows[jobs[k].row], jobs[k].run));
      to_run -= done[k] ? 1 : 0;
    }
  }
  spdlog::info("bench slam: {} datasets x {} rows x {} runs = {} runs into {}{}", m.datasets.size(), m.rows.size(), m.runs,
               jobs.size(), out.string(), a.resume ? fmt::format(" ({} complete, kept)", jobs.size() - to_run) : "");
  json results = json::array();
  int failed = 0;
  std::size_t ran = 0;
  const std::string host = host_name();
  const auto runs_start = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < jobs.size() && !app::stop_requested(); ++k) {
    const auto& job = jobs[k];
    const auto& d = m.datasets[job.dataset];
    const auto& row = m.rows[job.row];
    const fs::path folder = bench::run_folder(out, d, row, job.run);
    if (done[k]) {
      results.push_back(result_entry(d, row, job.run, 0, folder, out, nullptr, bench::measure_run(*opened[job.dataset], folder, row.anchor)));
      continue;
    }
    const fs::path log = bench::run_log_file(folder);
    std::error_code ec;
    fs::remove_all(folder, ec);  // a run cut off earlier (--resume) starts again
    fs::remove(bench::run_exit_file(folder), ec);
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = run_process(job_argv(row, d, folder, out, m.anchor, m.run_flag), log, [] { return app::stop_requested(); });
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // A run cut off by a signal still wrote its outputs so far: the report shows it (failed), but
    // it leaves no exit file, so --resume runs it again.
    const bool cut_off = app::stop_requested();
    if (!cut_off) bench::write_run_exit(folder, {rc, host});
    json metrics = bench::measure_run(*opened[job.dataset], folder, row.anchor);
    if (rc != 0) ++failed;
    results.push_back(result_entry(d, row, job.run, rc, folder, out, wall, metrics));
    ++ran;
    const json& ate = metrics["ate_m"];
    spdlog::info("[{}/{}] {} {} run {}: {}{}, {:.1f} s, ETA {:.0f} s", k + 1, jobs.size(), d.name, row.name, job.run,
                 ate.is_number() ? fmt::format("ATE {:.4f} m", ate.get<double>()) : std::string("no ATE"),
                 rc == 0 ? std::string() : fmt::format(" (exit {}, see {})", rc, log.string()), wall,
                 eta_seconds(runs_start, ran, to_run));
  }

  // Table I: the keypoint distribution on the same FAST candidates, one thread.
  json table1 = json::object();
  for (std::size_t i = 0; i < m.datasets.size() && a.table1_frames > 0 && !app::stop_requested(); ++i) {
    io::DatasetOptions o;
    o.max_frames = static_cast<std::size_t>(a.table1_frames);
    o.calibration = m.datasets[i].calibration;
    const auto ds = io::open_dataset(m.datasets[i].path, o);
    bench::PointBenchmarkOptions po;
    po.stop = [] { return app::stop_requested(); };
    const json j = bench::run_point_benchmark(*ds, po);
    table1[m.datasets[i].name] = {{"frames", j["frames"]}, {"ssc_ms", j["ssc_ms"]["median"]},
                                  {"quadtree_ms", j["quadtree_ms"]["median"]}, {"ssc_speedup", j["ssc_speedup"]}};
  }
  json extra;
  extra["timing"] = {{"hosts", json::array({host})}, {"comparable", true}};
  write_report(a, m, opened, results, table1, extra, out, start);
  if (app::stop_requested()) {
    spdlog::warn("bench slam: stopped by {} after {} of {} runs; the report covers those (--resume goes on)",
                 app::stop_signal_name(), results.size(), jobs.size());
    return app::stop_exit_code();
  }
  if (failed > 0) {
    return runs_failed(failed, results.size());
  }
  return 0;
}

}  // namespace plslam::cli
