#pragma once
// A fast path for the one PNG kind the datasets store: 8-bit greyscale, not interlaced (KITTI's
// and EuRoC's cameras). libdeflate inflates the whole image data in one call, about twice as
// fast as zlib's streaming inflate under libpng, and the rows are unfiltered here. With libpng,
// loading the images took an eighth of a KITTI run's CPU time (13 % of a profile), and in an
// unpaced run the loader competes with tracking for the two cores.
//
// Only a well-formed file takes this path: every chunk's CRC, the zlib checksum, the exact
// amount of image data and every row's filter type are checked. Anything else (another colour
// type or depth, interlacing, damage of any kind) is left to the general decoder, which then
// reports it as before, so the fast path never changes what a bad file does.
#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace plslam::io {

// The image, or nothing when the bytes are not a well-formed 8-bit grey non-interlaced PNG.
std::optional<cv::Mat> decode_grey8_png(const std::vector<std::uint8_t>& bytes);

}  // namespace plslam::io
