#include "hub.hpp"

#include <algorithm>
#include <chrono>
#include <utility>

#include <fmt/format.h>
#include <boost/asio/post.hpp>

#include "mesh_binary.hpp"
#include "uh/core/log.hpp"

namespace uh::service {
namespace {

using namespace std::chrono_literals;

json vec3_json(const Vec3& v) { return json::array({v.x, v.y, v.z}); }

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

json state_json(const controllers::SessionState& s) {
  const Quat& q = s.tool_orientation_world;
  return {
      {"time_s", s.time_s},
      {"clock_s", steady_seconds()},
      {"tool",
       {{"position", vec3_json(s.tool_position_world)}, {"orientation", json::array({q.w, q.x, q.y, q.z})}}},
      {"handle", {{"position", vec3_json(s.handle_position_world)}}},
      {"force", vec3_json(s.force_world)},
      {"torque", vec3_json(s.torque_world)},
      {"contact_pairs", s.contact_pairs},
      {"buttons", s.buttons},
      {"haptic",
       {{"rate_hz", s.haptic_rate_hz}, {"ticks", s.haptic_ticks}, {"missed_deadlines", s.missed_deadlines}}},
      {"collision", {{"rate_hz", s.collision_rate_hz}}}};
}

// the first tool's state at the top level (as with one tool); with several tools also `tools`:
// each one's state, named
json session_state_json(controllers::HapticSession& session) {
  json j = state_json(session.state());
  if (session.tool_count() < 2) return j;
  json tools = json::array();
  for (std::size_t t = 0; t < session.tool_count(); ++t) {
    json one = state_json(session.state(t));
    one.erase("clock_s");
    one.erase("collision");
    one["name"] = session.scene().tools[t].name;
    tools.push_back(std::move(one));
  }
  j["tools"] = std::move(tools);
  return j;
}

// "add_object 'bunny'": names the request in messages about its binary frame.
std::string add_object_label(const AddObject& add) {
  const auto name = add.object.find("name");
  return name != add.object.end() && name->is_string()
             ? fmt::format("add_object '{}'", name->get<std::string>())
             : std::string("add_object");
}

// Before a successful hello a client may send only small messages, and only a few.
constexpr std::size_t kMaxMessageBytesBeforeHello = 64 * 1024;
constexpr int kMaxMessagesBeforeHello = 16;
// get_mesh is refused while this much already waits to be sent to the client: one client's flood
// of large replies neither grows without bound nor keeps the network thread from the others.
constexpr std::size_t kMaxQueuedBytesForMesh = 8u << 20;

}  // namespace

Hub::Hub(boost::asio::io_context& io, HubOptions options)
    : io_(io), options_(std::move(options)), stop_timer_(io), event_timer_(io) {}

Hub::~Hub() { shutdown(); }

Hub::ClientId Hub::connect(Peer& peer) {
  const ClientId id = next_id_++;
  clients_[id].peer = &peer;
  return id;
}

void Hub::send_to(ClientId id, std::string text) {
  if (const auto it = clients_.find(id); it != clients_.end()) it->second.peer->send(std::move(text));
}

void Hub::receive(ClientId id, std::string_view text) {
  const auto it = clients_.find(id);
  if (it == clients_.end() || shut_down_) return;
  Client& c = it->second;
  if (c.closing) return;
  if (c.pending_mesh) {
    // the announced frame did not come: that add_object fails, this message is read as usual
    const auto pending = std::exchange(c.pending_mesh, std::nullopt);
    if (pending->add)
      c.peer->send(refusal(pending->req_id, "add_object",
                           fmt::format("{}: its mesh_binary frame ({} bytes) must be the next message, but "
                                       "a text message came; the object was not added",
                                       add_object_label(*pending->add), pending->add->mesh_binary->bytes())));
  }
  if (!c.greeted && ++c.messages_before_hello > kMaxMessagesBeforeHello) {
    c.closing = true;
    c.peer->close(1008, "too many messages before hello");
    return;
  }
  ParsedRequest req = parse_request(text);
  if (req.announces_binary) {
    if (auto e = on_announce_mesh(id, c, req); !e.empty()) c.peer->send(refusal(req.id, req.type, e));
    return;
  }
  if (!req.body) {
    c.peer->send(refusal(req.id, req.type, req.error));
    return;
  }
  if (!c.greeted && !std::holds_alternative<Hello>(*req.body)) {
    c.peer->send(
        refusal(req.id, req.type,
                fmt::format("send hello first: {{\"type\":\"hello\",\"protocol\":{}}}", kProtocolVersion)));
    return;
  }
  handle(id, c, req.id, req.type, *req.body);
}

std::size_t Hub::message_limit(ClientId id) const {
  const auto it = clients_.find(id);
  if (it == clients_.end()) return kMaxMessageBytes;
  // the limit rises only for a client that said hello (with the token): nobody else makes the
  // service hold a large buffer
  if (!it->second.greeted) return kMaxMessageBytesBeforeHello;
  if (!it->second.pending_mesh) return kMaxMessageBytes;
  const auto& pending = *it->second.pending_mesh;
  return std::max(kMaxMessageBytes, pending.add ? pending.add->mesh_binary->bytes() : kMaxMeshBinaryBytes);
}

std::string Hub::on_announce_mesh(ClientId id, Client& c, const ParsedRequest& req) {
  // before hello nothing is held for the frame (it comes under the small limit and is refused)
  if (!c.greeted)
    return fmt::format("send hello first: {{\"type\":\"hello\",\"protocol\":{}}}", kProtocolVersion);
  // whatever happens to the request, the frame that follows it is its own
  c.pending_mesh.emplace(Client::PendingMesh{req.id, std::nullopt});
  if (!req.body) return req.error;
  if (auto e = check_control(id, true); !e.empty()) return e;
  if (slot_->phase != Phase::kOpen) return "the session is running; stop it before editing the scene";
  c.pending_mesh->add = std::get<AddObject>(*req.body);
  return {};
}

void Hub::receive_binary(ClientId id, std::span<const std::byte> bytes) {
  const auto it = clients_.find(id);
  if (it == clients_.end() || shut_down_) return;
  Client& c = it->second;
  if (c.closing) return;
  if (!c.pending_mesh) {
    c.peer->send(refusal(nullptr, "",
                         "a binary frame must follow an add_object that announces it with "
                         "\"mesh_binary\"; none did, so this frame was dropped"));
    return;
  }
  const auto pending = std::exchange(c.pending_mesh, std::nullopt);
  if (!pending->add) return;  // its request was refused, and said so
  if (auto e = on_mesh_frame(id, *pending, bytes); !e.empty())
    send_to(id, refusal(pending->req_id, "add_object", e));
}

std::string Hub::on_mesh_frame(ClientId id, const Client::PendingMesh& pending,
                               std::span<const std::byte> bytes) {
  // the session cannot have changed hands or started meanwhile (only this client controls it and
  // it sent nothing in between), but the slot's state is checked again rather than assumed
  if (auto e = check_control(id, true); !e.empty()) return e;
  if (slot_->phase != Phase::kOpen) return "the session is running; stop it before editing the scene";
  if (meshing_) return "another inline mesh is being checked; send this one after its reply";
  // decoding, welding and checking a large mesh takes seconds: off the network thread, answered
  // when done
  meshing_ = true;
  if (mesher_.joinable()) mesher_.join();
  mesher_ = std::jthread([this, id, pending, generation = generation_,
                          frame = std::vector<std::byte>(bytes.begin(), bytes.end()),
                          mesh_dir = options_.cache_dir / "inline-meshes"] {
    auto decoded = decode_mesh_binary(frame, *pending.add->mesh_binary, add_object_label(*pending.add));
    auto written =
        std::make_shared<Result<InlineMesh>>(decoded ? write_inline_mesh(std::move(decoded).value(), mesh_dir)
                                                     : Result<InlineMesh>(decoded.error()));
    boost::asio::post(io_, [this, id, pending, generation, written] {
      mesh_written(generation, id, pending, std::move(*written));
    });
  });
  return {};
}

void Hub::mesh_written(std::uint64_t generation, ClientId id, const Client::PendingMesh& pending,
                       Result<InlineMesh> written) {
  meshing_ = false;
  if (shut_down_) {
    if (written) remove_inline_mesh(written->file, options_.cache_dir);
    return;
  }
  if (!written) {
    send_to(id, refusal(pending.req_id, "add_object", written.error().message));
    return;
  }
  // the slot was closed or replaced, or the session started, while the mesh was checked
  std::string refused = generation != generation_ ? "the scene was closed while its inline mesh was checked"
                                                  : check_control(id, true);
  if (refused.empty() && slot_->phase != Phase::kOpen)
    refused = "the session started while the inline mesh was checked; stop it before editing the scene";
  if (refused.empty()) {
    slot_->inline_meshes.push_back(written->file);
    slot_->mesh_replies.clear();
    if (auto added = slot_->document->add_inline_object(pending.add->object, written->file); !added)
      refused = added.error().message;
  } else {
    remove_inline_mesh(written->file, options_.cache_dir);
  }
  if (!refused.empty()) {
    send_to(id, refusal(pending.req_id, "add_object", refused));
    return;
  }
  const collette::MeshReport& report = written->report;
  send_to(id, reply("object_added", pending.req_id,
                    {{"name", slot_->scene().objects.back().name},
                     {"mesh",
                      {{"vertices", report.vertex_count},
                       {"triangles", report.triangle_count},
                       {"welded_vertices", report.welded_vertices},
                       {"degenerate_faces", report.degenerate_faces},
                       {"duplicate_faces", report.duplicate_faces},
                       {"winding_flipped", report.winding_flipped}}}}));
  broadcast_session("edited");
}

void Hub::handle(ClientId id, Client& c, const json& req_id, const std::string& type,
                 const RequestBody& body) {
  std::string error;
  if (const auto* h = std::get_if<Hello>(&body)) {
    error = on_hello(id, c, req_id, *h);
  } else if (std::holds_alternative<Ping>(body)) {
    c.peer->send(reply("pong", req_id, {{"time_s", steady_seconds()}}));
  } else if (const auto* o = std::get_if<Open>(&body)) {
    error = on_open(id, req_id, *o);
  } else if (const auto* s = std::get_if<Start>(&body)) {
    error = on_start(id, req_id, *s);
  } else if (std::holds_alternative<Stop>(body)) {
    error = on_stop(id, req_id);
  } else if (std::holds_alternative<Close>(body)) {
    error = on_close(id, req_id);
  } else if (const auto* sub = std::get_if<Subscribe>(&body)) {
    error = on_subscribe(id, c, req_id, *sub);
  } else if (std::holds_alternative<Unsubscribe>(body)) {
    c.rate_hz = 0.0;
    if (c.state_timer) c.state_timer->cancel();
    c.peer->send(reply("unsubscribed", req_id));
  } else if (std::holds_alternative<GetScene>(body)) {
    if (!slot_)
      error = "no scene is open";
    else
      c.peer->send(reply("scene", req_id,
                         {{"scene", describe_scene(slot_->scene())},
                          {"status", slot_->phase == Phase::kRunning    ? "running"
                                     : slot_->phase == Phase::kStarting ? "starting"
                                                                        : "open"},
                          {"controlled_here", slot_->controller == id}}));
  } else if (const auto* g = std::get_if<GetMesh>(&body)) {
    error = on_get_mesh(id, c, req_id, *g);
  } else {
    error = on_edit(id, req_id, type, body);
  }
  if (!error.empty()) c.peer->send(refusal(req_id, type, error));
}

std::string Hub::on_get_mesh(ClientId, Client& c, const json& req_id, const GetMesh& g) {
  if (!slot_) return "no scene is open";
  if (c.peer->queued_bytes() > kMaxQueuedBytesForMesh)
    return fmt::format(
        "{} bytes of replies wait to be sent to this connection; read them before asking for "
        "another mesh",
        c.peer->queued_bytes());
  auto made = slot_->mesh_replies.find(g.object);
  if (made == slot_->mesh_replies.end()) {
    auto mesh = scene_mesh(slot_->scene(), g.object);
    if (!mesh) return mesh.error().message;
    // the reply without its id, which each request sets
    made = slot_->mesh_replies.emplace(g.object, reply("mesh", nullptr, std::move(mesh).value())).first;
  }
  if (req_id.is_null()) {
    c.peer->send(made->second);
  } else {
    // the made reply, an object with fields, with the request's id as its first field
    c.peer->send(fmt::format("{{\"id\":{},{}", req_id.dump(), std::string_view(made->second).substr(1)));
  }
  return {};
}

std::string Hub::on_hello(ClientId, Client& c, const json& req_id, const Hello& h) {
  if (c.greeted) return "this connection already said hello";
  if (h.protocol != kProtocolVersion)
    return fmt::format("protocol {} is not supported (this service speaks protocol {})", h.protocol,
                       kProtocolVersion);
  if (!options_.token.empty() && !same_token(h.token, options_.token)) {
    // once per connection: the connection ends here
    log::warn("uh serve: {}: hello {}; the connection is closed", c.peer->address(),
              h.token.empty() ? "without the token" : "with a wrong token");
    c.peer->send(
        refusal(req_id, "hello",
                h.token.empty() ? "this service needs a token: send hello with \"token\"" : "wrong token"));
    c.closing = true;
    c.peer->close(1008, "wrong or missing token");
    return {};
  }
  c.greeted = true;
  json session = nullptr;
  if (slot_)
    session = {{"scene", slot_->scene().name},
               {"status", slot_->phase == Phase::kRunning    ? "running"
                          : slot_->phase == Phase::kStarting ? "starting"
                                                             : "open"}};
  c.peer->send(reply("welcome", req_id,
                     {{"protocol", kProtocolVersion},
                      {"version", UH_VERSION},
                      {"max_message_bytes", kMaxMessageBytes},
                      {"max_mesh_binary_bytes", kMaxMeshBinaryBytes},
                      {"session", std::move(session)}}));
  return {};
}

std::string Hub::check_control(ClientId id, bool needs_open) const {
  if (!slot_) return needs_open ? "no scene is open (send open first)" : "";
  if (slot_->controller != id)
    return slot_->controller == kHost ? "the session belongs to the program that runs it; this connection "
                                        "can watch it (subscribe, get_scene, get_mesh)"
                                      : "another client controls the open session; this connection can watch "
                                        "it (subscribe, get_scene, get_mesh)";
  return {};
}

// every error a client is sent names files relative to the service's root, never where the
// server keeps them
std::string Hub::refusal(const json& id, std::string_view request_type, std::string_view message) const {
  return error_reply(id, request_type, options_.folders.shown(std::string(message)));
}

std::string Hub::on_open(ClientId id, const json& req_id, const Open& o) {
  if (auto e = check_control(id, false); !e.empty()) return e;
  if (slot_ && slot_->phase != Phase::kOpen)
    return "the session is running; stop it before opening another scene";
  auto document = o.scene ? SceneDocument::open_file(std::filesystem::path(*o.scene).is_absolute()
                                                         ? std::filesystem::path(*o.scene)
                                                         : options_.working_dir / *o.scene,
                                                     options_.folders)
                          : SceneDocument::open_default(options_.cache_dir, options_.folders);
  if (!document) return document.error().message;
  ++generation_;
  slot_.emplace();
  slot_->controller = id;
  slot_->document = std::move(document).value();
  const controllers::Scene& scene = slot_->scene();
  json objects = json::array();
  for (const auto& object : scene.objects) objects.push_back(object.name);
  send_to(id, reply("opened", req_id,
                    {{"scene", scene.name}, {"objects", std::move(objects)}, {"tool", scene.tool().name}}));
  broadcast_session("opened");
  return {};
}

std::string Hub::on_start(ClientId id, const json& req_id, const Start& s) {
  if (auto e = check_control(id, true); !e.empty()) return e;
  if (slot_->phase == Phase::kStarting) return "the session is starting already";
  if (slot_->phase == Phase::kRunning) return "the session is running already";
  slot_->phase = Phase::kStarting;
  slot_->start_id = req_id;
  const std::uint64_t generation = ++generation_;
  controllers::SessionOptions options;
  options.cache_dir = options_.cache_dir;
  options.raise_priority = options_.raise_priority;
  // a session build may pack meshes for seconds: off the network thread, answered when done
  if (builder_.joinable()) builder_.join();
  builder_ = std::jthread([this, generation, seconds = s.seconds, scene = slot_->scene(), options] {
    auto built = std::make_shared<Result<std::unique_ptr<controllers::HapticSession>>>(
        controllers::HapticSession::create(scene, options));
    boost::asio::post(
        io_, [this, generation, seconds, built] { build_finished(generation, std::move(*built), seconds); });
  });
  broadcast_session("starting");
  return {};
}

void Hub::build_finished(std::uint64_t generation, Result<std::unique_ptr<controllers::HapticSession>> built,
                         std::optional<double> seconds) {
  // the slot was closed, stopped or replaced meanwhile: the session never starts
  if (shut_down_ || !slot_ || generation != generation_ || slot_->phase != Phase::kStarting) return;
  const ClientId controller = slot_->controller;
  const json start_id = slot_->start_id;
  if (!built) {
    slot_->phase = Phase::kOpen;
    send_to(controller, refusal(start_id, "start", built.error().message));
    broadcast_session("open");
    return;
  }
  slot_->owned = std::move(built).value();
  if (auto started = slot_->owned->start(); !started) {
    slot_->owned.reset();
    slot_->phase = Phase::kOpen;
    send_to(controller, refusal(start_id, "start", started.error().message));
    broadcast_session("open");
    return;
  }
  slot_->session = slot_->owned.get();
  slot_->phase = Phase::kRunning;
  send_to(controller, reply("started", start_id, {{"scene", slot_->scene().name}}));
  broadcast_session("started");
  poll_events();
  if (seconds) {
    stop_timer_.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(*seconds)));
    stop_timer_.async_wait([this, generation](const boost::system::error_code& ec) {
      if (ec || !slot_ || generation != generation_ || slot_->phase != Phase::kRunning) return;
      stop_by_itself("the session's seconds elapsed");
    });
  }
}

void Hub::stop_by_itself(const std::string& reason) {
  Status status{Ok{}};
  json state;
  json report = stop_session(&status, &state);
  json fields = {{"report", std::move(report)}, {"state", std::move(state)}, {"reason", reason}};
  if (!status) fields["error"] = status.error().message;
  send_to(slot_->controller, reply("stopped", nullptr, std::move(fields)));
  broadcast_session("stopped");
}

json Hub::stop_session(Status* status_out, json* state_out) {
  if (!slot_ || slot_->phase != Phase::kRunning) return nullptr;
  if (slot_->hosted) {
    // the program's own session stops on its owner's thread: ask it to (it ends within 20 ms)
    slot_->session->request_stop();
    return nullptr;
  }
  stop_timer_.cancel();
  event_timer_.cancel();
  Status status = slot_->session->stop();
  poll_events();  // the events up to the stop
  event_timer_.cancel();
  // after the stop: the zero force the device was sent last
  if (state_out != nullptr) *state_out = session_state_json(*slot_->session);
  json report = json::parse(controllers::session_report_json(slot_->session->report()));
  slot_->phase = Phase::kOpen;
  slot_->session = nullptr;
  slot_->owned.reset();
  if (status_out != nullptr) *status_out = status;
  return report;
}

std::string Hub::on_stop(ClientId id, const json& req_id) {
  if (auto e = check_control(id, true); !e.empty()) return e;
  if (slot_->phase == Phase::kOpen) return "the session is not running";
  json fields = json::object();
  if (slot_->phase == Phase::kStarting) {
    // the build finishes on its own thread and is dropped then
    ++generation_;
    slot_->phase = Phase::kOpen;
    fields["report"] = nullptr;
    fields["state"] = nullptr;
  } else {
    Status status{Ok{}};
    json state;
    fields["report"] = stop_session(&status, &state);
    fields["state"] = std::move(state);
    if (!status) fields["error"] = status.error().message;
  }
  send_to(id, reply("stopped", req_id, std::move(fields)));
  broadcast_session("stopped");
  return {};
}

std::string Hub::on_close(ClientId id, const json& req_id) {
  if (auto e = check_control(id, true); !e.empty()) return e;
  stop_session();
  close_slot();
  send_to(id, reply("closed", req_id));
  return {};
}

void Hub::close_slot() {
  if (!slot_) return;
  ++generation_;
  stop_timer_.cancel();
  event_timer_.cancel();
  // the scene's inline meshes were its own: they go with it
  for (const auto& file : slot_->inline_meshes) remove_inline_mesh(file, options_.cache_dir);
  slot_.reset();
  broadcast_session("closed");
}

void Hub::broadcast_session(std::string_view status) {
  json fields = {{"status", std::string(status)}};
  if (slot_) fields["scene"] = slot_->scene().name;
  const std::string text = reply("session", nullptr, std::move(fields));
  for (auto& [id, c] : clients_)
    if (c.greeted) c.peer->send(text);
}

std::string Hub::on_subscribe(ClientId id, Client& c, const json& req_id, const Subscribe& s) {
  c.rate_hz = s.rate_hz;
  if (!c.state_timer) c.state_timer = std::make_unique<boost::asio::steady_timer>(io_);
  c.state_timer->cancel();
  c.peer->send(reply("subscribed", req_id, {{"rate_hz", s.rate_hz}}));
  c.state_timer->expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / s.rate_hz)));
  // each period from the previous deadline, so the rate does not drift with the send time
  struct Tick {
    Hub* hub;
    ClientId id;
    void operator()(const boost::system::error_code& ec) const {
      if (ec) return;
      const auto it = hub->clients_.find(id);
      if (it == hub->clients_.end() || it->second.rate_hz <= 0.0) return;
      hub->send_state(id);
      auto& timer = *it->second.state_timer;
      const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(1.0 / it->second.rate_hz));
      const auto now = std::chrono::steady_clock::now();
      auto next = timer.expiry() + period;
      if (next < now) next = now + period;  // fell behind (a busy machine): skip, do not burst
      timer.expires_at(next);
      timer.async_wait(*this);
    }
  };
  c.state_timer->async_wait(Tick{this, id});
  return {};
}

void Hub::send_state(ClientId id) {
  if (!slot_ || slot_->phase != Phase::kRunning) return;
  const auto it = clients_.find(id);
  if (it == clients_.end()) return;
  json state = session_state_json(*slot_->session);
  add_deformed(it->second, state);
  it->second.peer->send(reply("state", nullptr, std::move(state)), true);
}

void Hub::add_deformed(Client& c, json& state) {
  controllers::HapticSession& session = *slot_->session;
  const std::size_t objects = session.scene().objects.size();
  const double now = steady_seconds();
  if (objects == 0 || now - c.deformed_sent_s < 1.0 / kDeformedRateHz) return;
  c.deformed_steps.resize(objects, 0);
  json deformed = json::array();
  std::size_t room = kMaxDeformedVertices;
  for (std::size_t k = 0; k < objects; ++k) {
    const std::size_t i = (c.next_deformed + k) % objects;
    if (session.soft_simulation(i) == nullptr) continue;
    const auto count = session.soft_vertex_count(i);
    if (!count || *count > room) continue;
    deformed_scratch_.resize(3 * *count);
    const auto step = session.soft_vertices(i, deformed_scratch_);
    if (!step || *step == c.deformed_steps[i]) continue;
    c.deformed_steps[i] = *step;
    room -= *count;
    deformed.push_back(deformed_json(session.scene().objects[i].name, *step, deformed_scratch_));
  }
  c.next_deformed = (c.next_deformed + 1) % objects;
  if (deformed.empty()) return;
  c.deformed_sent_s = now;
  state["deformed"] = std::move(deformed);
}

void Hub::poll_events() {
  if (!slot_ || slot_->phase != Phase::kRunning) return;
  // a thread that ended or a device that faulted has zeroed the force already; the session ends
  // and its controller learns why (a hosted session's owner sees it itself)
  if (!slot_->hosted && slot_->session->ended_by_itself()) {
    stop_by_itself("a thread of the session ended or a device faulted");
    return;
  }
  controllers::ContactEvent event;
  const controllers::Scene& scene = slot_->scene();
  while (slot_->session->poll_event(event)) {
    const bool known = event.object >= 0 && static_cast<std::size_t>(event.object) < scene.objects.size();
    const std::string text =
        reply("contact", nullptr,
              {{"event", event.kind == controllers::ContactEventKind::kBegin ? "begin" : "end"},
               {"object", known ? scene.objects[static_cast<std::size_t>(event.object)].name : std::string()},
               {"tool", static_cast<std::size_t>(event.tool) < scene.tools.size()
                            ? scene.tools[static_cast<std::size_t>(event.tool)].name
                            : std::string()},
               {"time_s", event.time_s},
               {"volume", event.volume},
               {"pairs", event.pairs}});
    for (auto& [id, c] : clients_)
      if (c.greeted && (c.rate_hz > 0.0 || id == slot_->controller)) c.peer->send(text);
  }
  event_timer_.expires_after(10ms);
  event_timer_.async_wait([this](const boost::system::error_code& ec) {
    if (!ec) poll_events();
  });
}

std::string Hub::on_edit(ClientId id, const json& req_id, const std::string& type, const RequestBody& body) {
  if (auto e = check_control(id, true); !e.empty()) return e;
  if (const auto* p = std::get_if<SetPose>(&body); p != nullptr && slot_->phase == Phase::kRunning)
    return move_object(id, req_id, *p);
  if (slot_->phase != Phase::kOpen)
    return "the session is running; stop it before editing the scene (only set_pose moves objects while it "
           "runs)";
  SceneDocument& doc = *slot_->document;
  Status done{Ok{}};
  json fields = json::object();
  if (const auto* a = std::get_if<AddObject>(&body)) {
    done = doc.add_object(a->object, options_.working_dir);
    if (done) fields["name"] = doc.scene().objects.back().name;
  } else if (const auto* r = std::get_if<RemoveObject>(&body)) {
    done = doc.remove_object(r->name);
    fields["name"] = r->name;
  } else if (const auto* p = std::get_if<SetPose>(&body)) {
    done = doc.set_pose(p->object, p->pose);
    fields["object"] = p->object;
  } else if (const auto* w = std::get_if<SetWatch>(&body)) {
    done = doc.set_watch(w->objects);
    fields["objects"] = doc.scene().watch;
  } else if (const auto* d = std::get_if<SetDevice>(&body)) {
    done = doc.set_device(d->device, options_.working_dir);
    fields["driver"] = doc.scene().tool().device.driver;
  } else if (const auto* t = std::get_if<SetTool>(&body)) {
    done = doc.set_tool(t->tool, options_.working_dir);
    fields["name"] = doc.scene().tool().name;
  } else if (const auto* rates = std::get_if<SetRates>(&body)) {
    done = doc.set_rates(rates->haptic_hz, rates->collision_hz);
    fields["haptic_hz"] = doc.scene().haptic_hz;
    fields["collision_hz"] = doc.scene().collision_hz;
  }
  if (!done) return done.error().message;
  slot_->mesh_replies.clear();  // an object may have another mesh now
  static const std::map<std::string, std::string, std::less<>> kReplies = {
      {"add_object", "object_added"}, {"remove_object", "object_removed"}, {"set_pose", "pose_set"},
      {"set_watch", "watch_set"},     {"set_device", "device_set"},        {"set_tool", "tool_set"},
      {"set_rates", "rates_set"}};
  send_to(id, reply(kReplies.at(type), req_id, std::move(fields)));
  broadcast_session("edited");
  return {};
}

std::string Hub::move_object(ClientId id, const json& req_id, const SetPose& p) {
  SceneDocument& doc = *slot_->document;
  if (auto done = doc.set_pose(p.object, p.pose); !done) return done.error().message;
  const auto& objects = doc.scene().objects;
  for (std::size_t i = 0; i < objects.size(); ++i)
    if (objects[i].name == p.object) {
      if (auto moved = slot_->session->set_object_pose(static_cast<std::int32_t>(i), objects[i].pose); !moved)
        return moved.error().message;
      break;
    }
  send_to(id, reply("pose_set", req_id, {{"object", p.object}}));
  return {};
}

void Hub::disconnect(ClientId id) {
  clients_.erase(id);
  if (slot_ && slot_->controller == id) {
    // the controlling client is gone: its session stops (zero force) and the slot is free
    stop_session();
    close_slot();
  }
}

Status Hub::show(controllers::HapticSession& session) {
  if (shut_down_) return Error{"the service is stopping"};
  if (slot_) return Error{"a client's session is open in the service"};
  ++generation_;
  slot_.emplace();
  slot_->controller = kHost;
  slot_->hosted = session.scene();
  slot_->session = &session;
  slot_->phase = Phase::kRunning;
  broadcast_session("opened");
  broadcast_session("started");
  poll_events();
  return Ok{};
}

void Hub::unshow() {
  if (!slot_ || !slot_->hosted) return;
  poll_events();  // the events up to the end
  broadcast_session("stopped");
  close_slot();
}

void Hub::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  stop_session();
  close_slot();
  for (auto& [id, c] : clients_) {
    if (c.state_timer) c.state_timer->cancel();
    c.peer->close(1001, "the service is stopping");
  }
  if (builder_.joinable()) builder_.join();
  if (mesher_.joinable()) mesher_.join();
}

}  // namespace uh::service
