#include "plslam/bench/dataset_suites.h"

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::bench {
namespace fs = std::filesystem;

const char* suite_convention(Suite s) {
  switch (s) {
    case Suite::kEuroc:
      return "EuRoC: ATE, RMSE of the translation after SE(3) alignment of the whole trajectory to "
             "state_groundtruth_estimate0 (moved to the left camera), as ORB-SLAM2/3 report stereo";
    case Suite::kKitti:
      return "KITTI: the odometry devkit's t_rel (%) and r_rel (deg/100 m), averaged over all sub-paths of "
             "100-800 m, unaligned; and ATE after SE(3) alignment, as ORB-SLAM2 reports";
    case Suite::kTumvi:
      return "TUM-VI: ATE after SE(3) alignment over the frames mocap0 covers (the rooms: all of them)";
  }
  return "";
}

const std::vector<StandardSequence>& standard_sequences() {
  static const std::vector<StandardSequence> all = [] {
    std::vector<StandardSequence> v = {
        {Suite::kEuroc, "euroc/MH01", "MH_01_easy"},      {Suite::kEuroc, "euroc/MH02", "MH_02_easy"},
        {Suite::kEuroc, "euroc/MH03", "MH_03_medium"},    {Suite::kEuroc, "euroc/MH04", "MH_04_difficult"},
        {Suite::kEuroc, "euroc/MH05", "MH_05_difficult"}, {Suite::kEuroc, "euroc/V101", "V1_01_easy"},
        {Suite::kEuroc, "euroc/V102", "V1_02_medium"},    {Suite::kEuroc, "euroc/V103", "V1_03_difficult"},
        {Suite::kEuroc, "euroc/V201", "V2_01_easy"},      {Suite::kEuroc, "euroc/V202", "V2_02_medium"},
        {Suite::kEuroc, "euroc/V203", "V2_03_difficult"},
    };
    for (int k = 0; k <= 10; ++k) v.push_back({Suite::kKitti, fmt::format("kitti/{:02d}", k), fmt::format("{:02d}", k)});
    for (int k = 1; k <= 6; ++k) {
      v.push_back({Suite::kTumvi, fmt::format("tumvi/room{}", k), fmt::format("dataset-room{}_512_16", k)});
    }
    return v;
  }();
  return all;
}

namespace {

bool is_dir(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}
bool is_file(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

// The folder of an EuRoC sequence: ROOT/<name> or the download site's ROOT/<group>/<name>.
std::optional<fs::path> euroc_folder(const fs::path& root, const std::string& name) {
  const std::string group = name.rfind("MH", 0) == 0 ? "machine_hall" : name.rfind("V1", 0) == 0 ? "vicon_room1" : "vicon_room2";
  for (const fs::path& p : {root / name, root / group / name}) {
    if (is_dir(p / "mav0")) return p;
  }
  return std::nullopt;
}

void find_euroc(const fs::path& root, const StandardSequence& s, SuiteDiscovery& out) {
  const auto dir = euroc_folder(root, s.folder);
  if (!dir) {
    out.missing.push_back(fmt::format("EuRoC {}: no {}/mav0 under {}", s.folder, s.folder, root.string()));
    return;
  }
  const fs::path gt = *dir / "mav0" / "state_groundtruth_estimate0" / "data.csv";
  if (!is_file(gt)) {
    out.missing.push_back(fmt::format("EuRoC {}: no ground truth {}", s.folder, gt.string()));
    return;
  }
  out.found.push_back({s.suite, s.id, s.folder, *dir, gt, {}});
}

void find_kitti(const fs::path& root, const StandardSequence& s, SuiteDiscovery& out) {
  const fs::path seq = root / "sequences" / s.folder;
  if (!is_dir(seq)) {
    out.missing.push_back(fmt::format("KITTI {}: no {}", s.folder, seq.string()));
    return;
  }
  const fs::path gt = root / "poses" / (s.folder + ".txt");
  if (!is_file(gt)) {
    out.missing.push_back(fmt::format("KITTI {}: no ground truth {}", s.folder, gt.string()));
    return;
  }
  out.found.push_back({s.suite, s.id, "kitti-" + s.folder, seq, gt, {}});
}

void find_tumvi(const fs::path& root, const StandardSequence& s, SuiteDiscovery& out) {
  fs::path dir = root / s.folder;
  if (!is_dir(dir / "mav0")) {
    std::string big = s.folder;
    big.replace(big.find("_512_"), 5, "_1024_");
    if (is_dir(root / big / "mav0")) dir = root / big;
  }
  if (!is_dir(dir / "mav0")) {
    out.missing.push_back(fmt::format("TUM-VI {}: no {}/mav0 under {}", s.folder, s.folder, root.string()));
    return;
  }
  const fs::path gt = dir / "mav0" / "mocap0" / "data.csv";
  if (!is_file(gt)) {
    out.missing.push_back(fmt::format("TUM-VI {}: no ground truth {}", s.folder, gt.string()));
    return;
  }
  fs::path calib;
  if (!is_file(dir / "mav0" / "cam0" / "sensor.yaml")) {
    calib = dir / "dso" / "camchain.yaml";
    if (!is_file(calib)) {
      out.missing.push_back(fmt::format("TUM-VI {}: no calibration (mav0/cam0/sensor.yaml or dso/camchain.yaml)", s.folder));
      return;
    }
  }
  out.found.push_back({s.suite, s.id, s.id.substr(6), dir, gt, calib});
}

}  // namespace

SuiteDiscovery discover_suites(const std::optional<fs::path>& euroc_root, const std::optional<fs::path>& kitti_root,
                               const std::optional<fs::path>& tumvi_root) {
  for (const auto* r : {&euroc_root, &kitti_root, &tumvi_root}) {
    if (*r && !is_dir(**r)) throw InputError((*r)->string(), "not a folder (a dataset root holds the official folders)");
  }
  SuiteDiscovery out;
  for (const auto& s : standard_sequences()) {
    if (s.suite == Suite::kEuroc && euroc_root) find_euroc(fs::absolute(*euroc_root).lexically_normal(), s, out);
    if (s.suite == Suite::kKitti && kitti_root) find_kitti(fs::absolute(*kitti_root).lexically_normal(), s, out);
    if (s.suite == Suite::kTumvi && tumvi_root) find_tumvi(fs::absolute(*tumvi_root).lexically_normal(), s, out);
  }
  return out;
}

std::string standard_sequence_id(const fs::path& dataset) {
  fs::path p = dataset.lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  if (p.filename() == "mav0") p = p.parent_path();
  const std::string name = p.filename().string();
  // TUM-VI: dataset-room<1-6>_512_16 or _1024_16.
  for (int k = 1; k <= 6; ++k) {
    for (const char* px : {"512", "1024"}) {
      if (name == fmt::format("dataset-room{}_{}_16", k, px)) return fmt::format("tumvi/room{}", k);
    }
  }
  for (const auto& s : standard_sequences()) {
    if (s.suite == Suite::kEuroc && name == s.folder) return s.id;
    if (s.suite == Suite::kKitti && name == s.folder && p.parent_path().filename() == "sequences") return s.id;
  }
  return "";
}

}  // namespace plslam::bench
