// SPDX-License-Identifier: MIT
// AtomicFile (see atomic_file.h): temporary + rename, with one flat output buffer.
#include "modules/io/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <csignal>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <string>
#include <system_error>
#include <utility>

#include "modules/base/error.h"

namespace plaf {
inline namespace io {
namespace {

constexpr std::size_t buffer_bytes = std::size_t{1} << 20;
// Longest output of to_chars for an int64 (20) or a shortest-form double (24), with margin.
constexpr std::size_t max_number_chars = 32;

// The cleanup slots: a path each, and its state (0 free, 1 a file, 2 a folder, 3 being written),
// read by the signal handler, which may only use async-signal-safe calls (unlink, rmdir, raise).
constexpr int slot_count = 64;
constexpr std::size_t path_bytes = 4096;
char slot_path[slot_count][path_bytes];
std::atomic<int> slot_state[slot_count];

extern "C" void on_stop_signal(int sig) {
  for (int kind : {1, 2})  // files first, then the folders that held them
    for (int k = 0; k < slot_count; ++k)
      if (slot_state[k].load() == kind) (kind == 1 ? ::unlink(slot_path[k]) : ::rmdir(slot_path[k]));
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

namespace cleanup {

int add(const std::filesystem::path& path, bool folder) {
  const std::string s = std::filesystem::absolute(path).string();
  if (s.size() + 1 > path_bytes) return -1;
  for (int k = 0; k < slot_count; ++k) {
    int free_state = 0;
    if (slot_state[k].compare_exchange_strong(free_state, 3)) {
      std::memcpy(slot_path[k], s.c_str(), s.size() + 1);
      slot_state[k].store(folder ? 2 : 1);
      return k;
    }
  }
  return -1;
}

void release(int slot) {
  if (slot >= 0 && slot < slot_count) slot_state[slot].store(0);
}

void release_under(const std::filesystem::path& folder) {
  const std::string f = std::filesystem::absolute(folder).string();
  for (int k = 0; k < slot_count; ++k) {
    const int state = slot_state[k].load();
    if (state != 1 && state != 2) continue;
    const std::string p = slot_path[k];
    if (p == f || (p.size() > f.size() && p.compare(0, f.size(), f) == 0 && p[f.size()] == '/')) slot_state[k].store(0);
  }
}

}  // namespace cleanup

void install_signal_cleanup() {
  static const bool once = [] {
    std::signal(SIGINT, on_stop_signal);
    std::signal(SIGTERM, on_stop_signal);
    return true;
  }();
  (void)once;
}

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)), buffer_(buffer_bytes) {
  temp_ = target_;
  temp_ += ".tmp." + std::to_string(static_cast<long long>(::getpid()));
  slot_ = cleanup::add(temp_);
  out_.open(temp_, std::ios::binary | std::ios::trunc);
  if (!out_) {
    const int err = errno;
    cleanup::release(slot_);
    throw Error("cannot open " + temp_.string() + " for writing (to create " + target_.string() +
                "): " + std::strerror(err));
  }
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.close();
  std::error_code ignored;
  std::filesystem::remove(temp_, ignored);
  cleanup::release(slot_);
}

void AtomicFile::fail(const char* what) const {
  throw Error(std::string(what) + " " + temp_.string() + " (writing " + target_.string() + ")");
}

void AtomicFile::flush_buffer() {
  if (used_ == 0) return;
  out_.write(buffer_.data(), static_cast<std::streamsize>(used_));
  used_ = 0;
  if (!out_) fail("write error on");
}

void AtomicFile::write(std::string_view text) {
  if (text.size() > buffer_.size() - used_) {
    flush_buffer();
    if (text.size() > buffer_.size()) {
      out_.write(text.data(), static_cast<std::streamsize>(text.size()));
      if (!out_) fail("write error on");
      return;
    }
  }
  std::memcpy(buffer_.data() + used_, text.data(), text.size());
  used_ += text.size();
}

void AtomicFile::write_int(std::int64_t value) {
  if (buffer_.size() - used_ < max_number_chars) flush_buffer();
  char* begin = buffer_.data() + used_;
  const auto r = std::to_chars(begin, begin + max_number_chars, value);
  used_ += static_cast<std::size_t>(r.ptr - begin);
}

void AtomicFile::write_double(double value) {
  if (buffer_.size() - used_ < max_number_chars) flush_buffer();
  char* begin = buffer_.data() + used_;
  const auto r = std::to_chars(begin, begin + max_number_chars, value);
  used_ += static_cast<std::size_t>(r.ptr - begin);
}

void AtomicFile::commit() {
  if (committed_) return;
  flush_buffer();
  out_.flush();
  if (!out_) fail("write error on");
  out_.close();
  if (!out_) fail("cannot close");
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec) throw Error("cannot rename " + temp_.string() + " to " + target_.string() + ": " + ec.message());
  committed_ = true;
  cleanup::release(slot_);
  // A file of an output set not yet complete (output_set.h) stays registered until the set is.
  if (target_.parent_path().filename().string().find(kStagingMarker) != std::string::npos) slot_ = cleanup::add(target_);
}

}  // namespace io
}  // namespace plaf
