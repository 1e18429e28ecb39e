#pragma once
// Checks an output folder before any work, so a bad --out fails in a second, not after a run.
#include <filesystem>

namespace plslam::io {

// Creates `dir` if missing and proves it writable by creating and removing a probe file.
// Throws InputError naming `dir` when it is empty, a file, or not writable.
void prepare_output_folder(const std::filesystem::path& dir);

// The same for a single output file (`option` names the flag in messages): its folder is
// prepared, and the path must not be an existing folder.
void prepare_output_file(const std::filesystem::path& path, const char* option);

}  // namespace plslam::io
