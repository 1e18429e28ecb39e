#pragma once
// Output files are whole or absent: the content goes to a temporary name in the same folder,
// is checked (stream state, fsync, close) and only then renamed over the final name, so a
// full disk or a crash never leaves a truncated file under the name a user trusts.
#include <filesystem>
#include <functional>
#include <ostream>

namespace plslam::io {

// Writes `path` through `write`; creates the parent folder if missing. On any failure the
// temporary file is removed and an InputError naming `path` is thrown.
// Test seam: PLSLAM_FAIL_WRITE=<file name> makes every write of a file with that name fail
// after its content was written, standing in for a full disk.
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

}  // namespace plslam::io
