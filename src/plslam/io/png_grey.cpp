#include "plslam/io/png_grey.h"

#include <cstdlib>
#include <cstring>
#include <memory>

#include <libdeflate.h>

namespace plslam::io {
namespace {

std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | std::uint32_t{p[3]};
}

bool is_type(const std::uint8_t* t, const char* name) { return std::memcmp(t, name, 4) == 0; }

// One row of filtered bytes (without the filter byte) into pixels, given the previous row's
// pixels (zeros above the first row). PNG's filters for one byte per pixel.
bool unfilter_row(int filter, const std::uint8_t* in, const std::uint8_t* up, std::uint8_t* out, int width) {
  switch (filter) {
    case 0:
      std::memcpy(out, in, static_cast<std::size_t>(width));
      return true;
    case 1: {
      std::uint8_t a = 0;
      for (int x = 0; x < width; ++x) out[x] = a = static_cast<std::uint8_t>(in[x] + a);
      return true;
    }
    case 2:
      for (int x = 0; x < width; ++x) out[x] = static_cast<std::uint8_t>(in[x] + up[x]);
      return true;
    case 3: {
      int a = 0;
      for (int x = 0; x < width; ++x) out[x] = static_cast<std::uint8_t>(a = (in[x] + ((a + up[x]) >> 1)) & 0xff);
      return true;
    }
    case 4: {
      int a = 0, c = 0;
      for (int x = 0; x < width; ++x) {
        const int b = up[x];
        const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
        const int pred = (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
        a = (in[x] + pred) & 0xff;
        out[x] = static_cast<std::uint8_t>(a);
        c = b;
      }
      return true;
    }
    default:
      return false;
  }
}

struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

}  // namespace

std::optional<cv::Mat> decode_grey8_png(const std::vector<std::uint8_t>& bytes) {
  static const std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kSignature, 8) != 0) return std::nullopt;
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> idat;
  bool header = false, ended = false, in_idat = false, idat_done = false;
  std::size_t p = 8;
  while (!ended) {
    if (bytes.size() - p < 12) return std::nullopt;  // truncated: no room for a chunk
    const std::uint32_t length = be32(&bytes[p]);
    if (length > 0x7fffffffu || bytes.size() - p - 12 < length) return std::nullopt;
    const std::uint8_t* type = &bytes[p + 4];
    const std::uint8_t* data = type + 4;
    if (libdeflate_crc32(0, type, length + 4) != be32(data + length)) return std::nullopt;
    const bool critical = (type[0] & 0x20) == 0;
    if (!header) {  // IHDR comes first
      if (!is_type(type, "IHDR") || length != 13) return std::nullopt;
      width = be32(data);
      height = be32(data + 4);
      // 8-bit grey, deflate, adaptive filtering, not interlaced.
      if (data[8] != 8 || data[9] != 0 || data[10] != 0 || data[11] != 0 || data[12] != 0) return std::nullopt;
      if (width == 0 || height == 0 || width > 0x7fffffffu || height > 0x7fffffffu) return std::nullopt;
      header = true;
    } else if (is_type(type, "IDAT")) {
      if (idat_done) return std::nullopt;  // the image data must be one run of chunks
      idat.insert(idat.end(), data, data + length);
      in_idat = true;
    } else if (is_type(type, "IEND")) {
      ended = true;
    } else if (critical || is_type(type, "tRNS") || is_type(type, "sBIT")) {
      // Another critical chunk (PLTE, ...), or one that changes the decoded values: the general
      // decoder's business.
      return std::nullopt;
    }
    if (in_idat && !is_type(type, "IDAT")) idat_done = true;
    p += 12 + length;
  }
  if (idat.empty()) return std::nullopt;
  // The filtered rows, each with its filter byte. Deflate expands at most 1032:1, so a header
  // promising more than that of the data held is damage; so is more than a gigabyte.
  const std::uint64_t row_bytes = std::uint64_t{width} + 1, raw_size = row_bytes * height;
  if (raw_size > (std::uint64_t{1} << 30) || raw_size > 1032 * static_cast<std::uint64_t>(idat.size()) + 64)
    return std::nullopt;
  std::vector<std::uint8_t> raw(static_cast<std::size_t>(raw_size));
  const std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> inflater(libdeflate_alloc_decompressor());
  if (!inflater) return std::nullopt;
  std::size_t produced = 0;
  if (libdeflate_zlib_decompress(inflater.get(), idat.data(), idat.size(), raw.data(), raw.size(), &produced) !=
          LIBDEFLATE_SUCCESS ||
      produced != raw.size()) {
    return std::nullopt;
  }
  cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_8UC1);
  const std::vector<std::uint8_t> zeros(width, 0);
  for (std::uint32_t y = 0; y < height; ++y) {
    const std::uint8_t* row = &raw[static_cast<std::size_t>(y * row_bytes)];
    const std::uint8_t* up = y == 0 ? zeros.data() : image.ptr<std::uint8_t>(static_cast<int>(y) - 1);
    if (!unfilter_row(row[0], row + 1, up, image.ptr<std::uint8_t>(static_cast<int>(y)), static_cast<int>(width)))
      return std::nullopt;
  }
  return image;
}

}  // namespace plslam::io
