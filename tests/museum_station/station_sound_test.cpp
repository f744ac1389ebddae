// Phantom's station as heard: StationSound and the station's cues rendered offline through OpenAL
// Soft's loopback device (no sound card), measured in the mix itself.

#include "uh/museum_station/station_sound.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "uh/museum/cues.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum_station/station.hpp"

namespace uh::museum_station {
namespace {

constexpr int kRate = 48000;

StationSound loopback_sound(bool hrtf = true) {
  auto sound = StationSound::create({.scene = {.loopback = true, .sample_rate_hz = kRate, .hrtf = hrtf}});
  EXPECT_TRUE(sound) << (sound ? "" : sound.error().message);
  return std::move(sound).value();
}

struct Levels {
  double left = 0.0;
  double right = 0.0;
};

// advances the station's frame clock and renders `seconds` of the mix in 10 ms frames
Levels listen(StationSound& sound, double seconds) {
  const int frames = std::max(1, static_cast<int>(std::lround(seconds / 0.01)));
  std::vector<float> out(2 * kRate / 100);
  double l = 0.0, r = 0.0;
  for (int f = 0; f < frames; ++f) {
    sound.update(0.01);
    sound.scene().render(out);
    for (std::size_t i = 0; i < out.size(); i += 2) {
      l += static_cast<double>(out[i]) * static_cast<double>(out[i]);
      r += static_cast<double>(out[i + 1]) * static_cast<double>(out[i + 1]);
    }
  }
  const double n = static_cast<double>(frames) * static_cast<double>(out.size() / 2);
  return {std::sqrt(l / n), std::sqrt(r / n)};
}

TEST(StationSound, SpeechIsNotSilent) {
  StationSound sound = loopback_sound();
  const Levels quiet = listen(sound, 0.1);
  ASSERT_TRUE(sound.say("Falcon here. Three targets tonight."));
  EXPECT_TRUE(sound.speaking());
  const Levels spoken = listen(sound, 1.0);
  EXPECT_GT(spoken.left, 0.01);
  EXPECT_GT(spoken.left, 10.0 * quiet.left + 1e-6);
  EXPECT_EQ(sound.last_line(), "Falcon here. Three targets tonight.");
}

TEST(StationSound, SpeechDucksTheGuardsAndTheyComeBack) {
  StationSound sound = loopback_sound(false);
  // speech muted on its channel: it still ducks, and the guards are then all the mix holds
  sound.set_volume(audio::Channel::speech, 0.0);
  sound.set_guards({0.0, 0.0}, {0.0, 1.0}, {{0.0, 1.0}});
  listen(sound, 0.3);
  const Levels before = listen(sound, 0.8);  // two whole periods of the footsteps
  ASSERT_GT(before.left, 1e-3);
  ASSERT_TRUE(sound.say("A guard heard something in the great hall and is going to look."));
  listen(sound, 0.3);  // the 0.15 s ramp has come in
  ASSERT_TRUE(sound.speaking());
  const Levels ducked = listen(sound, 0.8);
  ASSERT_TRUE(sound.speaking()) << "the line is longer than the measurement";
  EXPECT_NEAR(ducked.left / before.left, 0.3, 0.05);
  while (sound.speaking()) listen(sound, 0.1);
  listen(sound, 0.3);
  const Levels after = listen(sound, 0.8);
  EXPECT_NEAR(after.left / before.left, 1.0, 0.1);
}

TEST(StationSound, AGuardToVivesLeftIsLouderInTheLeftEar) {
  for (const bool hrtf : {true, false}) {
    SCOPED_TRACE(hrtf ? "HRTF" : "panning");
    StationSound sound = loopback_sound(hrtf);
    // Vive faces north: west is her left; then she faces east: north is her left
    sound.set_guards({5.0, 5.0}, {0.0, 1.0}, {{2.0, 5.0}});
    listen(sound, 0.3);
    Levels l = listen(sound, 0.8);
    EXPECT_GT(l.left, 1.4 * l.right) << l.left << " " << l.right;
    sound.set_guards({5.0, 5.0}, {1.0, 0.0}, {{5.0, 8.0}});
    listen(sound, 0.3);
    l = listen(sound, 0.8);
    EXPECT_GT(l.left, 1.4 * l.right) << l.left << " " << l.right;
    // and east of her, facing north, is her right
    sound.set_guards({5.0, 5.0}, {0.0, 1.0}, {{8.0, 5.0}});
    listen(sound, 0.3);
    l = listen(sound, 0.8);
    EXPECT_GT(l.right, 1.4 * l.left) << l.left << " " << l.right;
  }
}

TEST(StationSound, TheContactSoundFollowsTheStylusSpeed) {
  StationSound sound = loopback_sound(false);
  sound.set_material({.has_friction = true, .friction_static = 0.4, .friction_dynamic = 0.3});
  sound.set_contact(false, 0.1);
  listen(sound, 0.1);
  EXPECT_LT(listen(sound, 0.2).left, 1e-4) << "silent off the surface";
  sound.set_contact(true, 0.02);
  listen(sound, 0.1);
  const double slow = listen(sound, 0.3).left;
  sound.set_contact(true, 0.08);
  listen(sound, 0.1);
  const double fast = listen(sound, 0.3).left;
  EXPECT_GT(slow, 1e-3);
  EXPECT_GT(fast, 2.0 * slow);
}

// the earcons: every one a melody, no two alike, each under 0.6 s
TEST(StationSound, EveryEarconIsItsOwnShortMelody) {
  std::set<std::vector<double>> melodies;
  for (int e = 0; e < kStationEarconCount; ++e) {
    const std::vector<audio::Note> notes = earcon_notes(e);
    ASSERT_FALSE(notes.empty()) << e;
    double seconds = 0.0;
    std::vector<double> key;
    for (const audio::Note& n : notes) {
      seconds += n.seconds;
      key.push_back(n.frequency_hz);
      key.push_back(n.seconds);
    }
    EXPECT_LT(seconds, 0.6) << e;
    const audio::Sound s = audio::synthesize_notes(notes);
    EXPECT_GT(audio::rms(s.samples), 0.05) << e;
    melodies.insert(key);
  }
  EXPECT_EQ(static_cast<int>(melodies.size()), kStationEarconCount);
}

// every event type the server sends: the station plays an earcon, says a sentence and shows a caption
TEST(StationCues, EveryEventTypeHasAnEarconASpokenTextAndACaption) {
  Welcome welcome{
      .role = "phantom", .level = museum::make_level(museum::Difficulty::easy), .targets = {"bowl", "coin"}};
  auto station = Station::create(welcome, {}, loopback_sound(false), nullptr);
  ASSERT_TRUE(station) << station.error().message;
  StationSound& sound = *(*station)->sound();
  // speech muted on its channel (it still plays, in order, and still ducks): what is heard just
  // after an event is its earcon
  sound.set_volume(audio::Channel::speech, 0.0);
  Snapshot s;
  s.phase = "playing";
  s.cases = {{.item = {0, "bowl"}}, {.item = {1, "bowl"}}};
  s.carried = {{0, "bowl"}};
  (*station)->handle({.message = s});
  std::set<std::string> lines;
  for (int t = 0; t <= static_cast<int>(museum::EventType::round_ended); ++t) {
    const auto type = static_cast<museum::EventType>(t);
    SCOPED_TRACE(museum::to_string(type));
    const std::size_t captions = (*station)->captions().size();
    if (type == museum::EventType::round_ended) {
      // the points come with the summary
      (*station)->handle({.message = GameEvent{{.type = type}}});
      (*station)->handle({.message = Summary{.points = 140, .genuine_kept = 1}});
    } else {
      museum::Event e{.type = type,
                      .guard = 0,
                      .item = 0,
                      .case_index = 0,
                      .count = 1,
                      .pos = {3.0, 3.0},
                      .radius = 8.0,
                      .verdict = museum::Verdict::genuine};
      if (type == museum::EventType::time_warning) e.count = 30;
      (*station)->handle({.message = GameEvent{e}});
    }
    EXPECT_GT(listen(sound, 0.15).left, 0.005) << "no earcon";
    ASSERT_EQ((*station)->captions().size(), captions + 1);
    const std::string& caption = (*station)->captions().back();
    EXPECT_FALSE(caption.empty());
    EXPECT_EQ(caption.find("-1"), std::string::npos) << caption;
    // the sentence is spoken: let the queue play through and take the last line
    while (sound.speaking()) listen(sound, 0.2);
    EXPECT_FALSE(sound.last_line().empty());
    EXPECT_GT(sound.last_line().size(), caption.size()) << sound.last_line() << " / " << caption;
    lines.insert(sound.last_line());
  }
  EXPECT_EQ(static_cast<int>(lines.size()), static_cast<int>(museum::EventType::round_ended) + 1);
  EXPECT_NE((*station)->captions().back().find("140"), std::string::npos);
}

}  // namespace
}  // namespace uh::museum_station
