#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/io/image_loading.h"
#include "support/test_support.h"

namespace plslam::io {
namespace {

std::filesystem::path write(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

TEST(ImageLoading, RawPgmIsReadAndATruncatedOneIsRefusedBeforeDecoding) {
  test::TempDir tmp;
  std::string pixels(16 * 12, '\0');
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<char>(i % 251);
  const cv::Mat img = load_grey_image(write(tmp.path() / "ok.pgm", "P5\n# a comment\n16 12\n255\n" + pixels));
  EXPECT_EQ(img.cols, 16);
  EXPECT_EQ(img.rows, 12);
  EXPECT_EQ(img.at<unsigned char>(1, 2), 18);
  // A header promising 99999 x 9199 pixels in a 60-byte file: refused without allocating them.
  try {
    load_grey_image(write(tmp.path() / "giant.pgm", "P5\n99999 9199\n255\n" + pixels.substr(0, 40)));
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated PGM/PPM: the header says 99999 x 9199 pixels"), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_grey_image(write(tmp.path() / "bad.pgm", "P5\nabc\n")), InputError);
}

}  // namespace
}  // namespace plslam::io
