#include "plslam/io/imu_csv.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "plslam/core/error.h"
#include "plslam/io/text_table.h"

namespace plslam::io {
namespace {

constexpr std::size_t kColumns = 7;

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split_commas(std::string_view line) {
  std::vector<std::string_view> fields;
  while (true) {
    const auto comma = line.find(',');
    fields.push_back(trimmed(line.substr(0, comma)));
    if (comma == std::string_view::npos) return fields;
    line.remove_prefix(comma + 1);
  }
}

// One sample as read, with what the checks after reading need.
struct Row {
  std::int64_t ns = 0;
  std::size_t line = 0;
};

// b - a for b > a, exact even where the signed difference would overflow.
std::uint64_t period_ns(std::int64_t a, std::int64_t b) {
  return static_cast<std::uint64_t>(b) - static_cast<std::uint64_t>(a);
}

void check_gaps(const std::vector<Row>& rows, const std::filesystem::path& path) {
  std::vector<std::uint64_t> periods;
  periods.reserve(rows.size() - 1);
  for (std::size_t i = 1; i < rows.size(); ++i) periods.push_back(period_ns(rows[i - 1].ns, rows[i].ns));
  std::vector<std::uint64_t> sorted = periods;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double median = static_cast<double>(sorted[sorted.size() / 2]);
  for (std::size_t i = 0; i < periods.size(); ++i) {
    const double gap = static_cast<double>(periods[i]);
    if (gap > kMaxImuGapPeriods * median) {
      throw InputError(path.string(),
                       fmt::format("line {}: a gap of {:.3f} ms after the sample on line {}, over {} median sample "
                                   "periods ({:.3f} ms): samples are missing",
                                   rows[i + 1].line, gap * 1e-6, rows[i].line, kMaxImuGapPeriods, median * 1e-6));
    }
  }
}

}  // namespace

std::vector<ImuSample> read_imu_csv(const std::filesystem::path& path) {
  std::ifstream in = open_text_file(path);
  std::vector<ImuSample> samples;
  std::vector<Row> rows;
  std::string text;
  std::size_t line_no = 0;
  while (std::getline(in, text)) {
    ++line_no;
    // getline sets eof only on a last line without its '\n'.
    const bool unterminated = in.eof();
    strip_cr(text);
    const std::string_view line = trimmed(text);
    if (line.empty() || line.front() == '#') continue;
    // Column names without '#', as other tools write them.
    if (line_no == 1 && std::isalpha(static_cast<unsigned char>(line.front()))) continue;
    const auto fields = split_commas(line);
    if (fields.size() != kColumns) {
      if (unterminated && fields.size() < kColumns) {
        spdlog::warn("{}: line {} is cut short ({} of {} columns, no line end): left out", path.string(), line_no,
                     fields.size(), kColumns);
        break;
      }
      throw InputError(path.string(),
                       fmt::format("line {}: {} columns, expected {} (timestamp [ns], gyro x y z, acc x y z)", line_no,
                                   fields.size(), kColumns));
    }
    Row row;
    row.line = line_no;
    const auto stamp = fields[0];
    const auto [end, ec] = std::from_chars(stamp.data(), stamp.data() + stamp.size(), row.ns);
    if (ec != std::errc() || end != stamp.data() + stamp.size()) {
      throw InputError(path.string(),
                       fmt::format("line {}: bad timestamp '{}' (expected whole nanoseconds)", line_no, stamp));
    }
    ImuSample s;
    s.t = static_cast<double>(row.ns) * 1e-9;
    for (int k = 0; k < 3; ++k) s.gyro[k] = parse_finite(std::string(fields[1 + k]), path, line_no);
    for (int k = 0; k < 3; ++k) s.acc[k] = parse_finite(std::string(fields[4 + k]), path, line_no);
    if (!rows.empty() && row.ns <= rows.back().ns) {
      const auto& prev = rows.back();
      throw InputError(path.string(),
                       row.ns == prev.ns
                           ? fmt::format("line {}: duplicate timestamp {} (also on line {})", line_no, row.ns,
                                         prev.line)
                           : fmt::format("line {}: timestamp {} is before {} on line {}: timestamps must increase",
                                         line_no, row.ns, prev.ns, prev.line));
    }
    // Seconds in a double resolve ~240 ns at EuRoC's epoch times: samples closer than that would
    // share a time, and the samples' times must increase.
    if (!samples.empty() && !(s.t > samples.back().t)) {
      throw InputError(path.string(), fmt::format("line {}: timestamp {} is too close to {} on line {} to be told "
                                                  "apart in seconds",
                                                  line_no, row.ns, rows.back().ns, rows.back().line));
    }
    rows.push_back(row);
    samples.push_back(s);
  }
  if (in.bad()) throw InputError(path.string(), "read error");
  if (samples.size() < kMinImuSamples) {
    throw InputError(path.string(), fmt::format("{} IMU sample{}, at least {} are needed", samples.size(),
                                                samples.size() == 1 ? "" : "s", kMinImuSamples));
  }
  check_gaps(rows, path);
  return samples;
}

}  // namespace plslam::io
