#pragma once
// The standard sequences of EuRoC, KITTI odometry and TUM-VI, found under the roots a user
// downloaded them to, by their official folder names: what `bench slam --euroc-root DIR
// --kitti-root DIR --tumvi-root DIR` runs, and which of them are missing.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace plslam::bench {

enum class Suite { kEuroc, kKitti, kTumvi };

// The evaluation convention of each benchmark, as the report states it.
const char* suite_convention(Suite s);

struct SuiteSequence {
  Suite suite = Suite::kEuroc;
  std::string id;                      // the published figures' key: euroc/MH01, kitti/06, tumvi/room1
  std::string name;                    // the bench's dataset name: MH_01_easy, kitti-06, room1
  std::filesystem::path path;          // what `plslam run` opens
  std::filesystem::path ground_truth;  // the official ground-truth file
  std::filesystem::path calibration;   // --calib, where the sequence's own sensor.yaml is missing (TUM-VI)
};

struct SuiteDiscovery {
  std::vector<SuiteSequence> found;    // in the suites' standard order
  std::vector<std::string> missing;    // "<suite> <name>: why" for every standard sequence not found
};

// The standard sequences: EuRoC MH_01_easy ... V2_03_difficult, KITTI 00-10 (those with public
// ground truth), TUM-VI dataset-room1_512_16 ... room6 (the rooms: mocap covers them whole).
struct StandardSequence {
  Suite suite;
  std::string id, folder;
};
const std::vector<StandardSequence>& standard_sequences();

// Looks for each standard sequence of a suite whose root is given:
// - EuRoC: ROOT/<name>/mav0 or the download site's ROOT/{machine_hall,vicon_room1,vicon_room2}/<name>/mav0,
//   ground truth mav0/state_groundtruth_estimate0/data.csv;
// - KITTI: ROOT/sequences/NN with ROOT/poses/NN.txt;
// - TUM-VI: ROOT/dataset-roomN_512_16/mav0 (or the 1024 px version), ground truth mav0/mocap0/data.csv,
//   the calibration dso/camchain.yaml when mav0/cam0/sensor.yaml is absent.
// A sequence whose images are there but whose ground truth is not is missing ("no ground truth"):
// the bench scores every run. Throws InputError when a root given is not a folder.
SuiteDiscovery discover_suites(const std::optional<std::filesystem::path>& euroc_root,
                               const std::optional<std::filesystem::path>& kitti_root,
                               const std::optional<std::filesystem::path>& tumvi_root);

// The published figures' key of a dataset folder given by hand (MH_01_easy -> euroc/MH01, a KITTI
// sequences/06 -> kitti/06, dataset-room2_512_16 -> tumvi/room2), "" when it is none of them.
std::string standard_sequence_id(const std::filesystem::path& dataset);

}  // namespace plslam::bench
