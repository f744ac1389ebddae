#include "uh/museum_players/bot_rounds.hpp"

#include <map>
#include <utility>

#include <fmt/format.h>

#include "uh/core/split_mix.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum/sighted_bot.hpp"
#include "uh/museum_players/vive_view.hpp"

namespace uh::museum_players {

using museum_client::GameLink;
using museum_client::LinkNote;
using museum_protocol::GameEvent;
using museum_protocol::InHand;
using museum_protocol::Snapshot;
using museum_protocol::Summary;
using museum_protocol::Welcome;

Result<std::unique_ptr<GameLink>> join_as_bot(const std::string& url, const std::string& role) {
  return GameLink::connect({.url = url, .role = role, .reconnect = false});
}

std::optional<LinkNote> next_message(GameLink& link) {
  LinkNote note;
  for (;;) {
    if (!link.wait(note, 1.0)) continue;
    if (note.kind == LinkNote::Kind::dropped) return std::nullopt;
    if (note.kind == LinkNote::Kind::message) return note;
  }
}

namespace {

// The shipped level the welcome describes (the bots know the museum and its guards' rounds, as a
// player who has watched them does); the round's time as the server says.
Result<museum::Level> level_of(const Welcome& welcome) {
  museum::Level level = museum::make_level(welcome.level.difficulty);
  if (welcome.level.cases.size() != level.cases.size() || welcome.level.rooms.size() != level.rooms.size() ||
      welcome.level.name != level.name)
    return Error{
        fmt::format("the server plays level '{}', which is not a shipped one; the bots know only "
                    "the shipped museum",
                    welcome.level.name)};
  level.rules.round_s = welcome.level.rules.round_s;
  return level;
}

}  // namespace

Status play_vive(const std::string& url) {
  auto joined = join_as_bot(url, "vive");
  if (!joined) return joined.error();
  GameLink& link = **joined;
  const Welcome& welcome = link.welcome();
  auto level = level_of(welcome);
  if (!level) return level.error();
  museum::SightedBot bot(*level);
  ViveView view(*level);
  museum::ViveInput sent{};
  for (;;) {
    const auto note = next_message(link);
    if (!note || std::holds_alternative<Summary>(note->message)) return Ok{};
    if (const auto* e = std::get_if<GameEvent>(&note->message);
        e && e->event.type == museum::EventType::guard_heard)
      view.heard(e->event);
    const auto* snapshot = std::get_if<Snapshot>(&note->message);
    if (snapshot == nullptr) continue;
    const museum::GameState& s = view.update(*snapshot, welcome.targets);
    if (s.phase == museum::Phase::ended) continue;
    if (s.paused) continue;
    const museum::ViveInput in = bot.decide(s);
    if (museum::distance(in.move, sent.move) > 1e-3 || in.run != sent.run) {
      link.send(museum_protocol::write_message(museum_protocol::MoveMessage{in.move, in.run}));
      sent = in;
    }
    using museum_protocol::Action;
    for (const auto& [wanted, action] : {std::pair{in.break_case, Action::break_case},
                                         {in.take, Action::take},
                                         {in.deliver, Action::deliver}})
      if (wanted) link.send(museum_protocol::write_message(museum_protocol::ActionMessage{action}));
  }
}

Status play_phantom(const PhantomBotOptions& options) {
  // first a look at the round as a watcher: which targets to study
  Welcome welcome;
  {
    auto watcher = join_as_bot(options.url, "watcher");
    if (!watcher) return watcher.error();
    welcome = (*watcher)->welcome();
  }
  const museum::Difficulty difficulty = welcome.level.difficulty;
  const std::filesystem::path cache =
      options.cache_dir.empty() ? controllers::default_cache_dir() : options.cache_dir;
  core::SplitMix64 deal{options.seed * 0x9E3779B97F4A7C15ull + 17};  // the bot's deal
  std::map<std::string, Reference> references;
  const auto study = [&](museum_artifacts::ArtifactKind kind) -> Status {
    const std::string name = museum_artifacts::to_string(kind);
    if (references.contains(name)) return Ok{};
    auto reference = study_reference(kind, difficulty, SurveyOptions{}, cache, deal);
    if (!reference) return reference.error();
    references.emplace(name, std::move(*reference));
    return Ok{};
  };
  // Phantom studies the genuine pieces of Falcon's targets before taking its seat: the round
  // starts when it says hello as Phantom (the game clock does not run meanwhile)
  for (const std::string& target : welcome.targets)
    if (const auto kind = museum_artifacts::artifact_kind(target))
      if (const Status studied = study(*kind); !studied) return studied;
  auto joined = join_as_bot(options.url, "phantom");
  if (!joined) return joined.error();
  GameLink& link = **joined;
  if (options.seated) options.seated();
  for (;;) {
    const auto note = next_message(link);
    if (!note || std::holds_alternative<Summary>(note->message)) return Ok{};
    const auto* in_hands = std::get_if<InHand>(&note->message);
    if (in_hands == nullptr || in_hands->item < 0) continue;
    // the piece under the device: the form the server sent, built as the station builds it; the
    // verdict reads only the trace of exploring it
    const auto kind = museum_artifacts::check_form(in_hands->form);
    if (!kind)
      return Error{
          fmt::format("the server handed Phantom a piece it cannot build: {}", kind.error().message)};
    if (const Status studied = study(*kind); !studied) return studied;
    const Placement at = place_on_table(*kind, deal);
    SurveyOptions survey_options;
    survey_options.seed = deal.next();
    auto survey = survey_form(in_hands->form, at, survey_options, cache);
    if (!survey) return survey.error();
    const Reference& reference = references.at(in_hands->form.kind);
    BlindVerdict v{.item = in_hands->item,
                   .kind = in_hands->kind,
                   .judgement = judge_piece(*survey, reference.first, reference.again),
                   .simulated_s = survey->simulated_s};
    link.send(museum_protocol::write_message(museum_protocol::VerdictMessage{
        v.item,
        v.judgement.verdict == Verdict::genuine ? museum::Verdict::genuine : museum::Verdict::forgery}));
    if (options.judged) options.judged(v);
  }
}

}  // namespace uh::museum_players
