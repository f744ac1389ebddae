// uh devices [--json]: the drivers, where each looked for its vendor runtime, the devices found.
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "uh/devices/device_probe.hpp"
#include "uh/devices/hardware_drivers.hpp"

namespace uh::cli {
namespace {

nlohmann::json to_json(const devices::DriverFindings& f) {
  nlohmann::json j = {{"driver", f.driver}, {"simulated", f.simulated}};
  if (f.simulated) return j;
  j["runtime"] = f.runtime;
  j["looked_for"] = nlohmann::json::array();
  for (const auto& c : f.looked_for) j["looked_for"].push_back({{"path", c.path}, {"from", c.origin}});
  j["loaded_from"] = f.loaded_from;
  j["error"] = f.error;
  j["devices"] = nlohmann::json::array();
  for (const auto& d : f.devices) {
    const auto& w = d.info.workspace_half_extents;
    j["devices"].push_back({{"selector", d.selector},
                            {"name", d.info.name},
                            {"model", d.model},
                            {"serial", d.serial},
                            {"dof_sensed", d.info.dof_sensed},
                            {"dof_actuated", d.info.dof_actuated},
                            {"max_force_n", d.info.max_force_n},
                            {"max_torque_nm", d.info.max_torque_nm},
                            {"workspace_half_extents_m", {w.x, w.y, w.z}},
                            {"rate_hz", d.info.nominal_rate_hz}});
  }
  return j;
}

void print_text(const devices::DriverFindings& f) {
  std::printf("%s: %s\n", f.driver.c_str(), f.runtime.c_str());
  for (const auto& c : f.looked_for)
    std::printf("  looked for %s (from %s)\n", c.path.c_str(), c.origin.c_str());
  // a service (haply) is connected to, a library loaded
  if (!f.loaded_from.empty())
    std::printf("  %s %s\n", f.loaded_from.rfind("ws://", 0) == 0 ? "connected to" : "loaded",
                f.loaded_from.c_str());
  for (const auto& d : f.devices) {
    const auto& w = d.info.workspace_half_extents;
    // what a device does not report is said so, never shown as a zero
    const std::string workspace =
        w == Vec3{} ? "workspace not reported"
                    : fmt::format("workspace +-{:.0f} x {:.0f} x {:.0f} mm", w.x * 1e3, w.y * 1e3, w.z * 1e3);
    const std::string rate = d.info.nominal_rate_hz > 0.0 ? fmt::format("{:.0f} Hz", d.info.nominal_rate_hz)
                                                          : std::string("rate set by the client");
    std::printf("  %s  %s, serial %s: %d-DOF sensed, %d-DOF force, max %.1f N, %s, %s\n", d.selector.c_str(),
                d.model.c_str(), d.serial.empty() ? "none" : d.serial.c_str(), d.info.dof_sensed,
                d.info.dof_actuated, d.info.max_force_n, workspace.c_str(), rate.c_str());
  }
  if (f.devices.empty()) std::printf("  no device: %s\n", f.error.c_str());
}

int list_devices(bool json) {
  const auto findings = devices::probe_drivers(devices::all_drivers());
  if (json) {
    nlohmann::json j = {{"drivers", nlohmann::json::array()}};
    for (const auto& f : findings) j["drivers"].push_back(to_json(f));
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::string simulated;
  for (const auto& f : findings) {
    if (f.simulated) {
      simulated += fmt::format("{}{}", simulated.empty() ? "" : ", ", f.driver);
      continue;
    }
    print_text(f);
  }
  std::printf("simulated (no hardware): %s\n", simulated.c_str());
  return 0;
}

}  // namespace

void add_devices_command(CLI::App& app, CommandRunner& runner) {
  static bool json = false;
  auto* d = app.add_subcommand(
      "devices", "list the device drivers, where each looked for its vendor runtime, and the devices found");
  d->add_flag("--json", json, "print one JSON object");
  d->callback([&runner] { runner = [] { return list_devices(json); }; });
}

}  // namespace uh::cli
