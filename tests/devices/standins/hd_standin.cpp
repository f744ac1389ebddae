// A stand-in for OpenHaptics' libHD, built by the test suite only: it exports the documented HDAPI
// functions the openhaptics driver binds and runs its OWN scheduler thread (as HD does), so the
// driver's haptic tick really runs on the library's clock. The device is a mass on a spring in HD's
// frame (millimetres; x right, y up, z toward the user) moved by the force of each frame, and fails
// on script (standin_hd_set). Tests load it through the driver's real loading path and drive the
// script through the standin_hd_* functions.
#include <pthread.h>
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#define UH_EXPORT extern "C" __attribute__((visibility("default")))

namespace {

using HHD = unsigned int;
using HDenum = unsigned int;
using HDerror = unsigned int;
using HDSchedulerHandle = unsigned long;
using HDCallbackCode = unsigned int;
using HDboolean = unsigned char;
using Callback = HDCallbackCode (*)(void*);
struct HDErrorInfo {
  HDerror errorCode;
  int internalErrorCode;
  HHD hHD;
};

constexpr HHD kInvalidHandle = 0xFFFFFFFFu;
constexpr HDerror kCommError = 0x302;
constexpr HDerror kAlreadyInitiated = 0x301;
constexpr HDerror kInvalidEnum = 0x100;

struct Device {
  // mechanism: m x'' = k (rest - x) - b x' + F, in metres, one semi-implicit Euler step per servo tick
  double mass_kg = 0.1;
  double stiffness = 100.0;                   // [N/m]
  double damping = 2.0;                       // [N s/m]
  std::array<double, 3> rest{0.0, 0.0, 0.0};  // [m], HD frame
  std::array<double, 3> x{0.0, 0.0, 0.0};
  std::array<double, 3> v{0.0, 0.0, 0.0};
  std::array<double, 3> force{0.0, 0.0, 0.0};   // set in the current frame [N]
  std::array<double, 3> torque{0.0, 0.0, 0.0};  // [mN m]
  double rotation_y_rad = 0.0;                  // the stylus' orientation: a rotation about HD's y (up)
  std::array<double, 6> workspace_mm{-80.0, -60.0, -35.0, 80.0, 60.0, 35.0};
  double max_force_n = 3.3;
  double max_torque_mnm = 0.0;
  int output_dof = 3;
  std::string model = "Touch";
  std::string serial = "220-00042";
  int buttons = 0;
  bool initialised = false;
  bool force_output = false;
  bool clamping = false;
  bool broken = false;
  int init_count = 0;
  std::vector<std::array<double, 3>> received;  // every force of a frame while HD_FORCE_OUTPUT was on
};

struct World {
  Device device;
  bool fail_open = false;
  unsigned calibration = 0x5000;
  long error_after_frames = -1;  // frames after which the device breaks with HD_COMM_ERROR; -1: never
  long frames = 0;               // hdEndFrame calls since the device was initialised
  bool in_frame = false;
  std::vector<HDErrorInfo> errors;
  unsigned long rate_hz = 1000;
};

std::mutex g_mutex;  // the world
World g_world;

void push_error_locked(HDerror code) { g_world.errors.push_back({code, 0, 0}); }

void reset_locked() { g_world = World{}; }

void step_locked(double dt) {
  Device& d = g_world.device;
  for (std::size_t i = 0; i < 3; ++i) {
    const double applied = d.force_output && !d.broken ? d.force[i] : 0.0;
    const double f = d.stiffness * (d.rest[i] - d.x[i]) - d.damping * d.v[i] + applied;
    d.v[i] += f / d.mass_kg * dt;
    d.x[i] += d.v[i] * dt;
  }
}

// ---- the scheduler: its own thread, as in HD ----

struct Scheduled {
  Callback callback;
  void* data;
  HDSchedulerHandle handle;
  bool synchronous;
  bool done = false;
};

class Scheduler {
 public:
  ~Scheduler() { stop(); }

  void start(unsigned long rate_hz) {
    std::lock_guard lock(mutex_);
    if (thread_.joinable()) return;
    stopping_ = false;
    period_ = std::chrono::nanoseconds(1'000'000'000 / (rate_hz > 0 ? rate_hz : 1000));
    thread_ = std::thread([this] { run(); });
    thread_id_ = thread_.get_id();
  }
  void stop() {
    std::thread t;
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
      t = std::move(thread_);
    }
    wake_.notify_all();
    if (t.joinable()) t.join();
    std::lock_guard lock(mutex_);
    // synchronous calls still waiting never run: HD would not run them either
    for (Scheduled& s : queue_) s.done = true;
    queue_.erase(
        std::remove_if(queue_.begin(), queue_.end(), [](const Scheduled& s) { return s.synchronous; }),
        queue_.end());
    done_.notify_all();
  }
  bool running() {
    std::lock_guard lock(mutex_);
    return thread_.joinable();
  }
  bool on_scheduler_thread() const { return std::this_thread::get_id() == thread_id_.load(); }

  HDSchedulerHandle add(Callback cb, void* data) {
    std::lock_guard lock(mutex_);
    queue_.push_back({cb, data, ++next_handle_, false});
    return next_handle_;
  }
  void run_synchronously(Callback cb, void* data) {
    std::unique_lock lock(mutex_);
    if (!thread_.joinable()) return;  // HD runs nothing without its scheduler
    const HDSchedulerHandle h = ++next_handle_;
    queue_.push_back({cb, data, h, true});
    done_.wait(lock, [&] { return !contains_locked(h); });
  }
  void remove(HDSchedulerHandle h) {
    std::lock_guard lock(mutex_);
    std::erase_if(queue_, [h](const Scheduled& s) { return s.handle == h; });
  }
  bool active(HDSchedulerHandle h) {
    std::lock_guard lock(mutex_);
    return contains_locked(h);
  }
  // freezes the servo loop: no more frames run (a device that stops answering)
  void freeze(bool on) { frozen_.store(on); }

 private:
  bool contains_locked(HDSchedulerHandle h) const {
    for (const Scheduled& s : queue_)
      if (s.handle == h) return true;
    return false;
  }
  void run() {
    // a name a test of a whole program can wait for (as HD's servo thread, it is not the program's)
    pthread_setname_np(pthread_self(), "hd-servo");
    auto next = std::chrono::steady_clock::now();
    for (;;) {
      next += period_;
      std::this_thread::sleep_until(next);
      std::vector<Scheduled> batch;
      {
        std::lock_guard lock(mutex_);
        if (stopping_) return;
        if (frozen_.load()) continue;
        batch = queue_;
      }
      // callbacks run without the lock: they call HD functions and may schedule others
      std::vector<HDSchedulerHandle> finished;
      for (Scheduled& s : batch)
        if (s.callback(s.data) == 0 || s.synchronous) finished.push_back(s.handle);
      {
        std::lock_guard world(g_mutex);
        step_locked(1.0 / static_cast<double>(g_world.rate_hz));
      }
      {
        std::lock_guard lock(mutex_);
        std::erase_if(queue_, [&](const Scheduled& s) {
          return std::find(finished.begin(), finished.end(), s.handle) != finished.end();
        });
      }
      done_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable done_;
  std::condition_variable wake_;
  std::thread thread_;
  std::atomic<std::thread::id> thread_id_{};
  std::vector<Scheduled> queue_;
  HDSchedulerHandle next_handle_ = 0;
  std::chrono::nanoseconds period_{1'000'000};
  bool stopping_ = false;
  std::atomic<bool> frozen_{false};
};

Scheduler g_scheduler;

struct Init {
  Init() { reset_locked(); }
} g_init;

// the 4x4 column-major transform of the stylus [mm]
void transform_locked(double* out) {
  const Device& d = g_world.device;
  const double c = std::cos(d.rotation_y_rad), s = std::sin(d.rotation_y_rad);
  // rotation about y: rows (c 0 s), (0 1 0), (-s 0 c); element (r, col) at col * 4 + r
  const double m[16] = {c,
                        0.0,
                        -s,
                        0.0,  //
                        0.0,
                        1.0,
                        0.0,
                        0.0,  //
                        s,
                        0.0,
                        c,
                        0.0,  //
                        d.x[0] * 1e3,
                        d.x[1] * 1e3,
                        d.x[2] * 1e3,
                        1.0};
  std::memcpy(out, m, sizeof(m));
}

}  // namespace

// ---- the documented HD functions ----

UH_EXPORT HHD hdInitDevice(const char* name) {
  const std::lock_guard lock(g_mutex);
  Device& d = g_world.device;
  if (g_world.fail_open || (name != nullptr && std::string(name) != "Default Device")) {
    push_error_locked(kCommError);
    return kInvalidHandle;
  }
  if (d.initialised) {
    push_error_locked(kAlreadyInitiated);
    return kInvalidHandle;
  }
  d.initialised = true;
  d.force_output = false;
  d.broken = false;
  d.force = {0.0, 0.0, 0.0};
  d.x = d.rest;
  d.v = {0.0, 0.0, 0.0};
  ++d.init_count;
  g_world.frames = 0;
  return 1;
}

// For tests of whole programs (uh run stopped by a signal): when UH_STANDIN_HD_RECORD names a file,
// releasing the device writes there what it was last commanded, whether forces were still on, and
// the largest force it rendered
static void record_release_locked() {
  const char* path = std::getenv("UH_STANDIN_HD_RECORD");
  if (path == nullptr || *path == '\0') return;
  const Device& d = g_world.device;
  double largest = 0.0;
  for (const auto& f : d.received)
    largest = std::max(largest, std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
  if (std::FILE* out = std::fopen(path, "w"); out != nullptr) {
    std::fprintf(out, "force %.17g %.17g %.17g\nforce_output %d\nlargest_rendered %.17g\nframes %ld\n",
                 d.force[0], d.force[1], d.force[2], d.force_output ? 1 : 0, largest, g_world.frames);
    std::fclose(out);
  }
}

UH_EXPORT void hdDisableDevice(HHD) {
  const std::lock_guard lock(g_mutex);
  record_release_locked();
  g_world.device.initialised = false;
  g_world.device.force_output = false;
}

UH_EXPORT void hdMakeCurrentDevice(HHD) {}

UH_EXPORT HDErrorInfo hdGetError() {
  const std::lock_guard lock(g_mutex);
  if (g_world.errors.empty()) return {0, 0, 0};
  const HDErrorInfo e = g_world.errors.back();
  g_world.errors.pop_back();
  return e;
}

UH_EXPORT const char* hdGetErrorString(HDerror code) {
  switch (code) {
    case 0:
      return "No error";
    case kCommError:
      return "Communication error";
    case kAlreadyInitiated:
      return "Device already initiated";
    case kInvalidEnum:
      return "Invalid enumerant";
    default:
      return "Unknown error";
  }
}

UH_EXPORT void hdEnable(HDenum cap) {
  const std::lock_guard lock(g_mutex);
  if (cap == 0x4000)
    g_world.device.force_output = true;
  else if (cap == 0x4001)
    g_world.device.clamping = true;
  else
    push_error_locked(kInvalidEnum);
}

UH_EXPORT void hdDisable(HDenum cap) {
  const std::lock_guard lock(g_mutex);
  if (cap == 0x4000)
    g_world.device.force_output = false;
  else if (cap == 0x4001)
    g_world.device.clamping = false;
}

UH_EXPORT void hdStartScheduler() {
  unsigned long rate = 0;
  {
    const std::lock_guard lock(g_mutex);
    rate = g_world.rate_hz;
  }
  g_scheduler.start(rate);
}

UH_EXPORT void hdStopScheduler() { g_scheduler.stop(); }

UH_EXPORT void hdSetSchedulerRate(unsigned long hz) {
  const std::lock_guard lock(g_mutex);
  g_world.rate_hz = hz;
}

UH_EXPORT HDSchedulerHandle hdScheduleAsynchronous(Callback cb, void* data, unsigned short) {
  return g_scheduler.add(cb, data);
}

UH_EXPORT void hdScheduleSynchronous(Callback cb, void* data, unsigned short) {
  g_scheduler.run_synchronously(cb, data);
}

UH_EXPORT void hdUnschedule(HDSchedulerHandle h) { g_scheduler.remove(h); }

UH_EXPORT HDboolean hdWaitForCompletion(HDSchedulerHandle h, HDenum) { return g_scheduler.active(h) ? 1 : 0; }

UH_EXPORT void hdBeginFrame(HHD) {
  const std::lock_guard lock(g_mutex);
  g_world.in_frame = true;
}

UH_EXPORT void hdEndFrame(HHD) {
  const std::lock_guard lock(g_mutex);
  Device& d = g_world.device;
  g_world.in_frame = false;
  ++g_world.frames;
  if (g_world.error_after_frames >= 0 && g_world.frames > g_world.error_after_frames && !d.broken) {
    d.broken = true;
    push_error_locked(kCommError);
  }
  if (d.force_output && !d.broken) d.received.push_back(d.force);
}

UH_EXPORT void hdGetDoublev(HDenum what, double* out) {
  const std::lock_guard lock(g_mutex);
  const Device& d = g_world.device;
  switch (what) {
    case 0x2050:  // HD_CURRENT_POSITION [mm]
      for (std::size_t i = 0; i < 3; ++i) out[i] = d.x[i] * 1e3;
      return;
    case 0x2051:  // HD_CURRENT_VELOCITY [mm/s]
      for (std::size_t i = 0; i < 3; ++i) out[i] = d.v[i] * 1e3;
      return;
    case 0x2052:
      transform_locked(out);
      return;
    case 0x2053:  // HD_CURRENT_ANGULAR_VELOCITY: a still stylus, except a scripted spin about y
      out[0] = 0.0;
      out[1] = 0.0;
      out[2] = 0.0;
      return;
    case 0x2700:
      for (std::size_t i = 0; i < 3; ++i) out[i] = d.force[i];
      return;
    case 0x2603:
      *out = d.max_force_n;
      return;
    case 0x2622:
      *out = d.max_torque_mnm;
      return;
    case 0x2551:
      for (std::size_t i = 0; i < 6; ++i) out[i] = d.workspace_mm[i];
      return;
    default:
      push_error_locked(kInvalidEnum);
  }
}

UH_EXPORT void hdGetIntegerv(HDenum what, int* out) {
  const std::lock_guard lock(g_mutex);
  if (what == 0x2000)
    *out = g_world.device.buttons;
  else if (what == 0x2508)
    *out = g_world.device.output_dof;
  else
    push_error_locked(kInvalidEnum);
}

UH_EXPORT void hdSetDoublev(HDenum what, const double* in) {
  const std::lock_guard lock(g_mutex);
  Device& d = g_world.device;
  if (what == 0x2700) {
    for (std::size_t i = 0; i < 3; ++i) d.force[i] = in[i];
  } else if (what == 0x2701) {
    for (std::size_t i = 0; i < 3; ++i) d.torque[i] = in[i];
  } else {
    push_error_locked(kInvalidEnum);
  }
}

UH_EXPORT const char* hdGetString(HDenum what) {
  const std::lock_guard lock(g_mutex);
  if (what == 0x2501) return g_world.device.model.c_str();
  if (what == 0x2504) return g_world.device.serial.c_str();
  push_error_locked(kInvalidEnum);
  return nullptr;
}

UH_EXPORT HDenum hdCheckCalibration() {
  const std::lock_guard lock(g_mutex);
  return g_world.calibration;
}

// ---- the script and the observations, for tests ----

UH_EXPORT void standin_hd_reset() {
  g_scheduler.stop();
  g_scheduler.freeze(false);
  const std::lock_guard lock(g_mutex);
  reset_locked();
}

// keys: fail_open, calibration, error_after_frames, freeze, rest_x/y/z [m, HD frame], rotation_y_rad,
// workspace_min_x..z / workspace_max_x..z [mm], max_force_n, max_torque_mnm, output_dof, buttons, stiffness
UH_EXPORT int standin_hd_set(const char* key, double value) {
  const std::string k = key;
  if (k == "freeze") {
    g_scheduler.freeze(value != 0.0);
    return 0;
  }
  const std::lock_guard lock(g_mutex);
  Device& d = g_world.device;
  const char* axes = "xyz";
  for (std::size_t i = 0; i < 3; ++i) {
    if (k == std::string("rest_") + axes[i]) {
      d.x[i] = d.rest[i] = value;
      return 0;
    }
    if (k == std::string("workspace_min_") + axes[i]) {
      d.workspace_mm[i] = value;
      return 0;
    }
    if (k == std::string("workspace_max_") + axes[i]) {
      d.workspace_mm[i + 3] = value;
      return 0;
    }
  }
  if (k == "fail_open")
    g_world.fail_open = value != 0.0;
  else if (k == "calibration")
    g_world.calibration = static_cast<unsigned>(value);
  else if (k == "error_after_frames")
    g_world.error_after_frames = static_cast<long>(value);
  else if (k == "rotation_y_rad")
    d.rotation_y_rad = value;
  else if (k == "max_force_n")
    d.max_force_n = value;
  else if (k == "max_torque_mnm")
    d.max_torque_mnm = value;
  else if (k == "output_dof")
    d.output_dof = static_cast<int>(value);
  else if (k == "buttons")
    d.buttons = static_cast<int>(value);
  else if (k == "stiffness")
    d.stiffness = value;
  else
    return -1;
  return 0;
}

// keys: initialised, force_output, clamping, init_count, frames, rate_hz, force_x/y/z [N], torque_x/y/z [mN
// m], x, y, z [m] (HD frame), scheduler_running
UH_EXPORT double standin_hd_get(const char* key) {
  const std::string k = key;
  if (k == "scheduler_running") return g_scheduler.running() ? 1.0 : 0.0;
  const std::lock_guard lock(g_mutex);
  const Device& d = g_world.device;
  if (k == "initialised") return d.initialised ? 1.0 : 0.0;
  if (k == "force_output") return d.force_output ? 1.0 : 0.0;
  if (k == "clamping") return d.clamping ? 1.0 : 0.0;
  if (k == "init_count") return d.init_count;
  if (k == "frames") return static_cast<double>(g_world.frames);
  if (k == "rate_hz") return static_cast<double>(g_world.rate_hz);
  const char* axes = "xyz";
  for (std::size_t i = 0; i < 3; ++i) {
    if (k == std::string("force_") + axes[i]) return d.force[i];
    if (k == std::string("torque_") + axes[i]) return d.torque[i];
    if (k == std::string(1, axes[i])) return d.x[i];
  }
  return std::nan("");
}

// whether the caller runs on the stand-in's scheduler thread
UH_EXPORT int standin_hd_on_scheduler_thread() { return g_scheduler.on_scheduler_thread() ? 1 : 0; }

// copies up to `max` forces received while HD_FORCE_OUTPUT was on (x, y, z each, HD frame) into `out`;
// returns how many there are
UH_EXPORT int standin_hd_received(double* out, int max) {
  const std::lock_guard lock(g_mutex);
  const auto& r = g_world.device.received;
  for (std::size_t i = 0; i < r.size() && static_cast<int>(i) < max; ++i)
    for (std::size_t k = 0; k < 3; ++k) out[3 * i + k] = r[i][k];
  return static_cast<int>(r.size());
}
