#pragma once
/// \file
/// The automated players' rounds (`uh museum play`): each bot joins a museum server as a real
/// client over WebSocket, as the browser and the station do, and plays until the round ends or the
/// connection does. The sighted bot plays Vive from the snapshots (what she sees, ViveView); the
/// blind bot plays Phantom by touch alone: it studies the genuine piece of each target as the judge
/// does (study_reference), then explores each piece put in its hands (the form in_hands carries,
/// built as the station builds it) on a simulated device in simulated time and judges it against
/// that reference. Setup code on the caller's thread, not real-time.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "uh/core/result.hpp"
#include "uh/museum_client/game_link.hpp"
#include "uh/museum_players/blind_player.hpp"

namespace uh::museum_players {

/// A bot's connection to the server at `url` in `role`: it does not come back after a drop (the
/// round is over for it when the server goes).
Result<std::unique_ptr<museum_client::GameLink>> join_as_bot(const std::string& url, const std::string& role);

/// The next message from the server; none once the connection ended. A frame that does not parse
/// was logged by the link and is passed over.
std::optional<museum_client::LinkNote> next_message(museum_client::GameLink& link);

/// Plays Vive with the sighted bot on `url` until the round ends or the connection does. The bots
/// know only the shipped museum: another level is an error.
Status play_vive(const std::string& url);

/// One verdict of the blind bot.
struct BlindVerdict {
  int item = -1;
  std::string kind;
  Judgement judgement;
  double simulated_s = 0.0;  ///< device time the piece was explored [s]
};

struct PhantomBotOptions {
  std::string url;
  std::uint64_t seed = 1;             ///< deals the bot's placements and exploration spots
  std::filesystem::path cache_dir{};  ///< the artifacts' meshes and packings; empty: the default cache
  std::function<void()> seated{};     ///< when it takes Phantom's seat (the round starts)
  std::function<void(const BlindVerdict&)> judged{};  ///< each verdict, as it is sent
};

/// Plays Phantom with the blind bot: first, as a watcher, it reads the targets and studies the
/// genuine reference of each; then it takes the seat, and each piece in its hands is explored and
/// judged; only the device's trace decides.
Status play_phantom(const PhantomBotOptions& options);

}  // namespace uh::museum_players
