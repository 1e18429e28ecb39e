#include "plslam/io/output_folder.h"

#include <unistd.h>

#include <fstream>
#include <string>

#include "plslam/core/error.h"

namespace plslam::io {

void prepare_output_folder(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  if (dir.empty()) throw InputError("--out", "output folder is an empty string");
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) {
    throw InputError(dir.string(), "output folder is not a folder");
  }
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir.string(), "cannot create output folder: " + ec.message());
  std::string probe_name = ".plslam_probe.";
  probe_name.append(std::to_string(::getpid()));
  const fs::path probe = dir / probe_name;
  bool ok = false;
  {
    std::ofstream out(probe);
    out << "probe\n";
    out.flush();
    ok = static_cast<bool>(out);
  }
  fs::remove(probe, ec);
  if (!ok) throw InputError(dir.string(), "output folder is not writable");
}

void prepare_output_file(const std::filesystem::path& path, const char* option) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InputError(option, "output file is an empty string");
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path.string(), "output file is a folder");
  const fs::path parent = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  try {
    prepare_output_folder(parent);
  } catch (const InputError& e) {
    throw InputError(path.string(), "cannot write here: " + e.problem());
  }
}

}  // namespace plslam::io
