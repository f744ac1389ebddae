#include "uh/museum_station/station_sound.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <fmt/format.h>

namespace uh::museum_station {
namespace {

// equal-tempered note names used by the melodies [Hz]
constexpr double kC4 = 261.63, kE4 = 329.63, kG4 = 392.00, kA4 = 440.00, kC5 = 523.25, kE5 = 659.25,
                 kG5 = 783.99, kC6 = 1046.50, kE6 = 1318.51, kG3 = 196.00, kC3 = 130.81, kBb3 = 233.08,
                 kF4 = 349.23, kD5 = 587.33;

}  // namespace

std::vector<audio::Note> earcon_notes(int index) {
  using museum::Earcon;
  if (index == kVerdictSentEarcon) return {{kG4, 0.07, 0.4}, {kG4, 0.07, 0.4}};  // two taps: sent
  switch (static_cast<Earcon>(index)) {
    case Earcon::glass:  // high, falling, fast: shards
      return {{kE6, 0.05, 0.4}, {kC6, 0.05, 0.4}, {kG5, 0.05, 0.35}, {kE5, 0.08, 0.3}};
    case Earcon::empty:  // a hollow fall
      return {{kC4, 0.12, 0.45}, {kG3, 0.2, 0.45}};
    case Earcon::pickup:  // a rising third
      return {{kC5, 0.08, 0.45}, {kE5, 0.12, 0.45}};
    case Earcon::delivery:  // a rising arpeggio: something for you
      return {{kC4, 0.08, 0.5}, {kE4, 0.08, 0.5}, {kG4, 0.08, 0.5}, {kC5, 0.16, 0.5}};
    case Earcon::alert:  // two high alternating notes: attention
      return {{kA4 * 2.0, 0.08, 0.5}, {kF4 * 2.0, 0.08, 0.5}, {kA4 * 2.0, 0.08, 0.5}};
    case Earcon::caught:  // low and falling
      return {{kC4, 0.12, 0.6}, {kBb3, 0.12, 0.6}, {kC3, 0.3, 0.6}};
    case Earcon::right:  // a major third up, held
      return {{kE5, 0.08, 0.45}, {kG5, 0.2, 0.45}};
    case Earcon::wrong:  // a flat buzz down
      return {{kE4, 0.1, 0.45}, {kC4 * 0.9, 0.25, 0.45}};
    case Earcon::clock:  // ticks
      return {{kD5 * 2.0, 0.03, 0.5},
              {0.0, 0.12, 0.0},
              {kD5 * 2.0, 0.03, 0.5},
              {0.0, 0.12, 0.0},
              {kD5 * 2.0, 0.03, 0.5}};
    case Earcon::finale:  // a cadence
      return {{kG4, 0.12, 0.5}, {kC5, 0.12, 0.5}, {kE5, 0.12, 0.5}, {kC6, 0.2, 0.5}};
  }
  return {{kA4, 0.1, 0.4}};
}

Vec3 floor_to_audio(museum::Vec2 p) { return {p.x, 0.0, -p.y}; }

StationSound::StationSound(audio::AudioScene scene, const StationSoundOptions& options)
    : scene_(std::move(scene)), options_(options) {}

Result<StationSound> StationSound::create(const StationSoundOptions& options) {
  auto scene = audio::AudioScene::create(options.scene);
  if (!scene) return scene.error();
  StationSound s(std::move(*scene), options);
  const int rate = s.scene_.sample_rate_hz();
  for (int e = 0; e < kStationEarconCount; ++e) {
    const std::vector<audio::Note> notes = earcon_notes(e);
    auto id = s.scene_.load(audio::synthesize_notes(notes, rate));
    if (!id) return id.error();
    s.earcons_.push_back(*id);
  }
  // a guard's steps: two short bursts of noise and a pause, looped (broadband, as steps are: a low
  // thud alone would hardly be heard left or right, the head shadows only the higher frequencies)
  audio::Sound steps = audio::synthesize_contact_loop({.roughness = 0.5, .seconds = 0.8, .seed = 11}, rate);
  for (std::size_t i = 0; i < steps.samples.size(); ++i) {
    const double t = std::fmod(static_cast<double>(i) / rate, 0.4);  // a step every 0.4 s
    const double envelope = t < 0.005 ? t / 0.005 : std::exp(-(t - 0.005) / 0.02);
    steps.samples[i] = static_cast<float>(static_cast<double>(steps.samples[i]) * envelope);
  }
  auto footsteps = s.scene_.load(steps);
  if (!footsteps) return footsteps.error();
  s.footsteps_ = *footsteps;
  s.set_material({});
  return s;
}

void StationSound::earcon(int index) {
  assert(index >= 0 && index < kStationEarconCount);
  (void)scene_.play(earcons_[static_cast<std::size_t>(index)], {.channel = audio::Channel::earcons});
}

bool StationSound::speaking() const {
  return !queue_.empty() || (speech_voice_ && scene_.playing(*speech_voice_));
}

Status StationSound::speak_now(const std::string& text) {
  auto speech = audio::synthesize_speech(text, options_.speech);
  if (!speech) return speech.error();
  auto id = scene_.load(*speech);
  if (!id) return id.error();
  auto voice = scene_.play(*id, {.channel = audio::Channel::speech});
  if (!voice) return voice.error();
  speech_voice_ = *voice;
  last_line_ = text;
  return Ok{};
}

Status StationSound::say(const std::string& text, bool urgent) {
  if (urgent) {
    queue_.clear();
    if (speech_voice_) scene_.stop(*speech_voice_);
    return speak_now(text);
  }
  if (!speech_voice_ || !scene_.playing(*speech_voice_)) return speak_now(text);
  queue_.push_back(text);
  return Ok{};
}

void StationSound::set_guards(museum::Vec2 vive_pos, museum::Vec2 vive_facing,
                              const std::vector<museum::Vec2>& guards) {
  const museum::Vec2 f =
      museum::norm(vive_facing) > 0.0 ? museum::normalized(vive_facing) : museum::Vec2{0.0, 1.0};
  scene_.set_listener(floor_to_audio(vive_pos), floor_to_audio(f), {0.0, 1.0, 0.0});
  while (guard_voices_.size() > guards.size()) {
    scene_.stop(guard_voices_.back());
    guard_voices_.pop_back();
  }
  for (std::size_t g = 0; g < guards.size(); ++g) {
    if (g == guard_voices_.size()) {
      auto voice = scene_.play(footsteps_, {.channel = audio::Channel::guards,
                                            .position = floor_to_audio(guards[g]),
                                            .relative = false,
                                            .loop = true,
                                            .pitch = 1.0 + 0.07 * static_cast<double>(g)});
      if (!voice) return;
      guard_voices_.push_back(*voice);
    } else {
      scene_.set_position(guard_voices_[g], floor_to_audio(guards[g]));
    }
  }
}

void StationSound::set_material(const forcecomp::Material& material) {
  // rougher, grippier surfaces hiss brighter
  double roughness = material.has_friction ? std::clamp(material.friction_dynamic / 0.5, 0.0, 1.0) : 0.3;
  if (material.texture.kind != forcecomp::TextureKind::kNone) roughness = std::min(1.0, roughness + 0.3);
  if (contact_voice_) scene_.stop(*contact_voice_);
  contact_voice_.reset();
  auto sound = scene_.load(audio::synthesize_contact_loop({.roughness = roughness}, scene_.sample_rate_hz()));
  if (!sound) return;
  contact_sound_ = *sound;
  auto voice = scene_.play(*contact_sound_, {.channel = audio::Channel::contact, .loop = true, .gain = 0.0});
  if (voice) contact_voice_ = *voice;
}

void StationSound::set_contact(bool touching, double speed_m_per_s) {
  if (!contact_voice_) return;
  const double s = std::clamp(speed_m_per_s / options_.full_contact_speed_m_per_s, 0.0, 1.0);
  scene_.set_gain(*contact_voice_, touching ? s : 0.0);
  scene_.set_pitch(*contact_voice_, 0.7 + 0.8 * s);
}

void StationSound::set_volume(audio::Channel channel, double volume) {
  scene_.set_volume(channel, std::clamp(volume, 0.0, 1.0));
}

double StationSound::volume(audio::Channel channel) const { return scene_.volume(channel); }

void StationSound::update(double dt_s) {
  if (!queue_.empty() && (!speech_voice_ || !scene_.playing(*speech_voice_))) {
    const std::string next = std::move(queue_.front());
    queue_.pop_front();
    (void)speak_now(next);
  }
  scene_.update(dt_s);
}

}  // namespace uh::museum_station
