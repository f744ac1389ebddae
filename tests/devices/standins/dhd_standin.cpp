// A stand-in for Force Dimension's libdhd, built by the test suite only: it exports the documented
// DHD functions the forcedimension driver binds, simulates each device as a mass on a spring
// moved by the commanded force, and fails on script (standin_dhd_set). Tests load it through the
// driver's real loading path and drive the script through the standin_dhd_* functions.
#include <array>
#include <cmath>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#define UH_EXPORT extern "C" __attribute__((visibility("default")))

namespace {

struct Device {
  // mechanism: m x'' = k (rest - x) - b x' + F (enabled forces only); explicit steps of dt per dhdSetForce
  double mass_kg = 0.2;
  double stiffness = 200.0;  // [N/m]
  double damping = 4.0;      // [N s/m]
  std::array<double, 3> rest{0.0, 0.0, 0.0};
  std::array<double, 3> x{0.0, 0.0, 0.0};
  std::array<double, 3> v{0.0, 0.0, 0.0};
  std::array<double, 3> force{0.0, 0.0, 0.0};  // as applied (after saturation)
  double rotation_z_rad = 0.0;                 // orientation frame: a rotation about z
  double saturation_n = 1e9;                   // |F| above which dhdSetForce clips and returns 2
  int system_type = 33;                        // omega.3
  unsigned short serial = 0;
  bool open = false;
  bool forces_enabled = false;
  unsigned buttons = 0;
  int stop_calls = 0;
  int open_count = 0;
  long force_calls = 0;
  std::vector<std::array<double, 3>> received;  // every dhdSetForce argument while forces were on
};

struct World {
  std::vector<Device> devices;
  double dt_s = 0.001;
  bool fail_open = false;
  long comm_error_after = -1;  // dhdSetForce calls after which every call fails; -1: never
  long timeguard_every = 0;    // every n-th position read returns DHD_TIMEGUARD; 0: never
  long calls_since_open = 0;
  long reads = 0;
  bool comm_broken = false;
  const char* last_error = "no error";  // literals only: callers keep the pointer
};

std::mutex g_mutex;
World g_world;

void reset_locked() {
  g_world = World{};
  g_world.devices.resize(1);
  g_world.devices[0].serial = 11001;
}

struct Init {
  Init() { reset_locked(); }
} g_init;

Device* device_locked(char id) {
  const int i = static_cast<int>(id);
  if (i < 0 || i >= static_cast<int>(g_world.devices.size()) ||
      !g_world.devices[static_cast<std::size_t>(i)].open) {
    g_world.last_error = "invalid device ID";
    return nullptr;
  }
  return &g_world.devices[static_cast<std::size_t>(i)];
}

bool broken_locked() {
  if (!g_world.comm_broken) return false;
  g_world.last_error = "communication error (USB transfer failed)";
  return true;
}

void integrate_locked(Device& d) {
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const double f =
        d.stiffness * (d.rest[i] - d.x[i]) - d.damping * d.v[i] + (d.forces_enabled ? d.force[i] : 0.0);
    // semi-implicit Euler: stable for this spring at 1 ms
    d.v[i] += f / d.mass_kg * g_world.dt_s;
    d.x[i] += d.v[i] * g_world.dt_s;
  }
}

}  // namespace

// ---- the documented DHD functions ----

UH_EXPORT int dhdGetDeviceCount() {
  const std::lock_guard lock(g_mutex);
  return static_cast<int>(g_world.devices.size());
}

UH_EXPORT int dhdOpenID(char index) {
  const std::lock_guard lock(g_mutex);
  const int i = static_cast<int>(index);
  if (g_world.fail_open) {
    g_world.last_error = "no device found (USB device not responding)";
    return -1;
  }
  if (i < 0 || i >= static_cast<int>(g_world.devices.size())) {
    g_world.last_error = "no such device";
    return -1;
  }
  Device& d = g_world.devices[static_cast<std::size_t>(i)];
  d.open = true;
  d.forces_enabled = false;
  d.force = {0.0, 0.0, 0.0};
  d.x = d.rest;
  d.v = {0.0, 0.0, 0.0};
  ++d.open_count;
  g_world.calls_since_open = 0;
  g_world.comm_broken = false;
  return i;
}

UH_EXPORT int dhdClose(char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  if (d == nullptr) return -1;
  d->open = false;
  d->forces_enabled = false;
  return 0;
}

UH_EXPORT int dhdStop(char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  if (d == nullptr) return -1;
  // forces off and brakes on, even after a communication error (the brake is local)
  d->forces_enabled = false;
  d->force = {0.0, 0.0, 0.0};
  ++d->stop_calls;
  return 0;
}

UH_EXPORT int dhdGetSystemType(char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  return d == nullptr ? -1 : d->system_type;
}

UH_EXPORT const char* dhdGetSystemName(char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  if (d == nullptr) return nullptr;
  switch (d->system_type) {
    case 33:
      return "omega.3";
    case 60:
      return "Falcon";
    case 63:
      return "delta.3";
    case 104:
      return "sigma.7";
    default:
      return "prototype";
  }
}

UH_EXPORT int dhdGetSerialNumber(unsigned short* sn, char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  if (d == nullptr || sn == nullptr) return -1;
  *sn = d->serial;
  return 0;
}

UH_EXPORT int dhdEnableForce(unsigned char on, char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  if (d == nullptr || broken_locked()) return -1;
  d->forces_enabled = on != 0;
  return 0;
}

UH_EXPORT int dhdGetPositionAndOrientationFrame(double* px, double* py, double* pz, double matrix[3][3],
                                                char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  if (d == nullptr || broken_locked()) return -1;
  *px = d->x[0];
  *py = d->x[1];
  *pz = d->x[2];
  const double c = std::cos(d->rotation_z_rad), s = std::sin(d->rotation_z_rad);
  const double m[3][3] = {{c, -s, 0.0}, {s, c, 0.0}, {0.0, 0.0, 1.0}};
  std::memcpy(matrix, m, sizeof(m));
  ++g_world.reads;
  return g_world.timeguard_every > 0 && g_world.reads % g_world.timeguard_every == 0 ? 1 : 0;
}

UH_EXPORT int dhdGetLinearVelocity(double* vx, double* vy, double* vz, char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  if (d == nullptr || broken_locked()) return -1;
  *vx = d->v[0];
  *vy = d->v[1];
  *vz = d->v[2];
  return 0;
}

UH_EXPORT unsigned int dhdGetButtonMask(char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  return d == nullptr ? 0u : d->buttons;
}

UH_EXPORT int dhdSetForce(double fx, double fy, double fz, char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  if (d == nullptr) return -1;
  ++g_world.calls_since_open;
  if (g_world.comm_error_after >= 0 && g_world.calls_since_open > g_world.comm_error_after)
    g_world.comm_broken = true;
  if (broken_locked()) return -1;
  ++d->force_calls;
  if (d->forces_enabled) d->received.push_back({fx, fy, fz});
  const double n = std::sqrt(fx * fx + fy * fy + fz * fz);
  const double scale = n > d->saturation_n ? d->saturation_n / n : 1.0;
  d->force = {fx * scale, fy * scale, fz * scale};
  integrate_locked(*d);
  return scale < 1.0 ? 2 : 0;
}

UH_EXPORT double dhdGetComFreq(char id) {
  const std::lock_guard lock(g_mutex);
  Device* d = device_locked(id);
  return d == nullptr ? 0.0 : 1.0 / g_world.dt_s * 1e-3;  // kHz
}

UH_EXPORT const char* dhdErrorGetLastStr() {
  const std::lock_guard lock(g_mutex);
  return g_world.last_error;
}

UH_EXPORT void dhdGetSDKVersion(int* major, int* minor, int* release, int* revision) {
  *major = 3;
  *minor = 17;
  *release = 0;
  *revision = 0;
}

// ---- the script and the observations, for tests ----

UH_EXPORT void standin_dhd_reset() {
  const std::lock_guard lock(g_mutex);
  reset_locked();
}

// keys: devices, dt_s, fail_open, comm_error_after, break_now, timeguard_every (device -1); system_type,
// serial, saturation_n, rest_x/y/z, stiffness, mass_kg, damping, rotation_z_rad, buttons (device >= 0)
UH_EXPORT int standin_dhd_set(int device, const char* key, double value) {
  const std::lock_guard lock(g_mutex);
  const std::string k = key;
  if (device < 0) {
    if (k == "devices") {
      g_world.devices.resize(static_cast<std::size_t>(value));
      for (std::size_t i = 0; i < g_world.devices.size(); ++i)
        g_world.devices[i].serial = static_cast<unsigned short>(11001 + i);
    } else if (k == "dt_s") {
      g_world.dt_s = value;
    } else if (k == "fail_open") {
      g_world.fail_open = value != 0.0;
    } else if (k == "comm_error_after") {
      g_world.comm_error_after = static_cast<long>(value);
    } else if (k == "break_now") {
      g_world.comm_broken = value != 0.0;
    } else if (k == "timeguard_every") {
      g_world.timeguard_every = static_cast<long>(value);
    } else {
      return -1;
    }
    return 0;
  }
  if (device >= static_cast<int>(g_world.devices.size())) return -1;
  Device& d = g_world.devices[static_cast<std::size_t>(device)];
  if (k == "system_type")
    d.system_type = static_cast<int>(value);
  else if (k == "serial")
    d.serial = static_cast<unsigned short>(value);
  else if (k == "saturation_n")
    d.saturation_n = value;
  else if (k == "rest_x")
    d.x[0] = d.rest[0] = value;
  else if (k == "rest_y")
    d.x[1] = d.rest[1] = value;
  else if (k == "rest_z")
    d.x[2] = d.rest[2] = value;
  else if (k == "stiffness")
    d.stiffness = value;
  else if (k == "mass_kg")
    d.mass_kg = value;
  else if (k == "damping")
    d.damping = value;
  else if (k == "rotation_z_rad")
    d.rotation_z_rad = value;
  else if (k == "buttons")
    d.buttons = static_cast<unsigned>(value);
  else
    return -1;
  return 0;
}

// keys: open, forces_enabled, stop_calls, open_count, force_calls, force_x/y/z, x, y, z
UH_EXPORT double standin_dhd_get(int device, const char* key) {
  const std::lock_guard lock(g_mutex);
  if (device < 0 || device >= static_cast<int>(g_world.devices.size())) return std::nan("");
  const Device& d = g_world.devices[static_cast<std::size_t>(device)];
  const std::string k = key;
  if (k == "open") return d.open ? 1.0 : 0.0;
  if (k == "forces_enabled") return d.forces_enabled ? 1.0 : 0.0;
  if (k == "stop_calls") return d.stop_calls;
  if (k == "open_count") return d.open_count;
  if (k == "force_calls") return static_cast<double>(d.force_calls);
  if (k == "force_x") return d.force[0];
  if (k == "force_y") return d.force[1];
  if (k == "force_z") return d.force[2];
  if (k == "x") return d.x[0];
  if (k == "y") return d.x[1];
  if (k == "z") return d.x[2];
  return std::nan("");
}

// copies up to `max` forces received while forces were on (x, y, z each) into `out`; returns how many there
// are
UH_EXPORT int standin_dhd_received(int device, double* out, int max) {
  const std::lock_guard lock(g_mutex);
  if (device < 0 || device >= static_cast<int>(g_world.devices.size())) return -1;
  const auto& r = g_world.devices[static_cast<std::size_t>(device)].received;
  for (std::size_t i = 0; i < r.size() && static_cast<int>(i) < max; ++i)
    for (std::size_t k = 0; k < 3; ++k) out[3 * i + k] = r[i][k];
  return static_cast<int>(r.size());
}
