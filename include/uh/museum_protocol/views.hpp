#pragma once
/// \file
/// What each client may know of the round, as the messages the server sends: the game state and
/// the level turned into museum_protocol messages. A game client learns only what its player may
/// know: snapshots and events never say which piece is genuine (nor a verdict's points before the
/// end); Phantom's in_hands carries the form its station builds, never a label.

#include <string_view>

#include "uh/museum/game_state.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum_protocol/messages.hpp"

namespace uh::museum_protocol {

/// The state as every client may see it.
Snapshot snapshot_of(const museum::Level& level, const museum::GameState& state, std::string_view phase,
                     bool vive_connected, bool phantom_connected);
/// The level and the round's targets, for a client greeted in `role` (the seat key is Phantom's,
/// added by the server).
Welcome welcome_of(const museum::Level& level, const museum::GameState& state, Role role);
/// To Phantom only: `item` (the first on the table), its kind and the form of its piece from
/// level.pieces (a level without pieces gives an empty form).
InHand in_hand_of(const museum::Level& level, const museum::GameState& state, int item);
Summary summary_of(const museum::Level& level, const museum::RoundSummary& summary);

}  // namespace uh::museum_protocol
