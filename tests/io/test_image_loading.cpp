#include <fstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/io/image_loading.h"
#include "io/fake_datasets.h"
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

// Only the dataset formats reach a decoder: OpenCV would also try DICOM, whose decoder aborts the
// process on a damaged file (the fuzz seed dicom_assert_in_gdcm), JPEG 2000, OpenEXR and more.
TEST(ImageLoading, OtherFormatsAreRefusedBeforeDecoding) {
  test::TempDir tmp;
  const std::string dicom = std::string(128, '\0') + "DICM" + std::string(64, '\x01');
  try {
    load_grey_image(write(tmp.path() / "scan.png", dicom));
    ADD_FAILURE() << "a DICOM file was decoded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a PNG, JPEG, PGM/PPM, BMP or TIFF image"), std::string::npos) << e.what();
  }
  const std::string jp2("\0\0\0\x0cjP  \r\n\x87\n", 12);
  EXPECT_THROW(load_grey_image(write(tmp.path() / "j.png", jp2 + std::string(40, 'x'))), InputError);
  // The supported formats still decode: a BMP and a PGM of the same pixels.
  const cv::Mat img = test::noise_image(16, 12, 1);
  std::vector<uchar> bmp;
  cv::imencode(".bmp", img, bmp);
  const cv::Mat back = load_grey_image(write(tmp.path() / "ok.bmp", std::string(bmp.begin(), bmp.end())));
  EXPECT_EQ(cv::countNonZero(back != img), 0);
}

}  // namespace
}  // namespace plslam::io
