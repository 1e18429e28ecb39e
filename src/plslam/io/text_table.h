#pragma once
// Line-oriented numeric text parsing shared by the calibration, timestamp and trajectory readers:
// every failure becomes an InputError naming the file and line.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace plslam::io {

struct NumericRow {
  std::size_t line = 0;         // 1-based line number in the file
  std::vector<double> values;   // parsed numbers
  std::vector<std::string> raw; // the fields as written (for exact integer timestamps)
};

// Opens a user's text file for reading: a missing path says `missing` ("file not found" unless
// given), a folder in its place says so, and a UTF-8 byte-order mark (Windows editors write one)
// is skipped. Every reader of user text goes through here, so they all accept the same files.
std::ifstream open_text_file(const std::filesystem::path& path, const char* missing = "file not found");

// Removes the '\r' of a CRLF line ending, so files saved on Windows read like the others.
void strip_cr(std::string& line);

// Reads all non-empty, non-comment ('#') lines; fields are split on whitespace and commas.
// Throws InputError if the file cannot be opened or a field is not a finite number.
std::vector<NumericRow> read_numeric_rows(const std::filesystem::path& path);

// Parses one number; throws InputError(file, "line N: ...") when it is not a finite number.
double parse_finite(const std::string& field, const std::filesystem::path& path, std::size_t line);

}  // namespace plslam::io
