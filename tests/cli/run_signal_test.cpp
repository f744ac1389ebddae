// `uh run` interrupted as a user or the system interrupts it: SIGINT (Ctrl-C), SIGTERM, SIGHUP (a
// closed terminal or SSH session), SIGPIPE (a closed pipe) or SIGQUIT sent to the running
// program, with and without the live view (--view). It must send zero force, print its summary,
// keep the trace (whose last row is that zero) and exit with 128 + the signal number; on each
// hardware driver (its stand-in) and with two devices of different drivers in one session, each
// device itself is left with zero.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include "child_process.hpp"
#include "haply_standin.hpp"
#include "test_paths.hpp"

namespace uh {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

using test_support::Finished;
using test_support::read_text;
using test_support::wait_for_exit;

// The stylus bounces into the bunny and out for a minute: in contact most of the time.
std::string long_scene_json(const fs::path& assets) {
  return fmt::format(R"({{
  "name": "signal-test",
  "rates": {{ "haptic_hz": 1000, "collision_hz": 500 }},
  "seconds": 60,
  "objects": [{{ "name": "bunny", "mesh": "{0}/meshes/bunny_npm_3674.obj", "meters_per_unit": 0.01, "spheres": 600,
                "pose": {{ "position": [0, 0, 0], "rotation": [0.70710678, 0.70710678, 0, 0] }} }}],
  "tool": {{
    "name": "stylus", "mesh": "{0}/meshes/stylus.obj", "meters_per_unit": 0.01, "spheres": 150,
    "force": {{ "mode": "6dof", "stiffness": 1.6e4, "damping": 1.0, "center_of_mass": [0, 0, 0.025],
               "max_force_n": 6.0, "max_torque_nm": 0.3 }},
    "device": {{ "driver": "sim-line",
                "config": {{ "start": [0.0, 0.0, 0.07], "end": [0.0, 0.0, 0.045], "duration_s": 0.3, "bounce": true,
                            "dof_actuated": 6, "max_force_n": 6 }} }}
  }},
  "watch": ["bunny"]
}})",
                     assets.string());
}

// Two hands on two drivers in one session: an OpenHaptics device (the stand-in libHD) and a Haply
// Inverse3 (the stand-in service at `haply_url`); both handles rest inside the bunny. Both drivers'
// stall watchdogs get seconds (a loaded machine may starve the stand-ins' threads for longer than a
// real device's 250 and 100 ms): the test is about the signals, not about the stand-ins' speed.
std::string long_two_tool_scene_json(const fs::path& assets, const std::string& haply_url) {
  return fmt::format(R"({{
  "name": "signal-test",
  "rates": {{ "haptic_hz": 1000, "collision_hz": 500 }},
  "seconds": 60,
  "objects": [{{ "name": "bunny", "mesh": "{0}/meshes/bunny_npm_3674.obj", "meters_per_unit": 0.01, "spheres": 600,
                "pose": {{ "position": [0, 0, 0], "rotation": [0.70710678, 0.70710678, 0, 0] }} }}],
  "tools": [
    {{ "name": "left", "mesh": "{0}/meshes/stylus.obj", "meters_per_unit": 0.01, "spheres": 150,
      "force": {{ "mode": "3dof", "stiffness": 1.6e4, "damping": 1.0, "center_of_mass": [0, 0, 0.025], "max_force_n": 3.0 }},
      "device": {{ "driver": "openhaptics", "config": {{ "stall_limit_ms": 5000 }} }} }},
    {{ "name": "right", "mesh": "{0}/meshes/stylus.obj", "meters_per_unit": 0.01, "spheres": 150,
      "force": {{ "mode": "3dof", "stiffness": 1.6e4, "damping": 1.0, "center_of_mass": [0, 0, 0.025], "max_force_n": 2.0 }},
      "device": {{ "driver": "haply", "config": {{ "url": "{1}", "timeout_ms": 5000 }} }} }}
  ],
  "watch": ["bunny"]
}})",
                     assets.string(), haply_url);
}

// True once process `pid` has a thread named `name` (Linux: /proc/PID/task/*/comm).
bool has_thread(pid_t pid, const std::string& name) {
  std::error_code ec;
  for (const auto& task : fs::directory_iterator(fmt::format("/proc/{}/task", pid), ec)) {
    std::string comm = read_text(task.path() / "comm");
    while (!comm.empty() && comm.back() == '\n') comm.pop_back();
    if (comm == name) return true;
  }
  return false;
}

// The largest |fx| + |fy| + |fz| in the rows the running program has written to its trace so far:
// the temporary file beside `trace` (AtomicFileWriter's ".NAME.tmp..."), renamed into place at
// the end. 0 while there is none.
double largest_force_so_far(const fs::path& trace) {
  std::error_code ec;
  std::string prefix(".");
  prefix.append(trace.filename().string()).append(".tmp");
  for (const auto& entry : fs::directory_iterator(trace.parent_path(), ec)) {
    if (entry.path().filename().string().rfind(prefix, 0) != 0) continue;
    std::istringstream lines(read_text(entry.path()));
    std::string line;
    std::vector<std::size_t> force_columns;
    if (std::getline(lines, line)) {
      std::istringstream header(line);
      std::size_t i = 0;
      for (std::string name; std::getline(header, name, ','); ++i)
        if (name == "fx" || name == "fy" || name == "fz") force_columns.push_back(i);
    }
    double largest = 0.0;
    while (std::getline(lines, line)) {
      std::vector<double> cells;
      std::istringstream row(line);
      for (std::string c; std::getline(row, c, ',');) cells.push_back(std::strtod(c.c_str(), nullptr));
      double sum = 0.0;
      for (const std::size_t c : force_columns) sum += c < cells.size() ? std::abs(cells[c]) : 0.0;
      largest = std::max(largest, sum);
    }
    return largest;
  }
  return 0.0;
}

struct Interrupt {
  int signal_number;
  bool view;  // uh run --view: the live view's server shows the session meanwhile
  // uh run --device forcedimension:0 on the stand-in DHD library (its handle rests at the origin,
  // inside the bunny): the driver's path from the signal to the zero, not only the simulated one's
  bool force_dimension = false;
  // uh run --device openhaptics on the stand-in libHD: the tick runs on the library's own servo
  // thread, and the stand-in records what the device was last commanded as uh released it
  bool open_haptics = false;
  // uh run --device haply against the stand-in Inverse Service (in this process, on its own
  // thread), which keeps every force it was commanded
  bool haply = false;
  // a two-tool scene: openhaptics (stand-in libHD) and haply (stand-in service) in one session;
  // both devices must be left with zero
  bool two_devices = false;
};

// "SIGHUP" for SIGHUP (glibc's abbreviation, as the kernel's headers name it)
std::string signal_name(int signal_number) {
  const char* abbreviation = sigabbrev_np(signal_number);
  return abbreviation != nullptr ? std::string("SIG") + abbreviation : std::string("a signal");
}

// names the case in test output (instead of the struct's bytes)
void PrintTo(const Interrupt& i, std::ostream* out) {
  *out << signal_name(i.signal_number) << (i.view ? " with --view" : "")
       << (i.force_dimension ? " on forcedimension" : "") << (i.open_haptics ? " on openhaptics" : "")
       << (i.haply ? " on haply" : "") << (i.two_devices ? " on openhaptics and haply at once" : "");
}

class RunSignalTest : public ::testing::TestWithParam<Interrupt> {};

TEST_P(RunSignalTest, StopsWithZeroForceSummaryAndExitStatus) {
  const int signal_number = GetParam().signal_number;
  const bool view = GetParam().view;
  const bool force_dimension = GetParam().force_dimension;
  const bool haply = GetParam().haply;
  const bool two_devices = GetParam().two_devices;
  // the stand-in libHD serves the one-device openhaptics case and the two-device scene's left hand
  const bool open_haptics = GetParam().open_haptics || two_devices;
  const std::string name = signal_name(signal_number);
  const fs::path dir = fs::temp_directory_path() / fmt::format("uh_run_signal_test_{}_{}{}{}", ::getpid(),
                                                               signal_number, view ? "_view" : "",
                                                               force_dimension ? "_dhd"
                                                               : two_devices   ? "_hd_haply"
                                                               : open_haptics  ? "_hd"
                                                               : haply         ? "_haply"
                                                                               : "");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path scene = dir / "scene.json", trace = dir / "trace.csv", out = dir / "stdout.txt",
                 err = dir / "stderr.txt", hd_record = dir / "hd_release.txt";
  // the stand-in service runs before fork(): the child inherits none of its thread, only execs
  std::unique_ptr<devices::testing::HaplyStandinService> haply_service;
  if (haply || two_devices) haply_service = std::make_unique<devices::testing::HaplyStandinService>();
  if (two_devices)
    std::ofstream(scene) << long_two_tool_scene_json(fs::path(UH_TEST_DATA_DIR), haply_service->url());
  else
    std::ofstream(scene) << long_scene_json(fs::path(UH_TEST_DATA_DIR));

  // everything the child needs is prepared before fork(): it only redirects and execs
  const std::string cache_env = "UH_CACHE_DIR=" + (dir / "cache").string();
  std::vector<std::string> args = {UH_CLI_PATH, "run",          scene.string(),
                                   "--trace",   trace.string(), "--no-realtime"};
  if (view) args.insert(args.end(), {"--view", "--port", "0"});
  if (force_dimension) args.insert(args.end(), {"--device", "forcedimension:0"});
  if (open_haptics && !two_devices) args.insert(args.end(), {"--device", "openhaptics"});
  if (haply) args.insert(args.end(), {"--device", "haply"});
  // the stand-ins' handles rest inside the bunny, which the proxy, by design, leaves free until they
  // come out: the penalty path, so that the signal comes while a device is held in contact
  if (force_dimension || open_haptics || haply) args.insert(args.end(), {"--proxy", "off"});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_storage = {cache_env, "CI=1"};
  if (force_dimension) env_storage.push_back(std::string("UH_FORCEDIMENSION_LIBRARY=") + UH_STANDIN_DHD);
  if (open_haptics) {
    env_storage.push_back(std::string("UH_OPENHAPTICS_LIBRARY=") + UH_STANDIN_HD);
    env_storage.push_back("UH_STANDIN_HD_RECORD=" + hd_record.string());
  }
  if (haply) env_storage.push_back("UH_HAPLY_URL=" + haply_service->url());
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry(*e);
    if (entry.rfind("UH_CACHE_DIR=", 0) != 0 && entry.rfind("CI=", 0) != 0 &&
        entry.rfind("UH_FORCEDIMENSION_LIBRARY=", 0) != 0 && entry.rfind("UH_OPENHAPTICS_LIBRARY=", 0) != 0 &&
        entry.rfind("UH_STANDIN_HD_RECORD=", 0) != 0 && entry.rfind("UH_HAPLY_URL=", 0) != 0)
      env_storage.push_back(entry);
  }
  std::vector<char*> envp;
  for (auto& e : env_storage) envp.push_back(e.data());
  envp.push_back(nullptr);
  const std::string out_path = out.string(), err_path = err.string();

  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int o = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int e = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (o < 0 || e < 0 || dup2(o, STDOUT_FILENO) < 0 || dup2(e, STDERR_FILENO) < 0) _exit(120);
    execve(argv[0], argv.data(), envp.data());
    _exit(121);
  }

  // running: the haptic thread exists (the handlers are in place before it starts; on openhaptics
  // the haptic tick runs on HD's servo thread, the collision thread starts with it; with two
  // devices, haply's loop runs beside it on its own thread); then some ticks in contact, so that
  // there is a force to take away
  const auto running = [&] {
    if (two_devices)
      return has_thread(pid, "uh-collision") && has_thread(pid, "hd-servo") && has_thread(pid, "uh-haptic");
    return open_haptics ? has_thread(pid, "uh-collision") && has_thread(pid, "hd-servo")
                        : has_thread(pid, "uh-haptic");
  };
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  // (one reading of the thread list decides: a second one can miss a thread that is being listed
  // while another starts, which failed this test once under ASan)
  bool ran = false;
  while (!(ran = running()) && std::chrono::steady_clock::now() < deadline) {
    if (waitpid(pid, nullptr, WNOHANG) != 0) FAIL() << "uh run ended before it ran: " << read_text(err);
    std::this_thread::sleep_for(5ms);
  }
  ASSERT_TRUE(ran) << "uh run never started its haptic thread: " << read_text(err);
  // in contact: the trace written so far holds a force (a wait for the event, not a time: a
  // loaded machine or a sanitizer takes longer)
  while (largest_force_so_far(trace) <= 0.1 && std::chrono::steady_clock::now() < deadline) {
    if (waitpid(pid, nullptr, WNOHANG) != 0) FAIL() << "uh run ended before the signal: " << read_text(err);
    std::this_thread::sleep_for(5ms);
  }
  // the Inverse3's loop is clocked by the stand-in service's replies, which come slower on a loaded
  // machine (or under a sanitizer): wait for a few hundred ticks of contact rather than for a time
  while (haply_service && haply_service->replies() < 300 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(5ms);
  ASSERT_EQ(kill(pid, signal_number), 0);
  const auto signalled = std::chrono::steady_clock::now();
  const Finished finished = wait_for_exit(pid, 30s);
  const double stop_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - signalled).count();
  RecordProperty("stop_ms", std::to_string(stop_ms));

  ASSERT_TRUE(finished.exited) << "uh run did not end by itself after " << name;
  EXPECT_EQ(finished.code, 128 + signal_number) << read_text(err);
  const std::string stdout_text = read_text(out), stderr_text = read_text(err);
  EXPECT_NE(stdout_text.find("scene signal-test:"), std::string::npos) << "the summary: " << stdout_text;
  EXPECT_NE(stdout_text.find("(stopped early)"), std::string::npos) << stdout_text;
  EXPECT_NE(stdout_text.find("  force     max"), std::string::npos) << stdout_text;
  EXPECT_NE(stderr_text.find(fmt::format("stopped by {}", name)), std::string::npos) << stderr_text;
  if (view) {
    EXPECT_NE(stderr_text.find("live view: http://127.0.0.1:"), std::string::npos) << stderr_text;
  }

  // the trace is kept, and its last row is the zero the device got
  ASSERT_TRUE(fs::exists(trace)) << stderr_text;
  std::istringstream lines(read_text(trace));
  std::string header, line, last;
  std::getline(lines, header);
  std::vector<std::string> names;
  {
    std::istringstream h(header);
    for (std::string n; std::getline(h, n, ',');) names.push_back(n);
  }
  const auto column = [&](const std::string& n) {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == n) return i;
    ADD_FAILURE() << "no column " << n;
    return std::size_t{0};
  };
  const auto cells = [](const std::string& row) {
    std::vector<double> v;
    std::istringstream l(row);
    for (std::string c; std::getline(l, c, ',');) v.push_back(std::strtod(c.c_str(), nullptr));
    return v;
  };
  double max_force = 0.0;
  std::size_t rows = 0;
  while (std::getline(lines, line)) {
    if (!last.empty()) {
      const auto v = cells(last);
      max_force = std::max(max_force,
                           std::abs(v[column("fz")]) + std::abs(v[column("fx")]) + std::abs(v[column("fy")]));
    }
    last = line;
    ++rows;
  }
  ASSERT_GT(rows, 100u);
  const auto v = cells(last);
  ASSERT_EQ(v.size(), names.size());
  EXPECT_EQ(v[column("fx")], 0.0) << last;
  EXPECT_EQ(v[column("fy")], 0.0) << last;
  EXPECT_EQ(v[column("fz")], 0.0) << last;
  EXPECT_EQ(v[column("tx")], 0.0) << last;
  EXPECT_NE(static_cast<unsigned>(v[column("flags")]) & 1024u, 0u)
      << "the zero sent as the haptic thread ended: " << last;
  EXPECT_GT(max_force, 0.1) << "the stylus pressed into the bunny before the signal";
  if (open_haptics) {
    // what the device itself was left with as uh released it: zero commanded, forces off
    std::istringstream record(read_text(hd_record));
    std::string key;
    double fx = 1.0, fy = 1.0, fz = 1.0, largest = 0.0;
    int force_output = 1;
    record >> key >> fx >> fy >> fz >> key >> force_output >> key >> largest;
    ASSERT_TRUE(record) << "the stand-in's record at release: '" << read_text(hd_record) << "'";
    EXPECT_EQ(fx, 0.0);
    EXPECT_EQ(fy, 0.0);
    EXPECT_EQ(fz, 0.0);
    EXPECT_EQ(force_output, 0);
    EXPECT_GT(largest, 0.1) << "the device rendered the contact force before the signal";
  }
  if (haply_service) {
    // what the Inverse3 was last commanded: zero, after contact forces
    const std::vector<Vec3> received = haply_service->received();
    ASSERT_FALSE(received.empty()) << stderr_text;
    double largest = 0.0;
    for (const Vec3& f : received) largest = std::max(largest, norm(f));
    EXPECT_GT(largest, 0.1) << "the Inverse3 rendered the contact force before the signal";
    EXPECT_EQ(received.back().x, 0.0);
    EXPECT_EQ(received.back().y, 0.0);
    EXPECT_EQ(received.back().z, 0.0);
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Signals, RunSignalTest,
    ::testing::Values(Interrupt{SIGINT, false}, Interrupt{SIGTERM, false}, Interrupt{SIGINT, true},
                      Interrupt{SIGTERM, true}, Interrupt{SIGINT, false, true},
                      Interrupt{SIGTERM, false, true}, Interrupt{SIGINT, false, false, true},
                      Interrupt{SIGTERM, false, false, true}, Interrupt{SIGINT, false, false, false, true},
                      Interrupt{SIGTERM, false, false, false, true},
                      Interrupt{SIGINT, false, false, false, false, true},
                      Interrupt{SIGTERM, false, false, false, false, true}, Interrupt{SIGHUP, false},
                      Interrupt{SIGPIPE, false}, Interrupt{SIGQUIT, false}, Interrupt{SIGHUP, true},
                      Interrupt{SIGHUP, false, false, true}),
    [](const ::testing::TestParamInfo<Interrupt>& p) {
      std::string name = signal_name(p.param.signal_number);
      for (std::size_t i = 1; i < name.size(); ++i)
        name[i] = static_cast<char>(std::tolower(static_cast<unsigned char>(name[i])));
      return name + (p.param.view ? "WithView" : "") + (p.param.force_dimension ? "OnForceDimension" : "") +
             (p.param.open_haptics ? "OnOpenHaptics" : "") + (p.param.haply ? "OnHaply" : "") +
             (p.param.two_devices ? "OnTwoDevices" : "");
    });

}  // namespace
}  // namespace uh
