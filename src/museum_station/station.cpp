#include "uh/museum_station/station.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "uh/collette/ist_cache.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/controllers/session_model.hpp"
#include "uh/core/log.hpp"
#include "uh/devices/device_probe.hpp"
#include "uh/devices/hardware_drivers.hpp"
#include "uh/museum_artifacts/artifact.hpp"

namespace uh::museum_station {

using museum_protocol::GuardView;
using museum_protocol::ServerError;

namespace {

constexpr double kHomeAboveTopM = 0.03;   // home: this far over the middle of the piece's top
constexpr double kVolumeStep = 0.1;
constexpr const char* kSimulatedHand = "sim-hand";

std::string clock_words(double seconds) {
  const int s = std::max(0, static_cast<int>(std::lround(seconds)));
  if (s >= 60)
    return s % 60 == 0 ? fmt::format("{} minute{}", s / 60, s / 60 == 1 ? "" : "s")
                       : fmt::format("{} minute{} {} seconds", s / 60, s / 60 == 1 ? "" : "s", s % 60);
  return fmt::format("{} seconds", s);
}

std::string list_words(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += i + 1 == names.size() ? " and " : ", ";
    out += "the " + names[i];
  }
  return out.empty() ? "nothing" : out;
}

}  // namespace

Status check_device(const std::string& device) {
  if (device.empty()) return Ok{};  // the simulated hand
  const haptico::DeviceRegistry registry = devices::all_drivers();
  auto choice = devices::parse_device_choice(device, registry);
  if (!choice) return choice.error();
  auto made = registry.create(choice->driver, choice->selection);
  if (!made) return Error{fmt::format("--device {}: {}", device, made.error().message)};
  if (Status opened = (*made)->open(); !opened)
    return Error{fmt::format("--device {}: the device does not open: {}", device, opened.error().message)};
  if (Status closed = (*made)->close(); !closed)
    return Error{fmt::format("--device {}: the device does not close: {}", device, closed.error().message)};
  return Ok{};
}

Vec3 HomeGuide::force_at(Vec3 position) {
  const Vec3 away = position - home_;
  const double d = norm(away);
  if (guiding() && d <= options_.arrived_m) guiding_.store(false, std::memory_order_relaxed);
  const double free = guiding() ? 0.0 : options_.free_radius_m;
  if (!(d > free) || !std::isfinite(d)) return {};
  const double magnitude = std::min(options_.stiffness_n_per_m * (d - free), options_.max_force_n);
  return away * (-magnitude / d);
}

void HomeGuide::on_force(const haptico::DeviceState& state, haptico::DeviceCommand& command) {
  command.force += force_at(state.position);
}

Station::Station(const Welcome& welcome, StationOptions options, std::optional<StationSound> sound,
                 GameLink* link)
    : level_(welcome.level),
      targets_(welcome.targets),
      options_(std::move(options)),
      sound_(std::move(sound)),
      link_(link) {}

Station::~Station() { stop(); }

Result<std::unique_ptr<Station>> Station::create(const Welcome& welcome, StationOptions options,
                                                 std::optional<StationSound> sound, GameLink* link) {
  std::string driver = kSimulatedHand;
  haptico::DeviceConfig config;
  if (!options.device.empty()) {
    auto choice = devices::parse_device_choice(options.device, devices::all_drivers());
    if (!choice) return choice.error();
    driver = choice->driver;
    config = choice->selection;
  }
  if (options.cache_dir.empty()) options.cache_dir = controllers::default_cache_dir();
  std::unique_ptr<Station> station(new Station(welcome, std::move(options), std::move(sound), link));
  station->device_driver_ = driver;
  station->device_config_ = config;
  station->view_.item_count = 0;
  // Falcon's briefing
  station->say(
      fmt::format("Falcon here. Tonight's targets: {}. Each has a forgery that looks the same. Vive brings "
                  "them to your table; feel each one and tell me: genuine or forgery.",
                  list_words(station->targets_)),
      fmt::format("Falcon: targets {}", list_words(station->targets_)), false);
  return station;
}

void Station::say(const std::string& speech, const std::string& caption, bool urgent) {
  captions_.push_back(caption);
  last_speech_ = speech;
  if (options_.on_caption) options_.on_caption(caption);
  if (sound_) {
    if (Status s = sound_->say(speech, urgent); !s)
      log::warn("museum station: cannot speak: {}", s.error().message);
  }
}

void Station::cue(const museum::Cue& c) {
  if (sound_) sound_->earcon(static_cast<int>(c.earcon));
  say(c.speech, c.caption, c.urgent);
}

void Station::handle(const LinkNote& note) {
  switch (note.kind) {
    case LinkNote::Kind::message:
      on_message(note.message);
      break;
    case LinkNote::Kind::bad_message:
      break;  // the link logged it; nothing else to do
    case LinkNote::Kind::dropped:
      link_up_ = false;
      update_hold();
      say("Lost the museum server. Forces are off until it is back.", "Server lost", true);
      break;
    case LinkNote::Kind::reconnected:
      link_up_ = true;
      say("Back on the museum server.", "Server back", false);
      update_hold();
      break;
  }
}

void Station::remember_items(const std::vector<ItemView>& items) {
  for (const ItemView& it : items) {
    if (it.item < 0 || it.item >= museum::kMaxItems) continue;
    const auto kind = std::find(level_.artifact_kinds.begin(), level_.artifact_kinds.end(), it.kind);
    if (kind == level_.artifact_kinds.end()) continue;
    view_.items[static_cast<std::size_t>(it.item)].kind =
        static_cast<int>(kind - level_.artifact_kinds.begin());
    view_.item_count = std::max(view_.item_count, it.item + 1);
  }
}

void Station::on_message(const ServerMessage& message) {
  if (const auto* s = std::get_if<Snapshot>(&message)) return on_snapshot(*s);
  if (const auto* e = std::get_if<GameEvent>(&message)) return on_event(e->event);
  if (const auto* h = std::get_if<InHand>(&message)) return on_in_hand(*h);
  if (const auto* w = std::get_if<Welcome>(&message)) {
    level_ = w->level;
    targets_ = w->targets;
    return;
  }
  if (const auto* sum = std::get_if<Summary>(&message)) {
    summary_ = *sum;
    const bool clean = sum->forgeries_kept == 0 && sum->genuine_rejected == 0;
    if (sound_) sound_->earcon(static_cast<int>(clean ? museum::Earcon::right : museum::Earcon::wrong));
    const museum::Cue end =
        museum::describe({.type = museum::EventType::round_ended, .count = sum->points}, level_, view_);
    say(fmt::format(
            "{} Genuine pieces kept: {}. Forgeries kept: {}. Genuine pieces put aside: {}. Forgeries put "
            "aside: {}.",
            end.speech, sum->genuine_kept, sum->forgeries_kept, sum->genuine_rejected,
            sum->forgeries_rejected),
        end.caption, true);
    return;
  }
  if (const auto* err = std::get_if<ServerError>(&message)) {
    log::warn("museum station: the server refused {}: {}", err->request.empty() ? "a message" : err->request,
              err->message);
    return;
  }
}

void Station::on_snapshot(const Snapshot& s) {
  const bool was_playing = have_snapshot_ && last_snapshot_.phase == "playing";
  last_snapshot_ = s;
  have_snapshot_ = true;
  for (const museum_protocol::CaseView& c : s.cases) remember_items({c.item});
  remember_items(s.carried);
  remember_items(s.table);
  view_.table_count = 0;
  for (const ItemView& it : s.table)
    if (it.item >= 0 && view_.table_count < museum::kMaxItems)
      view_.table[static_cast<std::size_t>(view_.table_count++)] = it.item;
  view_.time_left_s = s.time_left_s;
  // the server says what comes to the front of the table (in_hands), not that the table emptied
  if (s.table.empty() && in_hand_.item >= 0) on_in_hand({});
  if (sound_) {
    std::vector<museum::Vec2> guards;
    guards.reserve(s.guards.size());
    for (const GuardView& g : s.guards) guards.push_back(g.pos);
    sound_->set_guards(s.vive_pos, s.vive_facing, guards);
  }
  if (s.phase == "playing" && !was_playing) say("The round is on.", "Playing", false);
  if (s.phase == "paused" && was_playing) say("The round is paused: a player dropped out.", "Paused", true);
  // the timer, spoken each whole minute (the last seconds come as time warnings)
  const int minute = static_cast<int>(std::ceil(s.time_left_s / 60.0 - 1e-9));
  if (s.phase == "playing" && minute != last_minute_said_ && last_minute_said_ >= 0 && minute >= 1)
    say(fmt::format("{} left.", clock_words(minute * 60.0)), fmt::format("{} min left", minute), false);
  if (s.phase == "playing") last_minute_said_ = minute;
  update_hold();
}

void Station::on_event(const museum::Event& e) {
  using museum::EventType;
  if (e.type == EventType::round_ended) return;  // said with the summary, which has the points
  if (e.type == EventType::verdict) {
    // whether it was right is only told at the end
    const std::string name =
        e.item >= 0 && e.item < museum::kMaxItems && view_.items[static_cast<std::size_t>(e.item)].kind >= 0
            ? level_.artifact_kinds[static_cast<std::size_t>(
                  view_.items[static_cast<std::size_t>(e.item)].kind)]
            : std::string("artifact");
    if (sound_) sound_->earcon(kVerdictSentEarcon);
    say(fmt::format("Falcon has your verdict: the {} is {}.", name,
                    e.verdict == museum::Verdict::genuine ? "genuine" : "a forgery"),
        fmt::format("{}: {}", name, museum::to_string(e.verdict)), false);
    return;
  }
  if (e.type == EventType::items_delivered) {
    // the event comes before the snapshot that shows them on the table
    for (const ItemView& it : last_snapshot_.carried)
      if (it.item >= 0 && view_.table_count < museum::kMaxItems &&
          std::find(view_.table.begin(), view_.table.begin() + view_.table_count, it.item) ==
              view_.table.begin() + view_.table_count)
        view_.table[static_cast<std::size_t>(view_.table_count++)] = it.item;
  }
  cue(museum::describe(e, level_, view_));
}

void Station::on_in_hand(const InHand& h) {
  if (h.item == in_hand_.item && (session_ || h.item < 0)) return;
  end_session();
  in_hand_ = h;
  piece_error_.clear();
  if (h.item < 0) return;
  if (Status loaded = load_piece(h); !loaded) {
    piece_error_ = loaded.error().message;
    log::error("museum station: cannot put the {} in your hands: {}", h.kind, piece_error_);
    say(fmt::format("The {} cannot be felt: {}", h.kind, piece_error_), "Piece failed to load", true);
    return;
  }
  say(fmt::format("The {} is in your hands.", h.kind), fmt::format("In hand: {}", h.kind), false);
}

Status Station::load_piece(const InHand& h) {
  // the station builds the form it is sent: which piece that is, only the server knows
  if (h.form.kind != h.kind)
    return Error{fmt::format("the server sent the form of a '{}' for a '{}'", h.form.kind, h.kind)};
  auto object = museum_artifacts::artifact_object(h.form, options_.cache_dir, h.kind, Pose{});
  if (!object) return object.error();
  const Sphere ball{0.f, 0.f, 0.f, static_cast<float>(museum_artifacts::kStylusRadiusM)};
  auto stylus = collette::build_sphere_tree(std::span<const Sphere>(&ball, 1));
  if (!stylus) return stylus.error();

  controllers::Scene scene = museum_artifacts::table_scene(
      *object, std::make_shared<const collette::SphereTree>(std::move(*stylus)), options_.haptic_hz);
  scene.tool().device.driver = device_driver_;
  scene.tool().device.config = device_config_;
  collette::IstCache cache(options_.cache_dir);
  auto compiled = controllers::compile(scene, cache, {.progress = options_.build_progress});
  if (!compiled) return compiled.error();
  std::shared_ptr<const controllers::SessionModel> model = *compiled;

  // the highest point of the piece (a rim, a lid, the top of a slab)
  Vec3 peak{};
  for (const Sphere& s : model->objects[0].tree->leaves())
    if (static_cast<double>(s.z + s.radius) > peak.z)
      peak = {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z + s.radius)};
  const double top = peak.z;
  if (device_driver_ == kSimulatedHand && !device_config_.has("target_start")) {
    // the simulated hand comes down onto the piece's highest point from over the middle, pressing
    // in 4 mm, and back, again and again: its script is the compiled piece's (a copy of the
    // model, its trees and surface shared)
    auto scripted = std::make_shared<controllers::SessionModel>(*model);
    haptico::DeviceConfig& config = scripted->scene.tool().device.config;
    config.set("target_start", Vec3{0.0, 0.0, top + museum_artifacts::kStylusRadiusM + 0.015});
    config.set("target_end", Vec3{peak.x, peak.y, top + museum_artifacts::kStylusRadiusM - 0.004});
    config.set("duration_s", 1.5);
    config.set("bounce", 1.0);
    model = std::move(scripted);
  }
  auto session = controllers::HapticSession::create(model);
  if (!session) return session.error();
  guide_ = std::make_unique<HomeGuide>(options_.home);
  guide_->set_home({0.0, 0.0, top + kHomeAboveTopM});
  guide_connection_ = (*session)->force_on_haptic_tick().connect<&HomeGuide::on_force>(*guide_);
  if (held_) (*session)->halt();
  if (!options_.trace.empty()) {
    trace_ = std::make_unique<std::ofstream>(options_.trace, std::ios::binary | std::ios::trunc);
    if (!*trace_) {
      trace_.reset();
      guide_connection_.disconnect();
      guide_.reset();
      return Error{fmt::format("cannot write the trace '{}'", options_.trace.string())};
    }
  }
  if (Status started = (*session)->start(trace_.get()); !started) {
    guide_connection_.disconnect();
    guide_.reset();
    trace_.reset();
    return started;
  }
  session_ = std::move(*session);
  have_tool_pos_ = false;
  last_buttons_ = 0;
  if (sound_) sound_->set_material(object->material);
  return Ok{};
}

void Station::end_session() {
  if (!session_) return;
  if (Status s = session_->stop(); !s)
    log::warn("museum station: the session ended with: {}", s.error().message);
  guide_connection_.disconnect();
  session_.reset();
  guide_.reset();
  trace_.reset();  // after stop(): its last row is the zero the device was sent
  if (sound_) sound_->set_contact(false, 0.0);
}

void Station::update_hold() {
  const bool hold = !link_up_ || !have_snapshot_ || last_snapshot_.phase != "playing";
  if (hold == held_) return;
  held_ = hold;
  if (!session_) return;
  if (hold)
    session_->halt();
  else
    session_->resume();
}

void Station::give_verdict(museum::Verdict verdict) {
  if (in_hand_.item < 0) return say("Nothing is in your hands yet.", "Nothing in hand", false);
  for (const auto& [item, v] : verdicts_sent_)
    if (item == in_hand_.item)
      return say("You already gave your verdict on this piece.", "Already judged", false);
  if (link_ == nullptr ||
      !link_->send(museum_protocol::write_message(museum_protocol::VerdictMessage{in_hand_.item, verdict})))
    return say("The verdict could not be sent; try again.", "Verdict not sent", true);
  verdicts_sent_.emplace_back(in_hand_.item, verdict);
  if (sound_) sound_->earcon(kVerdictSentEarcon);
  say(fmt::format("{}. Sent.", verdict == museum::Verdict::genuine ? "Genuine" : "Forgery"),
      fmt::format("Verdict sent: {}", museum::to_string(verdict)), false);
}

void Station::press(StationKey key) {
  switch (key) {
    case StationKey::where_am_i: {
      std::string text;
      if (have_snapshot_) {
        text = fmt::format(
            "Vive is in {}, carrying {}. ", museum::room_at(level_, last_snapshot_.vive_pos),
            last_snapshot_.carried.empty() ? std::string("nothing") : [&] {
              std::vector<std::string> kinds;
              for (const ItemView& it : last_snapshot_.carried) kinds.push_back(it.kind);
              return list_words(kinds);
            }());
        text += fmt::format("{} left. ", clock_words(last_snapshot_.time_left_s));
      }
      text += in_hand_.item >= 0 ? fmt::format("In your hands: the {}", in_hand_.kind)
                                 : std::string("Your hands are empty");
      const int waiting =
          have_snapshot_ ? static_cast<int>(last_snapshot_.table.size()) - (in_hand_.item >= 0 ? 1 : 0) : 0;
      text += waiting > 0 ? fmt::format(", and {} more on the table. ", waiting) : std::string(". ");
      text += fmt::format("Targets: {}.", list_words(targets_));
      return say(text, text, true);  // the answer is its own caption
    }
    case StationKey::repeat:
      if (last_speech_.empty()) return;
      if (options_.on_caption && !captions_.empty()) options_.on_caption(captions_.back());
      if (sound_) (void)sound_->say(last_speech_, true);
      return;
    case StationKey::genuine:
      return give_verdict(museum::Verdict::genuine);
    case StationKey::forgery:
      return give_verdict(museum::Verdict::forgery);
    case StationKey::guide_home:
      if (guide_) guide_->guide_home();
      return say("Guiding your hand home, over the piece.", "Going home", false);
    case StationKey::volume_up:
    case StationKey::volume_down: {
      if (!sound_) return say("There is no sound on this station.", "No sound", false);
      const double v = std::clamp(
          sound_->volume(channel_) + (key == StationKey::volume_up ? kVolumeStep : -kVolumeStep), 0.0, 1.0);
      sound_->set_volume(channel_, v);
      return say(fmt::format("{} volume {:.0f} percent.", audio::to_string(channel_), v * 100.0),
                 fmt::format("{} {:.0f}%", audio::to_string(channel_), v * 100.0), false);
    }
    case StationKey::next_channel:
      channel_ = static_cast<audio::Channel>((static_cast<int>(channel_) + 1) % audio::kChannelCount);
      return say(fmt::format("Volume keys now change the {}.", audio::to_string(channel_)),
                 fmt::format("Volume: {}", audio::to_string(channel_)), false);
  }
}

void Station::frame(double dt_s) {
  if (session_) {
    const controllers::SessionState st = session_->state();
    const std::uint32_t pressed = st.buttons & ~last_buttons_;
    last_buttons_ = st.buttons;
    if ((pressed & kGenuineButton) != 0) give_verdict(museum::Verdict::genuine);
    if ((pressed & kForgeryButton) != 0) give_verdict(museum::Verdict::forgery);
    double speed = 0.0;
    if (have_tool_pos_ && st.time_s > last_tool_time_s_)
      speed = norm(st.tool_position_world - last_tool_pos_) / (st.time_s - last_tool_time_s_);
    last_tool_pos_ = st.tool_position_world;
    last_tool_time_s_ = st.time_s;
    have_tool_pos_ = true;
    controllers::ContactEvent event;
    while (session_->poll_event(event)) {
    }
    if (sound_) sound_->set_contact(st.contact_pairs > 0 && !held_, speed);
  }
  if (sound_) sound_->update(dt_s);
}

void Station::stop() { end_session(); }

}  // namespace uh::museum_station
