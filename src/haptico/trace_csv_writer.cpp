#include "uh/haptico/trace_csv_writer.hpp"

#include <chrono>
#include <fmt/format.h>
#include <utility>

#include "uh/haptico/haptic_manager.hpp"

namespace uh::haptico {

Result<std::unique_ptr<TraceCsvWriter>> TraceCsvWriter::start(HapticManager& manager, const std::string& path,
                                                              const TraceCsvWriterOptions& options) {
  if (manager.options().trace_capacity == 0) {
    return Error{"trace writer: the haptic manager records no trace (set HapticManagerOptions::trace_capacity)"};
  }
  if (!(options.drain_period_s > 0.0)) return Error{"trace writer: drain_period_s must be positive"};
  auto file = AtomicFileWriter::create(path);
  if (!file) return file.error();
  write_trace_header(file->stream());
  return std::unique_ptr<TraceCsvWriter>(new TraceCsvWriter(manager, std::move(*file), options));
}

TraceCsvWriter::TraceCsvWriter(HapticManager& manager, AtomicFileWriter file, const TraceCsvWriterOptions& options)
    : manager_(manager), file_(std::move(file)), options_(options) {
  thread_ = std::thread([this] { run(); });
}

TraceCsvWriter::~TraceCsvWriter() { (void)stop(); }

Status TraceCsvWriter::stop() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_requested_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) {
    thread_.join();
    written_ = file_.commit();
  }
  return written_;
}

void TraceCsvWriter::run() {
  const auto period = std::chrono::duration<double>(options_.drain_period_s);
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    const bool stopping = wake_.wait_for(lock, period, [this] { return stop_requested_; });
    lock.unlock();
    rows_.fetch_add(manager_.drain_trace(file_.stream()), std::memory_order_relaxed);
    if (stopping) return;
    lock.lock();
  }
}

}  // namespace uh::haptico
