#include "uh/devices/open_haptics_device.hpp"

#include <fmt/format.h>
#include <cmath>
#include <cstdio>
#include <exception>
#include <thread>
#include <utility>

#include "hd_api.hpp"

namespace uh::devices {

namespace {

using haptico::DeviceStatus;
using Clock = TickRecorder::Clock;

// whether this thread is inside one of the device's servo frames (between hdBeginFrame and
// hdEndFrame), where state reads and the force write belong to the frame
thread_local bool t_in_frame = false;

// how long stop() waits for the servo thread to end the run before giving up on it
constexpr auto kStopWait = std::chrono::seconds(2);
// a run whose scheduler runs no frame for this long has stalled: the watchdog ends it, forces off
// (250 servo periods at 1 kHz: far beyond any scheduling hiccup, short for a hand on the stylus);
// config `stall_limit_ms` sets another, in [10, 10000]
constexpr double kDefaultStallLimitMs = 250.0;

// HD's frame (x right, y up, z toward the user) -> the field's (x toward the operator, y right, z up)
constexpr int kFromHd[3] = {2, 0, 1};  // field axis i is HD axis kFromHd[i]

Vec3 to_field(const double* hd) { return {hd[kFromHd[0]], hd[kFromHd[1]], hd[kFromHd[2]]}; }

void to_hd(const Vec3& field, double* hd) {
  hd[kFromHd[0]] = field.x;
  hd[kFromHd[1]] = field.y;
  hd[kFromHd[2]] = field.z;
}

double steady_now_s() { return std::chrono::duration<double>(Clock::now().time_since_epoch()).count(); }

}  // namespace

LibrarySearch open_haptics_library_search() {
#ifdef _WIN32
  std::vector<std::string> names{"hd.dll"};
#else
  std::vector<std::string> names{"libHD.so", "libHD.so.3.4", "libHD.so.3.4.0", "/usr/lib/libHD.so",
                                 "/opt/OpenHaptics/Developer/lib/libHD.so"};
#endif
  return {
      .vendor = "OpenHaptics HD", .environment_variable = "UH_OPENHAPTICS_LIBRARY", .install_names = names};
}

Result<std::unique_ptr<haptico::HapticDevice>> OpenHapticsDevice::create(
    const haptico::DeviceConfig& config) {
  constexpr std::string_view kName = "openhaptics";
  if (Status s = config.check_keys({"library", "name", "max_force_n", "stall_limit_ms"}, kName); !s)
    return s.error();
  auto force = config.number("max_force_n", 0.0);
  if (!force) return Error{fmt::format("{}: {}", kName, force.error().message)};
  if (config.has("max_force_n") && !(*force > 0.0)) return Error{"openhaptics: max_force_n must be positive"};
  if (config.has("name") && config.text("name", "").empty())
    return Error{"openhaptics: name is empty (leave it out for HD's default device)"};
  auto stall = config.number("stall_limit_ms", kDefaultStallLimitMs);
  if (!stall) return Error{fmt::format("{}: {}", kName, stall.error().message)};
  if (!(*stall >= 10.0 && *stall <= 10000.0)) return Error{"openhaptics: stall_limit_ms must be in [10, 10000]"};
  Selection sel{.name = config.text("name", ""),
                .max_force_n = *force,
                .stall_limit = std::chrono::milliseconds(std::lround(*stall))};
  return std::unique_ptr<haptico::HapticDevice>(new OpenHapticsDevice(config, std::move(sel)));
}

OpenHapticsDevice::OpenHapticsDevice(haptico::DeviceConfig config, Selection selection)
    : config_(std::move(config)), selection_(std::move(selection)) {
  info_.name = "openhaptics";
}

OpenHapticsDevice::~OpenHapticsDevice() {
  const Status closed = close();
  (void)closed;  // nothing left to report to
}

Status OpenHapticsDevice::setup_error(const char* what) {
  const hd::HDErrorInfo e = api_->hdGetError();
  if (e.errorCode == hd::kSuccess) return Ok{};
  return Error{fmt::format("openhaptics: {} failed: HD error 0x{:x}: {}", what, e.errorCode,
                           hd::error_text(*api_, e.errorCode))};
}

Status OpenHapticsDevice::open() {
  if (open_) return Ok{};
  if (Status s =
          load_vendor_api("openhaptics", open_haptics_library_search(), config_, &hd::bind, library_, api_);
      !s)
    return s;
  fault_.clear();
  forces_on_ = false;
  faulted_ = false;
  servo_dead_ = false;
  const hd::Api& api_ref = *api_;
  hhd_ = api_ref.hdInitDevice(selection_.name.empty() ? nullptr : selection_.name.c_str());
  const std::string which =
      selection_.name.empty() ? "the default device" : fmt::format("'{}'", selection_.name);
  if (Status s = setup_error(fmt::format("opening {} (hdInitDevice)", which).c_str());
      !s || hhd_ == hd::kInvalidHandle) {
    api_.reset();
    library_ = SharedLibrary{};
    return s ? Error{fmt::format("openhaptics: opening {} (hdInitDevice) failed without an HD error", which)}
             : s.error();
  }
  open_ = true;
  const auto refuse = [this](Error e) -> Status {
    release();
    return e;
  };
  api_ref.hdMakeCurrentDevice(hhd_);
  const hd::HDenum calibration = api_ref.hdCheckCalibration();
  if (calibration != hd::kCalibrationOk)
    return refuse(Error{fmt::format(
        "openhaptics: the calibration of {} is not OK (hdCheckCalibration returned 0x{:x}); calibrate "
        "the device with the vendor's tools (Touch Setup / Touch Diagnostic), then try again",
        which, calibration)});
  if (Status s = describe(); !s) return refuse(s.error());
  // HD clamps to its own nominal force as well: a second limit below ours
  api_ref.hdEnable(hd::kMaxForceClamping);
  api_ref.hdStartScheduler();
  if (Status s = setup_error("starting the scheduler (hdStartScheduler)"); !s) return refuse(s.error());
  return Ok{};
}

Status OpenHapticsDevice::describe() {
  const hd::Api& api = *api_;
  const char* model = api.hdGetString(hd::kDeviceModelType);
  const char* serial = api.hdGetString(hd::kDeviceSerialNumber);
  model_ = model != nullptr && *model != '\0' ? model : "unknown model";
  serial_ = serial != nullptr ? serial : "";
  double max_force = 0.0, max_torque_mnm = 0.0;
  double workspace[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  int output_dof = 0;
  api.hdGetDoublev(hd::kNominalMaxForce, &max_force);
  api.hdGetIntegerv(hd::kOutputDof, &output_dof);
  api.hdGetDoublev(hd::kUsableWorkspaceDimensions, workspace);
  if (output_dof == 6) api.hdGetDoublev(hd::kNominalMaxTorqueForce, &max_torque_mnm);
  if (Status s = setup_error("reading the device's description"); !s) return s;
  if (!(max_force > 0.0 && std::isfinite(max_force)))
    return Error{fmt::format("openhaptics: {} reports no valid nominal max force ({} N)", model_, max_force)};
  if (selection_.max_force_n > max_force)
    return Error{fmt::format("openhaptics: max_force_n {} N is above the {}'s nominal {} N",
                             selection_.max_force_n, model_, max_force)};
  double half_mm[3];
  for (int k = 0; k < 3; ++k) {
    centre_mm_[k] = 0.5 * (workspace[k] + workspace[k + 3]);
    half_mm[k] = 0.5 * (workspace[k + 3] - workspace[k]);
    if (!(half_mm[k] > 0.0 && std::isfinite(half_mm[k])))
      return Error{fmt::format("openhaptics: {} reports an empty usable workspace", model_)};
  }
  info_.name = fmt::format("openhaptics {}", model_);
  info_.dof_sensed = 6;  // every HD device reports the stylus' full transform
  info_.dof_actuated = output_dof == 6 ? 6 : 3;
  info_.max_force_n = selection_.max_force_n > 0.0 ? selection_.max_force_n : max_force;
  info_.max_torque_nm = output_dof == 6 ? max_torque_mnm * 1e-3 : 0.0;
  if (info_.dof_actuated == 6 && !(info_.max_torque_nm > 0.0 && std::isfinite(info_.max_torque_nm)))
    return Error{
        fmt::format("openhaptics: {} has 6 output DOF but reports no valid nominal max torque", model_)};
  info_.workspace_half_extents = to_field(half_mm) * 1e-3;
  info_.nominal_rate_hz = 1000.0;
  info_.model = model_;
  info_.serial = serial_;
  return Ok{};
}

void OpenHapticsDevice::release() {
  const hd::Api& api = *api_;
  api.hdStopScheduler();
  api.hdDisableDevice(hhd_);
  open_ = false;
  forces_on_ = false;
  api_.reset();
  library_ = SharedLibrary{};
}

Status OpenHapticsDevice::close() {
  if (!open_) return Ok{};
  stop();
  const hd::Api& api = *api_;
  // zero and forces off in one last frame; HD_FORCE_OUTPUT off again outside it, whatever happened
  in_own_frame([&] {
    const double zero[3] = {0.0, 0.0, 0.0};
    api.hdSetDoublev(hd::kCurrentForce, zero);
    if (info_.dof_actuated == 6) api.hdSetDoublev(hd::kCurrentTorque, zero);
  });
  api.hdDisable(hd::kForceOutput);
  const hd::HDErrorInfo e = api.hdGetError();
  const std::string message = e.errorCode == hd::kSuccess ? "" : hd::error_text(api, e.errorCode);
  release();
  if (!message.empty())
    return Error{fmt::format("openhaptics: {}: HD reported an error at close: {}", model_, message)};
  return Ok{};
}

template <typename Body>
void OpenHapticsDevice::in_own_frame(Body&& body) {
  if (servo_dead_) return;
  struct Call {
    OpenHapticsDevice* self;
    Body* body;
  } call{this, &body};
  api_->hdScheduleSynchronous(
      [](void* data) -> hd::HDCallbackCode {
        auto& c = *static_cast<Call*>(data);
        const hd::Api& api = *c.self->api_;
        api.hdBeginFrame(c.self->hhd_);
        t_in_frame = true;
        (*c.body)();
        t_in_frame = false;
        api.hdEndFrame(c.self->hhd_);
        c.self->check_frame_errors("a servo frame");
        return hd::kCallbackDone;
      },
      &call, hd::kMaxSchedulerPriority);
}

void OpenHapticsDevice::check_frame_errors(const char* where) {
  const hd::Api& api = *api_;
  const hd::HDErrorInfo e = api.hdGetError();
  if (e.errorCode == hd::kSuccess || faulted_.exchange(true)) return;
  // forces off at once; the HapticManager sends zero too from the next tick, which HD then ignores
  api.hdDisable(hd::kForceOutput);
  forces_on_ = false;
  char what[96];  // no allocation on the servo thread
  std::snprintf(what, sizeof what, "%s reported HD error 0x%x", where, e.errorCode);
  fault_.note(what, hd::error_text(api, e.errorCode));
}

haptico::DeviceState OpenHapticsDevice::read_state() {
  haptico::DeviceState s;
  if (!open_) return s;
  if (!t_in_frame) {
    s.status = DeviceStatus::kFault;  // a scheduler that no longer answers
    in_own_frame([&] { s = read_state(); });
    return s;
  }
  s.time_s = steady_now_s();
  if (faulted_) {
    s.status = DeviceStatus::kFault;
    return s;
  }
  const hd::Api& api = *api_;
  double transform[16] = {};
  double velocity[3] = {}, angular[3] = {};
  int buttons = 0;
  api.hdGetDoublev(hd::kCurrentTransform, transform);
  api.hdGetDoublev(hd::kCurrentVelocity, velocity);
  api.hdGetDoublev(hd::kCurrentAngularVelocity, angular);
  api.hdGetIntegerv(hd::kCurrentButtons, &buttons);
  // column-major: element (row r, column c) at c * 4 + r; translation in 12-14
  const double position_mm[3] = {transform[12] - centre_mm_[0], transform[13] - centre_mm_[1],
                                 transform[14] - centre_mm_[2]};
  Mat3 m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m.m[r][c] = transform[kFromHd[c] * 4 + kFromHd[r]];
  s.position = to_field(position_mm) * 1e-3;
  s.orientation = quat_from_rotation_matrix(m);
  s.linear_velocity = to_field(velocity) * 1e-3;
  s.angular_velocity = to_field(angular);
  s.buttons = static_cast<std::uint32_t>(buttons);
  s.status = DeviceStatus::kOk;
  return s;
}

void OpenHapticsDevice::command(const haptico::DeviceCommand& cmd) {
  if (!open_ || faulted_) return;
  if (!t_in_frame) {
    in_own_frame([&] { command(cmd); });
    return;
  }
  const hd::Api& api = *api_;
  Vec3 f = cmd.force;
  Vec3 t = info_.dof_actuated == 6 ? cmd.torque : Vec3{};
  // saturate as the motors would (a non-finite value becomes zero); the safety stage limited it already
  clamp_norm(f, info_.max_force_n);
  clamp_norm(t, info_.max_torque_nm);
  // forces come on with the first command that asks for one, which has been through the safety stage
  if (!forces_on_) {
    if (f == Vec3{} && t == Vec3{}) return;
    api.hdEnable(hd::kForceOutput);
    forces_on_ = true;
  }
  double out[3];
  to_hd(f, out);
  api.hdSetDoublev(hd::kCurrentForce, out);
  if (info_.dof_actuated == 6) {
    to_hd(t * 1e3, out);  // N m -> mN m
    api.hdSetDoublev(hd::kCurrentTorque, out);
  }
}

// ---- the servo clock ----

Status OpenHapticsDevice::start(double rate_hz, FixedRateLoop::Callback tick,
                                FixedRateLoop::ExitCallback on_exit) {
  if (!open_) return Error{"openhaptics: start: the device is not open"};
  if (running()) return Error{"openhaptics: the servo loop is already running"};
  if (servo_dead_) return Error{"openhaptics: the HD scheduler stopped answering; re-open the device"};
  const hd::Api& api = *api_;
  run_.begin(rate_hz, std::move(tick), std::move(on_exit));
  stop_requested_.store(false, std::memory_order_relaxed);
  // the rate is the scheduler's: set it with the scheduler stopped
  api.hdStopScheduler();
  api.hdSetSchedulerRate(static_cast<unsigned long>(std::lround(rate_hz)));
  api.hdStartScheduler();
  if (Status s = setup_error(fmt::format("setting the servo rate to {} Hz", rate_hz).c_str()); !s) return s;
  last_frame_ns_.store(Clock::now().time_since_epoch().count(), std::memory_order_relaxed);
  running_.store(true, std::memory_order_release);
  handle_ = api.hdScheduleAsynchronous(&OpenHapticsDevice::servo_frame, this, hd::kMaxSchedulerPriority);
  if (Status s = setup_error("scheduling the haptic tick (hdScheduleAsynchronous)"); !s) {
    running_.store(false, std::memory_order_release);
    return s;
  }
  watchdog_stop_.store(false, std::memory_order_relaxed);
  watchdog_ = std::thread([this] { watch(); });
  return Ok{};
}

unsigned int OpenHapticsDevice::servo_frame(void* self) {
  return static_cast<OpenHapticsDevice*>(self)->run_frame();
}

unsigned int OpenHapticsDevice::run_frame() {
  const hd::Api& api = *api_;
  const Clock::time_point start = Clock::now();
  last_frame_ns_.store(start.time_since_epoch().count(), std::memory_order_relaxed);
  api.hdBeginFrame(hhd_);
  t_in_frame = true;
  run_.begin_frame(start, start);
  bool done = stop_requested_.load(std::memory_order_acquire);
  if (!done) done = !run_.tick();
  if (done) {
    // the run's last act, inside this frame: the exit callback commands zero
    run_.end();
    if (forces_on_) api.hdDisable(hd::kForceOutput);
    forces_on_ = false;
  }
  t_in_frame = false;
  api.hdEndFrame(hhd_);
  check_frame_errors("the servo frame");
  run_.finish_frame(Clock::now());
  if (done) running_.store(false, std::memory_order_release);
  return done ? hd::kCallbackDone : hd::kCallbackContinue;
}

void OpenHapticsDevice::watch() {
  while (!watchdog_stop_.load(std::memory_order_acquire) && running()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const Clock::time_point last{Clock::duration(last_frame_ns_.load(std::memory_order_relaxed))};
    if (Clock::now() - last < selection_.stall_limit || !running()) continue;
    // the scheduler no longer runs frames: forces off without it, no more frames asked of it, and
    // the run over, so that the session ends now (the HapticManager latches it as a device fault)
    const hd::Api& api = *api_;
    api.hdUnschedule(handle_);
    api.hdDisable(hd::kForceOutput);
    servo_dead_.store(true);
    if (!faulted_.exchange(true))
      fault_.note("the HD scheduler stopped running servo frames",
                  fmt::format("no frame for {} ms; forces were disabled", selection_.stall_limit.count()).c_str());
    running_.store(false, std::memory_order_release);
    return;
  }
}

void OpenHapticsDevice::stop_watchdog() {
  watchdog_stop_.store(true, std::memory_order_release);
  if (watchdog_.joinable()) watchdog_.join();
}

void OpenHapticsDevice::stop() {
  // the watchdog first: from here only this thread decides about the run
  stop_watchdog();
  if (!running()) return;
  const hd::Api& api = *api_;
  stop_requested_.store(true, std::memory_order_release);
  const Clock::time_point give_up = Clock::now() + kStopWait;
  while (running() && Clock::now() < give_up) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (running()) {
    // the scheduler no longer runs frames: forces off without it, and no more frames asked of it
    api.hdUnschedule(handle_);
    api.hdDisable(hd::kForceOutput);
    servo_dead_.store(true);
    if (!faulted_.exchange(true))
      fault_.note("the HD scheduler stopped running servo frames", "no frame for 2 s; forces were disabled");
    running_.store(false, std::memory_order_release);
    return;
  }
  // the callback returned HD_CALLBACK_DONE: wait until HD has let go of it
  while (api.hdWaitForCompletion(handle_, hd::kWaitCheckStatus) != 0 && Clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

FixedRateLoopStats OpenHapticsDevice::stats() const { return run_.stats(running()); }

}  // namespace uh::devices
