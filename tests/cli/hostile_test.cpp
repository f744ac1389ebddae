// The `uh` program against what a hostile local user or client sends it, each program a child
// process over real sockets and signals: paths that are no regular files, `uh serve` stopped by
// SIGHUP while a session runs, `uh museum serve` guessed at and fed control bytes for its log.

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "child_process.hpp"
#include "test_paths.hpp"
#include "web_socket_test_client.hpp"

namespace uh {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using test_support::ChildProcess;
using test_support::Client;
using test_support::json;
using Clock = std::chrono::steady_clock;

class HostileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("uh-hostile-test-{}", ::getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  std::unique_ptr<ChildProcess> uh(std::vector<std::string> args, const std::string& name) {
    args.insert(args.begin(), UH_CLI_PATH);
    return std::make_unique<ChildProcess>(
        args, std::vector<std::string>{"UH_CACHE_DIR=" + std::string(UH_TEST_CACHE_DIR), "CI=1"},
        dir_ / (name + ".out"), dir_ / (name + ".err"));
  }

  // The port a server printed after `prefix` ("...ws://127.0.0.1:PORT/ws"); 0 if it never did.
  static std::uint16_t wait_for_port(ChildProcess& server, const std::string& prefix) {
    const auto give_up = Clock::now() + test_support::kPatience;
    while (Clock::now() < give_up && server.running()) {
      const std::string out = server.out();
      const std::size_t at = out.find(prefix);
      if (at != std::string::npos) {
        const std::size_t digits = at + prefix.size(), end = out.find("/ws", digits);
        if (end != std::string::npos && end > digits && end - digits <= 5) {
          unsigned value = 0;
          for (std::size_t i = digits; i < end; ++i) value = value * 10 + static_cast<unsigned>(out[i] - '0');
          return static_cast<std::uint16_t>(value);
        }
      }
      std::this_thread::sleep_for(20ms);
    }
    return 0;
  }

  // a small scene whose bunny mesh is `mesh`
  fs::path write_scene(const std::string& mesh) {
    const fs::path meshes = fs::path(UH_TEST_DATA_DIR) / "meshes";
    const fs::path scene = dir_ / "scene.json";
    std::ofstream(scene) << fmt::format(R"({{
  "name": "hostile",
  "seconds": 60,
  "objects": [{{ "name": "bunny", "mesh": "{0}", "meters_per_unit": 0.01, "spheres": 300 }}],
  "tool": {{ "name": "stylus", "mesh": "{1}", "meters_per_unit": 0.01, "spheres": 100,
            "device": {{ "driver": "sim-line", "config": {{ "start": [0, 0, 0.1], "end": [0, 0, 0.05], "duration_s": 0.5, "bounce": true }} }} }}
}})",
                                        mesh, (meshes / "stylus.obj").string());
    return scene;
  }

  fs::path dir_;
};

// A scene whose mesh is a directory aborted `uh run` (an uncaught std::ios_base::failure, exit
// 134); a scene at /dev/zero was read without end. Each is an error naming the path.
TEST_F(HostileTest, RunRefusesPathsThatAreNotRegularFiles) {
  const fs::path scene = write_scene(dir_.string());
  auto run = uh({"run", scene.string(), "--no-realtime"}, "dir");
  auto finished = run->wait(120s);
  ASSERT_TRUE(finished.exited) << run->err();
  EXPECT_EQ(finished.code, 1) << run->err();
  EXPECT_NE(
      run->err().find(fmt::format("field 'objects[0].mesh': {}: is a directory, not a file", dir_.string())),
      std::string::npos)
      << run->err();
  auto zero = uh({"run", "/dev/zero", "--no-realtime"}, "zero");
  finished = zero->wait(120s);
  ASSERT_TRUE(finished.exited) << zero->err();
  EXPECT_EQ(finished.code, 1);
  EXPECT_NE(zero->err().find("/dev/zero: is a device, not a file"), std::string::npos) << zero->err();
}

// A closed terminal or SSH session (SIGHUP) ended `uh serve` at once: no zero-force stop of the
// running session, no close for its clients. It stops as on SIGINT now.
TEST_F(HostileTest, ServeStopsItsSessionAndClosesClientsOnSighup) {
  const fs::path scene = write_scene((fs::path(UH_TEST_DATA_DIR) / "meshes" / "bunny_npm_3674.obj").string());
  // the scene's meshes are in the repository, outside the server's folders
  auto serve = uh({"serve", "--port", "0", "--no-realtime", "--allow-any-path"}, "serve");
  const std::uint16_t port = wait_for_port(*serve, "listening on ws://127.0.0.1:");
  ASSERT_NE(port, 0) << serve->out() << serve->err();
  Client c(port);
  c.hello();
  c.request({{"type", "open"}, {"scene", scene.string()}}, "opened");
  c.request({{"type", "start"}}, "started");
  ASSERT_TRUE(serve->signal(SIGHUP));
  test_support::beast::error_code ended;
  bool closed = false;
  while (auto m = c.read(&ended))
    closed = closed || ((*m)["type"] == "session" && (*m)["status"] == "closed");
  EXPECT_TRUE(closed) << "the session was stopped and closed before the connection";
  EXPECT_EQ(c.close_reason().code, test_support::websocket::close_code::going_away) << ended.message();
  EXPECT_EQ(c.close_reason().reason, "the service is stopping");
  const auto finished = serve->wait(60s);
  ASSERT_TRUE(finished.exited) << "uh serve ended by the signal itself";
  EXPECT_EQ(finished.code, 0);
  EXPECT_NE(serve->out().find("uh serve: stopped"), std::string::npos) << serve->out();
}

// `uh serve` read any file a client named (a scene, a mesh, /etc/shadow as a scene). With --root
// it reads only from that folder and its cache: a scene outside is refused, named relative to the
// root; a relative path starts at the root; --allow-any-path lifts the limit.
TEST_F(HostileTest, ServeReadsOnlyFromItsRootUnlessAllowedAnyPath) {
  const fs::path root = dir_ / "root";
  fs::create_directories(root);
  const fs::path outside =
      write_scene((fs::path(UH_TEST_DATA_DIR) / "meshes" / "bunny_npm_3674.obj").string());
  auto serve = uh({"serve", "--port", "0", "--no-realtime", "--root", root.string()}, "serve-root");
  const std::uint16_t port = wait_for_port(*serve, "listening on ws://127.0.0.1:");
  ASSERT_NE(port, 0) << serve->out() << serve->err();
  {
    Client c(port);
    c.hello();
    const std::string refused =
        c.request({{"type", "open"}, {"scene", outside.string()}}, "error")["message"];
    EXPECT_EQ(refused,
              "scene '../scene.json' is outside the folders this server reads from (its root and its cache)");
    const std::string missing = c.request({{"type", "open"}, {"scene", "here.json"}}, "error")["message"];
    EXPECT_EQ(missing.find(root.string()), std::string::npos) << missing;
    EXPECT_NE(missing.find("here.json: cannot open the scene file"), std::string::npos) << missing;
  }
  ASSERT_TRUE(serve->signal(SIGTERM));
  ASSERT_TRUE(serve->wait(60s).exited);

  auto any =
      uh({"serve", "--port", "0", "--no-realtime", "--root", root.string(), "--allow-any-path"}, "serve-any");
  const std::uint16_t any_port = wait_for_port(*any, "listening on ws://127.0.0.1:");
  ASSERT_NE(any_port, 0) << any->out() << any->err();
  Client c(any_port);
  c.hello();
  c.request({{"type", "open"}, {"scene", outside.string()}}, "opened");
  ASSERT_TRUE(any->signal(SIGTERM));
  ASSERT_TRUE(any->wait(60s).exited);
}

// `uh museum serve --token`: one socket guessed 24,000 tokens in 3 s, each guess logged, and text a
// client sent reached the operator's terminal raw (forged log lines, escape sequences). A client is
// closed after three failed hellos now, and what it sent is escaped and bounded in the log.
TEST_F(HostileTest, MuseumServeLimitsTokenGuessesAndEscapesClientTextInItsLog) {
  auto serve = uh({"museum", "serve", "--port", "0", "--token", "s3cret"}, "museum");
  const std::uint16_t port = wait_for_port(*serve, "players connect to ws://127.0.0.1:");
  ASSERT_NE(port, 0) << serve->out() << serve->err();
  const std::string forged = "x\nmuseum: phantom joined\x1b[31m";
  {
    Client c(port);
    for (int i = 0; i < 50; ++i)
      c.send({{"type", "hello"}, {"protocol", 1}, {"role", "vive"}, {"token", fmt::format("guess{}", i)}});
    int answered = 0;
    test_support::beast::error_code ended;
    while (c.read(&ended)) ++answered;
    EXPECT_EQ(answered, 3) << "three failed hellos are answered, then the connection is closed";
    EXPECT_EQ(c.close_reason().code, test_support::websocket::close_code::policy_error);
  }
  {
    Client c(port);
    for (int i = 0; i < 30; ++i) c.send({{"type", forged}, {"id", i}});
    for (int i = 0; i < 30; ++i) c.expect("error");
    c.request({{"type", "hello"}, {"protocol", 1}, {"role", "watcher"}, {"token", "s3cret"}}, "welcome");
  }
  ASSERT_TRUE(serve->signal(SIGTERM));
  serve->wait(60s);
  const std::string log = serve->err();
  EXPECT_EQ(log.find('\x1b'), std::string::npos) << "no escape sequence reaches the terminal";
  EXPECT_EQ(log.find("\nmuseum: phantom joined"), std::string::npos) << "no forged line: " << log;
  EXPECT_NE(log.find("x\\x0amuseum: phantom joined\\x1b[31m"), std::string::npos) << log;
  std::size_t lines = 0;
  for (const char ch : log) lines += ch == '\n' ? 1 : 0;
  EXPECT_LE(lines, 12u) << "a few refusals per client are logged, not every one: " << log;
}

}  // namespace
}  // namespace uh
