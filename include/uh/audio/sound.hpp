#pragma once
/// \file
/// Sound: a mono clip as plain data, and the procedural sounds of the station (earcons, the
/// contact noise of a material). Speech comes from speech.hpp; all of them play in an AudioScene.

#include <span>
#include <vector>

namespace uh::audio {

/// A mono clip: samples in [-1, 1] at sample_rate_hz.
struct Sound {
  int sample_rate_hz = 48000;
  std::vector<float> samples{};

  double seconds() const {
    return sample_rate_hz > 0 ? static_cast<double>(samples.size()) / sample_rate_hz : 0.0;
  }
};

/// One tone of an earcon: a sine with its first two overtones, shaped by short attack and release
/// ramps (no clicks). A frequency of 0 is a rest.
struct Note {
  double frequency_hz = 440.0;
  double seconds = 0.1;
  double gain = 0.5;  ///< peak amplitude, 0..1
};

/// The notes one after the other, at sample_rate_hz.
Sound synthesize_notes(std::span<const Note> notes, int sample_rate_hz = 48000);

/// What a material's contact sounds like while the stylus slides on it: a loop of noise whose
/// brightness follows the surface. Played looping; the station sets its gain and pitch from the
/// stylus speed and the contact force.
struct ContactTimbre {
  double roughness = 0.5;  ///< 0 (polished: dull, low) .. 1 (grainy: bright, hissing)
  double seconds = 1.0;    ///< loop length
  unsigned seed = 1;       ///< the noise's seed (the same timbre is the same sound)
};

/// A seamless loop of the timbre's noise, at sample_rate_hz.
Sound synthesize_contact_loop(const ContactTimbre& timbre, int sample_rate_hz = 48000);

/// Root mean square of the samples (0 for none).
double rms(std::span<const float> samples);

}  // namespace uh::audio
