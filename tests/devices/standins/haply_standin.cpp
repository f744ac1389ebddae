#include "haply_standin.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>
#include <utility>

#include <fmt/format.h>
#include <boost/asio/co_spawn.hpp>
#include <boost/asio/detached.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/redirect_error.hpp>
#include <boost/asio/use_awaitable.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

namespace uh::devices::testing {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using json = nlohmann::json;

namespace {

json xyz(const Vec3& v) { return {{"x", v.x}, {"y", v.y}, {"z", v.z}}; }

Vec3 path_at(const HaplyStandinScript& s, std::int64_t k) {
  if (s.motion_replies <= 0) return s.start;
  double t = static_cast<double>(k) / s.motion_replies;
  if (s.bounce) {
    t = std::fmod(t, 2.0);
    if (t > 1.0) t = 2.0 - t;
  } else {
    t = std::min(t, 1.0);
  }
  return s.start + (s.end - s.start) * t;
}

}  // namespace

struct HaplyStandinService::Impl {
  asio::io_context io;
  tcp::acceptor acceptor{io};
  std::thread thread;
  mutable std::mutex mutex;  // the script and the records: the test's thread reads them
  HaplyStandinScript script;
  std::vector<Vec3> received;
  int connections = 0;
  std::int64_t replies = 0;
  Vec3 last_position{};

  // one connection: the mechanism restarts from rest
  struct Mechanism {
    Vec3 x{}, v{};  // the mass' displacement from the path [m] and its velocity [m/s]
    std::int64_t k = 0;
  };

  std::string state_message(const HaplyStandinScript& s, const Mechanism& m, bool inventory) {
    const Vec3 position = path_at(s, m.k) + m.x;
    const Vec3 path_velocity =
        s.motion_replies > 0 ? (path_at(s, m.k + 1) - path_at(s, m.k)) * (1.0 / s.dt_s) : Vec3{};
    json device = {{"device_id", s.device_id},
                   {"state",
                    {{"cursor_position", xyz(position)},
                     {"cursor_velocity", xyz(path_velocity + m.v)},
                     {"body_orientation", {{"w", 1.0}, {"x", 0.0}, {"y", 0.0}, {"z", 0.0}}}}}};
    if (inventory) device["config"] = json::object();
    json j = {{"session_id", 7}, {"inverse3", json::array({device})}};
    if (s.with_grip) {
      const Quat& q = s.grip_orientation;
      j["wireless_verse_grip"] =
          json::array({{{"device_id", "0A1B"},
                        {"state",
                         {{"orientation", {{"w", q.w}, {"x", q.x}, {"y", q.y}, {"z", q.z}}},
                          {"buttons", {{"a", false}, {"b", s.button_b}}}}}}});
    }
    std::lock_guard lock(mutex);
    last_position = position;
    if (!inventory) ++replies;
    return j.dump();
  }

  // the force of a command (NaN when it has none in the expected place)
  static Vec3 force_of(const std::string& text, const HaplyStandinScript& s) {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    const json j = json::parse(text, nullptr, false);
    try {
      const json& f = j.at("inverse3")
                          .at(0)
                          .at("commands")
                          .at("set_cursor_force")
                          .at(s.legacy_force_key ? "values" : "vector");
      if (j.at("inverse3").at(0).at("device_id") != s.device_id) return {nan, nan, nan};
      return {f.at("x").get<double>(), f.at("y").get<double>(), f.at("z").get<double>()};
    } catch (const json::exception&) {
      return {nan, nan, nan};
    }
  }

  asio::awaitable<void> serve(tcp::socket socket) {
    websocket::stream<tcp::socket> ws(std::move(socket));
    beast::error_code ec;
    co_await ws.async_accept(asio::redirect_error(asio::use_awaitable, ec));
    if (ec) co_return;
    ws.text(true);
    Mechanism m;
    HaplyStandinScript s = current_script();
    co_await ws.async_write(asio::buffer(state_message(s, m, true)),
                            asio::redirect_error(asio::use_awaitable, ec));
    if (ec) co_return;
    beast::flat_buffer in;
    int answered = 0;
    for (;;) {
      in.clear();
      co_await ws.async_read(in, asio::redirect_error(asio::use_awaitable, ec));
      if (ec) co_return;
      s = current_script();
      const Vec3 f = force_of(beast::buffers_to_string(in.data()), s);
      {
        std::lock_guard lock(mutex);
        received.push_back(f);
      }
      std::string reply;
      if (s.fault != HaplyFault::kNone && answered >= s.fault_after) {
        if (s.fault == HaplyFault::kDrop) {
          ws.next_layer().close(ec);
          co_return;
        }
        if (s.fault == HaplyFault::kSilent) continue;
        reply = s.fault == HaplyFault::kError ? json{{"error", {{"message", s.error_text}}}}.dump()
                                              : std::string(R"({"inverse3": [{"device_id": "049D", "sta)");
      } else {
        // the mass on its spring, pushed by the commanded force (semi-implicit Euler)
        const Vec3 push = is_finite(f) ? f : Vec3{};
        const Vec3 a = (push - m.x * s.stiffness_n_per_m - m.v * s.damping_n_s_per_m) * (1.0 / s.mass_kg);
        m.v = m.v + a * s.dt_s;
        m.x = m.x + m.v * s.dt_s;
        ++m.k;
        reply = state_message(s, m, false);
      }
      ++answered;
      co_await ws.async_write(asio::buffer(reply), asio::redirect_error(asio::use_awaitable, ec));
      if (ec) co_return;
    }
  }

  asio::awaitable<void> accept_loop() {
    for (;;) {
      beast::error_code ec;
      tcp::socket socket = co_await acceptor.async_accept(asio::redirect_error(asio::use_awaitable, ec));
      if (ec) co_return;
      {
        std::lock_guard lock(mutex);
        ++connections;
      }
      asio::co_spawn(io, serve(std::move(socket)), asio::detached);
    }
  }

  HaplyStandinScript current_script() const {
    std::lock_guard lock(mutex);
    return script;
  }
};

HaplyStandinService::HaplyStandinService(HaplyStandinScript script) : impl_(std::make_unique<Impl>()) {
  impl_->script = std::move(script);
  const tcp::endpoint local(asio::ip::make_address("127.0.0.1"), 0);
  impl_->acceptor.open(local.protocol());
  impl_->acceptor.set_option(tcp::acceptor::reuse_address(true));
  impl_->acceptor.bind(local);
  impl_->acceptor.listen();
  port_ = impl_->acceptor.local_endpoint().port();
  asio::co_spawn(impl_->io, impl_->accept_loop(), asio::detached);
  impl_->thread = std::thread([this] { impl_->io.run(); });
}

HaplyStandinService::~HaplyStandinService() {
  impl_->io.stop();
  impl_->thread.join();
}

void HaplyStandinService::set_script(const HaplyStandinScript& script) {
  std::lock_guard lock(impl_->mutex);
  impl_->script = script;
}

std::vector<Vec3> HaplyStandinService::received() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->received;
}

int HaplyStandinService::connections() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->connections;
}

std::int64_t HaplyStandinService::replies() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->replies;
}

Vec3 HaplyStandinService::scripted_position(std::int64_t k) const {
  return path_at(impl_->current_script(), k);
}

Vec3 HaplyStandinService::last_position() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->last_position;
}

}  // namespace uh::devices::testing
