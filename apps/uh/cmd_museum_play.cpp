// uh museum play --bots [--seed N] [--level easy|hard] [--minutes M] [--speed S] [--json]
// uh museum play --bot vive|phantom --server URL
//
// A round with automated players as real clients of the game server over loopback WebSocket, as
// the browser and the station are: the sighted bot plays Vive from the snapshots (what she sees),
// the blind bot plays Phantom by touch alone (each piece in its hands explored on a simulated
// device in simulated time and compared with a genuine reference of its kind). `--bots` starts a
// server and both; `--bot` joins a server in one role (Vive in a browser against the automated
// Phantom).
#include <algorithm>
#include <array>
#include <atomic>
#include <limits>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/core/log.hpp"
#include "uh/museum/cues.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum/rules.hpp"
#include "uh/museum/sighted_bot.hpp"
#include "uh/museum_artifacts/artifact.hpp"
#include "uh/museum_client/game_link.hpp"
#include "uh/museum_players/blind_player.hpp"
#include "uh/museum_service/game_server.hpp"

namespace uh::cli {
namespace {

using museum_client::GameLink;
using museum_client::LinkNote;
using museum_protocol::GameEvent;
using museum_protocol::InHand;
using museum_protocol::Snapshot;
using museum_protocol::Summary;
using museum_protocol::Welcome;
using nlohmann::json;

// A bot's connection to the game server: it does not come back after a drop (the round is over
// for it when the server goes).
Result<std::unique_ptr<GameLink>> join(const std::string& url, const std::string& role) {
  return GameLink::connect({.url = url, .role = role, .reconnect = false});
}

// The next message from the server; nothing once the connection ended. A frame that does not
// parse was logged by the link and is passed over.
std::optional<LinkNote> next_message(GameLink& link) {
  LinkNote note;
  for (;;) {
    if (!link.wait(note, 1.0)) continue;
    if (note.kind == LinkNote::Kind::dropped) return std::nullopt;
    if (note.kind == LinkNote::Kind::message) return note;
  }
}

// The shipped level the welcome describes (the bots know the museum and its guards' rounds, as a
// player who has watched them does); the round's time as the server says.
Result<museum::Level> level_of(const Welcome& welcome) {
  museum::Level level = museum::make_level(welcome.level.difficulty);
  if (welcome.level.cases.size() != level.cases.size() || welcome.level.rooms.size() != level.rooms.size() ||
      welcome.level.name != level.name)
    return Error{
        fmt::format("the server plays level '{}', which is not a shipped one; the bots know only "
                    "the shipped museum",
                    welcome.level.name)};
  level.rules.round_s = welcome.level.rules.round_s;
  return level;
}

int kind_index(const museum::Level& level, const std::string& name) {
  for (std::size_t k = 0; k < level.artifact_kinds.size(); ++k)
    if (level.artifact_kinds[k] == name) return static_cast<int>(k);
  return -1;
}

// What Vive sees, as a state the sighted bot can play ahead on: positions, cases, the pieces'
// kinds and where they are, the guards and where they walk. Never which piece is genuine (every
// item reads as a forgery: the bot does not look). A guard's hidden bookkeeping is inferred: on
// its round, the leg it walks and which way (from where it faces); investigating, the noise it
// went for (the guard_heard events); going back, straight to the nearest corner of its round.
class ViveView {
 public:
  explicit ViveView(const museum::Level& level) : level_(level) {}

  void heard(const museum::Event& event) {
    if (event.guard >= 0 && event.guard < museum::kMaxGuards)
      noise_[static_cast<std::size_t>(event.guard)] = event.pos;
  }

  const museum::GameState& update(const Snapshot& snapshot, const std::vector<std::string>& targets) {
    museum::GameState& s = state_;
    s.tick = snapshot.tick;
    s.time_left_s = snapshot.time_left_s;
    s.phase = snapshot.phase == "ended" ? museum::Phase::ended : museum::Phase::playing;
    s.paused = snapshot.phase != "playing";
    s.target_count = static_cast<int>(std::min<std::size_t>(targets.size(), museum::kMaxTargets));
    for (int t = 0; t < s.target_count; ++t)
      s.target_kinds[static_cast<std::size_t>(t)] = kind_index(level_, targets[static_cast<std::size_t>(t)]);
    s.item_count = 2 * s.target_count;
    for (int i = 0; i < s.item_count; ++i) {
      museum::ItemState& item = s.items[static_cast<std::size_t>(i)];
      item.kind = s.target_kinds[static_cast<std::size_t>(i / 2)];
      item.place = museum::ItemPlace::kept;  // judged, unless seen below
    }
    const auto see = [&](const museum_protocol::ItemView& it, museum::ItemPlace place) {
      if (it.item < 0 || it.item >= s.item_count) return -1;
      s.items[static_cast<std::size_t>(it.item)].place = place;
      return it.item;
    };
    s.case_count = static_cast<int>(std::min<std::size_t>(snapshot.cases.size(), museum::kMaxCases));
    for (int c = 0; c < s.case_count; ++c) {
      const museum_protocol::CaseView& seen = snapshot.cases[static_cast<std::size_t>(c)];
      s.case_broken[static_cast<std::size_t>(c)] = seen.broken;
      s.case_item[static_cast<std::size_t>(c)] = -1;
      const int i = see(seen.item, museum::ItemPlace::in_case);
      if (i < 0) continue;
      s.case_item[static_cast<std::size_t>(c)] = i;
      s.items[static_cast<std::size_t>(i)].case_index = c;  // where it goes back when she is caught
    }
    s.vive.pos = snapshot.vive_pos;
    s.vive.facing = snapshot.vive_facing;
    s.vive.running = snapshot.vive_running;
    s.vive.times_caught = snapshot.times_caught;
    s.vive.carried_count = 0;
    for (const museum_protocol::ItemView& it : snapshot.carried) {
      const int i = see(it, museum::ItemPlace::carried);
      if (i >= 0 && s.vive.carried_count < museum::kMaxCarried)
        s.vive.carried[static_cast<std::size_t>(s.vive.carried_count++)] = i;
    }
    s.table_count = 0;
    for (const museum_protocol::ItemView& it : snapshot.table) {
      const int i = see(it, museum::ItemPlace::on_table);
      if (i >= 0 && s.table_count < museum::kMaxItems) s.table[static_cast<std::size_t>(s.table_count++)] = i;
    }
    s.guard_count = static_cast<int>(std::min(
        {snapshot.guards.size(), level_.routes.size(), static_cast<std::size_t>(museum::kMaxGuards)}));
    for (int g = 0; g < s.guard_count; ++g) infer_guard(g, snapshot.guards[static_cast<std::size_t>(g)]);
    return s;
  }
  const museum::GameState& state() const { return state_; }

 private:
  void infer_guard(int g, const museum_protocol::GuardView& seen) {
    museum::GuardState& guard = state_.guards[static_cast<std::size_t>(g)];
    guard.pos = seen.pos;
    guard.facing = seen.facing;
    const std::vector<museum::Vec2>& w = level_.routes[static_cast<std::size_t>(g)].waypoints;
    const int n = static_cast<int>(w.size());
    // the leg of its round nearest to where it stands
    int leg = 0;
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      const museum::Vec2 a = w[static_cast<std::size_t>(i)], b = w[static_cast<std::size_t>((i + 1) % n)];
      const museum::Vec2 ab = b - a;
      const double len2 = museum::dot(ab, ab);
      const double t = len2 > 0.0 ? std::clamp(museum::dot(guard.pos - a, ab) / len2, 0.0, 1.0) : 0.0;
      const double d = museum::distance(guard.pos, a + ab * t);
      if (d < best) {
        best = d;
        leg = i;
      }
    }
    const std::string& mode = seen.mode;
    const museum::GuardMode was = guard.mode;
    if (mode == "investigate") {
      guard.mode = museum::GuardMode::investigate;
      if (was != museum::GuardMode::investigate) guard.linger_left_s = level_.rules.linger_s;
      guard.noise_pos = noise_[static_cast<std::size_t>(g)];
      guard.goal = museum::clear_path(level_, guard.pos, guard.noise_pos) ? guard.noise_pos : guard.pos;
      guard.trail_count = 0;
    } else if (mode == "returning") {
      guard.mode = museum::GuardMode::returning;
      guard.trail[0] = w[static_cast<std::size_t>(leg)];
      guard.trail_count = 1;
    } else {
      guard.mode = museum::GuardMode::patrol;
      guard.trail_count = 0;
    }
    const museum::Vec2 along = w[static_cast<std::size_t>((leg + 1) % n)] - w[static_cast<std::size_t>(leg)];
    guard.direction = museum::dot(along, guard.facing) >= 0.0 ? 1 : -1;
    guard.next_waypoint = guard.direction > 0 ? (leg + 1) % n : leg;
  }

  const museum::Level& level_;
  museum::GameState state_{};
  std::array<museum::Vec2, museum::kMaxGuards> noise_{};
};

// Plays Vive with the sighted bot until the round ends or the connection does.
Status play_vive(GameLink& link, const Welcome& welcome) {
  auto level = level_of(welcome);
  if (!level) return level.error();
  museum::SightedBot bot(*level);
  ViveView view(*level);
  museum::ViveInput sent{};
  for (;;) {
    const auto note = next_message(link);
    if (!note || std::holds_alternative<Summary>(note->message)) return Ok{};
    if (const auto* e = std::get_if<GameEvent>(&note->message);
        e && e->event.type == museum::EventType::guard_heard)
      view.heard(e->event);
    const auto* snapshot = std::get_if<Snapshot>(&note->message);
    if (snapshot == nullptr) continue;
    const museum::GameState& s = view.update(*snapshot, welcome.targets);
    if (s.phase == museum::Phase::ended) continue;
    if (s.paused) continue;
    const museum::ViveInput in = bot.decide(s);
    if (museum::distance(in.move, sent.move) > 1e-3 || in.run != sent.run) {
      link.send(museum_protocol::write_message(museum_protocol::MoveMessage{in.move, in.run}));
      sent = in;
    }
    using museum_protocol::Action;
    for (const auto& [wanted, action] :
         {std::pair{in.break_case, Action::break_case}, {in.take, Action::take}, {in.deliver, Action::deliver}})
      if (wanted) link.send(museum_protocol::write_message(museum_protocol::ActionMessage{action}));
  }
}

// One verdict of the blind bot, for the report.
struct BlindVerdict {
  int item = -1;
  std::string kind;
  museum_players::Judgement judgement;
  double simulated_s = 0.0;
};

// Plays Phantom with the blind bot: first it explores the genuine reference of each target twice;
// then each piece that comes into its hands (in_hands) is put under a simulated device, explored
// and judged against the reference of its kind; only the device's trace decides.
Status play_phantom(const std::string& url, std::uint64_t seed, std::vector<BlindVerdict>& verdicts,
                    std::mutex& verdicts_mutex, bool announce) {
  // first a look at the round as a watcher: which targets to study
  Welcome welcome;
  {
    auto watcher = join(url, "watcher");
    if (!watcher) return watcher.error();
    welcome = (*watcher)->welcome();
  }
  using museum_artifacts::Piece;
  const museum::Difficulty difficulty = welcome.level.difficulty;
  const std::filesystem::path cache = controllers::default_cache_dir();
  std::uint64_t deal = seed * 0x9E3779B97F4A7C15ull + 17;
  const auto uniform = [&deal] {
    deal = deal * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(deal >> 11) * 0x1.0p-53;
  };
  const auto explore = [&](const museum::PieceForm& form, bool on_the_table) -> Result<museum_players::PieceSurvey> {
    const auto kind = museum_artifacts::check_form(form);
    if (!kind) return kind.error();
    // on the table a piece lies a few millimetres off the middle, a lathe piece turned any way
    const double turn = on_the_table && museum_players::turned_on_the_table(*kind) ? 2.0 * kPi * uniform() : 0.0;
    const double x = on_the_table ? (uniform() - 0.5) * 0.004 : 0.0, y = on_the_table ? (uniform() - 0.5) * 0.004 : 0.0;
    const Pose pose{quat_from_axis_angle({0, 0, 1}, turn), {x, y, 0.0}};
    auto object = museum_artifacts::artifact_object(form, cache, form.kind, pose);
    if (!object) return object.error();
    museum_players::SurveyOptions options;
    options.seed = static_cast<std::uint64_t>(uniform() * 0x1.0p52);
    return museum_players::survey_piece(*object, options, cache);
  };
  // the genuine reference of each kind, explored twice
  std::map<std::string, std::pair<museum_players::PieceSurvey, museum_players::PieceSurvey>> references;
  const auto study = [&](museum_artifacts::ArtifactKind kind) -> Status {
    const std::string name = museum_artifacts::to_string(kind);
    if (references.contains(name)) return Ok{};
    const museum::PieceForm genuine = museum_artifacts::piece_form(kind, difficulty, Piece::genuine);
    auto reference = explore(genuine, false);
    if (!reference) return reference.error();
    auto again = explore(genuine, true);
    if (!again) return again.error();
    references.emplace(name, std::pair{std::move(*reference), std::move(*again)});
    return Ok{};
  };
  // Phantom studies the genuine pieces of Falcon's targets before taking its seat: the round
  // starts when it says hello as Phantom (the game clock does not run meanwhile)
  for (const std::string& target : welcome.targets)
    if (const auto kind = museum_artifacts::artifact_kind(target))
      if (const Status studied = study(*kind); !studied) return studied;
  auto joined = join(url, "phantom");
  if (!joined) return joined.error();
  GameLink& link = **joined;
  if (announce) {
    std::printf("uh museum play: Phantom is at the table\n");
    std::fflush(stdout);
  }
  for (;;) {
    const auto note = next_message(link);
    if (!note || std::holds_alternative<Summary>(note->message)) return Ok{};
    const auto* in_hands = std::get_if<InHand>(&note->message);
    if (in_hands == nullptr || in_hands->item < 0) continue;
    const int item = in_hands->item;
    const std::string& kind_name = in_hands->kind;
    const auto kind = museum_artifacts::artifact_kind(kind_name);
    if (!kind) return Error{fmt::format("the server handed Phantom a '{}', which is no artifact kind", kind_name)};
    if (const Status studied = study(*kind); !studied) return studied;
    // the piece under the device: the form the server sent (as the station builds it); the bot's
    // verdict reads only the trace of exploring it
    auto survey = explore(in_hands->form, true);
    if (!survey) return survey.error();
    const auto& [reference, again] = references.at(kind_name);
    BlindVerdict v{.item = item,
                   .kind = kind_name,
                   .judgement = museum_players::judge_piece(*survey, reference, again),
                   .simulated_s = survey->simulated_s};
    link.send(museum_protocol::write_message(museum_protocol::VerdictMessage{
        item, v.judgement.verdict == museum_players::Verdict::genuine ? museum::Verdict::genuine
                                                                      : museum::Verdict::forgery}));
    const std::lock_guard lock(verdicts_mutex);
    verdicts.push_back(std::move(v));
  }
}

// One bot's round on the server at `url`.
Status play_bot(const std::string& role, const std::string& url, std::uint64_t seed,
                std::vector<BlindVerdict>& verdicts, std::mutex& verdicts_mutex, bool announce) {
  if (role == "phantom") return play_phantom(url, seed, verdicts, verdicts_mutex, announce);
  auto link = join(url, role);
  if (!link) return link.error();
  return play_vive(**link, (*link)->welcome());
}

struct MuseumPlayArgs {
  bool bots = false;
  std::string bot;     // with --server: vive or phantom
  std::string server;  // ws://HOST:PORT/ws or http://HOST:PORT/
  std::uint64_t seed = 1;
  std::string level = "easy";
  double minutes = 0.0;
  double speed = 1.0;
  bool json = false;
};

std::string clock_of(double seconds_left) {
  const int s = static_cast<int>(std::ceil(std::max(0.0, seconds_left)));
  return fmt::format("{}:{:02}", s / 60, s % 60);
}

// One bot joining a running server (e.g. Phantom against Vive in a browser).
int museum_play_one(const MuseumPlayArgs& args) {
  if (auto address = museum_client::parse_server_url(args.server); !address)
    return fail("--" + address.error().message);
  std::printf("uh museum play: the %s bot joins %s\n", args.bot.c_str(), args.server.c_str());
  std::fflush(stdout);
  std::vector<BlindVerdict> verdicts;
  std::mutex verdicts_mutex;
  const Status played = play_bot(args.bot, args.server, args.seed, verdicts, verdicts_mutex, true);
  if (!played) return fail(played.error().message);
  for (const BlindVerdict& v : verdicts)
    std::printf("uh museum play: judged the %s (item %d): %s\n", v.kind.c_str(), v.item,
                museum_players::to_string(v.judgement.verdict));
  std::printf("uh museum play: the round ended\n");
  return 0;
}

json verdict_json(const BlindVerdict& v) {
  json evidence = json::array();
  for (const auto& f : v.judgement.evidence) evidence.push_back(evidence_json(f));
  return {{"item", v.item},
          {"kind", v.kind},
          {"verdict", museum_players::to_string(v.judgement.verdict)},
          {"simulated_s", v.simulated_s},
          {"evidence", evidence}};
}

int museum_play_bots(const MuseumPlayArgs& args) {
  museum::Level level =
      museum::make_level(args.level == "hard" ? museum::Difficulty::hard : museum::Difficulty::easy);
  if (args.minutes > 0.0) level.rules.round_s = args.minutes * 60.0;
  level.pieces = museum_artifacts::piece_pairs(level);
  // the watcher below prints what happens; the server's own notes would repeat it (or break the JSON)
  log::set_level(args.json ? log::Level::error : log::Level::warn);
  auto server = museum_service::GameServer::start(
      {.host = "127.0.0.1", .port = 0, .level = level, .seed = args.seed, .speed = args.speed});
  if (!server) return fail(server.error().message);
  const std::uint16_t port = (*server)->port();
  const auto started = std::chrono::steady_clock::now();
  if (!args.json)
    std::printf("uh museum play: %s level, seed %llu, %.1f min round at %gx; the bots join ws://127.0.0.1:%u/ws\n",
                args.level.c_str(), static_cast<unsigned long long>(args.seed), level.rules.round_s / 60.0,
                args.speed, port);
  std::fflush(stdout);

  // the watcher: what is printed
  const std::string url = fmt::format("ws://127.0.0.1:{}/ws", port);
  auto watcher = join(url, "watcher");
  if (!watcher) return fail(watcher.error().message);
  const Welcome& welcome = (*watcher)->welcome();

  std::vector<BlindVerdict> verdicts;
  std::mutex verdicts_mutex;
  std::mutex failure_mutex;
  std::string failure;  // the first bot's error
  const auto run_bot = [&](const std::string& role) {
    const Status played = play_bot(role, url, args.seed, verdicts, verdicts_mutex, !args.json);
    if (!played) {
      {
        const std::lock_guard lock(failure_mutex);
        if (failure.empty()) failure = "the " + role + " bot: " + played.error().message;
      }
      (*server)->stop();  // ends the watcher and the other bot
    }
  };
  std::thread vive([&] { run_bot("vive"); });
  std::thread phantom([&] { run_bot("phantom"); });

  std::optional<Summary> summary;
  std::string summary_text;  // the summary as the server wrote it, for --json
  json event_counts = json::object();
  double time_left = level.rules.round_s;
  ViveView seen(level);  // the round as the watcher sees it: names the pieces in the lines
  for (;;) {
    auto note = next_message(**watcher);
    if (!note) break;
    if (const auto* s = std::get_if<Snapshot>(&note->message)) {
      time_left = s->time_left_s;
      seen.update(*s, welcome.targets);
    }
    if (const auto* e = std::get_if<GameEvent>(&note->message)) {
      const std::string name = museum::to_string(e->event.type);
      event_counts[name] = event_counts.value(name, 0) + 1;
      if (e->event.type == museum::EventType::guard_heard) seen.heard(e->event);
      if (!args.json)
        std::printf("[%s left] %s\n", clock_of(time_left).c_str(),
                    museum::describe(e->event, level, seen.state()).caption.c_str());
    }
    if (const auto* s = std::get_if<Summary>(&note->message)) {
      summary = *s;
      summary_text = std::move(note->text);
      break;
    }
    std::fflush(stdout);
  }
  vive.join();
  phantom.join();
  (*watcher)->stop();
  (*server)->stop();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!failure.empty()) return fail(failure);
  if (!summary) return fail("the round did not end: the server closed the connection first");

  if (args.json) {
    json out{{"level", args.level},
             {"seed", args.seed},
             {"speed", args.speed},
             {"wall_s", wall_s},
             {"summary", json::parse(summary_text, nullptr, false)},  // the link parsed it already
             {"events", event_counts},
             {"verdicts", json::array()}};
    for (const BlindVerdict& v : verdicts) out["verdicts"].push_back(verdict_json(v));
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  std::printf("uh museum play: the round ended%s after %.0f s of game time (%.0f s on the clock)\n",
              summary->ended_early ? " early, every target settled," : "", summary->seconds_played, wall_s);
  for (const museum_protocol::TargetView& t : summary->targets)
    std::printf("  %-8s genuine: %-8s forgery: %s\n", t.kind.c_str(), t.genuine.c_str(), t.forgery.c_str());
  for (const BlindVerdict& v : verdicts) {
    const auto& e = v.judgement.evidence;
    std::printf("  Phantom on the %s (item %d): %s, from %.0f s of touch%s\n", v.kind.c_str(), v.item,
                museum_players::to_string(v.judgement.verdict), v.simulated_s,
                e.empty() ? ""
                          : fmt::format(" (most telling: {} {:.2f} {} against {:.2f})", e.front().feature,
                                        e.front().difference, e.front().unit, e.front().threshold)
                                .c_str());
  }
  std::printf(
      "score %d: %d genuine kept, %d forgeries kept, %d genuine put aside, %d forgeries put aside, "
      "time bonus %d; caught %d times\n",
      summary->points, summary->genuine_kept, summary->forgeries_kept, summary->genuine_rejected,
      summary->forgeries_rejected, summary->time_bonus, summary->times_caught);
  return 0;
}

}  // namespace

void add_museum_play_command(CLI::App& museum, CommandRunner& runner) {
  static MuseumPlayArgs args;
  auto* p = museum.add_subcommand(
      "play", "play a round with automated players: both (--bots), or one joining a server (--bot ROLE --server URL)");
  auto* bots = p->add_flag("--bots", args.bots, "start a server and play a whole round with both bots");
  auto* bot = p->add_option("--bot", args.bot, "join --server as this bot: vive or phantom")
                  ->check(CLI::IsMember({"vive", "phantom"}));
  auto* server = p->add_option("--server", args.server, "the game server to join, e.g. ws://127.0.0.1:7780/ws");
  bot->needs(server);
  server->needs(bot);
  bots->excludes(bot);
  p->add_option("--seed", args.seed, "deals the round (--bots) and the blind bot's touch")->default_val(1);
  auto* level = p->add_option("--level", args.level, "easy or hard")
                    ->default_val("easy")
                    ->check(CLI::IsMember({"easy", "hard"}));
  auto* minutes = p->add_option("--minutes", args.minutes, "the round's time (default: the level's, 6 easy, 5 hard)")
                      ->check(CLI::Range(0.1, 600.0));
  auto* speed = p->add_option("--speed", args.speed, "game seconds per second of the clock (bots only)")
                    ->default_val(1.0)
                    ->check(CLI::Range(0.1, 20.0));
  auto* as_json = p->add_flag("--json", args.json, "print one JSON object at the end: the summary and the verdicts");
  for (CLI::Option* o : {level, minutes, speed, as_json}) o->needs(bots);
  p->callback([&runner] {
    runner = [] {
      if (!args.bots && args.bot.empty()) return fail("give --bots, or --bot vive|phantom with --server URL");
      return args.bots ? museum_play_bots(args) : museum_play_one(args);
    };
  });
}

}  // namespace uh::cli
