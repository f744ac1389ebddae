#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "uh/audio/sound.hpp"

namespace uh::audio {
namespace {

// the magnitude of one frequency in the samples (a single DFT bin, summed directly)
double magnitude_at(const Sound& s, double frequency_hz) {
  double re = 0.0;
  double im = 0.0;
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    const double phase = 2.0 * std::numbers::pi * frequency_hz * static_cast<double>(i) / s.sample_rate_hz;
    re += static_cast<double>(s.samples[i]) * std::cos(phase);
    im += static_cast<double>(s.samples[i]) * std::sin(phase);
  }
  return std::hypot(re, im) / static_cast<double>(s.samples.size());
}

TEST(Sound, NotesFollowEachOtherAtTheirPitch) {
  const Note notes[] = {{.frequency_hz = 440.0, .seconds = 0.2, .gain = 0.5},
                        {.frequency_hz = 0.0, .seconds = 0.1, .gain = 0.0},
                        {.frequency_hz = 660.0, .seconds = 0.2, .gain = 0.5}};
  const Sound s = synthesize_notes(notes, 48000);
  EXPECT_EQ(s.samples.size(), static_cast<std::size_t>(0.5 * 48000));
  const Sound first{48000, {s.samples.begin(), s.samples.begin() + 9600}};
  const Sound rest{48000, {s.samples.begin() + 9600, s.samples.begin() + 14400}};
  const Sound last{48000, {s.samples.begin() + 14400, s.samples.end()}};
  // the fundamental dominates every other frequency from 100 Hz to 2 kHz, by steps of 20 Hz
  for (double f = 100.0; f <= 2000.0; f += 20.0) {
    if (std::abs(f - 440.0) > 30.0) {
      EXPECT_LT(magnitude_at(first, f), magnitude_at(first, 440.0)) << f;
    }
    if (std::abs(f - 660.0) > 30.0) {
      EXPECT_LT(magnitude_at(last, f), magnitude_at(last, 660.0)) << f;
    }
  }
  EXPECT_EQ(rms(rest.samples), 0.0);
  for (const float x : s.samples) ASSERT_LE(std::abs(x), 0.5f + 1e-6f);
  // no click: the first and last samples of each note are near zero
  EXPECT_LT(std::abs(s.samples.front()), 1e-3f);
  EXPECT_LT(std::abs(first.samples.back()), 0.01f);
}

double mean_step(const std::vector<float>& x) {
  double sum = 0.0;
  for (std::size_t i = 1; i < x.size(); ++i) sum += static_cast<double>(std::abs(x[i] - x[i - 1]));
  return sum / static_cast<double>(x.size() - 1);
}

TEST(Sound, ContactLoopsJoinWithoutClickAndRoughIsBrighter) {
  const Sound polished = synthesize_contact_loop({.roughness = 0.0, .seconds = 0.5, .seed = 3});
  const Sound grainy = synthesize_contact_loop({.roughness = 1.0, .seconds = 0.5, .seed = 3});
  for (const Sound* s : {&polished, &grainy}) {
    EXPECT_NEAR(rms(s->samples), 0.25, 0.01);
    double largest = 0.0;
    for (std::size_t i = 1; i < s->samples.size(); ++i)
      largest = std::max(largest, static_cast<double>(std::abs(s->samples[i] - s->samples[i - 1])));
    // the seam (last sample to first) is no bigger a step than the loop's own
    EXPECT_LE(static_cast<double>(std::abs(s->samples.front() - s->samples.back())), largest);
  }
  // brightness: sample-to-sample change per unit of level; high frequencies change faster
  EXPECT_GT(mean_step(grainy.samples), 3.0 * mean_step(polished.samples));
  // the same timbre is the same sound
  EXPECT_EQ(synthesize_contact_loop({.roughness = 0.0, .seconds = 0.5, .seed = 3}).samples, polished.samples);
}

}  // namespace
}  // namespace uh::audio
