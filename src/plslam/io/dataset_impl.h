#pragma once
// Internal: the concrete readers behind open_dataset(). Not for use outside io/.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "plslam/io/dataset.h"

namespace plslam::io::detail {

std::unique_ptr<Dataset> open_kitti(const std::filesystem::path& sequence_dir, const DatasetOptions& options);
std::unique_ptr<Dataset> open_euroc(const std::filesystem::path& mav0_dir, const DatasetOptions& options);

// Applies --start/--max-frames to an index list; throws InputError when nothing is left.
std::pair<std::size_t, std::size_t> select_range(std::size_t total, const DatasetOptions& options,
                                                 const std::filesystem::path& root);

// An ASL/EuRoC camera's data.csv: nanosecond stamps (strictly increasing) and image file names.
struct ImageEntry {
  std::int64_t ns = 0;
  std::string file;
};
std::vector<ImageEntry> read_image_list(const std::filesystem::path& csv);

// Throws InputError(file, "timestamps not increasing ...") unless strictly increasing.
void check_increasing(const std::vector<double>& t, const std::filesystem::path& file);

}  // namespace plslam::io::detail
