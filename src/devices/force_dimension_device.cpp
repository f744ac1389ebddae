#include "uh/devices/force_dimension_device.hpp"

#include <fmt/format.h>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <utility>

#include "dhd_api.hpp"

namespace uh::devices {

namespace {

using haptico::DeviceStatus;

// rated force and workspace of the models in the vendor's data sheets, by dhdGetSystemType
// (the driver never claims more than these; a model missing here must be given max_force_n)
struct Model {
  int system_type;
  double max_force_n;  // [N]
  Vec3 half_extents;   // [m]
  int dof_sensed;
};
constexpr Model kModels[] = {
    {60, 8.9, {0.05, 0.05, 0.05}, 3},       // Novint Falcon: 4 in cube
    {33, 12.0, {0.08, 0.08, 0.055}, 3},     // omega.3: 160 mm x 110 mm
    {63, 20.0, {0.2, 0.2, 0.13}, 3},        // delta.3: 400 mm x 260 mm
    {104, 20.0, {0.095, 0.095, 0.065}, 6},  // sigma.7 right: 190 mm x 130 mm
};

// The DHD devices this program holds open, by library and index, with their DHD IDs: a second
// device object (two tools, two hands) must neither open one of them again nor close it while it
// looks for a serial number. Setup only (open and close), any thread.
class HeldDevices {
 public:
  // the ID of device `index` of `library` if this program holds it open, else -1
  int id_of(const std::string& library, int index) {
    const std::lock_guard lock(mutex_);
    const auto it = held_.find({library, index});
    return it == held_.end() ? -1 : it->second;
  }
  void hold(const std::string& library, int index, int id) {
    const std::lock_guard lock(mutex_);
    held_[{library, index}] = id;
  }
  void release(const std::string& library, int id) {
    const std::lock_guard lock(mutex_);
    for (auto it = held_.begin(); it != held_.end(); ++it)
      if (it->first.first == library && it->second == id) {
        held_.erase(it);
        return;
      }
  }

 private:
  std::mutex mutex_;
  std::map<std::pair<std::string, int>, int> held_;
};

HeldDevices& held_devices() {
  static HeldDevices held;
  return held;
}

double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

LibrarySearch force_dimension_library_search() {
  // the SDK's file names: dhd64.dll on Windows (found on PATH or beside the program)
#ifdef _WIN32
  std::vector<std::string> names{"dhd64.dll", "dhd.dll"};
#else
  std::vector<std::string> names{"libdhd.so", "libdhd.so.3", "/usr/local/lib/libdhd.so",
                                 "/opt/forcedimension/lib/libdhd.so"};
#endif
  return {.vendor = "Force Dimension DHD",
          .environment_variable = "UH_FORCEDIMENSION_LIBRARY",
          .install_names = names};
}

Result<std::unique_ptr<haptico::HapticDevice>> ForceDimensionDevice::create(
    const haptico::DeviceConfig& config) {
  constexpr std::string_view kName = "forcedimension";
  if (Status s = config.check_keys({"library", "index", "serial", "max_force_n", "workspace"}, kName); !s)
    return s.error();
  if (config.has("index") && config.has("serial"))
    return Error{"forcedimension: give either index or serial, not both"};
  Selection sel;
  auto index = config.number("index", 0.0);
  auto serial = config.number("serial", -1.0);
  auto force = config.number("max_force_n", 0.0);
  auto workspace = config.vec3("workspace", Vec3{});
  for (const Error* e : {index ? nullptr : &index.error(), serial ? nullptr : &serial.error(),
                         force ? nullptr : &force.error(), workspace ? nullptr : &workspace.error()}) {
    if (e != nullptr) return Error{fmt::format("{}: {}", kName, e->message)};
  }
  if (!(*index >= 0.0 && *index <= 126.0 && *index == std::floor(*index)))
    return Error{"forcedimension: index must be a whole number in [0, 126]"};
  if (config.has("serial") && !(*serial >= 0.0 && *serial <= 65535.0 && *serial == std::floor(*serial)))
    return Error{"forcedimension: serial must be a whole number in [0, 65535]"};
  if (config.has("max_force_n") && !(*force > 0.0))
    return Error{"forcedimension: max_force_n must be positive"};
  if (config.has("workspace") && !(workspace->x > 0.0 && workspace->y > 0.0 && workspace->z > 0.0))
    return Error{"forcedimension: workspace half extents must be positive"};
  sel.index = static_cast<int>(*index);
  sel.serial = static_cast<long>(*serial);
  sel.max_force_n = *force;
  sel.workspace = *workspace;
  return std::unique_ptr<haptico::HapticDevice>(new ForceDimensionDevice(config, sel));
}

ForceDimensionDevice::ForceDimensionDevice(haptico::DeviceConfig config, Selection selection)
    : config_(std::move(config)), selection_(selection) {
  info_.name = "forcedimension";
}

ForceDimensionDevice::~ForceDimensionDevice() {
  const Status closed = close();
  (void)closed;  // nothing left to report to
}

Status ForceDimensionDevice::open() {
  if (open_) return Ok{};
  if (Status s = load_vendor_api("forcedimension", force_dimension_library_search(), config_, &dhd::bind,
                                 library_, api_);
      !s)
    return s;
  fault_.clear();
  forces_on_ = false;
  faulted_ = false;
  reads_ = 0;
  if (Status s = open_selected(); !s) {
    api_.reset();
    library_ = SharedLibrary{};
    return s;
  }
  open_ = true;
  if (Status s = describe(); !s) {
    const Status closed = close();
    (void)closed;  // the description's error is the one to report
    return s;
  }
  return Ok{};
}

Status ForceDimensionDevice::open_selected() {
  const dhd::Api& api = *api_;
  const int count = api.dhdGetDeviceCount();
  if (count < 0)
    return Error{fmt::format("forcedimension: counting devices failed: {}", dhd::last_error(api))};
  if (count == 0)
    return Error{
        fmt::format("forcedimension: no device found by {} (is it plugged in, powered, and may this "
                    "user open it? see docs/devices.md)",
                    library_.path())};
  if (selection_.serial < 0) {
    if (selection_.index >= count)
      return Error{fmt::format("forcedimension: index {} asked for, but {} device{} found", selection_.index,
                               count, count == 1 ? " is" : "s are")};
    if (held_devices().id_of(library_.path(), selection_.index) >= 0)
      return Error{
          fmt::format("forcedimension: device {} is open already (another tool of this program drives it)",
                      selection_.index),
          ErrorKind::kBusy};
    const int id = api.dhdOpenID(static_cast<char>(selection_.index));
    if (id < 0)
      return Error{fmt::format("forcedimension: opening device {} failed: {}", selection_.index,
                               dhd::last_error(api))};
    id_ = static_cast<char>(id);
    held_devices().hold(library_.path(), selection_.index, id);
    return Ok{};
  }
  // by serial: open each in turn, keep the one whose serial matches
  std::string seen;
  for (int i = 0; i < count; ++i) {
    // a device this program drives already is read where it is, never opened or closed again
    if (const int held = held_devices().id_of(library_.path(), i); held >= 0) {
      unsigned short sn = 0;
      if (api.dhdGetSerialNumber(&sn, static_cast<char>(held)) == 0 && sn == selection_.serial)
        return Error{
            fmt::format("forcedimension: the device with serial {} is open already (another tool of this "
                        "program drives it)",
                        selection_.serial),
            ErrorKind::kBusy};
      seen += fmt::format("{}serial {} (in use)", seen.empty() ? "" : ", ", sn);
      continue;
    }
    const int id = api.dhdOpenID(static_cast<char>(i));
    if (id < 0) {
      seen +=
          fmt::format("{}device {} would not open ({})", seen.empty() ? "" : ", ", i, dhd::last_error(api));
      continue;
    }
    unsigned short sn = 0;
    const bool read = api.dhdGetSerialNumber(&sn, static_cast<char>(id)) == 0;
    if (read && sn == selection_.serial) {
      id_ = static_cast<char>(id);
      held_devices().hold(library_.path(), i, id);
      return Ok{};
    }
    seen += read ? fmt::format("{}serial {}", seen.empty() ? "" : ", ", sn)
                 : fmt::format("{}device {} without a serial number", seen.empty() ? "" : ", ", i);
    api.dhdClose(static_cast<char>(id));
  }
  return Error{fmt::format("forcedimension: no device with serial {} (found: {})", selection_.serial, seen)};
}

Status ForceDimensionDevice::describe() {
  const dhd::Api& api = *api_;
  const int type = api.dhdGetSystemType(id_);
  const char* name = api.dhdGetSystemName(id_);
  model_ = name != nullptr ? name : fmt::format("system type {}", type);
  unsigned short sn = 0;
  serial_ = api.dhdGetSerialNumber(&sn, id_) == 0 ? sn : 0;
  const Model* model = nullptr;
  for (const Model& m : kModels)
    if (m.system_type == type) model = &m;
  if (model == nullptr && !(selection_.max_force_n > 0.0))
    return Error{
        fmt::format("forcedimension: {} (system type {}) is not in the driver's table of rated forces; set "
                    "max_force_n in tool.device.config to its rated force [N]",
                    model_, type)};
  if (model != nullptr && selection_.max_force_n > model->max_force_n)
    return Error{fmt::format("forcedimension: max_force_n {} N is above the {}'s rated {} N",
                             selection_.max_force_n, model_, model->max_force_n)};
  info_.name = fmt::format("forcedimension {}", model_);
  info_.dof_sensed = model != nullptr ? model->dof_sensed : 3;
  // forces only: torques (dhdSetForceAndTorque) are not driven
  info_.dof_actuated = 3;
  info_.max_force_n = selection_.max_force_n > 0.0 ? selection_.max_force_n : model->max_force_n;
  info_.max_torque_nm = 0.0;
  const bool given = selection_.workspace.x > 0.0;
  info_.workspace_half_extents = given              ? selection_.workspace
                                 : model != nullptr ? model->half_extents
                                                    : Vec3{0.05, 0.05, 0.05};
  info_.nominal_rate_hz = 4000.0;
  info_.model = model_;
  info_.serial = serial_ != 0 ? std::to_string(serial_) : "";
  return Ok{};
}

Status ForceDimensionDevice::close() {
  if (!open_) return Ok{};
  const dhd::Api& api = *api_;
  const bool zeroed = api.dhdSetForce(0.0, 0.0, 0.0, id_) >= 0;
  const double khz = api.dhdGetComFreq(id_);
  if (std::isfinite(khz) && khz > 0.0) com_rate_hz_.store(khz * 1000.0, std::memory_order_relaxed);
  // dhdStop: forces off and brakes on, whatever the zero above achieved
  const bool stopped = api.dhdStop(id_) >= 0;
  const std::string message = dhd::last_error(api);
  api.dhdClose(id_);
  held_devices().release(library_.path(), id_);
  open_ = false;
  forces_on_ = false;
  id_ = -1;
  api_.reset();
  library_ = SharedLibrary{};
  if (!zeroed && !stopped)
    return Error{fmt::format("forcedimension: {}: sending zero force and stopping failed at close: {}",
                             model_, message)};
  return Ok{};
}

void ForceDimensionDevice::fault(const char* what) {
  faulted_ = true;
  fault_.note(what, dhd::last_error(*api_));
  // forces off and brakes on at once; the manager sends zero too, which a stopped device ignores
  api_->dhdStop(id_);
  forces_on_ = false;
}

haptico::DeviceState ForceDimensionDevice::read_state() {
  haptico::DeviceState s;
  if (!open_) return s;
  s.time_s = steady_now_s();
  if (faulted_) {
    s.status = DeviceStatus::kFault;
    return s;
  }
  const dhd::Api& api = *api_;
  double px = 0.0, py = 0.0, pz = 0.0;
  double frame[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int pose = api.dhdGetPositionAndOrientationFrame(&px, &py, &pz, frame, id_);
  if (pose < 0) {
    fault("reading the position (dhdGetPositionAndOrientationFrame)");
    s.status = DeviceStatus::kFault;
    return s;
  }
  double vx = 0.0, vy = 0.0, vz = 0.0;
  const int velocity = api.dhdGetLinearVelocity(&vx, &vy, &vz, id_);
  if (velocity < 0) {
    fault("reading the velocity (dhdGetLinearVelocity)");
    s.status = DeviceStatus::kFault;
    return s;
  }
  // DHD_TIMEGUARD: the previous values came back, which are still the newest the device has
  if (pose == dhd::kTimeGuard || velocity == dhd::kTimeGuard) timeguard_.increment();
  Mat3 m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m.m[r][c] = frame[r][c];
  s.position = {px, py, pz};
  s.orientation = quat_from_rotation_matrix(m);
  s.linear_velocity = {vx, vy, vz};
  s.buttons = api.dhdGetButtonMask(id_);
  // sampled soon after the start (the first reads have no history) and every 1024 reads after
  if ((++reads_ & 1023u) == 64) {
    const double khz = api.dhdGetComFreq(id_);
    if (std::isfinite(khz)) com_rate_hz_.store(khz * 1000.0, std::memory_order_relaxed);
  }
  s.status = DeviceStatus::kOk;
  return s;
}

void ForceDimensionDevice::command(const haptico::DeviceCommand& cmd) {
  if (!open_ || faulted_) return;
  const dhd::Api& api = *api_;
  // forces come on with the first command, which has been through the safety stage
  if (!forces_on_) {
    if (api.dhdEnableForce(dhd::kOn, id_) < 0) {
      fault("enabling forces (dhdEnableForce)");
      return;
    }
    forces_on_ = true;
  }
  Vec3 f = cmd.force;
  // saturate as the motors would (a non-finite force becomes zero); the safety stage has limited it already
  clamp_norm(f, info_.max_force_n);
  const int rc = api.dhdSetForce(f.x, f.y, f.z, id_);
  if (rc < 0) {
    fault("sending the force (dhdSetForce)");
  } else if (rc == dhd::kMotorSaturated) {
    saturated_.increment();
  }
}

}  // namespace uh::devices
