// SPDX-License-Identifier: MIT
#include "modules/base/parallel.h"

#include <doctest/doctest.h>
#include <stdlib.h>

#include <algorithm>
#include <atomic>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace plaf {
namespace {

TEST_CASE("parallel: chunks cover every index once, workers stay in range, errors come back") {
  // Four workers whatever the machine has, so the threaded path runs on one CPU too.
  ::setenv("PLAF_THREADS", "4", 1);
  REQUIRE(worker_threads() == 4);
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{255}, std::size_t{256}, std::size_t{10007}}) {
    CAPTURE(n);
    std::vector<int> hits(n, 0);
    std::atomic<bool> worker_ok{true};
    parallel_chunks(n, 64, [&](unsigned w, std::size_t b, std::size_t e) {
      if (w >= worker_threads()) worker_ok = false;
      for (std::size_t i = b; i < e; ++i) ++hits[i];
    });
    CHECK(worker_ok);
    CHECK(std::count(hits.begin(), hits.end(), 1) == static_cast<long>(n));
  }
  // Of two failing chunks, the lower one's error comes back (as on one thread), every time.
  for (int run = 0; run < 20; ++run)
    try {
      parallel_chunks(100000, 16, [](unsigned, std::size_t b, std::size_t) {
        if (b == 640) throw std::runtime_error("chunk 40");
        if (b == 480) throw std::runtime_error("chunk 30");
      });
      FAIL("no error came back");
    } catch (const std::runtime_error& e) {
      CHECK(std::string(e.what()) == "chunk 30");
    }
  // PLAF_THREADS=1 runs everything on the caller's thread, as one chunk.
  ::setenv("PLAF_THREADS", "1", 1);
  const std::thread::id caller = std::this_thread::get_id();
  int calls = 0;
  parallel_chunks(10000, 16, [&](unsigned w, std::size_t b, std::size_t e) {
    ++calls;
    CHECK(w == 0);
    CHECK(b == 0);
    CHECK(e == 10000);
    CHECK(std::this_thread::get_id() == caller);
  });
  CHECK(calls == 1);
  ::unsetenv("PLAF_THREADS");
}

}  // namespace
}  // namespace plaf
