#include "uh/devices/device_probe.hpp"

#include <fmt/format.h>

#include "uh/devices/force_dimension_device.hpp"

namespace uh::devices {

namespace {

DriverFindings probe_force_dimension() {
  DriverFindings f{.driver = "forcedimension", .runtime = force_dimension_library_search().vendor};
  const haptico::DeviceConfig none;
  f.looked_for = library_candidates(force_dimension_library_search(), none);
  auto library = SharedLibrary::load_first(force_dimension_library_search(), none);
  if (!library) {
    f.error = library.error().message;
    return f;
  }
  f.loaded_from = library->path();
  int (*count)() = nullptr;
  if (Status bound = library->bind(count, "dhdGetDeviceCount"); !bound) {
    f.error = bound.error().message;
    return f;
  }
  const int n = count();
  if (n <= 0) f.error = n == 0 ? "no device found" : "counting devices failed";
  for (int i = 0; i < n; ++i) {
    auto device = ForceDimensionDevice::create({{"library", f.loaded_from}, {"index", std::to_string(i)}});
    if (!device) continue;  // cannot happen: the config is the driver's own
    auto& fd = static_cast<ForceDimensionDevice&>(**device);
    if (Status opened = fd.open(); !opened) {
      f.error += fmt::format("{}device {}: {}", f.error.empty() ? "" : "; ", i, opened.error().message);
      continue;
    }
    f.devices.push_back({.selector = fmt::format("forcedimension:{}", i),
                         .model = fd.model(),
                         .serial = fd.serial_number() != 0 ? std::to_string(fd.serial_number()) : "",
                         .info = fd.info()});
    const Status closed = fd.close();
    (void)closed;  // the description is read; a failing close shows at the next open
  }
  return f;
}

}  // namespace

std::vector<DriverFindings> probe_drivers(const haptico::DeviceRegistry& registry) {
  std::vector<DriverFindings> out;
  for (const std::string& name : registry.names()) {
    if (name == "forcedimension") {
      out.push_back(probe_force_dimension());
    } else {
      out.push_back({.driver = name, .simulated = name.rfind("sim-", 0) == 0});
      if (!out.back().simulated) out.back().error = "this driver cannot be probed";
    }
  }
  return out;
}

Result<DeviceChoice> parse_device_choice(std::string_view text, const haptico::DeviceRegistry& registry) {
  const std::size_t colon = text.find(':');
  DeviceChoice choice{.driver = std::string(text.substr(0, colon))};
  if (!registry.contains(choice.driver)) {
    std::string known;
    for (const std::string& n : registry.names()) known += fmt::format("{}{}", known.empty() ? "" : ", ", n);
    return Error{fmt::format("--device: unknown driver '{}' (known drivers: {})", choice.driver, known)};
  }
  if (colon == std::string_view::npos) return choice;
  const std::string selector(text.substr(colon + 1));
  // the driver's usual selection key, for a bare value
  const char* usual = choice.driver == "forcedimension" ? "index" : nullptr;
  if (selector.empty()) return Error{fmt::format("--device {}: nothing after ':'", choice.driver)};
  const std::size_t eq = selector.find('=');
  if (eq == std::string::npos) {
    if (usual == nullptr)
      return Error{
          fmt::format("--device {}: this driver has no device to select; give KEY=VALUE for its settings",
                      choice.driver)};
    choice.selection.set(usual, selector);
  } else {
    if (eq == 0)
      return Error{fmt::format("--device {}: a setting name is missing before '='", choice.driver)};
    choice.selection.set(selector.substr(0, eq), selector.substr(eq + 1));
  }
  return choice;
}

}  // namespace uh::devices
