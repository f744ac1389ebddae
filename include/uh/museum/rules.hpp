#pragma once
/// \file
/// The heist's rules as step functions over plain data (in the style of Box2D's b2World_Step and
/// MuJoCo's mj_step): new_game() deals a round from a seed, step() advances it by one fixed tick
/// from the players' inputs and reports what happened as events, summarize() tallies the end.
///
/// Deterministic: the same level, seed and inputs give the same states bit for bit. The seed
/// decides Falcon's targets, which case holds each genuine piece and each forgery, and where and
/// which way round each guard starts. step() never allocates, locks, throws or logs.

#include <array>
#include <cstdint>

#include "uh/museum/game_state.hpp"
#include "uh/museum/level.hpp"

namespace uh::museum {

/// What Vive does in one tick. Actions act on the nearest case (or the table) within reach.
struct ViveInput {
  Vec2 move{};              ///< the wanted direction; longer than 1 counts as 1, zero stands still
  bool run = false;         ///< run instead of walk (faster, and guards hear it)
  bool break_case = false;  ///< smash the nearest intact case within reach (guards hear the glass)
  bool take = false;        ///< take the artifact from the nearest broken case within reach
  bool deliver = false;     ///< put every carried artifact on Phantom's table (within reach)
};

/// Phantom's verdict on the artifact at the front of the table, given with the device's button.
enum class Verdict : std::uint8_t { none, genuine, forgery };
const char* to_string(Verdict verdict);

/// Both players' inputs for one tick.
struct TickInput {
  ViveInput vive{};
  Verdict verdict = Verdict::none;
};

enum class EventType : std::uint8_t {
  case_broken,      ///< case_index, pos; a glass noise of radius
  case_empty,       ///< Vive broke a case that held nothing (case_index)
  item_taken,       ///< item, case_index
  items_delivered,  ///< count items put on the table
  guard_heard,      ///< guard, pos (the noise), radius: a guard started investigating
  vive_caught,      ///< guard, count items taken back to their cases, pos (where)
  verdict,          ///< item, verdict, correct
  time_warning,     ///< count seconds left (60, 30 or 10)
  round_ended,      ///< count: the points scored
};
const char* to_string(EventType type);

/// Something that happened in a tick; the fields its type does not use keep their defaults.
struct Event {
  EventType type = EventType::round_ended;
  int guard = -1;
  int item = -1;
  int case_index = -1;
  int count = 0;
  Vec2 pos{};           ///< [m]
  double radius = 0.0;  ///< how far the noise carried [m]
  Verdict verdict = Verdict::none;
  bool correct = false;

  friend bool operator==(const Event&, const Event&) = default;
};

/// The events of one tick (fixed capacity; step() clears it first).
struct Events {
  static constexpr int kCapacity = 32;
  std::array<Event, kCapacity> list{};
  int count = 0;
  int dropped = 0;  ///< events that did not fit (a capacity the tests keep at zero)

  void clear() {
    count = 0;
    dropped = 0;
  }
  void push(const Event& e) {
    if (count < kCapacity) {
      list[static_cast<std::size_t>(count++)] = e;
    } else {
      ++dropped;
    }
  }
};

/// A round dealt from `seed`. The level must have passed validate() (asserted).
GameState new_game(const Level& level, std::uint64_t seed);

/// Advances the round by one tick (Level::rules.tick_s) from the inputs, in this order: the timer,
/// Vive's movement and actions, Phantom's verdict, the guards (hearing this tick's noises,
/// walking, seeing), the end of the round. A paused or ended round does not change. Real-time
/// safe.
void step(const Level& level, GameState& state, const TickInput& input, Events& events);

/// Whether a guard at `guard_pos` facing `facing` sees `target` (within the view range, inside
/// the cone, along a clear path).
bool guard_sees(const Level& level, Vec2 guard_pos, Vec2 facing, Vec2 target);

/// Whether a target is settled: one of its pieces kept, or both rejected.
bool target_settled(const GameState& state, int target);

/// The end of a round, tallied from the items (independently of the running score).
struct TargetOutcome {
  int kind = -1;
  ItemPlace genuine_place = ItemPlace::in_case;  ///< where the genuine piece ended up
  ItemPlace forgery_place = ItemPlace::in_case;  ///< where the forgery ended up
};
struct RoundSummary {
  std::array<TargetOutcome, kMaxTargets> targets{};
  int target_count = 0;
  Score score{};
  int times_caught = 0;
  double seconds_played = 0.0;  ///< [s]
  bool ended_early = false;
};
RoundSummary summarize(const Level& level, const GameState& state);

}  // namespace uh::museum
