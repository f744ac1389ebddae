#include "uh/haptico/device_registry.hpp"

#include <cmath>
#include <fmt/format.h>
#include <utility>

#include "uh/haptico/sim_circle_device.hpp"
#include "uh/haptico/sim_hand_device.hpp"
#include "uh/haptico/sim_line_device.hpp"
#include "uh/haptico/sim_raster_device.hpp"
#include "uh/haptico/sim_replay_device.hpp"

namespace uh::haptico {

DeviceRegistry DeviceRegistry::with_simulated_devices() {
  DeviceRegistry registry;
  const Status status = register_simulated_devices(registry);
  (void)status;  // cannot fail on an empty registry
  return registry;
}

Status DeviceRegistry::register_driver(const std::string& name, Factory factory) {
  if (name.empty()) return Error{"device registry: a driver name must not be empty"};
  if (!factory) return Error{fmt::format("device registry: driver '{}' has no factory", name)};
  if (factories_.count(name) != 0) return Error{fmt::format("device registry: driver '{}' is already registered", name)};
  factories_.emplace(name, std::move(factory));
  return Ok{};
}

Result<std::unique_ptr<HapticDevice>> DeviceRegistry::create(const std::string& name, const DeviceConfig& config) const {
  const auto it = factories_.find(name);
  if (it == factories_.end()) {
    std::string known;
    for (const auto& [n, f] : factories_) known += fmt::format("{}{}", known.empty() ? "" : ", ", n);
    return Error{fmt::format("unknown device driver '{}' (known drivers: {})", name, known.empty() ? "none" : known),
                 ErrorKind::kDevice};
  }
  // a driver's refusal is the device's, unless it told more (a file it reads, a device in use)
  auto device = it->second(config);
  if (!device) return device.error().classified(ErrorKind::kDevice);
  return device;
}

std::vector<std::string> DeviceRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& [n, f] : factories_) out.push_back(n);
  return out;
}

namespace {

// settings every simulated driver accepts
#define UH_SIM_COMMON_KEYS "rate_hz", "max_force_n", "max_torque_nm", "dof_actuated", "workspace"

Result<SimDeviceOptions> common_options(const DeviceConfig& c, std::string_view driver) {
  SimDeviceOptions o;
  auto rate = c.number("rate_hz", o.rate_hz);
  auto force = c.number("max_force_n", o.max_force_n);
  auto torque = c.number("max_torque_nm", o.max_torque_nm);
  auto dof = c.number("dof_actuated", o.dof_actuated);
  auto workspace = c.vec3("workspace", o.workspace_half_extents);
  for (const Error* e : {rate ? nullptr : &rate.error(), force ? nullptr : &force.error(),
                         torque ? nullptr : &torque.error(), dof ? nullptr : &dof.error(),
                         workspace ? nullptr : &workspace.error()}) {
    if (e != nullptr) return Error{fmt::format("{}: {}", driver, e->message)};
  }
  if (!(*rate > 0.0 && *rate <= 100000.0)) return Error{fmt::format("{}: rate_hz must be in (0, 100000]", driver)};
  if (!(*force > 0.0)) return Error{fmt::format("{}: max_force_n must be positive", driver)};
  if (!(*torque >= 0.0)) return Error{fmt::format("{}: max_torque_nm must not be negative", driver)};
  if (*dof != 3.0 && *dof != 6.0) return Error{fmt::format("{}: dof_actuated must be 3 or 6", driver)};
  o.rate_hz = *rate;
  o.max_force_n = *force;
  o.max_torque_nm = *torque;
  o.dof_actuated = static_cast<int>(*dof);
  o.workspace_half_extents = *workspace;
  return o;
}

template <typename T>
Result<T> field(Result<T> r, std::string_view driver) {
  if (!r) return Error{fmt::format("{}: {}", driver, r.error().message)};
  return r;
}

// fetches typed settings with early return on the first error
#define UH_TRY_ASSIGN(target, expr)                     \
  do {                                                  \
    auto uh_try_result = (expr);                        \
    if (!uh_try_result) return uh_try_result.error();   \
    (target) = std::move(uh_try_result).value();        \
  } while (false)

Result<std::unique_ptr<HapticDevice>> make_line(const DeviceConfig& c) {
  constexpr std::string_view kName = "sim-line";
  if (Status s = c.check_keys({UH_SIM_COMMON_KEYS, "start", "end", "duration_s", "bounce"}, kName); !s) return s.error();
  SimLineOptions o;
  UH_TRY_ASSIGN(o.device, common_options(c, kName));
  UH_TRY_ASSIGN(o.start, field(c.vec3("start", o.start), kName));
  UH_TRY_ASSIGN(o.end, field(c.vec3("end", o.end), kName));
  UH_TRY_ASSIGN(o.duration_s, field(c.number("duration_s", o.duration_s), kName));
  double bounce = 1.0;
  UH_TRY_ASSIGN(bounce, field(c.number("bounce", 1.0), kName));
  o.bounce = bounce != 0.0;
  if (!(o.duration_s > 0.0)) return Error{"sim-line: duration_s must be positive"};
  return std::unique_ptr<HapticDevice>(new SimLineDevice(o));
}

Result<std::unique_ptr<HapticDevice>> make_circle(const DeviceConfig& c) {
  constexpr std::string_view kName = "sim-circle";
  if (Status s = c.check_keys({UH_SIM_COMMON_KEYS, "center", "axis", "radius", "period_s"}, kName); !s) return s.error();
  SimCircleOptions o;
  UH_TRY_ASSIGN(o.device, common_options(c, kName));
  UH_TRY_ASSIGN(o.center, field(c.vec3("center", o.center), kName));
  UH_TRY_ASSIGN(o.axis, field(c.vec3("axis", o.axis), kName));
  UH_TRY_ASSIGN(o.radius, field(c.number("radius", o.radius), kName));
  UH_TRY_ASSIGN(o.period_s, field(c.number("period_s", o.period_s), kName));
  if (!(o.radius > 0.0)) return Error{"sim-circle: radius must be positive"};
  if (!(o.period_s > 0.0)) return Error{"sim-circle: period_s must be positive"};
  if (!(norm(o.axis) > 0.0)) return Error{"sim-circle: axis must not be the zero vector"};
  return std::unique_ptr<HapticDevice>(new SimCircleDevice(o));
}

Result<std::unique_ptr<HapticDevice>> make_raster(const DeviceConfig& c) {
  constexpr std::string_view kName = "sim-raster";
  if (Status s = c.check_keys({UH_SIM_COMMON_KEYS, "min", "max", "depth", "lines", "speed"}, kName); !s) return s.error();
  SimRasterOptions o;
  double lines = o.lines;
  UH_TRY_ASSIGN(o.device, common_options(c, kName));
  UH_TRY_ASSIGN(o.box_min, field(c.vec3("min", o.box_min), kName));
  UH_TRY_ASSIGN(o.box_max, field(c.vec3("max", o.box_max), kName));
  UH_TRY_ASSIGN(o.depth, field(c.number("depth", o.depth), kName));
  UH_TRY_ASSIGN(lines, field(c.number("lines", lines), kName));
  UH_TRY_ASSIGN(o.speed, field(c.number("speed", o.speed), kName));
  if (!(o.box_max.x > o.box_min.x && o.box_max.y >= o.box_min.y && o.box_max.z >= o.box_min.z)) {
    return Error{"sim-raster: max must be greater than min (x strictly, y and z at least equal)"};
  }
  if (!(lines >= 1.0 && lines <= 10000.0) || lines != std::floor(lines)) {
    return Error{"sim-raster: lines must be a whole number in [1, 10000]"};
  }
  if (!(o.speed > 0.0)) return Error{"sim-raster: speed must be positive"};
  o.lines = static_cast<int>(lines);
  return std::unique_ptr<HapticDevice>(new SimRasterDevice(o));
}

Result<std::unique_ptr<HapticDevice>> make_replay(const DeviceConfig& c) {
  constexpr std::string_view kName = "sim-replay";
  if (Status s = c.check_keys({UH_SIM_COMMON_KEYS, "file", "loop"}, kName); !s) return s.error();
  if (!c.has("file")) return Error{"sim-replay: the setting 'file' (a CSV trajectory) is required"};
  SimReplayOptions o;
  double loop = 0.0;
  UH_TRY_ASSIGN(o.device, common_options(c, kName));
  UH_TRY_ASSIGN(loop, field(c.number("loop", 0.0), kName));
  o.loop = loop != 0.0;
  auto samples = SimReplayDevice::load_csv(c.text("file", ""));
  if (!samples) return Error{fmt::format("sim-replay: {}", samples.error().message)};
  return std::unique_ptr<HapticDevice>(new SimReplayDevice(std::move(samples).value(), o));
}

Result<std::unique_ptr<HapticDevice>> make_hand(const DeviceConfig& c) {
  constexpr std::string_view kName = "sim-hand";
  if (Status s = c.check_keys({UH_SIM_COMMON_KEYS, "handle_mass_kg", "hand_stiffness", "hand_damping", "device_damping",
                               "target_start", "target_end", "duration_s", "bounce", "substeps"},
                              kName);
      !s) {
    return s.error();
  }
  SimHandOptions o;
  UH_TRY_ASSIGN(o.device, common_options(c, kName));
  UH_TRY_ASSIGN(o.handle_mass_kg, field(c.number("handle_mass_kg", o.handle_mass_kg), kName));
  UH_TRY_ASSIGN(o.hand_stiffness, field(c.number("hand_stiffness", o.hand_stiffness), kName));
  UH_TRY_ASSIGN(o.hand_damping, field(c.number("hand_damping", o.hand_damping), kName));
  UH_TRY_ASSIGN(o.device_damping, field(c.number("device_damping", o.device_damping), kName));
  UH_TRY_ASSIGN(o.target_start, field(c.vec3("target_start", o.target_start), kName));
  UH_TRY_ASSIGN(o.target_end, field(c.vec3("target_end", o.target_end), kName));
  UH_TRY_ASSIGN(o.duration_s, field(c.number("duration_s", o.duration_s), kName));
  double bounce = 0.0;
  UH_TRY_ASSIGN(bounce, field(c.number("bounce", bounce), kName));
  o.bounce = bounce != 0.0;
  double substeps = o.substeps;
  UH_TRY_ASSIGN(substeps, field(c.number("substeps", substeps), kName));
  if (!(substeps >= 1.0 && substeps <= 1000.0) || substeps != std::floor(substeps)) {
    return Error{"sim-hand: substeps must be a whole number in [1, 1000]"};
  }
  o.substeps = static_cast<int>(substeps);
  if (!(o.handle_mass_kg > 0.0)) return Error{"sim-hand: handle_mass_kg must be positive"};
  if (!(o.hand_stiffness >= 0.0 && o.hand_damping >= 0.0 && o.device_damping >= 0.0)) {
    return Error{"sim-hand: hand_stiffness, hand_damping and device_damping must not be negative"};
  }
  if (!(o.duration_s > 0.0)) return Error{"sim-hand: duration_s must be positive"};
  return std::unique_ptr<HapticDevice>(new SimHandDevice(o));
}

#undef UH_TRY_ASSIGN
#undef UH_SIM_COMMON_KEYS

}  // namespace

Status register_simulated_devices(DeviceRegistry& registry) {
  for (auto& [name, factory] : {std::pair<const char*, DeviceRegistry::Factory>{"sim-line", make_line},
                                {"sim-circle", make_circle},
                                {"sim-raster", make_raster},
                                {"sim-replay", make_replay},
                                {"sim-hand", make_hand}}) {
    if (Status s = registry.register_driver(name, factory); !s) return s;
  }
  return Ok{};
}

}  // namespace uh::haptico
