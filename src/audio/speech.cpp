#include "uh/audio/speech.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace uh::audio {
namespace {

// Speech comes from the espeak-ng program (GPL-3), run as a separate process and never linked, so
// that no program of the project links a GPL library (docs/licenses.md).
constexpr const char* kProgram = "espeak-ng";
// a line's WAV: 16-bit mono at 22,050 Hz is 44 kB a second; a line never needs minutes
constexpr std::size_t kMaxWavBytes = std::size_t{32} << 20;

// A pipe's two ends, closed when it goes out of scope.
struct Pipe {
  int fds[2] = {-1, -1};
  ~Pipe() {
    for (int fd : fds)
      if (fd >= 0) close(fd);
  }
};

// Runs kProgram with `args` (no shell; stdin and stderr on /dev/null) and returns its stdout, at
// most kMaxWavBytes; an error when it cannot start or fails.
Result<std::string> run_espeak(const std::vector<std::string>& args) {
  std::vector<std::string> argv_storage{kProgram};
  argv_storage.insert(argv_storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_storage) argv.push_back(a.data());
  argv.push_back(nullptr);

  Pipe out;
  if (pipe2(out.fds, O_CLOEXEC) != 0) return Error{std::string("speech: no pipe: ") + std::strerror(errno)};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, out.fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, kProgram, &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(out.fds[1]);
  out.fds[1] = -1;
  if (spawned != 0) {
    return Error{std::string("speech: cannot run the espeak-ng program (Debian's espeak-ng package): ") +
                 std::strerror(spawned)};
  }
  std::string bytes;
  char buffer[1 << 16];
  bool too_long = false;
  for (;;) {
    const ssize_t got = read(out.fds[0], buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    if (bytes.size() + static_cast<std::size_t>(got) > kMaxWavBytes) {
      too_long = true;
      kill(pid, SIGKILL);
      break;
    }
    bytes.append(buffer, static_cast<std::size_t>(got));
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (too_long) return Error{"speech: espeak-ng's output passed the limit of 32 MiB for one line"};
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return Error{"speech: the espeak-ng program failed (exit status " +
                 std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)) + ")"};
  return bytes;
}

std::uint32_t little_endian(const std::string& bytes, std::size_t at, int size) {
  std::uint32_t value = 0;
  for (int i = size - 1; i >= 0; --i)
    value = (value << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(i)]);
  return value;
}

// The samples of a 16-bit mono PCM WAV as espeak-ng --stdout writes it (a stream: the data chunk's
// size may claim more than there is; what there is counts).
Result<Sound> decode_wav(const std::string& bytes) {
  const Error bad{"speech: espeak-ng's output is not 16-bit mono PCM WAV"};
  if (bytes.size() < 12 || bytes.compare(0, 4, "RIFF") != 0 || bytes.compare(8, 4, "WAVE") != 0) return bad;
  Sound sound;
  bool format_seen = false;
  for (std::size_t at = 12; at + 8 <= bytes.size();) {
    const std::string id = bytes.substr(at, 4);
    const std::size_t size = little_endian(bytes, at + 4, 4), body = at + 8;
    if (id == "fmt ") {
      if (size < 16 || body + 16 > bytes.size()) return bad;
      if (little_endian(bytes, body, 2) != 1 || little_endian(bytes, body + 2, 2) != 1 ||
          little_endian(bytes, body + 14, 2) != 16)
        return bad;
      sound.sample_rate_hz = static_cast<int>(little_endian(bytes, body + 4, 4));
      format_seen = true;
    } else if (id == "data") {
      if (!format_seen) return bad;
      const std::size_t end = std::min(bytes.size(), body + size);
      sound.samples.reserve((end - body) / 2);
      for (std::size_t i = body; i + 2 <= end; i += 2)
        sound.samples.push_back(static_cast<float>(static_cast<std::int16_t>(little_endian(bytes, i, 2))) /
                                32768.0f);
      return sound;
    }
    at = body + size + (size & 1);
  }
  return bad;
}

// The names espeak-ng knows a voice by (its language, name and file, as `espeak-ng --voices`
// lists them), read once: the program speaks an unknown voice in its default one without a word.
Result<std::set<std::string>> known_voices() {
  static std::mutex mutex;
  static std::optional<Result<std::set<std::string>>> voices;
  const std::lock_guard<std::mutex> lock(mutex);
  if (!voices) {
    auto listing = run_espeak({"--voices"});
    if (!listing) {
      voices = Result<std::set<std::string>>(listing.error());
    } else {
      std::set<std::string> names;
      std::istringstream lines(*listing);
      std::string line;
      std::getline(lines, line);  // the header
      while (std::getline(lines, line)) {
        std::istringstream fields(line);
        std::string priority, language, age_gender, name, file;
        if (!(fields >> priority >> language >> age_gender >> name >> file)) continue;
        names.insert({language, name, file, file.substr(file.rfind('/') + 1)});
      }
      voices = Result<std::set<std::string>>(std::move(names));
    }
  }
  return *voices;
}

}  // namespace

Result<Sound> synthesize_speech(std::string_view text, const SpeechDef& def) {
  auto voices = known_voices();
  if (!voices) return voices.error();
  // a voice may carry a variant ("en+f3"): the voice itself must exist
  const std::string voice(def.voice);
  if (voices->count(voice.substr(0, voice.find('+'))) == 0)
    return Error{"speech: espeak-ng has no voice '" + voice + "' (espeak-ng --voices lists them)"};
  // the text as one argument, after a space so that it is never read as an option
  std::string argument(" ");
  argument.append(text);
  auto wav = run_espeak({"--stdout", "-v", voice, "-s", std::to_string(def.words_per_minute), argument});
  if (!wav) return wav.error();
  return decode_wav(*wav);
}

}  // namespace uh::audio
