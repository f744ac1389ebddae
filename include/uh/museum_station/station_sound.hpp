#pragma once
/// \file
/// StationSound: everything Phantom hears, on uh::audio (docs/audio.md): an earcon (a short melody)
/// per museum::Earcon and for a verdict given; Falcon's lines, the events and the timer spoken by
/// espeak-ng (queued, or at once when urgent; the other channels duck under them); the guards as
/// footsteps placed around Vive (HRTF: a guard to her left is heard on the left); the stylus on the
/// artifact as the material's contact noise, louder and higher the faster it slides.
///
/// The station's own (non-real-time) thread drives it: a call per event and update() per frame.

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "uh/audio/audio_scene.hpp"
#include "uh/audio/speech.hpp"
#include "uh/core/result.hpp"
#include "uh/forcecomp/material.hpp"
#include "uh/museum/cues.hpp"
#include "uh/museum/level.hpp"

namespace uh::museum_station {

/// The station's earcons: one per museum::Earcon, and one that says a verdict was sent.
inline constexpr int kStationEarconCount = museum::kEarconCount + 1;
inline constexpr int kVerdictSentEarcon = museum::kEarconCount;

/// The notes of earcon `index` (0..kStationEarconCount-1): a melody short enough (under 0.6 s) to
/// come before any word, told apart by contour and register.
std::vector<audio::Note> earcon_notes(int index);

/// Where a point of the floor sounds in OpenAL's frame (x east, y up, -z north) [m].
Vec3 floor_to_audio(museum::Vec2 p);

struct StationSoundOptions {
  audio::AudioSceneDef scene{};
  audio::SpeechDef speech{};
  /// The stylus speed at which the contact sound is at full loudness [m/s].
  double full_contact_speed_m_per_s = 0.08;
};

class StationSound {
 public:
  /// Opens the output (fails with the reason when there is no sound card) and makes the earcons,
  /// the guards' footsteps and a contact loop.
  static Result<StationSound> create(const StationSoundOptions& options = {});

  /// Plays earcon `index` (0..kStationEarconCount-1).
  void earcon(int index);
  /// Speaks `text`: urgent lines interrupt the one speaking and skip the queue; others wait their
  /// turn. An error says why espeak-ng could not speak (the line is then dropped).
  Status say(const std::string& text, bool urgent = false);
  /// The line spoken last (for "repeat").
  const std::string& last_line() const { return last_line_; }
  /// Whether a line is speaking or waiting.
  bool speaking() const;

  /// The listener is Vive (at `pos`, facing `facing` on the floor); a footstep loop per guard.
  void set_guards(museum::Vec2 vive_pos, museum::Vec2 vive_facing, const std::vector<museum::Vec2>& guards);
  /// The contact sound of a material (its roughness from the friction and texture).
  void set_material(const forcecomp::Material& material);
  /// Whether the stylus touches the piece and how fast it moves [m/s].
  void set_contact(bool touching, double speed_m_per_s);

  void set_volume(audio::Channel channel, double volume);
  double volume(audio::Channel channel) const;

  /// Starts the next queued line when the last one ended, and advances the ducking. Per frame.
  void update(double dt_s);

  audio::AudioScene& scene() { return scene_; }

 private:
  explicit StationSound(audio::AudioScene scene, const StationSoundOptions& options);
  Status speak_now(const std::string& text);

  audio::AudioScene scene_;
  StationSoundOptions options_;
  std::vector<audio::SoundId> earcons_;
  audio::SoundId footsteps_{};
  std::vector<audio::VoiceId> guard_voices_;
  std::optional<audio::SoundId> contact_sound_;
  std::optional<audio::VoiceId> contact_voice_;
  std::optional<audio::VoiceId> speech_voice_;
  std::deque<std::string> queue_;
  std::string last_line_;
};

}  // namespace uh::museum_station
