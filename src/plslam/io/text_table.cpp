#include "plslam/io/text_table.h"

#include <charconv>
#include <cmath>
#include <fstream>

#include "plslam/core/error.h"

namespace plslam::io {

double parse_finite(const std::string& field, const std::filesystem::path& path, std::size_t line) {
  double v = 0;
  const char* b = field.data();
  const char* e = b + field.size();
  auto [ptr, ec] = std::from_chars(b, e, v);
  if (ec != std::errc() || ptr != e) {
    throw InputError(path.string(), "line " + std::to_string(line) + ": '" + field + "' is not a number");
  }
  if (!std::isfinite(v)) {
    throw InputError(path.string(), "line " + std::to_string(line) + ": non-finite value '" + field + "'");
  }
  return v;
}

std::vector<NumericRow> read_numeric_rows(const std::filesystem::path& path) {
  std::ifstream in = open_text_file(path);
  std::vector<NumericRow> rows;
  std::string text;
  std::size_t line_no = 0;
  while (std::getline(in, text)) {
    ++line_no;
    strip_cr(text);
    const auto first = text.find_first_not_of(" \t");
    if (first == std::string::npos || text[first] == '#') continue;
    NumericRow row;
    row.line = line_no;
    std::size_t i = 0;
    while (i < text.size()) {
      while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == ',')) ++i;
      if (i >= text.size()) break;
      std::size_t j = i;
      while (j < text.size() && text[j] != ' ' && text[j] != '\t' && text[j] != ',') ++j;
      row.raw.emplace_back(text.substr(i, j - i));
      row.values.push_back(parse_finite(row.raw.back(), path, line_no));
      i = j;
    }
    rows.push_back(std::move(row));
  }
  if (in.bad()) throw InputError(path.string(), "read error");
  return rows;
}

}  // namespace plslam::io
