// io/png_grey: the fast path for 8-bit grey PNGs. PNGs are built here byte by byte (each row's
// filter chosen, deflated by libdeflate, chunks with their CRCs), so every filter type and every
// kind of damage is exercised; libpng (cv::imdecode) decodes the same bytes as the reference.
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <libdeflate.h>
#include <opencv2/imgcodecs.hpp>

#include "plslam/core/error.h"
#include "plslam/io/image_loading.h"
#include "plslam/io/png_grey.h"
#include "support/test_support.h"

namespace plslam::io {
namespace {

using Bytes = std::vector<std::uint8_t>;

void put32(Bytes& b, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<std::uint8_t>(v >> s));
}

void chunk(Bytes& png, const char* type, const Bytes& data) {
  put32(png, static_cast<std::uint32_t>(data.size()));
  Bytes body(type, type + 4);
  body.insert(body.end(), data.begin(), data.end());
  png.insert(png.end(), body.begin(), body.end());
  put32(png, libdeflate_crc32(0, body.data(), body.size()));
}

// Row y filtered with filter f (PNG's encoder side, one byte per pixel).
Bytes filter_row(const cv::Mat& img, int y, int f) {
  Bytes out{static_cast<std::uint8_t>(f)};
  for (int x = 0; x < img.cols; ++x) {
    const int v = img.at<std::uint8_t>(y, x);
    const int a = x > 0 ? img.at<std::uint8_t>(y, x - 1) : 0;
    const int b = y > 0 ? img.at<std::uint8_t>(y - 1, x) : 0;
    const int c = x > 0 && y > 0 ? img.at<std::uint8_t>(y - 1, x - 1) : 0;
    int pred = 0;
    if (f == 1) pred = a;
    if (f == 2) pred = b;
    if (f == 3) pred = (a + b) / 2;
    if (f == 4) {
      const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
      pred = pa <= pb && pa <= pc ? a : (pb <= pc ? b : c);
    }
    out.push_back(static_cast<std::uint8_t>((v - pred) & 0xff));
  }
  return out;
}

struct PngParts {
  std::uint8_t depth = 8, colour = 0, interlace = 0;
  std::uint32_t width = 0, height = 0;  // 0: the image's own
  int filter_override = -1;             // every row's filter byte, even an invalid one
  int idat_pieces = 1;
  Bytes between_idat;                   // a tEXt chunk between the IDAT pieces when non-empty
  Bytes before_idat_type;               // an ancillary chunk of this type before the data
  bool iend = true;
};

Bytes make_png(const cv::Mat& img, const PngParts& o = {}) {
  Bytes filtered;
  for (int y = 0; y < img.rows; ++y) {
    Bytes row = filter_row(img, y, y % 5);  // every filter type, row after row
    if (o.filter_override >= 0) row[0] = static_cast<std::uint8_t>(o.filter_override);
    filtered.insert(filtered.end(), row.begin(), row.end());
  }
  libdeflate_compressor* c = libdeflate_alloc_compressor(6);
  Bytes z(libdeflate_zlib_compress_bound(c, filtered.size()));
  z.resize(libdeflate_zlib_compress(c, filtered.data(), filtered.size(), z.data(), z.size()));
  libdeflate_free_compressor(c);
  Bytes png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  Bytes ihdr;
  put32(ihdr, o.width ? o.width : static_cast<std::uint32_t>(img.cols));
  put32(ihdr, o.height ? o.height : static_cast<std::uint32_t>(img.rows));
  ihdr.insert(ihdr.end(), {o.depth, o.colour, 0, 0, o.interlace});
  chunk(png, "IHDR", ihdr);
  if (!o.before_idat_type.empty()) {
    const std::string type(o.before_idat_type.begin(), o.before_idat_type.end());
    chunk(png, type.c_str(), type == "tRNS" ? Bytes{0, 7} : Bytes{'k', 0, 'v'});
  }
  const std::size_t piece = (z.size() + static_cast<std::size_t>(o.idat_pieces) - 1) / static_cast<std::size_t>(o.idat_pieces);
  for (std::size_t s = 0; s < z.size(); s += piece) {
    if (s > 0 && !o.between_idat.empty()) chunk(png, "tEXt", o.between_idat);
    chunk(png, "IDAT", Bytes(z.begin() + static_cast<std::ptrdiff_t>(s), z.begin() + static_cast<std::ptrdiff_t>(std::min(z.size(), s + piece))));
  }
  if (o.iend) chunk(png, "IEND", {});
  return png;
}

cv::Mat random_image(int w, int h, unsigned seed) {
  cv::Mat img(h, w, CV_8UC1);
  std::mt19937 rng(seed);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)  // smooth plus noise, so every predictor is exercised with carries
      img.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>((3 * x + 5 * y + static_cast<int>(rng() % 64)) & 0xff);
  return img;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::countNonZero(a != b) == 0;
}

TEST(PngGrey, EveryFilterTypeDecodesExactlyAndAsLibpngDoes) {
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{1, 5}, std::pair{300, 11}}) {
    const cv::Mat img = random_image(w, h, static_cast<unsigned>(w * 100 + h));
    const Bytes png = make_png(img);
    const auto fast = decode_grey8_png(png);
    ASSERT_TRUE(fast.has_value()) << w << "x" << h;
    EXPECT_TRUE(same(*fast, img)) << w << "x" << h;
    EXPECT_TRUE(same(cv::imdecode(png, cv::IMREAD_UNCHANGED), img)) << "the test's encoder, checked by libpng";
  }
}

TEST(PngGrey, SplitImageDataAndAncillaryChunksAreRead) {
  const cv::Mat img = random_image(64, 40, 3);
  PngParts o;
  o.idat_pieces = 3;
  o.before_idat_type = {'t', 'E', 'X', 't'};
  const auto fast = decode_grey8_png(make_png(img, o));
  ASSERT_TRUE(fast.has_value());
  EXPECT_TRUE(same(*fast, img));
}

TEST(PngGrey, AnythingElseIsLeftToTheGeneralDecoder) {
  const cv::Mat img = random_image(40, 30, 5);
  const Bytes good = make_png(img);
  ASSERT_TRUE(decode_grey8_png(good).has_value());
  auto refused = [](const Bytes& b) { return !decode_grey8_png(b).has_value(); };
  Bytes not_png = good;
  not_png[1] = 'Q';
  EXPECT_TRUE(refused(not_png));
  Bytes colour, wide;
  cv::imencode(".png", cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3)), colour);
  cv::imencode(".png", cv::Mat(8, 8, CV_16UC1, cv::Scalar(300)), wide);
  EXPECT_TRUE(refused(colour));
  EXPECT_TRUE(refused(wide));
  PngParts o;
  o.interlace = 1;
  EXPECT_TRUE(refused(make_png(img, o)));
  o = {};
  o.filter_override = 5;  // no such filter
  EXPECT_TRUE(refused(make_png(img, o)));
  o = {};
  o.height = 31;  // one row more than the data holds
  EXPECT_TRUE(refused(make_png(img, o)));
  o = {};
  o.width = o.height = 100000;  // ten gigabytes promised by a few hundred bytes
  EXPECT_TRUE(refused(make_png(img, o)));
  o = {};
  o.iend = false;
  EXPECT_TRUE(refused(make_png(img, o)));
  o = {};
  o.idat_pieces = 2;
  o.between_idat = {'k', 0, 'v'};  // the image data must be one run of chunks
  EXPECT_TRUE(refused(make_png(img, o)));
  o = {};
  o.before_idat_type = {'t', 'R', 'N', 'S'};  // transparency: libpng's business
  EXPECT_TRUE(refused(make_png(img, o)));
  Bytes bad_crc = good;
  bad_crc[bad_crc.size() - 20] ^= 0x40;  // inside the last IDAT
  EXPECT_TRUE(refused(bad_crc));
  for (const std::size_t keep : {std::size_t{7}, std::size_t{30}, good.size() / 2, good.size() - 1})
    EXPECT_TRUE(refused(Bytes(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(keep)))) << keep;
}

// Through the loader: a file the fast path refuses gets what the general decoder says of it.
TEST(PngGrey, TheLoaderFallsBackToLibpng) {
  const test::TempDir tmp;
  const cv::Mat img = random_image(40, 30, 7);
  auto write = [&](const char* name, const Bytes& b) {
    const auto p = tmp.path() / name;
    std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
    return p;
  };
  EXPECT_TRUE(same(load_grey_image(write("good.png", make_png(img))), img));
  PngParts o;
  o.before_idat_type = {'t', 'R', 'N', 'S'};
  EXPECT_TRUE(same(load_grey_image(write("trns.png", make_png(img, o))), img));
  o = {};
  o.filter_override = 5;
  EXPECT_THROW(load_grey_image(write("bad_filter.png", make_png(img, o))), InputError);
  const Bytes good = make_png(img);
  EXPECT_THROW(load_grey_image(write("cut.png", Bytes(good.begin(), good.begin() + 40))), InputError);
}

TEST(PngGrey, DatasetFramesDecodeAsLibpngDoes) {
  PLSLAM_REQUIRE_SHARED_DATA(data);
  const auto euroc = data / "euroc/V1_01_easy_micro/mav0/cam0/data";
  std::vector<std::filesystem::path> files = {data / "kitti/sequences/06/image_0/000000.png",
                                              data / "kitti/sequences/01/image_1/000050.png"};
  for (const auto& e : std::filesystem::directory_iterator(euroc)) {
    files.push_back(e.path());
    break;
  }
  for (const auto& f : files) {
    const cv::Mat ref = cv::imread(f.string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(ref.empty()) << f;
    std::ifstream in(f, std::ios::binary);
    const Bytes bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto fast = decode_grey8_png(bytes);
    ASSERT_TRUE(fast.has_value()) << f << ": the datasets' PNGs are what the fast path is for";
    EXPECT_TRUE(same(*fast, ref)) << f;
  }
}

}  // namespace
}  // namespace plslam::io
