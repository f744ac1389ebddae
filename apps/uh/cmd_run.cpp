// uh run [SCENE] [--seconds S] [--json] [--trace OUT.csv] [--plot OUT.png] [--device DRIVER[:SELECTOR]]
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>

#include <iterator>

#include <fmt/format.h>

#include "commands.hpp"
#include "progress_bar.hpp"
#include "session_plot.hpp"
#include "stop_signals.hpp"
#include "uh/controllers/haptic_session.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/core/atomic_file_writer.hpp"
#include "uh/devices/device_probe.hpp"
#include "uh/devices/hardware_drivers.hpp"
#include "uh/service/server.hpp"
#include "view_assets.hpp"

namespace uh::cli {
namespace {

// The handler only records the signal and asks the session to stop (a sig_atomic_t store and one
// lock-free atomic store, both async-signal-safe); the run then ends as if its time were up: zero
// force, threads joined, trace renamed into place, summary printed, exit status 128 + signal.
volatile std::sig_atomic_t g_stop_signal = 0;
std::atomic<controllers::HapticSession*> g_running_session{nullptr};
static_assert(std::atomic<controllers::HapticSession*>::is_always_lock_free);

extern "C" void on_stop_signal(int signal_number) {
  // the first signal names the stop; a SIGPIPE from printing after it does not rename it
  if (g_stop_signal == 0) g_stop_signal = signal_number;
  if (controllers::HapticSession* session = g_running_session.load()) session->request_stop();
}

// Routes the stop signals (stop_signals.hpp) to `session` while it lives.
class StopOnSignals {
 public:
  explicit StopOnSignals(controllers::HapticSession& session)
      : session_(&session), handlers_(&on_stop_signal) {}
  ~StopOnSignals() { g_running_session.store(nullptr); }
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;

 private:
  // set before the handlers are installed: a signal that comes at once already stops the session
  struct Registered {
    explicit Registered(controllers::HapticSession* session) { g_running_session.store(session); }
  } session_;
  ScopedStopHandlers handlers_;
};

struct RunArgs {
  std::string scene;
  double seconds = 0.0;
  bool json = false;
  std::string trace;
  std::string plot;
  double haptic_hz = 0.0;
  double collision_hz = -1.0;
  double coherence_skin = -1.0;
  bool held_forces = false;
  bool exact_tick = false;
  std::string proxy;  // "on", "off" or "" (the scene's)
  bool check_model = false;
  bool stepped = false;
  int ticks_per_collision = 4;
  bool no_realtime = false;
  bool view = false;
  int view_port = 7770;
  std::string device;
};

// one device's lines of the summary; `label` names the tool in several-tool sessions
void print_tool_summary(const controllers::ToolReport& r, bool stepped, const std::string& label) {
  const controllers::DeviceReport& d = r.device;
  std::printf("  device    %s%s%s%s, max %.1f N%s\n", label.c_str(), d.name.c_str(),
              d.serial.empty() ? "" : fmt::format(", serial {}", d.serial).c_str(),
              d.name.rfind(d.driver, 0) == 0 ? "" : fmt::format(" (driver {})", d.driver).c_str(),
              d.max_force_n,
              d.com_rate_hz > 0.0 ? fmt::format(", communication {:.0f} Hz", d.com_rate_hz).c_str() : "");
  std::printf(
      "  haptic    %.1f Hz (target %.0f), %llu ticks, %llu missed deadlines, jitter p50 %.1f us, p99 %.1f "
      "us, max %.1f us\n",
      r.haptic_rate_hz, r.haptic_target_hz, static_cast<unsigned long long>(r.haptic_ticks),
      static_cast<unsigned long long>(r.haptic_missed_deadlines), r.jitter_p50_us, r.jitter_p99_us,
      r.jitter_max_us);
  std::printf(
      "  force     max %.2f N, torque max %.3f N m, largest tick-to-tick step %.3f N (%s), %llu non-finite\n",
      r.force_max_n, r.torque_max_nm, r.force_max_step_n,
      r.proxy ? "proxy" : !r.multi_rate ? "held forces" : (r.tick_force == "model" ? "local model" : "every pair re-evaluated"),
      static_cast<unsigned long long>(r.force_nonfinite));
  if (!stepped)
    std::printf("  tick      p50 %.1f us, p99 %.1f us, max %.1f us\n", r.tick_p50_us, r.tick_p99_us,
                r.tick_max_us);
  if (r.proxy) {
    std::printf("  proxy     %llu updates, %llu in contact, %llu unsolved, up to %d constraints, solve p50 %.1f us, "
                "p99 %.1f us, deepest %.3f mm, ended at (%.4f, %.4f, %.4f) m\n",
                static_cast<unsigned long long>(r.proxy_stats.updates),
                static_cast<unsigned long long>(r.proxy_stats.contact_updates),
                static_cast<unsigned long long>(r.proxy_stats.unsolved), r.proxy_stats.max_constraints,
                r.proxy_stats.solve_time.p50_ns * 1e-3, r.proxy_stats.solve_time.p99_ns * 1e-3,
                r.proxy_stats.deepest_m * 1e3, r.proxy_position.x, r.proxy_position.y, r.proxy_position.z);
    // a tool that begins inside an object has no side to keep (it follows the handle until it is
    // out): said, or a run that never felt the object puzzles
    if (r.proxy_stats.free_updates > 0)
      std::printf("            the tool began inside an object: the proxy followed the handle freely for %llu "
                  "updates, until the tool was out of every object\n",
                  static_cast<unsigned long long>(r.proxy_stats.free_updates));
  } else if (r.multi_rate && r.tick_force == "model")
    std::printf("  model     %llu ticks beyond the trust range, %llu holding%s\n",
                static_cast<unsigned long long>(r.model_clamped_ticks),
                static_cast<unsigned long long>(r.model_held_ticks),
                r.model_checked_ticks > 0
                    ? fmt::format("; force error against every pair re-evaluated: RMS {:.4f} N, max {:.4f} N",
                                  r.model_error_rms_n, r.model_error_max_n)
                          .c_str()
                    : "");
  std::printf("  limits    ticks limited by the device %llu, the tool %llu, the safety limit %llu, the rate limit %llu\n",
              static_cast<unsigned long long>(r.limits.device), static_cast<unsigned long long>(r.limits.tool),
              static_cast<unsigned long long>(r.limits.safety), static_cast<unsigned long long>(r.limits.rate));
  std::printf("  contact   %llu ticks in contact; energy into the hand %.4f J%s\n",
              static_cast<unsigned long long>(r.contact_ticks), r.work_on_hand_j, r.coupling ? " (virtual coupling)" : "");
}

// a soft object's line: its simulation thread's rate and step time
void print_soft_summary(const controllers::SessionReport::SoftObjectReport& s, bool stepped) {
  if (stepped) {
    std::printf("  soft      '%s': %lld tetrahedra, %llu steps at %.0f Hz of simulated time\n", s.object.c_str(),
                static_cast<long long>(s.tetrahedra), static_cast<unsigned long long>(s.steps), s.target_hz);
    return;
  }
  std::printf("  soft      '%s': %lld tetrahedra, %.1f steps/s (target %.0f), %llu steps, %llu missed deadlines, "
              "step p50 %.2f ms, p99 %.2f ms, max %.2f ms\n",
              s.object.c_str(), static_cast<long long>(s.tetrahedra), s.rate_hz, s.target_hz,
              static_cast<unsigned long long>(s.steps), static_cast<unsigned long long>(s.missed_deadlines),
              s.step_p50_ms, s.step_p99_ms, s.step_max_ms);
}

void print_summary(const controllers::SessionReport& r) {
  std::printf("scene %s: %.1f s%s%s\n", r.scene.c_str(), r.seconds,
              r.stepped ? " (stepped, simulated time)" : "", r.stopped_early ? " (stopped early)" : "");
  std::printf(
      "  collision median %.0f Hz, min %.0f Hz (target %.0f); query median %.1f us, p99 %.1f us, max %.1f "
      "us; up to %lld pairs\n",
      r.collision_rate_median_hz, r.collision_rate_min_hz, r.collision_target_hz, r.query_median_us,
      r.query_p99_us, r.query_max_us, static_cast<long long>(r.max_pairs));
  // one block per device; a one-tool session's block is as it always was
  for (const controllers::ToolReport& t : r.tools)
    print_tool_summary(t, r.stepped, r.tools.size() > 1 ? fmt::format("tool '{}': ", t.tool) : std::string());
  for (const auto& s : r.soft) print_soft_summary(s, r.stepped);
}

// The scene to run: the file's (or the default one) with --device's driver and selection on its tool
Result<controllers::Scene> scene_of(const RunArgs& args, const std::filesystem::path& cache) {
  auto scene = args.scene.empty() ? controllers::default_scene(cache) : controllers::load_scene(args.scene);
  if (!scene || args.device.empty()) return scene;
  auto choice = devices::parse_device_choice(args.device, devices::all_drivers());
  if (!choice) return choice.error();
  // another driver does not share the scene's settings; the same one keeps them, with the selection on top
  if (scene->tools.size() > 1)
    return Error{fmt::format("{}: --device replaces the device of a one-tool scene; this scene has {} tools "
                             "(set each one's device in its tools[i].device)",
                             scene->source, scene->tools.size())};
  controllers::SceneDevice& device = scene->tool().device;
  if (choice->driver != device.driver) device.config = {};
  device.driver = choice->driver;
  for (const auto& [key, value] : choice->selection.values()) device.config.set(key, value);
  return scene;
}

// What the run prints and writes once the session has stopped; the program's exit status
int finish_run(const RunArgs& args, const controllers::SessionReport& report) {
  if (!args.plot.empty())
    if (auto plotted = write_session_plot(report, args.plot); !plotted) return fail(plotted.error().message);
  if (args.json) {
    std::printf("%s\n", controllers::session_report_json(report).c_str());
  } else {
    print_summary(report);
    if (!args.trace.empty()) std::printf("  trace -> %s\n", args.trace.c_str());
    if (!args.plot.empty()) std::printf("  plot  -> %s\n", args.plot.c_str());
  }
  if (g_stop_signal != 0) {
    const int signal_number = g_stop_signal;
    std::fflush(stdout);
    std::fprintf(stderr, "uh: stopped by %s after %.2f s; the device was sent zero force\n",
                 signal_name(signal_number).c_str(), report.seconds);
    return 128 + signal_number;
  }
  return 0;
}

int run_session(const RunArgs& args) {
  const std::filesystem::path cache = controllers::default_cache_dir();
  auto scene = scene_of(args, cache);
  if (!scene) return fail(scene.error().message);

  controllers::SessionOptions options;
  if (args.haptic_hz > 0.0) options.haptic_hz = args.haptic_hz;
  if (args.collision_hz >= 0.0) options.collision_hz = args.collision_hz;
  if (args.coherence_skin >= 0.0) options.coherence_skin = args.coherence_skin;
  if (args.held_forces) options.multi_rate = false;
  if (args.exact_tick) options.tick_force = controllers::TickForce::kExact;
  if (!args.proxy.empty()) options.proxy = args.proxy == "on";
  options.check_model = args.check_model;
  options.raise_priority = !args.no_realtime;
  options.cache_dir = cache;
  StagedProgress bars;
  options.build_progress = bars.callback();
  auto session = controllers::HapticSession::create(*scene, options);
  bars.finish();
  if (!session) return fail(session.error().message);

  // the trace replaces an earlier file only once it is complete
  std::optional<AtomicFileWriter> trace_file;
  if (!args.trace.empty()) {
    auto created = AtomicFileWriter::create(args.trace);
    if (!created) return fail(created.error().message);
    trace_file.emplace(std::move(*created));
  }
  std::ostream* trace = trace_file ? &trace_file->stream() : nullptr;
  const double seconds = args.seconds > 0.0 ? args.seconds : scene->seconds;
  const char* ci = std::getenv("CI");
  const bool live = !args.json && isatty(STDERR_FILENO) == 1 && (ci == nullptr || *ci == '\0');

  // with the live view, the server shows the session to browsers while this thread runs it
  std::unique_ptr<service::Server> view_server;
  if (args.view) {
    auto server = service::Server::start({.port = static_cast<std::uint16_t>(args.view_port), .files = view::static_files()});
    if (!server) return fail(server.error().message);
    view_server = std::move(server).value();
    std::fprintf(stderr, "  live view: %s\n", view_server->url().c_str());
  }
  const auto on_status = [live](const controllers::SessionState& s) {
    if (!live) return;
    std::fprintf(stderr, "\r  t %5.1f s | haptic %6.0f Hz | collision %6.0f Hz | force %5.2f N | pairs %6d ",
                 s.time_s, s.haptic_rate_hz, s.collision_rate_hz, norm(s.force_world), s.contact_pairs);
  };
  Status ran = Ok{};
  {
    const StopOnSignals stop_on_signals(**session);
    if (view_server) {
      ran = view_server->run_session(**session, seconds, on_status, trace);
    } else {
      ran = args.stepped ? (*session)->run_stepped(seconds, args.ticks_per_collision, trace)
                         : (*session)->run(seconds, on_status, trace);
    }
  }
  // the session has stopped (zero force): closing the browsers' connections may take a moment
  if (view_server) view_server->stop();
  if (live) std::fputc('\n', stderr);
  // a session that ended in an error keeps its trace too: it shows what happened up to the end
  const Status traced = trace_file ? trace_file->commit() : Status{Ok{}};
  if (!ran) return fail(ran.error().message);
  if (!traced) return fail(traced.error().message);
  return finish_run(args, (*session)->report());
}

}  // namespace

void add_run_command(CLI::App& app, CommandRunner& runner) {
  static RunArgs args;
  auto* r = app.add_subcommand("run", "run a haptic session: device, haptic thread, collision thread, forces");
  r->add_option("scene", args.scene, "scene file (JSON); default: the embedded bunny sweep")->check(CLI::ExistingFile);
  r->add_option("--seconds", args.seconds, "session length [s] (default: the scene's)")->check(CLI::PositiveNumber);
  r->add_flag("--json", args.json, "print one JSON object with the session's figures");
  r->add_option("--trace", args.trace, "write every haptic tick (state, requested and sent force) to this CSV");
  r->add_option("--plot", args.plot, "write a PNG of force, torque and collision rate over time");
  r->add_option("--haptic-hz", args.haptic_hz, "override the haptic rate [Hz]")->check(CLI::Range(1.0, 10000.0));
  r->add_option("--collision-hz", args.collision_hz, "override the collision rate [Hz] (0 = free-running)")->check(CLI::Range(0.0, 10000.0));
  r->add_option("--coherence-skin", args.coherence_skin,
                "override the volume query's frame-to-frame coherence skin [m] (0 = traverse every step)")
      ->check(CLI::Range(0.0, 1.0));
  r->add_option("--proxy", args.proxy, "render through the 6-DOF proxy (on) or the penalty path (off), whatever the scene says")
      ->check(CLI::IsMember({"on", "off"}));
  auto* held_flag = r->add_flag("--held-forces", args.held_forces,
                                "hold each collision frame's force until the next frame");
  auto* exact_flag =
      r->add_flag("--exact-tick", args.exact_tick,
                  "re-evaluate every held sphere pair each tick instead of the frame's local force model");
  r->add_flag(
       "--check-model", args.check_model,
       "measure: also re-evaluate every held pair each tick and report how far the model's force is from it")
      ->excludes(exact_flag)
      ->excludes(held_flag);
  exact_flag->excludes(held_flag);
  r->add_flag("--stepped", args.stepped, "deterministic run on one thread in simulated time");
  r->add_option("--ticks-per-collision", args.ticks_per_collision, "with --stepped: haptic ticks per collision step")
      ->default_val(4)->check(CLI::Range(1, 1000));
  auto* view_flag = r->add_flag("--view", args.view, "serve the live view of the session at http://127.0.0.1:PORT/ while it runs");
  r->add_option("--port", args.view_port, "with --view: the port of the live view (0: any free port)")
      ->default_val(7770)->check(CLI::Range(0, 65535))->needs(view_flag);
  view_flag->excludes(r->get_option("--stepped"));
  r->add_option("--device", args.device,
                "the tool's device instead of the scene's: DRIVER[:SELECTOR], e.g. forcedimension:1 or "
                "forcedimension:serial=11003 (see uh devices)");
  r->add_flag("--no-realtime", args.no_realtime,
              "do not ask for SCHED_FIFO for the haptic and collision threads (asked by default; refused without privileges)");
  r->callback([&runner] { runner = [] { return run_session(args); }; });
}

}  // namespace uh::cli
