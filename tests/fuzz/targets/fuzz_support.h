#pragma once
// Shared by the fuzz targets: a scratch folder per process, files written into it, and the rule
// every target checks. Each target is one function `int fuzz_<name>(const uint8_t*, size_t)`,
// called by libFuzzer (libfuzzer_entry.cpp, PLSLAM_FUZZ builds) and by the corpus replay test
// (tests/fuzz/test_fuzz_replay.cpp, every normal and sanitizer build).
//
// The rule: a parser either accepts the bytes or throws plslam::InputError (which the CLI turns
// into a one-line message and exit 2). Any other exception escaping is a bug, reported by abort()
// so that libFuzzer keeps the input.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "plslam/core/error.h"

namespace plslam::fuzz {

// Created on first use, removed at process exit.
inline const std::filesystem::path& scratch_dir() {
  struct Scratch {
    std::filesystem::path dir;
    Scratch() : dir(std::filesystem::temp_directory_path() / ("plslam_fuzz_" + std::to_string(::getpid()))) {
      std::filesystem::create_directories(dir);
    }
    ~Scratch() {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    }
  };
  static const Scratch scratch;
  return scratch.dir;
}

inline void write_file(const std::filesystem::path& p, const std::string& bytes) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

inline std::string as_string(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// Runs `body`; InputError is the expected outcome of bad input, anything else aborts.
template <class F>
int expect_only_input_errors(const char* target, F&& body) {
  try {
    body();
  } catch (const InputError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: escaped %s\n", target, e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "%s: escaped a non-standard exception\n", target);
    std::abort();
  }
  return 0;
}

}  // namespace plslam::fuzz
