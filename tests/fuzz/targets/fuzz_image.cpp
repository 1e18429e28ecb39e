// An image file as the dataset readers load it: decode (PNG, JPEG, PGM headers), grey
// conversion, and the blank/unreadable checks. The first byte picks the file extension.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/io/image_loading.h"

namespace plslam::fuzz {

int fuzz_image(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* kNames[] = {"img.png", "img.jpg", "img.pgm"};
  const auto path = scratch_dir() / kNames[data[0] % 3];
  write_file(path, as_string(data + 1, size - 1));
  return expect_only_input_errors("image", [&] {
    const cv::Mat img = io::load_grey_image(path);
    (void)io::blank_image_problem(img, path);
  });
}

}  // namespace plslam::fuzz
