// SPDX-License-Identifier: MIT
#include "modules/base/parallel.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace plaf {
namespace {

TEST_CASE("parallel: chunks cover every index once, workers stay in range, errors come back") {
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
  CHECK_THROWS_AS(parallel_chunks(100000, 16,
                                  [](unsigned, std::size_t b, std::size_t) {
                                    if (b == 640) throw std::runtime_error("chunk 40");
                                  }),
                  std::runtime_error);
  CHECK(worker_threads() >= 1);
}

}  // namespace
}  // namespace plaf
