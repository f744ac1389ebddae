#include <gtest/gtest.h>

#include "uh/audio/speech.hpp"

namespace uh::audio {
namespace {

TEST(Speech, SpeaksASentenceAudibly) {
  const auto spoken = synthesize_speech("Two guards in the east gallery.");
  ASSERT_TRUE(spoken) << spoken.error().message;
  EXPECT_EQ(spoken->sample_rate_hz, 22050);
  // about two words per second at 175 words per minute: six words take 1-4 s
  EXPECT_GT(spoken->seconds(), 1.0);
  EXPECT_LT(spoken->seconds(), 4.0);
  EXPECT_GT(rms(spoken->samples), 0.02);
  // a longer text takes longer
  const auto longer =
      synthesize_speech("Two guards in the east gallery, and one more by the stairs to the vault.");
  ASSERT_TRUE(longer);
  EXPECT_GT(longer->seconds(), spoken->seconds() * 1.5);
}

TEST(Speech, UnknownVoiceIsAnErrorNamingIt) {
  const auto spoken = synthesize_speech("hello", {.voice = "no-such-voice"});
  ASSERT_FALSE(spoken);
  EXPECT_NE(spoken.error().message.find("no-such-voice"), std::string::npos) << spoken.error().message;
  // the synthesizer still works afterwards
  EXPECT_TRUE(synthesize_speech("hello"));
}

}  // namespace
}  // namespace uh::audio
