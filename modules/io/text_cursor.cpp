// SPDX-License-Identifier: MIT
// TextCursor (see text_cursor.h).
#include "modules/io/text_cursor.h"

#include "modules/base/coordinates.h"
#include "modules/base/format.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <system_error>
#include <utility>

#include "modules/base/error.h"

namespace plaf {
inline namespace io {
namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

}  // namespace

std::string read_whole_file(const std::filesystem::path& path) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path.string() + ":0: cannot read the file: " + ec.message());
  std::ifstream in(path, std::ios::binary);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in || !in.read(text.data(), static_cast<std::streamsize>(size)))
    throw InputError(path.string() + ":0: cannot read the file");
  return text;
}

TextCursor::TextCursor(std::filesystem::path path, std::string_view text, bool hash_comments)
    : path_(std::move(path)), p_(text.data()), end_(text.data() + text.size()), hash_comments_(hash_comments) {}

int TextCursor::next_line() {
  skip_space();
  return line_;
}

bool TextCursor::at_end() {
  skip_space();
  return p_ == end_;
}

void TextCursor::fail(const std::string& reason) const {
  fail_at(line_, reason);
}

void TextCursor::fail_at(int line, const std::string& reason) const {
  throw InputError(path_.string() + ":" + std::to_string(line) + ": " + reason);
}

std::string_view TextCursor::token(const char* what) {
  skip_space();
  if (p_ == end_) fail(std::string("unexpected end of file (expected ") + what + ")");
  const char* b = p_;
  while (p_ != end_ && !is_space(*p_)) ++p_;
  return {b, static_cast<std::size_t>(p_ - b)};
}

void TextCursor::start_binary() {
  while (p_ != end_ && *p_ != '\n') {
    if (!is_space(*p_)) fail("expected the end of the line before binary data, found " + quote(peek()));
    ++p_;
  }
  if (p_ != end_) {
    ++p_;
    ++line_;
  }
}

std::string_view TextCursor::raw(std::size_t n, const char* what) {
  if (remaining() < n) fail(std::string("unexpected end of file (expected ") + what + ")");
  const std::string_view v(p_, n);
  p_ += n;
  return v;
}

std::string_view TextCursor::peek() {
  skip_space();
  const char* e = p_;
  while (e != end_ && !is_space(*e)) ++e;
  return {p_, static_cast<std::size_t>(e - p_)};
}

std::int64_t TextCursor::integer(const char* what) {
  const std::string_view t = token(what);
  std::int64_t v = 0;
  const char* b = t.data() + (t.size() > 1 && t[0] == '+' ? 1 : 0);
  const auto r = std::from_chars(b, t.data() + t.size(), v);
  if (r.ec != std::errc() || r.ptr != t.data() + t.size()) fail(std::string("bad ") + what + " " + quote(t));
  return v;
}

std::int64_t TextCursor::integer(const char* what, std::int64_t lo, std::int64_t hi) {
  const std::int64_t v = integer(what);
  if (v < lo || v > hi)
    fail(std::string(what) + " " + std::to_string(v) + " is outside " + std::to_string(lo) + ".." + std::to_string(hi));
  return v;
}

std::int64_t TextCursor::count(const char* what, std::size_t min_bytes) {
  const std::int64_t v = integer(what);
  if (v < 0) fail(std::string("negative ") + what + " " + std::to_string(v));
  if (static_cast<std::uint64_t>(v) > remaining() / min_bytes + 1)
    fail(std::string(what) + " " + std::to_string(v) + " exceeds what the rest of the file can hold (truncated file?)");
  return v;
}

double TextCursor::real(const char* what) {
  const std::string_view t = token(what);
  double v = 0;
  const char* b = t.data() + (t.size() > 1 && t[0] == '+' ? 1 : 0);
  const auto r = std::from_chars(b, t.data() + t.size(), v);
  if (r.ec != std::errc() || r.ptr != t.data() + t.size() || !std::isfinite(v))
    fail(std::string("bad ") + what + " " + quote(t));
  return v;
}

double TextCursor::coordinate(const char* what) {
  const std::string_view t = peek();  // the token as written (a view into the text)
  const double v = real(what);
  if (std::abs(v) > kMaxCoordinate) fail(std::string(what) + " " + quote(t) + " is beyond +-" + num(kMaxCoordinate));
  return v;
}

void TextCursor::expect(const char* keyword) {
  const std::string_view t = token(keyword);
  if (t != keyword) fail("expected " + std::string(keyword) + ", found " + quote(t));
}

std::string TextCursor::quoted(const char* what) {
  skip_space();
  return quoted_here(what);
}

std::string TextCursor::quoted_on_line(const char* what) {
  while (p_ != end_ && (*p_ == ' ' || *p_ == '\t')) ++p_;
  return quoted_here(what);
}

std::string TextCursor::quoted_here(const char* what) {
  if (p_ == end_ || *p_ != '"') fail(std::string("expected a double-quoted ") + what);
  const char* b = ++p_;
  while (p_ != end_ && *p_ != '"' && *p_ != '\n') ++p_;
  if (p_ == end_ || *p_ != '"') fail(std::string("unterminated ") + what);
  std::string s(b, static_cast<std::size_t>(p_ - b));
  ++p_;
  return s;
}

void TextCursor::skip_to_line(std::string_view end_keyword, int start_line, std::string_view name) {
  while (p_ != end_) {
    skip_space();
    const char* b = p_;
    while (p_ != end_ && *p_ != '\n') ++p_;
    std::string_view l(b, static_cast<std::size_t>(p_ - b));
    while (!l.empty() && is_space(l.back())) l.remove_suffix(1);
    if (l == end_keyword) return;
  }
  fail_at(start_line, "section $" + std::string(name) + " has no " + std::string(end_keyword));
}

std::string TextCursor::quote(std::string_view t) {
  constexpr std::size_t max_chars = 40;
  std::string s = "'";
  for (std::size_t i = 0; i < t.size() && i < max_chars; ++i) s += (t[i] >= 32 && t[i] < 127) ? t[i] : '?';
  if (t.size() > max_chars) s += "...";
  return s + "'";
}

void TextCursor::skip_space() {
  while (p_ != end_) {
    if (*p_ == '\n') {
      ++line_;
      ++p_;
    } else if (is_space(*p_)) {
      ++p_;
    } else if (hash_comments_ && *p_ == '#') {
      while (p_ != end_ && *p_ != '\n') ++p_;
    } else {
      break;
    }
  }
}

}  // namespace io
}  // namespace plaf
