#pragma once
// Checks an output folder before any work, so a bad --out fails in a second, not after a run.
#include <filesystem>

namespace plslam::io {

// Creates `dir` if missing and proves it writable by creating and removing a probe file.
// Throws InputError naming `dir` when it is empty, a file, or not writable.
void prepare_output_folder(const std::filesystem::path& dir);

}  // namespace plslam::io
