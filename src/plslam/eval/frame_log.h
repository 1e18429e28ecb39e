#pragma once
// The per-frame log `plslam run` writes (frames.csv): one row per processed frame with what
// tracking saw and decided. Read back to plot it next to the error of the same frames.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace plslam::eval {

struct FrameLog {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;  // each as long as the header

  // The column's values as numbers (an empty cell reads 0). Throws InputError naming the file when
  // the column is missing or a cell is not a number.
  std::vector<double> numbers(const std::string& column) const;
  std::string source;
};

// Throws InputError naming the file on a missing file, no `frame`/`timestamp` columns, or a row
// whose cell count differs from the header's.
FrameLog read_frame_log(const std::filesystem::path& path);
FrameLog parse_frame_log(const std::string& text, const std::string& source);

}  // namespace plslam::eval
