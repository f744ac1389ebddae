#include "uh/audio/sound.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "uh/core/split_mix.hpp"

namespace uh::audio {

Sound synthesize_notes(std::span<const Note> notes, int sample_rate_hz) {
  Sound sound{.sample_rate_hz = sample_rate_hz};
  const double rate = sample_rate_hz;
  // 5 ms ramps: short enough to keep a note's attack crisp, long enough not to click
  const double ramp_s = 0.005;
  for (const Note& note : notes) {
    const auto count = static_cast<std::size_t>(std::max(0.0, note.seconds) * rate);
    const std::size_t start = sound.samples.size();
    sound.samples.resize(start + count, 0.0f);
    if (note.frequency_hz <= 0.0) continue;
    for (std::size_t i = 0; i < count; ++i) {
      const double t = static_cast<double>(i) / rate;
      const double envelope = std::min({1.0, t / ramp_s, (note.seconds - t) / ramp_s});
      const double phase = 2.0 * std::numbers::pi * note.frequency_hz * t;
      // the overtones make a tone that stays recognisable through HRTF filtering and small speakers
      const double tone = 0.7 * std::sin(phase) + 0.2 * std::sin(2.0 * phase) + 0.1 * std::sin(3.0 * phase);
      sound.samples[start + i] = static_cast<float>(note.gain * std::max(0.0, envelope) * tone);
    }
  }
  return sound;
}

Sound synthesize_contact_loop(const ContactTimbre& timbre, int sample_rate_hz) {
  Sound sound{.sample_rate_hz = sample_rate_hz};
  const auto count = static_cast<std::size_t>(std::max(0.05, timbre.seconds) * sample_rate_hz);
  core::SplitMix64 random{timbre.seed};
  std::vector<float> noise(count);
  for (float& x : noise) x = static_cast<float>(random.normal());

  // a one-pole low-pass: polished surfaces are dull (cutoff ~300 Hz), grainy ones hiss (~6 kHz)
  const double roughness = std::clamp(timbre.roughness, 0.0, 1.0);
  const double cutoff_hz = 300.0 * std::pow(20.0, roughness);
  const double a = std::exp(-2.0 * std::numbers::pi * cutoff_hz / sample_rate_hz);
  // run the filter over the loop twice and keep the second pass: its state at the start is the
  // state at the end of the first, so the loop joins without a click
  double state = 0.0;
  sound.samples.resize(count);
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < count; ++i) {
      state = (1.0 - a) * static_cast<double>(noise[i]) + a * state;
      sound.samples[i] = static_cast<float>(state);
    }
  }
  // the same loudness for every timbre: the station's gain, not the filter, says how loud
  const double level = rms(sound.samples);
  if (level > 0.0) {
    for (float& x : sound.samples)
      x = static_cast<float>(std::clamp(static_cast<double>(x) * 0.25 / level, -1.0, 1.0));
  }
  return sound;
}

double rms(std::span<const float> samples) {
  if (samples.empty()) return 0.0;
  double sum = 0.0;
  for (const float x : samples) sum += static_cast<double>(x) * static_cast<double>(x);
  return std::sqrt(sum / static_cast<double>(samples.size()));
}

}  // namespace uh::audio
