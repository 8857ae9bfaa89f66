// SPDX-License-Identifier: MIT
// File helpers shared by the test suites that write and read files: a scratch directory that
// cleans up after itself, and whole-file text I/O. Header-only; include it as
// "tests/test_support.h".
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <initializer_list>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace plaf::test {

// A fresh directory <system temp dir>/plaf_<name>_<pid>: emptied on construction, removed with
// everything in it at scope exit (also when a REQUIRE fails). The pid keeps concurrent test
// processes apart; `name` keeps the test cases of one process apart.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path(std::filesystem::temp_directory_path() / ("plaf_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::filesystem::path operator/(const std::string& file) const { return path / file; }

  // The names of the directory's entries, in directory order.
  std::vector<std::string> entries() const {
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::directory_iterator(path)) out.push_back(e.path().filename().string());
    return out;
  }

  const std::filesystem::path path;
};

// The whole file, byte for byte ("" if it cannot be opened).
inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The file's lines without their '\n' (a '\r' before it stays).
inline std::vector<std::string> read_lines(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Writes text to a fresh file at p, byte for byte, and returns p.
inline std::filesystem::path write_text(const std::filesystem::path& p, const std::string& text) {
  // Removing first makes a new file: rewriting one by truncation makes ext4 flush it on close
  // (auto_da_alloc), which slows tests that rewrite a file many times.
  std::filesystem::remove(p);
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

// The last line of a text without its '\n' (a run's one-line error is the last line of stderr).
inline std::string last_line(const std::string& text) {
  const std::size_t end = text.find_last_not_of('\n');
  if (end == std::string::npos) return "";
  const std::size_t begin = text.rfind('\n', end);
  return text.substr(begin == std::string::npos ? 0 : begin + 1, end - (begin == std::string::npos ? 0 : begin + 1) + 1);
}

// What a run of the plaf binary gave: its exit code (-1 if it did not exit) and its stderr.
struct PlafResult {
  int code = -1;
  std::string err;
};

// Runs `plaf args` (the built binary, PLAF_EXE) with stderr captured in dir/stderr.txt and stdout
// discarded.
inline PlafResult run_plaf(const std::string& args, const std::filesystem::path& dir) {
  const std::filesystem::path err = dir / "stderr.txt";
  const std::string cmd = std::string(PLAF_EXE) + " " + args + " > /dev/null 2> " + err.string();
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_text(err)};
}

inline PlafResult run_plaf(const std::string& args, const TempDir& dir) { return run_plaf(args, dir.path); }

// The same run with its stdout too (dir/stdout.txt), for commands whose output is the result.
struct PlafOutput {
  int code = -1;
  std::string out, err;
};
inline PlafOutput run_plaf_output(const std::string& args, const TempDir& dir) {
  const std::filesystem::path out = dir.path / "stdout.txt", err = dir.path / "stderr.txt";
  const std::string cmd = std::string(PLAF_EXE) + " " + args + " > " + out.string() + " 2> " + err.string();
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_text(out), read_text(err)};
}

// The regular files below dir (0 if it does not exist).
inline int count_files(const std::filesystem::path& dir) {
  if (!std::filesystem::exists(dir)) return 0;
  int n = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    if (e.is_regular_file()) ++n;
  return n;
}

// The number at a path of keys in a JSON report as plaf writes it: each section (`"key": {`)
// searched after the previous one, then the number's key ({"fill", "optimize", "after",
// "unit_fraction"}); NaN if a key is missing.
inline double report_value(const std::string& report, std::initializer_list<std::string> path) {
  std::size_t at = 0, left = path.size();
  for (const std::string& key : path) {
    const std::string want = "\"" + key + (--left > 0 ? "\": {" : "\": ");
    at = report.find(want, at);
    if (at == std::string::npos) return std::nan("");
    at += want.size();
  }
  return std::strtod(report.c_str() + at, nullptr);
}

}  // namespace plaf::test
