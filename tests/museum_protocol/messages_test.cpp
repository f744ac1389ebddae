// The museum's messages both ways (docs/museum.md): what the server writes, a client (the station, the
// bots) reads, and the other way; a bad one refused with the field named; Phantom's in_hands never says
// which piece it holds.

#include "uh/museum_protocol/messages.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "../museum/test_levels.hpp"
#include "text_mutation.hpp"
#include "uh/museum_protocol/views.hpp"

namespace uh::museum_protocol {
namespace {

using nlohmann::json;

// the server's own writers make the messages: the station reads what the server writes
TEST(ServerMessages, ReadsWhatTheServerWrites) {
  const museum::Level level = museum::make_level(museum::Difficulty::hard);
  museum::GameState state = museum::new_game(level, 4);
  state.table[0] = 1;
  state.table_count = 1;
  state.items[1].place = museum::ItemPlace::on_table;
  const auto snapshot = read_server_message(write_message(snapshot_of(level, state, "playing", true, true)));
  ASSERT_TRUE(snapshot) << snapshot.error().message;
  const auto& s = std::get<Snapshot>(*snapshot);
  EXPECT_EQ(s.phase, "playing");
  EXPECT_EQ(s.guards.size(), static_cast<std::size_t>(state.guard_count));
  EXPECT_EQ(s.guards[0].pos.x, state.guards[0].pos.x);
  ASSERT_EQ(s.table.size(), 1u);
  EXPECT_EQ(s.table[0].item, 1);
  EXPECT_EQ(s.table[0].kind, level.artifact_kinds[static_cast<std::size_t>(state.items[1].kind)]);
  EXPECT_EQ(s.cases.size(), level.cases.size());

  const auto in_hands = read_server_message(write_message(in_hand_of(level, state, 1)));
  ASSERT_TRUE(in_hands) << in_hands.error().message;
  EXPECT_EQ(std::get<InHand>(*in_hands).item, 1);
  EXPECT_EQ(std::get<InHand>(*in_hands).kind, s.table[0].kind);

  const auto w = read_server_message(write_message(welcome_of(level, state, Role::phantom)));
  ASSERT_TRUE(w) << w.error().message;
  EXPECT_EQ(std::get<Welcome>(*w).role, "phantom");
  const museum::Level& read = std::get<Welcome>(*w).level;
  EXPECT_EQ(read.difficulty, museum::Difficulty::hard);
  ASSERT_EQ(read.rooms.size(), level.rooms.size());
  for (std::size_t r = 0; r < level.rooms.size(); ++r) {
    EXPECT_EQ(read.rooms[r].name, level.rooms[r].name);
    EXPECT_EQ(read.rooms[r].min, level.rooms[r].min);
    EXPECT_EQ(read.rooms[r].max, level.rooms[r].max);
  }
  for (const museum::RuleField& f : museum::kRuleFields) {
    if (f.told) {
      EXPECT_EQ(read.rules.*f.value, level.rules.*f.value) << f.name;
    }
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
    const auto parsed = read_server_message(write_message(GameEvent{e}));
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
  const auto snapshot = read_server_message(write_message(snapshot_of(level, state, "playing", true, true)));
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
  const auto summary = read_server_message(write_message(summary_of(level, round)));
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
      write_message(snapshot_of(level, state, "playing", true, true)),
      write_message(summary_of(level, museum::summarize(level, state))),
      write_message(in_hand_of(level, state, 1)),
      write_message(GameEvent{{.type = museum::EventType::vive_caught, .guard = 1, .count = 2}}),
      write_message(welcome_of(level, state, Role::phantom)),
  };
  core::SplitMix64 rng{14};
  int refused = 0;
  for (const std::string& message : messages) {
    for (int i = 0; i < 400; ++i) {
      const std::string mutated = test::mutate_text(message, "{}[]\":,.-0123456789aeltrunfs ", rng);
      Result<ServerMessage> parsed = Error{"not parsed"};
      ASSERT_NO_THROW(parsed = read_server_message(mutated)) << mutated;
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
      {"not json", "not valid JSON"},
      {"[1, 2]", "not a JSON object"},
      {R"({"tick": 3})", "'type' is missing"},
      {R"({"type": "fireworks"})", "'fireworks'"},
      {R"({"type": "event", "event": "earthquake"})", "'earthquake'"},
      {R"({"type": "event", "event": "case_broken", "case": 1, "pos": [1], "radius": 2})", "'pos'"},
      {R"({"type": "event", "event": "verdict", "item": 1, "verdict": "maybe"})", "'maybe'"},
      {R"({"type": "in_hands", "item": 2, "kind": "bowl", "form": {"difficulty": "easy", "feature": "deep"}})",
       "'form.feature' must be a finite number"},
      {R"({"type": "in_hands", "item": 2, "kind": "bowl"})", "'form' is missing"},
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
    const auto parsed = read_server_message(c.text);
    ASSERT_FALSE(parsed) << c.text;
    EXPECT_NE(parsed.error().message.find(c.says), std::string::npos)
        << c.text << " -> " << parsed.error().message;
  }
}

// What a client writes, the server reads field for field; what the server refuses is named.
TEST(ClientMessages, TheServerReadsWhatAClientWrites) {
  const auto hello = read_client_message(
      write_message(HelloMessage{.role = Role::phantom, .token = "t0k", .seat_key = "0123abcd"}));
  ASSERT_TRUE(hello.body) << hello.error;
  const auto& h = std::get<HelloMessage>(*hello.body);
  EXPECT_EQ(h.protocol, kProtocolVersion);
  EXPECT_EQ(h.role, Role::phantom);
  EXPECT_EQ(h.token, "t0k");
  EXPECT_EQ(h.seat_key, "0123abcd");

  const auto move = read_client_message(write_message(MoveMessage{{0.6, -0.8}, true}));
  ASSERT_TRUE(move.body) << move.error;
  EXPECT_EQ(std::get<MoveMessage>(*move.body).move, (museum::Vec2{0.6, -0.8}));
  EXPECT_TRUE(std::get<MoveMessage>(*move.body).run);

  for (const Action a : {Action::break_case, Action::take, Action::deliver}) {
    const auto action = read_client_message(write_message(ActionMessage{a}));
    ASSERT_TRUE(action.body) << action.error;
    EXPECT_EQ(std::get<ActionMessage>(*action.body).action, a);
  }
  const auto verdict = read_client_message(write_message(VerdictMessage{3, museum::Verdict::forgery}));
  ASSERT_TRUE(verdict.body) << verdict.error;
  EXPECT_EQ(std::get<VerdictMessage>(*verdict.body).item, 3);
  EXPECT_EQ(std::get<VerdictMessage>(*verdict.body).verdict, museum::Verdict::forgery);

  const struct {
    const char* text;
    const char* says;
  } cases[] = {
      {"{not json", "not valid JSON"},
      {"[1, 2]", "must be a JSON object"},
      {R"({"id": 1})", "'type' is missing"},
      {R"({"type": "dance"})", "unknown message type 'dance'"},
      {R"({"type": "hello", "protocol": 1, "role": "guard"})", "'role' is 'guard'"},
      {R"({"type": "hello", "protocol": 1, "role": "vive", "token": 7})", "'token' must be a string"},
      {R"({"type": "move", "move": [1]})", "'move' must be [x, y]"},
      {R"({"type": "move", "move": [1, 0], "run": 1})", "'run' must be true or false"},
      {R"({"type": "action", "action": "dance"})", "'action' is 'dance'"},
      {R"({"type": "verdict", "item": 0})", "'verdict' is missing"},
  };
  for (const auto& c : cases) {
    const auto parsed = read_client_message(c.text);
    ASSERT_FALSE(parsed.body) << c.text;
    EXPECT_NE(parsed.error.find(c.says), std::string::npos) << c.text << " -> " << parsed.error;
  }
  // the parser's words quote the client's bytes, which need not be UTF-8: the error reply is still
  // written (replaced, never thrown on; the fuzzer's first find)
  const auto garbled = read_client_message("{\"typ\xff\":\"move\"}");
  ASSERT_FALSE(garbled.body);
  std::string reply;
  ASSERT_NO_THROW(reply = write_message(
                      ServerError{.id = garbled.id, .request = garbled.type, .message = garbled.error}));
  EXPECT_TRUE(read_server_message(reply)) << reply;
  const std::string deep = std::string(64, '[') + std::string(64, ']');
  EXPECT_NE(read_client_message(deep).error.find("nested deeper"), std::string::npos);
  EXPECT_FALSE(read_server_message(deep));
}

// A game client learns only what its player may know: Phantom's station is told the form of the
// piece in its hands, the same fields for the genuine piece and the forgery, and never which it is
// (issue 25: in_hands once said `piece: genuine|forgery` in plain text). The welcome carries no
// pieces, the snapshot no label.
TEST(ServerMessages, InHandsCarriesTheFormAndNeverWhichPieceItIs) {
  museum::Level level = museum::make_level(museum::Difficulty::easy);
  for (const std::string& kind : level.artifact_kinds)
    level.pieces.push_back(
        {{.kind = kind, .feature = 0.002, .stiffness = 2e5, .friction_static = 0.4, .friction_dynamic = 0.3},
         {.kind = kind, .feature = 0.0, .stiffness = 1e5, .friction_static = 0.5, .friction_dynamic = 0.4}});
  const museum::GameState state = museum::new_game(level, 8);
  std::vector<std::string> seen;
  for (int i = 0; i < state.item_count; ++i) {
    const museum::ItemState& item = state.items[static_cast<std::size_t>(i)];
    const std::string text = write_message(in_hand_of(level, state, i));
    SCOPED_TRACE(text);
    EXPECT_EQ(text.find("genuine"), std::string::npos);
    EXPECT_EQ(text.find("forgery"), std::string::npos);
    EXPECT_EQ(text.find("piece"), std::string::npos);
    // the form is that piece's: the station builds what the server holds it to be
    const auto read = read_server_message(text);
    ASSERT_TRUE(read) << read.error().message;
    const museum::PieceForm& form = std::get<InHand>(*read).form;
    const museum::PiecePair& pair = level.pieces[static_cast<std::size_t>(item.kind)];
    const museum::PieceForm& held = item.genuine ? pair.genuine : pair.forgery;
    EXPECT_EQ(form.kind, held.kind);
    EXPECT_EQ(form.feature, held.feature);
    EXPECT_EQ(form.stiffness, held.stiffness);
    EXPECT_EQ(form.friction_static, held.friction_static);
    EXPECT_EQ(form.friction_dynamic, held.friction_dynamic);
    // the same fields whichever piece it is
    json keys = json::parse(text);
    for (auto& [k, v] : keys.items())
      if (!v.is_object()) v = nullptr;
    keys["form"] = json::array();
    const json parsed = json::parse(text);  // named: a range over a temporary's member would dangle
    for (const auto& [k, v] : parsed["form"].items()) keys["form"].push_back(k);
    seen.push_back(keys.dump());
  }
  for (const std::string& k : seen) EXPECT_EQ(k, seen.front());
  const std::string welcome = write_message(welcome_of(level, state, Role::phantom));
  EXPECT_EQ(welcome.find("feature"), std::string::npos) << "the welcome tells no piece's form";
  EXPECT_EQ(write_message(snapshot_of(level, state, "playing", true, true)).find("genuine"),
            std::string::npos);
}

}  // namespace
}  // namespace uh::museum_protocol
