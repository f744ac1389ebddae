#pragma once
/// \file
/// ViveView: the round as Vive sees it (the snapshots and the guards she hears), turned into a game
/// state the sighted bot (museum::SightedBot) can plan on, and the watcher of `uh museum play` names
/// the pieces by. Never which piece is genuine: every item reads as a forgery (the bot does not
/// look). A guard's hidden bookkeeping is inferred: on its round, the leg it walks and which way
/// (from where it faces); investigating, the noise it went for (the guard_heard events); going
/// back, straight to the nearest corner of its round.

#include <array>
#include <string>
#include <vector>

#include "uh/museum/game_state.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum/rules.hpp"
#include "uh/museum_protocol/messages.hpp"

namespace uh::museum_players {

class ViveView {
 public:
  /// `level`: the shipped level the round plays (kept by reference: it must outlive the view).
  explicit ViveView(const museum::Level& level) : level_(level) {}

  /// A guard_heard event: where that guard goes to look.
  void heard(const museum::Event& event);
  /// The state after a snapshot, with the round's `targets` (from the welcome).
  const museum::GameState& update(const museum_protocol::Snapshot& snapshot,
                                  const std::vector<std::string>& targets);
  const museum::GameState& state() const { return state_; }

 private:
  void infer_guard(int g, const museum_protocol::GuardView& seen);

  const museum::Level& level_;
  museum::GameState state_{};
  std::array<museum::Vec2, museum::kMaxGuards> noise_{};
};

}  // namespace uh::museum_players
