// What the server says, as the station reads it: the messages of docs/museum.md, and a bad one
// refused with the field named.

#include "uh/museum_station/server_messages.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "../museum/test_levels.hpp"
#include "game_messages.hpp"

namespace uh::museum_station {
namespace {

using nlohmann::json;

// the server's own writers make the messages: the station reads what the server writes
TEST(StationMessages, ReadsWhatTheServerWrites) {
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
            state.items[1].genuine ? museum_artifacts::Piece::genuine : museum_artifacts::Piece::forgery);

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

TEST(StationMessages, ABadMessageIsAnErrorNamingTheField) {
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
  };
  for (const auto& c : cases) {
    const auto parsed = parse_server_message(c.text);
    ASSERT_FALSE(parsed) << c.text;
    EXPECT_NE(parsed.error().message.find(c.says), std::string::npos)
        << c.text << " -> " << parsed.error().message;
  }
}

}  // namespace
}  // namespace uh::museum_station
