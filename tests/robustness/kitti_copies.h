#pragma once
// Rearranged copies of the shared KITTI excerpts in a test's temporary folder (dropped, repeated,
// damaged or black frames), and `plslam run` on them with its stats.json read back.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace plslam::test {

enum class Damage { kNone, kEmptyFile, kBlank };

// A KITTI layout under `root` whose frame i shows source frame `frames[i]` of the shared excerpt
// `id` (images, time and ground-truth pose), with `damage` applied to some left images. A
// negative source frame is a black stereo pair (with the previous frame's pose). With
// `times_at_10hz`, frame i's time is 0.1 i instead of its source frame's.
std::filesystem::path make_copy(const std::filesystem::path& data, const std::filesystem::path& root,
                                const std::vector<int>& frames, const std::map<std::size_t, Damage>& damage = {},
                                const std::string& id = "06", bool times_at_10hz = false);

// from, from + step, ... below `to`.
std::vector<int> range(int from, int to, int step = 1);

struct Run {
  CliResult cli;
  std::filesystem::path out;
  nlohmann::json stats;
};

// `plslam run SEQ --out OUT --quiet --sequential EXTRA`; stats.json parsed when written.
Run run(const std::filesystem::path& seq, const std::filesystem::path& out, const std::string& extra = "");

}  // namespace plslam::test
