// `uh serve`'s server over real sockets on loopback: Beast clients speak the protocol of
// docs/protocol.md to a Server in this process. The happy path runs the default scene; every
// error and fault path of the protocol is driven from the client side.

#include "uh/service/server.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iterator>
#include <optional>
#include <set>
#include <thread>

#include <sys/stat.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include "mesh_binary.hpp"
#include "protocol.hpp"
#include "haply_standin.hpp"
#include "service_test_support.hpp"
#include "test_paths.hpp"
#include "uh/collette/mesh_import.hpp"
#include "web_socket_test_client.hpp"

namespace uh::service {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using nlohmann::json;
using namespace std::chrono_literals;

using test_support::Client;
using test_support::http_get;

constexpr std::string_view kPage = "<!doctype html><title>test page</title>";

class ServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::scratch("server");
    scene_ = testing::write_small_scene(dir_);
    start_server({});
  }
  void TearDown() override {
    server_.reset();
    std::filesystem::remove_all(dir_);
  }
  void start_server(std::string token) {
    server_.reset();
    ServerOptions options{.host = "127.0.0.1", .port = 0, .token = std::move(token)};
    options.files = {{.path = "/index.html", .content_type = "text/html", .body = kPage}};
    options.cache_dir = UH_TEST_CACHE_DIR;
    options.working_dir = dir_;
    auto s = Server::start(std::move(options));
    ASSERT_TRUE(s.has_value()) << s.error().message;
    server_ = std::move(s).value();
  }
  std::uint16_t port() const { return server_->port(); }

  std::filesystem::path dir_;
  std::filesystem::path scene_;
  std::unique_ptr<Server> server_;
};

TEST_F(ServerTest, HelloIsAnsweredWithTheVersionAndEchoesTheId) {
  Client c(port());
  c.send({{"type", "hello"}, {"protocol", 1}, {"id", 17}});
  const json w = c.expect("welcome");
  EXPECT_EQ(w["id"], 17);
  EXPECT_EQ(w["protocol"], 1);
  EXPECT_FALSE(w["version"].get<std::string>().empty());
  EXPECT_EQ(w["max_message_bytes"], 1 << 20);
  EXPECT_TRUE(w["session"].is_null());
  const json p = c.request({{"type", "ping"}, {"id", "p"}}, "pong");
  EXPECT_EQ(p["id"], "p");
}

TEST_F(ServerTest, BadRequestsGetErrorsAndTheConnectionStaysUsable) {
  Client c(port());
  // before hello, only hello
  const json early = c.request({{"type", "ping"}, {"id", 1}}, "error");
  EXPECT_NE(early["message"].get<std::string>().find("send hello first"), std::string::npos) << early;
  EXPECT_EQ(early["id"], 1);
  const json wrong_version = c.request({{"type", "hello"}, {"protocol", 2}}, "error");
  EXPECT_NE(wrong_version["message"].get<std::string>().find("protocol 2 is not supported"),
            std::string::npos);
  c.hello();

  struct Case {
    std::string text;
    std::string expected;
  };
  const Case cases[] = {
      {R"({"type":"ping")", "not valid JSON"},
      {R"({"type":"teleport","id":3})", "unknown message type 'teleport'"},
      {R"({"type":"subscribe","rate_hz":"fast"})", "field 'rate_hz': expected a number, got string"},
      {R"({"type":"open","scene":"no_such_scene.json"})", "no_such_scene.json: cannot open the scene file"},
      {R"({"type":"start"})", "no scene is open"},
      {R"({"type":"get_scene"})", "no scene is open"},
      {R"({"type":"hello","protocol":1})", "already said hello"},
  };
  for (const Case& k : cases) {
    c.send_text(k.text);
    const json e = c.expect("error");
    EXPECT_NE(e["message"].get<std::string>().find(k.expected), std::string::npos) << k.text << " -> " << e;
  }
  c.send_binary(std::string("\x00\x01\x02", 3));
  EXPECT_NE(c.expect("error")["message"].get<std::string>().find("none did, so this frame was dropped"),
            std::string::npos);
  c.request({{"type", "ping"}}, "pong");
}

TEST_F(ServerTest, AMessageAboveTheLimitClosesTheConnectionCleanly) {
  Client c(port());
  c.hello();
  c.send_text(R"({"type":"get_mesh","object":")" + std::string(kMaxMessageBytes, 'a') + "\"}");
  beast::error_code ended;
  EXPECT_FALSE(c.read(&ended).has_value());
  EXPECT_EQ(ended, websocket::error::closed) << ended.message();
  EXPECT_EQ(c.close_reason().code, websocket::close_code::too_big);
  // the service goes on for others
  Client other(port());
  other.hello();
}

TEST_F(ServerTest, ATokenIsRequiredWhenConfiguredAndOffLoopback) {
  auto refused = Server::start({.host = "0.0.0.0", .port = 0});
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().message.find("not a loopback address"), std::string::npos)
      << refused.error().message;
  auto bad_host = Server::start({.host = "my-laptop", .port = 0});
  ASSERT_FALSE(bad_host.has_value());
  EXPECT_NE(bad_host.error().message.find("not an IP address"), std::string::npos);

  start_server("s3cret");
  {
    Client c(port());
    const json e = c.request({{"type", "hello"}, {"protocol", 1}}, "error");
    EXPECT_NE(e["message"].get<std::string>().find("needs a token"), std::string::npos) << e;
    beast::error_code ended;
    EXPECT_FALSE(c.read(&ended).has_value());
    EXPECT_EQ(c.close_reason().code, websocket::close_code::policy_error);
  }
  {
    Client c(port());
    c.request({{"type", "hello"}, {"protocol", 1}, {"token", "guess"}}, "error");
    EXPECT_FALSE(c.read().has_value());
  }
  Client c(port());
  c.hello("s3cret");
  c.request({{"type", "ping"}}, "pong");
}

// A scene or mesh path that is a FIFO, a device or a directory is an error naming it; the network
// thread never blocks on one (a FIFO without a writer stalled every client) nor reads one without
// end (/dev/zero grew the server by gigabytes), and a directory mesh never reaches the packing
// (which aborted the server at start).
TEST_F(ServerTest, PathsThatAreNotRegularFilesAreRefusedWithoutStoppingOthers) {
  const auto fifo = dir_ / "scene-pipe.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  Client c(port());
  c.hello();
  Client other(port());
  other.hello();
  const json from_fifo = c.request({{"type", "open"}, {"scene", fifo.string()}}, "error");
  EXPECT_NE(from_fifo["message"].get<std::string>().find("is a FIFO (named pipe), not a file"),
            std::string::npos)
      << from_fifo;
  other.request({{"type", "ping"}}, "pong");
  const json from_dir = c.request({{"type", "open"}, {"scene", dir_.string()}}, "error");
  EXPECT_NE(from_dir["message"].get<std::string>().find("is a directory, not a file"), std::string::npos);
  c.request({{"type", "open"}, {"scene", scene_.string()}}, "opened");
  // named relative to the server's root folder (dir_)
  for (const auto& [mesh, named] : {std::pair{dir_.string(), std::string(".")},
                                    std::pair{fifo.string(), std::string("scene-pipe.json")}}) {
    const json e =
        c.request({{"type", "add_object"}, {"object", {{"name", "bad"}, {"mesh", mesh}}}}, "error");
    EXPECT_NE(e["message"].get<std::string>().find("field 'objects[1].mesh': " + named + ": is a"),
              std::string::npos)
        << e;
  }
  const json tool = c.request({{"type", "set_tool"}, {"tool", {{"mesh", dir_.string()}}}}, "error");
  EXPECT_NE(tool["message"].get<std::string>().find("is a directory, not a file"), std::string::npos) << tool;
  other.request({{"type", "ping"}}, "pong");
  std::filesystem::remove(fifo);
}

// A client names files in the server's root folder (ServerOptions::working_dir, `uh serve --root`)
// and its cache only: a scene, a mesh, an .ist, a device's trajectory outside it, a scene inside
// that names a mesh outside, a link inside that points outside and /dev/zero are refused before
// any of them is opened (a missing file outside is refused alike), named relative to the root; no error shows
// the root's or the cache's absolute path. With allow_any_path (`--allow-any-path`) the same scene opens.
TEST_F(ServerTest, PathsOutsideTheRootAreRefusedNamedRelativeToIt) {
  const std::filesystem::path outside = testing::scratch("server-outside");
  const std::filesystem::path outside_scene = testing::write_small_scene(outside);
  const std::string outside_mesh = (outside / "meshes" / "bunny_npm_3674.obj").string();
  const std::string outside_named = "../" + outside.filename().string();
  std::filesystem::create_symlink(outside_mesh, dir_ / "link.obj");
  // a scene inside the root whose mesh is outside it
  std::string reaching;
  {
    std::ifstream in(scene_);
    reaching.assign(std::istreambuf_iterator<char>(in), {});
  }
  reaching.replace(reaching.find("meshes/bunny_npm_3674.obj"),
                   std::string("meshes/bunny_npm_3674.obj").size(), outside_mesh);
  std::ofstream(dir_ / "reaching.json") << reaching;
  Client c(port());
  c.hello();
  const auto refused = [&](const json& request, const std::string& expected) {
    const std::string message = c.request(request, "error")["message"].get<std::string>();
    EXPECT_NE(message.find(expected + "' is outside the folders this server reads from"), std::string::npos)
        << request << " -> " << message;
    EXPECT_EQ(message.find(dir_.string()), std::string::npos) << message;
  };
  refused({{"type", "open"}, {"scene", outside_scene.string()}}, "scene '" + outside_named + "/small.json");
  refused({{"type", "open"}, {"scene", "/dev/zero"}}, "scene '../../dev/zero");
  const std::string far_bunny = outside_named + "/meshes/bunny_npm_3674.obj";
  refused({{"type", "open"}, {"scene", "reaching.json"}}, "field 'objects[0].mesh': '" + far_bunny);
  c.request({{"type", "open"}, {"scene", scene_.filename().string()}}, "opened");
  const json mesh = {{"name", "far"}, {"mesh", outside_mesh}, {"spheres", 100}, {"meters_per_unit", 0.01}};
  refused({{"type", "add_object"}, {"object", mesh}}, "field 'objects[1].mesh': '" + far_bunny);
  refused(
      {{"type", "add_object"},
       {"object", {{"name", "up"}, {"mesh", "../" + outside.filename().string() + "/meshes/stylus.obj"}}}},
      "field 'objects[1].mesh': '" + outside_named + "/meshes/stylus.obj");
  refused({{"type", "add_object"}, {"object", {{"name", "link"}, {"mesh", "link.obj"}}}},
          "field 'objects[1].mesh': '" + far_bunny);
  // a file outside that does not exist is refused the same way: nothing tells what is there
  refused({{"type", "add_object"}, {"object", {{"name", "tree"}, {"ist", (outside / "none.ist").string()}}}},
          "field 'objects[1].ist': '" + outside_named + "/none.ist");
  refused({{"type", "set_tool"}, {"tool", {{"mesh", outside_mesh}}}}, "field 'tool.mesh': '" + far_bunny);
  refused({{"type", "set_device"},
           {"device", {{"driver", "sim-replay"}, {"config", {{"file", (outside / "moves.csv").string()}}}}}},
          "field 'tool.device.config.file': '" + outside_named + "/moves.csv");
  // a file inside, missing: named relative to the root, without the root's path
  const std::string missing = c.request(
      {{"type", "add_object"}, {"object", {{"name", "gone"}, {"mesh", "gone.obj"}}}}, "error")["message"];
  EXPECT_NE(missing.find("field 'objects[1].mesh': file not found: gone.obj"), std::string::npos) << missing;
  EXPECT_EQ(missing.find(dir_.string()), std::string::npos) << missing;
  // the refused edits left the scene as it was
  EXPECT_EQ(c.request({{"type", "get_scene"}}, "scene")["scene"]["objects"].size(), 1u);

  // the same server with allow_any_path opens the scene outside
  server_.reset();
  ServerOptions options{.host = "127.0.0.1", .port = 0, .cache_dir = UH_TEST_CACHE_DIR, .working_dir = dir_};
  options.allow_any_path = true;
  auto any = Server::start(std::move(options));
  ASSERT_TRUE(any.has_value()) << any.error().message;
  Client d((*any)->port());
  d.hello();
  d.request({{"type", "open"}, {"scene", outside_scene.string()}}, "opened");
  d.request({{"type", "open"}, {"scene", "reaching.json"}}, "opened");
  std::filesystem::remove_all(outside);
}

// Before a successful hello the service holds nothing large for a client: an add_object that
// announces a binary frame does not raise the frame limit (a 2 MiB frame is closed with 1009, as
// any message above the limit), and a client that sends many messages without a hello is closed.
TEST_F(ServerTest, NothingLargeIsHeldForAClientBeforeItsHello) {
  start_server("s3cret");
  {
    Client c(port());
    c.send({{"type", "add_object"},
            {"object", {{"name", "x"}}},
            {"mesh_binary", {{"vertices", 100000}, {"triangles", 100000}}}});
    EXPECT_NE(c.expect("error")["message"].get<std::string>().find("send hello first"), std::string::npos);
    // the server closes (1009) as soon as it reads the frame's header: the rest of the frame may
    // meet a closed socket, so a failed write is that close too
    try {
      c.send_binary(std::string(2400000, '\0'));
    } catch (const boost::system::system_error&) {
    }
    beast::error_code ended;
    while (c.read(&ended)) {
    }
    EXPECT_TRUE(c.close_reason().code == websocket::close_code::too_big || ended)
        << "the connection ended: " << ended.message();
  }
  {
    Client c(port());
    try {
      for (int i = 0; i < 40; ++i) c.send({{"type", "ping"}});
    } catch (const boost::system::system_error&) {
      // closed after the 16th
    }
    int errors = 0;
    beast::error_code ended;
    while (c.read(&ended)) ++errors;
    EXPECT_EQ(errors, 16) << "each early message is answered until the connection is closed";
    EXPECT_EQ(c.close_reason().code, websocket::close_code::policy_error);
    EXPECT_EQ(c.close_reason().reason, "too many messages before hello");
  }
  // a wrong token closes at once; what the client sends after it is not read
  {
    Client c(port());
    c.send({{"type", "hello"}, {"protocol", 1}, {"token", "guess1"}});
    c.send({{"type", "hello"}, {"protocol", 1}, {"token", "s3cret"}});
    EXPECT_NE(c.expect("error")["message"].get<std::string>().find("wrong token"), std::string::npos);
    beast::error_code ended;
    EXPECT_FALSE(c.read(&ended).has_value()) << "the second hello is not answered";
    EXPECT_EQ(c.close_reason().code, websocket::close_code::policy_error);
  }
  Client c(port());
  c.hello("s3cret");
}

// A bounded number of connections: one more gets HTTP 503 naming the limit; a freed place is
// served again.
TEST_F(ServerTest, ConnectionsBeyondTheLimitAreRefusedWithAClearAnswer) {
  server_.reset();
  ServerOptions options{.host = "127.0.0.1", .port = 0, .max_connections = 3};
  options.cache_dir = UH_TEST_CACHE_DIR;
  auto s = Server::start(std::move(options));
  ASSERT_TRUE(s.has_value()) << s.error().message;
  server_ = std::move(s).value();
  auto first = std::make_unique<Client>(port());
  first->hello();
  Client second(port()), third(port());
  second.hello();
  third.hello();
  const auto [status, body] = http_get(port(), "/");
  EXPECT_EQ(status, 503u);
  EXPECT_EQ(body, "uh serve: too many connections (the limit is 3); try again later\n");
  first.reset();
  // the server notices the closed connection on its own thread: wait for the place, bounded
  const auto deadline = std::chrono::steady_clock::now() + test_support::kPatience;
  unsigned again = 503;
  while (again == 503 && std::chrono::steady_clock::now() < deadline) {
    again = http_get(port(), "/").first;
    if (again == 503) std::this_thread::sleep_for(10ms);
  }
  EXPECT_EQ(again, 404u) << "served again (this server has no page)";
}

// get_mesh asked over and over by a client that does not read is refused once its replies pile up,
// instead of the server growing its queue (and closing it) or spending its thread on it; another
// client's state stream goes on.
TEST_F(ServerTest, AGetMeshFloodIsBoundedAndOthersKeepTheirStream) {
  Client watcher(port());
  watcher.hello();
  Client c(port());
  c.hello();
  c.request({{"type", "open"}}, "opened");  // the default scene: a reply of about 140 kB
  // 200 replies (28 MB) are more than the 8 MiB bound and the kernel's socket buffers together
  constexpr int kRequests = 200;
  watcher.request({{"type", "subscribe"}, {"rate_hz", 50}}, "subscribed");
  c.request({{"type", "start"}}, "started");
  for (int i = 0; i < kRequests; ++i) c.send({{"type", "get_mesh"}, {"object", "bunny"}, {"id", i}});
  for (int i = 0; i < 20; ++i) watcher.expect("state");
  int meshes = 0, refused = 0;
  while (meshes + refused < kRequests) {
    const auto m = c.read();
    ASSERT_TRUE(m.has_value()) << "the flooding client stays connected";
    if ((*m)["type"] == "mesh") {
      EXPECT_EQ((*m)["id"], meshes + refused);
      EXPECT_EQ((*m)["object"], "bunny");
      ++meshes;
    } else if ((*m)["type"] == "error") {
      EXPECT_NE((*m)["message"].get<std::string>().find("read them before asking for another mesh"),
                std::string::npos)
          << *m;
      ++refused;
    }
  }
  EXPECT_GE(meshes, 1);
  EXPECT_GE(refused, 1);
  // once read, it may ask again
  const json again = c.request({{"type", "get_mesh"}, {"object", "bunny"}, {"id", "again"}}, "mesh");
  EXPECT_EQ(again["id"], "again");
  EXPECT_GT(again["triangles"].size(), 10000u);
}

// An inline mesh is the scene's own: its file (and its packing cache) goes when the scene closes,
// so that clients cannot fill the service's disk.
TEST_F(ServerTest, AnInlineMeshFileGoesWithItsScene) {
  server_.reset();
  const auto cache = dir_ / "own-cache";
  ServerOptions options{.host = "127.0.0.1", .port = 0, .cache_dir = cache, .working_dir = dir_};
  auto s = Server::start(std::move(options));
  ASSERT_TRUE(s.has_value()) << s.error().message;
  server_ = std::move(s).value();
  auto bunny = collette::load_mesh(testing::assets() / "meshes" / "bunny_npm_3674.obj");
  ASSERT_TRUE(bunny.has_value()) << bunny.error().message;
  const auto files_in = [](const std::filesystem::path& d) {
    std::error_code ec;
    std::size_t n = 0;
    for (std::filesystem::directory_iterator it(d, ec), end; !ec && it != end; it.increment(ec)) ++n;
    return n;
  };
  Client c(port());
  c.hello();
  c.request({{"type", "open"}, {"scene", scene_.string()}}, "opened");
  c.send({{"type", "add_object"},
          {"object", {{"name", "inline"}, {"spheres", 100}, {"meters_per_unit", 0.01}}},
          {"mesh_binary", {{"vertices", bunny->vertices.size()}, {"triangles", bunny->triangles.size()}}}});
  c.send_binary(encode_mesh_binary(*bunny));
  c.expect("object_added");
  EXPECT_EQ(files_in(cache / "inline-meshes"), 1u);
  c.request({{"type", "close"}}, "closed");
  EXPECT_EQ(files_in(cache / "inline-meshes"), 0u);
}

TEST_F(ServerTest, ServesThePageOverHttp) {
  EXPECT_EQ(http_get(port(), "/"), std::make_pair(200u, std::string(kPage)));
  EXPECT_EQ(http_get(port(), "/index.html?token=x").first, 200u);
  EXPECT_EQ(http_get(port(), "/nothing.js").first, 404u);
  EXPECT_EQ(http_get(port(), "/ws").first, 426u);
}

TEST_F(ServerTest, DefaultSessionRunsStreamsStateAndStopsWithTheReport) {
  Client c(port());
  c.hello();
  const json opened = c.request({{"type", "open"}, {"id", 1}}, "opened");
  EXPECT_EQ(opened["id"], 1);
  EXPECT_EQ(opened["scene"], "bunny-sweep");
  EXPECT_EQ(opened["objects"], json::array({"bunny"}));
  const json subscribed = c.request({{"type", "subscribe"}, {"rate_hz", 100}}, "subscribed");
  EXPECT_EQ(subscribed["rate_hz"], 100.0);
  const json started = c.request({{"type", "start"}, {"id", 2}}, "started");
  EXPECT_EQ(started["id"], 2);

  // the tool moves (sim-raster); states carry every documented field
  std::set<double> xs;
  double last_time = -1.0;
  for (int i = 0; i < 40; ++i) {
    const json s = c.expect("state");
    const double t = s["time_s"].get<double>();
    EXPECT_GE(t, last_time);
    last_time = t;
    ASSERT_EQ(s["tool"]["position"].size(), 3u);
    ASSERT_EQ(s["tool"]["orientation"].size(), 4u);
    ASSERT_EQ(s["force"].size(), 3u);
    ASSERT_EQ(s["torque"].size(), 3u);
    EXPECT_TRUE(s["contact_pairs"].is_number_integer());
    EXPECT_EQ(s["buttons"], 0) << "the raster script presses none";
    EXPECT_TRUE(s["haptic"]["ticks"].is_number_unsigned());
    EXPECT_TRUE(s["haptic"]["missed_deadlines"].is_number_unsigned());
    EXPECT_TRUE(s["haptic"]["rate_hz"].is_number());
    EXPECT_TRUE(s["collision"]["rate_hz"].is_number());
    double norm = 0.0;
    for (const auto& f : s["force"]) norm += f.get<double>() * f.get<double>();
    EXPECT_LE(std::sqrt(norm), 8.0 + 1e-9) << "the scene's force limit";
    xs.insert(s["tool"]["position"][0].get<double>());
  }
  EXPECT_GT(xs.size(), 5u) << "the tool's position changes between states";

  const json scene = c.request({{"type", "get_scene"}}, "scene");
  EXPECT_EQ(scene["status"], "running");
  EXPECT_EQ(scene["controlled_here"], true);
  const json mesh = c.request({{"type", "get_mesh"}, {"object", "bunny"}}, "mesh");
  EXPECT_GT(mesh["vertices"].size(), 3000u);

  const json stopped = c.request({{"type", "stop"}, {"id", 3}}, "stopped");
  EXPECT_EQ(stopped["id"], 3);
  const json& report = stopped["report"];
  EXPECT_EQ(report["scene"], "bunny-sweep");
  EXPECT_GT(report["haptic"]["ticks"].get<std::uint64_t>(), 0u);
  EXPECT_TRUE(report.contains("collision"));
  EXPECT_TRUE(report.contains("force"));
  EXPECT_EQ(c.request({{"type", "stop"}}, "error")["message"], "the session is not running");
  c.request({{"type", "close"}}, "closed");
}

// scenes/soft_block.json served: its block's mesh comes refined and marked soft, and while its ball
// presses it the states carry the block's deformed vertices, changed from rest, the top under the
// ball gone down, within the protocol's bounds.
TEST_F(ServerTest, AWatchedSoftBlockStreamsItsDeformedVertices) {
  std::filesystem::create_directories(dir_ / "scenes");
  std::filesystem::create_directories(dir_ / "assets" / "meshes");
  std::filesystem::copy_file(testing::assets().parent_path() / "scenes" / "soft_block.json",
                             dir_ / "scenes" / "soft_block.json");
  for (const char* mesh : {"block.obj", "ball.obj"})
    std::filesystem::copy_file(testing::assets() / "meshes" / mesh, dir_ / "assets" / "meshes" / mesh);
  Client c(port());
  c.hello();
  c.request({{"type", "open"}, {"scene", "scenes/soft_block.json"}}, "opened");
  const json mesh = c.request({{"type", "get_mesh"}, {"object", "block"}}, "mesh");
  EXPECT_EQ(mesh["soft"], true);
  const std::vector<double> rest = mesh["vertices"].get<std::vector<double>>();
  ASSERT_GT(rest.size(), 3u * 1000u);  // block.obj's 8 corners, refined
  c.request({{"type", "subscribe"}, {"rate_hz", 100}}, "subscribed");
  c.request({{"type", "start"}}, "started");

  int deformed_states = 0, states = 0;
  std::uint64_t last_step = 0;
  double deepest = 0.0;
  const auto first = std::chrono::steady_clock::now();
  for (; states < 1000 && deepest < 1e-3; ++states) {
    const json st = c.expect("state");
    if (!st.contains("deformed")) continue;
    ASSERT_EQ(st["deformed"].size(), 1u);
    const json& d = st["deformed"][0];
    EXPECT_EQ(d["object"], "block");
    EXPECT_GT(d["step"].get<std::uint64_t>(), last_step) << "only a newer step is sent";
    last_step = d["step"].get<std::uint64_t>();
    const double unit = d["unit_m"].get<double>();
    const auto& v = d["vertices"];
    ASSERT_EQ(v.size(), rest.size());
    ++deformed_states;
    for (std::size_t i = 0; i + 2 < rest.size(); i += 3) {
      const bool under_ball = std::abs(rest[i + 2]) < 1e-6 && std::hypot(rest[i], rest[i + 1]) < 0.004;
      if (under_ball) deepest = std::max(deepest, rest[i + 2] - v[i + 2].get<double>() * unit);
    }
  }
  std::printf("%d states, %d with deformed vertices (last step %llu); the top under the ball %.2f mm down\n",
              states, deformed_states, static_cast<unsigned long long>(last_step), deepest * 1e3);
  // >=, as the loop stops: the vertices come quantised to unit_m, so 1 mm can come exactly
  EXPECT_GE(deepest, 1e-3);
  // at most kDeformedRateHz a second carry them (100 Hz subscribed, 30 Hz at most), counted over
  // the time they came in (a slow build, a sanitizer's, sends fewer states than subscribed)
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - first).count();
  EXPECT_LE(deformed_states, seconds * kDeformedRateHz + 2);
  c.request({{"type", "stop"}}, "stopped");
}

// The device faults while the session runs (the loopback Inverse Service answers with an error
// after 300 replies): the device was sent zero, the service ends the session by itself and tells
// its controller why, unasked, and watchers see it stopped; a new start may follow.
TEST_F(ServerTest, ASessionWhoseDeviceFaultsEndsByItselfAndItsControllerIsTold) {
  devices::testing::HaplyStandinScript failing;
  failing.fault = devices::testing::HaplyFault::kError;
  failing.fault_after = 300;
  devices::testing::HaplyStandinService haply(failing);
  Client c(port());
  c.hello();
  Client watcher(port());
  watcher.hello();
  c.request({{"type", "open"}, {"scene", scene_.filename().string()}}, "opened");
  c.request({{"type", "set_device"}, {"device", {{"driver", "haply"}, {"config", {{"url", haply.url()}}}}}},
            "device_set");
  watcher.request({{"type", "subscribe"}, {"rate_hz", 50}}, "subscribed");
  c.request({{"type", "start"}}, "started");
  const json stopped = c.expect("stopped");
  EXPECT_FALSE(stopped.contains("id")) << "unasked";
  EXPECT_EQ(stopped["reason"], "a thread of the session ended or a device faulted");
  EXPECT_NE(stopped["error"].get<std::string>().find(
                "device 'haply Inverse3 049D' faulted: the service reported an error: Inverse3 049D: the motors "
                "are too hot; it was sent zero force"),
            std::string::npos)
      << stopped["error"];
  EXPECT_GT(stopped["report"]["haptic"]["ticks"].get<int>(), 0);
  EXPECT_EQ(stopped["state"]["force"], json::array({0.0, 0.0, 0.0}));
  ASSERT_FALSE(haply.received().empty());
  EXPECT_EQ(haply.received().back(), Vec3{}) << "the last force the device was commanded";
  for (json m = watcher.expect("session"); m["status"] != "stopped"; m = watcher.expect("session")) {
  }
  // the session is open again: it may start anew (the stand-in faults again, and is told again)
  c.request({{"type", "start"}}, "started");
  EXPECT_EQ(c.expect("stopped")["reason"], "a thread of the session ended or a device faulted");
}

TEST_F(ServerTest, OneClientControlsOthersWatchAndItsDisconnectStopsTheSession) {
  Client watcher(port());
  watcher.hello();
  std::optional<Client> controller;
  controller.emplace(port());
  controller->hello();
  controller->request({{"type", "open"}, {"scene", scene_.filename().string()}}, "opened");
  EXPECT_EQ(watcher.expect("session")["status"], "opened");

  // the watcher may look, not change
  for (const json& m : {json{{"type", "open"}}, json{{"type", "start"}}, json{{"type", "stop"}},
                        json{{"type", "remove_object"}, {"name", "bunny"}}}) {
    const json e = watcher.request(m, "error");
    EXPECT_NE(e["message"].get<std::string>().find("another client controls"), std::string::npos) << e;
  }
  EXPECT_EQ(watcher.request({{"type", "get_scene"}}, "scene")["controlled_here"], false);
  watcher.request({{"type", "subscribe"}, {"rate_hz", 200}}, "subscribed");

  controller->request({{"type", "start"}}, "started");
  EXPECT_EQ(watcher.expect("state")["tool"]["position"].size(), 3u);
  // the stylus goes into the bunny within 0.5 s: the watcher is told
  const json contact = watcher.expect("contact");
  EXPECT_EQ(contact["event"], "begin");
  EXPECT_EQ(contact["object"], "bunny");
  // through the proxy, the default, which rests on the surface: its rows in contact, no overlap volume
  EXPECT_GT(contact["pairs"].get<int>(), 0);
  EXPECT_EQ(contact["volume"].get<double>(), 0.0);

  controller.reset();  // the controlling client goes away without a word
  for (;;) {
    const json m = watcher.expect("session");
    if (m["status"] == "closed") break;
  }
  // the slot is free: the watcher may now open its own session
  watcher.request({{"type", "open"}, {"scene", scene_.string()}}, "opened");
}

TEST_F(ServerTest, EditsTheSceneBeforeStartAndRefusesEditsWhileRunning) {
  Client c(port());
  c.hello();
  c.request({{"type", "open"}, {"scene", scene_.string()}}, "opened");
  const json missing =
      c.request({{"type", "add_object"}, {"object", {{"name", "b2"}, {"mesh", "missing.obj"}}}}, "error");
  EXPECT_NE(missing["message"].get<std::string>().find("file not found"), std::string::npos) << missing;
  const auto bunny = (dir_ / "meshes" / "bunny_npm_3674.obj").string();
  const json added = c.request({{"type", "add_object"},
                                {"id", 5},
                                {"object",
                                 {{"name", "b2"},
                                  {"mesh", bunny},
                                  {"spheres", 200},
                                  {"meters_per_unit", 0.01},
                                  {"pose", {{"position", {0.3, 0, 0}}}}}}},
                               "object_added");
  EXPECT_EQ(added["id"], 5);
  EXPECT_EQ(added["name"], "b2");
  c.request({{"type", "set_pose"}, {"object", "b2"}, {"pose", {{"position", {0.4, 0, 0}}}}}, "pose_set");
  c.request({{"type", "set_watch"}, {"objects", {"bunny"}}}, "watch_set");
  const json tool = c.request({{"type", "set_tool"}, {"tool", {{"force", {{"damping", 1.5}}}}}}, "tool_set");
  EXPECT_EQ(tool["name"], "stylus");
  const json rates = c.request({{"type", "set_rates"}, {"collision_hz", 250}}, "rates_set");
  EXPECT_EQ(rates["collision_hz"], 250.0);
  EXPECT_EQ(rates["haptic_hz"], 1000.0);
  const json bad_device = c.request({{"type", "set_device"}, {"device", {{"driver", 7}}}}, "error");
  EXPECT_NE(bad_device["message"].get<std::string>().find("tool.device.driver"), std::string::npos)
      << bad_device;
  const json scene = c.request({{"type", "get_scene"}}, "scene")["scene"];
  ASSERT_EQ(scene["objects"].size(), 2u);
  EXPECT_EQ(scene["objects"][1]["pose"]["position"][0], 0.4);
  EXPECT_EQ(scene["objects"][1]["watched"], false);

  c.request({{"type", "start"}}, "started");
  const json refused = c.request({{"type", "remove_object"}, {"name", "b2"}}, "error");
  EXPECT_NE(refused["message"].get<std::string>().find("stop it before editing"), std::string::npos);
  c.request({{"type", "stop"}}, "stopped");
  c.request({{"type", "remove_object"}, {"name", "b2"}}, "object_removed");
  // a stopped session starts again, as a new run of the edited scene
  c.request({{"type", "start"}, {"seconds", 0.2}}, "started");
  const json stopped = c.expect("stopped");
  EXPECT_EQ(stopped["reason"], "the session's seconds elapsed");
  EXPECT_GT(stopped["report"]["haptic"]["ticks"].get<std::uint64_t>(), 0u);
}

TEST_F(ServerTest, AnInlineMeshInABinaryFrameBecomesAnObjectThatTheSessionFeels) {
  auto bunny = collette::load_mesh(testing::assets() / "meshes" / "bunny_npm_3674.obj");
  ASSERT_TRUE(bunny.has_value()) << bunny.error().message;
  const std::string frame = encode_mesh_binary(*bunny);
  const json counts = {{"vertices", bunny->vertices.size()}, {"triangles", bunny->triangles.size()}};
  Client c(port());
  c.hello();
  // the scene's own bunny is replaced by the same mesh sent inline, where the tool goes
  c.request({{"type", "open"}, {"scene", scene_.string()}}, "opened");
  const auto add = [&](const std::string& name, const json& mesh_binary) {
    return json{{"type", "add_object"},
                {"id", name},
                {"object",
                 {{"name", name},
                  {"spheres", 400},
                  {"meters_per_unit", 0.01},
                  {"pose", {{"rotation", {0.70710678, 0.70710678, 0, 0}}}}}},
                {"mesh_binary", mesh_binary}};
  };
  c.send(add("inline", counts));
  c.send_binary(frame);
  const json added = c.expect("object_added");
  EXPECT_EQ(added["id"], "inline");
  EXPECT_EQ(added["name"], "inline");
  EXPECT_EQ(added["mesh"]["vertices"], bunny->vertices.size());
  EXPECT_EQ(added["mesh"]["triangles"], bunny->triangles.size());
  c.request({{"type", "remove_object"}, {"name", "bunny"}}, "object_removed");
  const json mesh = c.request({{"type", "get_mesh"}, {"object", "inline"}}, "mesh");
  EXPECT_EQ(mesh["triangles"].size(), 3 * bunny->triangles.size());
  EXPECT_NEAR(mesh["vertices"][0].get<double>(), 0.01 * bunny->vertices[0].x, 1e-8)
      << "float32 in mesh units";

  // every bad frame is an error naming the request, and nothing is added
  std::string wrong_size = frame;
  wrong_size.pop_back();
  c.send(add("short", counts));
  c.send_binary(wrong_size);
  json e = c.expect("error");
  EXPECT_EQ(e["id"], "short");
  EXPECT_NE(e["message"].get<std::string>().find("add_object 'short': the binary frame has"),
            std::string::npos)
      << e;
  std::string bad_index = frame;
  bad_index.replace(bad_index.size() - 4, 4, std::string("\xff\xff\x00\x00", 4));
  c.send(add("far", counts));
  c.send_binary(bad_index);
  e = c.expect("error");
  EXPECT_NE(e["message"].get<std::string>().find("uses vertex 65535, but there are only"), std::string::npos)
      << e;
  // a mesh that is not closed: the closed-mesh rule of mesh files
  json open_counts = counts;
  open_counts["triangles"] = bunny->triangles.size() - 1;
  c.send(add("open", open_counts));
  c.send_binary(frame.substr(0, frame.size() - 12));
  e = c.expect("error");
  EXPECT_NE(e["message"].get<std::string>().find("add_object 'open' (mesh_binary): mesh is not closed"),
            std::string::npos)
      << e;
  // the announced frame must come next: a text message instead fails the add, then is answered
  c.send(add("late", counts));
  c.send({{"type", "ping"}, {"id", "p"}});
  e = c.expect("error");
  EXPECT_EQ(e["id"], "late");
  EXPECT_NE(e["message"].get<std::string>().find("must be the next message"), std::string::npos) << e;
  EXPECT_EQ(c.expect("pong")["id"], "p");
  // a refused announcement owns its frame too: one error, and the frame is not taken for another
  c.send(add("inline", {{"vertices", 2}, {"triangles", 4}}));
  c.send_binary(frame);
  e = c.expect("error");
  EXPECT_NE(e["message"].get<std::string>().find("mesh_binary.vertices"), std::string::npos) << e;
  const json scene = c.request({{"type", "get_scene"}}, "scene")["scene"];
  ASSERT_EQ(scene["objects"].size(), 1u) << scene;
  EXPECT_EQ(scene["objects"][0]["name"], "inline");

  // the session feels the inline bunny; while it runs, set_pose moves it
  c.request({{"type", "subscribe"}, {"rate_hz", 50}}, "subscribed");
  c.request({{"type", "start"}}, "started");
  const json contact = c.expect("contact");
  EXPECT_EQ(contact["object"], "inline");
  // through the proxy the contact begins on the collision step the proxy lands; the haptic thread
  // renders its force a tick or more later (on a sanitizer's build, many): wait for a state with it
  bool felt = false;
  for (int states = 0; states < 500 && !felt; ++states) {
    const json st = c.expect("state");
    for (const auto& f : st["force"]) felt = felt || std::abs(f.get<double>()) > 0.0;
  }
  EXPECT_TRUE(felt) << "no state with a force in 10 s of them";
  c.request({{"type", "set_pose"}, {"object", "inline"}, {"pose", {{"position", {0.5, 0, 0}}}}}, "pose_set");
  const json refused = c.request({{"type", "remove_object"}, {"name", "inline"}}, "error");
  EXPECT_NE(refused["message"].get<std::string>().find("stop it before editing"), std::string::npos);
  const json stopped = c.request({{"type", "stop"}}, "stopped");
  EXPECT_GT(stopped["report"]["force"]["max_n"].get<double>(), 0.0) << stopped["report"]["force"];
  EXPECT_EQ(stopped["state"]["force"], json::array({0.0, 0.0, 0.0})) << "zero force after the stop";
  EXPECT_GT(stopped["state"]["haptic"]["ticks"].get<std::uint64_t>(), 0u);
  const json moved = c.request({{"type", "get_scene"}}, "scene")["scene"];
  EXPECT_EQ(moved["objects"][0]["pose"]["position"][0], 0.5);
}

TEST_F(ServerTest, AnAnnouncedFrameLargerThanTheTextLimitIsRead) {
  // 100,000 vertices and triangles: 2.4 MB, above the 1 MiB of text messages; a grid of that size
  // is not closed, so the reply is the closed-mesh error, which shows the frame was read whole
  collette::TriangleMesh grid;
  for (int i = 0; i < 100000; ++i) grid.vertices.push_back(Vec3{double(i % 300), double(i / 300), 0.0});
  for (int t = 0; t < 100000; ++t) grid.triangles.push_back({t % 99000, t % 99000 + 1, t % 99000 + 300});
  Client c(port());
  c.hello();
  c.request({{"type", "open"}, {"scene", scene_.string()}}, "opened");
  c.send({{"type", "add_object"},
          {"object", {{"name", "grid"}}},
          {"mesh_binary", {{"vertices", 100000}, {"triangles", 100000}}}});
  c.send_binary(encode_mesh_binary(grid));
  const json e = c.expect("error");
  EXPECT_NE(e["message"].get<std::string>().find("add_object 'grid' (mesh_binary)"), std::string::npos) << e;
  EXPECT_EQ(e["message"].get<std::string>().find("binary frame has"), std::string::npos) << e;
  c.request({{"type", "ping"}}, "pong");
}

TEST_F(ServerTest, AStartThatCannotBuildTheSessionIsAnError) {
  Client c(port());
  c.hello();
  c.request({{"type", "open"}, {"scene", scene_.string()}}, "opened");
  c.request({{"type", "set_device"}, {"device", {{"driver", "no-such-device"}}}}, "device_set");
  const json e = c.request({{"type", "start"}, {"id", 9}}, "error");
  EXPECT_EQ(e["id"], 9);
  EXPECT_NE(e["message"].get<std::string>().find("no-such-device"), std::string::npos) << e;
  c.request({{"type", "set_device"}, {"device", {{"driver", "sim-line"}}}}, "device_set");
  c.request({{"type", "start"}}, "started");
}

TEST_F(ServerTest, StoppingTheServerStopsTheSessionAndClosesClients) {
  Client c(port());
  c.hello();
  c.request({{"type", "open"}, {"scene", scene_.string()}}, "opened");
  c.request({{"type", "start"}}, "started");
  server_->stop();
  beast::error_code ended;
  for (;;) {
    if (!c.read(&ended)) break;
  }
  EXPECT_EQ(c.close_reason().code, websocket::close_code::going_away);
}

}  // namespace
}  // namespace uh::service
