#pragma once
// Error types that the CLI maps to exit codes: InputError -> 2 (bad input or usage),
// anything else -> 1 (internal error). InputError messages are one line and name the file.
#include <stdexcept>
#include <string>

namespace plslam {

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& problem)
      : std::runtime_error(file.empty() ? problem : file + ": " + problem),
        file_(file), problem_(problem) {}
  const std::string& file() const { return file_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string file_;
  std::string problem_;
};

}  // namespace plslam
