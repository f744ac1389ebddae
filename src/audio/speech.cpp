#include "uh/audio/speech.hpp"

#include <espeak-ng/speak_lib.h>

#include <mutex>
#include <string>

namespace uh::audio {
namespace {

// espeak-ng keeps one synthesizer per process, set up once and never torn down (terminating and
// initialising it again is not supported by every version); the mutex lets threads take turns
std::mutex speech_mutex;
int speech_rate_hz = 0;  // espeak-ng's output rate once initialised; 0: not yet; < 0: failed
std::vector<float>* speech_target = nullptr;

int collect_samples(short* wave, int count, espeak_EVENT* /*events*/) {
  if (wave != nullptr && speech_target != nullptr) {
    for (int i = 0; i < count; ++i) speech_target->push_back(static_cast<float>(wave[i]) / 32768.0f);
  }
  return 0;  // continue
}

}  // namespace

Result<Sound> synthesize_speech(std::string_view text, const SpeechDef& def) {
  const std::lock_guard<std::mutex> lock(speech_mutex);
  if (speech_rate_hz == 0) {
    // synchronous: espeak-ng renders into our callback on this thread, no sound card involved
    speech_rate_hz = espeak_Initialize(AUDIO_OUTPUT_SYNCHRONOUS, 0, nullptr, espeakINITIALIZE_DONT_EXIT);
    if (speech_rate_hz <= 0)
      speech_rate_hz = -1;
    else
      espeak_SetSynthCallback(collect_samples);
  }
  if (speech_rate_hz < 0) {
    return Error{"speech: espeak-ng could not start (its voice data is in Debian's espeak-ng-data package)"};
  }
  if (espeak_SetVoiceByName(def.voice) != EE_OK) {
    return Error{std::string("speech: espeak-ng has no voice '") + def.voice +
                 "' (espeak-ng --voices lists them)"};
  }
  espeak_SetParameter(espeakRATE, def.words_per_minute, 0);

  Sound sound{.sample_rate_hz = speech_rate_hz};
  const std::string terminated(text);  // espeak-ng reads up to a NUL
  speech_target = &sound.samples;
  const espeak_ERROR synthesized = espeak_Synth(terminated.c_str(), terminated.size() + 1, 0, POS_CHARACTER,
                                                0, espeakCHARS_UTF8, nullptr, nullptr);
  const espeak_ERROR finished = espeak_Synchronize();
  speech_target = nullptr;
  if (synthesized != EE_OK || finished != EE_OK) {
    return Error{"speech: espeak-ng failed to speak \"" + terminated + "\""};
  }
  return sound;
}

}  // namespace uh::audio
