#pragma once
// `bench slam --plan FILE`: the run matrix as shell commands, one (sequence, configuration,
// repetition) per line, for existing engines to spread over machines: GNU parallel (its
// --sshloginfile) or a Slurm job array (the sbatch script written beside the plan picks its line
// by SLURM_ARRAY_TASK_ID). Each line leaves, beside its run folder, run-<n>.log and run-<n>.exit
// ("<exit code> <host>"), which `bench slam --report-from` and `--resume` read.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "plslam/bench/slam_bench.h"

namespace plslam::bench {

// What a bench runs: configurations, rows, datasets and repetitions, as plan.json in its --out
// holds them, so that --report-from and --resume work from the same matrix.
struct BenchMatrix {
  std::vector<SlamConfiguration> configs;
  std::vector<BenchRow> rows;
  std::vector<BenchDataset> datasets;
  std::vector<std::string> missing_sequences;  // standard sequences not found under the roots given
  int runs = 1;
  std::string mode, run_flag, anchor, preset;
};

nlohmann::json matrix_json(const BenchMatrix& m);

// plan.json's text: {"plslam_bench_plan": 1, "version", "build_id", "matrix": matrix_json}. Throws
// InputError (naming `source`) unless it is one, with names fit for folders and 1-100 runs.
BenchMatrix parse_bench_plan(const std::string& text, const std::string& source);

// A word for sh/bash: in single quotes, with a quote inside written as '\''.
std::string shell_quote(const std::string& word);

// run-<n>.exit beside the run folder run-<n>.
std::filesystem::path run_exit_file(const std::filesystem::path& run_folder);
std::filesystem::path run_log_file(const std::filesystem::path& run_folder);

struct RunExit {
  int code = 0;
  std::string host;
};
// The exit file's content; nullopt when it is absent or not "<int> <host>" (a run cut off).
std::optional<RunExit> read_run_exit(const std::filesystem::path& run_folder);
// What the plan's lines write, for runs the bench starts itself (written atomically).
void write_run_exit(const std::filesystem::path& run_folder, const RunExit& e);

// One line of the plan: creates the folder's parent, runs argv with its output into the log, and
// writes the exit file; the line's own status is the run's.
std::string plan_line(const std::vector<std::string>& argv, const std::filesystem::path& run_folder);

// A Slurm array script over the plan's `lines` lines (task ids 1..lines), its output files in
// `log_dir`. Passes `bash -n`; runs one line with SLURM_ARRAY_TASK_ID set by hand too.
std::string slurm_array_script(const std::filesystem::path& plan_file, std::size_t lines,
                               const std::filesystem::path& log_dir);

}  // namespace plslam::bench
