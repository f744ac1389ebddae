#pragma once
/// \file
/// TraceCsvWriter: the non-real-time thread that drains a HapticManager's trace into a CSV file.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "uh/core/atomic_file_writer.hpp"
#include "uh/core/result.hpp"

namespace uh::haptico {

class HapticManager;

/// Options of a TraceCsvWriter (options aggregate).
struct TraceCsvWriterOptions {
  double drain_period_s = 0.05;  ///< how often the queue is drained [s]; the queue must hold this many ticks
};

/// Drains HapticManager::drain_trace() into a CSV file (write_trace_header / write_trace_row
/// format) from its own thread, so that the haptic tick never does I/O. It is the trace queue's
/// only consumer while it runs: nobody else may call drain_trace() meanwhile.
///
/// Threads: start(), stop() and the destructor on one controlling thread; rows_written() from any.
/// Not real-time: it writes files and may block. The manager must outlive the writer.
class TraceCsvWriter {
 public:
  /// Starts a new trace for `path` (written beside it and moved into place by stop(), so an
  /// earlier file at `path` stays whole until then), writes the header and starts draining. An
  /// Error if the manager records no trace (trace_capacity 0) or the file cannot be created.
  static Result<std::unique_ptr<TraceCsvWriter>> start(HapticManager& manager, const std::string& path,
                                                       const TraceCsvWriterOptions& options = {});
  /// stop(), ignoring its result.
  ~TraceCsvWriter();
  TraceCsvWriter(const TraceCsvWriter&) = delete;
  TraceCsvWriter& operator=(const TraceCsvWriter&) = delete;

  /// Drains what is left (call after HapticManager::stop() to get every tick), joins the thread
  /// and puts the file in place (AtomicFileWriter::commit()); an Error names the file and why it
  /// could not be written. Idempotent: later calls return the first one's result.
  Status stop();
  /// Rows written so far.
  std::uint64_t rows_written() const { return rows_.load(std::memory_order_relaxed); }

 private:
  TraceCsvWriter(HapticManager& manager, AtomicFileWriter file, const TraceCsvWriterOptions& options);
  void run();

  HapticManager& manager_;
  AtomicFileWriter file_;
  Status written_ = Ok{};  // the commit's result (controlling thread only)
  TraceCsvWriterOptions options_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_requested_ = false;  // guarded by mutex_
  std::atomic<std::uint64_t> rows_{0};
  std::thread thread_;
};

}  // namespace uh::haptico
