#pragma once
/// \file
/// Text to speech with espeak-ng (Debian's libespeak-ng1 and espeak-ng-data), rendered into a
/// Sound rather than to a sound card, so that speech plays in the AudioScene like any other clip
/// (ducking, volume, the offline render of the tests).

#include <string_view>

#include "uh/audio/sound.hpp"
#include "uh/core/result.hpp"

namespace uh::audio {

struct SpeechDef {
  const char* voice = "en";    ///< an espeak-ng voice name
  int words_per_minute = 175;  ///< espeak-ng's rate, 80..450
};

/// Speaks the text into a mono Sound at espeak-ng's own sample rate (22,050 Hz).
/// espeak-ng keeps process-wide state: calls from several threads take turns (a mutex); never
/// call it from a real-time thread. An error names what espeak-ng could not do (no voice data,
/// an unknown voice).
Result<Sound> synthesize_speech(std::string_view text, const SpeechDef& def = {});

}  // namespace uh::audio
