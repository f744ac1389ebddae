#include "uh/audio/audio_scene.hpp"

#include <AL/al.h>
#include <AL/alc.h>
#include <AL/alext.h>

#include <algorithm>
#include <cassert>
#include <optional>
#include <string>
#include <vector>

#include "uh/core/slot_table.hpp"

namespace uh::audio {
namespace {

// enough for every guard, the contact loop, speech and overlapping earcons
constexpr std::uint32_t kMaxVoices = 64;

}  // namespace

const char* to_string(Channel channel) {
  switch (channel) {
    case Channel::speech:
      return "speech";
    case Channel::earcons:
      return "earcons";
    case Channel::guards:
      return "guards";
    case Channel::contact:
      return "contact";
    case Channel::ambience:
      return "ambience";
  }
  return "unknown";
}

struct AudioScene::Impl {
  // a voice's slot keeps its OpenAL source when the voice ends, for the next voice in that slot
  struct Voice {
    ALuint source = 0;
    Channel channel = Channel::earcons;
    double gain = 1.0;
  };

  AudioSceneDef def{};
  ALCdevice* device = nullptr;
  ALCcontext* context = nullptr;
  LPALCRENDERSAMPLESSOFT render_samples = nullptr;
  bool hrtf = false;
  int rate_hz = 0;
  std::vector<ALuint> buffers{};
  core::SlotTable<Voice> voices{kMaxVoices};
  double volumes[kChannelCount] = {1.0, 1.0, 1.0, 1.0, 1.0};
  double duck = 1.0;

  ~Impl() {
    if (context != nullptr) {
      alcMakeContextCurrent(context);
      for (std::uint32_t i = 0; i < voices.slots_used(); ++i) {
        alSourceStop(voices.item(i).source);
        alDeleteSources(1, &voices.item(i).source);
      }
      if (!buffers.empty()) alDeleteBuffers(static_cast<ALsizei>(buffers.size()), buffers.data());
      alcMakeContextCurrent(nullptr);
      alcDestroyContext(context);
    }
    if (device != nullptr) alcCloseDevice(device);
  }

  // OpenAL's calls act on the current context, one per process: every entry point makes ours current
  void current() const { alcMakeContextCurrent(context); }

  Voice* find(VoiceId id) { return voices.find({id.index, id.generation}); }

  // frees the slots of the voices whose clip ended
  void release_ended() {
    voices.for_each_live([this](core::SlotId id, const Voice& v) {
      if (!is_playing(v)) voices.release(id);
    });
  }

  void apply_gains() {
    voices.for_each_live([this](core::SlotId, const Voice& v) { apply_gain(v); });
  }

  bool is_playing(const Voice& v) const {
    ALint state = AL_STOPPED;
    alGetSourcei(v.source, AL_SOURCE_STATE, &state);
    return state == AL_PLAYING;
  }

  void apply_gain(const Voice& v) const {
    const double ducked = v.channel == Channel::speech ? 1.0 : duck;
    alSourcef(v.source, AL_GAIN,
              static_cast<ALfloat>(std::max(0.0, v.gain * volumes[static_cast<int>(v.channel)] * ducked)));
  }
};

Result<AudioScene> AudioScene::create(const AudioSceneDef& def) {
  if (!(def.duck_gain >= 0.0 && def.duck_gain <= 1.0) || !(def.duck_ramp_s >= 0.0)) {
    return Error{"audio: duck_gain must be within 0..1 and duck_ramp_s >= 0"};
  }
  auto impl = std::make_unique<Impl>();
  impl->def = def;
  const ALCint hrtf_request = def.hrtf ? ALC_TRUE : ALC_FALSE;
  if (def.loopback) {
    if (def.sample_rate_hz < 8000 || def.sample_rate_hz > 192000) {
      return Error{"audio: sample_rate_hz = " + std::to_string(def.sample_rate_hz) +
                   " is out of range (8000..192000)"};
    }
    if (alcIsExtensionPresent(nullptr, "ALC_SOFT_loopback") != ALC_TRUE) {
      return Error{
          "audio: this OpenAL has no loopback device (ALC_SOFT_loopback; Debian's libopenal1 has it)"};
    }
    auto open_loopback = reinterpret_cast<LPALCLOOPBACKOPENDEVICESOFT>(
        alcGetProcAddress(nullptr, "alcLoopbackOpenDeviceSOFT"));
    impl->render_samples =
        reinterpret_cast<LPALCRENDERSAMPLESSOFT>(alcGetProcAddress(nullptr, "alcRenderSamplesSOFT"));
    if (open_loopback == nullptr || impl->render_samples == nullptr) {
      return Error{"audio: OpenAL's loopback functions are missing"};
    }
    impl->device = open_loopback(nullptr);
    if (impl->device == nullptr) return Error{"audio: cannot open OpenAL's loopback device"};
    const ALCint attributes[] = {ALC_FORMAT_CHANNELS_SOFT,
                                 ALC_STEREO_SOFT,
                                 ALC_FORMAT_TYPE_SOFT,
                                 ALC_FLOAT_SOFT,
                                 ALC_FREQUENCY,
                                 def.sample_rate_hz,
                                 ALC_HRTF_SOFT,
                                 hrtf_request,
                                 0};
    impl->context = alcCreateContext(impl->device, attributes);
  } else {
    impl->device = alcOpenDevice(nullptr);
    if (impl->device == nullptr) return Error{"audio: no sound card (OpenAL found no output device)"};
    const ALCint attributes[] = {ALC_HRTF_SOFT, hrtf_request, 0};
    impl->context = alcCreateContext(impl->device, attributes);
  }
  if (impl->context == nullptr)
    return Error{"audio: OpenAL refused the output format (stereo, float samples)"};
  impl->current();
  ALCint hrtf = ALC_FALSE;
  alcGetIntegerv(impl->device, ALC_HRTF_SOFT, 1, &hrtf);
  impl->hrtf = hrtf == ALC_TRUE;
  ALCint rate = 0;
  alcGetIntegerv(impl->device, ALC_FREQUENCY, 1, &rate);
  impl->rate_hz = rate;
  // the guards' steps fade with distance: full within 2 m, half at 4 m
  alDistanceModel(AL_INVERSE_DISTANCE_CLAMPED);
  return AudioScene(std::move(impl));
}

AudioScene::AudioScene(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
AudioScene::AudioScene(AudioScene&&) noexcept = default;
AudioScene& AudioScene::operator=(AudioScene&&) noexcept = default;
AudioScene::~AudioScene() = default;

bool AudioScene::hrtf_enabled() const { return impl_->hrtf; }
int AudioScene::sample_rate_hz() const { return impl_->rate_hz; }

Result<SoundId> AudioScene::load(const Sound& sound) {
  if (sound.samples.empty() || sound.sample_rate_hz <= 0)
    return Error{"audio: an empty sound cannot be loaded"};
  impl_->current();
  alGetError();
  ALuint buffer = 0;
  alGenBuffers(1, &buffer);
  alBufferData(buffer, AL_FORMAT_MONO_FLOAT32, sound.samples.data(),
               static_cast<ALsizei>(sound.samples.size() * sizeof(float)), sound.sample_rate_hz);
  if (const ALenum error = alGetError(); error != AL_NO_ERROR) {
    alDeleteBuffers(1, &buffer);
    return Error{"audio: OpenAL refused a sound of " + std::to_string(sound.samples.size()) +
                 " samples (error " + std::to_string(error) + ")"};
  }
  impl_->buffers.push_back(buffer);
  return SoundId{static_cast<std::uint32_t>(impl_->buffers.size() - 1)};
}

Result<VoiceId> AudioScene::play(SoundId sound, const VoiceDef& def) {
  if (sound.index >= impl_->buffers.size())
    return Error{"audio: no sound " + std::to_string(sound.index) + " was loaded"};
  impl_->current();
  // reuse a voice whose clip ended, else open a new one
  impl_->release_ended();
  const std::optional<core::SlotId> id = impl_->voices.occupy();
  if (!id) return Error{"audio: all " + std::to_string(kMaxVoices) + " voices are playing"};
  Impl::Voice& v = impl_->voices.item(id->index);
  if (v.source == 0) {
    alGetError();
    alGenSources(1, &v.source);
    if (alGetError() != AL_NO_ERROR) {
      v.source = 0;
      impl_->voices.release(*id);
      return Error{"audio: OpenAL has no source left"};
    }
  }
  alSourceStop(v.source);
  v.channel = def.channel;
  v.gain = def.gain;
  alSourcei(v.source, AL_BUFFER, static_cast<ALint>(impl_->buffers[sound.index]));
  alSourcei(v.source, AL_SOURCE_RELATIVE, def.relative ? AL_TRUE : AL_FALSE);
  alSourcei(v.source, AL_LOOPING, def.loop ? AL_TRUE : AL_FALSE);
  alSource3f(v.source, AL_POSITION, static_cast<ALfloat>(def.position.x),
             static_cast<ALfloat>(def.position.y), static_cast<ALfloat>(def.position.z));
  alSourcef(v.source, AL_REFERENCE_DISTANCE, 2.0f);
  alSourcef(v.source, AL_PITCH, static_cast<ALfloat>(std::clamp(def.pitch, 0.25, 4.0)));
  impl_->apply_gain(v);
  alSourcePlay(v.source);
  return VoiceId{id->index, id->generation};
}

void AudioScene::set_position(VoiceId voice, Vec3 p) {
  impl_->current();
  if (Impl::Voice* v = impl_->find(voice)) {
    alSource3f(v->source, AL_POSITION, static_cast<ALfloat>(p.x), static_cast<ALfloat>(p.y),
               static_cast<ALfloat>(p.z));
  }
}

void AudioScene::set_gain(VoiceId voice, double gain) {
  impl_->current();
  if (Impl::Voice* v = impl_->find(voice)) {
    v->gain = gain;
    impl_->apply_gain(*v);
  }
}

void AudioScene::set_pitch(VoiceId voice, double pitch) {
  impl_->current();
  if (Impl::Voice* v = impl_->find(voice))
    alSourcef(v->source, AL_PITCH, static_cast<ALfloat>(std::clamp(pitch, 0.25, 4.0)));
}

void AudioScene::stop(VoiceId voice) {
  impl_->current();
  if (Impl::Voice* v = impl_->find(voice)) {
    alSourceStop(v->source);
    impl_->voices.release({voice.index, voice.generation});
  }
}

bool AudioScene::playing(VoiceId voice) const {
  impl_->current();
  const Impl::Voice* v = impl_->find(voice);
  return v != nullptr && impl_->is_playing(*v);
}

void AudioScene::set_listener(Vec3 position, Vec3 forward, Vec3 up) {
  impl_->current();
  alListener3f(AL_POSITION, static_cast<ALfloat>(position.x), static_cast<ALfloat>(position.y),
               static_cast<ALfloat>(position.z));
  const ALfloat orientation[] = {static_cast<ALfloat>(forward.x), static_cast<ALfloat>(forward.y),
                                 static_cast<ALfloat>(forward.z), static_cast<ALfloat>(up.x),
                                 static_cast<ALfloat>(up.y),      static_cast<ALfloat>(up.z)};
  alListenerfv(AL_ORIENTATION, orientation);
}

void AudioScene::set_volume(Channel channel, double volume) {
  impl_->volumes[static_cast<int>(channel)] = std::clamp(volume, 0.0, 1.0);
  impl_->current();
  impl_->apply_gains();
}

double AudioScene::volume(Channel channel) const { return impl_->volumes[static_cast<int>(channel)]; }

double AudioScene::duck_factor() const { return impl_->duck; }

void AudioScene::update(double dt_s) {
  impl_->current();
  impl_->release_ended();
  bool speaking = false;
  impl_->voices.for_each_live(
      [&speaking](core::SlotId, const Impl::Voice& v) { speaking = speaking || v.channel == Channel::speech; });
  // a linear ramp between 1 and duck_gain over duck_ramp_s, both ways
  const double target = speaking ? impl_->def.duck_gain : 1.0;
  const double span = 1.0 - impl_->def.duck_gain;
  const double step =
      impl_->def.duck_ramp_s > 0.0 ? span * std::max(0.0, dt_s) / impl_->def.duck_ramp_s : span;
  if (impl_->duck > target)
    impl_->duck = std::max(target, impl_->duck - step);
  else
    impl_->duck = std::min(target, impl_->duck + step);
  impl_->apply_gains();
}

void AudioScene::render(std::span<float> interleaved_stereo) {
  assert(impl_->render_samples != nullptr &&
         "uh::audio::AudioScene::render(): the scene was not created with loopback = true");
  assert(interleaved_stereo.size() % 2 == 0 &&
         "uh::audio::AudioScene::render(): stereo frames come in pairs");
  if (impl_->render_samples == nullptr) return;
  impl_->current();
  impl_->render_samples(impl_->device, interleaved_stereo.data(),
                        static_cast<ALCsizei>(interleaved_stereo.size() / 2));
}

}  // namespace uh::audio
