// SPDX-License-Identifier: MIT
// AtomicFile: a buffered text sink that writes <target>.tmp.<pid> and renames it onto the target
// on commit(). Every writer of plaf goes through it, so a writer that fails half-way never leaves
// a partial file, nor a stale temporary: the destructor removes the temporary unless committed.
//
// Numbers are formatted with std::to_chars into one large buffer (no per-number allocation);
// doubles use the shortest form that reads back to the same bits, which is at most 17
// significant digits. Two AtomicFiles of one process must not target the same path at once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <vector>

namespace plaf {
inline namespace io {

// Files and folders removed when the process is stopped by SIGINT or SIGTERM, once
// install_signal_cleanup() ran: the temporaries of open AtomicFiles (registered by them) and an
// output set not yet complete (OutputSet, output_set.h). The handler unlinks the files, removes
// the folders (files first), then lets the signal end the process as it would have.
namespace cleanup {
// Registers a path; returns its slot (-1 when every slot is taken or the path is too long: it is
// then not removed on a signal, as before).
int add(const std::filesystem::path& path, bool folder = false);
void release(int slot);  // a no-op for -1
// Releases every slot whose path lies in `folder` (and the folder's own).
void release_under(const std::filesystem::path& folder);
}  // namespace cleanup
// Installs the SIGINT and SIGTERM handler (idempotent; the CLI calls it at start).
void install_signal_cleanup();

// The name mark of an output set's staging folder (output_set.h): a file committed into such a
// folder stays registered for cleanup until the set is committed or removed.
inline constexpr const char* kStagingMarker = ".plaf-stage-";

class AtomicFile {
 public:
  // Opens the temporary next to the target; throws Error naming the path if it cannot.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  void write(std::string_view text);
  void put(char c) {
    if (used_ == buffer_.size()) flush_buffer();
    buffer_[used_++] = c;
  }
  void write_int(std::int64_t value);
  // Shortest round-trip representation (non-finite values are written as "nan", "inf", "-inf").
  void write_double(double value);

  // Raw bytes (binary formats: MSH 4.1 with file type 1, VTU's appended data), in this machine's
  // byte order.
  void write_bytes(const void* data, std::size_t size) {
    write(std::string_view(static_cast<const char*>(data), size));
  }

  // Flushes, closes and renames the temporary onto the target (replacing an existing file).
  // Throws Error naming the path if any write failed or the rename is refused.
  void commit();

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temp_path() const { return temp_; }

 private:
  void flush_buffer();
  void fail(const char* what) const;

  std::filesystem::path target_;
  std::filesystem::path temp_;
  std::ofstream out_;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  bool committed_ = false;
  int slot_ = -1;  // the temporary's cleanup slot
};

}  // namespace io
}  // namespace plaf
