#pragma once
/// \file
/// AudioScene: what the blind player hears, on OpenAL Soft: clips placed around a listener with
/// HRTF (head-related transfer functions, Debian's libopenal-data), channels with their own
/// volume, and every other channel lowered while speech plays (ducking).
///
/// Two outputs: the sound card (the station), or a loopback device that renders into memory on
/// demand (render()), so that the tests listen offline and deterministically. One AudioScene per
/// thread that drives it; its calls are not real-time safe (OpenAL takes locks).

#include <cstdint>
#include <memory>
#include <span>

#include "uh/audio/sound.hpp"
#include "uh/core/math.hpp"
#include "uh/core/result.hpp"

namespace uh::audio {

/// The mixer's channels, each with its own volume. Speech ducks all the others.
enum class Channel : std::uint8_t { speech, earcons, guards, contact, ambience };
inline constexpr int kChannelCount = 5;
const char* to_string(Channel channel);

struct AudioSceneDef {
  bool loopback = false;       ///< render into memory with render() instead of playing
  int sample_rate_hz = 48000;  ///< of the loopback render (the sound card picks its own)
  bool hrtf = true;            ///< binaural rendering for headphones (falls back to panning)
  double duck_gain = 0.3;      ///< the other channels' gain while speech plays (0.3: -10.5 dB)
  double duck_ramp_s = 0.15;   ///< how long ducking takes to come in and to go
};

/// A clip loaded into the scene.
struct SoundId {
  std::uint32_t index = 0;
};

/// A playing clip; it stays valid until it ends (or is stopped), then calls on it do nothing.
struct VoiceId {
  std::uint32_t index = 0;
  std::uint32_t generation = 0;
};

struct VoiceDef {
  Channel channel = Channel::earcons;
  Vec3 position{};       ///< [m]; in the listener's frame when relative, else in the world's
  bool relative = true;  ///< position relative to the listener (0,0,0: inside the head)
  bool loop = false;
  double gain = 1.0;   ///< the voice's own gain, before its channel's volume and ducking
  double pitch = 1.0;  ///< playback speed (1: as recorded)
};

class AudioScene {
 public:
  /// Opens the output (a loopback device or the default sound card) and a context on it.
  /// Fails with the reason (no sound card, OpenAL Soft without loopback support).
  static Result<AudioScene> create(const AudioSceneDef& def = {});

  AudioScene(AudioScene&&) noexcept;
  AudioScene& operator=(AudioScene&&) noexcept;
  ~AudioScene();

  /// True when HRTF rendering was asked for and OpenAL Soft enabled it.
  bool hrtf_enabled() const;
  int sample_rate_hz() const;

  Result<SoundId> load(const Sound& sound);
  /// Starts the clip; fails when the id is not a loaded clip or OpenAL has no source left.
  Result<VoiceId> play(SoundId sound, const VoiceDef& def);
  /// Moves a playing voice or changes its gain and pitch (a stale id is ignored).
  void set_position(VoiceId voice, Vec3 position);
  void set_gain(VoiceId voice, double gain);
  void set_pitch(VoiceId voice, double pitch);
  void stop(VoiceId voice);
  bool playing(VoiceId voice) const;

  /// The listener in the world: position [m], facing and up (unit vectors; OpenAL's frame is
  /// right-handed: with forward -z and up +y, +x is to the right).
  void set_listener(Vec3 position, Vec3 forward, Vec3 up);
  void set_volume(Channel channel, double volume);
  double volume(Channel channel) const;
  /// The gain ducking applies to the non-speech channels now (1: not ducked).
  double duck_factor() const;

  /// Advances ducking by dt seconds and applies every voice's gain; call it once per frame of the
  /// station's loop (the tests call it between renders).
  void update(double dt_s);

  /// Loopback scenes only: renders the next frames into interleaved stereo (left, right, ...).
  void render(std::span<float> interleaved_stereo);

 private:
  struct Impl;
  explicit AudioScene(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace uh::audio
