// `uh museum station` run as Phantom runs it, each program a child process: `uh museum serve` (at
// ten times the clock), the station with the simulated hand and a trace, and the sighted bot as
// Vive (`uh museum play --bot vive`), which brings a piece to Phantom's table. Once the piece is in
// the station's hands and pressed on:
// - SIGINT, SIGTERM, SIGHUP, SIGQUIT or SIGPIPE stop the station with 128 + the signal number, the
//   last force its device was sent is zero, and the server logs that Phantom dropped out and
//   pauses the round;
// - a dropped connection (a relay between the station and the server cut) takes the force to zero
//   at once, the station connects again by itself and the round resumes with the force back.
// And a bad --server or --device is refused at startup, naming it, before anything connects.

#include <gtest/gtest.h>

#include <netinet/in.h>
#include <poll.h>
#include <string.h>
#include <sys/socket.h>

#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "child_process.hpp"
#include "test_paths.hpp"

namespace uh {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using test_support::ChildProcess;
using test_support::read_text;
using Clock = std::chrono::steady_clock;

// Guards against a round that never gets there; not a measurement.
constexpr auto kPatience = 180s;
constexpr std::uint32_t kTraceZeroed = 1u << 3;    // haptico::kTraceZeroed: held at zero
constexpr std::uint32_t kTraceStopped = 1u << 10;  // haptico::kTraceStopped: the zero at the end

// One row of a haptic trace: the force sent and the flags.
struct TraceRow {
  double fx = 0.0, fy = 0.0, fz = 0.0, tx = 0.0;
  std::uint32_t flags = 0;
  double force() const { return std::sqrt(fx * fx + fy * fy + fz * fz); }
};

// The complete rows of the trace written so far (the monitor may be writing the last line).
std::vector<TraceRow> read_trace(const fs::path& path) {
  std::istringstream lines(read_text(path));
  std::string header, line;
  std::vector<TraceRow> rows;
  if (!std::getline(lines, header)) return rows;
  std::vector<std::string> names;
  {
    std::istringstream h(header);
    for (std::string n; std::getline(h, n, ',');) names.push_back(n);
  }
  const auto column = [&](const std::string& n) -> std::optional<std::size_t> {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == n) return i;
    return std::nullopt;
  };
  const auto fx = column("fx"), fy = column("fy"), fz = column("fz"), tx = column("tx"),
             flags = column("flags");
  if (!fx || !fy || !fz || !tx || !flags) {
    ADD_FAILURE() << "the trace's header lacks a force or flags column: " << header;
    return rows;
  }
  while (std::getline(lines, line)) {
    if (lines.eof()) break;  // no newline yet: being written
    std::vector<double> v;
    std::istringstream l(line);
    for (std::string c; std::getline(l, c, ',');) v.push_back(std::strtod(c.c_str(), nullptr));
    if (v.size() != names.size()) continue;
    rows.push_back({v[*fx], v[*fy], v[*fz], v[*tx], static_cast<std::uint32_t>(v[*flags])});
  }
  return rows;
}

// A loopback TCP relay the test can cut, as a network drop cuts a connection: it listens on a free
// port and joins each connection to the server's port.
class Relay {
 public:
  explicit Relay(std::uint16_t to_port) : to_port_(to_port) {
    listener_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    socklen_t length = sizeof a;
    if (listener_ < 0 || bind(listener_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        listen(listener_, 8) != 0 || getsockname(listener_, reinterpret_cast<sockaddr*>(&a), &length) != 0 ||
        pipe(wake_.data()) != 0) {
      ADD_FAILURE() << "the relay cannot listen";
      return;
    }
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { run(); });
  }
  ~Relay() {
    stop_.store(true);
    if (thread_.joinable()) {
      (void)!write(wake_[1], "s", 1);
      thread_.join();
    }
    for (const auto& [a, b] : pairs_) close_pair(a, b);
    for (int fd : {listener_, wake_[0], wake_[1]})
      if (fd >= 0) close(fd);
  }
  Relay(const Relay&) = delete;
  Relay& operator=(const Relay&) = delete;

  std::uint16_t port() const { return port_; }
  // Closes every connection through the relay (new ones are relayed again).
  void cut() { (void)!write(wake_[1], "c", 1); }
  int connections() const { return connections_.load(); }

 private:
  static void close_pair(int a, int b) {
    close(a);
    close(b);
  }
  int dial() const {
    const int s = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(to_port_);
    if (s >= 0 && connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) return s;
    if (s >= 0) close(s);
    return -1;
  }
  void run() {
    std::array<char, 65536> buffer{};
    while (!stop_.load()) {
      std::vector<pollfd> fds{{listener_, POLLIN, 0}, {wake_[0], POLLIN, 0}};
      for (const auto& [a, b] : pairs_) {
        fds.push_back({a, POLLIN, 0});
        fds.push_back({b, POLLIN, 0});
      }
      if (poll(fds.data(), fds.size(), 100) <= 0) continue;
      if ((fds[1].revents & POLLIN) != 0) {
        char c = 0;
        if (read(wake_[0], &c, 1) == 1 && c == 'c') {
          for (const auto& [a, b] : pairs_) close_pair(a, b);
          pairs_.clear();
          continue;
        }
      }
      if ((fds[0].revents & POLLIN) != 0) {
        const int in = accept(listener_, nullptr, nullptr);
        const int out = in >= 0 ? dial() : -1;
        if (out >= 0) {
          pairs_.emplace_back(in, out);
          connections_.fetch_add(1);
        } else if (in >= 0) {
          close(in);
        }
      }
      // what one side says goes to the other; a side that ends ends the pair. A pair accepted
      // above was not in this poll (it has no entries in fds): it is only kept.
      const std::size_t polled = (fds.size() - 2) / 2;
      std::vector<std::pair<int, int>> kept;
      for (std::size_t p = 0; p < pairs_.size(); ++p) {
        const auto [a, b] = pairs_[p];
        if (p >= polled) {
          kept.emplace_back(a, b);
          continue;
        }
        bool open = true;
        for (const auto& [from, to, revents] :
             {std::tuple{a, b, fds[2 + 2 * p].revents}, std::tuple{b, a, fds[3 + 2 * p].revents}}) {
          if (!open || (revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
          const ssize_t n = read(from, buffer.data(), buffer.size());
          open = n > 0 && send(to, buffer.data(), static_cast<std::size_t>(n), MSG_NOSIGNAL) == n;
        }
        if (open)
          kept.emplace_back(a, b);
        else
          close_pair(a, b);
      }
      pairs_ = std::move(kept);
    }
  }

  std::uint16_t to_port_ = 0;
  std::uint16_t port_ = 0;
  int listener_ = -1;
  std::array<int, 2> wake_{-1, -1};
  std::vector<std::pair<int, int>> pairs_;  // the relay's thread's: (from the station, to the server)
  std::atomic<bool> stop_{false};
  std::atomic<int> connections_{0};
  std::thread thread_;
};

// Waits until `done`, at most kPatience; false if `alive` ends first or the patience runs out.
template <typename Done, typename Alive>
bool wait_until(Done done, Alive alive) {
  const auto give_up = Clock::now() + kPatience;
  while (Clock::now() < give_up) {
    if (done()) return true;
    if (!alive()) return done();
    std::this_thread::sleep_for(20ms);
  }
  return false;
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A 20-minute round at ten times the clock (two minutes at most): the server, the station (through `relay`
// when there is one) and the sighted bot as Vive.
class MuseumStationRound : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           fmt::format("uh_museum_station_test_{}_{}", ::getpid(),
                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    trace_ = dir_ / "trace.csv";
  }
  void TearDown() override {
    // the bot ends with the server; every child is reaped (killed if it hangs) before the files go
    for (ChildProcess* c : {station_.get(), server_.get()})
      if (c != nullptr && c->signal(SIGTERM)) c->wait(30s);
    if (vive_) vive_->wait(30s);
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // Starts the server and waits for its address; the port it listens on.
  std::uint16_t start_server() {
    server_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{UH_CLI_PATH, "museum", "serve", "--port", "0", "--seed", "1", "--minutes",
                                 "20", "--speed", "10"},
        std::vector<std::string>{"UH_CACHE_DIR=" + std::string(UH_TEST_CACHE_DIR)}, dir_ / "server.out",
        dir_ / "server.err");
    // "players connect to ws://127.0.0.1:PORT/ws" (read without std::regex: g++ 12 reports its
    // automaton's std::function as maybe uninitialized under the sanitizer builds' -O1)
    static constexpr std::string_view kAddress = "players connect to ws://127.0.0.1:";
    std::string out;
    std::uint16_t port = 0;
    const bool listening = wait_until(
        [&] {
          out = server_->out();
          const std::size_t at = out.find(kAddress);
          if (at == std::string::npos) return false;
          const std::size_t digits = at + kAddress.size(), end = out.find("/ws", digits);
          if (end == std::string::npos || end == digits || end - digits > 5) return false;
          unsigned value = 0;
          for (std::size_t i = digits; i < end; ++i) {
            if (out[i] < '0' || out[i] > '9') return false;
            value = value * 10 + static_cast<unsigned>(out[i] - '0');
          }
          if (value == 0 || value > 65535) return false;
          port = static_cast<std::uint16_t>(value);
          return true;
        },
        [&] { return server_->running(); });
    if (!listening) {
      ADD_FAILURE() << "the server never said where it listens: " << out << server_->err();
      return 0;
    }
    return port;
  }
  void start_station(std::uint16_t port) {
    station_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{UH_CLI_PATH, "museum", "station", "--server",
                                 fmt::format("ws://127.0.0.1:{}/ws", port), "--no-sound", "--trace",
                                 trace_.string()},
        std::vector<std::string>{"UH_CACHE_DIR=" + std::string(UH_TEST_CACHE_DIR)}, dir_ / "station.out",
        dir_ / "station.err");
  }
  void start_vive(std::uint16_t port) {
    vive_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{UH_CLI_PATH, "museum", "play", "--bot", "vive", "--server",
                                 fmt::format("ws://127.0.0.1:{}/ws", port)},
        std::vector<std::string>{}, dir_ / "vive.out", dir_ / "vive.err");
  }
  // Waits until a piece is in the station's hands and its device was sent a force of some size.
  bool wait_for_force() {
    return wait_until(
        [&] {
          if (station_->out().find("In hand: ") == std::string::npos) return false;
          for (const TraceRow& r : read_trace(trace_))
            if (r.force() > 0.1 && (r.flags & kTraceZeroed) == 0) return true;
          return false;
        },
        [&] { return station_->running() && server_->running(); });
  }
  // what the server logged (its notes go to stdout, beside its address)
  std::string server_log() const { return server_->out() + server_->err(); }
  std::string said() const {
    return fmt::format("station: {}{}\nserver: {}{}\nvive: {}{}", station_->out(), station_->err(),
                       server_->out(), server_->err(), vive_ ? vive_->out() : "", vive_ ? vive_->err() : "");
  }

  fs::path dir_, trace_;
  std::unique_ptr<ChildProcess> server_, station_, vive_;
};

class MuseumStationSignal : public MuseumStationRound, public ::testing::WithParamInterface<int> {};

TEST_P(MuseumStationSignal, StopsWithZeroForceAndTheServerPausesTheRound) {
  const int signal_number = GetParam();
  const std::string name = std::string("SIG") + sigabbrev_np(signal_number);
  const std::uint16_t port = start_server();
  ASSERT_NE(port, 0);
  start_station(port);
  start_vive(port);
  ASSERT_TRUE(wait_for_force()) << "no piece was pressed on in the station's hands: " << said();

  ASSERT_TRUE(station_->signal(signal_number));
  const test_support::Finished finished = station_->wait(30s);
  ASSERT_TRUE(finished.exited) << "the station did not end by itself after " << name << ": " << said();
  EXPECT_EQ(finished.code, 128 + signal_number) << said();
  EXPECT_NE(station_->err().find(fmt::format("stopped by {}; the device was sent zero force", name)),
            std::string::npos)
      << said();
  // the trace is kept, and its last row is the zero the device got as the session stopped
  const std::vector<TraceRow> rows = read_trace(trace_);
  ASSERT_GT(rows.size(), 100u);
  const TraceRow& last = rows.back();
  EXPECT_EQ(last.fx, 0.0);
  EXPECT_EQ(last.fy, 0.0);
  EXPECT_EQ(last.fz, 0.0);
  EXPECT_EQ(last.tx, 0.0);
  EXPECT_NE(last.flags & kTraceStopped, 0u) << "the zero sent as the haptic thread ended";
  // the server noticed Phantom leave and paused the round
  const bool paused = wait_until(
      [&] { return server_log().find("phantom dropped out; the round pauses") != std::string::npos; },
      [&] { return server_->running(); });
  EXPECT_TRUE(paused) << said();
}

// every signal `uh run` stops on (RunSignalTest) reaches the same zero-force stop here
INSTANTIATE_TEST_SUITE_P(Signals, MuseumStationSignal,
                         ::testing::Values(SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE),
                         [](const ::testing::TestParamInfo<int>& p) {
                           std::string name = std::string("Sig") + sigabbrev_np(p.param);
                           for (std::size_t i = 4; i < name.size(); ++i)
                             name[i] = static_cast<char>(std::tolower(static_cast<unsigned char>(name[i])));
                           return name;
                         });

TEST_F(MuseumStationRound, ADroppedConnectionZeroesTheForceAndTheRoundResumesOnReconnect) {
  const std::uint16_t port = start_server();
  ASSERT_NE(port, 0);
  Relay relay(port);
  ASSERT_NE(relay.port(), 0);
  start_station(relay.port());
  start_vive(port);
  ASSERT_TRUE(wait_for_force()) << "no piece was pressed on in the station's hands: " << said();
  const std::size_t rows_before = read_trace(trace_).size();

  relay.cut();
  // the station hears of the drop, the server pauses, the station says hello again through the
  // relay and the round plays on with the force back
  const bool lost = wait_until([&] { return station_->out().find("Server lost") != std::string::npos; },
                               [&] { return station_->running(); });
  ASSERT_TRUE(lost) << said();
  const bool back = wait_until(
      [&] {
        return station_->out().find("Server back") != std::string::npos &&
               count_of(server_log(), "museum: phantom joined") >= 2;
      },
      [&] { return station_->running() && server_->running(); });
  ASSERT_TRUE(back) << said();
  EXPECT_NE(server_log().find("phantom dropped out; the round pauses"), std::string::npos) << said();
  EXPECT_GE(relay.connections(), 2);
  // in the trace (one session: the piece stayed in hand): force, then held at zero, then force again
  std::size_t zeroed_at = 0, resumed_at = 0;
  const bool force_again = wait_until(
      [&] {
        const std::vector<TraceRow> rows = read_trace(trace_);
        zeroed_at = resumed_at = 0;
        for (std::size_t i = rows_before; i < rows.size(); ++i) {
          if (zeroed_at == 0 && (rows[i].flags & kTraceZeroed) != 0) zeroed_at = i;
          if (zeroed_at != 0 && (rows[i].flags & kTraceZeroed) == 0 && rows[i].force() > 0.1) {
            resumed_at = i;
            return true;
          }
        }
        return false;
      },
      [&] { return station_->running(); });
  ASSERT_TRUE(force_again) << "held from row " << zeroed_at << "; " << said();
  const std::vector<TraceRow> rows = read_trace(trace_);
  for (std::size_t i = zeroed_at; i < resumed_at; ++i)
    if ((rows[i].flags & kTraceZeroed) != 0) {
      ASSERT_EQ(rows[i].force(), 0.0) << "row " << i << " was held yet sent a force";
    }
  EXPECT_GT(resumed_at - zeroed_at, 100u) << "held for the second before the station reconnects";
  EXPECT_EQ(count_of(station_->out(), "In hand: "), 1u) << "the same piece stayed in hand: " << said();
}

// The station's own mistakes on its command line: said at once, naming the argument, with no
// attempt to connect (the server named does not exist).
TEST(MuseumStationCli, ABadServerOrDeviceIsRefusedAtStartupByName) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("uh_museum_station_cli_{}", ::getpid());
  fs::create_directories(dir);
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> env;
    std::string expected;
  };
  const std::string nobody = "ws://127.0.0.1:1/ws";
  const std::vector<Case> cases{
      {{"--server", "ftp://127.0.0.1:7780/"}, {}, "--server 'ftp://127.0.0.1:7780/': the address must be"},
      {{"--server", "ws://127.0.0.1/ws"}, {}, "--server 'ws://127.0.0.1/ws': give the host and the port"},
      {{"--server", "127.0.0.1:99999"}, {}, "the port '99999' is not a number from 0 to 65535"},
      {{"--server", nobody, "--device", "simulated"}, {}, "--device: unknown driver 'simulated'"},
      {{"--server", nobody, "--device", "sim-hand:substeps=0"},
       {},
       "--device sim-hand:substeps=0: sim-hand: substeps must be a whole number"},
      // a selector that names no device: found when the device is opened, before the round
      {{"--server", nobody, "--device", "forcedimension:serial=4"},
       {std::string("UH_FORCEDIMENSION_LIBRARY=") + UH_STANDIN_DHD},
       "--device forcedimension:serial=4: the device does not open: forcedimension: no device with serial 4"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{UH_CLI_PATH, "museum", "station", "--no-sound"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    ChildProcess station(args, c.env, dir / "out.txt", dir / "err.txt");
    const test_support::Finished finished = station.wait(60s);
    const std::string err = station.err();
    EXPECT_TRUE(finished.exited) << c.expected;
    EXPECT_EQ(finished.code, 1) << err;
    EXPECT_NE(err.find(c.expected), std::string::npos) << err;
    EXPECT_EQ(err.find("cannot reach"), std::string::npos) << "refused before connecting: " << err;
    EXPECT_EQ(station.out(), "") << "nothing started";
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace uh
