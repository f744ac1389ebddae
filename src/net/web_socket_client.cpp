#include "uh/net/web_socket_client.hpp"

#include <algorithm>
#include <charconv>
#include <deque>
#include <optional>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/websocket.hpp>

namespace uh::net {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

namespace {

// how often a wait looks at the owner's cancel flag
constexpr auto kCancelPoll = std::chrono::milliseconds(10);
// how long drop() lets aborted operations finish
constexpr auto kDropLimit = std::chrono::milliseconds(100);

std::string seconds_text(WebSocketClient::Duration d) {
  return fmt::format("{:g} s", std::chrono::duration<double>(d).count());
}

struct Outgoing {
  std::string payload;
  WebSocketClient::Frame frame;
};

}  // namespace

// Every operation is started asynchronously and completes into a member, so that one still under
// way when its wait ended completes harmlessly in a later call.
struct WebSocketClient::Impl {
  asio::io_context io{1};
  websocket::stream<tcp::socket> ws{io};
  beast::flat_buffer in;
  std::deque<Outgoing> outbox;  // the front is being written while write_pending
  bool read_pending = false;
  bool read_ready = false;  // a message waits in `in`
  bool write_pending = false;
  bool close_pending = false;
  beast::error_code failure;  // the first error; the connection is gone once set
  const std::atomic<bool>* cancel = nullptr;

  // runs the context on this thread until `done()` or `limit` passed; false on timeout
  template <typename Done>
  bool run_until(Done done, Duration limit) {
    const auto deadline = Clock::now() + limit;
    io.restart();
    while (!done()) {
      if (cancel != nullptr && cancel->load()) return false;
      const auto until = cancel != nullptr ? std::min(deadline, Clock::now() + kCancelPoll) : deadline;
      if (io.run_one_until(until) == 0 && (io.stopped() || Clock::now() >= deadline)) return done();
    }
    return true;
  }

  void fail(const beast::error_code& ec) {
    if (!failure) failure = ec;
  }

  void write_next() {
    if (write_pending || outbox.empty() || failure) return;
    write_pending = true;
    ws.text(outbox.front().frame == Frame::text);
    ws.async_write(asio::buffer(outbox.front().payload), [this](beast::error_code ec, std::size_t) {
      write_pending = false;
      if (ec) {
        fail(ec);
        outbox.clear();
        return;
      }
      outbox.pop_front();
      write_next();
    });
  }

  void read_next() {
    if (read_pending || read_ready || failure) return;
    read_pending = true;
    ws.async_read(in, [this](beast::error_code ec, std::size_t) {
      read_pending = false;
      if (ec)
        fail(ec);
      else
        read_ready = true;
    });
  }

  // why a step did not complete within `limit`
  std::string timed_out(Duration limit) const {
    return cancel != nullptr && cancel->load() ? std::string("connecting was cancelled")
                                               : fmt::format("no answer within {}", seconds_text(limit));
  }

  // where `url` points: an IP address as it is (no lookup, no resolver thread), a name resolved
  Result<std::vector<tcp::endpoint>> resolve(const WsUrl& url, const ConnectOptions& options) {
    beast::error_code ec;
    const asio::ip::address address = asio::ip::make_address(url.host, ec);
    unsigned short port = 0;
    const auto [end, parsed] = std::from_chars(url.port.data(), url.port.data() + url.port.size(), port);
    if (!ec && parsed == std::errc{} && end == url.port.data() + url.port.size())
      return std::vector<tcp::endpoint>{tcp::endpoint(address, port)};
    tcp::resolver resolver(io);
    std::optional<beast::error_code> resolved;
    std::vector<tcp::endpoint> endpoints;
    resolver.async_resolve(url.host, url.port,
                           [&](beast::error_code e, const tcp::resolver::results_type& results) {
                             resolved = e;
                             endpoints.assign(results.begin(), results.end());
                           });
    if (!run_until([&] { return resolved.has_value(); }, options.step_limit)) {
      resolver.cancel();
      abandon([&] { return resolved.has_value(); });
      return Error{
          fmt::format("cannot resolve the host of {}: {}", options.name, timed_out(options.step_limit))};
    }
    if (*resolved)
      return Error{fmt::format("cannot resolve the host of {}: {}", options.name, resolved->message())};
    return endpoints;
  }

  Status open(const WsUrl& url, const ConnectOptions& options) {
    cancel = options.cancel;
    auto endpoints = resolve(url, options);
    if (!endpoints) return endpoints.error();
    std::optional<beast::error_code> connected;
    asio::async_connect(ws.next_layer(), *endpoints,
                        [&connected](beast::error_code ec, const tcp::endpoint&) { connected = ec; });
    if (!run_until([&] { return connected.has_value(); }, options.step_limit)) {
      abandon([&] { return connected.has_value(); });
      return Error{fmt::format("cannot reach {}: {}", options.name, timed_out(options.step_limit))};
    }
    if (*connected) return Error{fmt::format("cannot reach {}: {}", options.name, connected->message())};
    std::optional<beast::error_code> shaken;
    ws.async_handshake(fmt::format("{}:{}", url.host, url.port), url.path,
                       [&shaken](beast::error_code ec) { shaken = ec; });
    if (!run_until([&] { return shaken.has_value(); }, options.step_limit)) {
      abandon([&] { return shaken.has_value(); });
      return Error{fmt::format("{} did not complete the WebSocket handshake: {}", options.name,
                               timed_out(options.step_limit))};
    }
    if (*shaken)
      return Error{fmt::format("{} refused the WebSocket handshake: {}", options.name, shaken->message())};
    return Ok{};
  }

  // closes the socket and lets the operation that `done` watches end before its state goes
  template <typename Done>
  void abandon(Done done) {
    close_socket();
    const std::atomic<bool>* keep = std::exchange(cancel, nullptr);
    run_until(done, kDropLimit);
    cancel = keep;
  }

  void close_socket() {
    beast::error_code ignored;
    ws.next_layer().shutdown(tcp::socket::shutdown_both, ignored);
    ws.next_layer().close(ignored);
  }
};

WebSocketClient::WebSocketClient(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

WebSocketClient::~WebSocketClient() { drop(); }

Result<std::unique_ptr<WebSocketClient>> WebSocketClient::connect(const WsUrl& url,
                                                                  const ConnectOptions& options) {
  auto impl = std::make_unique<Impl>();
  if (Status opened = impl->open(url, options); !opened) return opened.error();
  impl->cancel = nullptr;  // from here every wait is bounded by its own limit
  return std::unique_ptr<WebSocketClient>(new WebSocketClient(std::move(impl)));
}

void WebSocketClient::send(std::string_view payload, Frame frame) {
  if (impl_->failure) return;
  impl_->outbox.push_back({std::string(payload), frame});
  impl_->write_next();
}

bool WebSocketClient::flush(Duration limit) {
  Impl& c = *impl_;
  return c.run_until([&c] { return c.outbox.empty() || bool(c.failure); }, limit) && !c.failure;
}

WebSocketClient::Received WebSocketClient::receive(std::string& out, Duration limit) {
  Impl& c = *impl_;
  c.read_next();
  c.run_until([&c] { return c.read_ready || bool(c.failure); }, limit);
  if (c.read_ready) {
    out = beast::buffers_to_string(c.in.data());
    c.in.consume(c.in.size());
    c.read_ready = false;
    return Received::message;
  }
  return c.failure ? Received::ended : Received::nothing;
}

bool WebSocketClient::close(Duration limit) {
  Impl& c = *impl_;
  if (c.failure || c.close_pending) return false;
  c.close_pending = true;
  c.ws.async_close(websocket::close_code::normal, [&c](beast::error_code ec) {
    c.close_pending = false;
    c.fail(ec ? ec : beast::error_code(websocket::error::closed));
  });
  const bool done = c.run_until([&c] { return !c.close_pending; }, limit);
  if (!done) c.abandon([&c] { return !c.close_pending; });
  return done && c.failure == websocket::error::closed;
}

void WebSocketClient::drop() {
  if (!impl_) return;
  Impl& c = *impl_;
  c.close_socket();
  c.cancel = nullptr;
  c.run_until([&c] { return !c.read_pending && !c.write_pending && !c.close_pending; }, kDropLimit);
  c.fail(asio::error::operation_aborted);
}

bool WebSocketClient::alive() const { return !impl_->failure; }

bool WebSocketClient::reading() const { return impl_->read_pending; }

boost::system::error_code WebSocketClient::error() const { return impl_->failure; }

CloseReason WebSocketClient::close_reason() const {
  const websocket::close_reason& r = impl_->ws.reason();
  return {r.code, std::string(r.reason.data(), r.reason.size())};
}

}  // namespace uh::net
