// The viewer's HTTP server: what it serves, what it refuses, and that clients cannot stall it or
// the thread that publishes.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <httplib.h>

#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "plslam/core/error.h"
#include "plslam/viz/viewer_server.h"
#include "support/test_support.h"

namespace plslam::viz {
namespace {

namespace fs = std::filesystem;

void write_asset(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

// An asset folder with a page, and a secret file beside it that no request may reach.
struct Fixture {
  test::TempDir dir;
  fs::path assets = dir.path() / "web";
  Fixture() {
    write_asset(assets / "index.html", "<html>viewer page</html>");
    write_asset(assets / "vendor/three/build/three.module.js", "export const x = 1;");
    write_asset(dir.path() / "secret.txt", "SECRET");
    fs::create_symlink(dir.path() / "secret.txt", assets / "leak.txt");
  }
  ViewerServerOptions options() const {
    ViewerServerOptions o;
    o.port = 0;
    o.assets = assets;
    o.io_timeout = std::chrono::milliseconds(500);
    return o;
  }
};

// Sends `request` as raw bytes (no client-side normalisation of the path) and returns the reply.
std::string raw_request(int port, const std::string& request) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  EXPECT_EQ(::send(fd, request.data(), request.size(), 0), static_cast<ssize_t>(request.size()));
  std::string reply;
  char buf[4096];
  for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) reply.append(buf, static_cast<std::size_t>(n));
  ::close(fd);
  return reply;
}

TEST(ViewerServer, ServesThePageItsAssetsAndThePublishedScene) {
  Fixture f;
  ViewerServer server(f.options());
  EXPECT_EQ(server.url(), "http://127.0.0.1:" + std::to_string(server.port()) + "/");
  server.publish(R"({"revision": 3})", 3);
  httplib::Client client("127.0.0.1", server.port());
  auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_EQ(page->body, "<html>viewer page</html>");
  EXPECT_EQ(page->get_header_value("Content-Type"), "text/html; charset=utf-8");
  auto js = client.Get("/vendor/three/build/three.module.js");
  ASSERT_TRUE(js);
  EXPECT_EQ(js->status, 200);
  EXPECT_EQ(js->get_header_value("Content-Type"), "text/javascript; charset=utf-8");
  auto scene = client.Get("/api/scene");
  ASSERT_TRUE(scene);
  EXPECT_EQ(scene->body, R"({"revision": 3})");
  EXPECT_EQ(scene->get_header_value("Content-Type"), "application/json");
  // Unchanged since revision 3: nothing to send.
  auto same = client.Get("/api/scene?since=3");
  ASSERT_TRUE(same);
  EXPECT_EQ(same->status, 204);
  server.publish(R"({"revision": 4})", 4);
  auto changed = client.Get("/api/scene?since=3");
  ASSERT_TRUE(changed);
  EXPECT_EQ(changed->status, 200);
  EXPECT_EQ(changed->body, R"({"revision": 4})");
  auto missing = client.Get("/nothing.js");
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);
}

TEST(ViewerServer, AnswersOnlyGetAndHead) {
  Fixture f;
  ViewerServer server(f.options());
  httplib::Client client("127.0.0.1", server.port());
  auto head = client.Head("/");
  ASSERT_TRUE(head);
  EXPECT_EQ(head->status, 200);
  for (const auto& res : {client.Post("/api/scene", "x", "text/plain"), client.Put("/index.html", "x", "text/plain"),
                          client.Delete("/index.html")}) {
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 405);
  }
  EXPECT_EQ(test::read_file(f.assets / "index.html"), "<html>viewer page</html>");
}

TEST(ViewerServer, RefusesEveryPathOutsideTheAssetFolder) {
  Fixture f;
  ViewerServer server(f.options());
  const std::vector<std::string> attacks = {
      "/../secret.txt",         "/vendor/../../secret.txt", "/%2e%2e/secret.txt", "/%2E%2E/secret.txt",
      "/..%2fsecret.txt",       "/vendor%2f..%2f..%2fsecret.txt", "/%252e%252e/secret.txt", "/..\\secret.txt",
      "/%5c..%5csecret.txt",    "//etc/passwd", "/leak.txt",  "/./index.html", "/%00index.html",
      "/vendor/three/../../../secret.txt"};
  for (const auto& path : attacks) {
    const auto reply = raw_request(server.port(), "GET " + path + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
    EXPECT_EQ(reply.find("SECRET"), std::string::npos) << path;
    EXPECT_EQ(reply.find("root:"), std::string::npos) << path;
    EXPECT_EQ(reply.find(" 200 "), std::string::npos) << path << ": " << reply.substr(0, 40);
  }
  // The checks themselves, without the HTTP layer.
  const auto root = fs::canonical(f.assets);
  EXPECT_TRUE(asset_file(root, "/"));
  EXPECT_TRUE(asset_file(root, "/vendor/three/build/three.module.js"));
  EXPECT_FALSE(asset_file(root, "/../secret.txt"));
  EXPECT_FALSE(asset_file(root, "/leak.txt"));  // a symlink out of the folder
  EXPECT_FALSE(asset_file(root, "/vendor"));     // a folder
  EXPECT_FALSE(asset_file(root, "index.html"));  // not a request path
}

TEST(ViewerServer, APortInUseIsAOneLineInputError) {
  Fixture f;
  ViewerServer first(f.options());
  auto o = f.options();
  o.port = first.port();
  try {
    ViewerServer second(o);
    FAIL() << "a second server on the same port";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("127.0.0.1:" + std::to_string(first.port())), std::string::npos) << what;
    EXPECT_NE(what.find("in use"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos);
  }
  o.port = 70000;
  EXPECT_THROW(ViewerServer{o}, InputError);
  o.port = 0;
  o.assets = f.dir.path() / "no-such-folder";
  EXPECT_THROW(ViewerServer{o}, InputError);
}

// A client that asks for a large scene and never reads: the publisher goes on, other clients are
// served the newer documents, and the server still stops.
TEST(ViewerServer, AClientThatNeverReadsStallsNeitherThePublisherNorOtherClients) {
  Fixture f;
  ViewerServer server(f.options());
  const std::string big(32 << 20, 'x');  // far beyond the socket buffers
  server.publish(big, 1);
  std::vector<int> stalled;
  for (int i = 0; i < 3; ++i) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(server.port()));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    const std::string get = "GET /api/scene HTTP/1.1\r\nHost: x\r\n\r\n";
    ASSERT_EQ(::send(fd, get.data(), get.size(), 0), static_cast<ssize_t>(get.size()));
    stalled.push_back(fd);  // never read
  }
  for (long r = 2; r < 200; ++r) server.publish("{\"revision\": " + std::to_string(r) + "}", r);
  httplib::Client client("127.0.0.1", server.port());
  auto res = client.Get("/api/scene");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->body, "{\"revision\": 199}");
  server.stop();
  for (const int fd : stalled) ::close(fd);
}

TEST(ViewerServer, FiftyClientsConnectingAndDroppingInALoopLeaveItServing) {
  Fixture f;
  ViewerServer server(f.options());
  server.publish(std::string(1 << 20, ' ') + "{}", 1);
  std::vector<std::thread> clients;
  for (int c = 0; c < 50; ++c) {
    clients.emplace_back([port = server.port(), c] {
      for (int i = 0; i < 10; ++i) {
        const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in addr{};
        addr.sin_family = AF_INET;
        addr.sin_port = htons(static_cast<std::uint16_t>(port));
        addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 && (c + i) % 2 == 0) {
          const std::string get = "GET /api/scene HTTP/1.1\r\nHost: x\r\n\r\n";
          (void)::send(fd, get.data(), get.size(), MSG_NOSIGNAL);
          char buf[512];
          (void)::recv(fd, buf, sizeof buf, 0);  // read a little, then drop mid-answer
        }
        ::close(fd);
      }
    });
  }
  for (auto& t : clients) t.join();
  httplib::Client client("127.0.0.1", server.port());
  auto res = client.Get("/");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  server.stop();
}

}  // namespace
}  // namespace plslam::viz
