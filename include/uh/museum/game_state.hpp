#pragma once
/// \file
/// GameState: everything that changes during a round, as plain data (like MuJoCo's mjData).
///
/// Fixed capacities and integer indices (into the Level and into the state's own arrays), no
/// pointers: a state is trivially copyable, compares with ==, and a round is replayed exactly by
/// stepping a copy with the same inputs. Made by new_game() and changed only by step() (rules.hpp).

#include <array>
#include <cstdint>

#include "uh/museum/level.hpp"

namespace uh::museum {

/// Where an artifact is.
enum class ItemPlace : std::uint8_t {
  in_case,   ///< in its display case (broken or not)
  carried,   ///< in Vive's hands
  on_table,  ///< on Phantom's table, waiting for a verdict
  kept,      ///< Phantom judged it genuine and kept it
  rejected,  ///< Phantom judged it a forgery and put it aside
};
const char* to_string(ItemPlace place);

/// One artifact of the round: a target's genuine piece or its forgery (they look the same).
struct ItemState {
  int kind = -1;         ///< index into Level::artifact_kinds
  bool genuine = false;  ///< the truth, known to the rules only; a client never sees it
  ItemPlace place = ItemPlace::in_case;
  int case_index = -1;  ///< the case it was displayed in (it goes back there when Vive is caught)

  friend bool operator==(const ItemState&, const ItemState&) = default;
};

enum class GuardMode : std::uint8_t {
  patrol,       ///< walking its round
  investigate,  ///< walking to (or looking around) a noise it heard
  returning,    ///< walking back along its trail to where it left its round
};
const char* to_string(GuardMode mode);

struct GuardState {
  Vec2 pos{};             ///< [m]
  Vec2 facing{1.0, 0.0};  ///< unit vector the guard looks along
  int next_waypoint = 0;  ///< on its route (Level::routes[guard index])
  int direction = 1;      ///< +1: along the route's order, -1: against it
  GuardMode mode = GuardMode::patrol;
  Vec2 noise_pos{};  ///< where the noise it investigates came from: it faces there [m]
  /// Where it walks while investigating [m]: the noise when the way there is clear, else where it
  /// stood when it heard it (it turns to look instead).
  Vec2 goal{};
  double linger_left_s = 0.0;  ///< looking around at the noise, counting down [s]
  /// Where it turned since leaving its round (trail[0]: where it left): it walks back along
  /// them, so every leg it walks is a clear straight path.
  std::array<Vec2, kMaxTrail> trail{};
  int trail_count = 0;

  friend bool operator==(const GuardState&, const GuardState&) = default;
};

struct ViveState {
  Vec2 pos{};                                    ///< [m]
  Vec2 facing{1.0, 0.0};                         ///< unit vector of the last movement
  bool running = false;                          ///< ran this tick (moved at run speed)
  std::array<int, kMaxCarried> carried{-1, -1};  ///< item indices, the first carried_count valid
  int carried_count = 0;
  double grace_left_s = 0.0;  ///< after a catch, guards cannot catch again until this is zero [s]
  int times_caught = 0;

  friend bool operator==(const ViveState&, const ViveState&) = default;
};

enum class Phase : std::uint8_t { playing, ended };
const char* to_string(Phase phase);

/// The running score; summarize() (rules.hpp) recounts it from the items.
struct Score {
  int genuine_kept = 0;
  int forgeries_kept = 0;
  int genuine_rejected = 0;
  int forgeries_rejected = 0;
  int time_bonus = 0;  ///< awarded when the round ends early with every target settled
  int points = 0;      ///< genuine_points per genuine kept - forgery_penalty per forgery kept + time_bonus

  friend bool operator==(const Score&, const Score&) = default;
};

struct GameState {
  std::uint64_t seed = 0;
  std::int64_t tick = 0;     ///< rule steps played (pauses do not count)
  double time_left_s = 0.0;  ///< [s], >= 0
  Phase phase = Phase::playing;
  /// Set by whoever runs the round (the server when a client drops out): step() then changes
  /// nothing, the timer included.
  bool paused = false;
  bool ended_early = false;  ///< every target settled before the time ran out

  std::array<int, kMaxTargets> target_kinds{};  ///< Falcon's targets, indices into artifact kinds
  int target_count = 0;
  /// Items 2t and 2t+1 are target t's two pieces; which of them is genuine is the seed's choice.
  std::array<ItemState, kMaxItems> items{};
  int item_count = 0;
  std::array<bool, kMaxCases> case_broken{};
  std::array<int, kMaxCases> case_item{};  ///< item index displayed there, -1: empty
  int case_count = 0;
  std::array<GuardState, kMaxGuards> guards{};
  int guard_count = 0;
  ViveState vive{};
  /// Items on Phantom's table in the order delivered; Phantom judges table[0] first.
  std::array<int, kMaxItems> table{};
  int table_count = 0;
  Score score{};

  friend bool operator==(const GameState&, const GameState&) = default;
};

}  // namespace uh::museum
