#pragma once
// stdout of a `--json` command holds only its JSON document. Libraries print to stdout on their
// own (OpenCV's logger writes its INFO and DEBUG lines there, e.g. with OPENCV_LOG_LEVEL=DEBUG),
// so with --json the process's stdout is moved aside before any command runs: file descriptor 1
// then points at stderr, and the document alone goes to the real stdout through print_json().
#include <string>

namespace plslam::cli {

// Called once by main() when "--json" is among the arguments, before anything else prints.
void reserve_stdout_for_json();

// Writes `text` to the real stdout (the reserved one, or fd 1 if none was reserved) and flushes.
// Throws std::runtime_error when the write fails (a closed pipe, a full disk).
void print_json(const std::string& text);

}  // namespace plslam::cli
