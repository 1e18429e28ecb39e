#include "plslam/eval/frame_log.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "plslam/core/error.h"

namespace plslam::eval {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

}  // namespace

FrameLog parse_frame_log(const std::string& text, const std::string& source) {
  FrameLog log;
  log.source = source;
  std::istringstream in(text);
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    auto cells = split(line);
    if (log.header.empty()) {
      log.header = std::move(cells);
      for (const char* need : {"frame", "timestamp"}) {
        if (std::find(log.header.begin(), log.header.end(), need) == log.header.end())
          throw InputError(source, fmt::format("no '{}' column in the header (not a plslam frames.csv)", need));
      }
      continue;
    }
    if (cells.size() != log.header.size())
      throw InputError(source, fmt::format("line {}: {} cells, the header has {}", line_no, cells.size(), log.header.size()));
    log.rows.push_back(std::move(cells));
  }
  if (log.header.empty()) throw InputError(source, "empty file");
  return log;
}

FrameLog read_frame_log(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in || std::filesystem::is_directory(path)) throw InputError(path.string(), "cannot read the frame log");
  std::ostringstream s;
  s << in.rdbuf();
  return parse_frame_log(s.str(), path.string());
}

std::vector<double> FrameLog::numbers(const std::string& column) const {
  const auto it = std::find(header.begin(), header.end(), column);
  if (it == header.end()) throw InputError(source, fmt::format("no '{}' column", column));
  const auto c = static_cast<std::size_t>(it - header.begin());
  std::vector<double> out;
  out.reserve(rows.size());
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const std::string& cell = rows[r][c];
    if (cell.empty()) {
      out.push_back(0.0);
      continue;
    }
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(cell.c_str(), &end);
    if (end != cell.c_str() + cell.size() || errno == ERANGE || !std::isfinite(v))
      throw InputError(source, fmt::format("row {}, column '{}': '{}' is not a number", r + 1, column, cell));
    out.push_back(v);
  }
  return out;
}

}  // namespace plslam::eval
