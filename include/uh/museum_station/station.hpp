#pragma once
/// \file
/// Station: Phantom's side of the museum heist (`uh museum station`, docs/museum.md "Playing
/// Phantom"). It takes what the server says (GameLink's notes), keeps the round's view, speaks and
/// plays it (StationSound, when there is audio), and runs a HapticSession on the artifact in
/// Phantom's hands: the piece is loaded (its .ist packed on first use and cached like any scene
/// object's) when it reaches the front of the table, felt with the device, and judged with the
/// device's buttons or the keys. A home spring guides the stylus back over the piece.
///
/// Threads: the station's calls run on one (non-real-time) thread; the haptic and collision
/// threads are the session's. Data crosses only through the session's state() (a LatestValue),
/// the home spring's atomics and the GameLink's queues: the haptic loop never waits on the network.

#include <atomic>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "uh/controllers/haptic_session.hpp"
#include "uh/core/result.hpp"
#include "uh/museum/cues.hpp"
#include "uh/museum/game_state.hpp"
#include "uh/museum_client/game_link.hpp"
#include "uh/museum_station/station_sound.hpp"

namespace uh::museum_station {

// the server's messages and the connection, as every client of the game server has them
using museum_protocol::GameEvent;
using museum_client::GameLink;
using museum_protocol::InHand;
using museum_protocol::ItemView;
using museum_client::LinkNote;
using museum_protocol::ServerMessage;
using museum_protocol::Snapshot;
using museum_protocol::Summary;
using museum_protocol::Welcome;

/// The home spring: beyond `free_radius_m` from home the stylus is pulled back with a soft spring
/// whose force never exceeds `max_force_n` (and then passes the session's limit chain like every
/// force). "Guide me home" pulls from anywhere until the stylus is within `arrived_m`.
struct HomeGuideOptions {
  double stiffness_n_per_m = 40.0;
  double max_force_n = 1.0;
  double free_radius_m = 0.07;
  double arrived_m = 0.01;
};

/// The spring itself, bound to a session's force delegate (real-time safe: atomics only).
class HomeGuide {
 public:
  explicit HomeGuide(const HomeGuideOptions& options) : options_(options) {}
  /// Home in the device's frame [m]. Owner thread, before the session starts.
  void set_home(Vec3 home) { home_ = home; }
  Vec3 home() const { return home_; }
  /// Pull from anywhere until the stylus is home. Any thread.
  void guide_home() { guiding_.store(true, std::memory_order_relaxed); }
  bool guiding() const { return guiding_.load(std::memory_order_relaxed); }
  /// The spring's force for a handle at `position` (device frame) [N]: also what the tests check.
  Vec3 force_at(Vec3 position);
  /// ForceOnHapticTick: adds the spring to the command. Haptic thread.
  void on_force(const haptico::DeviceState& state, haptico::DeviceCommand& command);

 private:
  HomeGuideOptions options_;
  Vec3 home_{};
  std::atomic<bool> guiding_{false};
};

/// What the keys (and the buttons) ask for.
enum class StationKey : std::uint8_t {
  where_am_i,    ///< says where Vive is, what is in Phantom's hands, the time and the targets
  repeat,        ///< says the last line again
  genuine,       ///< the verdict on the piece in hand
  forgery,       ///< the verdict on the piece in hand
  guide_home,    ///< pulls the stylus home
  volume_up,     ///< of the selected channel
  volume_down,   ///< of the selected channel
  next_channel,  ///< selects the next channel for the volume keys
};

struct StationOptions {
  /// The device as `uh run --device` takes it (DRIVER[:SELECTOR]); empty: a simulated hand that
  /// strokes the piece's top back and forth.
  std::string device{};
  std::filesystem::path cache_dir{};  ///< .ist cache; empty: controllers::default_cache_dir()
  double haptic_hz = 1000.0;
  HomeGuideOptions home{};
  /// Each caption (what is also spoken) as it is said: the CLI prints them, the tests read them.
  std::function<void(const std::string&)> on_caption{};
  /// Progress while a piece is packed on first use.
  std::function<void(const std::string& what, double fraction)> build_progress{};
  /// When set, the haptic trace (CSV, as `uh run --trace`) of the piece in Phantom's hands: the
  /// file is written anew for each piece; its last row is the zero sent when that piece's session
  /// stopped.
  std::filesystem::path trace{};
};

/// Checks a device as StationOptions::device takes it before the round: the driver and its
/// settings, and that the device opens (it is closed again at once). Errors name `device`.
Status check_device(const std::string& device);

/// Which device button gives which verdict (bit i: button i; the first button is the one under
/// the index finger on a stylus).
inline constexpr std::uint32_t kGenuineButton = 1u << 0;
inline constexpr std::uint32_t kForgeryButton = 1u << 1;

class Station {
 public:
  /// A station for the round the welcome describes. `sound` empty: no audio (captions only).
  /// Errors: a bad device selector, a level the station cannot play.
  static Result<std::unique_ptr<Station>> create(const Welcome& welcome, StationOptions options,
                                                 std::optional<StationSound> sound, GameLink* link);
  ~Station();
  Station(const Station&) = delete;
  Station& operator=(const Station&) = delete;

  /// Takes a note from the link: the view, cues, the piece in hand, pause and drop (the force goes
  /// to zero at once).
  void handle(const LinkNote& note);
  /// A key or button.
  void press(StationKey key);
  /// Per frame of the station's loop: buttons, the contact sound, speech and ducking.
  void frame(double dt_s);
  /// Stops the session (zero force) and the sound. Idempotent.
  void stop();

  // what the station is doing (the CLI's status line and the tests)
  /// The item whose piece the session renders, or -1.
  int item_in_hand() const { return in_hand_.item; }
  /// What the server said is in Phantom's hands (item -1: nothing).
  const InHand& in_hand() const { return in_hand_; }
  /// The session on the piece in hand, if any.
  controllers::HapticSession* session() { return session_.get(); }
  const HomeGuide* home_guide() const { return guide_.get(); }
  /// Whether forces are held at zero now (no round playing, the server away).
  bool held() const { return held_; }
  const std::vector<std::string>& captions() const { return captions_; }
  /// Verdicts sent to the server (item, verdict), in order.
  const std::vector<std::pair<int, museum::Verdict>>& verdicts_sent() const { return verdicts_sent_; }
  const std::optional<Summary>& summary() const { return summary_; }
  StationSound* sound() { return sound_ ? &*sound_ : nullptr; }
  /// The channel the volume keys change.
  audio::Channel selected_channel() const { return channel_; }
  /// The last error loading a piece or starting its session (empty: none).
  const std::string& piece_error() const { return piece_error_; }

 private:
  Station(const Welcome& welcome, StationOptions options, std::optional<StationSound> sound, GameLink* link);
  void on_message(const ServerMessage& message);
  void on_snapshot(const Snapshot& s);
  void on_event(const museum::Event& e);
  void on_in_hand(const InHand& h);
  void cue(const museum::Cue& c);
  void say(const std::string& speech, const std::string& caption, bool urgent);
  void give_verdict(museum::Verdict verdict);
  void update_hold();
  Status load_piece(const InHand& h);
  void end_session();
  void remember_items(const std::vector<ItemView>& items);

  museum::Level level_;
  std::vector<std::string> targets_;
  StationOptions options_;
  std::optional<StationSound> sound_;
  GameLink* link_ = nullptr;
  std::string device_driver_;
  haptico::DeviceConfig device_config_;

  museum::GameState view_{};  // what the station knows of the round: kinds of the items seen, the table
  Snapshot last_snapshot_{};
  bool have_snapshot_ = false;
  bool link_up_ = true;
  bool held_ = true;
  InHand in_hand_{};
  std::unique_ptr<HomeGuide> guide_;
  std::unique_ptr<controllers::HapticSession> session_;
  std::unique_ptr<std::ofstream> trace_;  // outlives the session's stop(), which writes its last row
  ScopedConnection guide_connection_;  // the home spring on the session's force delegate
  Vec3 last_tool_pos_{};
  bool have_tool_pos_ = false;
  std::uint32_t last_buttons_ = 0;
  double last_tool_time_s_ = 0.0;
  std::vector<std::string> captions_;
  std::string last_speech_;
  std::vector<std::pair<int, museum::Verdict>> verdicts_sent_;
  std::optional<Summary> summary_;
  audio::Channel channel_ = audio::Channel::speech;
  std::string piece_error_;
  int last_minute_said_ = -1;  // the timer's minute last spoken (-1: before the round)
};

}  // namespace uh::museum_station
