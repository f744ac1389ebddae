#pragma once
// A WebSocket client for the tests of servers on the WebSocket host (uh serve, uh museum serve):
// Boost.Beast on its own io_context over loopback, JSON messages, every wait bounded.

#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <string>
#include <utility>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

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

// A protocol client on its own io_context; every wait is bounded by kPatience.
class Client {
 public:
  explicit Client(std::uint16_t port) {
    tcp::resolver resolver(io_);
    asio::connect(ws_.next_layer(), resolver.resolve("127.0.0.1", std::to_string(port)));
    ws_.handshake("127.0.0.1", "/ws");
  }

  void send(const json& message) { send_text(message.dump()); }
  void send_text(const std::string& text) {
    ws_.text(true);
    ws_.write(asio::buffer(text));
  }
  void send_binary(const std::string& bytes) {
    ws_.binary(true);
    ws_.write(asio::buffer(bytes));
  }

  /// The next message, or an error code when the connection ended.
  std::optional<json> read(beast::error_code* ended = nullptr) {
    beast::flat_buffer buffer;
    beast::error_code ec;
    bool done = false;
    ws_.async_read(buffer, [&](beast::error_code e, std::size_t) {
      ec = e;
      done = true;
    });
    io_.restart();
    io_.run_for(kPatience);
    if (!done) {
      ADD_FAILURE() << "no message within the patience limit";
      ws_.next_layer().close();
      io_.restart();
      io_.run();
      return std::nullopt;
    }
    if (ec) {
      if (ended != nullptr) *ended = ec;
      return std::nullopt;
    }
    return json::parse(beast::buffers_to_string(buffer.data()));
  }

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

  websocket::close_reason close_reason() const { return ws_.reason(); }

 private:
  asio::io_context io_;
  websocket::stream<tcp::socket> ws_{io_};
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
