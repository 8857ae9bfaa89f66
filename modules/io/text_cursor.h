// SPDX-License-Identifier: MIT
// TextCursor: the tokenizer of plaf's ASCII mesh readers (Gmsh MSH 4.1 in msh_read.cpp; the
// $NodeData scan in background_read_msh.cpp and the libMeshb .mesh/.sol reader in
// background_read_meshb.cpp). It walks a whole file held in memory as white-space separated
// tokens and counts lines from 1. Every failure throws InputError "path:line: reason"; line 0
// stands for the file as a whole.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace plaf {
inline namespace io {

// The whole file; throws InputError "path:0: cannot read the file[: why]".
std::string read_whole_file(const std::filesystem::path& path);

class TextCursor {
 public:
  // `text` (the contents of `path`) must outlive the cursor. With hash_comments, '#' starts a
  // comment that runs to the end of the line (libMeshb ASCII); MSH has no comments.
  TextCursor(std::filesystem::path path, std::string_view text, bool hash_comments = false);

  // The line of the current position: that of the last token read, or of the next one once
  // white space has been skipped (at_end, next_line).
  int line() const { return line_; }
  // Skips white space and comments; the line of the next token (or of the end of the text).
  int next_line();
  // Skips white space and comments; true when the text is exhausted.
  bool at_end();
  // Characters not read yet.
  std::size_t remaining() const { return static_cast<std::size_t>(end_ - p_); }

  // Throw InputError "path:line: reason", at line() or at the given line.
  [[noreturn]] void fail(const std::string& reason) const;
  [[noreturn]] void fail_at(int line, const std::string& reason) const;

  // The next token; at the end of the text fails with "unexpected end of file (expected what)".
  std::string_view token(const char* what);
  // The next token without consuming it ("" at the end of the text).
  std::string_view peek();
  // A decimal integer token (an optional leading '+' is accepted); `what` names it in failures.
  std::int64_t integer(const char* what);
  // An integer in [lo, hi].
  std::int64_t integer(const char* what, std::int64_t lo, std::int64_t hi);
  // A count of items that each take at least min_bytes characters of the rest of the file: a
  // corrupt count fails here instead of reserving gigabytes.
  std::int64_t count(const char* what, std::size_t min_bytes);
  // A finite floating-point token.
  double real(const char* what);
  // A real within +-kMaxCoordinate (modules/base/coordinates.h), else "<what> 'X' is beyond +-1e+12".
  double coordinate(const char* what);
  // The token `keyword` itself.
  void expect(const char* keyword);
  // A double-quoted string without line breaks, after white space that may span lines (MSH
  // $NodeData string tags); the quotes are dropped.
  std::string quoted(const char* what);
  // The same on the current line: only blanks may come before the opening quote
  // (MSH $PhysicalNames).
  std::string quoted_on_line(const char* what);
  // Skips to the line after the first one that holds only end_keyword (between white space);
  // fails at start_line with "section $name has no end_keyword".
  void skip_to_line(std::string_view end_keyword, int start_line, std::string_view name);

  // Binary data after a text line (binary MSH): skips the rest of the current line and its '\n',
  // once, before the first raw read; then raw() hands out the next n bytes (fails with
  // "unexpected end of file (expected what)" when fewer are left). Lines are not counted in them.
  void start_binary();
  std::string_view raw(std::size_t n, const char* what);

  // A printable excerpt of a token for messages: quoted, one line, at most 40 characters.
  static std::string quote(std::string_view t);

 private:
  void skip_space();
  std::string quoted_here(const char* what);

  std::filesystem::path path_;
  const char* p_;
  const char* end_;
  bool hash_comments_;
  int line_ = 1;
};

}  // namespace io
}  // namespace plaf
