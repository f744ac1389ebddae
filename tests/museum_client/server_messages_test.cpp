// What the server says, as a client (the station, the bots) reads it: the messages of docs/museum.md, and a
// bad one refused with the field named.

#include "uh/museum_client/server_messages.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "../museum/test_levels.hpp"
#include "game_messages.hpp"
#include "text_mutation.hpp"

namespace uh::museum_client {
namespace {

using nlohmann::json;

// the server's own writers make the messages: the station reads what the server writes
TEST(ServerMessages, ReadsWhatTheServerWrites) {
  const museum::Level level = museum::make_level(museum::Difficulty::hard);
  museum::GameState state = museum::new_game(level, 4);
  state.table[0] = 1;
  state.table_count = 1;
  state.items[1].place = museum::ItemPlace::on_table;
  const auto snapshot =
      parse_server_message(museum_service::snapshot_json(level, state, "playing", true, true).dump());
  ASSERT_TRUE(snapshot) << snapshot.error().message;
  const auto& s = std::get<Snapshot>(*snapshot);
  EXPECT_EQ(s.phase, "playing");
  EXPECT_EQ(s.guards.size(), static_cast<std::size_t>(state.guard_count));
  EXPECT_EQ(s.guards[0].pos.x, state.guards[0].pos.x);
  ASSERT_EQ(s.table.size(), 1u);
  EXPECT_EQ(s.table[0].item, 1);
  EXPECT_EQ(s.table[0].kind, level.artifact_kinds[static_cast<std::size_t>(state.items[1].kind)]);
  EXPECT_EQ(s.cases.size(), level.cases.size());

  const auto in_hands = parse_server_message(museum_service::in_hands_json(level, state, 1).dump());
  ASSERT_TRUE(in_hands) << in_hands.error().message;
  EXPECT_EQ(std::get<InHand>(*in_hands).item, 1);
  EXPECT_EQ(std::get<InHand>(*in_hands).kind, s.table[0].kind);
  EXPECT_EQ(std::get<InHand>(*in_hands).piece,
            state.items[1].genuine ? museum::Piece::genuine : museum::Piece::forgery);

  const json welcome = {{"type", "welcome"},
                        {"role", "phantom"},
                        {"targets", {"bowl"}},
                        {"level", museum_service::level_json(level)}};
  const auto w = parse_server_message(welcome.dump());
  ASSERT_TRUE(w) << w.error().message;
  const museum::Level& read = std::get<Welcome>(*w).level;
  EXPECT_EQ(read.difficulty, museum::Difficulty::hard);
  ASSERT_EQ(read.rooms.size(), level.rooms.size());
  for (std::size_t r = 0; r < level.rooms.size(); ++r) {
    EXPECT_EQ(read.rooms[r].name, level.rooms[r].name);
    EXPECT_EQ(read.rooms[r].min, level.rooms[r].min);
    EXPECT_EQ(read.rooms[r].max, level.rooms[r].max);
  }
  EXPECT_EQ(read.artifact_kinds, level.artifact_kinds);

  // every event type, field for field (a verdict's correctness is not on the wire)
  for (int t = 0; t <= static_cast<int>(museum::EventType::round_ended); ++t) {
    museum::Event e{.type = static_cast<museum::EventType>(t)};
    SCOPED_TRACE(museum::to_string(e.type));
    switch (e.type) {
      case museum::EventType::case_broken:
        e = {.type = e.type, .case_index = 2, .pos = {1.5, 2.5}, .radius = 8.0};
        break;
      case museum::EventType::case_empty:
        e.case_index = 3;
        break;
      case museum::EventType::item_taken:
        e = {.type = e.type, .item = 4, .case_index = 1};
        break;
      case museum::EventType::items_delivered:
        e.count = 2;
        break;
      case museum::EventType::guard_heard:
        e = {.type = e.type, .guard = 1, .pos = {3.0, 4.0}, .radius = 4.0};
        break;
      case museum::EventType::vive_caught:
        e = {.type = e.type, .guard = 0, .count = 1, .pos = {7.0, 1.0}};
        break;
      case museum::EventType::verdict:
        e = {.type = e.type, .item = 5, .verdict = museum::Verdict::forgery};
        break;
      case museum::EventType::time_warning:
        e.count = 30;
        break;
      case museum::EventType::round_ended:
        break;
    }
    const auto parsed = parse_server_message(museum_service::event_json(e).dump());
    ASSERT_TRUE(parsed) << parsed.error().message;
    EXPECT_EQ(std::get<GameEvent>(*parsed).event, e);
  }
}

// A client reads what Vive's bot and the watcher need as well: who runs, how often she was caught,
// which cases are broken, and the whole summary.
TEST(ServerMessages, ReadsTheSnapshotAndSummaryFieldsTheBotsNeed) {
  const museum::Level level = museum::make_level(museum::Difficulty::easy);
  museum::GameState state = museum::new_game(level, 3);
  state.vive.running = true;
  state.vive.times_caught = 2;
  state.case_broken[1] = true;
  const auto snapshot =
      parse_server_message(museum_service::snapshot_json(level, state, "playing", true, true).dump());
  ASSERT_TRUE(snapshot) << snapshot.error().message;
  const auto& s = std::get<Snapshot>(*snapshot);
  EXPECT_TRUE(s.vive_running);
  EXPECT_EQ(s.times_caught, 2);
  ASSERT_EQ(s.cases.size(), static_cast<std::size_t>(state.case_count));
  for (int c = 0; c < state.case_count; ++c) {
    EXPECT_EQ(s.cases[static_cast<std::size_t>(c)].broken, state.case_broken[static_cast<std::size_t>(c)]);
    EXPECT_EQ(s.cases[static_cast<std::size_t>(c)].item.item, state.case_item[static_cast<std::size_t>(c)]);
  }

  state.items[0].place = museum::ItemPlace::kept;
  state.score.genuine_kept = 1;
  const museum::RoundSummary round = museum::summarize(level, state);
  const auto summary = parse_server_message(museum_service::summary_json(level, round).dump());
  ASSERT_TRUE(summary) << summary.error().message;
  const auto& sum = std::get<Summary>(*summary);
  EXPECT_EQ(sum.points, round.score.points);
  EXPECT_EQ(sum.times_caught, round.times_caught);
  EXPECT_EQ(sum.seconds_played, round.seconds_played);
  EXPECT_EQ(sum.ended_early, round.ended_early);
  ASSERT_EQ(sum.targets.size(), static_cast<std::size_t>(round.target_count));
  for (int t = 0; t < round.target_count; ++t) {
    const museum::TargetOutcome& o = round.targets[static_cast<std::size_t>(t)];
    EXPECT_EQ(sum.targets[static_cast<std::size_t>(t)].kind,
              level.artifact_kinds[static_cast<std::size_t>(o.kind)]);
    EXPECT_EQ(sum.targets[static_cast<std::size_t>(t)].genuine, museum::to_string(o.genuine_place));
    EXPECT_EQ(sum.targets[static_cast<std::size_t>(t)].forgery, museum::to_string(o.forgery_place));
  }
}

// Whatever a server (or the network) garbles, a client gets a message or an error saying what is
// wrong: never an exception, never an empty excuse.
TEST(ServerMessages, AnyMutationOfAMessageParsesOrIsAnError) {
  const museum::Level level = museum::make_level(museum::Difficulty::hard);
  museum::GameState state = museum::new_game(level, 6);
  state.table[0] = 1;
  state.table_count = 1;
  const std::vector<std::string> messages{
      museum_service::snapshot_json(level, state, "playing", true, true).dump(),
      museum_service::summary_json(level, museum::summarize(level, state)).dump(),
      museum_service::in_hands_json(level, state, 1).dump(),
      museum_service::event_json({.type = museum::EventType::vive_caught, .guard = 1, .count = 2}).dump(),
      json{{"type", "welcome"},
           {"role", "phantom"},
           {"level", museum_service::level_json(level)},
           {"targets", {"bowl"}}}
          .dump(),
  };
  std::mt19937 rng(14);
  int refused = 0;
  for (const std::string& message : messages) {
    for (int i = 0; i < 400; ++i) {
      const std::string mutated = test::mutate_text(message, "{}[]\":,.-0123456789aeltrunfs ", rng);
      Result<ServerMessage> parsed = Error{"not parsed"};
      ASSERT_NO_THROW(parsed = parse_server_message(mutated)) << mutated;
      if (!parsed) {
        ++refused;
        EXPECT_FALSE(parsed.error().message.empty()) << mutated;
      }
    }
  }
  EXPECT_GT(refused, 100) << "the mutations reached the checks";
}

TEST(ServerMessages, ABadMessageIsAnErrorNamingTheField) {
  const struct {
    const char* text;
    const char* says;
  } cases[] = {
      {"not json", "not JSON"},
      {"[1, 2]", "not a JSON object"},
      {R"({"tick": 3})", "'type' is missing"},
      {R"({"type": "fireworks"})", "'fireworks'"},
      {R"({"type": "event", "event": "earthquake"})", "'earthquake'"},
      {R"({"type": "event", "event": "case_broken", "case": 1, "pos": [1], "radius": 2})", "'pos'"},
      {R"({"type": "event", "event": "verdict", "item": 1, "verdict": "maybe"})", "'maybe'"},
      {R"({"type": "in_hands", "item": 2, "kind": "bowl", "piece": "replica"})", "'replica'"},
      {R"({"type": "snapshot", "tick": 1, "time_left_s": "soon"})", "'time_left_s'"},
      {R"({"type": "summary", "score": {"points": 1.5}})", "'score.points'"},
      {R"({"type": "snapshot", "tick": 1, "time_left_s": 3, "phase": "playing", "vive": {"pos": [0, 0],
          "facing": [1, 0], "running": "yes"}})",
       "'vive.running' must be true or false"},
      {R"({"type": "snapshot", "tick": 1, "time_left_s": 3, "phase": "playing", "vive": {"pos": [0, 0],
          "facing": [1, 0], "running": false, "times_caught": 0, "carried": [{"item": "one"}]}})",
       "'vive.carried[0].item' must be an integer"},
      {R"({"type": "summary", "score": {"points": 1, "genuine_kept": 0, "forgeries_kept": 0,
          "genuine_rejected": 0, "forgeries_rejected": 0, "time_bonus": 0}, "targets": [{"kind": 3}]})",
       "'targets[0].kind' must be a string"},
  };
  for (const auto& c : cases) {
    const auto parsed = parse_server_message(c.text);
    ASSERT_FALSE(parsed) << c.text;
    EXPECT_NE(parsed.error().message.find(c.says), std::string::npos)
        << c.text << " -> " << parsed.error().message;
  }
}

}  // namespace
}  // namespace uh::museum_client
