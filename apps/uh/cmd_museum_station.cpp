// uh museum station [--server URL] [--device DRIVER[:SELECTOR]] [--token T] [--no-sound] [--trace FILE]
// Phantom's station: the artifact in Phantom's hands on a haptic device, the round through sound
// and speech, keys on the terminal (docs/museum.md, "Playing Phantom").
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>

#include <fmt/format.h>

#include "commands.hpp"
#include "progress_bar.hpp"
#include "stop_signals.hpp"
#include "uh/museum_client/game_link.hpp"
#include "uh/museum_station/station.hpp"

namespace uh::cli {
namespace {

using museum_station::StationKey;

struct StationArgs {
  std::string server = "ws://127.0.0.1:7780/ws";
  std::string device;
  std::string token;
  std::string trace;
  bool no_sound = false;
};

// the first stop signal (stop_signals.hpp) names the stop; the loop below takes it to the zero force
volatile std::sig_atomic_t g_station_signal = 0;
extern "C" void on_station_signal(int signal_number) {
  if (g_station_signal == 0) g_station_signal = signal_number;
}

// The terminal in raw mode (keys without Enter, no echo; Ctrl-C still stops), restored on exit.
class RawTerminal {
 public:
  RawTerminal() {
    if (isatty(STDIN_FILENO) != 1 || tcgetattr(STDIN_FILENO, &saved_) != 0) return;
    termios raw = saved_;
    raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    active_ = tcsetattr(STDIN_FILENO, TCSANOW, &raw) == 0;
  }
  ~RawTerminal() {
    if (active_) tcsetattr(STDIN_FILENO, TCSANOW, &saved_);
  }
  RawTerminal(const RawTerminal&) = delete;
  RawTerminal& operator=(const RawTerminal&) = delete;

 private:
  termios saved_{};
  bool active_ = false;
};

// The next key waiting on stdin, or none (never blocks); end of input stops reading.
std::optional<char> next_key(bool& input_open) {
  if (!input_open) return std::nullopt;
  pollfd p{.fd = STDIN_FILENO, .events = POLLIN, .revents = 0};
  if (poll(&p, 1, 0) <= 0 || (p.revents & (POLLIN | POLLHUP)) == 0) return std::nullopt;
  char c = 0;
  const ssize_t n = read(STDIN_FILENO, &c, 1);
  if (n <= 0) {
    input_open = false;
    return std::nullopt;
  }
  return c;
}

constexpr const char* kKeysHelp =
    "keys: w or space  where am I / what is this    r  repeat the last line\n"
    "      g  genuine    f  forgery    (or the device's first and second button)\n"
    "      h  guide the stylus home    c  next sound channel    + / -  its volume\n"
    "      q  quit\n";

// A key of the station's keyboard pressed (kKeysHelp); false for 'q' (quit)
bool press_key(museum_station::Station& station, char key) {
  switch (key) {
    case 'w':
    case ' ':
      station.press(StationKey::where_am_i);
      break;
    case 'r':
      station.press(StationKey::repeat);
      break;
    case 'g':
      station.press(StationKey::genuine);
      break;
    case 'f':
      station.press(StationKey::forgery);
      break;
    case 'h':
      station.press(StationKey::guide_home);
      break;
    case 'c':
      station.press(StationKey::next_channel);
      break;
    case '+':
    case '=':
      station.press(StationKey::volume_up);
      break;
    case '-':
      station.press(StationKey::volume_down);
      break;
    case 'q':
      return false;
    default:
      break;
  }
  return true;
}

int museum_station_run(const StationArgs& args) {
  // a bad address or device is said before anything connects (the device is opened once and
  // closed: a selector naming no device fails now, not when the first piece comes)
  if (auto address = museum_client::parse_server_url(args.server); !address)
    return fail("--" + address.error().message);
  if (Status device = museum_station::check_device(args.device); !device) return fail(device.error().message);
  auto link = museum_station::GameLink::connect({.url = args.server, .token = args.token});
  if (!link) return fail(link.error().message);
  std::optional<museum_station::StationSound> sound;
  if (!args.no_sound) {
    auto made = museum_station::StationSound::create();
    if (made) {
      sound.emplace(std::move(*made));
    } else {
      std::fprintf(stderr, "uh museum station: no sound (%s); going on with captions only\n",
                   made.error().message.c_str());
    }
  }
  StagedProgress bars;
  museum_station::StationOptions options;
  options.device = args.device;
  options.trace = args.trace;
  options.on_caption = [](const std::string& caption) {
    std::printf("  %s\n", caption.c_str());
    std::fflush(stdout);
  };
  options.build_progress = bars.callback();
  auto station = museum_station::Station::create((*link)->welcome(), options, std::move(sound), link->get());
  if (!station) return fail(station.error().message);
  std::printf("uh museum station: Phantom at %s, %s%s\n%s", args.server.c_str(),
              args.device.empty() ? "a simulated hand" : args.device.c_str(),
              (*station)->sound() != nullptr ? ", with sound" : "", kKeysHelp);
  std::fflush(stdout);

  int code = 0;
  {
    const ScopedStopHandlers stop_handlers(&on_station_signal);
    const RawTerminal terminal;
    bool input_open = true;
    auto last = std::chrono::steady_clock::now();
    museum_station::LinkNote note;
    for (;;) {
      if (g_station_signal != 0) {
        (*station)->stop();  // zero force before anything else
        code = 128 + g_station_signal;
        break;
      }
      while ((*link)->poll(note)) (*station)->handle(note);
      bool quit = false;
      while (auto key = next_key(input_open))
        if (!press_key(**station, *key)) quit = true;
      if (quit) break;
      const auto now = std::chrono::steady_clock::now();
      (*station)->frame(std::chrono::duration<double>(now - last).count());
      last = now;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    (*station)->stop();
  }
  (*link)->stop();
  if (code != 0)
    std::fprintf(stderr, "uh: stopped by %s; the device was sent zero force\n",
                 signal_name(code - 128).c_str());
  return code;
}

}  // namespace

void add_museum_station_command(CLI::App& museum, CommandRunner& runner) {
  static StationArgs args;
  auto* s = museum.add_subcommand(
      "station", "play Phantom: feel the delivered artifacts on a haptic device, hear the round");
  s->add_option("--server", args.server, "the museum server (what uh museum serve prints), ws://HOST:PORT/ws")
      ->default_val("ws://127.0.0.1:7780/ws");
  s->add_option("--device", args.device,
                "the haptic device, DRIVER[:SELECTOR] as for uh run (default: a simulated hand)");
  s->add_option("--token", args.token, "the server's token, when it has one");
  s->add_flag("--no-sound", args.no_sound, "captions only, no sound output");
  s->add_option("--trace", args.trace,
                "write the haptic trace (CSV) of the piece in hand to this file, anew for each piece");
  s->callback([&runner] { runner = [] { return museum_station_run(args); }; });
}

}  // namespace uh::cli
