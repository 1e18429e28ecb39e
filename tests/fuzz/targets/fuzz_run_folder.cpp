// The files `plslam view` reads from a run folder besides trajectory.tum (which has a target of
// its own): stats.json, the map's PLY files and map_graph.json. The first byte chooses.
#include "fuzz/targets/fuzz_support.h"
#include "plslam/io/map_export.h"
#include "plslam/viz/scene_document.h"

namespace plslam::fuzz {

int fuzz_run_folder(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text = as_string(data + 1, size - 1);
  return expect_only_input_errors("run_folder", [&] {
    if (data[0] % 3 == 0) {
      (void)io::parse_ply(text, "map_points.ply");
    } else if (data[0] % 3 == 1) {
      map::MapSnapshot map;
      viz::parse_map_graph(text, "map_graph.json", map);
    } else {
      viz::SceneInfo info;
      (void)viz::parse_run_stats(text, "stats.json", info);
    }
  });
}

}  // namespace plslam::fuzz
