#include "plslam/io/calibration_file.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "plslam/core/config_reader.h"
#include "plslam/core/error.h"
#include "plslam/core/input_file.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/camchain_file.h"
#include "plslam/io/sensor_yaml.h"

namespace plslam::io {

namespace {

void require(const ConfigReader& reader, const char* key, const char* meaning) {
  if (!reader.has(key)) throw InputError(reader.source(), fmt::format("{}: missing ({})", key, meaning));
}

template <class T>
T read_positive(const ConfigReader& reader, const char* key, const char* meaning) {
  require(reader, key, meaning);
  T value{};
  reader.get(key, value);  // wrong types and non-finite numbers fail here, naming the key
  if (!(value > 0)) throw InputError(reader.source(), fmt::format("{}: must be positive, got {}", key, value));
  return value;
}

// A file that does not parse as a mapping is left to the rectified form's reader, whose errors
// name the problem in its terms.
bool holds_camchain(const std::filesystem::path& path) {
  try {
    return is_camchain(detail::load_sensor_yaml(path, "calibration file not found"));
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace

StereoCalibration read_calibration_file(const std::filesystem::path& path) {
  if (holds_camchain(path)) {
    throw InputError(path.string(), "holds raw cameras (cam0, cam1); this input needs the rectified calibration "
                                    "(width, height, fx, fy, cx, cy, baseline)");
  }
  std::ifstream in = open_text_file(path, "calibration file not found");
  std::stringstream text;
  text << in.rdbuf();
  const ConfigReader reader = ConfigReader::from_string(text.str(), path.string());
  StereoCalibration c;
  c.width = read_positive<int>(reader, "width", "image width in pixels of one camera");
  c.height = read_positive<int>(reader, "height", "image height in pixels");
  c.fx = read_positive<double>(reader, "fx", "rectified focal length in pixels, P1(0,0)");
  c.fy = read_positive<double>(reader, "fy", "rectified focal length in pixels, P1(1,1)");
  c.cx = read_positive<double>(reader, "cx", "rectified principal point in pixels, P1(0,2)");
  c.cy = read_positive<double>(reader, "cy", "rectified principal point in pixels, P1(1,2)");
  c.baseline = read_positive<double>(reader, "baseline", "metres, -P2(0,3) / P2(0,0)");
  reader.check_all_used();
  return c;
}

UserCalibration read_user_calibration(const std::filesystem::path& path) {
  UserCalibration c;
  if (holds_camchain(path)) {
    c.raw = read_camchain_file(path);
  } else {
    c.rectified = read_calibration_file(path);
  }
  return c;
}

InputRectification rectify_user_calibration(const UserCalibration& calibration, double balance,
                                            const std::filesystem::path& source) {
  InputRectification out;
  if (calibration.rectified) {
    out.calibration = *calibration.rectified;
    return out;
  }
  out.rectification = geometry::rectify_stereo(*calibration.raw, balance, source.string());
  out.calibration = out.rectification->calibration;
  return out;
}

void write_calibration_file(const std::filesystem::path& path, const StereoCalibration& c) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "# plslam stereo calibration of RECTIFIED images (README: Video and camera input).\n"
        << "# width, height: one camera's image in pixels (a side-by-side frame is 2 * width wide);\n"
        << "# fx, fy, cx, cy: the rectified pinhole intrinsics in pixels (stereoRectify's P1);\n"
        << "# baseline: metres between the cameras, -P2(0,3) / P2(0,0).\n"
        << fmt::format("width: {}\nheight: {}\n", c.width, c.height)
        << fmt::format("fx: {:.17g}\nfy: {:.17g}\ncx: {:.17g}\ncy: {:.17g}\n", c.fx, c.fy, c.cx, c.cy)
        << fmt::format("baseline: {:.17g}\n", c.baseline);
  });
}

}  // namespace plslam::io
