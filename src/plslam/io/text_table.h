#pragma once
// Line-oriented numeric text parsing shared by the calibration, timestamp and trajectory readers:
// every failure becomes an InputError naming the file and line.
#include <filesystem>
#include <string>
#include <vector>

#include "plslam/core/input_file.h"  // open_text_file, strip_cr: every reader of user text uses them

namespace plslam::io {

struct NumericRow {
  std::size_t line = 0;         // 1-based line number in the file
  std::vector<double> values;   // parsed numbers
  std::vector<std::string> raw; // the fields as written (for exact integer timestamps)
};

// Reads all non-empty, non-comment ('#') lines; fields are split on whitespace and commas.
// Throws InputError if the file cannot be opened or a field is not a finite number.
std::vector<NumericRow> read_numeric_rows(const std::filesystem::path& path);

// Parses one number; throws InputError(file, "line N: ...") when it is not a finite number.
double parse_finite(const std::string& field, const std::filesystem::path& path, std::size_t line);

}  // namespace plslam::io
