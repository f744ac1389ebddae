#pragma once
// A WebSocket client for the tests of servers on the WebSocket host (uh serve, uh museum serve):
// uh::net's client over loopback, JSON messages, every wait bounded; and a plain HTTP GET.

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/system/system_error.hpp>
#include <nlohmann/json.hpp>

#include "uh/net/web_socket_client.hpp"

namespace uh::test_support {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using nlohmann::json;
using namespace std::chrono_literals;

// Guards against a server that never answers; not a measurement.
constexpr auto kPatience = 60s;

// A protocol client: uh::net's WebSocket client on loopback; every wait is bounded by kPatience.
class Client {
 public:
  explicit Client(std::uint16_t port) {
    auto connected =
        net::WebSocketClient::connect({.host = "127.0.0.1", .port = std::to_string(port), .path = "/ws"},
                                      {.name = "the test's server", .step_limit = kPatience});
    if (!connected) throw std::runtime_error(connected.error().message);
    client_ = std::move(connected).value();
  }

  void send(const json& message) { send_text(message.dump()); }
  /// Written before this returns, as a blocking write would; a failed write throws.
  void send_text(const std::string& text) { write(text, net::WebSocketClient::Frame::text); }
  void send_binary(const std::string& bytes) { write(bytes, net::WebSocketClient::Frame::binary); }

  /// The next message, or an error code when the connection ended.
  std::optional<json> read(beast::error_code* ended = nullptr) {
    std::string text;
    switch (client_->receive(text, kPatience)) {
      case net::WebSocketClient::Received::message:
        return json::parse(text);
      case net::WebSocketClient::Received::ended:
        if (ended != nullptr) *ended = client_->error();
        return std::nullopt;
      case net::WebSocketClient::Received::nothing:
        break;
    }
    ADD_FAILURE() << "no message within the patience limit";
    client_->drop();
    return std::nullopt;
  }

  /// The next message if one comes within `limit`; nullopt when none did or the connection ended
  /// (then ended() is true). For a test that does other work between reads.
  std::optional<json> poll(std::chrono::milliseconds limit) {
    std::string text;
    const auto got = client_->receive(text, limit);
    ended_ = ended_ || got == net::WebSocketClient::Received::ended;
    if (got == net::WebSocketClient::Received::message) return json::parse(text);
    return std::nullopt;
  }
  bool ended() const { return ended_; }

  /// Reads until a message of `type` (others, e.g. state and session events, are skipped).
  json expect(const std::string& type) {
    for (;;) {
      auto m = read();
      if (!m) {
        ADD_FAILURE() << "connection ended while waiting for '" << type << "'";
        return json::object();
      }
      if ((*m)["type"] == type) return *m;
      if ((*m)["type"] == "error" && type != "error") ADD_FAILURE() << "unexpected error: " << m->dump();
    }
  }

  json request(json message, const std::string& reply_type) {
    send(message);
    return expect(reply_type);
  }

  json hello(const std::string& token = "", json extra = json::object()) {
    json h = {{"type", "hello"}, {"protocol", 1}};
    h.update(extra);
    if (!token.empty()) h["token"] = token;
    return request(h, "welcome");
  }

  net::CloseReason close_reason() const { return client_->close_reason(); }

 private:
  void write(const std::string& payload, net::WebSocketClient::Frame frame) {
    client_->send(payload, frame);
    if (!client_->flush(kPatience)) {
      if (client_->error()) throw boost::system::system_error(client_->error());
      ADD_FAILURE() << "a message was not written within the patience limit";
    }
  }

  std::unique_ptr<net::WebSocketClient> client_;
  bool ended_ = false;
};

// A plain HTTP GET on loopback: status and body.
std::pair<unsigned, std::string> http_get(std::uint16_t port, const std::string& target) {
  asio::io_context io;
  tcp::socket socket(io);
  tcp::resolver resolver(io);
  asio::connect(socket, resolver.resolve("127.0.0.1", std::to_string(port)));
  http::request<http::empty_body> req(http::verb::get, target, 11);
  req.set(http::field::host, "127.0.0.1");
  http::write(socket, req);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(socket, buffer, res);
  return {res.result_int(), res.body()};
}

}  // namespace uh::test_support
