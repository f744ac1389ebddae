#include "uh/museum/cues.hpp"

#include <fmt/format.h>

namespace uh::museum {
namespace {

std::string item_name(const Level& level, const GameState& state, int item) {
  if (item < 0 || item >= state.item_count) return "an artifact";
  const int kind = state.items[static_cast<std::size_t>(item)].kind;
  if (kind < 0 || kind >= static_cast<int>(level.artifact_kinds.size())) return "an artifact";
  return "the " + level.artifact_kinds[static_cast<std::size_t>(kind)];
}

std::string plural(int count, const char* one, const char* many) {
  return fmt::format("{} {}", count, count == 1 ? one : many);
}

}  // namespace

const char* to_string(Earcon earcon) {
  switch (earcon) {
    case Earcon::glass:
      return "glass";
    case Earcon::empty:
      return "empty";
    case Earcon::pickup:
      return "pickup";
    case Earcon::delivery:
      return "delivery";
    case Earcon::alert:
      return "alert";
    case Earcon::caught:
      return "caught";
    case Earcon::right:
      return "right";
    case Earcon::wrong:
      return "wrong";
    case Earcon::clock:
      return "clock";
    case Earcon::finale:
      return "finale";
  }
  return "unknown";
}

std::string room_at(const Level& level, Vec2 pos) {
  for (const Room& room : level.rooms) {
    if (pos.x >= room.min.x && pos.x <= room.max.x && pos.y >= room.min.y && pos.y <= room.max.y)
      return room.name;
  }
  return "the corridors";
}

Cue describe(const Event& event, const Level& level, const GameState& state) {
  switch (event.type) {
    case EventType::case_broken:
      return {Earcon::glass,
              fmt::format("Glass breaks in {}. It carries {:.0f} metres.", room_at(level, event.pos),
                          event.radius),
              "Case broken", false};
    case EventType::case_empty:
      return {Earcon::empty, "That case was empty.", "Empty case", false};
    case EventType::item_taken:
      return {Earcon::pickup, fmt::format("Vive has {}.", item_name(level, state, event.item)),
              fmt::format("Took {}", item_name(level, state, event.item)), false};
    case EventType::items_delivered: {
      const std::string first = state.table_count > 0 ? item_name(level, state, state.table[0]) : "it";
      return {Earcon::delivery,
              fmt::format("{} on your table. Feel {} first.", plural(event.count, "artifact", "artifacts"),
                          first),
              fmt::format("{} delivered", plural(event.count, "artifact", "artifacts")), false};
    }
    case EventType::guard_heard:
      return {Earcon::alert,
              fmt::format("A guard heard something in {} and is going to look.", room_at(level, event.pos)),
              "Guard alerted", false};
    case EventType::vive_caught:
      return {Earcon::caught,
              event.count > 0
                  ? fmt::format("Vive was caught in {}. {} back to the cases.", room_at(level, event.pos),
                                plural(event.count, "artifact goes", "artifacts go"))
                  : fmt::format("Vive was caught in {}.", room_at(level, event.pos)),
              "Vive caught", true};
    case EventType::verdict: {
      const std::string name = item_name(level, state, event.item);
      const char* said = event.verdict == Verdict::genuine ? "genuine" : "a forgery";
      return {event.correct ? Earcon::right : Earcon::wrong,
              fmt::format("You called {} {}. {}", name, said, event.correct ? "Right." : "Wrong."),
              fmt::format("{}: {}", name, event.correct ? "right" : "wrong"), false};
    }
    case EventType::time_warning:
      return {Earcon::clock, fmt::format("{} seconds left.", event.count),
              fmt::format("{} s left", event.count), event.count <= 10};
    case EventType::round_ended:
      return {Earcon::finale, fmt::format("The round is over. {} points.", event.count),
              fmt::format("Round over: {} points", event.count), true};
  }
  return {Earcon::finale, "Something happened.", "Event", false};
}

}  // namespace uh::museum
