// The files `plslam view` reads from a run folder besides stats.json and trajectory.tum (which
// have targets of their own): the map's PLY files and map_graph.json. The first byte chooses.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/io/map_export.h"
#include "plslam/viz/scene_document.h"

namespace plslam::fuzz {

int fuzz_run_folder(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text = as_string(data + 1, size - 1);
  return expect_only_input_errors("run_folder", [&] {
    if (data[0] % 2 == 0) {
      (void)io::parse_ply(text, "map_points.ply");
    } else {
      map::MapSnapshot map;
      viz::parse_map_graph(text, "map_graph.json", map);
    }
  });
}

}  // namespace plslam::fuzz
