#include "uh/devices/device_probe.hpp"

#include <fmt/format.h>

#include "uh/devices/force_dimension_device.hpp"
#ifdef UH_DEVICES_HAPLY
#include "uh/devices/haply_device.hpp"
#endif
#include "uh/devices/open_haptics_device.hpp"

namespace uh::devices {

namespace {

// the findings of loading `driver`'s runtime the way it would to open a device without a scene
// config; `library` is what loaded (nothing when f.error says why)
DriverFindings find_runtime(const char* driver, const LibrarySearch& search, SharedLibrary& library) {
  DriverFindings f{.driver = driver, .runtime = search.vendor};
  const haptico::DeviceConfig none;
  f.looked_for = library_candidates(search, none);
  auto loaded = SharedLibrary::load_first(search, none);
  if (!loaded) {
    f.error = loaded.error().message;
    return f;
  }
  library = std::move(loaded).value();
  f.loaded_from = library.path();
  return f;
}

DriverFindings probe_force_dimension() {
  SharedLibrary library;
  DriverFindings f = find_runtime("forcedimension", force_dimension_library_search(), library);
  if (!library.loaded()) return f;
  int (*count)() = nullptr;
  if (Status bound = library.bind(count, "dhdGetDeviceCount"); !bound) {
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

// HD opens one device by its configured name; the probe opens HD's default device
DriverFindings probe_open_haptics() {
  SharedLibrary library;
  DriverFindings f = find_runtime("openhaptics", open_haptics_library_search(), library);
  if (!library.loaded()) return f;
  auto device = OpenHapticsDevice::create({{"library", f.loaded_from}});
  if (!device) return f;  // cannot happen: the config is the driver's own
  auto& oh = static_cast<OpenHapticsDevice&>(**device);
  if (Status opened = oh.open(); !opened) {
    f.error = opened.error().message;
    return f;
  }
  f.devices.push_back(
      {.selector = "openhaptics", .model = oh.model(), .serial = oh.serial_number(), .info = oh.info()});
  const Status closed = oh.close();
  (void)closed;  // the description is read; a failing close shows at the next open
  return f;
}

#ifdef UH_DEVICES_HAPLY
// the service's inventory lists every Inverse3 it runs; each is opened for its description
DriverFindings probe_haply() {
  DriverFindings f{.driver = "haply", .runtime = "Haply Inverse Service"};
  const haptico::DeviceConfig none;
  f.looked_for = {haply_service_url(none)};
  auto first = HaplyDevice::create(none);
  if (!first) {
    f.error = first.error().message;  // a malformed UH_HAPLY_URL
    return f;
  }
  auto& service = static_cast<HaplyDevice&>(**first);
  if (Status opened = service.open(); !opened) {
    f.error = opened.error().message;
    return f;
  }
  f.loaded_from = service.url().path;
  const std::vector<std::string> ids = service.inventory();
  const Status closed = service.close();
  (void)closed;  // closing a connection reports nothing
  for (const std::string& id : ids) {
    auto device = HaplyDevice::create({{"device_id", id}});
    if (!device) continue;  // cannot happen: the id came from the service's own inventory check
    auto& haply = static_cast<HaplyDevice&>(**device);
    if (Status opened = haply.open(); !opened) {
      f.error += fmt::format("{}{}", f.error.empty() ? "" : "; ", opened.error().message);
      continue;
    }
    f.devices.push_back(
        {.selector = fmt::format("haply:{}", id), .model = "Inverse3", .serial = id, .info = haply.info()});
    const Status done = haply.close();
    (void)done;
  }
  return f;
}
#endif

}  // namespace

std::vector<DriverFindings> probe_drivers(const haptico::DeviceRegistry& registry) {
  std::vector<DriverFindings> out;
  for (const std::string& name : registry.names()) {
    if (name == "forcedimension") {
      out.push_back(probe_force_dimension());
    } else if (name == "openhaptics") {
      out.push_back(probe_open_haptics());
#ifdef UH_DEVICES_HAPLY
    } else if (name == "haply") {
      out.push_back(probe_haply());
#endif
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
  const char* usual = choice.driver == "forcedimension" ? "index"
                      : choice.driver == "openhaptics"  ? "name"
                      : choice.driver == "haply"        ? "device_id"
                                                        : nullptr;
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
