// SPDX-License-Identifier: MIT
// Published geometry in the tests: found through the data root as a run finds it
// (modules/pipeline/data_root.h: --data, PLAF_DATA, ../shared/data beside the repository).
//
// A test case that needs a published file starts with PLAF_NEEDS_PUBLISHED("airfoils/e387.dat",
// ...): without the file it asks to be reported skipped and returns. A case that checks what it
// can and leaves the rest out (the shipped configs without their published files) calls
// request_skip(). The skip marker is printed when the case ends, and only when nothing in it
// failed (tests/main_test.cpp's listener): ctest then reports it *skipped*
// (tests/CMakeLists.txt: SKIP_REGULAR_EXPRESSION), never passed, and a failure still fails.
#pragma once

#include <initializer_list>
#include <string>

#include "modules/pipeline/data_root.h"

namespace plaf::test {

// The marker ctest turns into "skipped".
inline constexpr const char* kSkipMarker = "plaf-test-skipped:";

// Why the running test case asked to be reported skipped ("" when it did not); the listener
// clears it when a case starts and prints it when the case ends.
inline std::string& skip_request() {
  static std::string why;
  return why;
}

inline void request_skip(const std::string& why) {
  if (skip_request().empty()) skip_request() = why;
}

// The path of a published file (data root relative `rel`), or "" when no root has it.
inline std::string published(const std::string& rel) { return find_data_file(rel).value_or(""); }

// True when every file is found; else asks to be reported skipped, naming the first missing one.
inline bool have_published(std::initializer_list<const char*> rels) {
  for (const char* rel : rels)
    if (!find_data_file(rel)) {
      request_skip(std::string("published file ") + rel +
                   " is in no data root (--data, PLAF_DATA, ../shared/data beside the repository)");
      return false;
    }
  return true;
}

}  // namespace plaf::test

// Returns from the test case (reported skipped) unless every published file named is found.
#define PLAF_NEEDS_PUBLISHED(...)                              \
  do {                                                         \
    if (!::plaf::test::have_published({__VA_ARGS__})) return; \
  } while (false)
