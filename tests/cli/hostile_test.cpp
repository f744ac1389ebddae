// The `uh` program against what a hostile local user or client sends it, each program a child
// process over real sockets and signals: paths that are no regular files, `uh serve` stopped by
// SIGHUP while a session runs, `uh museum serve` guessed at and fed control bytes for its log; both
// servers under a load of slow readers, floods and garbage.

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
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

  // `uh serve` (named `name` in the test's folder) with a session of write_scene()'s running, and
  // the client that controls it; the scene's meshes are in the repository, outside its folders
  std::pair<std::unique_ptr<ChildProcess>, std::unique_ptr<Client>> serve_a_session(const std::string& name) {
    const fs::path scene = write_scene((fs::path(UH_TEST_DATA_DIR) / "meshes" / "bunny_npm_3674.obj").string());
    auto serve = uh({"serve", "--port", "0", "--no-realtime", "--allow-any-path"}, name);
    const std::uint16_t port = wait_for_port(*serve, "listening on ws://127.0.0.1:");
    if (port == 0) throw std::runtime_error("uh serve printed no port: " + serve->out() + serve->err());
    auto c = std::make_unique<Client>(port);
    c->hello();
    c->request({{"type", "open"}, {"scene", scene.string()}}, "opened");
    c->request({{"type", "start"}}, "started");
    return {std::move(serve), std::move(c)};
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
  auto [serve, client] = serve_a_session("serve");
  Client& c = *client;
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

// ---- Load: a few hundred connections at once, slow readers, floods and garbage --------------------

// The load of docs/security.md ("Load"): what each server is given at once.
constexpr int kSlowReaders = 300;    // connect, say hello, subscribe, never read
constexpr int kFlooders = 8;         // send as fast as the server reads; half read and drop the
                                     // replies, half never read them
constexpr auto kLoadWindow = 8s;     // the honest client's stream is counted over this window
// The peak resident memory (VmHWM) each server may reach under that load [MiB]: the server with
// its session or round and the connections within 64 MiB, plus 64 MiB for each client that floods
// and never reads (the WebSocket host closes a client whose unsent replies pass 64 MiB). Why, and
// what was measured: docs/security.md, "Load". The sanitizers' shadow memory, redzones and ASan's
// 256 MiB quarantine of freed blocks come on top in their builds.
constexpr long kMemoryBoundMiB = 64 + (kFlooders / 2) * 64;
#ifdef UH_TEST_SANITIZED
constexpr long kSanitizerFactor = 3, kSanitizerExtraMiB = 256;
#else
constexpr long kSanitizerFactor = 1, kSanitizerExtraMiB = 0;
#endif

// A client frame (RFC 6455: masked; the key need not be secret for a test) with `opcode`; `masked`
// false or a `claimed_length` other than the payload's make it a frame a server must refuse.
std::string ws_frame(std::uint8_t opcode, const std::string& payload, bool masked = true,
                     std::uint64_t claimed_length = UINT64_MAX) {
  const std::uint64_t length = claimed_length == UINT64_MAX ? payload.size() : claimed_length;
  std::string f(1, static_cast<char>(0x80 | opcode));
  const int mask_bit = masked ? 0x80 : 0;
  if (length < 126) {
    f += static_cast<char>(mask_bit | static_cast<int>(length));
  } else if (length < 65536) {
    f += static_cast<char>(mask_bit | 126);
    for (int shift = 8; shift >= 0; shift -= 8) f += static_cast<char>((length >> shift) & 0xff);
  } else {
    f += static_cast<char>(mask_bit | 127);
    for (int shift = 56; shift >= 0; shift -= 8) f += static_cast<char>((length >> shift) & 0xff);
  }
  const char key[4] = {0x1b, 0x2c, 0x3d, 0x4e};
  if (masked) f.append(key, 4);
  for (std::size_t i = 0; i < payload.size(); ++i)
    f += masked ? static_cast<char>(payload[i] ^ key[i % 4]) : payload[i];
  return f;
}
std::string ws_text(const json& message) { return ws_frame(0x1, message.dump()); }

const std::string kUpgrade =
    "GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
    "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";

// A hostile client's TCP connection, bytes as they are: it may never read, write faster than the
// server reads, or send what no WebSocket client would. Non-blocking after the connect.
class RawConnection {
 public:
  RawConnection(std::uint16_t port, int receive_buffer = 0) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    if (fd_ < 0) return;
    if (receive_buffer > 0) ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
      ::close(fd_);
      fd_ = -1;
      return;
    }
    ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) | O_NONBLOCK);
  }
  ~RawConnection() {
    if (fd_ >= 0) ::close(fd_);
  }
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;

  bool open() const { return fd_ >= 0; }
  // queues `bytes` and writes what the socket takes now
  void send(const std::string& bytes) {
    pending_ += bytes;
    pump();
  }
  // writes what is queued as far as the socket takes it; false once the server closed
  bool pump() {
    while (fd_ >= 0 && !pending_.empty()) {
      const ssize_t n = ::send(fd_, pending_.data(), pending_.size(), MSG_NOSIGNAL);
      if (n < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK) return true;
        return false;
      }
      sent_ += static_cast<std::size_t>(n);
      pending_.erase(0, static_cast<std::size_t>(n));
    }
    return fd_ >= 0;
  }
  // reads and drops what came; false once the server closed
  bool drain() {
    char buffer[65536];
    for (;;) {
      const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
      if (n > 0) continue;
      return n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);
    }
  }
  // waits for the server's answer to kUpgrade (sent before): true on "101 Switching Protocols".
  // A client sends no frame before it (RFC 6455, 4.1), and the server reads none sent earlier.
  bool upgraded() {
    std::string answer;
    const auto give_up = Clock::now() + test_support::kPatience;
    while (fd_ >= 0 && answer.find("\r\n\r\n") == std::string::npos && Clock::now() < give_up) {
      pollfd readable{fd_, POLLIN, 0};
      if (::poll(&readable, 1, 100) <= 0) continue;
      char buffer[512];
      const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
      if (n <= 0) return false;
      answer.append(buffer, static_cast<std::size_t>(n));
    }
    return answer.rfind("HTTP/1.1 101 ", 0) == 0;
  }
  bool idle() const { return pending_.empty(); }
  std::size_t sent() const { return sent_; }

 private:
  int fd_;
  std::string pending_;
  std::size_t sent_ = 0;
};

// The peak resident memory of process `pid` so far (VmHWM of /proc/PID/status) in MiB; -1 if unread.
long peak_memory_mib(pid_t pid) {
  std::ifstream status(fmt::format("/proc/{}/status", pid));
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6)) / 1024;
  return -1;
}

// What no client may send, each on a connection of its own, which is then dropped: bytes that are
// no HTTP, an endless header; after the upgrade an unmasked frame, a reserved opcode, text that is
// no UTF-8, a frame announcing 2^62 bytes, JSON that is no JSON or nested 10,000 deep, random
// binary, half a frame.
void send_garbage(std::uint16_t port, std::mt19937& random) {
  std::string noise(2048, '\0');
  for (char& c : noise) c = static_cast<char>(random() & 0xff);
  for (const std::string& bytes : {noise, "GET /ws HTTP/1.1\r\nX-Long: " + std::string(200000, 'a')}) {
    RawConnection c(port);
    if (c.open()) c.send(bytes);
  }
  const std::vector<std::string> frames = {
      ws_frame(0x1, R"({"type":"ping"})", false),
      ws_frame(0x3, "reserved"),
      ws_frame(0x1, "\xc3\x28\xff"),
      ws_frame(0x2, "", true, std::uint64_t{1} << 62),
      ws_frame(0x1, "{not json"),
      ws_frame(0x1, std::string(10000, '[') + std::string(10000, ']')),
      ws_frame(0x2, noise),
      ws_frame(0x1, R"({"type":"hello","protocol":1})").substr(0, 5),
  };
  for (const std::string& bytes : frames) {
    RawConnection c(port);
    c.send(kUpgrade);
    if (c.upgraded()) c.send(bytes);
  }
}

struct LoadResult {
  std::size_t stream_messages = 0;  // of the honest client, within the window
  double window_s = 0.0;
  std::size_t flooded_bytes = 0;
  int slow_readers_connected = 0;
  int readers_kept = 0;  // flooders that read their replies and were still connected at the end
  double longest_gap_s = 0.0;
};

// The load on the server at `port` while `honest` (subscribed to its stream of `stream_type`
// messages) is counted: kSlowReaders connections that say `hello_and_subscribe` and never read,
// kFlooders sending `flood` as fast as the server reads, garbage every half second.
LoadResult load(std::uint16_t port, Client& honest, const std::string& stream_type,
                const std::string& hello_and_subscribe, const std::string& flood) {
  LoadResult result;
  std::vector<std::unique_ptr<RawConnection>> slow, flooders;
  // all upgrades first, so that the server has them at once; then each says hello and subscribes
  for (int i = 0; i < kSlowReaders; ++i) {
    slow.push_back(std::make_unique<RawConnection>(port, 4096));
    slow.back()->send(kUpgrade);
  }
  for (int i = 0; i < kFlooders; ++i) {
    flooders.push_back(std::make_unique<RawConnection>(port));
    flooders.back()->send(kUpgrade);
  }
  for (auto& c : slow) {
    if (!c->upgraded()) continue;
    c->send(hello_and_subscribe);
    ++result.slow_readers_connected;
    honest.poll(0ms);  // the honest client keeps reading while the others connect
  }
  for (auto& f : flooders)
    if (f->upgraded()) f->send(hello_and_subscribe);
  std::string burst;
  for (int i = 0; i < 64; ++i) burst += flood;
  std::mt19937 random(25);
  const auto start = Clock::now();
  auto last_message = start, next_garbage = start;
  while (Clock::now() - start < kLoadWindow && !honest.ended()) {
    for (std::size_t i = 0; i < flooders.size(); ++i) {
      if (flooders[i]->idle()) flooders[i]->send(burst);
      flooders[i]->pump();
      if (i % 2 == 0) flooders[i]->drain();
    }
    if (Clock::now() >= next_garbage) {
      send_garbage(port, random);
      next_garbage += 500ms;
    }
    while (auto m = honest.poll(2ms)) {
      if ((*m)["type"] != stream_type) continue;
      const auto now = Clock::now();
      result.longest_gap_s =
          std::max(result.longest_gap_s, std::chrono::duration<double>(now - last_message).count());
      last_message = now;
      ++result.stream_messages;
    }
  }
  result.window_s = std::chrono::duration<double>(Clock::now() - start).count();
  for (std::size_t i = 0; i < flooders.size(); i += 2) result.readers_kept += flooders[i]->drain() ? 1 : 0;
  for (auto& f : flooders) result.flooded_bytes += f->sent();
  return result;
}

std::string describe(const LoadResult& r) {
  return fmt::format(
      "{} stream messages in {:.1f} s (longest gap {:.2f} s); {} slow readers; {} kB flooded, {} reading flooders kept",
      r.stream_messages, r.window_s, r.longest_gap_s, r.slow_readers_connected, r.flooded_bytes / 1000,
      r.readers_kept);
}

// After load(): `server` is up, its peak memory within the bound, `honest` was kept and got its
// stream at half the `documented_hz` or more, and a new client's `hello` is welcomed; then it stops
// on SIGTERM. Prints what was measured, for the test command's log.
void expect_served_through(ChildProcess& server, std::uint16_t port, const Client& honest, const LoadResult& r,
                           double documented_hz, const json& hello) {
  ASSERT_TRUE(server.running()) << server.err();
  EXPECT_FALSE(honest.ended()) << "the honest client was kept";
  EXPECT_GE(r.stream_messages / r.window_s, documented_hz / 2) << describe(r);
  const long peak = peak_memory_mib(server.pid());
  EXPECT_GT(peak, 0);
  EXPECT_LE(peak, kMemoryBoundMiB * kSanitizerFactor + kSanitizerExtraMiB) << describe(r);
  Client late(port);
  late.request(hello, "welcome");
  ASSERT_TRUE(server.signal(SIGTERM));
  EXPECT_TRUE(server.wait(60s).exited);
  std::printf("%s under load: peak %ld MiB; %s\n", server.out().substr(0, server.out().find(':')).c_str(), peak,
              describe(r).c_str());
}

// `uh serve` under load: 300 clients that subscribe to the state stream and never read, 8 that flood
// it with requests, garbage every half second. It stays up, stays under its memory bound, and the
// honest client that controls the session gets its 60 Hz state stream at half that rate or more.
TEST_F(HostileTest, ServeStaysUpBoundedAndServingUnderLoad) {
  constexpr double kDocumentedStateHz = 60.0;  // subscribe's default (docs/protocol.md)
  auto [serve, client] = serve_a_session("serve-load");
  Client& honest = *client;
  honest.request({{"type", "subscribe"}}, "subscribed");
  const std::uint16_t port = wait_for_port(*serve, "listening on ws://127.0.0.1:");

  const std::string hello_and_subscribe = ws_text({{"type", "hello"}, {"protocol", 1}}) +
                                          ws_text({{"type", "subscribe"}, {"rate_hz", 1000}});
  const std::string flood = ws_text({{"type", "ping"}}) + ws_text({{"type", "get_scene"}}) +
                            ws_text({{"type", "get_mesh"}, {"object", "bunny"}});
  const LoadResult r = load(port, honest, "state", hello_and_subscribe, flood);

  expect_served_through(*serve, port, honest, r, kDocumentedStateHz, {{"type", "hello"}, {"protocol", 1}});
}

// `uh museum serve` under the same load: 300 watchers that never read, 8 flooding pings and moves
// they may not make, garbage. It stays up and bounded, and an honest watcher gets its 20 Hz
// snapshots at half that rate or more.
TEST_F(HostileTest, MuseumServeStaysUpBoundedAndServingUnderLoad) {
  constexpr double kDocumentedSnapshotHz = 20.0;  // GameServerOptions::snapshot_hz (docs/museum.md)
  auto serve = uh({"museum", "serve", "--port", "0"}, "museum-load");
  const std::uint16_t port = wait_for_port(*serve, "players connect to ws://127.0.0.1:");
  ASSERT_NE(port, 0) << serve->out() << serve->err();
  Client honest(port);
  honest.request({{"type", "hello"}, {"protocol", 1}, {"role", "watcher"}}, "welcome");

  const std::string hello = ws_text({{"type", "hello"}, {"protocol", 1}, {"role", "watcher"}});
  const std::string flood = ws_text({{"type", "ping"}}) + ws_text({{"type", "move"}, {"move", {1, 0}}});
  const LoadResult r = load(port, honest, "snapshot", hello, flood);

  expect_served_through(*serve, port, honest, r, kDocumentedSnapshotHz,
                        {{"type", "hello"}, {"protocol", 1}, {"role", "watcher"}});
}

}  // namespace
}  // namespace uh
