#include "plslam/io/map_export.h"

#include <charconv>
#include <cmath>
#include <iterator>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/core/input_file.h"
#include "plslam/io/atomic_file.h"

namespace plslam::io {
void write_ply_points(const std::filesystem::path& path, const std::vector<Eigen::Vector3d>& points) {
  write_file_atomically(path, [&](std::ostream& out) {
  out << "ply\nformat ascii 1.0\ncomment plslam map points\n"
      << "element vertex " << points.size() << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const auto& p : points) out << fmt::format("{:.6f} {:.6f} {:.6f}\n", p.x(), p.y(), p.z());
  });
}

void write_ply_lines(const std::filesystem::path& path,
                     const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments) {
  write_file_atomically(path, [&](std::ostream& out) {
  out << "ply\nformat ascii 1.0\ncomment plslam map lines\n"
      << "element vertex " << 2 * segments.size()
      << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "element edge " << segments.size() << "\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  for (const auto& [a, b] : segments) {
    out << fmt::format("{:.6f} {:.6f} {:.6f}\n{:.6f} {:.6f} {:.6f}\n", a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
  }
  for (std::size_t i = 0; i < segments.size(); ++i) out << 2 * i << " " << 2 * i + 1 << "\n";
  });
}

namespace {

// Lines of a text, '\r' dropped, with their 1-based numbers for messages.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const auto end = text_.find('\n', pos_);
    line = text_.substr(pos_, end == std::string_view::npos ? std::string_view::npos : end - pos_);
    pos_ = end == std::string_view::npos ? text_.size() : end + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++number_;
    return true;
  }
  int number() const { return number_; }
  std::size_t remaining() const { return text_.size() - pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int number_ = 0;
};

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

template <typename T>
bool parse_number(std::string_view word, T& value) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  return ec == std::errc() && end == word.data() + word.size();
}

}  // namespace

PlyVertices parse_ply(std::string_view text, const std::string& source) {
  LineReader reader(text);
  std::string_view line;
  auto fail = [&](const std::string& problem) -> InputError {
    return InputError(source, fmt::format("line {}: {}", reader.number(), problem));
  };
  if (!reader.next(line) || line != "ply") throw InputError(source, "not a PLY file (no 'ply' first line)");
  if (!reader.next(line) || line != "format ascii 1.0") throw fail("only 'format ascii 1.0' is read");
  // Header: the vertex element with float x, y, z, then optionally the edge element with two int
  // vertex indices, which is what write_ply_points / write_ply_lines write.
  long vertices = -1, edges = -1;
  std::vector<std::string> vertex_properties, edge_properties;
  std::string element;
  bool header_done = false;
  while (!header_done && reader.next(line)) {
    const auto w = split_words(line);
    if (w.empty()) throw fail("empty header line");
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      header_done = true;
    } else if (w[0] == "element" && w.size() == 3) {
      long n = 0;
      if (!parse_number(w[2], n) || n < 0) throw fail("element count is not a number >= 0");
      element = std::string(w[1]);
      if (element == "vertex" && vertices < 0 && edges < 0) {
        vertices = n;
      } else if (element == "edge" && vertices >= 0 && edges < 0) {
        edges = n;
      } else {
        throw fail("expected the element 'vertex', then optionally 'edge'");
      }
    } else if (w[0] == "property" && w.size() == 3 && element == "vertex") {
      if (w[1] != "float" && w[1] != "double") throw fail("vertex properties must be float");
      vertex_properties.emplace_back(w[2]);
    } else if (w[0] == "property" && w.size() == 3 && element == "edge") {
      if (w[1] != "int") throw fail("edge properties must be int");
      edge_properties.emplace_back(w[2]);
    } else {
      throw fail(fmt::format("unexpected header line '{}'", std::string(line.substr(0, 60))));
    }
  }
  if (!header_done) throw InputError(source, "the header has no end_header");
  if (vertices < 0) throw InputError(source, "no vertex element");
  if (vertex_properties != std::vector<std::string>{"x", "y", "z"}) {
    throw InputError(source, "vertex properties must be x y z");
  }
  if (edges >= 0 && edge_properties != std::vector<std::string>{"vertex1", "vertex2"}) {
    throw InputError(source, "edge properties must be vertex1 vertex2");
  }
  // Each row takes at least 6 bytes ("0 0 0\n"): a count the rest of the text cannot hold is
  // refused before anything is allocated for it.
  const auto rows = static_cast<std::size_t>(vertices) + static_cast<std::size_t>(std::max(edges, 0L));
  if (rows > reader.remaining() / 4 + 1) {
    throw InputError(source, fmt::format("the header promises {} rows, more than the file holds", rows));
  }
  PlyVertices out;
  out.vertices.reserve(static_cast<std::size_t>(vertices));
  for (long i = 0; i < vertices; ++i) {
    if (!reader.next(line)) throw InputError(source, fmt::format("{} of {} vertices", i, vertices));
    const auto w = split_words(line);
    Eigen::Vector3d v;
    if (w.size() != 3 || !parse_number(w[0], v.x()) || !parse_number(w[1], v.y()) || !parse_number(w[2], v.z()) ||
        !v.allFinite()) {
      throw fail("a vertex must be 3 finite numbers");
    }
    out.vertices.push_back(v);
  }
  for (long i = 0; i < std::max(edges, 0L); ++i) {
    if (!reader.next(line)) throw InputError(source, fmt::format("{} of {} edges", i, edges));
    const auto w = split_words(line);
    long a = 0, b = 0;
    if (w.size() != 2 || !parse_number(w[0], a) || !parse_number(w[1], b) || a < 0 || b < 0 || a >= vertices ||
        b >= vertices) {
      throw fail("an edge must be 2 vertex indices");
    }
    out.edges.emplace_back(a, b);
  }
  while (reader.next(line)) {
    if (!split_words(line).empty()) throw fail("text after the last element");
  }
  return out;
}

namespace {

PlyVertices read_ply(const std::filesystem::path& path) {
  auto in = open_input_file(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_ply(text, path.string());
}

}  // namespace

std::vector<Eigen::Vector3d> read_ply_points(const std::filesystem::path& path) {
  auto ply = read_ply(path);
  if (!ply.edges.empty()) throw InputError(path.string(), "a point file has no edges");
  return std::move(ply.vertices);
}

std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> read_ply_lines(const std::filesystem::path& path) {
  const auto ply = read_ply(path);
  if (ply.edges.size() * 2 != ply.vertices.size()) {
    throw InputError(path.string(), "a line file has one edge per two vertices");
  }
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> out;
  out.reserve(ply.edges.size());
  for (std::size_t i = 0; i < ply.edges.size(); ++i) {
    const auto [a, b] = ply.edges[i];
    if (a != static_cast<long>(2 * i) || b != static_cast<long>(2 * i + 1)) {
      throw InputError(path.string(), fmt::format("edge {} must join vertices {} and {}", i, 2 * i, 2 * i + 1));
    }
    out.emplace_back(ply.vertices[static_cast<std::size_t>(a)], ply.vertices[static_cast<std::size_t>(b)]);
  }
  return out;
}

}  // namespace plslam::io
