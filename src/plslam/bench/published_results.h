#pragma once
// The published per-sequence figures that `bench slam` prints beside a user's runs (marked
// "published"): ORB-SLAM2 and ORB-SLAM3 stereo and stereo-inertial, and the paper's Tables II-III,
// read from data/published/slam_results.yaml, where every figure names its source.
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace plslam::bench {

struct PublishedSource {
  std::string title, authors, venue, url;
  std::string cite;  // short, for the report's tables: "Mur-Artal & Tardos, T-RO 2017"
};

struct PublishedSequence {
  std::string folder;
  long frames = 0;  // of the whole official sequence
  std::optional<double> length_m;
};

struct PublishedResult {
  std::string system, mode, sequence, metric, source, table, note;
  std::optional<double> value;  // none: the system lost track (an X in the table)
  bool verified = true;
};

struct PublishedResults {
  std::map<std::string, PublishedSource> sources;
  std::map<std::string, PublishedSequence> sequences;  // by id: euroc/MH01, kitti/06
  std::vector<PublishedResult> results;

  // The results of one sequence, in the file's order.
  std::vector<PublishedResult> of(const std::string& sequence) const;
};

// The metrics a published figure may give (bench metric keys where plslam measures the same).
const std::vector<std::string>& published_metrics();

// Parses the file; every result must name a known source and sequence and an allowed metric.
// Throws InputError naming the file and the entry.
PublishedResults parse_published_results(const std::string& text, const std::string& source);
PublishedResults load_published_results(const std::filesystem::path& file);

// The published figures of one sequence beside a bench's summary of it (summary[dataset]):
// {sequence, frames_published, full_sequence, rows: [{system, mode, source, tables, values: {metric:
// value|null}, notes, verified, beaten_by: [bench rows]}]}. Rows are grouped by system, mode and
// source. A bench row beats a published one when its medians are lower on every metric both give
// (ATE and the KITTI devkit's t_rel and r_rel; the paper's RPE columns have no stated delta and are
// not compared), and only on the whole sequence (`dataset_frames` at least 95 % of the published
// count): an excerpt is not compared. Null when the file has no figure of the sequence.
nlohmann::json published_comparison(const PublishedResults& published, const std::string& sequence,
                                    std::size_t dataset_frames, const nlohmann::json& per_row,
                                    const std::vector<std::string>& plslam_rows);

// The file shipped with plslam: the source tree's data/published, else the installed copy.
std::filesystem::path default_published_results_file();

}  // namespace plslam::bench
