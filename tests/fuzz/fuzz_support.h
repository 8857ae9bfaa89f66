// SPDX-License-Identifier: MIT
// Shared by the libFuzzer harnesses (tests/fuzz/README.md): the readers take paths, so each input
// is written to a per-process temporary file first. A plaf::Error (InputError, ConfigError, ...)
// is the expected answer to a bad input; anything else escapes so that libFuzzer reports it.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "modules/base/error.h"

namespace plaf_fuzz {

// $TMPDIR (or /tmp)/plaf-fuzz-<pid>, created on first use and removed at normal exit (a crash
// leaves it behind: remove /tmp/plaf-fuzz-* by hand).
inline const std::filesystem::path& scratch_dir() {
  // Never destroyed, so that the exit handler (registered before it is built) still sees it.
  static const std::filesystem::path* const dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    auto* d = new std::filesystem::path(std::filesystem::path(tmp && *tmp ? tmp : "/tmp") /
                                        ("plaf-fuzz-" + std::to_string(static_cast<long>(::getpid()))));
    std::filesystem::create_directories(*d);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(scratch_dir(), ec);
    });
    return d;
  }();
  return *dir;
}

// Writes bytes to scratch_dir()/name (truncating) and returns the path.
inline std::filesystem::path write_input(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path p = scratch_dir() / name;
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) std::abort();  // the harness itself failed: never a finding about plaf
  return p;
}

// Runs f; a plaf::Error is the expected outcome of a bad input and is swallowed.
template <class F>
void expect_plaf_errors_only(F&& f) {
  try {
    f();
  } catch (const plaf::Error&) {
  }
}

}  // namespace plaf_fuzz
