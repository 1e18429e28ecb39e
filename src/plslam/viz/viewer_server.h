#pragma once
// The browser viewer's HTTP server (cpp-httplib): the page and its assets from one folder, and
// the scene document that the owner publishes. GET and HEAD only; a path that leaves the asset
// folder is refused. Publishing swaps a shared string under a mutex, so the SLAM threads never
// wait for a client: the server threads send the document they took, however slowly.
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace plslam::viz {

struct ViewerServerOptions {
  std::string host = "127.0.0.1";  // 0.0.0.0 serves every interface: an explicit choice
  int port = 8080;                 // 0: any free port (port() tells which)
  std::filesystem::path assets;    // holds index.html; empty: default_asset_folder()
  // A client that stops reading holds one server thread at most this long.
  std::chrono::milliseconds io_timeout{2000};

  // InputError naming what is wrong (a port outside 0..65535, an asset folder without index.html).
  void validate() const;
};

// The file a request path names inside `canonical_root`, or nullopt: a ".", ".." segment, a
// backslash or NUL, a missing file, or a symlink that leads out of the folder.
std::optional<std::filesystem::path> asset_file(const std::filesystem::path& canonical_root,
                                                const std::string& request_path);

// The page's folder in the build tree (web/ copied by CMake with three.js from npm), else the
// installed one (<prefix>/share/plslam/web); PLSLAM_WEB_DIR overrides both.
std::filesystem::path default_asset_folder();

class ViewerServer {
 public:
  // Binds at once: InputError "host:port: ..." when the port is in use or the host is not an
  // address of this machine. Then serves from its own threads until stop() or destruction.
  explicit ViewerServer(ViewerServerOptions options);
  ~ViewerServer();
  ViewerServer(const ViewerServer&) = delete;
  ViewerServer& operator=(const ViewerServer&) = delete;

  int port() const;
  std::string url() const;  // http://host:port/

  // The document GET /api/scene answers from now on; GET /api/scene?since=R answers 204 (no
  // change) while `revision` is R. Thread-safe, never blocks on a client.
  void publish(std::string document, long revision);
  // A revision whose full document is made only when a request needs it (at most once, in the
  // server thread that asks first), with the delta from the revision before it. A client at
  // revision R gets {"type": "delta", "from": R, "revision": N, "deltas": [...]} while the last
  // deltas reach back to R, else the full document. An empty delta starts over: every client
  // then loads the full document.
  void publish(long revision, std::function<std::string()> make_full, std::string delta);

  // The live camera image GET /api/image.jpg answers (404 until the first).
  void publish_image(std::string jpeg);

  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace plslam::viz
