#include "uh/devices/fault_note.hpp"

#include <cstdio>

namespace uh::devices {

void FaultNote::note(const char* what, const char* detail) {
  if (noted_) return;
  noted_ = true;
  Text& t = handoff_.write_buffer();
  // snprintf into a fixed buffer: no allocation on the haptic thread
  std::snprintf(t.chars.data(), t.chars.size(), "%s: %s", what,
                detail != nullptr && *detail != '\0' ? detail : "no message from the device");
  handoff_.publish();
}

std::string FaultNote::text() {
  if (handoff_.update()) last_ = handoff_.read_buffer();
  return std::string(last_.chars.data());
}

void FaultNote::clear() {
  noted_ = false;
  last_ = Text{};
  // drop a note the controlling thread has not picked up: it belongs to the previous session
  (void)handoff_.update();
  last_ = Text{};
}

}  // namespace uh::devices
