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

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "uh/core/log.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum/rules.hpp"
#include "uh/museum/sighted_bot.hpp"
#include "uh/museum_artifacts/artifact.hpp"
#include "uh/museum_players/blind_player.hpp"
#include "uh/museum_service/game_server.hpp"

namespace uh::cli {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using nlohmann::json;

// A player's connection to the game server: blocking reads and writes on its own thread.
class Link {
 public:
  static Result<std::unique_ptr<Link>> open(const std::string& host, std::uint16_t port) {
    auto link = std::unique_ptr<Link>(new Link());
    beast::error_code ec;
    tcp::resolver resolver(link->io_);
    const auto endpoints = resolver.resolve(host, std::to_string(port), ec);
    if (!ec) asio::connect(link->ws_.next_layer(), endpoints, ec);
    if (!ec) link->ws_.handshake(host, "/ws", ec);
    if (ec) return Error{fmt::format("cannot reach the game server at {}:{}: {}", host, port, ec.message())};
    link->ws_.read_message_max(64u << 20);
    return link;
  }
  bool send(const json& message) {
    beast::error_code ec;
    ws_.text(true);
    ws_.write(asio::buffer(message.dump()), ec);
    return !ec;
  }
  // the next message; nothing when the connection ended
  std::optional<json> read() {
    beast::flat_buffer buffer;
    beast::error_code ec;
    ws_.read(buffer, ec);
    if (ec) return std::nullopt;
    json m = json::parse(beast::buffers_to_string(buffer.data()), nullptr, false);
    if (m.is_discarded() || !m.is_object()) return json::object();
    return m;
  }
  // the welcome, or the server's error
  Result<json> hello(const std::string& role) {
    if (!send({{"type", "hello"}, {"protocol", museum_service::kGameProtocolVersion}, {"role", role}}))
      return Error{"the game server closed the connection"};
    for (;;) {
      const auto m = read();
      if (!m) return Error{"the game server closed the connection before welcoming " + role};
      if ((*m)["type"] == "welcome") return *m;
      if ((*m)["type"] == "error")
        return Error{fmt::format("the game server refused {}: {}", role, (*m).value("message", ""))};
    }
  }
  void close() {
    beast::error_code ec;
    ws_.close(websocket::close_code::normal, ec);
  }

 private:
  Link() = default;
  asio::io_context io_;
  websocket::stream<tcp::socket> ws_{io_};
};

museum::Vec2 vec2(const json& v) { return {v.at(0).get<double>(), v.at(1).get<double>()}; }

// The shipped level the welcome describes (the bots know the museum and its guards' rounds, as a
// player who has watched them does); the round's time as the server says.
Result<museum::Level> level_of(const json& welcome) {
  const json& l = welcome.at("level");
  museum::Level level = museum::make_level(l.value("difficulty", "") == "hard" ? museum::Difficulty::hard
                                                                              : museum::Difficulty::easy);
  if (l.at("cases").size() != level.cases.size() || l.at("rooms").size() != level.rooms.size() ||
      l.value("name", "") != level.name)
    return Error{fmt::format("the server plays level '{}', which is not a shipped one; the bots know only "
                             "the shipped museum",
                             l.value("name", ""))};
  level.rules.round_s = l.at("rules").at("round_s").get<double>();
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

  void heard(const json& event) {
    const int g = event.at("guard").get<int>();
    if (g >= 0 && g < museum::kMaxGuards) noise_[static_cast<std::size_t>(g)] = vec2(event.at("pos"));
  }

  const museum::GameState& update(const json& snapshot, const json& targets) {
    museum::GameState& s = state_;
    s.tick = snapshot.at("tick").get<std::int64_t>();
    s.time_left_s = snapshot.at("time_left_s").get<double>();
    s.phase = snapshot.at("phase") == "ended" ? museum::Phase::ended : museum::Phase::playing;
    s.paused = snapshot.at("phase") != "playing";
    s.target_count = static_cast<int>(targets.size());
    for (int t = 0; t < s.target_count; ++t)
      s.target_kinds[static_cast<std::size_t>(t)] = kind_index(level_, targets.at(static_cast<std::size_t>(t)));
    s.item_count = 2 * s.target_count;
    for (int i = 0; i < s.item_count; ++i) {
      museum::ItemState& item = s.items[static_cast<std::size_t>(i)];
      item.kind = s.target_kinds[static_cast<std::size_t>(i / 2)];
      item.place = museum::ItemPlace::kept;  // judged, unless seen below
    }
    const auto see = [&](const json& it, museum::ItemPlace place) {
      const int i = it.at("item").get<int>();
      if (i < 0 || i >= s.item_count) return -1;
      s.items[static_cast<std::size_t>(i)].place = place;
      return i;
    };
    const json& cases = snapshot.at("cases");
    s.case_count = static_cast<int>(std::min<std::size_t>(cases.size(), museum::kMaxCases));
    for (int c = 0; c < s.case_count; ++c) {
      const json& cj = cases.at(static_cast<std::size_t>(c));
      s.case_broken[static_cast<std::size_t>(c)] = cj.at("broken").get<bool>();
      s.case_item[static_cast<std::size_t>(c)] = -1;
      if (cj.at("item").is_null()) continue;
      const int i = see(cj.at("item"), museum::ItemPlace::in_case);
      if (i < 0) continue;
      s.case_item[static_cast<std::size_t>(c)] = i;
      s.items[static_cast<std::size_t>(i)].case_index = c;  // where it goes back when she is caught
    }
    const json& vive = snapshot.at("vive");
    s.vive.pos = vec2(vive.at("pos"));
    s.vive.facing = vec2(vive.at("facing"));
    s.vive.running = vive.at("running").get<bool>();
    s.vive.times_caught = vive.at("times_caught").get<int>();
    s.vive.carried_count = 0;
    for (const json& it : vive.at("carried")) {
      const int i = see(it, museum::ItemPlace::carried);
      if (i >= 0 && s.vive.carried_count < museum::kMaxCarried)
        s.vive.carried[static_cast<std::size_t>(s.vive.carried_count++)] = i;
    }
    s.table_count = 0;
    for (const json& it : snapshot.at("table")) {
      const int i = see(it, museum::ItemPlace::on_table);
      if (i >= 0) s.table[static_cast<std::size_t>(s.table_count++)] = i;
    }
    const json& guards = snapshot.at("guards");
    s.guard_count = static_cast<int>(std::min({guards.size(), level_.routes.size(),
                                               static_cast<std::size_t>(museum::kMaxGuards)}));
    for (int g = 0; g < s.guard_count; ++g) infer_guard(g, guards.at(static_cast<std::size_t>(g)));
    return s;
  }

 private:
  void infer_guard(int g, const json& gj) {
    museum::GuardState& guard = state_.guards[static_cast<std::size_t>(g)];
    guard.pos = vec2(gj.at("pos"));
    guard.facing = vec2(gj.at("facing"));
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
    const std::string mode = gj.at("mode").get<std::string>();
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
Status play_vive(Link& link, const json& welcome) {
  auto level = level_of(welcome);
  if (!level) return level.error();
  museum::SightedBot bot(*level);
  ViveView view(*level);
  museum::ViveInput sent{};
  for (;;) {
    const auto m = link.read();
    if (!m) return Ok{};
    const std::string type = m->value("type", "");
    if (type == "summary") return Ok{};
    if (type == "event" && m->value("event", "") == "guard_heard") view.heard(*m);
    if (type != "snapshot") continue;
    const museum::GameState& s = view.update(*m, welcome.at("targets"));
    if (s.phase == museum::Phase::ended) continue;
    if (s.paused) continue;
    const museum::ViveInput in = bot.decide(s);
    if (museum::distance(in.move, sent.move) > 1e-3 || in.run != sent.run) {
      link.send({{"type", "move"}, {"move", {in.move.x, in.move.y}}, {"run", in.run}});
      sent = in;
    }
    for (const auto& [wanted, name] : {std::pair{in.break_case, "break"}, {in.take, "take"}, {in.deliver, "deliver"}})
      if (wanted) link.send({{"type", "action"}, {"action", name}});
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
Status play_phantom(const std::string& host, std::uint16_t port, std::uint64_t seed,
                    std::vector<BlindVerdict>& verdicts, std::mutex& verdicts_mutex, bool announce) {
  // first a look at the round as a watcher: which targets to study
  json welcome;
  {
    auto watcher = Link::open(host, port);
    if (!watcher) return watcher.error();
    auto w = (*watcher)->hello("watcher");
    if (!w) return w.error();
    welcome = std::move(*w);
    (*watcher)->close();
  }
  using museum_artifacts::Piece;
  const museum::Difficulty difficulty = welcome.at("level").value("difficulty", "") == "hard"
                                            ? museum::Difficulty::hard
                                            : museum::Difficulty::easy;
  const std::filesystem::path cache = controllers::default_cache_dir();
  std::uint64_t deal = seed * 0x9E3779B97F4A7C15ull + 17;
  const auto uniform = [&deal] {
    deal = deal * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(deal >> 11) * 0x1.0p-53;
  };
  const auto explore = [&](museum_artifacts::ArtifactKind kind, Piece piece,
                           bool on_the_table) -> Result<museum_players::PieceSurvey> {
    // on the table a piece lies a few millimetres off the middle, a lathe piece turned any way
    const double turn = on_the_table && museum_players::turned_on_the_table(kind) ? 2.0 * kPi * uniform() : 0.0;
    const double x = on_the_table ? (uniform() - 0.5) * 0.004 : 0.0, y = on_the_table ? (uniform() - 0.5) * 0.004 : 0.0;
    const Pose pose{quat_from_axis_angle({0, 0, 1}, turn), {x, y, 0.0}};
    auto object = museum_artifacts::artifact_object(kind, difficulty, piece, cache,
                                                    museum_artifacts::to_string(kind), pose);
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
    auto reference = explore(kind, Piece::genuine, false);
    if (!reference) return reference.error();
    auto again = explore(kind, Piece::genuine, true);
    if (!again) return again.error();
    references.emplace(name, std::pair{std::move(*reference), std::move(*again)});
    return Ok{};
  };
  // Phantom studies the genuine pieces of Falcon's targets before taking its seat: the round
  // starts when it says hello as Phantom (the game clock does not run meanwhile)
  for (const json& target : welcome.at("targets"))
    if (const auto kind = museum_artifacts::artifact_kind(target.get<std::string>()))
      if (const Status studied = study(*kind); !studied) return studied;
  auto opened = Link::open(host, port);
  if (!opened) return opened.error();
  Link& link = **opened;
  if (auto w = link.hello("phantom"); !w) return w.error();
  if (announce) {
    std::printf("uh museum play: Phantom is at the table\n");
    std::fflush(stdout);
  }
  for (;;) {
    const auto m = link.read();
    if (!m) return Ok{};
    const std::string type = m->value("type", "");
    if (type == "summary") return Ok{};
    if (type != "in_hands") continue;
    const int item = m->at("item").get<int>();
    const std::string kind_name = m->at("kind").get<std::string>();
    const auto kind = museum_artifacts::artifact_kind(kind_name);
    if (!kind) return Error{fmt::format("the server handed Phantom a '{}', which is no artifact kind", kind_name)};
    if (const Status studied = study(*kind); !studied) return studied;
    // the piece under the device: the server says which (as the station loads it); the bot's
    // verdict reads only the trace of exploring it
    auto survey = explore(*kind, m->value("piece", "") == "genuine" ? Piece::genuine : Piece::forgery, true);
    if (!survey) return survey.error();
    const auto& [reference, again] = references.at(kind_name);
    BlindVerdict v{.item = item,
                   .kind = kind_name,
                   .judgement = museum_players::judge_piece(*survey, reference, again),
                   .simulated_s = survey->simulated_s};
    link.send({{"type", "verdict"}, {"item", item}, {"verdict", museum_players::to_string(v.judgement.verdict)}});
    const std::lock_guard lock(verdicts_mutex);
    verdicts.push_back(std::move(v));
  }
}

// One bot's round on the server at host:port.
Status play_bot(const std::string& role, const std::string& host, std::uint16_t port, std::uint64_t seed,
                std::vector<BlindVerdict>& verdicts, std::mutex& verdicts_mutex, bool announce) {
  if (role == "phantom") return play_phantom(host, port, seed, verdicts, verdicts_mutex, announce);
  auto link = Link::open(host, port);
  if (!link) return link.error();
  auto welcome = (*link)->hello(role);
  if (!welcome) return welcome.error();
  Status played = play_vive(**link, *welcome);
  (*link)->close();
  return played;
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

// A line for an event, as the watcher reads it.
std::string describe_event(const json& e, const json& welcome) {
  const std::string what = e.value("event", "");
  const auto kind_of = [&](int item) {
    const json& targets = welcome.at("targets");
    return item >= 0 && static_cast<std::size_t>(item / 2) < targets.size()
               ? targets.at(static_cast<std::size_t>(item / 2)).get<std::string>()
               : std::string("artifact");
  };
  if (what == "case_broken")
    return fmt::format("Vive broke case {} (heard within {:.0f} m)", e.value("case", -1), e.value("radius", 0.0));
  if (what == "case_empty") return fmt::format("case {} was empty", e.value("case", -1));
  if (what == "item_taken")
    return fmt::format("Vive took the {} (item {})", kind_of(e.value("item", -1)), e.value("item", -1));
  if (what == "items_delivered") return fmt::format("Vive delivered {} to Phantom's table", e.value("count", 0));
  if (what == "guard_heard") return fmt::format("guard {} heard a noise", e.value("guard", -1));
  if (what == "vive_caught")
    return fmt::format("guard {} caught Vive ({} carried lost)", e.value("guard", -1), e.value("items_lost", 0));
  if (what == "verdict")
    return fmt::format("Phantom judged the {} (item {}): {}", kind_of(e.value("item", -1)), e.value("item", -1),
                       e.value("verdict", ""));
  if (what == "time_warning") return fmt::format("{} s left", e.value("seconds_left", 0));
  if (what == "round_ended") return "the round ended";
  return what;
}

std::pair<std::string, int> split_server(const std::string& url) {
  std::string rest = url;
  for (const char* scheme : {"ws://", "http://"})
    if (rest.rfind(scheme, 0) == 0) rest = rest.substr(std::string(scheme).size());
  rest = rest.substr(0, rest.find('/'));
  const auto colon = rest.rfind(':');
  if (colon == std::string::npos) return {rest, 7780};
  try {
    return {rest.substr(0, colon), std::stoi(rest.substr(colon + 1))};
  } catch (const std::exception&) {
    return {rest, -1};
  }
}

// One bot joining a running server (e.g. Phantom against Vive in a browser).
int museum_play_one(const MuseumPlayArgs& args) {
  const auto [host, port] = split_server(args.server);
  if (port <= 0 || port > 65535)
    return fail(fmt::format("--server '{}': expected ws://HOST:PORT/ws or http://HOST:PORT/", args.server));
  std::printf("uh museum play: the %s bot joins %s\n", args.bot.c_str(), args.server.c_str());
  std::fflush(stdout);
  std::vector<BlindVerdict> verdicts;
  std::mutex verdicts_mutex;
  const Status played = play_bot(args.bot, host, static_cast<std::uint16_t>(port), args.seed, verdicts, verdicts_mutex, true);
  if (!played) return fail(played.error().message);
  for (const BlindVerdict& v : verdicts)
    std::printf("uh museum play: judged the %s (item %d): %s\n", v.kind.c_str(), v.item,
                museum_players::to_string(v.judgement.verdict));
  std::printf("uh museum play: the round ended\n");
  return 0;
}

json verdict_json(const BlindVerdict& v) {
  json evidence = json::array();
  for (const auto& f : v.judgement.evidence)
    evidence.push_back({{"feature", f.feature},
                        {"where", f.where},
                        {"difference", f.difference},
                        {"threshold", f.threshold},
                        {"unit", f.unit},
                        {"differs", f.differs()}});
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
  auto watcher = Link::open("127.0.0.1", port);
  if (!watcher) return fail(watcher.error().message);
  auto welcome = (*watcher)->hello("watcher");
  if (!welcome) return fail(welcome.error().message);

  std::vector<BlindVerdict> verdicts;
  std::mutex verdicts_mutex;
  std::mutex failure_mutex;
  std::string failure;  // the first bot's error
  const auto run_bot = [&](const std::string& role) {
    const Status played = play_bot(role, "127.0.0.1", port, args.seed, verdicts, verdicts_mutex, !args.json);
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

  json summary;
  json event_counts = json::object();
  double time_left = level.rules.round_s;
  for (;;) {
    const auto m = (*watcher)->read();
    if (!m) break;
    const std::string type = m->value("type", "");
    if (type == "snapshot") time_left = m->value("time_left_s", time_left);
    if (type == "event") event_counts[m->value("event", "")] = event_counts.value(m->value("event", ""), 0) + 1;
    if (type == "event" && !args.json)
      std::printf("[%s left] %s\n", clock_of(time_left).c_str(), describe_event(*m, *welcome).c_str());
    if (type == "summary") {
      summary = *m;
      break;
    }
    std::fflush(stdout);
  }
  vive.join();
  phantom.join();
  (*watcher)->close();
  (*server)->stop();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!failure.empty()) return fail(failure);
  if (summary.is_null()) return fail("the round did not end: the server closed the connection first");

  const json& score = summary.at("score");
  if (args.json) {
    json out{{"level", args.level}, {"seed", args.seed}, {"speed", args.speed}, {"wall_s", wall_s},
             {"summary", summary},  {"events", event_counts}, {"verdicts", json::array()}};
    for (const BlindVerdict& v : verdicts) out["verdicts"].push_back(verdict_json(v));
    std::printf("%s\n", out.dump(2).c_str());
    return 0;
  }
  std::printf("uh museum play: the round ended%s after %.0f s of game time (%.0f s on the clock)\n",
              summary.value("ended_early", false) ? " early, every target settled," : "",
              summary.value("seconds_played", 0.0), wall_s);
  for (const json& t : summary.at("targets"))
    std::printf("  %-8s genuine: %-8s forgery: %s\n", t.value("kind", "").c_str(), t.value("genuine", "").c_str(),
                t.value("forgery", "").c_str());
  for (const BlindVerdict& v : verdicts) {
    const auto& e = v.judgement.evidence;
    std::printf("  Phantom on the %s (item %d): %s, from %.0f s of touch%s\n", v.kind.c_str(), v.item,
                museum_players::to_string(v.judgement.verdict), v.simulated_s,
                e.empty() ? ""
                          : fmt::format(" (most telling: {} {:.2f} {} against {:.2f})", e.front().feature,
                                        e.front().difference, e.front().unit, e.front().threshold)
                                .c_str());
  }
  std::printf("score %d: %d genuine kept, %d forgeries kept, %d genuine put aside, %d forgeries put aside, "
              "time bonus %d; caught %d times\n",
              score.value("points", 0), score.value("genuine_kept", 0), score.value("forgeries_kept", 0),
              score.value("genuine_rejected", 0), score.value("forgeries_rejected", 0), score.value("time_bonus", 0),
              summary.value("times_caught", 0));
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
