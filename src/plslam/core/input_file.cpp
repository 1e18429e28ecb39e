#include "plslam/core/input_file.h"

#include "plslam/core/error.h"

namespace plslam {

std::ifstream open_input_file(const std::filesystem::path& path, const char* missing) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw InputError(path.string(), missing);
  if (std::filesystem::is_directory(status)) throw InputError(path.string(), "is a folder, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "cannot open file (permission denied?)");
  return in;
}

std::ifstream open_text_file(const std::filesystem::path& path, const char* missing) {
  std::ifstream in = open_input_file(path, missing);
  char bom[3] = {};
  in.read(bom, 3);
  if (!(in.gcount() == 3 && bom[0] == '\xEF' && bom[1] == '\xBB' && bom[2] == '\xBF')) {
    in.clear();
    in.seekg(0);
  }
  return in;
}

void strip_cr(std::string& line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
}

}  // namespace plslam
