#include <gtest/gtest.h>

#include <set>
#include <string>

#include "uh/museum/cues.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum/rules.hpp"

namespace uh::museum {
namespace {

constexpr int kEventTypeCount = static_cast<int>(EventType::round_ended) + 1;

// one event of each type, with the fields its type uses
Event example(EventType type, const Level& level) {
  Event e{.type = type};
  e.pos = level.cases.front().pos;
  e.item = 0;
  e.case_index = 0;
  e.guard = 0;
  e.count = 2;
  e.radius = level.rules.glass_hear_radius;
  e.verdict = Verdict::forgery;
  e.correct = true;
  return e;
}

TEST(Cues, EveryEventTypeHasAnEarconASentenceAndACaption) {
  const Level level = make_level(Difficulty::easy);
  GameState state = new_game(level, 7);
  state.table[0] = 1;
  state.table_count = 1;
  std::set<std::string> sentences;
  for (int t = 0; t < kEventTypeCount; ++t) {
    const auto type = static_cast<EventType>(t);
    SCOPED_TRACE(to_string(type));
    const Cue cue = describe(example(type, level), level, state);
    EXPECT_GE(static_cast<int>(cue.earcon), 0);
    EXPECT_LT(static_cast<int>(cue.earcon), kEarconCount);
    EXPECT_STRNE(to_string(cue.earcon), "unknown");
    ASSERT_FALSE(cue.speech.empty());
    ASSERT_FALSE(cue.caption.empty());
    EXPECT_TRUE(cue.speech.back() == '.' || cue.speech.back() == '!') << cue.speech;
    EXPECT_LT(cue.caption.size(), cue.speech.size()) << cue.caption << " / " << cue.speech;
    EXPECT_EQ(cue.speech.find("-1"), std::string::npos) << cue.speech;
    sentences.insert(cue.speech);
  }
  // no two event types sound the same
  EXPECT_EQ(static_cast<int>(sentences.size()), kEventTypeCount);
}

TEST(Cues, NameTheArtifactTheRoomAndTheOutcome) {
  const Level level = make_level(Difficulty::easy);
  GameState state = new_game(level, 7);
  const std::string kind = level.artifact_kinds[static_cast<std::size_t>(state.items[0].kind)];
  const Cue taken = describe({.type = EventType::item_taken, .item = 0}, level, state);
  EXPECT_NE(taken.speech.find(kind), std::string::npos) << taken.speech;

  Event right{.type = EventType::verdict, .item = 0, .verdict = Verdict::genuine, .correct = true};
  Event wrong = right;
  wrong.correct = false;
  EXPECT_EQ(describe(right, level, state).earcon, Earcon::right);
  EXPECT_EQ(describe(wrong, level, state).earcon, Earcon::wrong);
  EXPECT_NE(describe(wrong, level, state).speech.find("Wrong"), std::string::npos);

  // a noise in a room names that room; outside every room, the corridors
  const Room& room = level.rooms.front();
  const Vec2 inside{(room.min.x + room.max.x) / 2, (room.min.y + room.max.y) / 2};
  EXPECT_EQ(room_at(level, inside), room.name);
  EXPECT_EQ(room_at(level, {-1e6, -1e6}), "the corridors");
  const Cue heard = describe({.type = EventType::guard_heard, .pos = inside}, level, state);
  EXPECT_NE(heard.speech.find(room.name), std::string::npos) << heard.speech;

  // being caught and the last ten seconds interrupt; other news waits its turn
  EXPECT_TRUE(describe({.type = EventType::vive_caught}, level, state).urgent);
  EXPECT_TRUE(describe({.type = EventType::time_warning, .count = 10}, level, state).urgent);
  EXPECT_FALSE(describe({.type = EventType::time_warning, .count = 60}, level, state).urgent);
  EXPECT_FALSE(describe({.type = EventType::case_broken}, level, state).urgent);
}

}  // namespace
}  // namespace uh::museum
