#include "plslam/bench/bench_plan.h"

#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/io/atomic_file.h"

namespace plslam::bench {
namespace fs = std::filesystem;
using nlohmann::json;

json matrix_json(const BenchMatrix& m) {
  json j;
  j["runs"] = m.runs;
  j["mode"] = m.mode;
  j["run_flag"] = m.run_flag;
  j["anchor"] = m.anchor;
  j["preset"] = m.preset;
  j["configurations"] = json::array();
  for (const auto& c : m.configs) {
    j["configurations"].push_back({{"name", c.name}, {"description", c.description}, {"overrides", c.yaml}});
  }
  j["rows"] = json::array();
  for (const auto& r : m.rows) j["rows"].push_back({{"name", r.name}, {"anchor", r.anchor}, {"loop_closing", r.loop_closing}});
  j["datasets"] = json::array();
  for (const auto& d : m.datasets) {
    j["datasets"].push_back({{"name", d.name}, {"path", d.path.string()}, {"calibration", d.calibration.string()},
                             {"sequence_id", d.sequence_id}});
  }
  j["missing_sequences"] = m.missing_sequences;
  return j;
}

BenchMatrix parse_bench_plan(const std::string& text, const std::string& src) {
  BenchMatrix m;
  try {
    const json plan = json::parse(text);
    if (!plan.is_object() || plan.value("plslam_bench_plan", 0) != 1) {
      throw InputError(src, "not a plan of plslam bench slam (no \"plslam_bench_plan\": 1)");
    }
    const json& j = plan.at("matrix");
    m.runs = j.at("runs").get<int>();
    m.mode = j.at("mode").get<std::string>();
    m.run_flag = j.at("run_flag").get<std::string>();
    m.anchor = j.at("anchor").get<std::string>();
    m.preset = j.at("preset").get<std::string>();
    for (const auto& c : j.at("configurations")) {
      m.configs.push_back({c.at("name").get<std::string>(), c.at("description").get<std::string>(),
                           c.at("overrides").get<std::string>()});
    }
    for (const auto& r : j.at("rows")) {
      BenchRow row{r.at("name").get<std::string>(), r.at("anchor").get<bool>(), r.at("loop_closing").get<bool>(), {}};
      for (const auto& c : m.configs) {
        if (c.name == row.name) row.config = c;
      }
      m.rows.push_back(row);
    }
    for (const auto& d : j.at("datasets")) {
      m.datasets.push_back({d.at("name").get<std::string>(), d.at("path").get<std::string>(),
                            d.at("calibration").get<std::string>(), d.at("sequence_id").get<std::string>()});
    }
    m.missing_sequences = j.at("missing_sequences").get<std::vector<std::string>>();
  } catch (const json::exception& e) {
    throw InputError(src, std::string("not a plan of plslam bench slam: ") + e.what());
  }
  if (m.runs < 1 || m.runs > 100) throw InputError(src, "matrix.runs: expected 1-100");
  if (m.rows.empty() || m.datasets.empty()) throw InputError(src, "a plan without rows or datasets");
  // Row and dataset names become folders: nothing that could leave the run folder.
  for (const auto& r : m.rows) {
    if (!valid_configuration_name(r.name)) throw InputError(src, "matrix.rows: '" + r.name + "' is no folder name");
  }
  for (const auto& d : m.datasets) {
    if (d.name.empty() || d.name == "." || d.name == ".." || d.name.find_first_of(std::string("/\0", 2)) != std::string::npos) {
      throw InputError(src, "matrix.datasets: '" + d.name + "' is no folder name");
    }
  }
  return m;
}

std::string shell_quote(const std::string& word) {
  std::string out = "'";
  for (char c : word) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

fs::path run_exit_file(const fs::path& run_folder) {
  return run_folder.parent_path() / (run_folder.filename().string() + ".exit");
}

fs::path run_log_file(const fs::path& run_folder) {
  return run_folder.parent_path() / (run_folder.filename().string() + ".log");
}

std::optional<RunExit> read_run_exit(const fs::path& run_folder) {
  std::ifstream in(run_exit_file(run_folder));
  RunExit e;
  if (!(in >> e.code >> e.host)) return std::nullopt;
  return e;
}

void write_run_exit(const fs::path& run_folder, const RunExit& e) {
  io::write_file_atomically(run_exit_file(run_folder), [&](std::ostream& o) { o << e.code << " " << e.host << "\n"; });
}

std::string plan_line(const std::vector<std::string>& argv, const fs::path& run_folder) {
  std::string cmd;
  for (const auto& a : argv) {
    if (!cmd.empty()) cmd.push_back(' ');
    cmd.append(shell_quote(a));
  }
  // The exit file is written to a temporary name and renamed: a run cut off leaves none.
  const std::string exit_file = shell_quote(run_exit_file(run_folder).string());
  return fmt::format("mkdir -p {} && {{ {} > {} 2>&1; rc=$?; echo \"$rc $(hostname)\" > {}.tmp && mv {}.tmp {}; exit $rc; }}",
                     shell_quote(run_folder.parent_path().string()), cmd, shell_quote(run_log_file(run_folder).string()),
                     exit_file, exit_file, exit_file);
}

std::string slurm_array_script(const fs::path& plan_file, std::size_t lines, const fs::path& log_dir) {
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# plslam bench slam: one line of the plan per task of a Slurm job array. Submit with\n"
    << "#   sbatch " << plan_file.string() << ".sbatch\n"
    << "# (add --array=1-" << lines << "%K to run at most K at once). Every node must reach plslam, the datasets\n"
    << "# and the output folder under the same paths (a shared file system). One run per node keeps its\n"
    << "# timing clean: --exclusive, or --cpus-per-task as the nodes' cores.\n"
    << "#SBATCH --job-name=plslam-bench\n"
    << "#SBATCH --array=1-" << lines << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --output=" << (log_dir / "slurm-%A_%a.out").string() << "\n"
    << "set -euo pipefail\n"
    << "plan=" << shell_quote(plan_file.string()) << "\n"
    << "task=\"${SLURM_ARRAY_TASK_ID:?not set: this script is one task of a Slurm job array}\"\n"
    << "line=$(sed -n \"${task}p\" \"$plan\")\n"
    << "if [ -z \"$line\" ]; then echo \"plslam: $plan has no line $task\" >&2; exit 2; fi\n"
    << "exec bash -c \"$line\"\n";
  return s.str();
}

}  // namespace plslam::bench
