#pragma once
/// \file
/// What Phantom's station says and plays for each game event: every event type has an earcon (a
/// short sound that tells the type before any word), a spoken text (for speech synthesis, the
/// words a blind player hears) and a caption (the same in a few words, for a braille line or a
/// screen). Plain data; the station turns earcons into sounds (uh::audio).

#include <cstdint>
#include <string>

#include "uh/museum/game_state.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum/rules.hpp"

namespace uh::museum {

/// One earcon per meaning; several event types may share one when they mean the same to the player.
enum class Earcon : std::uint8_t {
  glass,     ///< a case broke
  empty,     ///< nothing in it
  pickup,    ///< an artifact taken
  delivery,  ///< artifacts on the table
  alert,     ///< a guard heard something
  caught,    ///< Vive caught
  right,     ///< a verdict that was right
  wrong,     ///< a verdict that was wrong
  clock,     ///< time is running out
  finale,    ///< the round ended
};
inline constexpr int kEarconCount = 10;
const char* to_string(Earcon earcon);

struct Cue {
  Earcon earcon = Earcon::finale;
  std::string speech{};   ///< a full sentence
  std::string caption{};  ///< a few words
  /// Said at once, interrupting speech in progress (being caught, the last seconds); otherwise
  /// queued after it.
  bool urgent = false;
};

/// The cue of one event of the round. `state` is the state after the tick that produced the
/// event (for the artifacts' names and the table); `level` names the rooms and artifact kinds.
Cue describe(const Event& event, const Level& level, const GameState& state);

/// The room that holds the point, or "the corridors" when none does.
std::string room_at(const Level& level, Vec2 pos);

}  // namespace uh::museum
