#pragma once
// The force that means contact, shared by the scripted hand (which feels for it) and the
// estimators (which read only the samples in contact).

namespace uh::exploration {

constexpr double kTouchN = 0.05;  // a force above this means contact [N]

}  // namespace uh::exploration
