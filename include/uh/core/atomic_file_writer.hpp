#pragma once
/// \file
/// AtomicFileWriter: the one way the project writes an output file (.ist files, PNG previews and
/// plots, traces, query results, cached assets).
///
/// The content goes to a temporary file beside the target (same directory, hidden name); commit()
/// flushes it, fsyncs it, renames it over the target and fsyncs the directory. Readers therefore
/// see either the old file or the complete new one, after a crash or power loss too, and a failure
/// at any step (disk full, file size limit, a vanished directory) leaves the old file as it was
/// and removes the temporary. Setup and non-real-time threads only: it writes files and may block.

#include <filesystem>
#include <memory>
#include <ostream>
#include <string_view>

#include "uh/core/result.hpp"

namespace uh {

class AtomicFileWriter {
 public:
  /// Creates the temporary file beside `target`. Error (naming `target` and the reason) when the
  /// directory does not exist or is not writable; nothing is touched then.
  static Result<AtomicFileWriter> create(const std::filesystem::path& target);

  AtomicFileWriter(AtomicFileWriter&&) noexcept;
  AtomicFileWriter& operator=(AtomicFileWriter&&) noexcept;
  /// Removes the temporary file unless commit() succeeded: an abandoned write changes nothing.
  ~AtomicFileWriter();

  /// Where to write the content. Write errors are kept and reported by commit().
  std::ostream& stream();
  /// Makes the content the target's: flush, fsync, rename over the target, fsync the directory.
  /// On failure the target is unchanged (the old file, or none), the temporary is removed and the
  /// Error names the target and the reason ("out.csv: write failed: No space left on device").
  /// Call once.
  Status commit();

  const std::filesystem::path& target() const;

 private:
  struct State;
  explicit AtomicFileWriter(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

/// Writes `bytes` as the whole content of `target`, atomically (AtomicFileWriter).
Status write_file_atomically(const std::filesystem::path& target, std::string_view bytes);

}  // namespace uh
