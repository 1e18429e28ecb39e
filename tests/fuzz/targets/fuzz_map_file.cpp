// plslam map files (system/map_file.h), read by `plslam run --load-map` and `plslam map`.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/map/map.h"
#include "plslam/system/map_file.h"

namespace plslam::fuzz {

int fuzz_map_file(const std::uint8_t* data, std::size_t size) {
  return expect_only_input_errors("map_file", [&] {
    const std::string bytes = as_string(data, size);
    // Behind the checksums, where a mutation would otherwise always end: every structure check.
    system::MapReadOptions unchecked;
    unchecked.verify_checksums = false;
    const auto contents = system::map_from_bytes(bytes, "map.plmap", unchecked);
    // Contents that parse must restore into a map without a throw or a crash.
    map::Map map;
    system::restore_map(contents, map, nullptr);
    (void)system::map_to_bytes(system::capture_map(map, nullptr, contents.meta));
  });
}

}  // namespace plslam::fuzz
