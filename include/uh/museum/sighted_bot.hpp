#pragma once
/// \file
/// SightedBot: an automated Vive. It walks through the rooms to the
/// nearest case that holds a piece of one of Falcon's targets, breaks it and takes the piece, two
/// at a time, and brings them to Phantom's table. It looks a few seconds ahead by playing the rules
/// on a copy of what it sees (walking on, standing still, walking back towards the entrance,
/// then running on or back: running is faster but heard) and takes the first way no guard
/// catches it on; it waits to break a case while a guard would hear
/// the glass. It reads only what Vive sees: positions, cases, the kinds of the pieces, never
/// which one is genuine.

#include <cstdint>
#include <vector>

#include "uh/museum/game_state.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum/rules.hpp"

namespace uh::museum {

class SightedBot {
 public:
  /// The level must validate; the bot keeps a reference to it.
  explicit SightedBot(const Level& level);

  /// Vive's input for the next tick.
  ViveInput decide(const GameState& state);

  /// The way from `from` to `to` across the rooms: the doorways' centres to pass, then `to`; empty
  /// when either point is off the floor or no way joins them. Every leg stays on the floor.
  std::vector<Vec2> route(Vec2 from, Vec2 to) const;

 private:
  // the case to go for next (a target's piece still in it, nearest by route), or -1
  int next_case(const GameState& state) const;
  // walking on, standing, walking back towards the entrance; running on or back (heard, faster)
  enum class Plan : std::uint8_t { go_on, stand, back_off, run_on, run_off };
  // how often she looks ahead, and how far [ticks]
  static constexpr int kReplanTicks = 6;
  static constexpr int kLookAheadTicks = 240;
  // the move towards `goal` along its route (none when `stand`)
  ViveInput step_towards(Vec2 from, Vec2 goal, bool stand) const;
  // the input of a plan from where she stands
  ViveInput follow(Vec2 from, Plan plan, Vec2 goal) const;
  // whether following `plan` for the look-ahead keeps her out of the guards' hands
  bool safe(const GameState& state, Plan plan, Vec2 goal) const;

  const Level& level_;
  std::int64_t waiting_since_tick_ = -1;  ///< by a case for the guards to be out of earshot, since
  std::int64_t replan_at_tick_ = 0;  ///< looks ahead again at this tick
  Plan plan_ = Plan::go_on;
};

}  // namespace uh::museum
