// The sighted bot's view: the round as Vive sees it, read from the snapshots the server writes.

#include "uh/museum_players/vive_view.hpp"

#include <gtest/gtest.h>

#include "uh/museum_protocol/views.hpp"

namespace uh::museum_players {
namespace {

TEST(ViveView, SeesWhatTheSnapshotShowsAndInfersTheGuardsRounds) {
  const museum::Level level = museum::make_level(museum::Difficulty::easy);
  museum::GameState truth = museum::new_game(level, 5);
  truth.paused = false;
  museum::Events events;
  for (int i = 0; i < 300; ++i) museum::step(level, truth, {.vive = {.move = {1.0, 0.0}}}, events);
  truth.vive.carried[0] = truth.case_item[0];
  truth.vive.carried_count = 1;
  truth.items[static_cast<std::size_t>(truth.case_item[0])].place = museum::ItemPlace::carried;
  truth.case_item[0] = -1;
  truth.case_broken[0] = true;

  const auto read = museum_protocol::read_server_message(
      museum_protocol::write_message(museum_protocol::snapshot_of(level, truth, "playing", true, true)));
  ASSERT_TRUE(read) << read.error().message;
  const auto& snapshot = std::get<museum_protocol::Snapshot>(*read);
  ViveView view(level);
  const museum::GameState& seen = view.update(snapshot, snapshot.targets);
  EXPECT_EQ(seen.tick, truth.tick);
  EXPECT_FALSE(seen.paused);
  EXPECT_EQ(seen.vive.pos, truth.vive.pos);
  ASSERT_EQ(seen.vive.carried_count, 1);
  EXPECT_EQ(seen.vive.carried[0], truth.vive.carried[0]);
  EXPECT_EQ(seen.target_count, truth.target_count);
  for (int c = 0; c < truth.case_count; ++c) {
    EXPECT_EQ(seen.case_broken[static_cast<std::size_t>(c)], truth.case_broken[static_cast<std::size_t>(c)]);
    EXPECT_EQ(seen.case_item[static_cast<std::size_t>(c)], truth.case_item[static_cast<std::size_t>(c)]);
  }
  for (int i = 0; i < truth.item_count; ++i) {
    EXPECT_EQ(seen.items[static_cast<std::size_t>(i)].kind, truth.items[static_cast<std::size_t>(i)].kind);
    EXPECT_EQ(seen.items[static_cast<std::size_t>(i)].place, truth.items[static_cast<std::size_t>(i)].place);
    EXPECT_FALSE(seen.items[static_cast<std::size_t>(i)].genuine) << "the view never knows a genuine piece";
  }
  ASSERT_EQ(seen.guard_count, truth.guard_count);
  for (int g = 0; g < truth.guard_count; ++g) {
    const museum::GuardState& a = seen.guards[static_cast<std::size_t>(g)];
    const museum::GuardState& b = truth.guards[static_cast<std::size_t>(g)];
    EXPECT_EQ(a.pos, b.pos);
    EXPECT_EQ(a.mode, b.mode);
    // on its round, the bot infers the corner it walks to from where it faces
    if (b.mode == museum::GuardMode::patrol) {
      EXPECT_EQ(a.next_waypoint, b.next_waypoint) << "guard " << g;
      EXPECT_EQ(a.direction, b.direction) << "guard " << g;
    }
  }
}

}  // namespace
}  // namespace uh::museum_players
