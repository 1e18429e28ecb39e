#include "json_stdout.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <stdexcept>

namespace plslam::cli {
namespace {
int json_fd = STDOUT_FILENO;
}  // namespace

void reserve_stdout_for_json() {
  std::cout.flush();
  std::fflush(stdout);
  const int saved = ::dup(STDOUT_FILENO);
  if (saved < 0 || ::dup2(STDERR_FILENO, STDOUT_FILENO) < 0) {
    throw std::runtime_error(std::string("cannot reserve stdout for --json: ") + std::strerror(errno));
  }
  json_fd = saved;
}

void print_json(const std::string& text) {
  std::cout.flush();
  std::fflush(stdout);
  const char* p = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const ssize_t n = ::write(json_fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error(std::string("cannot write the JSON to stdout: ") + std::strerror(errno));
    p += n;
    left -= static_cast<std::size_t>(n);
  }
}

}  // namespace plslam::cli
