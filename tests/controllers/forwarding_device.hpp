#pragma once
// A test device around another: every call goes to the inner device. The fault tests derive from
// it and override the one call they change (a read that throws or faults, a command recorded).

#include <memory>
#include <string>
#include <utility>

#include "uh/haptico/haptic_device.hpp"

namespace uh::controllers::testing {

class ForwardingDevice : public haptico::HapticDevice {
 public:
  explicit ForwardingDevice(std::unique_ptr<haptico::HapticDevice> inner) : inner_(std::move(inner)) {}
  haptico::DeviceInfo info() const override { return inner_->info(); }
  Status open() override { return inner_->open(); }
  Status close() override { return inner_->close(); }
  haptico::DeviceState read_state() override { return inner_->read_state(); }
  void command(const haptico::DeviceCommand& cmd) override { inner_->command(cmd); }
  std::string fault_reason() override { return inner_->fault_reason(); }

 protected:
  haptico::HapticDevice& inner() { return *inner_; }

 private:
  std::unique_ptr<haptico::HapticDevice> inner_;
};

}  // namespace uh::controllers::testing
