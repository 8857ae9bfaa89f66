// SPDX-License-Identifier: MIT
// AtomicFile (see atomic_file.h): temporary + rename, with one flat output buffer.
#include "modules/io/atomic_file.h"

#include <unistd.h>

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

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)), buffer_(buffer_bytes) {
  temp_ = target_;
  temp_ += ".tmp." + std::to_string(static_cast<long long>(::getpid()));
  out_.open(temp_, std::ios::binary | std::ios::trunc);
  if (!out_) {
    const int err = errno;
    throw Error("cannot open " + temp_.string() + " for writing (to create " + target_.string() +
                "): " + std::strerror(err));
  }
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.close();
  std::error_code ignored;
  std::filesystem::remove(temp_, ignored);
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
}

}  // namespace io
}  // namespace plaf
