#pragma once
/// \file
/// The signals that end a command which drives a device (`uh run`, `uh museum station`), handled in
/// one way: SIGINT (Ctrl-C), SIGTERM, SIGHUP (the terminal or SSH session closed), SIGQUIT and
/// SIGPIPE (the reader of stdout went away). The command's handler only records the signal (and
/// asks its session to stop); the command then stops with zero force, exits 128 + the signal.

#include <csignal>
#include <iterator>
#include <string>

namespace uh::cli {

inline constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE};

/// "SIGHUP" for SIGHUP (glibc's abbreviation, as the kernel's headers name it).
std::string signal_name(int signal_number);

/// Routes every stop signal to `handler` (async-signal-safe, it must only record) while it lives;
/// restores the previous handlers after, except SIGPIPE, which stays ignored: a summary written to
/// a closed pipe fails quietly instead of ending the program before its exit status.
class ScopedStopHandlers {
 public:
  explicit ScopedStopHandlers(void (*handler)(int));
  ~ScopedStopHandlers();
  ScopedStopHandlers(const ScopedStopHandlers&) = delete;
  ScopedStopHandlers& operator=(const ScopedStopHandlers&) = delete;

 private:
  struct sigaction previous_[std::size(kStopSignals)]{};
};

}  // namespace uh::cli
