#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "uh/audio/audio_scene.hpp"
#include "uh/audio/sound.hpp"

namespace uh::audio {
namespace {

constexpr int kRate = 48000;

AudioScene loopback_scene(bool hrtf) {
  auto scene = AudioScene::create({.loopback = true, .sample_rate_hz = kRate, .hrtf = hrtf});
  EXPECT_TRUE(scene) << (scene ? "" : scene.error().message);
  return std::move(scene).value();
}

struct Levels {
  double left = 0.0;
  double right = 0.0;
};

// renders `seconds` of the mix and measures each ear's level
Levels listen(AudioScene& scene, double seconds) {
  std::vector<float> out(2 * static_cast<std::size_t>(seconds * kRate));
  scene.render(out);
  double l = 0.0;
  double r = 0.0;
  for (std::size_t i = 0; i < out.size(); i += 2) {
    l += static_cast<double>(out[i]) * static_cast<double>(out[i]);
    r += static_cast<double>(out[i + 1]) * static_cast<double>(out[i + 1]);
  }
  const double n = static_cast<double>(out.size() / 2);
  return {std::sqrt(l / n), std::sqrt(r / n)};
}

double decibels(double a, double b) { return 20.0 * std::log10(a / b); }

Sound steps_sound() { return synthesize_contact_loop({.roughness = 0.6, .seconds = 0.5, .seed = 7}); }

TEST(AudioScene, AGuardToTheLeftIsLouderInTheLeftEar) {
  for (const bool hrtf : {true, false}) {
    SCOPED_TRACE(hrtf ? "HRTF" : "panning");
    AudioScene scene = loopback_scene(hrtf);
    EXPECT_EQ(scene.hrtf_enabled(), hrtf);
    const auto steps = scene.load(steps_sound());
    ASSERT_TRUE(steps);
    // the listener at the origin facing -z with +y up: -x is to the left
    scene.set_listener({0, 0, 0}, {0, 0, -1}, {0, 1, 0});
    const auto guard = scene.play(
        *steps, {.channel = Channel::guards, .position = {-3, 0, 0}, .relative = false, .loop = true});
    ASSERT_TRUE(guard);
    listen(scene, 0.05);  // past the mixer's first block
    const Levels left = listen(scene, 0.3);
    EXPECT_GT(decibels(left.left, left.right), 3.0) << left.left << " " << left.right;
    // the guard walks round to the right
    scene.set_position(*guard, {3, 0, 0});
    listen(scene, 0.05);
    const Levels right = listen(scene, 0.3);
    EXPECT_GT(decibels(right.right, right.left), 3.0) << right.left << " " << right.right;
    // the listener turns round (faces +z): the guard at +x is now on the left
    scene.set_listener({0, 0, 0}, {0, 0, 1}, {0, 1, 0});
    listen(scene, 0.05);
    const Levels turned = listen(scene, 0.3);
    EXPECT_GT(decibels(turned.left, turned.right), 3.0);
    // and farther away is quieter
    scene.set_position(*guard, {12, 0, 0});
    listen(scene, 0.05);
    const Levels far = listen(scene, 0.3);
    EXPECT_LT(far.left + far.right, 0.5 * (turned.left + turned.right));
  }
}

TEST(AudioScene, SpeechDucksTheOtherChannelsAndTheyComeBack) {
  AudioScene scene = loopback_scene(false);
  const auto loop = scene.load(steps_sound());
  // speech stands in here as a silent clip on the speech channel: it ducks like speech, and the
  // contact loop is then all the mix holds, so its level alone is measured
  const auto silence =
      scene.load(Sound{kRate, std::vector<float>(static_cast<std::size_t>(0.6 * kRate), 0.0f)});
  ASSERT_TRUE(loop && silence);
  ASSERT_TRUE(scene.play(*loop, {.channel = Channel::contact, .loop = true}));
  scene.update(0.01);
  listen(scene, 0.05);
  const Levels before = listen(scene, 0.2);
  ASSERT_GT(before.left, 0.01);

  const auto speech = scene.play(*silence, {.channel = Channel::speech});
  ASSERT_TRUE(speech);
  // 0.3 s in steps of 10 ms: the 0.15 s ramp has come in
  for (int i = 0; i < 30; ++i) {
    scene.update(0.01);
    listen(scene, 0.01);
  }
  EXPECT_NEAR(scene.duck_factor(), 0.3, 1e-9);
  const Levels ducked = listen(scene, 0.1);
  EXPECT_NEAR(ducked.left / before.left, 0.3, 0.03);
  EXPECT_TRUE(scene.playing(*speech));
  // the clip ends at 0.6 s; the ramp goes out over 0.15 s
  for (int i = 0; i < 60; ++i) {
    scene.update(0.01);
    listen(scene, 0.01);
  }
  EXPECT_FALSE(scene.playing(*speech));
  EXPECT_EQ(scene.duck_factor(), 1.0);
  const Levels after = listen(scene, 0.2);
  EXPECT_NEAR(after.left / before.left, 1.0, 0.05);
}

TEST(AudioScene, ChannelVolumesScaleTheirVoicesOnly) {
  AudioScene scene = loopback_scene(false);
  const auto loop = scene.load(steps_sound());
  ASSERT_TRUE(loop);
  ASSERT_TRUE(scene.play(*loop, {.channel = Channel::guards, .loop = true}));
  listen(scene, 0.05);
  const Levels full = listen(scene, 0.2);
  scene.set_volume(Channel::contact, 0.0);  // another channel: no change
  listen(scene, 0.05);
  EXPECT_NEAR(listen(scene, 0.2).left / full.left, 1.0, 0.05);
  scene.set_volume(Channel::guards, 0.5);
  listen(scene, 0.05);
  EXPECT_NEAR(listen(scene, 0.2).left / full.left, 0.5, 0.03);
  scene.set_volume(Channel::guards, 0.0);
  listen(scene, 0.05);
  EXPECT_LT(listen(scene, 0.2).left, 1e-4);
}

TEST(AudioScene, StaleVoicesAndUnknownSoundsAreHandled) {
  AudioScene scene = loopback_scene(false);
  EXPECT_FALSE(scene.play(SoundId{3}, {}));
  EXPECT_FALSE(scene.load(Sound{}));
  const auto click =
      scene.load(synthesize_notes(std::vector<Note>{{.frequency_hz = 1000.0, .seconds = 0.02}}));
  ASSERT_TRUE(click);
  const auto first = scene.play(*click, {});
  ASSERT_TRUE(first);
  listen(scene, 0.1);
  scene.update(0.1);
  EXPECT_FALSE(scene.playing(*first));
  // the ended voice's slot is reused; the old id no longer reaches it
  const auto second = scene.play(*click, {.loop = true});
  ASSERT_TRUE(second);
  EXPECT_EQ(second->index, first->index);
  scene.stop(*first);
  EXPECT_TRUE(scene.playing(*second));
  scene.stop(*second);
  EXPECT_FALSE(scene.playing(*second));
  EXPECT_FALSE(AudioScene::create({.loopback = true, .sample_rate_hz = 10}));
  EXPECT_FALSE(AudioScene::create({.loopback = true, .duck_gain = 2.0}));
}

}  // namespace
}  // namespace uh::audio
