#pragma once
/// \file
/// Text to speech with the espeak-ng program (Debian's espeak-ng package; run as a process of its
/// own, never linked, because it is GPL-3: docs/licenses.md), rendered into a Sound rather than to
/// a sound card, so that speech plays in the AudioScene like any other clip
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
/// Runs the program once per call (and once for its list of voices): any thread but a real-time
/// one. An error names what went wrong (no espeak-ng program, an unknown voice).
Result<Sound> synthesize_speech(std::string_view text, const SpeechDef& def = {});

}  // namespace uh::audio
