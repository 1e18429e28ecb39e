#include "plslam/viz/viewer_server.h"

#include <httplib.h>
#include <sys/socket.h>

#include <cstdlib>
#include <deque>
#include <fstream>
#include <iterator>
#include <mutex>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/core/thread_priority.h"

namespace plslam::viz {
namespace {

namespace fs = std::filesystem;

const char* content_type(const fs::path& file) {
  const auto ext = file.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  return "application/octet-stream";
}

bool is_inside(const fs::path& file, const fs::path& root) {
  const auto mismatch = std::mismatch(root.begin(), root.end(), file.begin(), file.end());
  return mismatch.first == root.end();
}

// Every answer goes out through a content provider of known length, which httplib sends as it is:
// a plain body would be Brotli-compressed on every request when the browser accepts it, which
// takes seconds for three.js on this kind of machine and buys nothing on a local network. The
// shared pointer keeps the text alive while httplib sends it, however long that takes.
void send(httplib::Response& res, std::shared_ptr<const std::string> text, const char* type) {
  const auto size = text->size();
  res.set_content_provider(size, type, [text](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
    return sink.write(text->data() + offset, length);
  });
}

}  // namespace

// httplib has decoded the path already, so "%2e%2e" arrives here as "..".
std::optional<fs::path> asset_file(const fs::path& canonical_root, const std::string& request_path) {
  if (request_path.empty() || request_path.front() != '/') return std::nullopt;
  if (request_path.find('\0') != std::string::npos || request_path.find('\\') != std::string::npos) {
    return std::nullopt;
  }
  const fs::path relative = request_path == "/" ? fs::path("index.html") : fs::path(request_path.substr(1));
  if (relative.is_absolute()) return std::nullopt;
  for (const auto& part : relative) {
    if (part == "." || part == "..") return std::nullopt;
  }
  std::error_code ec;
  const auto file = fs::canonical(canonical_root / relative, ec);
  if (ec || !fs::is_regular_file(file, ec) || !is_inside(file, canonical_root)) return std::nullopt;
  return file;
}

void ViewerServerOptions::validate() const {
  if (port < 0 || port > 65535) throw InputError("", fmt::format("--port {}: must be 0..65535", port));
  if (io_timeout.count() <= 0) throw InputError("", "the viewer's I/O timeout must be positive");
  const auto folder = assets.empty() ? default_asset_folder() : assets;
  std::error_code ec;
  if (!fs::is_regular_file(folder / "index.html", ec)) {
    throw InputError(folder.string(), "the viewer's page is missing (no index.html): build plslam after "
                                      "scripts/install-deps.sh, which installs three.js with npm");
  }
}

fs::path default_asset_folder() {
  if (const char* dir = std::getenv("PLSLAM_WEB_DIR"); dir && *dir) return dir;
  const fs::path build_tree = PLSLAM_WEB_BUILD_DIR;
  std::error_code ec;
  if (fs::is_regular_file(build_tree / "index.html", ec)) return build_tree;
  const auto exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto beside = exe.parent_path().parent_path() / "share/plslam/web";
    if (fs::is_regular_file(beside / "index.html", ec)) return beside;
  }
  return fs::path(PLSLAM_INSTALL_DATA_DIR) / "web";
}

struct ViewerServer::Impl {
  ViewerServerOptions options;
  fs::path root;  // canonical asset folder
  httplib::Server server;
  std::thread thread;
  int port = 0;

  // A revision's full document, made once by the first request that needs it.
  struct FullDocument {
    std::function<std::string()> make;
    std::once_flag once;
    std::string text;
    const std::string& get() {
      std::call_once(once, [this] {
        text = make();
        make = nullptr;  // frees the state it held
      });
      return text;
    }
  };
  static constexpr std::size_t kMaxDeltas = 64;  // about 13 s at 5 Hz

  std::mutex mutex;  // guards the three below
  long revision = 0;
  std::shared_ptr<FullDocument> full = std::make_shared<FullDocument>();
  std::deque<std::pair<long, std::shared_ptr<const std::string>>> deltas;  // by revision, contiguous
  std::shared_ptr<const std::string> image;  // JPEG; null before the first

  Impl() { full->make = [] { return std::string("{}"); }; }

  // What a client at `since` is sent: nothing (204), the deltas after it, or the full document.
  void answer(const httplib::Request& req, httplib::Response& res) {
    std::shared_ptr<FullDocument> document;
    std::shared_ptr<std::string> body;
    {
      std::lock_guard lock(mutex);
      document = full;
      if (req.has_param("since")) {
        const auto since = req.get_param_value("since");
        if (since == std::to_string(revision)) {
          res.status = 204;
          return;
        }
        for (std::size_t i = 0; i < deltas.size(); ++i) {
          if (std::to_string(deltas[i].first - 1) != since) continue;
          body = std::make_shared<std::string>(
              fmt::format(R"({{"type": "delta", "from": {}, "revision": {}, "deltas": [)", since, revision));
          for (std::size_t j = i; j < deltas.size(); ++j) {
            if (j > i) body->push_back(',');
            body->append(*deltas[j].second);
          }
          body->append("]}");
          break;
        }
      }
    }
    res.set_header("Cache-Control", "no-store");
    if (body) {
      send(res, std::move(body), "application/json");
      return;
    }
    // Aliases the document's text, so that it stays alive while sent even if newer revisions
    // are published meanwhile.
    send(res, std::shared_ptr<const std::string>(document, &document->get()), "application/json");
  }
};

ViewerServer::ViewerServer(ViewerServerOptions options) : impl_(std::make_unique<Impl>()) {
  options.validate();
  if (options.assets.empty()) options.assets = default_asset_folder();
  impl_->options = options;
  impl_->root = fs::canonical(options.assets);
  auto& server = impl_->server;
  const auto timeout = std::chrono::duration_cast<std::chrono::microseconds>(options.io_timeout);
  server.set_read_timeout(timeout);
  server.set_write_timeout(timeout);
  server.set_keep_alive_timeout(std::chrono::duration_cast<std::chrono::seconds>(options.io_timeout).count() + 1);
  server.set_payload_max_length(1 << 16);  // GET only: no body to read
  // httplib's default adds SO_REUSEPORT, with which a second server binds the same port silently
  // and the two share the connections: a port in use must be an error instead.
  server.set_socket_options([](socket_t sock) {
    const int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  server.set_pre_routing_handler([](const httplib::Request& req, httplib::Response& res) {
    if (req.method == "GET" || req.method == "HEAD") return httplib::Server::HandlerResponse::Unhandled;
    res.status = 405;
    res.set_header("Allow", "GET, HEAD");
    res.set_content("only GET\n", "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  });
  Impl* impl = impl_.get();
  server.Get("/api/scene", [impl](const httplib::Request& req, httplib::Response& res) { impl->answer(req, res); });
  server.Get("/api/image.jpg", [impl](const httplib::Request&, httplib::Response& res) {
    std::shared_ptr<const std::string> image;
    {
      std::lock_guard lock(impl->mutex);
      image = impl->image;
    }
    if (!image) {
      res.status = 404;
      res.set_content("no image yet\n", "text/plain");
      return;
    }
    res.set_header("Cache-Control", "no-store");
    send(res, std::move(image), "image/jpeg");
  });
  server.Get(R"(/.*)", [impl](const httplib::Request& req, httplib::Response& res) {
    const auto file = asset_file(impl->root, req.path);
    if (!file) {
      res.status = 404;
      res.set_content("not found\n", "text/plain");
      return;
    }
    std::ifstream in(*file, std::ios::binary);
    auto body = std::make_shared<const std::string>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    send(res, std::move(body), content_type(*file));
  });
  const int port = options.port == 0 ? server.bind_to_any_port(options.host)
                                     : (server.bind_to_port(options.host, options.port) ? options.port : -1);
  if (port <= 0) {
    throw InputError("", fmt::format("{}:{}: cannot serve the viewer there (the port is in use, or the host is "
                                     "not an address of this machine)",
                                     options.host, options.port));
  }
  impl_->port = port;
  impl_->thread = std::thread([impl] {
    core::name_this_thread("plslam-http");
    impl->server.listen_after_bind();
  });
  // stop() before the loop runs would not reach it: wait until it does.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!server.is_running() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

ViewerServer::~ViewerServer() { stop(); }

void ViewerServer::stop() {
  if (!impl_ || !impl_->thread.joinable()) return;
  impl_->server.stop();
  impl_->thread.join();
}

void ViewerServer::publish_image(std::string jpeg) {
  auto shared = std::make_shared<const std::string>(std::move(jpeg));
  std::lock_guard lock(impl_->mutex);
  impl_->image = std::move(shared);
}

int ViewerServer::port() const { return impl_->port; }

std::string ViewerServer::url() const { return fmt::format("http://{}:{}/", impl_->options.host, impl_->port); }

void ViewerServer::publish(std::string document, long revision) {
  auto shared = std::make_shared<const std::string>(std::move(document));
  publish(revision, [shared] { return *shared; }, {});
}

void ViewerServer::publish(long revision, std::function<std::string()> make_full, std::string delta) {
  auto full = std::make_shared<Impl::FullDocument>();
  full->make = std::move(make_full);
  auto shared_delta = delta.empty() ? nullptr : std::make_shared<const std::string>(std::move(delta));
  std::lock_guard lock(impl_->mutex);
  impl_->full = std::move(full);
  if (!shared_delta || (!impl_->deltas.empty() && impl_->deltas.back().first != revision - 1) ||
      (impl_->deltas.empty() && impl_->revision != revision - 1)) {
    impl_->deltas.clear();  // not a continuation: clients reload the full document
  }
  if (shared_delta) {
    impl_->deltas.emplace_back(revision, std::move(shared_delta));
    if (impl_->deltas.size() > Impl::kMaxDeltas) impl_->deltas.pop_front();
  }
  impl_->revision = revision;
}

}  // namespace plslam::viz
