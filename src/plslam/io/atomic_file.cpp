#include "plslam/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "plslam/core/error.h"

namespace plslam::io {
namespace {

// True when the test seam asks this write to fail (see the header).
bool injected_failure(const std::filesystem::path& path) {
  const char* v = std::getenv("PLSLAM_FAIL_WRITE");
  return v != nullptr && path.filename() == v;
}

bool fsync_path(const std::filesystem::path& p, int flags) {
  const int fd = ::open(p.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  return ::close(fd) == 0 && ok;
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(path.string(), "cannot create folder: " + ec.message());
  // Same folder as the final name, so the rename is atomic (one file system).
  std::string tmp_name = path.filename().string();  // built by appends: GCC 12 warns on "." + s
  tmp_name.insert(0, 1, '.');
  tmp_name.append(".tmp.").append(std::to_string(::getpid()));
  const fs::path tmp = dir / tmp_name;
  bool ok = false;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (out) {
      try {
        write(out);
      } catch (...) {
        out.close();
        fs::remove(tmp, ec);
        throw;
      }
      out.flush();
      ok = static_cast<bool>(out);
      out.close();
      ok = ok && !out.fail();
    }
  }
  ok = ok && !injected_failure(path) && fsync_path(tmp, O_WRONLY);
  if (!ok) {
    fs::remove(tmp, ec);
    throw InputError(path.string(), "write failed (disk full or not writable)");
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(path.string(), "cannot rename into place: " + ec.message());
  }
  // The rename itself is durable only once the folder entry is synced; failure here is harmless.
  fsync_path(dir, O_RDONLY | O_DIRECTORY);
}

}  // namespace plslam::io
