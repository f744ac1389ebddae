#pragma once
// What the tests of every driver share: creating a device through the registry, loading a
// stand-in's script side, and reading back the forces a stand-in received.

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "uh/devices/hardware_drivers.hpp"
#include "uh/devices/shared_library.hpp"

namespace uh::devices::testing {

/// A device of `driver` from the registry of every driver (a failed test, and null, when refused).
inline std::unique_ptr<haptico::HapticDevice> make_device(const char* driver,
                                                          const haptico::DeviceConfig& config) {
  auto device = all_drivers().create(driver, config);
  EXPECT_TRUE(device) << (device ? "" : device.error().message);
  return device ? std::move(device).value() : nullptr;
}

/// Waits until `done` (no time limit on the result, only on the test's patience: 10 s).
template <typename Done>
void wait_for(Done done) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!done() && std::chrono::steady_clock::now() < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
}

/// The stand-in library at `path`, as the test loads it (the loader hands out one instance per
/// file, so the test and the driver see one simulation).
inline SharedLibrary load_standin(const char* path) {
  auto library = SharedLibrary::load(path);
  EXPECT_TRUE(library) << (library ? "" : library.error().message);
  return library ? std::move(library).value() : SharedLibrary{};
}

/// Forces a stand-in hands out as x, y, z triples: `copy(out, max)` copies up to `max` and returns
/// how many there are.
template <typename Copy>
std::vector<std::array<double, 3>> received_forces(Copy copy) {
  const int n = copy(nullptr, 0);
  std::vector<double> flat(3 * static_cast<std::size_t>(n));
  copy(flat.data(), n);
  std::vector<std::array<double, 3>> out(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]};
  return out;
}

}  // namespace uh::devices::testing
