// plslam view <run-dir | map.plmap>: serves the browser viewer for a finished run or a saved map
// until Ctrl-C. The URL goes to stdout (one line), everything else to the log.
#include <chrono>
#include <iostream>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command_registry.h"
#include "stop_signals.h"
#include "plslam/core/error.h"
#include "plslam/core/stopwatch.h"
#include "plslam/viz/scene_document.h"
#include "plslam/viz/viewer_server.h"

namespace plslam::cli {
namespace {

namespace fs = std::filesystem;

struct ViewArgs {
  std::string target;
  viz::ViewerServerOptions server;
  std::string assets;
};

int run_view(const ViewArgs& args) {
  app::install_stop_signals();
  auto options = args.server;
  options.assets = args.assets;
  options.validate();  // a bad port or missing page before the map is read
  const fs::path target = args.target;
  std::error_code ec;
  const auto t0 = std::chrono::steady_clock::now();
  const auto scene = fs::is_directory(target, ec) ? viz::scene_from_run_folder(target)
                                                  : viz::scene_from_map_file(target);
  const auto document = viz::scene_document(scene.map, scene.info).dump();
  viz::ViewerServer server(options);
  server.publish(document, scene.info.revision);
  spdlog::info("{}: {} keyframes, {} points, {} lines ({:.1f} MB document, {:.0f} ms); Ctrl-C stops",
               target.string(), scene.map.keyframes.size(), scene.map.points.size(), scene.map.lines.size(),
               static_cast<double>(document.size()) / 1e6, ms_since(t0));
  std::cout << "viewer: " << server.url() << std::endl;
  while (!app::stop_requested()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  server.stop();
  return 0;
}

CommandRegistration register_view_command({"view", "Serve the browser map viewer for a run folder or a saved map",
                         [](CLI::App& sub) {
                           auto args = std::make_shared<ViewArgs>();
                           sub.add_option("target", args->target, "A folder `plslam run --out` wrote, or a .plmap")
                               ->required();
                           sub.add_option("--port", args->server.port, "TCP port (0: any free one)")
                               ->capture_default_str();
                           sub.add_option("--host", args->server.host,
                                          "Address to serve on; 0.0.0.0 serves every network, an explicit choice")
                               ->capture_default_str();
                           sub.add_option("--assets", args->assets, "The page's folder (default: the built one)");
                           return std::function<int()>([args] { return run_view(*args); });
                         }});

}  // namespace
}  // namespace plslam::cli
