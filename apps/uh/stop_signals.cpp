#include "stop_signals.hpp"

#include <signal.h>
#include <string.h>

namespace uh::cli {

std::string signal_name(int signal_number) {
  const char* abbreviation = sigabbrev_np(signal_number);
  return abbreviation != nullptr ? std::string("SIG") + abbreviation : std::string("a signal");
}

ScopedStopHandlers::ScopedStopHandlers(void (*handler)(int)) {
  struct sigaction action {};
  action.sa_handler = handler;
  sigemptyset(&action.sa_mask);
  for (std::size_t i = 0; i < std::size(kStopSignals); ++i)
    sigaction(kStopSignals[i], &action, &previous_[i]);
}

ScopedStopHandlers::~ScopedStopHandlers() {
  for (std::size_t i = 0; i < std::size(kStopSignals); ++i) {
    if (kStopSignals[i] == SIGPIPE) previous_[i].sa_handler = SIG_IGN;
    sigaction(kStopSignals[i], &previous_[i], nullptr);
  }
}

}  // namespace uh::cli
