// uh::net: the one ws:// URL reader in both forms, and the one client against the host.
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <string>

#include <boost/beast/websocket/error.hpp>

#include "uh/net/web_socket_client.hpp"
#include "uh/net/web_socket_host.hpp"
#include "uh/net/ws_url.hpp"

namespace uh::net {
namespace {

using namespace std::chrono_literals;
using Received = WebSocketClient::Received;

// the museum client's form (page addresses, the socket at /ws, a port required)
constexpr WsUrlForm kPageForm{.wrong_form = "the address must be ws://HOST:PORT/ws or http://HOST:PORT/",
                              .example = "ws://127.0.0.1:7780/ws",
                              .default_port = "",
                              .default_path = "/ws",
                              .page_address = true};

TEST(WsUrl, ReadsHostPortAndPathWithTheFormsDefaults) {
  auto full = parse_ws_url("ws://10.0.0.2:10001/inverse");
  ASSERT_TRUE(full) << full.error().message;
  EXPECT_EQ(full->host, "10.0.0.2");
  EXPECT_EQ(full->port, "10001");
  EXPECT_EQ(full->path, "/inverse");
  auto bare = parse_ws_url("ws://localhost");
  ASSERT_TRUE(bare);
  EXPECT_EQ(bare->port, "80");
  EXPECT_EQ(bare->path, "/");
  for (const char* page : {"http://127.0.0.1:7780/", "127.0.0.1:7780", "ws://127.0.0.1:7780/ws"}) {
    auto p = parse_ws_url(page, kPageForm);
    ASSERT_TRUE(p) << page << ": " << p.error().message;
    EXPECT_EQ(p->host, "127.0.0.1");
    EXPECT_EQ(p->port, "7780");
    EXPECT_EQ(p->path, "/ws") << page;
  }
}

TEST(WsUrl, SaysWhatIsWrong) {
  const std::map<std::string, std::string> plain = {
      {"http://127.0.0.1:10001", "expected ws://HOST:PORT[/PATH]"},
      {"ws://:10001/", "give the host, e.g. ws://127.0.0.1:80"},
      {"ws://127.0.0.1:port", "the port 'port' is not a number from 0 to 65535"},
      {"ws://127.0.0.1:65536", "the port '65536' is not a number from 0 to 65535"},
  };
  for (const auto& [url, message] : plain) {
    auto r = parse_ws_url(url);
    ASSERT_FALSE(r) << url;
    EXPECT_EQ(r.error().message, message);
  }
  const std::map<std::string, std::string> page = {
      {"ftp://127.0.0.1:7780/", "the address must be ws://HOST:PORT/ws or http://HOST:PORT/"},
      {"ws://127.0.0.1/ws", "give the host and the port, e.g. ws://127.0.0.1:7780/ws"},
      {"127.0.0.1:99999", "the port '99999' is not a number from 0 to 65535"},
  };
  for (const auto& [url, message] : page) {
    auto r = parse_ws_url(url, kPageForm);
    ASSERT_FALSE(r) << url;
    EXPECT_EQ(r.error().message, message);
  }
}

// Answers a text with itself, a binary frame with its size, and "bye" with a close 1008.
class EchoEndpoint final : public Endpoint {
 public:
  ClientId connect(Peer& peer) override {
    peer_ = &peer;
    return 1;
  }
  void receive(ClientId, std::string_view text) override {
    if (text == "bye") return peer_->close(1008, "asked to leave");
    peer_->send(std::string(text));
  }
  void receive_binary(ClientId, std::span<const std::byte> bytes) override {
    peer_->send("binary " + std::to_string(bytes.size()));
  }
  std::size_t message_limit(ClientId) const override { return 1 << 16; }
  void disconnect(ClientId) override { peer_ = nullptr; }
  void shutdown() override {
    if (peer_ != nullptr) peer_->close(1001, "stopping");
  }

 private:
  Peer* peer_ = nullptr;
};

class ClientTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto started = WebSocketHost::start(
        {.port = 0}, [](boost::asio::io_context&) { return std::make_unique<EchoEndpoint>(); });
    ASSERT_TRUE(started) << started.error().message;
    host_ = std::move(started).value();
  }
  WsUrl url() const { return {.host = "127.0.0.1", .port = std::to_string(host_->port()), .path = "/ws"}; }
  std::unique_ptr<WebSocketClient> connect() {
    auto c = WebSocketClient::connect(url(), {});
    EXPECT_TRUE(c) << c.error().message;
    return c ? std::move(c).value() : nullptr;
  }

  std::unique_ptr<WebSocketHost> host_;
};

TEST_F(ClientTest, SendsInOrderAndReceivesWithinItsLimit) {
  auto c = connect();
  ASSERT_TRUE(c);
  std::string got;
  EXPECT_EQ(c->receive(got, 20ms), Received::nothing) << "nothing was asked yet";
  c->send("one");
  c->send("two");
  c->send(std::string(3, '\0'), WebSocketClient::Frame::binary);
  for (const char* expected : {"one", "two", "binary 3"}) {
    ASSERT_EQ(c->receive(got, 10s), Received::message);
    EXPECT_EQ(got, expected);
  }
  EXPECT_TRUE(c->alive());
  EXPECT_TRUE(c->close(10s));
  EXPECT_FALSE(c->alive());
}

TEST_F(ClientTest, AServersCloseEndsTheConnectionWithItsReason) {
  auto c = connect();
  ASSERT_TRUE(c);
  c->send("bye");
  std::string got;
  EXPECT_EQ(c->receive(got, 10s), Received::ended);
  EXPECT_EQ(c->error(), boost::beast::websocket::error::closed) << c->error().message();
  EXPECT_EQ(c->close_reason().code, 1008);
  EXPECT_EQ(c->close_reason().reason, "asked to leave");
  c->send("ignored");
  EXPECT_FALSE(c->flush(1s));
}

TEST_F(ClientTest, ConnectingNamesTheServerAndTheStepThatFailed) {
  const WsUrl gone = url();
  host_.reset();  // nothing listens on that port now
  auto refused = WebSocketClient::connect(gone, {.name = "the echo server", .step_limit = 2s});
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message.rfind("cannot reach the echo server: ", 0), 0u)
      << refused.error().message;
  std::atomic<bool> cancel{true};
  auto cancelled = WebSocketClient::connect(gone, {.step_limit = 60s, .cancel = &cancel});
  EXPECT_FALSE(cancelled) << "a cancelled connect gives up at once";
}

}  // namespace
}  // namespace uh::net
