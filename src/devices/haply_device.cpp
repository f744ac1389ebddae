#include "uh/devices/haply_device.hpp"

#include <pthread.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include <fmt/format.h>
#include <boost/beast/websocket/error.hpp>
#include <nlohmann/json.hpp>

#include "uh/net/web_socket_client.hpp"
#include "uh/net/ws_url.hpp"

namespace uh::devices {

using json = nlohmann::json;
using haptico::DeviceStatus;
using Clock = TickRecorder::Clock;

namespace {

constexpr const char* kUrlVariable = "UH_HAPLY_URL";
// connecting, the WebSocket handshake and the inventory: a local service answers in milliseconds
constexpr std::chrono::milliseconds kConnectTimeout{2000};
// the last zero force and the close handshake, when the service still listens
constexpr std::chrono::milliseconds kHangUpTimeout{100};

// whether this thread is the device's network thread during a run (where command() only keeps
// the force for the next exchange)
thread_local bool t_in_run = false;

double steady_now_s() { return std::chrono::duration<double>(Clock::now().time_since_epoch()).count(); }

Result<net::WsUrl> parse_url(const std::string& text) {
  return net::parse_ws_url(text,
                           {.wrong_form = "expected ws://HOST:PORT[/PATH]", .example = kHaplyDefaultUrl});
}

// a device id goes into the command text as it is: only the characters of Haply's ids
bool plain_id(const std::string& id) {
  if (id.empty() || id.size() > 32) return false;
  for (const char c : id)
    if (!(std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_')) return false;
  return true;
}

// the start of a message, for an error that shows what came
std::string excerpt(const std::string& text) { return text.size() <= 80 ? text : text.substr(0, 80) + "..."; }

bool read_vec3(const json& parent, const char* key, Vec3& out) {
  const auto it = parent.find(key);
  if (it == parent.end() || !it->is_object()) return false;
  double v[3];
  const char* axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    const auto a = it->find(axes[k]);
    if (a == it->end() || !a->is_number()) return false;
    v[k] = a->get<double>();
    if (!std::isfinite(v[k])) return false;
  }
  out = {v[0], v[1], v[2]};
  return true;
}

// the service's error, as text: a string, an object's "message", or the JSON itself
std::string error_text(const json& error) {
  if (error.is_string()) return error.get<std::string>();
  if (error.is_object()) {
    const auto m = error.find("message");
    if (m != error.end() && m->is_string()) return m->get<std::string>();
  }
  return error.dump();
}

}  // namespace

// The WebSocket to the service; every wait on it is bounded (net::WebSocketClient).
struct HaplyDevice::Connection {
  std::unique_ptr<net::WebSocketClient> client;
  std::string reply;  // the last message received
  std::array<char, 512> out{};

  // the command text for `force` [N] to device `id`
  std::string_view format_command(const std::string& id, const Vec3& force) {
    const int n = std::snprintf(
        out.data(), out.size(),
        R"({"inverse3":[{"device_id":"%s","commands":{"set_cursor_force":{"vector":{"x":%.9g,"y":%.9g,"z":%.9g}}}}]})",
        id.c_str(), force.x, force.y, force.z);
    return {out.data(), static_cast<std::size_t>(n)};
  }
};

LibraryCandidate haply_service_url(const haptico::DeviceConfig& config) {
  if (config.has("url")) return {config.text("url", ""), "tool.device.config.url"};
  const char* env = std::getenv(kUrlVariable);
  if (env != nullptr && *env != '\0') return {env, kUrlVariable};
  return {kHaplyDefaultUrl, "the service's default address"};
}

Result<std::unique_ptr<haptico::HapticDevice>> HaplyDevice::create(const haptico::DeviceConfig& config) {
  constexpr std::string_view kName = "haply";
  if (Status s = config.check_keys({"url", "device_id", "max_force_n", "workspace", "timeout_ms"}, kName); !s)
    return s.error();
  Selection sel{.device_id = config.text("device_id", "")};
  if (config.has("device_id") && !plain_id(sel.device_id))
    return Error{fmt::format("haply: device_id '{}' is not a device id (letters and digits, e.g. 049D)",
                             sel.device_id)};
  auto force = config.number("max_force_n", kDefaultMaxForceN);
  if (!force) return Error{fmt::format("haply: {}", force.error().message)};
  if (!(*force > 0.0)) return Error{"haply: max_force_n must be positive"};
  auto workspace = config.vec3("workspace", Vec3{});
  if (!workspace) return Error{fmt::format("haply: {}", workspace.error().message)};
  if (config.has("workspace") && !(workspace->x > 0.0 && workspace->y > 0.0 && workspace->z > 0.0))
    return Error{"haply: workspace half extents must be positive"};
  auto timeout = config.number("timeout_ms", kDefaultTimeoutMs);
  if (!timeout) return Error{fmt::format("haply: {}", timeout.error().message)};
  if (!(*timeout >= 1.0 && *timeout <= 10000.0)) return Error{"haply: timeout_ms must be in [1, 10000]"};
  if (Result<net::WsUrl> url = parse_url(haply_service_url(config).path); !url)
    return Error{fmt::format("haply: url '{}' (from {}): {}", haply_service_url(config).path,
                             haply_service_url(config).origin, url.error().message)};
  sel.max_force_n = *force;
  sel.workspace = *workspace;
  sel.timeout = std::chrono::milliseconds(std::lround(*timeout));
  return std::unique_ptr<haptico::HapticDevice>(new HaplyDevice(config, std::move(sel)));
}

HaplyDevice::HaplyDevice(haptico::DeviceConfig config, Selection selection)
    : config_(std::move(config)), selection_(std::move(selection)), url_(haply_service_url(config_)) {
  info_.name = "haply";
}

HaplyDevice::~HaplyDevice() {
  const Status closed = close();
  (void)closed;  // nothing left to report to
}

Status HaplyDevice::open() {
  if (connection_) return Ok{};
  join_thread();
  fault_.clear();
  faulted_ = false;
  state_ = {};
  pending_force_ = {};
  const Result<net::WsUrl> url = parse_url(url_.path);  // checked by create()
  const std::string where = fmt::format("the Inverse Service at {} (from {})", url_.path, url_.origin);
  const auto unreachable = [&](const std::string& why) -> Status {
    return Error{fmt::format("haply: {}; is the service running? (see docs/devices.md)", why)};
  };
  auto client = net::WebSocketClient::connect(*url, {.name = where, .step_limit = kConnectTimeout});
  if (!client) return unreachable(client.error().message);
  auto c = std::make_unique<Connection>();
  c->client = std::move(client).value();
  switch (c->client->receive(c->reply, kConnectTimeout)) {
    case net::WebSocketClient::Received::message:
      break;
    case net::WebSocketClient::Received::nothing:
      return unreachable(fmt::format("cannot reach {}: the service sent no inventory within 2 s", where));
    case net::WebSocketClient::Received::ended:
      return unreachable(fmt::format("cannot reach {}: reading its inventory failed: {}", where,
                                     c->client->error().message()));
  }
  const std::string inventory = c->reply;
  connection_ = std::move(c);
  if (Status s = describe(inventory); !s) {
    hang_up();
    return Error{fmt::format("haply: {}: {}", where, s.error().message)};
  }
  return Ok{};
}

Status HaplyDevice::describe(const std::string& inventory_text) {
  const json j = json::parse(inventory_text, nullptr, false);
  if (j.is_discarded() || !j.is_object())
    return Error{fmt::format("its inventory is not a JSON object: {}", excerpt(inventory_text))};
  if (const auto e = j.find("error"); e != j.end())
    return Error{fmt::format("the service reported an error: {}", error_text(*e))};
  inventory_.clear();
  if (const auto devices = j.find("inverse3"); devices != j.end() && devices->is_array())
    for (const json& d : *devices)
      if (const auto id = d.find("device_id"); id != d.end() && id->is_string())
        inventory_.push_back(id->get<std::string>());
  if (inventory_.empty())
    return Error{
        "the service reports no Inverse3 (is the device plugged in, powered and on the service's list?)"};
  std::string id = selection_.device_id.empty() ? inventory_.front() : selection_.device_id;
  if (std::find(inventory_.begin(), inventory_.end(), id) == inventory_.end()) {
    std::string found;
    for (const std::string& i : inventory_) found += fmt::format("{}{}", found.empty() ? "" : ", ", i);
    return Error{fmt::format("no Inverse3 with device_id '{}' (the service reports: {})", id, found)};
  }
  if (!plain_id(id)) return Error{fmt::format("the service reports an unexpected device id '{}'", id)};
  const auto grips = j.find("wireless_verse_grip");
  has_grip_ = grips != j.end() && grips->is_array() && !grips->empty();
  info_.name = fmt::format("haply Inverse3 {}", id);
  info_.model = "Inverse3";
  info_.serial = id;
  info_.dof_sensed = has_grip_ ? 6 : 3;  // the orientation only comes from a VerseGrip
  info_.dof_actuated = 3;
  info_.max_force_n = selection_.max_force_n;
  info_.max_torque_nm = 0.0;
  info_.workspace_half_extents = selection_.workspace;
  info_.nominal_rate_hz = 0.0;  // the client's commands pace the service: it reports no rate
  // the inventory carries the device's state: the first state, before any command
  if (!take_reply(inventory_text)) return Error{fault_.text()};
  return Ok{};
}

bool HaplyDevice::take_reply(const std::string& text) {
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    fault("the service's reply is not a JSON object", excerpt(text));
    return false;
  }
  if (const auto e = j.find("error"); e != j.end()) {
    fault("the service reported an error", error_text(*e));
    return false;
  }
  const json* device = nullptr;
  if (const auto devices = j.find("inverse3"); devices != j.end() && devices->is_array())
    for (const json& d : *devices)
      if (const auto id = d.find("device_id"); id != d.end() && id->is_string() && *id == info_.serial)
        device = &d;
  const auto state = device != nullptr ? device->find("state") : json::const_iterator{};
  haptico::DeviceState s;
  if (device == nullptr || state == device->end() || !state->is_object() ||
      !read_vec3(*state, "cursor_position", s.position)) {
    fault(fmt::format("the service's reply has no cursor_position of Inverse3 {}", info_.serial).c_str(),
          excerpt(text));
    return false;
  }
  // the velocity is optional: a service that does not send it reports zero
  if (!read_vec3(*state, "cursor_velocity", s.linear_velocity)) s.linear_velocity = {};
  if (has_grip_) {
    if (const auto grips = j.find("wireless_verse_grip");
        grips != j.end() && grips->is_array() && !grips->empty()) {
      const json& grip = grips->front();
      if (const auto g = grip.find("state"); g != grip.end() && g->is_object()) {
        if (const auto q = g->find("orientation"); q != g->end() && q->is_object()) {
          double v[4];
          const char* keys[4] = {"w", "x", "y", "z"};
          bool ok = true;
          for (int k = 0; k < 4 && ok; ++k) {
            const auto a = q->find(keys[k]);
            ok = a != q->end() && a->is_number() && std::isfinite(v[k] = a->get<double>());
          }
          const double norm = ok ? std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]) : 0.0;
          if (norm > 0.0) s.orientation = Quat{v[0] / norm, v[1] / norm, v[2] / norm, v[3] / norm};
        }
        if (const auto b = g->find("buttons"); b != g->end() && b->is_object()) {
          const char* names[2] = {"a", "b"};  // bit 0 and bit 1
          for (std::uint32_t k = 0; k < 2; ++k)
            if (const auto p = b->find(names[k]); p != b->end() && p->is_boolean() && p->get<bool>())
              s.buttons |= 1u << k;
        }
      }
    }
  }
  s.time_s = steady_now_s();
  s.status = DeviceStatus::kOk;
  state_ = s;
  return true;
}

void HaplyDevice::fault(const char* what, const std::string& detail) {
  faulted_ = true;
  fault_.note(what, detail.c_str());
}

bool HaplyDevice::exchange() {
  Connection& c = *connection_;
  net::WebSocketClient& client = *c.client;
  if (!client.alive() || client.reading()) {
    fault("the connection to the service is gone", "no command can be sent");
    return false;
  }
  client.send(c.format_command(info_.serial, pending_force_));
  switch (client.receive(c.reply, selection_.timeout)) {
    case net::WebSocketClient::Received::message:
      return take_reply(c.reply);
    case net::WebSocketClient::Received::nothing:
      fault(
          fmt::format("the Inverse Service did not answer within {} ms", selection_.timeout.count()).c_str(),
          "it stopped sending device states");
      return false;
    case net::WebSocketClient::Received::ended:
      break;
  }
  const auto ec = client.error();
  fault("the connection to the Inverse Service was lost",
        ec == boost::beast::websocket::error::closed ? std::string("the service closed it") : ec.message());
  return false;
}

void HaplyDevice::hang_up() {
  if (!connection_) return;
  Connection& c = *connection_;
  net::WebSocketClient& client = *c.client;
  // the device must not keep the last force: zero, if the service can still be told
  if (client.alive()) {
    client.send(c.format_command(info_.serial, Vec3{}));
    // the reply to the zero may come before the service's close: the close reads past it
    if (client.flush(kHangUpTimeout) && !client.reading()) (void)client.close(kHangUpTimeout);
  }
  client.drop();
  connection_.reset();
}

Status HaplyDevice::close() {
  stop();
  join_thread();
  if (!connection_) return Ok{};
  pending_force_ = {};
  hang_up();
  state_ = {};
  return Ok{};
}

haptico::DeviceState HaplyDevice::read_state() {
  haptico::DeviceState s = state_;
  if (faulted_) {
    s.status = DeviceStatus::kFault;
    return s;
  }
  if (!connection_) s.status = DeviceStatus::kNotOpen;
  return s;
}

void HaplyDevice::command(const haptico::DeviceCommand& cmd) {
  Vec3 f = cmd.force;
  clamp_norm(f, info_.max_force_n);  // as the motors would; a non-finite value becomes zero
  pending_force_ = f;
  if (t_in_run || !connection_ || faulted_) return;
  // outside a run: one exchange on this thread
  if (!exchange()) hang_up();
}

// ---- the clock: the service's replies ----

Status HaplyDevice::start(double rate_hz, FixedRateLoop::Callback tick, FixedRateLoop::ExitCallback on_exit) {
  if (running()) return Error{"haply: the servo loop is already running"};
  join_thread();
  if (faulted_) return Error{fmt::format("haply: {} faulted ({}); re-open it", info_.name, fault_.text())};
  if (!connection_) return Error{"haply: start: the device is not open"};
  run_.begin(rate_hz, std::move(tick), std::move(on_exit));
  stop_requested_.store(false, std::memory_order_relaxed);
  pending_force_ = {};
  running_.store(true, std::memory_order_release);
  thread_ = std::thread([this] { run_loop(); });
  return Ok{};
}

void HaplyDevice::run_loop() {
  pthread_setname_np(pthread_self(), "uh-haptic");
  t_in_run = true;
  const std::chrono::nanoseconds period = run_.period();
  // a zero force brings the first state of the run: the device is the clock from here
  bool live = exchange();
  Clock::time_point next = Clock::now();
  for (;;) {
    const Clock::time_point start = Clock::now();
    run_.begin_frame(std::min(next, start), start);
    // after a fault this tick reads kFault: the HapticManager latches it and commands zero
    const bool ticked = run_.tick();
    const Clock::time_point end = Clock::now();
    run_.finish_frame(end);
    // a stop: the exit callback's zero is the next command
    if (!ticked || !live || stop_requested_.load(std::memory_order_acquire)) break;
    // never faster than the session's rate: the next command waits for its grid point
    next += period;
    if (next > end)
      std::this_thread::sleep_until(next);
    else
      next = end;
    live = exchange();
  }
  // the run's last act: the exit callback commands zero, which goes out at once
  run_.end();
  pending_force_ = {};
  if (live) live = exchange();
  if (!live) hang_up();
  t_in_run = false;
  running_.store(false, std::memory_order_release);
}

void HaplyDevice::stop() {
  stop_requested_.store(true, std::memory_order_release);
  // bounded: every exchange of the loop has its time limit; a run that ended by itself is joined here
  join_thread();
}

void HaplyDevice::join_thread() {
  if (thread_.joinable()) thread_.join();
}

FixedRateLoopStats HaplyDevice::stats() const { return run_.stats(running()); }

}  // namespace uh::devices
