// SPDX-License-Identifier: MIT
// AtomicFile: a buffered text sink that writes <target>.tmp.<pid> and renames it onto the target
// on commit(). Every writer of plaf goes through it, so a writer that fails half-way never leaves
// a partial file, nor a stale temporary: the destructor removes the temporary unless committed.
//
// Numbers are formatted with std::to_chars into one large buffer (no per-number allocation);
// doubles use the shortest form that reads back to the same bits, which is at most 17
// significant digits. Two AtomicFiles of one process must not target the same path at once.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <vector>

namespace plaf {
inline namespace io {

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
  // Writes the point x (an Eigen vector of 2 or 3 coordinates) as the line "x y z"; z is 0 in
  // 2D, since MSH and VTU store every point in 3D.
  template <class Point>
  void write_point_line(const Point& x) {
    static_assert(Point::SizeAtCompileTime == 2 || Point::SizeAtCompileTime == 3);
    write_double(x[0]);
    put(' ');
    write_double(x[1]);
    put(' ');
    if constexpr (Point::SizeAtCompileTime == 3)
      write_double(x[2]);
    else
      put('0');
    put('\n');
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
};

}  // namespace io
}  // namespace plaf
